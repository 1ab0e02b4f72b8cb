"""Run a sweep on Dask (a local cluster, or an existing scheduler) or serially, and keep the table.

    from restitution.sweep import SweepSpec, run_sweep
    spec = SweepSpec(pairs=["s2_tool_steel/al_6061"], grid={"v_approach": {"geomspace": [0.1, 10, 50]},
                                                              "t_over_d": {"geomspace": [0.1, 10, 40]}})
    result = run_sweep(spec)                             # LocalCluster sized to this machine
    result = run_sweep(spec, scheduler="tcp://10.0.0.5:8786", backend="fmu")   # an existing cluster
    result.write("map.parquet"); result.plot("map.png")

The work is cut into chunks of consecutive case indices; each Dask task builds its cases
from the spec (nothing large travels to the workers) and evaluates them with the back end.

With ``parts=DIR`` every finished chunk is written to DIR as it completes (one ``.npz`` file a
chunk, written under a temporary name and renamed, so a file there is always whole), beside a
``manifest.json`` naming the spec, back end, chunk size and columns. An interrupt (Ctrl-C) then
raises :class:`SweepInterrupted` carrying the table of the finished chunks, and
``resume=True`` on the same DIR evaluates only the chunks that are missing. With
``in_memory=False`` as well, nothing but counts stays in memory: the result's :meth:`~SweepResult.write`
streams the table from DIR chunk by chunk (for tables bigger than the memory budget, see :func:`plan_size`).
"""
from __future__ import annotations

import contextlib
import json
import logging
import math
import os
import shutil
import sys
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..cosim.interrupt import DeferredInterrupt
from .backends import Backend, FmuBackend, code_fingerprint, get_backend, release_fmus
from .spec import INPUT_NAMES, INTEGER_INPUTS, OUTPUT_NAMES, OUTPUTS as _OUTPUT_TYPES, T_OVER_D, SizeError, SweepSpec

__all__ = ["run_sweep", "SweepResult", "DiskSweepResult", "SweepInterrupted", "ResumeError", "open_client",
           "machine_workers", "compare_results", "COLUMNS", "VALIDITY", "table_bytes", "memory_budget", "check_memory", "plan_size", "SizePlan", "SizeError"]

#: Column order of a result table.
COLUMNS = ("case", "pair", *INPUT_NAMES, T_OVER_D, *OUTPUT_NAMES, "ok")
#: Validity columns every table keeps, whatever ``columns`` asks for (with ``case``, ``pair`` and ``ok``).
VALIDITY = ("valid", "jgm.in_range", "zener.in_range")
_ALWAYS = ("case", "pair", *VALIDITY, "ok")
#: Rows converted to text at a time when a table is written as CSV (bounds the memory it takes).
CSV_BLOCK = 65_536


class ResumeError(ValueError):
    """``resume=True`` on the finished chunks of another sweep (spec, back end, chunk size or columns)."""


class SweepInterrupted(KeyboardInterrupt):
    """An interrupted sweep: ``result`` holds the finished chunks, ``missing`` counts the cases left."""

    def __init__(self, result: "SweepResult", missing: int):
        super().__init__(f"sweep interrupted: {missing} of {missing + len(result)} cases missing")
        self.result = result
        self.missing = missing


# --- the size guard --------------------------------------------------------------------------------
def table_bytes(n_cases: int, columns=None) -> int:
    """Bytes the table of ``n_cases`` cases takes in memory (8 bytes a number, 1 a Boolean, a
    pointer for the pair label), for ``columns`` (None: all of :data:`COLUMNS`). Python ints."""
    names = COLUMNS if columns is None else [c for c in COLUMNS if c in columns]
    booleans = {"ok", *(name for name, _, vtype in _OUTPUT_TYPES if vtype == "Boolean")}
    per_case = sum(1 if name in booleans else 8 for name in names)
    return int(n_cases) * per_case


def output_bytes(n_cases: int, columns=None, suffix: str = ".csv", label: int = 40) -> int:
    """Upper estimate of the size of the written table: CSV text (a float's repr is at most 24
    characters, ``label`` characters for the pair) or Parquet (about the table in memory). Python ints."""
    if suffix.lower() == ".parquet":
        return table_bytes(n_cases, columns)
    names = COLUMNS if columns is None else [c for c in COLUMNS if c in columns]
    booleans = {"ok", *(name for name, _, vtype in _OUTPUT_TYPES if vtype == "Boolean")}
    per_case = sum(6 if name in booleans else label + 1 if name == "pair" else 25 for name in names)
    return int(n_cases) * per_case


def memory_budget(fraction: float = 0.5) -> int:
    """Default memory budget of a sweep table [bytes]: ``fraction`` of the memory available now
    (MemAvailable on Linux, else of the physical memory)."""
    available = None
    with contextlib.suppress(OSError, ValueError):
        with open("/proc/meminfo", encoding="ascii") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    available = int(line.split()[1]) * 1024
    if available is None:
        try:
            available = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
        except (ValueError, OSError, AttributeError):
            available = 4 * 2**30
    return int(available * fraction)


@dataclass
class SizePlan:
    """Where a sweep's table goes: in memory (``stream`` false) or streamed to disk chunk by chunk."""

    n_cases: int
    memory: int  #: bytes the table(s) take in memory
    budget: int  #: the memory budget [bytes]
    stream: bool = False  #: over the budget, but fits on disk: kept on disk, never gathered
    disk: int = 0  #: bytes needed on disk when streaming (finished chunks + the written table)
    disk_free: int = 0  #: bytes free where the table is written

    def describe(self) -> str:
        text = f"the table would take {_bytes(self.memory)} in memory"
        if not self.stream:
            text += f", within the memory budget of {_bytes(self.budget)}"
        else:
            text += (f", over the memory budget of {_bytes(self.budget)}: it is streamed to disk chunk by chunk "
                     f"(needs {_bytes(self.disk)} on disk, {_bytes(self.disk_free)} free) and never gathered")
        return text


def _check_case_numbers(spec: SweepSpec) -> None:
    """Case numbers are 64-bit integers in the table: :class:`SizeError` for 2**63 cases or more."""
    if spec.n_cases >= 2 ** 63:
        raise SizeError(f"{spec.n_cases:,} cases: case numbers are 64-bit integers, at most "
                        f"{2 ** 63 - 1:,} cases a sweep")


def check_memory(spec: SweepSpec, columns=None, budget: int | None = None, backends: int = 1) -> int:
    """Bytes the table(s) will take; :class:`SizeError` with the numbers when above ``budget``
    (default :func:`memory_budget`) or when an axis is too long to build. Called before any work."""
    spec.check_axes()
    return plan_size(spec, columns, budget, backends=backends).memory


def plan_size(spec: SweepSpec, columns=None, budget: int | None = None, backends: int = 1, out=None,
              parts=None) -> SizePlan:
    """The size guard, from the axis sizes alone (nothing is built): a :class:`SizePlan`, or
    :class:`SizeError` with the numbers. A table over the memory budget (default
    :func:`memory_budget`) is streamed to disk when ``out`` (the table's path) is given, one back
    end runs and the finished chunks plus the written table fit in the free space there."""
    _check_case_numbers(spec)
    need = backends * table_bytes(spec.n_cases, columns)
    budget = memory_budget() if budget is None else int(budget)
    plan = SizePlan(spec.n_cases, need, budget)
    if need <= budget:
        return plan
    refused = (f"the table of {spec.n_cases:,} cases would take {_bytes(need)}, over the memory budget "
               f"of {_bytes(budget)}")
    advice = "sweep fewer cases, keep fewer --columns, or raise --memory-budget"
    if out is None:
        raise SizeError(f"{refused}: {advice}")
    if backends > 1:
        raise SizeError(f"{refused}; --backend both compares the two tables in memory: {advice}, "
                        f"or run each back end on its own")
    out = Path(out)
    where = next((d for d in (out.parent.resolve(), *out.parent.resolve().parents) if d.exists()), Path("/"))
    free = shutil.disk_usage(where).free
    disk = table_bytes(spec.n_cases, columns) + output_bytes(
        spec.n_cases, columns, out.suffix, label=max([len(p) for p in spec.pairs] + [0]))
    if parts is not None and Path(parts).exists():  # resuming: what is there already counts as free
        free += sum(f.stat().st_size for f in Path(parts).rglob("*") if f.is_file())
    if disk > free:
        raise SizeError(f"{refused}, and streamed to disk it would need {_bytes(disk)} in {where} "
                        f"({_bytes(free)} free): {advice}")
    plan.stream, plan.disk, plan.disk_free = True, disk, free
    return plan


def _bytes(n: int) -> str:
    for unit, size in (("TiB", 2**40), ("GiB", 2**30), ("MiB", 2**20), ("KiB", 2**10)):
        if n >= size:
            return f"{n / size:,.3g} {unit} ({n:,} bytes)"
    return f"{n} bytes"


def machine_workers() -> int:
    """Worker processes for a local cluster: the cores this process may use."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # not Linux
        return max(1, os.cpu_count() or 1)


@contextlib.contextmanager
def open_client(scheduler=None, n_workers: int | None = None, threads_per_worker: int = 1, **cluster_kwargs):
    """A ``distributed.Client`` for a sweep, closed (with any cluster it started) on exit.

    ``scheduler``: a ``Client`` (used as is, left open), a scheduler address
    (``"tcp://host:8786"``), or None / ``"local"``: the scheduler named by Dask's config
    (``DASK_SCHEDULER_ADDRESS``) if set, else a new ``LocalCluster`` of ``n_workers``
    single-threaded processes (default: one per core).
    """
    from distributed import Client, LocalCluster

    if isinstance(scheduler, Client):
        yield scheduler
        return
    if scheduler in (None, "local"):
        import dask

        address = dask.config.get("scheduler-address", None) if scheduler is None else None
        if address:
            scheduler = address
    if scheduler not in (None, "local"):
        with Client(scheduler) as client:
            yield client
        return
    kwargs = dict(n_workers=n_workers or machine_workers(), threads_per_worker=threads_per_worker,
                  processes=True, dashboard_address=None, silence_logs=logging.ERROR)
    kwargs.update(cluster_kwargs)
    # the workers start with this process's sys.path, and ignoring Ctrl-C (see _workers_ignore_sigint)
    with _without_fmu_resources_on_sys_path(), _workers_ignore_sigint():
        cluster = LocalCluster(**kwargs)
    with cluster, Client(cluster) as client:
        yield client


@contextlib.contextmanager
def _workers_ignore_sigint():
    """SIGINT ignored while a LocalCluster spawns its worker processes, which keep that disposition.

    Ctrl-C in a terminal reaches every process of the foreground group: the workers' event loops
    would die with a KeyboardInterrupt traceback each, and an FMU back end's worker would take it
    inside an FMU call (fmi2Fatal). The client process alone takes Ctrl-C: it cancels the tasks,
    keeps the finished chunks and closes the cluster, which stops the workers. A Ctrl-C during
    these start-up seconds is ignored (press it again once the sweep runs)."""
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


@contextlib.contextmanager
def _without_fmu_resources_on_sys_path():
    """sys.path minus the resources/ directories of pythonfmu FMUs loaded in this process.

    pythonfmu prepends an FMU's resources/ to sys.path when it instantiates it; worker processes
    started afterwards would inherit that entry and import the FMU's physics-only copy of
    ``restitution`` (no ``restitution.sweep``) instead of this one, and die.
    """
    import sys

    saved = list(sys.path)
    sys.path[:] = [p for p in saved if not (p and os.path.isfile(os.path.join(p, "slavemodule.txt")))]
    try:
        yield
    finally:
        sys.path[:] = saved


def _run_chunk(start: int, stop: int, spec: SweepSpec, backend: Backend, payload=None, keep=None):
    cpu = time.thread_time()
    cases = spec.cases(start, stop)
    outputs, info = backend.evaluate(cases, payload, keep)
    info["cpu"] = time.thread_time() - cpu
    cases.update(outputs)
    if keep is not None:
        cases = {k: v for k, v in cases.items() if k in keep}
    info["counts"] = _counts(cases)
    return cases, info


def _counts(columns: dict) -> dict:
    """Cases, evaluated cases (``ok``), cases inside the validated ranges (``valid``) and evaluated
    cases outside each range (``valid``, ``jgm.in_range``, ``zener.in_range`` false), as ints."""
    n = int(np.size(columns["case"]))
    ok = np.asarray(columns["ok"], dtype=bool) if "ok" in columns else np.ones(n, dtype=bool)
    counts = {"cases": n, "ok": int(np.count_nonzero(ok)),
              "inside": int(np.count_nonzero(columns["valid"])) if "valid" in columns else n}
    for flag in VALIDITY:
        counts[flag] = int(np.count_nonzero(ok & ~np.asarray(columns[flag], dtype=bool))) if flag in columns else 0
    return counts


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
        return _counts(self.columns)

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
        return _write_atomic(Path(path), lambda tmp: self._write_to(tmp, Path(path).suffix))

    def _write_to(self, path: Path, suffix: str) -> None:
        if suffix.lower() == ".parquet":
            self.to_parquet(path)
        else:
            self.to_csv(path)

    def to_csv(self, path) -> Path:
        path = Path(path)
        with open(path, "w", encoding="utf-8", newline="") as f:
            f.write(",".join(self.columns) + "\n")
            _write_csv_rows(f, self.columns)
        return path

    def to_parquet(self, path) -> Path:
        try:
            import pyarrow as pa
            import pyarrow.parquet as pq
        except ModuleNotFoundError:
            raise RuntimeError("writing Parquet needs pyarrow (pip install pyarrow); or write .csv") from None
        path = Path(path)
        table = pa.table({name: (col.tolist() if col.dtype == object else col)
                          for name, col in self.columns.items()})
        pq.write_table(table, path)
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


def _write_csv_rows(f, columns: dict) -> None:
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


def _write_atomic(path: Path, write) -> Path:
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


@dataclass
class DiskSweepResult(SweepResult):
    """A sweep whose table stays on disk, in its finished chunks (``run_sweep(..., in_memory=False)``):
    the counts are known, :meth:`write` streams the table chunk by chunk; ``columns`` is empty."""

    parts: Path | None = None  #: the directory of the finished chunks
    chunk_counts: dict = field(default_factory=dict)  #: chunk start -> counts

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
        store = _PartStore(self.parts)
        keep = self.info.get("keep")
        starts = sorted(self.chunk_counts)
        if suffix.lower() == ".parquet":
            import pyarrow as pa
            import pyarrow.parquet as pq

            writer = None
            try:
                for a in starts:
                    cols = _assemble(self.spec, [store.read(a)[0]], keep)
                    table = pa.table({k: (v.tolist() if v.dtype == object else v) for k, v in cols.items()})
                    if writer is None:
                        writer = pq.ParquetWriter(path, table.schema)
                    writer.write_table(table)
                if writer is None:  # no chunk finished: an empty table with the columns
                    cols = _assemble(self.spec, [], keep)
                    pq.write_table(pa.table({k: v.tolist() for k, v in cols.items()}), path)
            finally:
                if writer is not None:
                    writer.close()
            return
        names = [c for c in COLUMNS if keep is None or c in keep]
        with open(path, "w", encoding="utf-8", newline="") as f:
            f.write(",".join(names) + "\n")
            for a in starts:
                _write_csv_rows(f, _assemble(self.spec, [store.read(a)[0]], keep))

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


def compare_results(a, b, names=None) -> dict:
    """Largest difference per output between two results (or column dicts) of the same spec.

    Reals: max |a - b| / max(1, |b|) over cases where both are finite (NaN and inf must match
    exactly, else the difference is inf); Booleans: number of cases that differ. ``names``:
    default, every output both have.
    """
    ca = a.columns if isinstance(a, SweepResult) else a
    cb = b.columns if isinstance(b, SweepResult) else b
    if not np.array_equal(ca["case"], cb["case"]):
        raise ValueError("the two results cover different cases")
    out = {}
    if names is None:
        names = [n for n in (*OUTPUT_NAMES, "ok") if n in ca and n in cb]
    for name in names:
        x, y = np.asarray(ca[name]), np.asarray(cb[name])
        if x.dtype == bool or y.dtype == bool:
            out[name] = int(np.count_nonzero(x.astype(bool) != y.astype(bool)))
            continue
        finite = np.isfinite(x) & np.isfinite(y)
        same_special = (np.isnan(x) & np.isnan(y)) | (x == y)
        if not np.all(finite | same_special):
            out[name] = math.inf
            continue
        diff = np.abs(x[finite] - y[finite]) / np.maximum(1.0, np.abs(y[finite]))
        out[name] = float(diff.max()) if diff.size else 0.0
    return out


def _chunks(n: int, chunk_size: int):
    return [(s, min(s + chunk_size, n)) for s in range(0, n, chunk_size)]


def _assemble(spec: SweepSpec, parts, keep) -> dict:
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


def _keep(columns):
    if columns is None:
        return None
    unknown = set(columns) - set(COLUMNS)
    if unknown:
        raise ValueError(f"unknown column(s) {sorted(unknown)}; the table has {', '.join(COLUMNS)}")
    return frozenset((*_ALWAYS, *columns))  # validity travels with every row


def run_sweep(spec: SweepSpec | dict, backend: str | Backend = "package", *, fmu=None, scheduler=None,
              n_workers: int | None = None, chunk_size: int | None = None, progress: bool = False,
              columns=None, release: bool = True, parts=None, resume: bool = False,
              in_memory: bool = True) -> SweepResult:
    """Evaluate every case of ``spec`` and return the table.

    ``backend``: "package" (vectorized :func:`restitution.impact`) or "fmu" (the FMU at ``fmu``,
    default dist/SpherePlateImpact.fmu). ``scheduler``: None (Dask's configured scheduler
    address, else a LocalCluster of ``n_workers`` processes, default one per core),
    "local" (always a new LocalCluster), a scheduler address, a ``distributed.Client``, or
    "serial" (no Dask: one loop in this process, for reference and debugging).
    ``chunk_size``: cases per task (default: the back end's, at most a quarter of each worker's
    share so the work spreads and progress moves). ``progress``: a progress line on stderr
    (redrawn in a terminal; elsewhere only the final state). ``columns``: keep only these
    columns (besides ``case``, ``pair``, ``ok`` and the validity flags, which every table has), for
    sweeps whose full table would be too big to gather. ``release=False`` keeps the FMU instances
    loaded in the workers for the next sweep (free them with ``client.run(release_fmus)``).
    ``parts``: directory where each finished chunk is written as it completes; ``resume=True``
    keeps the chunks already there (same spec, back end, chunk size and columns) and evaluates
    only the missing ones. ``in_memory=False`` (needs ``parts``): the chunks are not gathered, a
    :class:`DiskSweepResult` streams the table from ``parts`` when written. An interrupt raises
    :class:`SweepInterrupted` with the finished chunks' table.
    """
    if isinstance(spec, dict):
        spec = SweepSpec.from_dict(spec)
    if not in_memory and parts is None:
        raise ValueError("in_memory=False keeps the table on disk: give parts=DIR")
    for name, value in (("chunk_size", chunk_size), ("n_workers", n_workers)):
        if value is not None and (isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1):
            raise ValueError(f"{name} = {value!r}: expected an integer >= 1")
    spec.check_axes()
    _check_case_numbers(spec)
    backend = get_backend(backend, fmu)
    n = spec.n_cases
    keep = _keep(columns)
    store = None if parts is None else _PartStore(Path(parts))
    run = _Run(spec, backend, keep, store, in_memory)

    if scheduler == "serial":
        chunk_size = _chunk_size(store, resume, chunk_size or backend.default_chunk)
        chunks = _chunks(n, chunk_size)
        run.open(chunk_size, resume, len(chunks), "this process (serial)", 1)
        payload = backend.local_payload() if isinstance(backend, FmuBackend) else backend.payload()
        bar = _Progress(len(chunks), progress, "serial")
        bar.update(len(run.done))
        # an FMU in this process: Ctrl-C is taken between two FMU calls, never inside one
        deferred = DeferredInterrupt() if isinstance(backend, FmuBackend) else contextlib.nullcontext()
        try:
            with deferred, _fmu_interrupt_check(deferred):
                for a, b in chunks:
                    if a in run.done:
                        continue
                    run.finished(a, b, _run_chunk(a, b, spec, backend, payload, keep))
                    bar.update(len(run.done))
                    if isinstance(deferred, DeferredInterrupt):
                        deferred.check()
        except KeyboardInterrupt:
            bar.close(len(run.done))
            raise run.interrupted() from None
        finally:
            if isinstance(backend, FmuBackend) and release:
                release_fmus()
        bar.close(len(run.done))
        return run.result()

    with open_client(scheduler, n_workers) as client:
        workers = _count_workers(client)
        if chunk_size is None:
            chunk_size = max(1, min(backend.default_chunk, math.ceil(n / (4 * workers))))
        chunk_size = _chunk_size(store, resume, chunk_size)
        chunks = _chunks(n, chunk_size)
        run.open(chunk_size, resume, len(chunks), _describe_client(client, scheduler), workers)
        todo = [(a, b) for a, b in chunks if a not in run.done]
        bar = _Progress(len(chunks), progress, "dask")
        bar.update(len(run.done))
        futures = []
        payload = None
        try:
            payload = backend.payload()
            if payload is not None and todo:
                payload = client.scatter([payload], broadcast=True, hash=False)[0]
            from distributed import as_completed

            futures = client.map(_run_chunk, [a for a, _ in todo], [b for _, b in todo],
                                 spec=spec, backend=backend, payload=payload, keep=keep, pure=False)
            bounds = {f.key: ab for f, ab in zip(futures, todo)}
            for future in as_completed(futures):
                a, b = bounds[future.key]
                run.finished(a, b, future.result())
                future.release()
                bar.update(len(run.done))
        except KeyboardInterrupt:
            bar.close(len(run.done))
            with contextlib.suppress(Exception):
                client.cancel(futures)
            raise run.interrupted() from None
        finally:
            with contextlib.suppress(Exception):
                client.cancel(futures)
            if isinstance(backend, FmuBackend) and release:
                with contextlib.suppress(Exception):
                    client.run(release_fmus)  # an instance still busy with a cancelled chunk is freed after it
            if hasattr(payload, "release"):
                with contextlib.suppress(Exception):
                    client.cancel([payload])
        bar.close(len(run.done))
        return run.result()


class _Run:
    """The finished chunks of one run: in memory (start -> (columns, info)), or on disk only
    (start -> (None, info)) when ``in_memory`` is false; written to ``store`` as they finish."""

    def __init__(self, spec, backend, keep, store, in_memory: bool):
        self.spec, self.backend, self.keep, self.store, self.in_memory = spec, backend, keep, store, in_memory
        self.done = {}

    def open(self, chunk_size, resume, n_chunks, where, workers):
        self.n_chunks, self.where, self.workers = n_chunks, where, workers
        if self.store is not None:
            self.done = self.store.open(self.spec, self.backend, chunk_size, self.keep, resume,
                                        load_columns=self.in_memory)
        self.t0 = time.perf_counter()

    def finished(self, a, b, part):
        if self.store is not None:
            self.store.write(a, b, part)
        self.done[a] = part if self.in_memory else (None, part[1])

    def result(self) -> SweepResult:
        elapsed = time.perf_counter() - self.t0
        results = [self.done[a] for a in sorted(self.done)]
        if self.in_memory:
            return _result(self.spec, self.backend, results, self.where, self.workers, elapsed, self.n_chunks,
                           self.keep)
        return _disk_result(self.spec, self.backend, self.done, self.where, self.workers, elapsed, self.n_chunks,
                            self.keep, self.store.path)

    def interrupted(self) -> "SweepInterrupted":
        result = self.result()
        return SweepInterrupted(result, self.spec.n_cases - len(result))


@contextlib.contextmanager
def _fmu_interrupt_check(deferred):
    """The FMU back end checks ``deferred`` between cases while it is in force (serial runs)."""
    from . import backends

    if not isinstance(deferred, DeferredInterrupt):
        yield
        return
    backends._INTERRUPT_CHECK = deferred.check
    try:
        yield
    finally:
        backends._INTERRUPT_CHECK = None


def _chunk_size(store, resume: bool, chunk_size: int) -> int:
    """The chunk size: a resumed run keeps the one its parts were cut with."""
    if store is not None and resume:
        manifest = store.manifest()
        if manifest is not None:
            return int(manifest["chunk_size"])
    return int(chunk_size)


class _PartStore:
    """Finished chunks of one sweep on disk: ``chunk-<start>-<stop>.npz`` and ``manifest.json``."""

    def __init__(self, path: Path):
        self.path = path

    def manifest(self):
        try:
            return json.loads((self.path / "manifest.json").read_text(encoding="utf-8"))
        except (OSError, ValueError):
            return None

    def open(self, spec, backend, chunk_size, keep, resume: bool, load_columns: bool = True) -> dict:
        """Chunks already finished (``resume``; start -> (columns, info), columns None unless
        ``load_columns``), after checking that they belong to this sweep; without ``resume``, an
        empty directory."""
        manifest = {"spec": spec.as_dict(), "backend": backend.name, "chunk_size": int(chunk_size),
                    "n_cases": int(spec.n_cases), "columns": None if keep is None else sorted(keep)}
        old = self.manifest() if resume else None
        if old is not None and old != json.loads(json.dumps(manifest)):
            raise ResumeError(f"--resume: the finished chunks in {self.path} belong to another sweep "
                             f"(spec, back end or columns differ); run without --resume to start over")
        if old is None and self.path.exists():
            shutil.rmtree(self.path)
        self.path.mkdir(parents=True, exist_ok=True)
        if old is None:
            self._write_text("manifest.json", json.dumps(manifest, indent=1))
        done = {}
        for file in sorted(self.path.glob("chunk-*.npz")):
            a = int(file.stem.split("-")[1])
            done[a] = self.read(a, file, load_columns)
        return done

    def _file(self, a: int) -> Path:
        return next(self.path.glob(f"chunk-{a:015d}-*.npz"))

    def read(self, a: int, file: Path | None = None, load_columns: bool = True):
        """(columns or None, info) of the chunk starting at case ``a``."""
        with np.load(file or self._file(a), allow_pickle=False) as z:
            info = json.loads(str(z["info"]))
            columns = None
            if load_columns or "counts" not in info:
                columns = {k[2:]: z[k] for k in z.files if k.startswith("c:")}
                info.setdefault("counts", _counts(columns))
        return (columns if load_columns else None), info

    def write(self, a: int, b: int, part) -> None:
        columns, info = part
        tmp = self.path / f".chunk-{a}-{b}.tmp.npz"
        np.savez(tmp, info=np.array(json.dumps(info, default=str)), **{f"c:{k}": v for k, v in columns.items()})
        os.replace(tmp, self.path / f"chunk-{a:015d}-{b:015d}.npz")

    def _write_text(self, name, text):
        tmp = self.path / f".{name}.tmp"
        tmp.write_text(text, encoding="utf-8")
        os.replace(tmp, self.path / name)

    def remove(self) -> None:
        shutil.rmtree(self.path, ignore_errors=True)


class _Progress:
    """Chunks done, on stderr: redrawn in a terminal once the run has taken a second; when
    redirected, nothing but the final state (``close``), always on a line of its own."""

    def __init__(self, total: int, enabled: bool, label: str):
        self.total, self.enabled, self.label = total, enabled, label
        self.tty = enabled and sys.stderr.isatty()
        self.t0 = time.perf_counter()
        self.drawn = False

    def update(self, done: int) -> None:
        if self.tty and time.perf_counter() - self.t0 >= 1.0:
            print(f"\r[{self.label}] {done}/{self.total} chunks", end="", file=sys.stderr, flush=True)
            self.drawn = True

    def close(self, done: int) -> None:
        if not self.enabled:
            return
        end = "\r" if self.drawn else ""
        sys.stdout.flush()  # what was printed before stays before, when both go to one file
        print(f"{end}[{self.label}] {done}/{self.total} chunks done in {time.perf_counter() - self.t0:.3g} s",
              file=sys.stderr, flush=True)


def _count_workers(client) -> int:
    try:
        info = client.scheduler_info(n_workers=-1)
    except TypeError:  # distributed before 2025.4 lists every worker anyway
        info = client.scheduler_info()
    return max(1, len(info["workers"]))


def _describe_client(client, scheduler) -> str:
    from distributed import LocalCluster

    if isinstance(getattr(client, "cluster", None), LocalCluster) and not isinstance(scheduler, str):
        return f"a LocalCluster ({client.scheduler.address})"
    return f"the Dask scheduler at {client.scheduler.address}"


def _info(backend, infos) -> dict:
    codes = sorted({i["code"] for i in infos})
    info = {"code": codes, "processes": len({i["pid"] for i in infos}),
            "cpu_seconds": float(sum(i["cpu"] for i in infos)), "client_code": code_fingerprint()}
    if "fmu_code_file" in (infos[0] if infos else {}):
        info["fmu_code_files"] = sorted({i["fmu_code_file"] for i in infos})
    if backend.name == "package" and codes and codes != [info["client_code"]]:
        warnings.warn(f"the workers ran restitution code {codes}, this process has {info['client_code']}: "
                      f"install the same restitution on the workers", RuntimeWarning, stacklevel=4)
    return info


def _disk_result(spec, backend, done, where, workers, elapsed, n_chunks, keep, parts) -> "DiskSweepResult":
    info = _info(backend, [done[a][1] for a in sorted(done)])
    info["keep"] = keep
    return DiskSweepResult(columns={}, spec=spec, backend=backend.describe(), scheduler=where, n_workers=workers,
                           elapsed=elapsed, n_chunks=n_chunks, info=info, parts=Path(parts),
                           chunk_counts={a: done[a][1]["counts"] for a in done})


def _result(spec, backend, results, where, workers, elapsed, n_chunks, keep) -> SweepResult:
    parts = [r[0] for r in results]
    info = _info(backend, [r[1] for r in results])
    return SweepResult(columns=_assemble(spec, parts, keep), spec=spec, backend=backend.describe(), scheduler=where,
                       n_workers=workers, elapsed=elapsed, n_chunks=n_chunks, info=info)
