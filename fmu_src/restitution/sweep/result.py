"""A sweep's result: its table in memory (:class:`SweepResult`) or on disk in its finished chunks
(:class:`DiskSweepResult`), how it ran, and writing it (CSV or Parquet, under a temporary name renamed
when whole, :func:`restitution.output_files.atomic_write`; from the parts' column chunks where they
are there) and drawing its plot. It sits above the table's columns (:mod:`~restitution.sweep.table`),
the parts (:mod:`~restitution.sweep.parts`) and the plots (:mod:`~restitution.sweep.plot`), which
import none of it."""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..output_files import atomic_write
from .parts import PartError, write_from_parts
from .plot import plot_cor_map
from .spec import SweepSpec
from .table import VALIDITY, arrow_table, csv_header, parquet_options, table_counts, write_csv_rows

__all__ = ["SweepResult", "DiskSweepResult"]


@dataclass
class SweepResult:
    """The table of a sweep (``columns``: name -> array, in :data:`COLUMNS` order) and how it ran.

    An input that holds one value over the whole sweep (a fixed parameter; with one pair, its materials
    and ``pair``) is a read-only view of that value, which takes no memory (``numpy.array(col)`` gives a
    writable copy); every other column is an array of its own."""

    columns: dict
    spec: SweepSpec
    backend: str
    scheduler: str
    n_workers: int
    elapsed: float  #: wall time of the evaluation (tasks submitted -> results gathered) [s]
    #: ``info``: ``code`` (fingerprints of the restitution code that ran), ``processes`` (how many
    #: worker processes took part), ``cpu_seconds`` (CPU time of the tasks: building the cases and
    #: evaluating them), ``fmu_code_files`` (FMU back end: the model.py that ran, the code the FMU ships).
    n_chunks: int
    info: dict = field(default_factory=dict)
    parts: Path | None = None  #: the directory of the finished chunks (``run_sweep(..., parts=DIR)``)
    chunk_counts: dict = field(default_factory=dict)  #: with ``parts``: chunk start -> its counts

    def __len__(self):
        return int(np.size(self.columns["case"]))

    def __getitem__(self, name):
        return self.columns[name]

    @property
    def cases_per_second(self) -> float:
        """Cases evaluated per second of :attr:`elapsed`: those reused from the parts (``resume``) not counted."""
        n = len(self) - self.info.get("reused", {}).get("cases", 0)
        return n / self.elapsed if self.elapsed > 0 else math.inf

    def counts(self) -> dict:
        """``cases``, ``ok`` (evaluated), ``inside`` (``valid``: inside the validated ranges), and per
        flag (``valid``, ``jgm.in_range``, ``zener.in_range``) the evaluated cases outside it."""
        return table_counts(self.columns)

    def summary(self) -> str:
        c = self.counts()
        text = (f"{len(self)} cases with the {self.backend} back end on {self.scheduler} "
                f"({self.n_workers} worker(s), {self.n_chunks} chunk(s)): {self.elapsed:.3g} s, "
                f"{self.cases_per_second:,.0f} cases/s")
        reused = self.info.get("reused")
        if reused:
            text += (f" over the {len(self) - reused['cases']:,} cases evaluated ({reused['chunks']:,} chunk(s) of "
                     f"{reused['cases']:,} cases reused from {reused['from']})")
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
        """Write the table: ``.parquet`` (needs pyarrow) or ``.csv``, under a temporary name, fsynced and
        renamed when whole (an interrupted or failed write leaves no half table, and the file that was
        there whole; :func:`restitution.output_files.atomic_write`). An I/O error raises
        :class:`~restitution.output_files.OutputWriteError` (one line naming ``path``)."""
        return atomic_write(Path(path), lambda tmp: self._write_to(tmp, Path(path).suffix), "table")

    def _write_to(self, path: Path, suffix: str) -> None:
        if suffix.lower() == ".parquet":
            if self.parts is not None and self.chunk_counts and self.parts.is_dir():
                try:  # the parts' column chunks, joined: nothing encoded again
                    write_from_parts(self, path, suffix)
                    return
                except PartError:  # the parts changed since (removed, another sweep's): the columns are here
                    pass
            self.to_parquet(path)
        else:
            self.to_csv(path)

    def to_csv(self, path) -> Path:
        path = Path(path)
        with open(path, "w", encoding="utf-8", newline="") as f:
            f.write(csv_header(self.columns))
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
        """The table as a pandas DataFrame, ``pair`` categorical."""
        import pandas as pd

        frame = pd.DataFrame(self.columns)
        if "pair" in frame:
            frame["pair"] = frame["pair"].astype("category")
        return frame

    def plot(self, path, **kwargs) -> Path:
        """The plot: a grid's COR map, the histogram of e of random draws around one point (see
        :func:`restitution.sweep.plot.plot_cor_map`)."""
        return plot_cor_map(self, path, **kwargs)


@dataclass
class DiskSweepResult(SweepResult):
    """A sweep whose table stays on disk, in its finished chunks (``run_sweep(..., in_memory=False)``):
    the counts are known, :meth:`write` joins the table from the parts; ``columns`` is empty."""

    def __len__(self):
        return sum(c["cases"] for c in self.chunk_counts.values())

    def __getitem__(self, name):
        raise KeyError(f"{name!r}: this sweep's table is on disk ({self.parts}), not in memory; write() it")

    def counts(self) -> dict:
        total = {k: 0 for k in ("cases", "ok", "inside", *VALIDITY)}
        for c in self.chunk_counts.values():
            for k in total:
                total[k] += c[k]
        return total

    def _write_to(self, path: Path, suffix: str) -> None:
        write_from_parts(self, path, suffix)

    def to_csv(self, path) -> Path:
        self._write_to(Path(path), ".csv")
        return Path(path)

    def to_parquet(self, path) -> Path:
        self._write_to(Path(path), ".parquet")
        return Path(path)

    def to_pandas(self):
        raise RuntimeError(f"this sweep's table is on disk ({self.parts}), too big for memory; write() it")

    def plot(self, path, **kwargs) -> Path:
        raise RuntimeError("no COR map for a sweep streamed to disk: its table does not fit in memory "
                           "(plot a smaller sweep, or from the written table)")
