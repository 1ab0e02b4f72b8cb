#!/usr/bin/env python
"""What the uncertainty tools of a sweep cost: a Monte Carlo with ``--summary``, and ``--sobol``.

    .venv/bin/python benchmarks/bench_uncertainty.py [--samples N] [--reps N] [--runs N]
        [--sobol-n N] [--quick]

Measured in one run, each ratio's two sides interleaved (A B A B ...), medians:

1. A Monte Carlo of ``--samples`` draws (default 10^6) on the start values of the FMU (no pair), three
   inputs scattered: plate.Sy = uniform_rel:0.15, plate.t = uniform_rel:0.1, v_approach = uniform:1:3;
   as a multiple of ``restitution.impact`` called on the same draws (goal <= 2x):

   (a) in this process, CPU time of this thread (``time.thread_time``): ``run_sweep(spec, "package",
       scheduler="serial", on_chunk=SweepStatistics(spec))`` and the statistics' ``summary()``, against
       ``restitution.impact`` on the sweep's own draws (taken from ``spec.cases()`` outside the timed
       region) with numpy's mean, std and percentiles of e;
   (b) whole processes, user + system CPU of the process and its children (``os.wait4``) and wall time:
       ``python -m restitution.sweep ... --scheduler serial --summary s.json --no-plot --out t.parquet``
       against a plain ``python -c`` that imports restitution, draws the same numbers with numpy (the
       sweep's blocks of 4096 draws, each generator seeded with (seed, block)) and calls ``impact`` once.
       Before the timed runs each side runs once and the two results are compared (same mean and
       percentiles of e). The command writes all 37 columns (a 139 MB table and its parts) and the
       statistics of every output, which the plain process does not: the price of the full table, printed
       without a goal;
   (c) the same with ``--columns e``: the command then keeps and describes e alone, the plain process's work;
   (d) against the numpy floor: a Monte Carlo of the speed alone (v_approach = uniform:0.2:5, the FMU's start
       values otherwise: one sphere on one plate), ``--columns e --summary``, the whole command, against a plain
       ``python -c`` that imports numpy and numpy_floor.py only, draws the same speeds, computes e and v_rebound
       by the numpy floor (its parameter terms once) and e's mean, std and percentiles (goal <= 1.5x, CPU).

2. ``--sobol`` with N = ``--sobol-n`` (default 4096) base samples over plate.t = uniform_rel:0.15 and
   v_approach = uniform:0.5:3 (N x 4 cases), the whole command (``--no-plot --summary``), serially and on a
   LocalCluster of 2 workers: wall time in all (goal <= 5 s), split into the model evaluation (the
   elapsed time the command prints for its sweep), the analysis (``SobolCollector.analyze()``, the bootstrap,
   timed in this process on the same design: thread CPU time, interleaved with ``run_sweep`` of the design
   serially in this process) and the rest (interpreter, imports, the cluster, writing the table and JSON).

No figure is judged here beyond printing it beside its goal; the machine is shared. ``--quick`` runs small
sizes (a test runs it). The full run takes about 2 minutes on a shared 2-core machine.
"""
from __future__ import annotations

from harness import cpu_name  # this folder: the benchmarks' harness

import argparse
import json
import os
import platform
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
for _p in (ROOT / "fmu_src", ROOT / "benchmarks"):
    if str(_p) not in sys.path:
        sys.path.insert(0, str(_p))

GOAL_MC = 2.0  #: sweep + statistics / impact + numpy statistics, at most
GOAL_SOBOL = 5.0  #: [s] wall time of the whole --sobol command, at most
MC_RANDOM = {"plate.Sy": "uniform_rel:0.15", "plate.t": "uniform_rel:0.1", "v_approach": "uniform:1:3"}
SOBOL_RANDOM = {"plate.t": "uniform_rel:0.15", "v_approach": "uniform:0.5:3"}
PERCENTILES = (2.5, 50.0, 97.5)

#: The plain process of 1(b): draws the sweep's numbers with numpy, one impact() call, numpy's statistics of
#: e, printed as JSON. Filled with the draws' description and the other inputs (the FMU's start values).
PLAIN = """\
import json, sys
import numpy as np
import restitution
N, SEED, BLOCK, DISTS, BASE, FIXED = {n}, {seed}, {block}, {dists!r}, {base!r}, {fixed!r}
draws = {{k: np.empty(N) for k in DISTS}}
for b in range(-(-N // BLOCK)):
    rng = np.random.default_rng([SEED, b])
    lo, hi = b * BLOCK, min(N, (b + 1) * BLOCK)
    for k, (lo_, hi_) in DISTS.items():
        draws[k][lo:hi] = rng.uniform(lo_, hi_, BLOCK)[:hi - lo]
kw = dict(FIXED)
for k, x in draws.items():
    kw[k] = x * BASE[k] if k in BASE else x
e = restitution.impact(**kw).e
json.dump({{"mean": float(e.mean()), "std": float(e.std(ddof=1)),
           "percentiles": np.percentile(e, {percentiles!r}).tolist()}}, sys.stdout)
"""


GOAL_FLOOR = 1.5  #: the --columns e command / the numpy floor's plain process, at most
FLOOR_RANDOM = {"v_approach": "uniform:0.2:5"}
#: The plain process of 1(d): the speeds the sweep draws, the numpy floor's e and v_rebound, e's statistics.
PLAIN_FLOOR = """\
import json, sys
import numpy as np
sys.path.insert(0, {here!r})
import numpy_floor
N, SEED, BLOCK, (LO, HI), PARAMS = {n}, {seed}, {block}, {bounds!r}, {params!r}
v = np.empty(N)
for b in range(-(-N // BLOCK)):
    lo, hi = b * BLOCK, min(N, (b + 1) * BLOCK)
    v[lo:hi] = np.random.default_rng([SEED, b]).uniform(LO, HI, BLOCK)[:hi - lo]
e, v_rebound = numpy_floor.e_and_rebound(v, numpy_floor.floor_terms(PARAMS))
json.dump({{"mean": float(e.mean()), "std": float(e.std(ddof=1)),
           "percentiles": np.percentile(e, {percentiles!r}).tolist()}}, sys.stdout)
"""


def mc_spec(samples: int):
    from restitution.sweep import SweepSpec

    return SweepSpec.from_dict({"random": dict(MC_RANDOM), "samples": samples})


def sobol_spec(n: int):
    from restitution.sweep.sobol import SobolSpec

    return SobolSpec.from_dict({"random": dict(SOBOL_RANDOM), "samples": n})


def impact_inputs(spec) -> tuple[dict, dict]:
    """(the impact() keywords that vary: arrays of the sweep's own draws, the others: scalars), from the
    spec's cases (outside any timed region)."""
    import numpy as np
    from restitution.sweep.spec import INPUTS

    cases = spec.cases()
    varying, fixed = {}, {}
    for name, key, vtype, _start in INPUTS:
        if vtype != "Real":
            continue  # the integer-coded options: their start values are impact()'s defaults
        column = np.asarray(cases[name], dtype=float)
        if name in spec.random:
            varying[key] = np.ascontiguousarray(column)
        else:
            fixed[key] = float(column[0])
    return varying, fixed


def _median(xs) -> float:
    return float(statistics.median(xs))


# --- 1(a): in this process -----------------------------------------------------------------------
def mc_in_process(samples: int, reps: int) -> dict:
    import numpy as np
    import restitution
    from harness import settle_allocator
    from restitution.sweep import run_sweep
    from restitution.sweep.statistics import SweepStatistics

    spec = mc_spec(samples)
    varying, fixed = impact_inputs(spec)
    split = {"run_sweep": [], "summary": []}

    def sweep():
        stats = SweepStatistics(spec)
        t0 = time.thread_time()
        run_sweep(spec, "package", scheduler="serial", on_chunk=stats)
        t1 = time.thread_time()
        summary = stats.summary()
        split["run_sweep"].append(t1 - t0)
        split["summary"].append(time.thread_time() - t1)
        return summary

    def plain():
        e = restitution.impact(**varying, **fixed).e
        return {"mean": float(e.mean()), "std": float(e.std(ddof=1)),
                "percentiles": np.percentile(e, PERCENTILES).tolist()}

    # the first of each (imports, first-call caches), and the two results compared: the same draws
    got, want = sweep()["outputs"]["e"], plain()
    agree = max(abs(got["mean"] / want["mean"] - 1), abs(got["std"] / want["std"] - 1),
                *(abs(got[f"p{p:g}"] / w - 1) for p, w in zip(PERCENTILES, want["percentiles"])))
    for v in split.values():
        v.clear()
    settle_allocator()
    times = {"sweep": [], "plain": []}
    for _ in range(reps):
        for name, fn in (("sweep", sweep), ("plain", plain)):
            t0 = time.thread_time()
            fn()
            times[name].append(time.thread_time() - t0)
    ratios = [a / b for a, b in zip(times["sweep"], times["plain"])]
    return {"sweep": _median(times["sweep"]), "plain": _median(times["plain"]), "ratio": _median(ratios),
            "spread": (min(ratios), max(ratios)), "run_sweep": _median(split["run_sweep"]),
            "summary": _median(split["summary"]), "agree": agree}


# --- whole processes -----------------------------------------------------------------------------
def _env() -> dict:
    path = os.environ.get("PYTHONPATH")
    return {**os.environ, "PYTHONPATH": str(ROOT / "fmu_src") + (os.pathsep + path if path else ""),
            "PYTHONUNBUFFERED": "1"}


def run_process(cmd: list, cwd: Path) -> dict:
    """Run ``cmd`` to its end: wall seconds, CPU seconds (user + system, the process and the children it
    waited for: the Dask workers of a LocalCluster), its stdout; raises if it failed."""
    with tempfile.TemporaryFile() as out, tempfile.TemporaryFile() as err:
        t0 = time.perf_counter()
        proc = subprocess.Popen(cmd, cwd=cwd, env=_env(), stdout=out, stderr=err, stdin=subprocess.DEVNULL)
        _pid, status, usage = os.wait4(proc.pid, 0)
        wall = time.perf_counter() - t0
        proc.returncode = os.waitstatus_to_exitcode(status)
        out.seek(0)
        err.seek(0)
        stdout, stderr = out.read().decode(), err.read().decode()
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(map(str, cmd))}: exit status {proc.returncode}\n{stderr[-2000:]}")
    return {"wall": wall, "cpu": usage.ru_utime + usage.ru_stime, "stdout": stdout}


def sweep_command(random: dict, samples: int, *extra) -> list:
    cmd = [sys.executable, "-m", "restitution.sweep"]
    for name, dist in random.items():
        cmd += ["--random", f"{name}={dist}"]
    return cmd + ["--samples", str(samples), "--no-plot", "--no-progress", *extra]


def plain_command(samples: int) -> list:
    """``python -c CODE``: :data:`PLAIN` for the Monte Carlo's draws (the relative ones on the FMU's start
    values, as the sweep has them without a pair)."""
    from restitution.sweep.spec import INPUTS, RANDOM_BLOCK, START

    spec = mc_spec(samples)
    _varying, fixed = impact_inputs(mc_spec(1))
    keys = {name: key for name, key, _t, _s in INPUTS}
    dists, base = {}, {}
    for name, (kind, args) in spec._dists.items():
        if kind == "uniform":
            dists[keys[name]] = (float(args[0]), float(args[1]))
        elif kind == "uniform_rel":
            dists[keys[name]] = (1.0 - float(args[0]), 1.0 + float(args[0]))
            base[keys[name]] = float(START[name])
        else:
            raise ValueError(f"{name}: the plain process draws uniform and uniform_rel only")
    code = PLAIN.format(n=samples, seed=spec.seed, block=RANDOM_BLOCK, dists=dists, base=base, fixed=fixed,
                        percentiles=PERCENTILES)
    return [sys.executable, "-c", code]


def mc_processes(samples: int, runs: int, work: Path, columns: str | None = None) -> dict:
    """The Monte Carlo command (keeping ``columns`` only, None: all) and the plain process, in turn."""
    keep = ["--columns", columns] if columns else []
    sweep = sweep_command(MC_RANDOM, samples, "--scheduler", "serial", "--summary", "s.json", *keep, "--out", "t.parquet")
    plain = plain_command(samples)
    # once each, untimed (the file caches), and the results compared: the same draws, the same statistics of e
    run_process(sweep, work)
    want = json.loads(run_process(plain, work)["stdout"])
    got = json.loads((work / "s.json").read_text())["outputs"]["e"]
    agree = max(abs(got["mean"] / want["mean"] - 1), abs(got["std"] / want["std"] - 1),
                *(abs(got[f"p{p:g}"] / w - 1) for p, w in zip(PERCENTILES, want["percentiles"])))
    res = {"sweep": [], "plain": []}
    for _ in range(runs):
        res["sweep"].append(run_process(sweep, work))
        res["plain"].append(run_process(plain, work))
    out = {"agree": agree, "runs": runs}
    for fig in ("cpu", "wall"):
        a, b = [r[fig] for r in res["sweep"]], [r[fig] for r in res["plain"]]
        out[fig] = {"sweep": _median(a), "plain": _median(b), "ratio": _median([x / y for x, y in zip(a, b)])}
    return out


def mc_floor_processes(samples: int, runs: int, work: Path) -> dict:
    """1(d): the Monte Carlo of the speed keeping e, and the numpy floor's plain process, in turn. ``agree``: the
    largest difference of e's mean and percentiles between the two, which differ by the paper's fit of Zener's
    COR (the floor's) against the exact solution (the command's): up to 0.0136 in e."""
    from restitution.sweep import SweepSpec
    from restitution.sweep.spec import RANDOM_BLOCK

    spec = SweepSpec.from_dict({"random": dict(FLOOR_RANDOM), "samples": samples})
    _varying, fixed = impact_inputs(SweepSpec.from_dict({"random": dict(FLOOR_RANDOM), "samples": 1}))
    params = {k: fixed[k] for k in ("sphere_E", "sphere_nu", "sphere_Sy", "sphere_rho", "sphere_d", "plate_E",
                                    "plate_nu", "plate_Sy", "plate_rho", "plate_t")}
    kind, args = spec._dists["v_approach"]
    plain = [sys.executable, "-c", PLAIN_FLOOR.format(here=str(Path(__file__).resolve().parent), n=samples,
                                                      seed=spec.seed, block=RANDOM_BLOCK, bounds=tuple(map(float, args)),
                                                      params=params, percentiles=PERCENTILES)]
    sweep = sweep_command(FLOOR_RANDOM, samples, "--scheduler", "serial", "--columns", "e", "--summary", "s.json",
                          "--out", "t.parquet")
    run_process(sweep, work)
    want = json.loads(run_process(plain, work)["stdout"])
    got = json.loads((work / "s.json").read_text())["outputs"]["e"]
    agree = max(abs(got["mean"] - want["mean"]), *(abs(got[f"p{p:g}"] - w) for p, w in zip(PERCENTILES, want["percentiles"])))
    res = {"sweep": [], "plain": []}
    for turn in range(runs):
        for side in (("sweep", "plain") if turn % 2 == 0 else ("plain", "sweep")):
            res[side].append(run_process(sweep if side == "sweep" else plain, work))
    out = {"agree": agree, "runs": runs}
    for fig in ("cpu", "wall"):
        a, b = [r[fig] for r in res["sweep"]], [r[fig] for r in res["plain"]]
        out[fig] = {"sweep": _median(a), "plain": _median(b), "ratio": _median([x / y for x, y in zip(a, b)])}
    return out


def sobol_processes(n: int, runs: int, work: Path) -> dict:
    """The whole --sobol command, serially and on a LocalCluster of 2 workers, in turn: wall and CPU
    time, and the model evaluation's elapsed time as the command prints it (medians)."""
    base = sweep_command(SOBOL_RANDOM, n, "--sobol", "--summary", "sobol.json", "--out", "sobol.parquet")
    variants = {"serial": base + ["--scheduler", "serial"],
                "cluster": base + ["--scheduler", "local", "--workers", "2"]}
    for cmd in variants.values():  # once each, untimed (file caches)
        run_process(cmd, work)
    res = {name: [] for name in variants}
    for _ in range(runs):
        for name, cmd in variants.items():
            res[name].append(run_process(cmd, work))
    out = {}
    for name, rs in res.items():
        evals = []
        for r in rs:
            m = re.search(r"^\d+ cases with the package back end .*?\): ([0-9.e+-]+) s,", r["stdout"], re.M)
            if m is None:
                raise RuntimeError(f"no evaluation time in the output of --sobol ({name}):\n{r['stdout'][:2000]}")
            evals.append(float(m.group(1)))
        out[name] = {"wall": _median([r["wall"] for r in rs]), "cpu": _median([r["cpu"] for r in rs]),
                     "evaluation": _median(evals), "walls": [r["wall"] for r in rs]}
    return out


def sobol_in_process(n: int, reps: int) -> dict:
    """Thread CPU seconds of the design's evaluation (run_sweep serially, the collector as on_chunk) and of
    SobolCollector.analyze() on it (the bootstrap), interleaved, medians."""
    from restitution.sweep import run_sweep
    from restitution.sweep.sobol import SobolCollector

    spec = sobol_spec(n)
    collector = SobolCollector(spec)

    def evaluate():
        run_sweep(spec, "package", scheduler="serial", on_chunk=collector)

    evaluate()
    collector.analyze()  # imports SALib
    times = {"evaluate": [], "analyze": []}
    for _ in range(reps):
        for name, fn in (("evaluate", evaluate), ("analyze", collector.analyze)):
            t0 = time.thread_time()
            fn()
            times[name].append(time.thread_time() - t0)
    return {name: _median(v) for name, v in times.items()} | {"cases": spec.n_cases}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--samples", type=int, default=1_000_000, help="draws of the Monte Carlo (default 10^6)")
    parser.add_argument("--reps", type=int, default=5, help="in-process repeats of each side (default 5)")
    parser.add_argument("--runs", type=int, default=5, help="whole-process runs of each side (default 5)")
    parser.add_argument("--sobol-n", type=int, default=4096, help="Sobol' base samples N, a power of 2 (default 4096)")
    parser.add_argument("--sobol-runs", type=int, default=3, help="runs of each --sobol command (default 3)")
    parser.add_argument("--quick", action="store_true", help="small sizes, one or two repeats (for a test)")
    args = parser.parse_args(argv)
    if args.quick:
        args.samples, args.reps, args.runs, args.sobol_n, args.sobol_runs = 20_000, 2, 1, 256, 1

    import numpy as np

    t_all = time.perf_counter()
    load = os.getloadavg()[0]
    print(f"bench_uncertainty.py on {time.strftime('%Y-%m-%d')}: {cpu_name()}, "
          f"{os.cpu_count()} cores (shared), Python {platform.python_version()}, numpy {np.__version__}, "
          f"load average {load:.1f}{' (--quick: small sizes, not the figures to quote)' if args.quick else ''}")
    n = args.samples
    mc = mc_in_process(n, args.reps)
    print(f"1(a) Monte Carlo, {n:,} draws, in process (thread CPU, median of {args.reps} interleaved): "
          f"sweep + statistics {mc['sweep']:.3f} s, impact + numpy statistics {mc['plain']:.3f} s: "
          f"{mc['ratio']:.2f}x (goal <= {GOAL_MC:g}x: {'met' if mc['ratio'] <= GOAL_MC else 'NOT met'}; "
          f"spread {mc['spread'][0]:.2f}-{mc['spread'][1]:.2f}x)")
    print(f"     of the sweep side: run_sweep with the on_chunk statistics {mc['run_sweep']:.3f} s, summary() "
          f"{mc['summary']:.3f} s; e's mean, std and percentiles agree to {mc['agree']:.1e}")
    with tempfile.TemporaryDirectory(prefix="bench_uncertainty_") as tmp:
        work = Path(tmp)
        pr = mc_processes(n, args.runs, work)
        c, w = pr["cpu"], pr["wall"]
        print(f"1(b) Monte Carlo, {n:,} draws, whole processes (CPU user + sys, median of {pr['runs']} interleaved): "
              f"sweep command {c['sweep']:.2f} s, plain impact process {c['plain']:.2f} s: {c['ratio']:.2f}x "
              f"(no goal: more work than the plain process, all 37 columns written and every output described; "
              f"1(c) is the same work)")
        print(f"     wall: sweep command {w['sweep']:.2f} s, plain impact process {w['plain']:.2f} s: "
              f"{w['ratio']:.2f}x; e's statistics agree to {pr['agree']:.1e}")
        pe = mc_processes(n, args.runs, work, columns="e")
        c, w = pe["cpu"], pe["wall"]
        print(f"1(c) the same with --columns e, the work of the plain process (e's table and statistics; CPU, median of "
              f"{pe['runs']} interleaved): sweep command {c['sweep']:.2f} s, plain impact process {c['plain']:.2f} s: "
              f"{c['ratio']:.2f}x (goal <= {GOAL_MC:g}x: {'met' if c['ratio'] <= GOAL_MC else 'NOT met'}); wall "
              f"{w['ratio']:.2f}x")
        pf = mc_floor_processes(n, args.runs, work)
        c, w = pf["cpu"], pf["wall"]
        print(f"1(d) Monte Carlo of the speed, {n:,} draws, --columns e --summary, whole command against the numpy "
              f"floor's plain process (CPU user + sys, median of {pf['runs']} interleaved; load average "
              f"{os.getloadavg()[0]:.1f}): sweep command {c['sweep']:.2f} s, numpy floor process {c['plain']:.2f} s: "
              f"{c['ratio']:.2f}x (goal <= {GOAL_FLOOR:g}x: {'met' if c['ratio'] <= GOAL_FLOOR else 'NOT met'}); "
              f"wall {w['sweep']:.2f} s / {w['plain']:.2f} s = {w['ratio']:.2f}x; e's mean and percentiles "
              f"within {pf['agree']:.1e} of the floor's (its paper fit of e_ze: up to 0.0136)")
        sp = sobol_in_process(args.sobol_n, args.reps)
        so = sobol_processes(args.sobol_n, args.sobol_runs, work)
    for name, label in (("serial", "--scheduler serial"), ("cluster", "LocalCluster of 2 workers")):
        s = so[name]
        rest = s["wall"] - s["evaluation"] - sp["analyze"]
        print(f"2.   --sobol, N = {args.sobol_n:,} ({sp['cases']:,} cases), whole command, {label} (median of "
              f"{args.sobol_runs}): wall {s['wall']:.2f} s (goal <= {GOAL_SOBOL:g} s: "
              f"{'met' if s['wall'] <= GOAL_SOBOL else 'NOT met'}), CPU {s['cpu']:.2f} s; model evaluation "
              f"{s['evaluation']:.3f} s, analysis {sp['analyze']:.3f} s: analysis / evaluation "
              f"{sp['analyze'] / s['evaluation']:.2g}x; the rest (interpreter, imports, cluster, files) {rest:.2f} s")
    print(f"     in process (thread CPU, median of {args.reps} interleaved): evaluation of the design "
          f"{sp['evaluate']:.3f} s, SobolCollector.analyze() {sp['analyze']:.3f} s: analysis / evaluation "
          f"{sp['analyze'] / sp['evaluate']:.2g}x")
    print(f"(benchmark took {time.perf_counter() - t_all:.0f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
