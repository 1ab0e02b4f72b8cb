"""The sweep's cost goals, measured in one process (part of bench_sweep.py's run).

* sweep / model: a serial package sweep (cases built as arrays per chunk, evaluated, the whole table
  gathered) against :func:`restitution.impact` alone on the same cases' arrays, CPU time of this
  thread, best of ``repeats``;
* write / gather: writing the table as Parquet (and as CSV) against gathering it, i.e. joining the
  chunks' columns into one table (``restitution.sweep.table.assemble``), CPU time, best of ``repeats``;
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
    """CPU seconds of a serial package sweep of ``spec`` and of impact() on its cases' arrays."""
    import restitution as r
    from restitution.model import PARAMETERS
    from restitution.quantities import si_only
    from restitution.sweep import run_sweep

    result = run_sweep(spec, "package", scheduler="serial")
    cols = result.columns
    v = np.asarray(cols["v_approach"], dtype=float)
    params = {key: np.asarray(cols[key.replace("_", ".", 1)], dtype=float) for key, _unit, _check in PARAMETERS}
    impact = si_only(r.impact)  # what the sweep calls: SI arrays, checked by the sweep
    sweep_s = _best_cpu(lambda: run_sweep(spec, "package", scheduler="serial"), repeats)
    model_s = _best_cpu(lambda: impact(v, **params, validate=False), repeats)
    return {"cases": len(v), "sweep_s": sweep_s, "model_s": model_s, "ratio": sweep_s / model_s, "result": result}


def _chunks(result, n_chunks: int) -> list[dict]:
    """The table cut back into chunk columns as the workers return them (pair as its code)."""
    cols = result.columns
    code = {label: i for i, label in enumerate(result.spec.pairs)}
    pair = np.array([code.get(x, len(code)) for x in cols["pair"]], dtype=np.int64)
    bounds = np.linspace(0, len(pair), n_chunks + 1).astype(int)
    return [{name: (pair if name == "pair" else col)[a:b].copy() for name, col in cols.items()}
            for a, b in zip(bounds[:-1], bounds[1:])]


def write_over_gather(result, n_chunks: int, repeats: int = 3) -> dict:
    """CPU seconds to gather ``result``'s table from ``n_chunks`` chunks, and to write it as Parquet
    and as CSV."""
    from restitution.sweep.table import assemble

    gather_s = float("inf")
    for _ in range(repeats):
        parts = _chunks(result, n_chunks)  # assemble consumes them
        t0 = time.thread_time()
        assemble(result.spec, parts, None)
        gather_s = min(gather_s, time.thread_time() - t0)
    with tempfile.TemporaryDirectory(prefix="bench_sweep_write_") as tmp:
        parquet_s = _best_cpu(lambda: result.write(Path(tmp) / "t.parquet"), repeats)
        parquet_mb = (Path(tmp) / "t.parquet").stat().st_size / 1e6
        csv_s = _best_cpu(lambda: result.write(Path(tmp) / "t.csv"), 1)
        csv_mb = (Path(tmp) / "t.csv").stat().st_size / 1e6
    return {"cases": len(result), "gather_s": gather_s, "parquet_s": parquet_s, "parquet_mb": parquet_mb,
            "csv_s": csv_s, "csv_mb": csv_mb}


def goal_lines(model: dict, write: dict, cpu_eff: dict, task_cpu_us: float, streamed: list | None = None,
               dask_gather_us: float | None = None) -> list[str]:
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
        ("Parquet write / joining the chunks in this process alone (the cheapest gather: a copy)",
         write["parquet_s"] / write["gather_s"], 1.5, "x", True),
        ("CPU per case, 1 worker / 2 workers (package back end)", cpu_eff["package"], 0.9, "%", False),
    ]
    lines = ["| goal | measured | target | met |", "|---|---:|---:|---|"]
    for text, value, target, kind, at_most in rows:
        met = value <= target if at_most else value >= target
        shown = f"{value:.2f}x" if kind == "x" else f"{value:.0%}"
        limit = f"<= {target:g}x" if kind == "x" else f">= {target:.0%}"
        lines.append(f"| {text} | {shown} | {limit} | {'yes' if met else '**no**'} |")
    lines += [
        "",
        f"- Model alone: {model_us:.3f} µs CPU per case (`impact` on the arrays of {model['cases']:,} cases); "
        f"the serial sweep {model['sweep_s'] / model['cases'] * 1e6:.3f} µs.",
        f"- Gathering the {write['cases']:,}-row table from its chunks: {write['gather_s']:.3f} s CPU; writing it "
        f"as Parquet {write['parquet_s']:.3f} s ({write['parquet_mb']:.0f} MB), as CSV {write['csv_s']:.2f} s "
        f"({write['csv_mb']:.0f} MB, {write['csv_s'] / write['gather_s']:.0f}x the gather): CSV stays available "
        f"for small tables and tools without Parquet.",
    ]
    if not streamed:
        lines.append("- The streamed runs were not part of this run (`--streamed-cases 0`, or too little free disk).")
    else:
        small, big = streamed[0], streamed[-1]
        lines.append(
            f"- Streamed run on a LocalCluster of 2 workers: {big['cases']:,} cases (the whole 37-column "
            f"table) in {big['wall_s']:.0f} s, **{big['rate']:,.0f} cases/s**, each of its {big['chunks']:,} "
            f"chunks written as Parquet when it finished and nothing gathered ({big['disk_gb']:.0f} GB on disk); "
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
    written as Parquet as it completes, nothing gathered): wall time, rate, peak memory of this
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
