"""A sweep's table: its columns, how they are built, written (CSV or Parquet) and read back; the result
classes that hold a table and write it under a temporary name are :mod:`restitution.sweep.result`'s.

Units: a column that holds a quantity has the SI unit of its FMU variable (``[1]`` for a dimensionless
one: ``e``, ``t_over_d``, ``sphere.nu``); ``case``, ``pair``, the integer codes and the flags have none
(:func:`column_unit`). A CSV header names each column with its unit in brackets, ``v_approach [m/s]``,
``e [1]``, ``valid`` (:func:`csv_header`); a Parquet table keeps the bare names, the unit in each
field's metadata (``unit``). Floats are written in CSV as Python's ``repr``: the shortest text that reads
back as the same double. :func:`read_table` reads both headers, with units and without (tables written
before they had them), and gives the bare names."""
from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from .._blocks import has_own_bytes
from ..fmu.models.sphere_plate_impact.variables import TABLE
from ..output_files import atomic_write as write_atomic
from . import arrow_arrays
from .columns import (INPUT_NAMES, INTEGER_INPUTS, OUTPUT_NAMES, OUTPUTS as _OUTPUT_TYPES, T_OVER_D, VALIDITY,
                      is_one_value_view, table_counts)

__all__ = ["COLUMNS", "VALIDITY", "PackedColumns", "read_table", "table_counts", "assemble",
           "keep_columns", "TableBuilder", "write_atomic", "write_csv_rows", "chunk_table", "pair_codes",
           "column_unit", "csv_header", "UNITS"]

#: Column order of a result table.
COLUMNS = ("case", "pair", *INPUT_NAMES, T_OVER_D, *OUTPUT_NAMES, "ok")

#: Column -> SI unit of the quantity it holds ("1": dimensionless), for every Real column (the FMU
#: variables' units, as the interface table gives them) and t_over_d.
UNITS = {**{v.name: v.unit or "1" for v in (*TABLE.settable, *TABLE.outputs) if v.type == "Real"}, T_OVER_D: "1"}
#: A CSV header cell: the column's name, then its unit in brackets.
_HEADER = re.compile(r"(?P<name>.*?) \[(?P<unit>[^\]]*)\]")


def column_unit(name: str) -> str | None:
    """The SI unit of column ``name`` ("1": a dimensionless quantity); None for a column that holds no
    quantity (``case``, ``pair``, the integer codes, the flags, ``ok``)."""
    return UNITS.get(name)


def csv_header(names) -> str:
    """The header line of a CSV table of the columns ``names``: each with its unit in brackets
    (``v_approach [m/s]``, ``e [1]``), bare where it holds no quantity (``case``, ``valid``)."""
    return ",".join(f"{name} [{column_unit(name)}]" if column_unit(name) else name for name in names) + "\n"


#: Validity columns every table keeps, whatever ``columns`` asks for (with ``case``, ``pair`` and ``ok``).
_ALWAYS = ("case", "pair", *VALIDITY, "ok")


#: Rows converted to text at a time when a table is written as CSV (bounds the memory it takes).
CSV_BLOCK = 65_536


class PackedColumns:
    """A chunk's columns in one buffer, for the trip from a worker to this process.

    Dask sends each array as its own buffer; the receiving process allocates each one fresh (about
    a megabyte a column of a 100,000-case chunk) and the allocator hands those pages back to the
    system when they are freed, so every chunk faulted its 25 MB in again, 4 KiB at a time, on the
    one thread that receives. One buffer for the whole chunk is one frame on the wire, allocated in
    huge pages where the system has them (numpy asks for them from 4 MiB on). A column that holds
    one value throughout the chunk (bit for bit: a material's constants, the fixed parameters)
    travels as that value."""

    def __init__(self, columns: dict):
        self.layout = []  # (name, dtype string, offset in the buffer, rows, travels as one value)
        self.rows = int(np.size(columns["case"]))
        arrays, offset = [], 0
        for name, col in columns.items():
            col = np.asarray(col).reshape(-1)
            if is_one_value_view(col):  # sent as its value
                col, constant = col[:1].copy(), True
            else:
                col = np.ascontiguousarray(col)
                bits = col.view(f"u{col.dtype.itemsize}")
                constant = col.size > 1 and bool(np.all(bits == bits[0]))
            sent = col[:1] if constant else col
            offset = -(-offset // 8) * 8  # every column on an 8-byte boundary
            self.layout.append((name, col.dtype.str, offset, self.rows, constant))
            arrays.append(sent)
            offset += sent.nbytes
        self.buffer = np.empty(offset, dtype=np.uint8)
        for (_name, _dtype, start, _rows, _constant), sent in zip(self.layout, arrays):
            self.buffer[start:start + sent.nbytes] = sent.view(np.uint8)

    def columns(self) -> dict:
        """The columns, as views of the buffer (no copy; a one-value column read-only, repeated)."""
        out = {}
        for name, dtype, start, rows, constant in self.layout:
            count = 1 if constant else rows
            col = self.buffer[start:start + count * np.dtype(dtype).itemsize].view(dtype)
            out[name] = np.broadcast_to(col, (rows,)) if constant else col
        return out


def _column_type(name: str):
    if name in ("case", "pair") or name in INTEGER_INPUTS:
        return np.int64
    if name == "ok" or any(name == n and t == "Boolean" for n, _f, t in _OUTPUT_TYPES):
        return bool
    return float


def assemble(spec, parts: list, keep) -> dict:
    """The table from consecutive chunks (each a dict of columns or a :class:`PackedColumns`), as
    :class:`TableBuilder` makes it. ``parts`` is consumed: each chunk is dropped once copied."""
    rows = sum(part.rows if isinstance(part, PackedColumns) else int(np.size(part["case"])) for part in parts)
    builder, start = TableBuilder(spec, keep, rows), 0
    parts.reverse()
    while parts:
        part = parts.pop()
        start = builder.add(start, part)
        del part
    return builder.table()


#: The columns that may stay one-value views in a table: the inputs (what the spec fixes), never an output.
_VIEW_COLUMNS = frozenset(("pair", *INPUT_NAMES, T_OVER_D))


class TableBuilder:
    """A table of ``rows`` cases filled chunk by chunk as the chunks finish, in any order (:meth:`add`),
    then taken (:meth:`table`).

    Each chunk is copied into columns allocated once at their final types, and can be dropped at once:
    the memory in use stays near one table, and the chunks' own pages are reused by the next ones (a
    serial sweep of 10^7 cases that kept its ten chunks until the end faulted in all their pages as
    well as the table's, and cost several times the model). An input that holds one value over every
    chunk (bit for bit: a fixed parameter, a single pair's materials, ``pair`` itself then) stays a
    read-only view of that value (:func:`~restitution.sweep.spec.is_one_value_view`): no memory, as in
    the chunks. A chunk that is the whole table gives its own arrays (no copy)."""

    def __init__(self, spec, keep, rows: int):
        self.spec, self.rows = spec, rows
        self.names = [c for c in COLUMNS if keep is None or c in keep]
        self.filled = {}  #: start -> stop of each chunk added
        self.values = {}  #: name -> its one value (an array of one), while every chunk added holds it as a view
        self.columns = {}  #: name -> its column of ``rows`` rows, filled where chunks were added

    def add(self, start: int, part) -> int:
        """Copy the chunk ``part`` (columns of cases ``start`` ...) into the table; returns where it ends."""
        packed = isinstance(part, PackedColumns)
        chunk = part.columns() if packed else part
        stop = start + int(np.size(chunk["case"]))
        for name in self.names:
            self._take(name, chunk[name], start, stop, packed)
        self.filled[start] = stop
        return stop

    def _take(self, name, col, start, stop, packed):
        dtype = _column_type(name)
        if name not in self.columns:
            if name in _VIEW_COLUMNS and self.rows > 1 and is_one_value_view(col):
                value, held = np.asarray(col[:1], dtype=dtype), self.values.get(name)
                if held is None or held.tobytes() == value.tobytes():
                    self.values[name] = value
                    return
            if start == 0 and stop == self.rows:  # the whole table in one chunk
                self.columns[name] = _own_column(col, dtype, packed)
                return
            column = np.empty(self.rows, dtype=dtype)
            held = self.values.pop(name, None)
            if held is not None:  # it was one value up to this chunk
                for a, b in self.filled.items():
                    column[a:b] = held
            self.columns[name] = column
        self.columns[name][start:stop] = col

    def table(self) -> dict:
        """The table of the chunks added, in case order (all of them: the columns as filled; fewer, as
        after an interruption: their rows only, copied). Call once."""
        spans = sorted(self.filled.items())
        rows = sum(b - a for a, b in spans)
        columns = {}
        for name in self.names:
            dtype = _column_type(name)
            if name in self.values:
                value = self.values[name]
                columns[name] = np.broadcast_to(value, (rows,)) if rows > 1 else np.repeat(value, rows)
            elif name not in self.columns:  # no chunk
                columns[name] = np.empty(0, dtype=dtype)
            elif rows == self.rows:
                columns[name] = self.columns[name]
            else:
                columns[name] = np.concatenate([self.columns[name][a:b] for a, b in spans] or [np.empty(0, dtype)])
        self.columns.clear()
        labels = np.array(list(self.spec.pairs) + [""], dtype=object)  # pair -1 (no pairs) reads ""
        pair = columns["pair"]
        columns["pair"] = (np.broadcast_to(labels[pair[:1]], (rows,)) if is_one_value_view(pair) else labels[pair])
        return columns


def _own_column(col, dtype, packed: bool):
    """A chunk's column as a table column without a copy where it can be one: a writable, contiguous
    array of the table's type that no other column shares (an array the chunk owns, a whole row of a 2-D
    block, as ``impact`` returns its outputs over many cases, or a column of a packed chunk's buffer: each
    has its own bytes); else a copy."""
    col = np.asarray(col)
    if (col.dtype == dtype and col.flags.c_contiguous and col.flags.writeable
            and (packed or has_own_bytes(col)) and col.strides[0] != 0):
        return col
    return np.array(col, dtype=dtype)



def keep_columns(columns):
    if columns is None:
        return None
    unknown = set(columns) - set(COLUMNS)
    if unknown:
        raise ValueError(f"unknown column(s) {sorted(unknown)}; the table has {', '.join(COLUMNS)}")
    return frozenset((*_ALWAYS, *columns))  # validity travels with every row


def _csv_text(x) -> str:
    text = str(x)
    return f'"{text}"' if ("," in text or '"' in text) else text


def arrow_table(columns: dict):
    """The table's columns as a pyarrow Table (``pair`` dictionary-encoded), every column declared
    without missing values, as a sweep's columns are (an out-of-range case has NaN outputs, a value):
    Parquet then stores no definition levels, which took a fifth of the write."""
    import pyarrow as pa

    arrays = [arrow_arrays.dictionary(col) if col.dtype == object else arrow_arrays.numbers(col)
              for col in columns.values()]
    return pa.Table.from_arrays(arrays, schema=_schema(columns, arrays))


def _schema(names, arrays):
    """The table's schema: its bare column names, each quantity's unit in its field's metadata."""
    import pyarrow as pa

    return pa.schema([pa.field(name, a.type, nullable=False,
                               metadata={"unit": column_unit(name)} if column_unit(name) else None)
                      for name, a in zip(names, arrays)])


def _pair_labels(spec):
    return arrow_arrays.labels([*spec.pairs, ""])  # the last: no pairs (index -1)


def chunk_table(spec, columns: dict | None, keep):
    """One chunk's columns (as :meth:`SweepSpec.cases` and the back ends give them; None: no rows) as a
    pyarrow Table of the table's columns at their types, ``pair`` dictionary-encoded with the spec's
    pair labels as the dictionary (the same in every chunk). Columns that hold one value (views of it,
    ``numpy.broadcast_to``) are filled from it."""
    import pyarrow as pa

    names = [c for c in COLUMNS if keep is None or c in keep]
    n = 0 if columns is None else int(np.size(columns["case"]))
    arrays = []
    for name in names:
        if name == "pair":
            codes = np.zeros(0, np.int32) if columns is None else np.asarray(columns["pair"], dtype=np.int32)
            codes = np.where(codes < 0, len(spec.pairs), codes) if n and codes.min() < 0 else codes
            arrays.append(pa.DictionaryArray.from_arrays(arrow_arrays.numbers(codes.astype(np.int32, copy=False)),
                                                         _pair_labels(spec)))
            continue
        col = np.empty(0, _column_type(name)) if columns is None else np.asarray(columns[name])
        want = np.dtype(_column_type(name))
        if is_one_value_view(col):  # the same array each chunk
            arrays.append(_constant_array(col[:1].astype(want), col.size))
            continue
        if col.dtype != want or not col.flags.c_contiguous:  # an integer input held as float
            col = np.ascontiguousarray(col, dtype=want)
        arrays.append(arrow_arrays.numbers(col))
    return pa.Table.from_arrays(arrays, schema=_schema(names, arrays))


#: Arrow arrays of one value repeated, by (type, value's bytes, rows): a grid sweep's chunks share their
#: material constants and fixed inputs, which were a third of the cost of turning a chunk into a table
#: (written out in fresh memory, 26 columns of 37, every chunk). Immutable, so shared freely.
_CONSTANTS: dict = {}
#: Bytes the kept arrays may take (a 10^5-row chunk's 26 one-value columns: 21 MB).
_CONSTANTS_BYTES = 64 * 2**20


def _constant_array(value: np.ndarray, rows: int):
    key = (value.dtype.str, value.tobytes(), rows)
    array = _CONSTANTS.get(key)
    if array is None:
        array = arrow_arrays.numbers(np.repeat(value, rows))
        if sum(a.nbytes for a in _CONSTANTS.values()) + array.nbytes > _CONSTANTS_BYTES:
            _CONSTANTS.clear()
        if array.nbytes <= _CONSTANTS_BYTES:
            _CONSTANTS[key] = array
    return array


def pair_codes(spec, column) -> np.ndarray:
    """The spec's pair index (-1: no pairs) of each row of a ``pair`` column read from a Parquet file
    (dictionary-encoded: its labels matched to the spec's, whatever dictionary the file kept)."""
    import pyarrow as pa

    column = column.combine_chunks() if isinstance(column, pa.ChunkedArray) else column
    if not pa.types.is_dictionary(column.type):
        column = column.dictionary_encode()
    lookup = {label: i for i, label in enumerate(spec.pairs)}
    codes = np.array([lookup.get(label, -1) for label in column.dictionary.to_pylist()], dtype=np.int64)
    indices = column.indices.to_numpy(zero_copy_only=False)
    return codes[indices] if codes.size else np.full(indices.size, -1, dtype=np.int64)


def parquet_options(names) -> dict:
    """How a sweep table is written as Parquet: dictionary encoding for ``pair`` only (a few distinct
    values); pyarrow's default tries it on every column, which took 45 % of a write of the numbers
    (measured on 10^6 rows: 0.28 s against 0.15 s, for a file 9 % larger). Snappy, the most widely
    read codec, still compresses the per-pair constants. Values are handed to the encoder 65,536 at
    a time, not 1,024 (a fifth less CPU, measured on 10^5-row chunks of 37 columns). Statistics (min
    and max) for ``case`` only, so a reader finds a case's row group: on every column they took a
    quarter of the encoding (4 of 16 ms a 10^5-row chunk)."""
    return {"use_dictionary": [name for name in names if name == "pair"], "compression": "snappy",
            "write_batch_size": 65_536, "write_statistics": [name for name in names if name == "case"]}


def write_csv_rows(f, columns: dict) -> None:
    """The rows of ``columns`` as CSV text, :data:`CSV_BLOCK` rows at a time (the text of a whole
    table would take many times its memory)."""
    names = list(columns)
    n = int(np.size(columns[names[0]])) if names else 0
    for lo in range(0, n, CSV_BLOCK):
        hi = min(lo + CSV_BLOCK, n)
        cols = []
        for name in names:
            col = columns[name][lo:hi]
            if col.dtype == bool:
                cols.append(np.where(col, "True", "False").tolist())
            elif col.dtype.kind in "iu":
                cols.append(col.astype(str).tolist())
            elif col.dtype.kind == "f":
                cols.append([repr(x) for x in col.tolist()])
            else:
                cols.append([_csv_text(x) for x in col.tolist()])
        f.write("".join(",".join(row) + "\n" for row in zip(*cols)))


def read_table(path) -> dict:
    """Columns of a table written by :meth:`SweepResult.write` (CSV or Parquet), by their bare names: a CSV
    header's units (``v_approach [m/s]``) are taken off, and a header without them (a table written before
    they were added) reads the same. :func:`column_unit` gives each column's unit."""
    path = Path(path)
    if path.suffix.lower() == ".parquet":
        import pyarrow.parquet as pq

        import pyarrow as pa

        table = pq.read_table(path)
        out = {}
        for name in table.column_names:
            col = table.column(name)
            if pa.types.is_dictionary(col.type):
                col = col.cast(col.type.value_type)
            out[name] = (np.array(col.to_pylist(), dtype=object) if pa.types.is_string(col.type)
                         else col.to_numpy())
        return out
    import csv

    with open(path, encoding="utf-8", newline="") as f:
        rows = list(csv.reader(f))
    header, body = [_bare(cell) for cell in rows[0]], rows[1:]
    out = {}
    for j, name in enumerate(header):
        values = [r[j] for r in body]
        if name == "pair":
            out[name] = np.array(values, dtype=object)
        elif values and values[0] in ("True", "False"):
            out[name] = np.array([v == "True" for v in values])
        elif name == "case" or name in INTEGER_INPUTS:
            out[name] = np.array(values, dtype=np.int64)
        else:
            out[name] = np.array(values, dtype=float)
    return out


def _bare(cell: str) -> str:
    """A CSV header cell's column name: ``v_approach [m/s]`` is ``v_approach``, ``valid`` itself."""
    match = _HEADER.fullmatch(cell.strip())
    return match["name"] if match else cell.strip()
