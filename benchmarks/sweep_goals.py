"""The sweep's cost goals, measured in one process (part of bench_sweep.py's run).

* sweep / model: a serial package sweep (cases built as arrays per chunk, evaluated, the whole table
  gathered) against :func:`restitution.impact` alone on the arrays the sweep hands it, CPU time of
  this thread, taken in turn, the least of ``repeats`` each;
* write / gather: writing the table as Parquet against the gather of a Dask sweep (measured by the
  caller), and beside it the in-process join of the chunks (``restitution.sweep.table.assemble``), the
  table's raw bytes written to a file and CSV, CPU time, best of ``repeats``;
* a streamed run: a big sweep on a LocalCluster, every chunk written to disk as it finishes: its rate
  and the peak memory of all its processes.

Ratios are the headline: both sides of each are measured in the same run on the same machine.
"""
from __future__ import annotations

import math
import tempfile
import time
from pathlib import Path

import numpy as np


def _best_cpu(fn, repeats: int) -> float:
    best = float("inf")
    for _ in range(repeats):
        t0 = time.thread_time()
        fn()
        best = min(best, time.thread_time() - t0)
    return best


def sweep_over_model(spec, repeats: int = 3) -> dict:
    """CPU seconds of this thread of a serial package sweep of ``spec`` (the whole table gathered in
    memory) and of impact() alone on the arrays the sweep hands it (the spec's case columns: the
    constants as one-value views, as :meth:`SweepSpec.cases` gives them), taken in turn ``repeats``
    times; the least of each."""
    from restitution.model import impact
    from restitution.sweep import run_sweep
    from restitution.sweep.backends import impact_groups

    result = run_sweep(spec, "package", scheduler="serial")
    cases = spec.cases()
    groups = list(impact_groups(cases, np.arange(spec.n_cases)))
    sweep_s = model_s = float("inf")
    for _ in range(repeats):  # interleaved: a drift of the machine's speed meets both sides
        sweep_s = min(sweep_s, _best_cpu(lambda: run_sweep(spec, "package", scheduler="serial"), 1))
        model_s = min(model_s, _best_cpu(lambda: [impact(**inputs, **options, validate=False)
                                                  for _sel, inputs, options in groups], 1))
    return {"cases": spec.n_cases, "sweep_s": sweep_s, "model_s": model_s, "ratio": sweep_s / model_s,
            "result": result}


def _chunks(result, n_chunks: int) -> list[dict]:
    """The table cut back into chunk columns as the workers return them (pair as its code)."""
    cols = result.columns
    code = {label: i for i, label in enumerate(result.spec.pairs)}
    pair = np.array([code.get(x, len(code)) for x in cols["pair"]], dtype=np.int64)
    bounds = np.linspace(0, len(pair), n_chunks + 1).astype(int)
    return [{name: (pair if name == "pair" else col)[a:b].copy() for name, col in cols.items()}
            for a, b in zip(bounds[:-1], bounds[1:])]


def _write_raw(columns: dict, path: Path) -> None:
    """The columns' bytes as they are in memory, one column after another: the least any file format
    of these numbers costs to write."""
    with open(path, "wb") as f:
        for col in columns.values():
            col.tofile(f)


def write_over_gather(result, n_chunks: int, repeats: int = 3) -> dict:
    """CPU seconds to gather ``result``'s table from ``n_chunks`` chunks, and to write it as Parquet,
    as CSV and as its raw bytes (the floor of any file format)."""
    from restitution.sweep.table import assemble

    gather_s = float("inf")
    for _ in range(repeats):
        parts = _chunks(result, n_chunks)  # assemble consumes them
        t0 = time.thread_time()
        assemble(result.spec, parts, None)
        gather_s = min(gather_s, time.thread_time() - t0)
    with tempfile.TemporaryDirectory(prefix="bench_sweep_write_") as tmp:
        numbers = dict(result.columns, pair=np.unique(result.columns["pair"], return_inverse=True)[1])
        raw_s = _best_cpu(lambda: _write_raw(numbers, Path(tmp) / "t.raw"), repeats)
        raw_mb = (Path(tmp) / "t.raw").stat().st_size / 1e6
        parquet_s = _best_cpu(lambda: result.write(Path(tmp) / "t.parquet"), repeats)
        parquet_mb = (Path(tmp) / "t.parquet").stat().st_size / 1e6
        csv_s = _best_cpu(lambda: result.write(Path(tmp) / "t.csv"), 1)
        csv_mb = (Path(tmp) / "t.csv").stat().st_size / 1e6
    return {"cases": len(result), "gather_s": gather_s, "raw_s": raw_s, "raw_mb": raw_mb, "parquet_s": parquet_s,
            "parquet_mb": parquet_mb, "csv_s": csv_s, "csv_mb": csv_mb}


def _evaluate_chunks(spec, bounds, barrier=None) -> float:
    """CPU seconds of this thread to build and evaluate the chunks ``bounds`` with the package back end
    (a Dask task's work without Dask), after one chunk of warm-up and, with ``barrier``, once every
    process taking part is ready."""
    from restitution.sweep.backends import PackageBackend

    backend = PackageBackend()
    backend.evaluate(spec.cases(*bounds[0]))
    if barrier is not None:
        barrier.wait()
    t0 = time.thread_time()
    for a, b in bounds:
        backend.evaluate(spec.cases(a, b))
    return time.thread_time() - t0


_BARRIER = None
_THREAD = None


def _set_barrier(barrier):
    global _BARRIER
    _BARRIER = barrier


def _evaluate_after_barrier(spec, bounds) -> float:
    from concurrent.futures import ThreadPoolExecutor

    global _THREAD
    # in one thread of its own for every run, as a Dask worker runs its tasks: glibc gives that thread
    # an arena that keeps its freed memory, while the main thread's heap is trimmed and faulted in
    # again (measured: 0.19 against 0.27 µs per case)
    if _THREAD is None:
        _THREAD = ThreadPoolExecutor(1)
    return _THREAD.submit(_evaluate_chunks, spec, bounds, _BARRIER).result()


def machine_scaling(spec, chunk: int = 100_000, n_chunks: int = 20, repeats: int = 3) -> dict:
    """What the machine allows a second worker: CPU per case of the package back end's chunks in one
    process alone, and in each of two processes running at once (no Dask, nothing gathered). Two busy
    cores share caches, memory bandwidth and, on many CPUs, a lower clock, so ``ratio`` (alone / two at
    once) is the ceiling of the sweep's CPU scaling on this machine."""
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    from restitution.sweep.cluster import _without_fmu_resources_on_sys_path

    starts = np.linspace(0, max(0, spec.n_cases - chunk), n_chunks).astype(int)  # across the sweep's cases
    bounds = [(int(a), int(min(a + chunk, spec.n_cases))) for a in starts]
    n = sum(b - a for a, b in bounds)
    ctx = multiprocessing.get_context("spawn")  # as Dask starts its workers
    cpu = {}
    for processes in (1, 2):
        # the children start with this process's sys.path less any pythonfmu FMU's resources/ (its
        # physics-only restitution would shadow this one), as open_client's workers do; a child that
        # dies makes the pool broken (an error here), where multiprocessing.Pool waited forever
        with _without_fmu_resources_on_sys_path(), ProcessPoolExecutor(
                processes, mp_context=ctx, initializer=_set_barrier, initargs=(ctx.Barrier(processes),)) as pool:
            runs = [sum(pool.map(_evaluate_after_barrier, [spec] * processes, [bounds] * processes)) / processes
                    for _ in range(repeats + 1)]
        cpu[processes] = min(runs[1:]) / n  # the first run warms the thread's arena, as a worker's first tasks do
    alone, both = cpu[1], cpu[2]
    return {"alone_us": alone * 1e6, "both_us": both * 1e6, "ratio": alone / both}


def goal_lines(model: dict, write: dict, cpu_eff: dict, task_cpu_us: float, streamed: list | None = None,
               dask_gather_us: float | None = None, ceiling: dict | None = None) -> list[str]:
    """The Markdown table of the goals. ``task_cpu_us``: CPU per case inside the tasks of a LocalCluster
    of 1 worker; ``dask_gather_us``: CPU per case of that run beyond its tasks (Dask's own work,
    moving the chunks to this process and joining them: the gather of a Dask sweep)."""
    model_us = model["model_s"] / model["cases"] * 1e6
    parquet_us = write["parquet_s"] / write["cases"] * 1e6
    rows = [
        ("sweep / model per case, serial (cases built, evaluated, whole table gathered)",
         model["ratio"], 2.0, "x", True),
        ("sweep / model per case, per Dask worker (CPU inside the tasks, LocalCluster of 1)",
         task_cpu_us / model_us, 2.0, "x", True),
        ("Parquet write / gather of the table from a LocalCluster of 1 worker (CPU beyond the tasks: "
         "moving the chunks here, Dask, joining them)", parquet_us / dask_gather_us if dask_gather_us else math.nan,
         1.5, "x", True),
        ("CPU per case, 1 worker / 2 workers (package back end)", cpu_eff["package"], 0.9, "%", False),
    ]
    lines = ["| goal | measured | target | met |", "|---|---:|---:|---|"]
    for text, value, target, kind, at_most in rows:
        met = value <= target if at_most else value >= target
        shown = f"{value:.2f}x" if kind == "x" else f"{value:.0%}"
        limit = f"<= {target:g}x" if kind == "x" else f">= {target:.0%}"
        lines.append(f"| {text} | {shown} | {limit} | {'yes' if met else '**no**'} |")
    lines += [""]
    if ceiling:
        lines.append(
            f"- What the machine allows a second worker: the package back end's chunks without Dask take "
            f"{ceiling['alone_us']:.3f} µs CPU per case in one process alone and {ceiling['both_us']:.3f} µs in each "
            f"of two processes running at once (shared caches, memory bandwidth, clock), a ceiling of "
            f"**{ceiling['ratio']:.0%}** for the CPU scaling above.")
    lines += [
        f"- Model alone: {model_us:.3f} µs CPU per case (`impact` on the arrays of {model['cases']:,} cases); "
        f"the serial sweep {model['sweep_s'] / model['cases'] * 1e6:.3f} µs.",
        f"- The {write['cases']:,}-row table, CPU seconds: joined from its chunks in this process (a serial "
        f"sweep's gather, a memory copy) {write['gather_s']:.3f} s; written as its raw bytes, column after "
        f"column (the floor of any file format) {write['raw_s']:.3f} s ({write['raw_mb']:.0f} MB); as Parquet {write['parquet_s']:.3f} s "
        f"({write['parquet_mb']:.0f} MB); as CSV {write['csv_s']:.2f} s ({write['csv_mb']:.0f} MB). Parquet is "
        f"{write['parquet_s'] / write['gather_s']:.1f}x the in-process join (not within 1.5x of a memory copy) and "
        f"{write['parquet_s'] / write['raw_s']:.1f}x the raw bytes: the difference is encoding the pages, their "
        f"statistics and snappy, for a typed file {write['parquet_mb'] / write['raw_mb']:.0%} the size that every "
        f"Parquet reader takes. CSV is "
        f"{write['csv_s'] / write['parquet_s']:.0f}x Parquet and stays for small tables and tools without Parquet.",
    ]
    if not streamed:
        lines.append("- The streamed runs were not part of this run (`--streamed-cases 0`, or too little free disk).")
    else:
        small, big = streamed[0], streamed[-1]
        lines.append(
            f"- Streamed run on a LocalCluster of 2 workers: {big['cases']:,} cases (the whole 37-column "
            f"table) in {big['wall_s']:.0f} s, **{big['rate']:,.0f} cases/s**, each of its {big['chunks']:,} "
            f"chunks written to disk (a Parquet part) when it finished and nothing gathered ({big['disk_gb']:.0f} GB on disk); "
            f"peak memory of this process and the workers together **{big['peak_gb']:.1f} GB**, against "
            f"{small['peak_gb']:.1f} GB for {small['cases']:,} cases in the same run. Interrupted, such a run "
            f"resumes from the chunks on disk (`--resume`).")
    return lines


class PeakMemory:
    """Peak resident memory of this process and its children (the Dask workers), sampled every
    ``interval`` seconds in a background thread while the block runs."""

    def __init__(self, interval: float = 0.1):
        self.interval = interval
        self.peak = 0

    def _sample(self) -> int:
        import psutil

        me = psutil.Process()
        total = me.memory_info().rss
        for child in me.children(recursive=True):
            try:
                total += child.memory_info().rss
            except psutil.Error:
                pass
        return total

    def __enter__(self):
        import threading

        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()
        return self

    def _run(self):
        while not self._stop.is_set():
            self.peak = max(self.peak, self._sample())
            self._stop.wait(self.interval)

    def __exit__(self, *exc):
        self._stop.set()
        self._thread.join()
        self.peak = max(self.peak, self._sample())


def streamed_run(spec, client, directory: Path) -> dict:
    """A sweep of ``spec`` on ``client``'s cluster streamed to ``directory`` (every finished chunk
    written to disk as it completes, nothing gathered): wall time, rate, peak memory of this
    process and the workers, and the size on disk."""
    from restitution.sweep import run_sweep

    parts = Path(directory) / "parts"
    with PeakMemory() as memory:
        t0 = time.perf_counter()
        result = run_sweep(spec, "package", scheduler=client, parts=parts, in_memory=False)
        wall = time.perf_counter() - t0
    disk = sum(p.stat().st_size for p in parts.rglob("*") if p.is_file())
    return {"cases": spec.n_cases, "wall_s": wall, "rate": spec.n_cases / wall, "peak_gb": memory.peak / 1e9,
            "disk_gb": disk / 1e9, "chunks": result.n_chunks}
