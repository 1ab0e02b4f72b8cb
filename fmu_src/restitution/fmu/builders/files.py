"""Writing FMU archives and putting them in place, for every builder: the output directory checked, an
archive written reproducibly from a staged folder (fixed times, order, permissions), a zip member rewritten, and the finished FMU
moved into place atomically (``os.replace``), readable as the umask allows, so a failed build leaves
the previous FMU untouched."""
from __future__ import annotations

import os
import zipfile
from pathlib import Path

from ...reproducible import write_zip, zip_directory

__all__ = ["BuildError", "writable_dir", "zip_dir", "rewrite_zip", "place"]


class BuildError(RuntimeError):
    """The FMU cannot be built here (a one-line reason for the user: no pythonfmu, unwritable --out, ...)."""


def writable_dir(out_dir: Path) -> Path:
    """``out_dir``, created where missing; BuildError where it is not a writable directory."""
    out_dir = Path(out_dir)
    if out_dir.exists() and not out_dir.is_dir():
        raise BuildError(f"--out {out_dir}: exists and is not a directory")
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise BuildError(f"--out {out_dir}: cannot create the directory ({exc.strerror})") from None
    if not os.access(out_dir, os.W_OK | os.X_OK):
        raise BuildError(f"--out {out_dir}: directory is not writable")
    return out_dir


def zip_dir(directory: Path, fmu: Path) -> None:
    """The archive ``fmu`` of every file below ``directory``, reproducibly
    (:func:`restitution.reproducible.write_zip`: fixed times, order and permissions)."""
    zip_directory(directory, fmu)


def rewrite_zip(fmu: Path, replace: dict[str, bytes]) -> None:
    """The archive ``fmu`` with the members named in ``replace`` given that content (added where new),
    every other member's content kept, written anew reproducibly (:func:`restitution.reproducible.write_zip`),
    whatever times and order the archive had."""
    tmp = fmu.with_suffix(".tmp")
    with zipfile.ZipFile(fmu) as src:
        entries = {item.filename: src.read(item.filename) for item in src.infolist() if not item.is_dir()}
    write_zip(tmp, {**entries, **replace})
    tmp.replace(fmu)


def place(fmu: Path, target: Path) -> Path:
    """Move the finished ``fmu`` to ``target`` (same file system: atomic), readable as the umask allows
    (0644 typically)."""
    mask = os.umask(0o022)
    os.umask(mask)
    os.chmod(fmu, 0o666 & ~mask)
    os.replace(fmu, target)
    return target
