#!/usr/bin/env python
"""What ``restitution.impact`` costs on an array of cases, against the numpy floor (numpy_floor.py).

    .venv/bin/python benchmarks/bench_impact.py [--cases N] [--repeats N] [--quick]

One sphere on one plate (S2 tool steel, d = 6.35 mm, on Al 6061, t = d), ``--cases`` cases (default 10^6)
with random approach speeds, log-uniform from 0.2 to 5 m/s, the default options (``zener_method="exact"``,
``restitution_model="e45"``, both effects ``"auto"``). Three sides:

* ``impact``: ``restitution.impact(v, **params)``, every output (the default ImpactResult), goal <= 2x the floor;
* ``impact e, v_rebound``: ``restitution.impact(v, **params, outputs=("e", "v_rebound"))``, goal <= 1.2x;
* ``numpy floor``: numpy_floor.e_and_rebound, the numpy expression of e and v_rebound (Eqs. 8, 12, the
  paper's fit of e_ze, Eq. 13, and 20) with the parameter terms computed once. Before timing, its e and
  v_rebound are compared with impact()'s under the same equations (``zener_method="paper_fit"``, both
  effects on; the benchmark stops if they differ beyond rounding).
* ``result arrays alone``: no physics, only what the default result's arrays cost to make: each of
  ImpactResult's real fields (17) as one product v * c and each flag (7) as one comparison v < c, into
  fresh arrays as impact() returns them (owned, writable, one per field). No goal: it is the part of the
  first side's cost that any implementation returning those arrays pays, printed beside the floor.

The sides take turns (the first rotating), ``--repeats`` times each, CPU time of this thread
(``time.thread_time``: page faults of fresh arrays included); a ratio is the median of the per-turn ratios.
The machine is shared: ratios are the result, absolute times only say how busy it was; the load average
is printed with them. ``--quick`` runs 10^4 cases three times (a test runs it).
"""
from __future__ import annotations

import argparse
import math
import os
import platform
import statistics
import sys
import time
from datetime import datetime, timezone
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
for _path in (ROOT / "fmu_src", Path(__file__).resolve().parent):
    if str(_path) not in sys.path:
        sys.path.insert(0, str(_path))

import numpy_floor  # noqa: E402
from harness import cpu_name  # noqa: E402

GOALS = {"impact": 2.0, "impact e, v_rebound": 1.2}  #: each side / the numpy floor, at most
DIAMETER = 6.35e-3  #: sphere diameter [m], also the plate's thickness
SPHERE, PLATE = "s2_tool_steel", "al_6061"
SIDES = ("impact", "impact e, v_rebound", "numpy floor", "result arrays alone")


def cases(n: int, seed: int = 2026):
    """``n`` approach speeds [m/s], log-uniform over 0.2 ... 5 m/s."""
    return 10.0 ** np.random.default_rng(seed).uniform(math.log10(0.2), math.log10(5.0), n)


def parameters() -> dict:
    """impact()'s parameters of the pair."""
    from restitution.materials import MATERIALS, Plate, Sphere

    return {**Sphere(MATERIALS[SPHERE], DIAMETER).params(), **Plate(MATERIALS[PLATE], DIAMETER).params()}


def disagreement(v, params) -> float:
    """The largest difference of the floor's e and v_rebound from impact()'s under the same equations, beyond
    rounding (1e-12 relative); 0 when they agree."""
    import restitution

    ref = restitution.impact(v, **params, zener_method="paper_fit", plasticity="on", plate_waves="on")
    e, v_rebound = numpy_floor.e_and_rebound(v, numpy_floor.floor_terms(params))
    return max(float(np.max(np.abs(e - ref.e) - 1e-12 * np.maximum(1.0, np.abs(ref.e)))),
               float(np.max(np.abs(v_rebound - ref.v_rebound) - 1e-12 * np.maximum(1.0, np.abs(ref.v_rebound)))), 0.0)


def result_array_counts() -> tuple[int, int]:
    """(real arrays, flag arrays) a default ImpactResult holds."""
    from restitution.record import RECORD_FLAGS, RECORD_REALS

    return len(RECORD_REALS), len(RECORD_FLAGS) - 1  # "valid" is a property of the result, not an array it holds


def result_arrays_alone(v) -> list:
    """The arrays of a default ImpactResult of the speeds ``v`` without its physics: one fresh product per
    real field and one fresh comparison per flag."""
    reals, flags = result_array_counts()
    return [v * 1.5 for _ in range(reals)] + [v < 1.0 for _ in range(flags)]


def measure(n: int, repeats: int) -> dict:
    import restitution

    v, params = cases(n), parameters()
    wrong = disagreement(v[:100_000], params)
    if wrong:
        raise SystemExit(f"the numpy floor and impact(zener_method='paper_fit') disagree by {wrong:.3g}")
    terms = numpy_floor.floor_terms(params)
    run = {"impact": lambda: restitution.impact(v, **params),
           "impact e, v_rebound": lambda: restitution.impact(v, **params, outputs=("e", "v_rebound")),
           "numpy floor": lambda: numpy_floor.e_and_rebound(v, terms),
           "result arrays alone": lambda: result_arrays_alone(v)}
    times = {side: [] for side in SIDES}
    for side in SIDES:
        run[side]()  # warm-up
    for turn in range(repeats):
        for k in range(len(SIDES)):
            side = SIDES[(k + turn) % len(SIDES)]
            start = time.thread_time()
            run[side]()
            times[side].append(time.thread_time() - start)
    ratios = {side: statistics.median(a / b for a, b in zip(times[side], times["numpy floor"]))
              for side in (*GOALS, "result arrays alone")}
    return {"cases": n, "seconds": {side: statistics.median(t) for side, t in times.items()}, "ratios": ratios,
            "load": os.getloadavg()}


def report(m: dict) -> str:
    sec = m["seconds"]
    lines = [f"{m['cases']:.3g} cases: impact {sec['impact']:.4g} s, impact e, v_rebound {sec['impact e, v_rebound']:.4g} s, "
             f"numpy floor {sec['numpy floor']:.4g} s (load average {m['load'][0]:.2f})"]
    for side, goal in GOALS.items():
        ratio = m["ratios"][side]
        lines.append(f"{side} / numpy floor, {m['cases']:.3g} cases: {ratio:.2f}x "
                     f"(goal <= {goal:g}x: {'met' if ratio <= goal else 'NOT met'})")
    reals, flags = result_array_counts()
    lines.append(f"result arrays alone / numpy floor, {m['cases']:.3g} cases: {m['ratios']['result arrays alone']:.2f}x "
                 f"(no goal: the {reals} real and {flags} flag arrays of the default result made fresh, no physics; "
                 f"{sec['result arrays alone']:.4g} s)")
    return "\n".join(lines)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, action="append", help="cases per call (repeatable; default 10^6)")
    parser.add_argument("--repeats", type=int, default=15, help="turns of each side (default 15)")
    parser.add_argument("--quick", action="store_true", help="10^4 cases, 3 turns")
    args = parser.parse_args(argv)
    sizes = [10_000] if args.quick else (args.cases or [1_000_000])
    repeats = 3 if args.quick else args.repeats
    print(f"bench_impact.py on {datetime.now(timezone.utc):%Y-%m-%d %H:%M} UTC: {cpu_name()}"
          f", {len(os.sched_getaffinity(0))} cores; Python {platform.python_version()}, numpy {np.__version__}; "
          f"{SPHERE} d = {DIAMETER * 1e3:g} mm on {PLATE} t = d, default options, {repeats} interleaved turns, thread CPU time")
    for n in sizes:
        print(report(measure(n, repeats)), flush=True)


if __name__ == "__main__":
    main()
