#!/usr/bin/env python
"""What accuracy costs in time: measure every accuracy choice and write docs/accuracy.md.

    .venv/bin/python benchmarks/bench_accuracy.py [--quick] [--out DIR] [--jobs N]

writes DIR/accuracy.md (Markdown tables) and DIR/img/accuracy_cost.png (error against cost,
log-log); DIR defaults to docs/. ``--quick`` (a minute or so, used by the tests) measures
fewer points, tolerances and repeats; the full run takes a few minutes.

What is measured
----------------
* Zener's COR e_ze and contact time tau0 by each method (``exact``, ``paper_fit``,
  ``linear``, ``ode`` at rtol 1e-3 ... 1e-12) against a high-precision reference, over
  lambda in [0, 1.5] (Zener's studied range) and (1.5, 100]. The reference is computed
  here, in this run, independently of every method under test: scipy's Radau (implicit
  Runge-Kutta, order 5) at rtol = 1e-13 on Zener's first-order form in tau, started from
  its own analytic series. The ``ode`` method uses DOP853/LSODA and the ``exact`` table was
  made with DOP853 in s = sqrt(sigma) plus a fitted large-lambda form (make_zener_table.py).
* Cost per evaluation (a) of a scalar package call (``zener_restitution`` and the whole
  ``impact``), (b) per element of a vectorized call on 1e5 cases, (c) of one FMU round
  trip through ``fmpy.fmi2.FMU2Slave``: set ``v_approach``, ``doStep``, get every output.
  The FMU costs are also given as ratios to a trivial pythonfmu FMU with the same
  variables (the floor the wrapper itself sets), built and timed in the same run.
* e44 against e45 over V* in [1, 1000] (no ground truth exists: both are fits).
* The bouncing ball: fixed-step co-simulation (BouncingBall.fmu + SpherePlateImpact.fmu,
  ``restitution.cosim.FixedStepMaster``) against the event-exact master
  (``restitution.cosim.bounce``) over communication step sizes, with wall time.

Costs are medians of repeated batches in one process, variants interleaved batch by batch
so that ratios compare like with like; they are CPU time of the benchmarking thread
(``time.thread_time``), so other processes on a shared machine do not inflate them. The
machine is reported with the results. Ratios are the headline; absolute times move with
the machine.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
for _p in (ROOT / "fmu_src", ROOT / "benchmarks"):
    if str(_p) not in sys.path:
        sys.path.insert(0, str(_p))

from accuracy_bench.bouncing import bouncing  # noqa: E402
from accuracy_bench.config import FULL, QUICK, RANGES, TARGETS  # noqa: E402
from accuracy_bench.fmu_costs import build_fmus, fmu_costs  # noqa: E402
from accuracy_bench.jgm_fits import jgm_fits  # noqa: E402
from accuracy_bench.model_costs import model_costs  # noqa: E402
from accuracy_bench.page import headline, markdown  # noqa: E402
from harness import machine, settle_allocator  # noqa: E402
from accuracy_bench.plot import plot  # noqa: E402
from accuracy_bench.reference import lambda_points, reference_many  # noqa: E402
from accuracy_bench.zener_costs import method_list, zener_accuracy, zener_scalar_costs, zener_vector_costs  # noqa: E402


def run(quick: bool = False, out_dir: Path | None = None, jobs: int | None = None, verbose: bool = True) -> dict:
    """Measure everything, write ``out_dir/accuracy.md`` and ``out_dir/img/accuracy_cost.png``; return results."""
    cfg = QUICK if quick else FULL
    out_dir = Path(out_dir) if out_dir is not None else ROOT / "docs"
    jobs = jobs or os.cpu_count() or 1
    start = time.perf_counter()

    def say(msg):
        if verbose:
            print(f"[{time.perf_counter() - start:6.1f} s] {msg}", flush=True)

    settle_allocator()
    res = {"machine": machine(), "methods": method_list(cfg), "n_vector": cfg.n_vector,
           "n_vector_ode": cfg.n_vector_ode}
    lams = lambda_points(cfg)
    say(f"reference: Radau rtol 1e-13 at {sum(len(x) for x in lams.values())} lambdas on {jobs} processes")
    ref = {rng: reference_many(lams[rng], jobs) for rng in RANGES}
    res["reference"] = {"n": {rng: len(lams[rng]) for rng in RANGES}, "tau0_at_0": float(ref[RANGES[0]][1][0]),
                        "lambdas": {rng: lams[rng].tolist() for rng in RANGES},
                        "e": {rng: ref[rng][0].tolist() for rng in RANGES},
                        "tau0": {rng: ref[rng][1].tolist() for rng in RANGES}}
    if cfg.reference_check:
        e12, t12 = reference_many(cfg.reference_check, jobs, rtol=1e-12)
        e13, t13 = reference_many(cfg.reference_check, jobs)
        res["reference"]["self_check"] = float(max(np.max(np.abs(e12 / e13 - 1)), np.max(np.abs(t12 / t13 - 1))))
    say("Zener accuracy of every method")
    res["accuracy"] = zener_accuracy(cfg, lams, ref)
    say("Zener costs: scalar")
    res["zener_scalar"] = zener_scalar_costs(cfg, lams, res["accuracy"])
    say("Zener costs: vectorized")
    res["zener_vector"] = zener_vector_costs(cfg)
    say("whole model: scalar against vectorized")
    res["model"] = model_costs(cfg)
    say("e44 against e45")
    res["jgm"] = jgm_fits(cfg)
    with tempfile.TemporaryDirectory(prefix="bench_accuracy_") as tmp:
        work = Path(tmp)
        say("building the FMUs (SpherePlateImpact, BouncingBall, trivial floors)")
        fmus = build_fmus(work)
        res["floor_counts"] = {f"{k[1]} {k[0]}": v for k, v in fmus.pop("counts").items()}
        say("FMU round trips")
        res["fmu"] = fmu_costs(cfg, fmus)
        say("bouncing ball co-simulation")
        res["bouncing"] = bouncing(cfg, fmus, work)
    elapsed = time.perf_counter() - start
    res["headline"] = headline(res)
    md_path = out_dir / "accuracy.md"
    md_path.parent.mkdir(parents=True, exist_ok=True)
    md_path.write_text(markdown(res, "quick" if quick else "full", elapsed))
    png = plot(res, out_dir / "img" / "accuracy_cost.png")
    res["paths"] = {"markdown": md_path, "png": png}
    say(f"wrote {md_path} and {png}")
    if verbose:
        print_headline(res)
    return res


def print_headline(res: dict):
    h = res["headline"]
    print("headline (ratios; goal in brackets):")
    goal = {key: text for key, (text, _met) in TARGETS.items()}
    print(f"  exact max rel error vs reference, lambda in [0, 100]: {h['exact_rel_error']:.2e}  ({goal['exact_rel_error']})")
    print(f"  exact / paper_fit, scalar package call:               {h['exact_over_paper_fit_package']:.2f}x "
          f"({goal['exact_over_paper_fit_package']})")
    print(f"  exact / paper_fit, FMU round trip:                    {h['exact_over_paper_fit_fmu']:.2f}x "
          f"({goal['exact_over_paper_fit_fmu']})")
    print(f"  SpherePlateImpact / trivial FMU, round trip:          {h['fmu_over_floor']:.2f}x ({goal['fmu_over_floor']})")
    print(f"  whole model scalar / vectorized per case:             {h['scalar_over_vectorized']:.0f}x "
          f"({goal['scalar_over_vectorized']})")


def results_json(res: dict) -> str:
    """The results as JSON (tuple keys joined with ' | ')."""
    def conv(x):
        if isinstance(x, dict):
            return {(" | ".join(map(str, k)) if isinstance(k, tuple) else str(k)): conv(v) for k, v in x.items()}
        if isinstance(x, (list, tuple)):
            return [conv(v) for v in x]
        if isinstance(x, Path):
            return str(x)
        if isinstance(x, float) and not math.isfinite(x):
            return str(x)
        return x
    return json.dumps(conv(res), indent=1)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="fewer points and repeats (about a minute)")
    parser.add_argument("--out", type=Path, default=ROOT / "docs", help="output folder (default: docs/)")
    parser.add_argument("--jobs", type=int, default=None, help="processes for the reference solves (default: all cores)")
    parser.add_argument("--json", type=Path, default=None, help="also write every number to this JSON file")
    args = parser.parse_args(argv)
    res = run(quick=args.quick, out_dir=args.out, jobs=args.jobs)
    if args.json is not None:
        args.json.write_text(results_json(res))
    return 0


if __name__ == "__main__":
    sys.exit(main())
