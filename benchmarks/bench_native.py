#!/usr/bin/env python
"""What one impact costs in the native SpherePlateImpact FMU: write docs/native_cost.md.

    .venv/bin/python benchmarks/bench_native.py [--quick] [--out DIR]

builds, in a scratch directory, the pythonfmu FMU (behind the C guard), the native FMU, a *floor*
FMU (the same C front and generated interface table with a backend that does nothing) and two C
programs (the timing host, with the *precomputed C floor* in it: the least C computing e and v_rebound,
its parameter-only terms computed once, no FMI), then measures, every ratio in this one run:

1. one impact (set v_approach, doStep, get all 11 Real and 6 Boolean outputs) through fmpy's
   ``FMU2Slave``, raw calls: native against the floor (goal <= 1.5x), and the pythonfmu FMU;
2. the same in a plain C host (``env -i PATH=/usr/bin:/bin``): pythonfmu against native (goal native
   >= 30x faster), the native FMU's absolute figure (goal < 1 us), the native FMI 3.0 FMU against the
   native FMI 2.0 one (goal <= 1.1x), the floor, and the floor's four calls one by one (where the
   front's time goes);
3. one impact as a simulation needs it (set v_approach, doStep, get e and v_rebound) in the plain C host:
   native FMI 2.0 and 3.0 against the precomputed C floor (the least C computing e and v_rebound with the
   parameter terms once; goal <= 2.5x), and the floor FMU against it (what of that ratio is the C front;
   the rest is the physics and its glue);
4. the C physics (``rst_impact``) against the package's scalar ``restitution.impact``.

Prints the headline next to the goals and writes DIR/native_cost.md (DIR defaults to docs/).
``--quick`` (used by tests/benchmarks/test_bench_native.py) measures 3 short repeats; the full run takes about a
minute. Split by job: bench_native_build.py (the FMUs and C programs), bench_native_timing.py
(interleaved batches), bench_native_page.py (the page).
"""
from __future__ import annotations

import argparse
import datetime
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
for _p in (ROOT / "fmu_src", ROOT / "benchmarks"):
    if str(_p) not in sys.path:
        sys.path.insert(0, str(_p))

import bench_native_build as build  # noqa: E402
import bench_native_page as page  # noqa: E402
import bench_native_timing as timing  # noqa: E402
from harness import machine  # noqa: E402

#: name -> (repeats, CPU seconds per batch)
CONFIGS = {"full": (11, 0.2), "quick": (3, 0.02)}


def run(quick: bool = False, out_dir: Path | None = None, verbose: bool = True) -> dict:
    """Build, measure, write ``out_dir/native_cost.md`` (default docs/); returns the results."""
    say = print if verbose else (lambda *a, **k: None)
    name = "quick" if quick else "full"
    reps, seconds = CONFIGS[name]
    out_dir = Path(out_dir) if out_dir is not None else ROOT / "docs"
    start = time.monotonic()
    res = {"config": {"name": name, "reps": reps, "seconds": seconds}, "machine": machine(),
           "date": datetime.date.today().isoformat(), "step": timing.STEP}
    say(f"machine: {res['machine']['cpu']}, {res['machine']['cores']} cores, load {res['machine']['load_start']:.1f}")
    with tempfile.TemporaryDirectory(prefix="bench_native-") as tmp:
        say("building the FMUs (pythonfmu, native FMI 2.0 and 3.0, floor) and the C hosts ...")
        built = build.build_all(Path(tmp), log=lambda message: say(message, file=sys.stderr))
        _, reals, bools = timing._interfaces(built.model_description)
        res["n_reals"], res["n_bools"] = len(reals), len(bools)
        say("fmpy round trips ...")
        res["fmpy"] = timing.fmpy_round_trips(built, page.FMU_ROWS, reps, seconds)
        say("C host round trips ...")
        res["c_host"] = timing.c_host_round_trips(built, page.C_HOST_ROWS, reps, seconds)
        say("C host, e and v_rebound: native, the floor FMU and the precomputed C floor ...")
        res["impact"] = timing.c_host_round_trips(built, page.IMPACT_ROWS, reps, seconds,
                                                  outputs=timing.IMPACT_OUTPUTS)
        say("C host, the floor's calls one by one ...")
        res["calls"] = timing.c_host_round_trips(built, ("floor",), reps, seconds / 2, each_call=True)
        say("C physics against the package ...")
        res["physics"] = timing.physics_against_package(built, reps, seconds / 2)
    fm, ch, ph, im = res["fmpy"], res["c_host"], res["physics"], res["impact"]
    native = ch.batches["native"]
    res["headline"] = {
        "native_over_floor_fmpy": (fm.ratio("native", "floor"), fm.spread("native", "floor")),
        "python_over_native_c_host": (ch.ratio("pythonfmu", "native"), ch.spread("pythonfmu", "native")),
        "native_c_host": (statistics.median(native), (min(native), max(native))),
        "fmi3_over_native_c_host": (ch.ratio("fmi3", "native"), ch.spread("fmi3", "native")),
        "native_over_precomputed_c_host": (im.ratio("native", "precomputed"), im.spread("native", "precomputed")),
        "fmi3_over_precomputed_c_host": (im.ratio("fmi3", "precomputed"), im.spread("fmi3", "precomputed")),
        "package_over_c_physics": (ph.ratio("package exact", "C exact"), ph.spread("package exact", "C exact")),
    }
    res["machine"]["load_end"] = os.getloadavg()[0]
    res["duration"] = time.monotonic() - start
    out_dir.mkdir(parents=True, exist_ok=True)
    target = out_dir / "native_cost.md"
    target.write_text(page.render(res), encoding="utf-8")
    say("")
    say(page.console(res))
    say(f"\nwrote {target}")
    return res


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[1])
    parser.add_argument("--quick", action="store_true", help="3 short repeats (a test run; the page says so)")
    parser.add_argument("--out", type=Path, default=None, help="directory of native_cost.md (default: docs/)")
    args = parser.parse_args(argv)
    run(quick=args.quick, out_dir=args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
