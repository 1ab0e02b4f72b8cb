"""Measurements from files, in SI units, for ``restitution fit``:

* :func:`read_data` takes any measurement file by its suffix: a table (``.csv``, ``.txt``:
  :func:`read_csv`) or a recording (``.wav``: :func:`restitution.fit.recording.read_recording`);
* :func:`read_csv` tells the two tables apart by their header:

  - ``v_in,v_out`` and optionally ``sigma``: approach and rebound speeds of separate impacts [m/s]
    and the standard deviation of each rebound speed [m/s]: :class:`~restitution.fit.datasets.ReboundPairs`;
  - ``t_impact``: the successive impact times of one drop [s]: :class:`~restitution.fit.datasets.ImpactTimes`;

  in any column order, names in any case, separated by commas, ``#`` starting a comment (to the end of
  the line) and blank lines skipped. A header may carry its unit, ``v_in [m/s]`` or ``v_in (m/s)``,
  ``t_impact [s]``: the SI unit only (no conversion is made). Messages count the file's lines from 1
  and its data rows (after the header, comments and blank lines skipped) from 1, as the containers do;
* :func:`write_times` writes impact times as a ``t_impact`` table that :func:`read_csv` reads back to
  the same floats (the ``--times FILE`` option: detected times to check, edit and fit again).

Every fault is a :class:`~restitution.fit.datasets.DataError` whose message is one line naming the file
and the fault; the containers check the values themselves (count, finite, signs, order)."""
from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from restitution.fit.datasets import DataError, ImpactTimes, ReboundPairs, Recording, read_regular_file
from restitution.fit.recording import read_recording
from restitution.output_files import atomic_write

__all__ = ["read_data", "read_csv", "write_times", "TABLE_SUFFIXES", "RECORDING_SUFFIXES", "LAYOUTS",
           "MAX_TABLE_BYTES", "NUMBER"]

#: The largest table read [bytes] (64 MiB: some three million rows).
MAX_TABLE_BYTES = 64 * 2 ** 20
#: A cell that is a number: plain decimal or scientific notation in ASCII digits (no ``_`` digit
#: separators, no hexadecimal, no other scripts' digits, all of which Python's float() would take),
#: or nan / inf, which the containers then refuse by name.
NUMBER = re.compile(r"[+-]?(?:(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?|nan|inf|infinity)",
                    re.ASCII | re.IGNORECASE)

#: The suffixes of the tables :func:`read_csv` reads (case ignored).
TABLE_SUFFIXES = (".csv", ".txt")
#: The suffixes of the recordings :func:`restitution.fit.recording.read_recording` reads (case ignored).
RECORDING_SUFFIXES = (".wav",)
#: The SI unit of each column a table may hold.
UNITS = {"v_in": "m/s", "v_out": "m/s", "sigma": "m/s", "t_impact": "s"}
#: The two tables, in words, for the messages.
LAYOUTS = "'v_in,v_out' [m/s] with an optional 'sigma' [m/s] (rebound pairs), or 't_impact' [s] (impact times)"

#: A line end: LF, CR LF or CR (and nothing else, so that line numbers are an editor's).
_LINE_END = re.compile(r"\r\n|\r|\n")
#: A header cell: a name, then optionally a unit in square brackets or parentheses.
_HEADER_CELL = re.compile(r"^(?P<name>[^\[\]()]*?)\s*(?:\[(?P<sq>[^\]]*)\]|\((?P<par>[^)]*)\))?$")


def read_data(path) -> ReboundPairs | ImpactTimes | Recording:
    """The measurements in the file ``path``, by its suffix: a table (:data:`TABLE_SUFFIXES`,
    :func:`read_csv`) gives rebound pairs [m/s] or impact times [s], a recording
    (:data:`RECORDING_SUFFIXES`) a :class:`~restitution.fit.datasets.Recording` with the impact times
    [s] found in it. DataError (one line naming the file) for any other suffix or a file that cannot be
    read."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix in TABLE_SUFFIXES:
        return read_csv(path)
    if suffix in RECORDING_SUFFIXES:
        return read_recording(path)
    kind = f"suffix '{path.suffix}'" if path.suffix else "no suffix"
    raise DataError(f"{path}: {kind}: give a table ({', '.join(TABLE_SUFFIXES)}) with columns {LAYOUTS}, or a "
                    f"recording ({', '.join(RECORDING_SUFFIXES)}: 16-bit PCM)")


def _text(path: Path) -> str:
    """The contents of ``path`` as text (UTF-8, a byte order mark dropped); DataError if missing, not a
    regular file, larger than :data:`MAX_TABLE_BYTES`, unreadable or not UTF-8."""
    data = read_regular_file(path, MAX_TABLE_BYTES, "table")
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise DataError(f"{path}: not UTF-8 text (byte 0x{data[exc.start]:02x} at offset {exc.start}): "
                        "save the table as plain UTF-8 CSV") from None


def _rows(text: str):
    """``(line number, cells)`` of each line of ``text`` that is not blank once its comment (from ``#``)
    is cut, the cells stripped of blanks."""
    for number, line in enumerate(_LINE_END.split(text), start=1):
        line = line.split("#", 1)[0]
        if line.strip():
            yield number, [cell.strip() for cell in line.split(",")]


def _column(path: Path, cell: str) -> str:
    """The column name of the header cell ``cell``, its unit checked against :data:`UNITS`."""
    match = _HEADER_CELL.match(cell)
    if match is None:
        raise DataError(f"{path}: header cell '{cell}' is not a name, optionally with a unit in [] or ()")
    name = match["name"].strip().lower()
    unit = match["sq"] if match["sq"] is not None else match["par"]
    if unit is not None and name in UNITS and "".join(unit.split()) != UNITS[name]:
        raise DataError(f"{path}: column '{cell}': unit '{unit.strip()}' is not accepted, give {name} in "
                        f"{UNITS[name]} (SI; no conversion is made)")
    return name if name in UNITS else cell


def _is_number(cell: str) -> bool:
    """Whether ``cell`` is a number (:data:`NUMBER`)."""
    return NUMBER.fullmatch(cell) is not None


def _layout(path: Path, names: list[str]) -> str:
    """Which table the header ``names`` is: ``"pairs"`` or ``"times"``; DataError naming the columns
    found otherwise."""
    found = set(names)
    if len(found) != len(names):
        twice = next(name for name in names if names.count(name) > 1)
        raise DataError(f"{path}: column '{twice}' appears twice in the header")
    if found == {"t_impact"}:
        return "times"
    if {"v_in", "v_out"} <= found <= {"v_in", "v_out", "sigma"}:
        return "pairs"
    listed = ",".join(names)
    unknown = [name for name in names if name not in UNITS]
    if not found & {"v_in", "v_out", "t_impact"}:
        fault = "missing columns v_in,v_out or t_impact"
        if all(_is_number(name) for name in names):
            fault += " (the first line is numbers: the header is missing)"
    elif unknown:
        fault = f"unknown column{'s' if len(unknown) > 1 else ''} {', '.join(repr(n) for n in unknown)}"
    elif "t_impact" in found:
        fault = "t_impact cannot share a table with v_in, v_out or sigma"
    else:
        fault = f"missing column {' and '.join(sorted({'v_in', 'v_out'} - found))}"
    raise DataError(f"{path}: {fault}: found '{listed}'; a table has {LAYOUTS}")


def read_csv(path) -> ReboundPairs | ImpactTimes:
    """The table in the CSV file ``path``: :class:`~restitution.fit.datasets.ReboundPairs` [m/s] from
    columns ``v_in,v_out`` (and ``sigma``), :class:`~restitution.fit.datasets.ImpactTimes` [s] from a
    column ``t_impact`` (see the module's docstring). DataError (one line naming the file) for an
    unreadable file, another header, a unit that is not SI, a row of the wrong length, a cell that is
    not a number, or values the container refuses (fewer than 3, not finite, a negative speed,
    ``v_out > v_in``, times not increasing)."""
    path = Path(path)
    rows = _rows(_text(path))
    try:
        line, header = next(rows)
    except StopIteration:
        raise DataError(f"{path}: no header and no data: a table has {LAYOUTS}") from None
    names = [_column(path, cell) for cell in header]
    layout = _layout(path, names)
    columns: list[list[float]] = [[] for _ in names]
    for row, (line, cells) in enumerate(rows, start=1):
        if len(cells) != len(names):
            hint = " (a decimal comma? write 0.5, not 0,5)" if len(cells) > len(names) else ""
            raise DataError(f"{path}: line {line} has {len(cells)} cells, the header {len(names)}{hint}")
        for name, cell, column in zip(names, cells, columns):
            if not _is_number(cell):
                shown = cell if len(cell) <= 40 else f"{cell[:40]}... ({len(cell)} characters)"
                raise DataError(f"{path}: line {line} (row {row}), column {name}: '{shown}' is not a number "
                                "(plain decimal or scientific notation, e.g. 0.25 or 2.5e-1)")
            column.append(float(cell))
    values = dict(zip(names, (np.asarray(column, dtype=float) for column in columns)))
    source = str(path)
    if layout == "times":
        return ImpactTimes(values["t_impact"], source=source)
    return ReboundPairs(values["v_in"], values["v_out"], values.get("sigma"), source=source)


def write_times(path, times: ImpactTimes) -> Path:
    """Write the impact times ``times`` [s] to ``path`` as a ``t_impact`` table (each time as Python's
    shortest repr of the float, which reads back to the same float), atomically
    (:func:`restitution.output_files.atomic_write`: the old file stays whole until the new one is);
    returns ``path``. OutputWriteError / OutputPathError (one line) if it cannot be written."""
    origin = " ".join(str(times.source).split())
    lines = ["# impact times [s], one per line, increasing; edit and fit again with --times"]
    if origin:
        lines.append(f"# found in: {origin}")
    lines.append("t_impact")
    lines.extend(repr(float(t)) for t in times.t)
    text = "\n".join(lines) + "\n"
    return atomic_write(path, lambda tmp: Path(tmp).write_text(text, encoding="utf-8", newline=""), "--times")
