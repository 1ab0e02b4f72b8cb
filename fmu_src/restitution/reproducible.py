"""Reproducible archives: the same contents give the same bytes, whenever and wherever they are written.

:func:`write_zip` is the one writer of every archive the project makes (the FMUs, and any other zip such as
an SSP file): each entry's time is ``SOURCE_DATE_EPOCH`` where it is set (https://reproducible-builds.org/
specs/source-date-epoch/), otherwise the constant :data:`ZIP_EPOCH`; the entries are written in sorted
order of their names; each has fixed Unix permissions (0755 for shared libraries under ``binaries/``, 0644
for the rest) and a fixed "made by" system, whatever the umask, the file system or the operating system
the build runs on. It has no dependency beyond the standard library, so any module can use it.
"""
from __future__ import annotations

import os
import re
import zipfile
from datetime import datetime, timezone
from pathlib import Path
from typing import Iterable, Mapping

__all__ = ["ZIP_EPOCH", "source_date_epoch", "zip_date_time", "entry_mode", "write_zip", "zip_directory"]

#: The entry time of every archive without SOURCE_DATE_EPOCH: the earliest a zip entry can state.
ZIP_EPOCH = (1980, 1, 1, 0, 0, 0)
#: The latest time a zip entry (MS-DOS date and time) can state.
_ZIP_LAST = (2107, 12, 31, 23, 59, 58)
#: "Made by" Unix (3), so that the permissions in external_attr mean the same to every reader.
_UNIX = 3


def source_date_epoch(environ: Mapping[str, str] | None = None) -> int | None:
    """``SOURCE_DATE_EPOCH`` (whole seconds since 1970-01-01 UTC) of ``environ`` (default this process's);
    None where it is unset or empty; ValueError for a value that is not a whole number of seconds."""
    text = (os.environ if environ is None else environ).get("SOURCE_DATE_EPOCH", "").strip()
    if not text:
        return None
    if not re.fullmatch(r"[0-9]+", text):
        raise ValueError(f"SOURCE_DATE_EPOCH={text!r} is not a whole number of seconds since 1970-01-01 UTC")
    return int(text)


def zip_date_time(environ: Mapping[str, str] | None = None) -> tuple[int, int, int, int, int, int]:
    """The time every entry of an archive gets: SOURCE_DATE_EPOCH in UTC, held within what a zip entry can
    state (1980 to 2107; zip stores even seconds), else :data:`ZIP_EPOCH`."""
    seconds = source_date_epoch(environ)
    if seconds is None:
        return ZIP_EPOCH
    try:
        when = datetime.fromtimestamp(seconds, timezone.utc).timetuple()[:6]
    except (OverflowError, OSError, ValueError):
        return _ZIP_LAST
    return max(ZIP_EPOCH, min(_ZIP_LAST, when))


def entry_mode(name: str) -> int:
    """The Unix permissions of the archive entry ``name``: 0755 for a file under ``binaries/`` (a shared
    library, which some hosts map executable straight from the extracted file), 0644 otherwise."""
    return 0o755 if name.startswith("binaries/") else 0o644


def write_zip(path: str | Path, entries: Mapping[str, bytes] | Iterable[tuple[str, bytes]],
              environ: Mapping[str, str] | None = None) -> Path:
    """Write the zip archive ``path`` of ``entries`` (archive name -> bytes; names with "/" separators),
    deflated, reproducibly (see the module docstring); returns ``path``. ValueError for a malformed
    SOURCE_DATE_EPOCH or a name given twice."""
    items = list(entries.items() if isinstance(entries, Mapping) else entries)
    names = [name for name, _ in items]
    if len(set(names)) != len(names):
        raise ValueError(f"{path}: an entry name given twice")
    date_time = zip_date_time(environ)
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as archive:
        for name, data in sorted(items):
            info = zipfile.ZipInfo(name, date_time=date_time)
            info.compress_type = zipfile.ZIP_DEFLATED
            info.create_system = _UNIX
            info.external_attr = (0o100000 | entry_mode(name)) << 16  # a regular file and its permissions
            archive.writestr(info, data)
    return Path(path)


def zip_directory(directory: str | Path, path: str | Path, environ: Mapping[str, str] | None = None) -> Path:
    """:func:`write_zip` of every file below ``directory``, named by its path relative to it."""
    directory = Path(directory)
    return write_zip(path, ((p.relative_to(directory).as_posix(), p.read_bytes())
                            for p in directory.rglob("*") if p.is_file()), environ)
