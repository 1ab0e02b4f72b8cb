"""The benchmarks' one harness: the machine a figure was measured on, and the timing (variants
interleaved batch by batch, CPU time of this thread, medians and median ratios: ratios compare like with
like on a shared, noisy machine). Every benchmark in this folder describes its machine and times through
here."""
from __future__ import annotations

import os
import platform
import statistics
import subprocess
import time
from pathlib import Path


def cpu_name() -> str:
    """The CPU's model name (Linux's /proc/cpuinfo), else what the platform module knows."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.lower().startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def machine() -> dict:
    """The machine a run measured on: CPU, cores, platform, the versions that bear on the figures, the
    date and the load average at the start (a shared machine's load is part of every figure)."""
    versions = {"python": platform.python_version()}
    for module in ("numpy", "scipy", "fmpy", "pythonfmu"):
        try:
            versions[module] = __import__(module).__version__
        except Exception:  # noqa: BLE001 - reporting only: a missing or broken package is "?"
            versions[module] = "?"
    try:
        versions["gcc"] = subprocess.run(["gcc", "-dumpfullversion"], capture_output=True,
                                         text=True).stdout.strip() or "?"
    except OSError:
        versions["gcc"] = "?"
    line = ", ".join(f"{'Python' if k == 'python' else k} {v}" for k, v in versions.items() if v != "?")
    return {"cpu": cpu_name(), "cores": os.cpu_count(), "platform": platform.platform(), **versions,
            "versions": line, "date": time.strftime("%Y-%m-%d"), "load_start": os.getloadavg()[0]}


def machine_line() -> str:
    """The machine in one phrase for a page: architecture, CPU model, CPU count."""
    return ", ".join(x for x in (platform.machine(), cpu_name(), f"{os.cpu_count()} CPUs") if x)


def clock() -> float:
    return time.thread_time()


def settle_allocator() -> None:
    """Bring glibc's allocator to the state a long-running process is in before anything is timed.

    glibc maps every block over 128 KiB fresh (and page-faults it) until the first large mapped block
    is freed; it then raises that threshold to the block's size, up to 32 MiB, and serves such blocks
    from its heap. A process that has ever freed a big array (a sweep's table, a model call on 10^6
    cases) is in that state; without it a vectorized call on 10^5 cases measured 25 ns a case where it
    takes 7 (paper_fit), whatever the model did."""
    import numpy as np

    block = np.ones(2 << 20)  # 16 MiB: mapped, then freed
    del block


def interleaved(variants: dict, reps: int, batch_seconds: float) -> dict:
    """{name: [seconds per evaluation, one per batch]} for ``variants`` {name: run(n) -> evaluations}.

    ``run(n)`` performs n repetitions of its work and returns how many evaluations that was.
    Batch sizes are calibrated to ``batch_seconds``; the variants take turns batch by batch.
    """
    sizes = {}
    for name, run in variants.items():
        n = 1
        while True:
            t0 = clock()
            run(n)
            dt = clock() - t0
            if dt >= batch_seconds / 4 or n >= 1 << 20:
                break
            n *= 4
        sizes[name] = max(1, int(n * batch_seconds / max(dt, 1e-9)))
    out = {name: [] for name in variants}
    for _ in range(reps):
        for name, run in variants.items():
            t0 = clock()
            count = run(sizes[name])
            out[name].append((clock() - t0) / count)
    return out


def median(xs) -> float:
    return float(statistics.median(xs))


def median_ratio(num, den) -> float:
    """Median over batches of num/den (the batches were taken in turn)."""
    return median([a / b for a, b in zip(num, den)])


def timed(run, n):
    t0 = clock()
    count = run(n)
    return (clock() - t0) / count
