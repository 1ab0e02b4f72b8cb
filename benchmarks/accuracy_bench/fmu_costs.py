"""FMU round trips through fmpy: SpherePlateImpact per method, against a trivial pythonfmu FMU with the
same variables (the floor the wrapper itself sets), built in the same run."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from restitution.cosim import FmuInstance
from restitution.fmu.models import table

from .config import Config, RANGES
from harness import timed, interleaved, median, median_ratio


FLOOR_SCRIPT = '''"""Trivial pythonfmu FMU with the variables of SpherePlateImpact (counts and types): the floor."""
from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Boolean, Integer, Real
from pythonfmu.enums import Fmi2Initial

COUNTS = {counts!r}


class {name}(Fmi2Slave):
    author = "bench_accuracy.py"
    description = "does nothing: what the FMU wrapper costs"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        kinds = {{"Real": Real, "Integer": Integer, "Boolean": Boolean}}
        for (vtype, causality), count in COUNTS.items():
            for i in range(count):
                name = f"{{causality}}_{{vtype}}_{{i}}"
                setattr(self, name, False if vtype == "Boolean" else 1 if vtype == "Integer" else 1.0)
                if causality == "output":
                    var = kinds[vtype](name, causality=Fmi2Causality.output, initial=Fmi2Initial.calculated,
                                       variability=Fmi2Variability.continuous if vtype == "Real"
                                       else Fmi2Variability.discrete)
                else:
                    var = kinds[vtype](name, causality=getattr(Fmi2Causality, causality),
                                       variability=Fmi2Variability.continuous if causality == "input"
                                       else Fmi2Variability.tunable)
                self.register_variable(var)
{extra}
    def do_step(self, current_time, step_size):
        return True
'''


FLOOR_FAST_ACCESSORS = '''
    def get_real(self, vrs):
        v = self.vars
        return [getattr(self, v[vr].local_name) for vr in vrs]

    def get_boolean(self, vrs):
        v = self.vars
        return [getattr(self, v[vr].local_name) for vr in vrs]
'''


def build_fmus(work: Path) -> dict:
    """Build SpherePlateImpact, BouncingBall and the two trivial FMUs from the working tree."""
    from pythonfmu.builder import FmuBuilder
    from restitution.fmu.builders import FMUS, build_one
    from restitution.fmu.models import table
    from restitution.fmu.builders.guard import add_guard

    out = {"SpherePlateImpact": build_one("SpherePlateImpact", work)}
    if "BouncingBall" in FMUS:
        out["BouncingBall"] = build_one("BouncingBall", work)
    counts = {}
    for var in table("SpherePlateImpact"):
        key = (var.type, var.causality)
        counts[key] = counts.get(key, 0) + 1
    for name, extra in (("BenchWrapperFloor", ""), ("BenchWrapperFloorOnePass", FLOOR_FAST_ACCESSORS)):
        src = work / "floor_src" / name
        src.mkdir(parents=True, exist_ok=True)
        script = src / f"bench_{name.lower()}.py"
        script.write_text(FLOOR_SCRIPT.format(counts=counts, name=name, extra=extra))
        out[name] = Path(FmuBuilder.build_FMU(script, dest=work))
        # The same guard as the project's pythonfmu FMU: a like-for-like floor (the guard's checks
        # and forwarding are part of every call), and the fix for pythonfmu 0.7's exit double-free,
        # which a plain pythonfmu binary would bring into this process.
        add_guard(out[name])
    out["counts"] = counts
    return out


def round_trips(fmu, speeds, full: bool = True):
    """run(n): n passes of (setReal v, doStep, getReal outputs[, getBoolean outputs]) over ``speeds``,
    raw fmpy calls on the instance ``fmu`` (a :class:`restitution.cosim.FmuInstance`)."""
    variables = fmu.model_description.modelVariables
    outs = [v for v in variables if v.causality == "output"]
    reals = [v.valueReference for v in outs if v.type == "Real"]
    bools = [v.valueReference for v in outs if v.type == "Boolean"]
    s, vin = fmu.slave, [next(v.valueReference for v in variables if v.causality == "input")]
    reals = reals if full else reals[:1]
    values = [[float(x)] for x in speeds]
    h = 1e-3

    def run(n):
        t = fmu.time
        for _ in range(n):
            for value in values:
                s.setReal(vin, value)
                s.doStep(t, h)
                t += h
                s.getReal(reals)
                if full:
                    s.getBoolean(bools)
        fmu.time = t
        return n * len(values)
    return run


def fmu_costs(cfg: Config, fmus: dict) -> dict:
    floor, floor_fast, spi = (FmuInstance(fmus[name], instance_name=name, logging_on=False)
                              for name in ("BenchWrapperFloor", "BenchWrapperFloorOnePass", "SpherePlateImpact"))
    vr = {name: spi.vr(name) for name in ("plate.t", "v_approach", "zener.lambda", "zener_method",
                                          "zener.ode_tolerance")}
    d = 6.35e-3
    speeds = list(np.linspace(0.5, 5.0, 97))  # distinct consecutive values: every set is a new impact
    out = {"costs": {}, "ratios": {}, "exact_over_paper_fit": {}, "get_e_only": {}}
    s = spi.slave
    codes = table("SpherePlateImpact")["zener_method"].codes
    try:
        for rng, t_over_d in zip(RANGES, (1.0, 0.1)):
            s.setReal([vr["plate.t"]], [t_over_d * d])
            s.setReal([vr["v_approach"]], [speeds[0]])
            lam = s.getReal([vr["zener.lambda"]])[0]
            s.setReal([vr["v_approach"]], [speeds[-1]])
            lam_hi = s.getReal([vr["zener.lambda"]])[0]
            out.setdefault("lambda_span", {})[rng] = (min(lam, lam_hi), max(lam, lam_hi), t_over_d)

            def with_method(method, rtol=None):
                def run(n):
                    s.setInteger([vr["zener_method"]], [codes[method]])
                    if rtol is not None:
                        s.setReal([vr["zener.ode_tolerance"]], [rtol])
                    return round_trips(spi, speeds)(n)
                return run
            variants = {"trivial FMU (floor)": round_trips(floor, speeds),
                        "trivial FMU, one-pass getters": round_trips(floor_fast, speeds),
                        "exact": with_method("exact"), "paper_fit": with_method("paper_fit"),
                        "linear": with_method("linear")}
            timings = interleaved(variants, cfg.reps, cfg.batch_seconds)
            base = timings["trivial FMU (floor)"]
            for label, ts in timings.items():
                out["costs"][(label, rng)] = median(ts)
                out["ratios"][(label, rng)] = median_ratio(ts, base)
            out["exact_over_paper_fit"][rng] = median_ratio(timings["exact"], timings["paper_fit"])
            for rtol in cfg.ode_rtols:
                label = f"ode rtol {rtol:.0e}"
                ode_speeds = speeds[:: max(1, len(speeds) // 8)]

                def run_ode(n, rtol=rtol, ode_speeds=ode_speeds):
                    s.setInteger([vr["zener_method"]], [codes["ode"]])
                    s.setReal([vr["zener.ode_tolerance"]], [rtol])
                    return round_trips(spi, ode_speeds)(n)
                ts = [timed(run_ode, 1) for _ in range(cfg.ode_reps)]
                out["costs"][(label, rng)] = median(ts)
                out["ratios"][(label, rng)] = median(ts) / out["costs"][("trivial FMU (floor)", rng)]
            s.setInteger([vr["zener_method"]], [codes["exact"]])
        # the same with a single output read (set v, step, get e)
        s.setReal([vr["plate.t"]], [d])
        timings = interleaved({"floor": round_trips(floor, speeds, full=False),
                               "exact": round_trips(spi, speeds, full=False)}, cfg.reps, cfg.batch_seconds)
        out["get_e_only"] = {"floor": median(timings["floor"]), "exact": median(timings["exact"]),
                             "ratio": median_ratio(timings["exact"], timings["floor"])}
    finally:
        for x in (floor, floor_fast, spi):
            x.close()
    return out
