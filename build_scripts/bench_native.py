"""Cost of one impact in the native C physics against the Python package and, when they can be
built, the native FMU against the pythonfmu FMU; every ratio is measured in this one run.

    .venv/bin/python build_scripts/bench_native.py [--cases N]

* C physics: ``rst_impact`` in a compiled C loop (clock_gettime), v changing every call so nothing
  is cached, for each Zener method the C implements;
* package: ``restitution.impact`` with Python floats (the pythonfmu FMU's evaluation), same cases;
* FMUs through fmpy ``FMU2Slave`` (set v_approach, doStep, get every Real and Boolean output): the
  native FMU (``DIR/native/SpherePlateImpact.fmu``) against the pythonfmu one, when the native
  FMU builds here (it needs the C FMI front; otherwise this part says so and is skipped).

Medians of ``--repeats`` runs. Numbers depend on the machine; the ratios are what to read.
"""
from __future__ import annotations

import argparse
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

_LOOP = r"""
#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include "rst_physics.h"
int main(int argc, char **argv)
{
    long n;
    int method;
    if (argc != 3)
        return 2;
    n = atol(argv[1]);
    method = atoi(argv[2]);
    rst_impact_inputs in = {1.0, 207e9, 0.30, 2.0e9, 7861.0, 6.35e-3, 69e9, 0.33, 0.290e9, 2700.0, 6.35e-3,
                            1, 1, 2, 2, 1e-6, 1e-10};
    rst_impact_result out;
    struct timespec t0, t1;
    double sink = 0.0;
    long i;
    in.zener_method = method;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    for (i = 0; i < n; i++) {
        in.v = 0.1 + 1e-6 * (double)(i % 1000000);
        rst_impact(&in, &out);
        sink += out.e + out.t_contact;
    }
    clock_gettime(CLOCK_MONOTONIC, &t1);
    printf("%.6e %g\n", ((double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec)) / (double)n, sink);
    return 0;
}
"""
METHODS = {"exact": 1, "paper_fit": 2, "linear": 3}


def c_loop_seconds(tmp: Path, n: int, repeats: int) -> dict:
    from restitution.fmu.native.compile import CFLAGS, prepare_sources

    src = prepare_sources(tmp / "src")
    (src / "loop.c").write_text(_LOOP)
    exe = tmp / "loop"
    subprocess.run(["gcc", *CFLAGS, "-o", str(exe), str(src / "loop.c"), str(src / "rst_physics.c"), "-lm"],
                   check=True)
    return {m: statistics.median(float(subprocess.run([str(exe), str(n), str(code)], check=True, capture_output=True,
                                                      text=True).stdout.split()[0]) for _ in range(repeats))
            for m, code in METHODS.items()}


def package_seconds(n: int, repeats: int) -> dict:
    import restitution as r

    sphere = r.Sphere(r.MATERIALS["s2_tool_steel"], d=6.35e-3).params()
    plate = r.Plate(r.MATERIALS["al_6061"], t=6.35e-3).params()
    out = {}
    for method in METHODS:
        runs = []
        for _ in range(repeats):
            t0 = time.perf_counter()
            for i in range(n):
                r.impact(0.1 + 1e-6 * i, **sphere, **plate, zener_method=method, validate=False)
            runs.append((time.perf_counter() - t0) / n)
        out[method] = statistics.median(runs)
    return out


def fmu_round_trip_seconds(fmu: Path, n: int, repeats: int) -> float:
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    md = read_model_description(str(fmu))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    reals = [v.valueReference for v in md.modelVariables if v.causality == "output" and v.type == "Real"]
    bools = [v.valueReference for v in md.modelVariables if v.causality == "output" and v.type == "Boolean"]
    slave = FMU2Slave(guid=md.guid, unzipDirectory=extract(str(fmu)), modelIdentifier=md.coSimulation.modelIdentifier,
                      instanceName="bench")
    slave.instantiate()
    slave.setupExperiment(startTime=0.0)
    slave.enterInitializationMode()
    slave.exitInitializationMode()
    runs, t, h = [], 0.0, 1e-3
    for _ in range(repeats):
        t0 = time.perf_counter()
        for i in range(n):
            slave.setReal([vr["v_approach"]], [0.1 + 1e-6 * i])
            slave.doStep(t, h)
            t += h
            slave.getReal(reals)
            slave.getBoolean(bools)
        runs.append((time.perf_counter() - t0) / n)
    slave.terminate()
    slave.freeInstance()
    return statistics.median(runs)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=20000)
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args(argv)
    print(f"machine: {platform.processor() or platform.machine()}, Python {platform.python_version()}")
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        c = c_loop_seconds(tmp, max(args.cases * 50, 10**6), args.repeats)
        py = package_seconds(args.cases, args.repeats)
        print(f"{'method':<10} {'C physics':>12} {'package':>12} {'package / C':>12}")
        for m in METHODS:
            print(f"{m:<10} {c[m] * 1e9:>9.1f} ns {py[m] * 1e6:>9.2f} us {py[m] / c[m]:>11.0f}x")
        try:
            from restitution.fmu.build import build_one
            from restitution.fmu.native.build_native import NativeBuildSkipped, build_native_one

            python_fmu = build_one("SpherePlateImpact", tmp / "fmus")
            native_fmu = build_native_one("SpherePlateImpact", tmp / "fmus", python_fmu)
        except Exception as exc:  # noqa: BLE001 - report and keep the physics numbers
            print(f"FMU round trips skipped: {type(exc).__name__}: {exc}")
            return 0
        n = max(args.cases // 4, 1000)
        native = fmu_round_trip_seconds(native_fmu, n, args.repeats)
        python = fmu_round_trip_seconds(python_fmu, n, args.repeats)
        print(f"fmpy round trip (setReal v, doStep, getReal + getBoolean of all outputs): native {native * 1e6:.2f} us, "
              f"pythonfmu {python * 1e6:.2f} us, pythonfmu / native = {python / native:.1f}x")
    return 0


if __name__ == "__main__":
    sys.exit(main())
