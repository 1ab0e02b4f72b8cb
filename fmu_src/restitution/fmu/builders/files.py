"""Writing FMU archives and putting them in place, for every builder: the output directory checked, an
archive written from a staged folder in a stable order, a zip member rewritten, and the finished FMU
moved into place atomically (``os.replace``), readable as the umask allows, so a failed build leaves
the previous FMU untouched."""
from __future__ import annotations

import os
import zipfile
from pathlib import Path

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
    """The archive ``fmu`` of every file below ``directory``, in sorted order."""
    with zipfile.ZipFile(fmu, "w", zipfile.ZIP_DEFLATED) as z:
        for path in sorted(directory.rglob("*")):
            if path.is_file():
                z.write(path, path.relative_to(directory).as_posix())


def rewrite_zip(fmu: Path, replace: dict[str, bytes]) -> None:
    """The archive ``fmu`` with the members named in ``replace`` given that content (added where new),
    every other member kept as it is."""
    tmp = fmu.with_suffix(".tmp")
    with zipfile.ZipFile(fmu) as src, zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as dst:
        for item in src.infolist():
            if item.filename not in replace:
                dst.writestr(item, src.read(item.filename))
        for name, data in replace.items():
            dst.writestr(name, data)
    tmp.replace(fmu)


def place(fmu: Path, target: Path) -> Path:
    """Move the finished ``fmu`` to ``target`` (same file system: atomic), readable as the umask allows
    (0644 typically)."""
    mask = os.umask(0o022)
    os.umask(mask)
    os.chmod(fmu, 0o666 & ~mask)
    os.replace(fmu, target)
    return target
