#!/usr/bin/env python
"""What ``restitution cor`` costs as a whole command, beside the interpreter alone.

    .venv/bin/python benchmarks/bench_cor_startup.py [--reps N] [--write]

Runs, in turn, ``python -c pass`` and ``python -m restitution cor`` on the docs' example (a chrome-steel
ball on an Al 6061 plate), each a fresh process, and gives the median wall time of each over ``--reps``
rounds (wall time: a command's start is what a user waits for, imports and all; the rounds interleave
the two so that a load on a shared machine weighs on both alike), their difference (what the command
adds to the interpreter) and the modules of the package the command loads. The goal: the whole command
in at most 0.3 s on 2 cores. ``--write`` puts the result into docs/performance.md.
"""
from __future__ import annotations

import argparse
import os
import platform
import subprocess
import sys
import time
from pathlib import Path

from accuracy_bench.docs_block import replace_block  # beside this script: on sys.path when it runs
from harness import cpu_name, median

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "performance.md"
BEGIN, END = "<!-- bench_cor_startup:begin -->", "<!-- bench_cor_startup:end -->"
#: The whole command's wall time, the goal [s].
GOAL = 0.3
COR = ["-m", "restitution", "cor", "--sphere", "chrome_steel", "--d", "6.35 mm", "--plate", "al_6061",
       "--t", "3.18 mm", "--v", "2.3 m/s"]
#: The modules of the package a command loaded, printed by the child at its exit.
_COUNT = ("import atexit, sys\n"
          "atexit.register(lambda: sys.stderr.write(' '.join(m for m in sys.modules if m.split('.')[0] == "
          "'restitution')))\n"
          "import runpy\nsys.argv = ['restitution', *sys.argv[1:]]\nrunpy.run_module('restitution', run_name='__main__')")


def _env() -> dict:
    """The children's environment: the package's sources first, and bytecode caches written and read as
    for a user (an inherited PYTHONDONTWRITEBYTECODE made every run compile the package's modules again)."""
    env = {key: value for key, value in os.environ.items() if key != "PYTHONDONTWRITEBYTECODE"}
    return env | {"PYTHONPATH": os.pathsep.join([str(ROOT / "fmu_src"), os.environ.get("PYTHONPATH", "")])}


def wall(args: list[str]) -> float:
    """Seconds from starting ``python ARGS`` to its exit (its output discarded; a failure stops the run)."""
    started = time.perf_counter()
    subprocess.run([sys.executable, *args], stdout=subprocess.DEVNULL, check=True, env=_env())
    return time.perf_counter() - started


def loaded_modules() -> list[str]:
    """The package's modules ``restitution cor`` loads."""
    done = subprocess.run([sys.executable, "-c", _COUNT, *COR[2:]], capture_output=True, text=True, check=True,
                          env=_env())
    return sorted(done.stderr.split())


def measure(reps: int) -> dict:
    times = {"pass": [], "cor": []}
    wall(COR)  # the first run writes the bytecode caches
    for _ in range(reps):
        times["pass"].append(wall(["-c", "pass"]))
        times["cor"].append(wall(COR))
    return {name: median(values) for name, values in times.items()} | {"spread": (min(times["cor"]), max(times["cor"]))}


def report(res: dict, modules: list[str], reps: int, elapsed: float) -> str:
    cor, bare = res["cor"], res["pass"]
    return "\n".join([
        f"bench_cor_startup.py on {time.strftime('%Y-%m-%d')}: {cpu_name()}, "
        f"{os.cpu_count()} cores (shared), Python {platform.python_version()}, load average "
        f"{os.getloadavg()[0]:.1f}; wall time of a fresh process, medians of {reps} interleaved rounds; {elapsed:.0f} s",
        "",
        f"python -c pass:          {bare:6.3f} s",
        f"restitution cor (docs):  {cor:6.3f} s  (goal <= {GOAL:g} s: {'met' if cor <= GOAL else 'NOT met'}; "
        f"spread {res['spread'][0]:.3f}-{res['spread'][1]:.3f} s)",
        f"what cor adds:           {cor - bare:6.3f} s",
        f"modules of the package it loads: {len(modules)} (goal < 25)",
    ])


def write_doc(block: str, path: Path = DOC) -> None:
    replace_block(path, BEGIN, END, block)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--reps", type=int, default=15, help="interleaved rounds (default 15)")
    parser.add_argument("--write", action="store_true", help=f"put the result into {DOC.relative_to(ROOT)}")
    args = parser.parse_args(argv)
    started = time.perf_counter()
    res = measure(args.reps)
    block = report(res, loaded_modules(), args.reps, time.perf_counter() - started)
    print(block)
    if args.write:
        write_doc(block)
    return 0


if __name__ == "__main__":
    sys.exit(main())
