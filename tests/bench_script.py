"""Run one of benchmarks/ in a process of its own, as a user would: the package from this
checkout's fmu_src/ first on PYTHONPATH. What the benchmark tests share; they assert what it prints, never
its timings."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
BENCHMARKS = ROOT / "benchmarks"
#: A number as the benchmarks print it (a regular expression): 0.123, 1e+04.
NUMBER = r"[0-9.]+(?:e[+-]?\d+)?"


def run_benchmark(name: str, *args: str, cwd: Path, timeout: float, env: dict | None = None):
    """``python benchmarks/<name> *args`` in ``cwd``, with ``env`` (default: this process's
    environment) and fmu_src/ ahead of its PYTHONPATH: the finished process, output captured as text."""
    env = dict(os.environ if env is None else env)
    env["PYTHONPATH"] = os.pathsep.join(p for p in (str(ROOT / "fmu_src"), env.get("PYTHONPATH")) if p)
    return subprocess.run([sys.executable, str(BENCHMARKS / name), *args], capture_output=True, text=True,
                          cwd=cwd, env=env, timeout=timeout)
