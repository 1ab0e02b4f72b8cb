#!/usr/bin/env python
"""What the pythonfmu SpherePlateImpact FMU costs per step beyond a plain pythonfmu FMU.

    .venv/bin/python benchmarks/bench_pythonfmu.py [--quick] [--work DIR]

Builds, in a scratch directory (``--work``, default a temporary one):

* the product: ``SpherePlateImpact.fmu`` by :func:`restitution.fmu.builders.build_one`, exactly as the
  project builds it (pythonfmu, the package, the C guard in front of pythonfmu's binary);
* the *plain twin*: a pythonfmu FMU built by pythonfmu alone (no guard, no package) whose slave
  registers the same variables (names, types, causalities, variabilities, start values, hence the same
  value references) in plain pythonfmu style (attributes read and written by pythonfmu's default
  getters and setters) and does no physics: ``do_step`` returns True, every output is a constant;
* for the breakdown, the product *without its physics*: a copy of the product whose slave script calls
  :func:`restitution.model.impact_record_at` once and returns that record at every later evaluation (the
  guard, pythonfmu and the slave's per-step work, all but the physics).

Then, in this process (a Python host, fmpy's ctypes bindings called raw: prepared argument arrays, no
fmpy wrappers), it times one round trip of each FMU, interleaved batch by batch: ``fmi2SetReal`` of
``v_approach`` (a new value every time, so the product evaluates the model), ``fmi2DoStep``,
``fmi2GetReal`` of every Real output and ``fmi2GetBoolean`` of every Boolean output. Times are CPU time
of this thread (``time.thread_time``; the slaves run in the calling thread). The headline is the median
over batches of product / twin, which the goal bounds: what a user pays for the guard, the slave's
per-step work and the physics, over what pythonfmu itself costs. The product without its physics is timed
in the same batches (its ratio to the twin is what the guard and the slave add); the product and the twin
are also timed with one output read (``e``), and call by call.

The process ends with ``os._exit``: the plain twin brings pythonfmu 0.7's exit-time double release
(docs: pythonfmu_guard/README.md) into this process, which the guard disarms only for its own binary.
"""
from __future__ import annotations

from harness import cpu_name  # this folder: the benchmarks' harness

import argparse
import ctypes
import os
import platform
import shutil
import sys
import tempfile
import time
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
for _p in (ROOT / "fmu_src", ROOT / "benchmarks"):
    if str(_p) not in sys.path:
        sys.path.insert(0, str(_p))

from harness import interleaved, median, median_ratio  # noqa: E402

MODEL = "SpherePlateImpact"
TWIN = "PlainSpherePlateImpact"
#: product round trip / plain twin round trip, the goal
GOAL = 1.5
#: The four calls of a round trip, in order.
CALLS = ("set", "step", "get_real", "get_boolean")
FULL = {"reps": 15, "batch_seconds": 0.4}
QUICK = {"reps": 3, "batch_seconds": 0.05}

TWIN_SCRIPT = '''"""A plain pythonfmu FMU with the variables of {model} and no physics (bench_pythonfmu.py)."""
from types import SimpleNamespace

from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Boolean, Integer, Real
from pythonfmu.enums import Fmi2Initial

#: (name, type, causality, variability, value): the interface table's rows, outputs given a constant
VARIABLES = {rows!r}


class {name}(Fmi2Slave):
    author = "bench_pythonfmu.py"
    description = "pythonfmu alone: the variables of {model}, no physics"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        kinds = {{"Real": Real, "Integer": Integer, "Boolean": Boolean}}
        for name, vtype, causality, variability, value in VARIABLES:
            owner = self
            for part in name.split(".")[:-1]:  # "sphere.E": attribute E of self.sphere
                if not hasattr(owner, part):
                    setattr(owner, part, SimpleNamespace())
                owner = getattr(owner, part)
            setattr(owner, name.split(".")[-1], value)
            extra = {{}} if causality in ("input", "parameter") else {{"initial": Fmi2Initial.calculated}}
            self.register_variable(kinds[vtype](name, causality=getattr(Fmi2Causality, causality),
                                                variability=getattr(Fmi2Variability, variability), **extra))

    def do_step(self, current_time, step_size):
        return True
'''


def _twin_rows():
    from restitution.fmu.models import table

    rows = []
    for var in table(MODEL):
        if var.causality in ("input", "parameter"):
            value = var.start
        else:  # a constant of the output's type
            value = {"Real": 0.5, "Integer": 1, "Boolean": True}[var.type]
        rows.append((var.name, var.type, var.causality, var.variability, value))
    return rows


def _unzip(fmu: Path, directory: Path) -> Path:
    with zipfile.ZipFile(fmu) as z:
        z.extractall(directory)
    return directory


#: The line of the slave script that binds the physics, and what the copy without physics has instead.
PHYSICS_LINE = "_impact_si = si_only(impact_record_at)\n"
MEMO_PHYSICS = '''_impact_once = si_only(impact_record_at)
_first_result = []


def _impact_si(v, *args, **kwargs):  # bench_pythonfmu.py: the physics once, its result ever after
    if not _first_result:
        _first_result.append(_impact_once(v, *args, **kwargs))
    return _first_result[0]
'''


def _without_physics(product: Path, directory: Path) -> Path:
    """A copy of the unzipped product whose slave evaluates the physics once (see the module docstring)."""
    shutil.copytree(product, directory)
    script = directory / "resources" / "sphere_plate_impact_slave.py"
    text = script.read_text(encoding="utf-8")
    if text.count(PHYSICS_LINE) != 1:
        raise RuntimeError(f"{script.name} no longer binds the physics as {PHYSICS_LINE.strip()!r}: "
                           "update bench_pythonfmu.PHYSICS_LINE")
    script.write_text(text.replace(PHYSICS_LINE, MEMO_PHYSICS), encoding="utf-8")
    return directory


def build(work: Path) -> dict:
    """{"product", "no_physics", "twin": unzipped dir} built into ``work``."""
    from pythonfmu.builder import FmuBuilder
    from restitution.fmu.builders import build_one

    product = build_one(MODEL, work / "fmus", log=lambda message: print(message, file=sys.stderr))
    source = work / "twin_src"
    source.mkdir(parents=True, exist_ok=True)
    script = source / "plain_sphere_plate_impact.py"
    script.write_text(TWIN_SCRIPT.format(model=MODEL, name=TWIN, rows=_twin_rows()), encoding="utf-8")
    twin = Path(FmuBuilder.build_FMU(script, dest=work / "fmus"))
    unzipped = _unzip(product, work / "product")
    return {"product": unzipped, "no_physics": _without_physics(unzipped, work / "no_physics"),
            "twin": _unzip(twin, work / "twin")}


class RawInstance:
    """One co-simulation instance through fmpy's ctypes bindings, initialised at t = 0. ``runner(calls)``
    gives ``run(n)``: n round trips of raw calls on prepared arrays (``calls``: which of :data:`CALLS`)."""

    def __init__(self, directory: Path, name: str):
        from fmpy import read_model_description
        from fmpy.fmi2 import FMU2Slave

        md = read_model_description(str(directory))
        self.slave = FMU2Slave(guid=md.guid, unzipDirectory=str(directory),
                               modelIdentifier=md.coSimulation.modelIdentifier, instanceName=name)
        self.slave.instantiate(loggingOn=False)
        self.slave.setupExperiment(startTime=0.0)
        self.slave.enterInitializationMode()
        self.slave.exitInitializationMode()
        by_name = {v.name: v for v in md.modelVariables}
        outputs = [v for v in md.modelVariables if v.causality == "output"]
        self.reals = [v.valueReference for v in outputs if v.type == "Real"]
        self.bools = [v.valueReference for v in outputs if v.type == "Boolean"]
        self.vr_v = by_name["v_approach"].valueReference
        self.vr_e = by_name["e"].valueReference
        self.t = 0.0
        self.k = 0

    def runner(self, calls=None, reals=None):
        s = self.slave
        c = s.component
        calls = CALLS if calls is None else calls
        reals = self.reals if reals is None else reals
        vr_v = (ctypes.c_uint * 1)(self.vr_v)
        value = (ctypes.c_double * 1)()
        vr_r = (ctypes.c_uint * len(reals))(*reals)
        out_r = (ctypes.c_double * len(reals))()
        vr_b = (ctypes.c_uint * len(self.bools))(*self.bools)
        out_b = (ctypes.c_int * len(self.bools))()
        n_r, n_b = len(reals), len(self.bools)
        set_real, do_step = s.fmi2SetReal, s.fmi2DoStep
        get_real, get_boolean = s.fmi2GetReal, s.fmi2GetBoolean
        do_set, do_st, do_gr, do_gb = (name in calls for name in CALLS)
        h = 1e-3

        def run(n):
            t, k = self.t, self.k
            bad = 0
            for _ in range(n):
                if do_set:
                    value[0] = 0.5 + 1e-6 * (k % 1000000)  # a new speed: a new impact
                    k += 1
                    bad |= set_real(c, vr_v, 1, value)
                if do_st:
                    bad |= do_step(c, t, h, 1)
                    t += h
                if do_gr:
                    bad |= get_real(c, vr_r, n_r, out_r)
                if do_gb:
                    bad |= get_boolean(c, vr_b, n_b, out_b)
            if bad:
                raise RuntimeError("a call did not return fmi2OK")
            self.t, self.k = t, k
            return n
        return run


def _raw_functions(slave):
    """fmpy's FMU2Slave wraps each FMI function in a logging and checking closure: the bare ctypes
    functions, so that both FMUs are called with the least host code."""
    for name in ("fmi2SetReal", "fmi2DoStep", "fmi2GetReal", "fmi2GetBoolean"):
        fn = getattr(slave.dll, name)
        setattr(slave, name, fn)


def measure(dirs: dict, reps: int, batch_seconds: float) -> dict:
    product = RawInstance(dirs["product"], "product")
    no_physics = RawInstance(dirs["no_physics"], "no_physics")
    twin = RawInstance(dirs["twin"], "twin")
    if product.reals != twin.reals or product.bools != twin.bools or product.vr_v != twin.vr_v:
        raise RuntimeError("the twin's value references differ from the product's")
    for inst in (product, no_physics, twin):
        _raw_functions(inst.slave)
    variants = {"product": product.runner(), "no_physics": no_physics.runner(), "twin": twin.runner()}
    timings = interleaved(variants, reps, batch_seconds)
    out = {"round_trip": {k: median(v) for k, v in timings.items()},
           "ratio": median_ratio(timings["product"], timings["twin"]),
           "ratios": sorted(a / b for a, b in zip(timings["product"], timings["twin"])),
           "no_physics_ratio": median_ratio(timings["no_physics"], timings["twin"])}
    # call by call: the round trip cut after each call (set; set, step; ...), interleaved: each call's
    # share is the difference between two consecutive cuts (the step evaluates the new impact, the gets
    # read what it left)
    cuts = {}
    for end in range(1, len(CALLS) + 1):
        calls = CALLS[:end]
        cuts[CALLS[end - 1]] = interleaved({"product": product.runner(calls), "twin": twin.runner(calls)},
                                           max(3, reps // 3), batch_seconds / 2)
    out["cuts"] = {call: {k: median(v) for k, v in ts.items()} for call, ts in cuts.items()}
    one = interleaved({"product": product.runner(reals=[product.vr_e], calls=("set", "step", "get_real")),
                       "twin": twin.runner(reals=[twin.vr_e], calls=("set", "step", "get_real"))},
                      max(3, reps // 3), batch_seconds)
    out["get_e_only"] = {"ratio": median_ratio(one["product"], one["twin"]),
                         **{k: median(v) for k, v in one.items()}}
    return out


def report(res: dict, quick: bool) -> str:
    us = 1e6
    rt = res["round_trip"]
    lines = [f"bench_pythonfmu ({'quick' if quick else 'full'} run, {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, "
             f"{platform.node()}, {cpu_name()}, {os.cpu_count()} cpus)",
             "host: this Python process, fmpy's ctypes functions called raw; CPU time of the thread",
             "round trip (set v_approach, doStep, get every Real and Boolean output):",
             f"  product (guard + pythonfmu + slave + physics) {rt['product'] * us:8.2f} us",
             f"  product with the physics replaced by one result {rt['no_physics'] * us:6.2f} us"
             f" ({res['no_physics_ratio']:.2f}x the twin: the guard, pythonfmu and the slave)",
             f"  plain pythonfmu twin (no guard, no physics)   {rt['twin'] * us:8.2f} us",
             f"  product / twin = {res['ratio']:.2f}x (goal <= {GOAL}x: {'met' if res['ratio'] <= GOAL else 'NOT met'};"
             f" batches {res['ratios'][0]:.2f}x - {res['ratios'][-1]:.2f}x)",
             "call by call (the round trip cut after each call; each call's share of it):"]
    before = {"product": 0.0, "twin": 0.0}
    for call, m in res["cuts"].items():
        p, t = m["product"] - before["product"], m["twin"] - before["twin"]
        lines.append(f"  {call:12s} product {p * us:7.2f} us   twin {t * us:7.2f} us   difference {(p - t) * us:7.2f} us")
        before = m
    g = res["get_e_only"]
    lines.append(f"set, step, get e only: product {g['product'] * us:.2f} us, twin {g['twin'] * us:.2f} us, "
                 f"ratio {g['ratio']:.2f}x")
    return "\n".join(lines)


def run(quick: bool = False, work: Path | None = None) -> dict:
    cfg = QUICK if quick else FULL
    own = work is None
    work = Path(tempfile.mkdtemp(prefix="bench_pythonfmu-")) if own else Path(work)
    try:
        dirs = build(work)
        res = measure(dirs, cfg["reps"], cfg["batch_seconds"])
    finally:
        if own:
            shutil.rmtree(work, ignore_errors=True)
    res["text"] = report(res, quick)
    return res


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="a few short batches (the tests' run)")
    parser.add_argument("--work", type=Path, help="scratch directory (default: a temporary one, removed)")
    args = parser.parse_args(argv)
    res = run(quick=args.quick, work=args.work)
    print(res["text"])
    return 0


if __name__ == "__main__":
    code = main()
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(code)  # see the module docstring: no interpreter exit with the plain twin loaded
