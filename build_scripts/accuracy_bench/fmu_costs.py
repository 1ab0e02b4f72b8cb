"""FMU round trips through fmpy: SpherePlateImpact per method, against a trivial pythonfmu FMU with the
same variables (the floor the wrapper itself sets), built in the same run."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .config import Config, RANGES
from .timing import timed, interleaved, median, median_ratio


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
    from restitution.fmu.build import FMUS, build_one
    from restitution.fmu.models import table
    from restitution.fmu.build_guard import make_standalone

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
        # The same native loader as the project's FMUs: a like-for-like floor (the shim's
        # forwarding is part of every call), and the fix for pythonfmu 0.7's exit double-free,
        # which a plain pythonfmu binary would bring into this process.
        make_standalone(out[name])
    out["counts"] = counts
    return out


class _Slave:
    """An instantiated FMU2Slave with the value references of its input and outputs."""

    def __init__(self, path: Path, work: Path):
        from fmpy import extract, read_model_description
        from fmpy.fmi2 import FMU2Slave

        md = read_model_description(str(path))
        self.unzipped = extract(str(path), unzipdir=str(work / f"unzipped_{path.stem}"))
        self.slave = FMU2Slave(guid=md.guid, unzipDirectory=self.unzipped,
                               modelIdentifier=md.coSimulation.modelIdentifier, instanceName=path.stem)
        self.slave.instantiate()
        self.slave.setupExperiment(startTime=0.0)
        self.slave.enterInitializationMode()
        self.slave.exitInitializationMode()
        self.vr = {v.name: v.valueReference for v in md.modelVariables}
        outs = [v for v in md.modelVariables if v.causality == "output"]
        self.reals = [v.valueReference for v in outs if v.type == "Real"]
        self.bools = [v.valueReference for v in outs if v.type == "Boolean"]
        self.input = next(v.valueReference for v in md.modelVariables if v.causality == "input")
        self.t = 0.0

    def round_trips(self, speeds, full: bool = True):
        """run(n): n passes of (setReal v, doStep, getReal outputs[, getBoolean outputs]) over ``speeds``."""
        s, vin, reals, bools = self.slave, [self.input], self.reals if full else self.reals[:1], self.bools
        values = [[float(x)] for x in speeds]
        h = 1e-3

        def run(n):
            t = self.t
            for _ in range(n):
                for value in values:
                    s.setReal(vin, value)
                    s.doStep(t, h)
                    t += h
                    s.getReal(reals)
                    if full:
                        s.getBoolean(bools)
            self.t = t
            return n * len(values)
        return run

    def close(self):
        self.slave.terminate()
        self.slave.freeInstance()


def fmu_costs(cfg: Config, fmus: dict, work: Path) -> dict:
    floor = _Slave(fmus["BenchWrapperFloor"], work)
    floor_fast = _Slave(fmus["BenchWrapperFloorOnePass"], work)
    spi = _Slave(fmus["SpherePlateImpact"], work)
    d = 6.35e-3
    speeds = list(np.linspace(0.5, 5.0, 97))  # distinct consecutive values: every set is a new impact
    out = {"costs": {}, "ratios": {}, "exact_over_paper_fit": {}, "get_e_only": {}}
    s = spi.slave
    codes = {"exact": 1, "paper_fit": 2, "linear": 3, "ode": 4}
    try:
        for rng, t_over_d in zip(RANGES, (1.0, 0.1)):
            s.setReal([spi.vr["plate.t"]], [t_over_d * d])
            s.setReal([spi.vr["v_approach"]], [speeds[0]])
            lam = s.getReal([spi.vr["zener.lambda"]])[0]
            s.setReal([spi.vr["v_approach"]], [speeds[-1]])
            lam_hi = s.getReal([spi.vr["zener.lambda"]])[0]
            out.setdefault("lambda_span", {})[rng] = (min(lam, lam_hi), max(lam, lam_hi), t_over_d)

            def with_method(method, rtol=None):
                def run(n):
                    s.setInteger([spi.vr["zener_method"]], [codes[method]])
                    if rtol is not None:
                        s.setReal([spi.vr["zener.ode_tolerance"]], [rtol])
                    return spi.round_trips(speeds)(n)
                return run
            variants = {"trivial FMU (floor)": floor.round_trips(speeds),
                        "trivial FMU, one-pass getters": floor_fast.round_trips(speeds),
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
                    s.setInteger([spi.vr["zener_method"]], [4])
                    s.setReal([spi.vr["zener.ode_tolerance"]], [rtol])
                    return spi.round_trips(ode_speeds)(n)
                ts = [timed(run_ode, 1) for _ in range(cfg.ode_reps)]
                out["costs"][(label, rng)] = median(ts)
                out["ratios"][(label, rng)] = median(ts) / out["costs"][("trivial FMU (floor)", rng)]
            s.setInteger([spi.vr["zener_method"]], [1])
        # the same with a single output read (set v, step, get e)
        s.setReal([spi.vr["plate.t"]], [d])
        timings = interleaved({"floor": floor.round_trips(speeds, full=False),
                               "exact": spi.round_trips(speeds, full=False)}, cfg.reps, cfg.batch_seconds)
        out["get_e_only"] = {"floor": median(timings["floor"]), "exact": median(timings["exact"]),
                             "ratio": median_ratio(timings["exact"], timings["floor"])}
    finally:
        for x in (floor, floor_fast, spi):
            x.close()
    return out
