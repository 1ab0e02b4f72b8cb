"""The FMU at the ends of its declared ranges, through both FMI 2.0 implementations (the guard in front of
pythonfmu, and the native C): each Real input and parameter at and next to both ends of its range, alone and
with the extreme geometries, gives finite results equal to the package's within conditioning
(restitution.agreement), or fmi2Discard with a logged message; never a NaN or inf output with fmi2OK,
never ``valid`` with a non-finite core output. Runs in a child process (tests/fmi_child.py)."""
from __future__ import annotations

import math
import sys

import pytest
from fmpy import extract

import restitution as r
from restitution.agreement import disagreements, tolerances
from restitution.fmu.describe.c_header import variables

from fmi_child import run_child

FMI_OK, FMI_DISCARD = 0, 2


@pytest.fixture(scope="module")
def unzipped(any_impact_fmu, tmp_path_factory):
    return extract(str(any_impact_fmu), str(tmp_path_factory.mktemp("unzipped")))


def _extremes():
    """(name, value) at and next to both ends of each Real input and parameter's declared range."""
    out = []
    for var in variables("SpherePlateImpact"):
        if var.type != "Real" or var.interval is None or var.name == "zener.ode_tolerance":
            continue
        low, high, low_open, high_open = var.interval
        values = []
        if not low_open:
            values += [low, math.nextafter(low, math.inf)]
        else:
            values += [math.nextafter(low, math.inf), low + 1e-300 if low == 0 else low * (1 + 1e-12)]
        if math.isinf(high):
            values += [1.0, 1e300, sys.float_info.max]
        else:
            values += [math.nextafter(high, -math.inf)] + ([] if high_open else [high])
            if low > 0:
                values.append(math.sqrt(low * high))
        out += [(var.name, float(v)) for v in values]
    return out


EXTREMES = _extremes()
PACKAGE_NAME = {"v_approach": "v", **{f"{b}.{k}": f"{b}_{k}" for b in ("sphere", "plate")
                                      for k in ("E", "nu", "Sy", "rho", "d", "t")}}


def test_values_at_the_ends_of_the_declared_ranges(any_impact_fmu, unzipped):
    """Finite results equal to the package's (within conditioning), or fmi2Discard with a logged
    message: never a NaN or inf output with fmi2OK, never valid with a non-finite core output."""
    code = """
    import json
    cases = json.loads(ARGS[0])
    out = []
    for base in ({}, {"plate.t": 1e-7, "sphere.d": 10.0}, {"plate.t": 100.0, "sphere.d": 1e-6}):
        for name, value in cases:
            if name in base:
                continue
            s = instance("extreme", base)
            n = len(LOG)
            st = status(s.setReal, [VR[name]], [value])
            step = status(s.doStep, 0.0, 1e-3)
            got = reals(s, ["e", "v_rebound", "jgm.e", "jgm.V_c", "jgm.V_star", "zener.e", "zener.lambda",
                            "zener.tau0", "zener.t_contact", "plate.mass_ratio", "plate.v_after"])
            valid = bool(s.getBoolean([VR["valid"]])[0])
            out.append([base, name, value, st, step, got, valid, [m for _, _, m in LOG[n:]]])
            s.terminate()
            s.freeInstance()
    report(out=out)
    """
    import json

    run = run_child(code, any_impact_fmu, unzipped, json.dumps(EXTREMES), timeout=900)
    assert run.returncode == 0 and run.report is not None, run.explain()
    fields = ("e", "v_rebound", "e_ep", "V_c", "V_star", "e_ze", "lam", "tau0", "t_contact", "mass_ratio", "v_plate")
    defaults = {v.name: v.start for v in variables("SpherePlateImpact") if v.name in PACKAGE_NAME}
    bases = ({}, {"plate.t", "sphere.d"}, {"plate.t", "sphere.d"})
    assert len(run.report["out"]) == sum(name not in base for base in bases for name, _ in EXTREMES) > 140
    for base, name, value, st, step, got, valid, messages in run.report["out"]:
        assert st == FMI_OK, (name, value, messages)
        if step == FMI_DISCARD:  # allowed: an evaluation failure, said in the log
            assert any("evaluation failed" in m for m in messages), (name, value, messages)
            assert not valid
            continue
        assert step == FMI_OK, (base, name, value, step, messages)
        settings = {PACKAGE_NAME[k]: v for k, v in {**defaults, **base, name: value}.items() if k in PACKAGE_NAME}
        options = {"effect_tolerance": value} if name == "effect_tolerance" else {}
        v = settings.pop("v")
        result = dict(zip(fields, got))
        assert not any(math.isnan(x) for x in result.values()), (base, name, value, result)
        problems = disagreements(type("R", (), result), r.impact(v, **settings, **options),
                                 *tolerances(v, settings, **options))
        assert not problems, (base, name, value, problems)
