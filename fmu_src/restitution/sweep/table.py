"""A sweep's table: its columns, the result classes that hold it and write it (CSV or Parquet, under a
temporary name renamed when whole), and reading a written table back."""
from __future__ import annotations

import contextlib
import math
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .spec import INPUT_NAMES, INTEGER_INPUTS, OUTPUT_NAMES, OUTPUTS as _OUTPUT_TYPES, T_OVER_D, SweepSpec

__all__ = ["COLUMNS", "VALIDITY", "SweepResult", "read_table", "table_counts", "assemble", "keep_columns",
           "write_atomic", "write_csv_rows"]

#: Column order of a result table.
COLUMNS = ("case", "pair", *INPUT_NAMES, T_OVER_D, *OUTPUT_NAMES, "ok")


#: Validity columns every table keeps, whatever ``columns`` asks for (with ``case``, ``pair`` and ``ok``).
VALIDITY = ("valid", "jgm.in_range", "zener.in_range")


_ALWAYS = ("case", "pair", *VALIDITY, "ok")


#: Rows converted to text at a time when a table is written as CSV (bounds the memory it takes).
CSV_BLOCK = 65_536


def table_counts(columns: dict) -> dict:
    """Cases, evaluated cases (``ok``), cases inside the validated ranges (``valid``) and evaluated
    cases outside each range (``valid``, ``jgm.in_range``, ``zener.in_range`` false), as ints."""
    n = int(np.size(columns["case"]))
    ok = np.asarray(columns["ok"], dtype=bool) if "ok" in columns else np.ones(n, dtype=bool)
    counts = {"cases": n, "ok": int(np.count_nonzero(ok)),
              "inside": int(np.count_nonzero(columns["valid"])) if "valid" in columns else n}
    for flag in VALIDITY:
        counts[flag] = int(np.count_nonzero(ok & ~np.asarray(columns[flag], dtype=bool))) if flag in columns else 0
    return counts


def assemble(spec: SweepSpec, parts, keep) -> dict:
    """The table from the chunks' columns (consumed: each column of the chunks is freed once joined,
    so the peak is the table plus one column, not twice the table)."""
    names = [c for c in COLUMNS if keep is None or c in keep]
    if parts:
        columns = {name: np.concatenate([p.pop(name) for p in parts]) for name in names}
    else:
        booleans = {"ok", *(n for n, _f, t in _OUTPUT_TYPES if t == "Boolean")}
        columns = {name: np.empty(0, dtype=bool if name in booleans else np.int64 if name == "case" else float)
                   for name in names}
    labels = np.array(list(spec.pairs) + [""], dtype=object)
    columns["pair"] = labels[np.asarray(columns["pair"], dtype=np.int64)]
    for name in INTEGER_INPUTS:
        if name in columns:
            columns[name] = np.asarray(columns[name]).astype(np.int64)
    return columns


def keep_columns(columns):
    if columns is None:
        return None
    unknown = set(columns) - set(COLUMNS)
    if unknown:
        raise ValueError(f"unknown column(s) {sorted(unknown)}; the table has {', '.join(COLUMNS)}")
    return frozenset((*_ALWAYS, *columns))  # validity travels with every row


@dataclass
class SweepResult:
    """The table of a sweep (``columns``: name -> array, in :data:`COLUMNS` order) and how it ran."""

    columns: dict
    spec: SweepSpec
    backend: str
    scheduler: str
    n_workers: int
    elapsed: float  #: wall time of the evaluation (tasks submitted -> results gathered) [s]
    #: ``info``: ``code`` (fingerprints of the restitution code that ran), ``processes`` (how many
    #: worker processes took part), ``cpu_seconds`` (CPU time of the tasks: building the cases and
    #: evaluating them), ``fmu_code_files`` (FMU back end: the bundled model.py that ran).
    n_chunks: int
    info: dict = field(default_factory=dict)

    def __len__(self):
        return int(np.size(self.columns["case"]))

    def __getitem__(self, name):
        return self.columns[name]

    @property
    def cases_per_second(self) -> float:
        return len(self) / self.elapsed if self.elapsed > 0 else math.inf

    def counts(self) -> dict:
        """``cases``, ``ok`` (evaluated), ``inside`` (``valid``: inside the validated ranges), and per
        flag (``valid``, ``jgm.in_range``, ``zener.in_range``) the evaluated cases outside it."""
        return table_counts(self.columns)

    def summary(self) -> str:
        c = self.counts()
        text = (f"{len(self)} cases with the {self.backend} back end on {self.scheduler} "
                f"({self.n_workers} worker(s), {self.n_chunks} chunk(s)): {self.elapsed:.3g} s, "
                f"{self.cases_per_second:,.0f} cases/s")
        text += f"; {c['ok']} evaluated, {c['cases'] - c['ok']} with inputs out of range"
        text += (f"; {c['inside']} inside the models' validated ranges ({c['valid']} outside: "
                 f"{c['jgm.in_range']} beyond JGM's V* <= 1000, {c['zener.in_range']} beyond Zener's lambda <= 1.5)")
        return text

    def out_of_range(self) -> dict:
        """Evaluated cases (``ok``) outside the validated ranges, per flag (``valid``,
        ``jgm.in_range``, ``zener.in_range``)."""
        c = self.counts()
        return {flag: c[flag] for flag in VALIDITY}

    def warning(self) -> str | None:
        """A one-line warning when any evaluated case lies outside the validated ranges, else None."""
        counts = self.out_of_range()
        if not counts["valid"]:
            return None
        return (f"warning: {counts['valid']} of {len(self)} cases lie outside the models' validated ranges "
                f"(valid = False: {counts['jgm.in_range']} with V* > 1000, {counts['zener.in_range']} with "
                f"lambda > 1.5); their e is an extrapolation")

    # --- output ---
    def write(self, path) -> Path:
        """Write the table: ``.parquet`` (needs pyarrow) or ``.csv``, under a temporary name renamed
        when whole (an interrupted write leaves no half table)."""
        return write_atomic(Path(path), lambda tmp: self._write_to(tmp, Path(path).suffix))

    def _write_to(self, path: Path, suffix: str) -> None:
        if suffix.lower() == ".parquet":
            self.to_parquet(path)
        else:
            self.to_csv(path)

    def to_csv(self, path) -> Path:
        path = Path(path)
        with open(path, "w", encoding="utf-8", newline="") as f:
            f.write(",".join(self.columns) + "\n")
            write_csv_rows(f, self.columns)
        return path

    def to_parquet(self, path) -> Path:
        try:
            import pyarrow as pa
            import pyarrow.parquet as pq
        except ModuleNotFoundError:
            raise RuntimeError("writing Parquet needs pyarrow (pip install pyarrow); or write .csv") from None
        path = Path(path)
        pq.write_table(arrow_table(self.columns), path, **parquet_options(self.columns))
        return path

    def to_pandas(self):
        import pandas as pd

        return pd.DataFrame(self.columns)

    def plot(self, path, **kwargs) -> Path:
        """The COR map (see :func:`restitution.sweep.plot.plot_cor_map`)."""
        from .plot import plot_cor_map

        return plot_cor_map(self, path, **kwargs)


def _csv_text(x) -> str:
    text = str(x)
    return f'"{text}"' if ("," in text or '"' in text) else text


def arrow_table(columns: dict):
    """The table's columns as a pyarrow Table (text columns as strings)."""
    import pyarrow as pa

    return pa.table({name: (col.tolist() if col.dtype == object else col) for name, col in columns.items()})


def parquet_options(columns: dict) -> dict:
    """How a sweep table is written as Parquet: dictionary encoding for the text columns only (the
    material pair: a few distinct values). pyarrow's default tries it on every column, which took
    45 % of a write of the numbers (measured on 10^6 rows: 0.28 s against 0.15 s, for a file 9 %
    larger); snappy, the most widely read codec, still compresses the per-pair constants."""
    return {"use_dictionary": [name for name, col in columns.items() if col.dtype == object],
            "compression": "snappy"}


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


def write_atomic(path: Path, write) -> Path:
    """``write(tmp)`` to a temporary file beside ``path``, then renamed to ``path``."""
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.tmp{os.getpid()}")
    try:
        write(tmp)
        os.replace(tmp, path)
    finally:
        with contextlib.suppress(OSError):
            tmp.unlink()
    return path


def read_table(path) -> dict:
    """Columns of a table written by :meth:`SweepResult.write` (CSV or Parquet)."""
    path = Path(path)
    if path.suffix.lower() == ".parquet":
        import pyarrow.parquet as pq

        table = pq.read_table(path)
        return {name: np.asarray(table.column(name).to_pylist() if table.column(name).type == "string"
                                 else table.column(name).to_numpy()) for name in table.column_names}
    import csv

    with open(path, encoding="utf-8", newline="") as f:
        rows = list(csv.reader(f))
    header, body = rows[0], rows[1:]
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
