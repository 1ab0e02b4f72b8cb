"""Plotting helpers shared by the examples and scripts (needs matplotlib; Pillow optional).

A subpackage so that build_fmu.py leaves it out of the FMUs, which need no plotting.
"""
from __future__ import annotations

from pathlib import Path

__all__ = ["write_png", "finish"]


def write_png(fig, path: Path, dpi: int) -> Path:
    """Save ``fig`` as a small PNG (128-colour palette when Pillow is there, as it is with matplotlib).

    Written to a temporary file and renamed, so a reader never sees a half-written picture.
    """
    import os
    import tempfile

    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(suffix=".png", dir=path.parent)
    os.close(fd)
    try:
        fig.savefig(tmp, dpi=dpi)
        try:
            from PIL import Image
        except ImportError:
            pass
        else:
            with Image.open(tmp) as image:
                small = image.convert("RGB").quantize(colors=128, method=Image.Quantize.MEDIANCUT,
                                                      dither=Image.Dither.NONE)
            small.save(tmp, format="PNG", optimize=True)
        os.chmod(tmp, 0o644)  # mkstemp makes it private
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
    return path


def finish(fig, path: Path, dpi: int, show: bool = False) -> Path:
    """What every example does with its figure: :func:`write_png` it to ``path``, show it on screen when
    ``show`` (blocking until the window closes), close it; returns ``path``."""
    import matplotlib.pyplot as plt

    write_png(fig, path, dpi)
    if show:
        plt.show()
    plt.close(fig)
    return path
