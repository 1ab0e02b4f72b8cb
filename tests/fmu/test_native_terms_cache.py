"""The native SpherePlateImpact FMU keeps the parameter-only terms of the physics (rst_impact_terms_of) in
its instance and recomputes them only when something but v_approach changed: a parameter set between
steps, a reset, a restored FMU state. A stale cache would answer with the old parameters' numbers.

A scenario of FMI calls (sets of parameters and of v_approach, steps, FMU states, a reset) runs on the
native FMI 2.0 FMU in a child process (tests/fmi_child.py: a crash fails this test only), which reports
every output at each check. The test keeps its own account of the parameters each check should see
(the interface's start values, then every set, snapshot and reset, the preset materials from
restitution.MATERIALS) and compares each check with restitution.impact for those parameters, within
restitution.agreement's per-case tolerances (each output's conditioning), never bit for bit.
"""
from __future__ import annotations

import json
import math
import shutil

import pytest

import restitution as r
from restitution.agreement import disagreements, tolerances
from restitution.fmu.describe.c_header import variables
from restitution.model import published

from cases import FMU_FLAGS, FMU_REALS
from fmi_child import run_child

pytestmark = pytest.mark.skipif(shutil.which("gcc") is None, reason="gcc is needed to build the native FMU")

#: The child: runs the operations of ARGS[0] (JSON) on one instance; reports each check's outputs and
#: every status that was not fmi2OK.
SCENARIO = r'''
ops = json.loads(ARGS[0])
outputs = json.loads(ARGS[1])
s = instance("cache")
t, saved, checks, bad = 0.0, None, [], []
for op in ops:
    kind = op[0]
    if kind == "set":
        for name, value in op[1].items():
            f = s.setReal if TYPE[name] == "Real" else s.setInteger
            code = status(f, [VR[name]], [value])
            if code:
                bad.append([name, code])
    elif kind == "step":
        code = status(s.doStep, t, 1e-3)
        bad += [["doStep", code]] if code else []
        t += 1e-3
    elif kind == "check":
        checks.append(reals(s, outputs["reals"]) + [bool(b) for b in s.getBoolean([VR[n] for n in outputs["flags"]])])
    elif kind == "save":
        saved = s.getFMUstate(), t
    elif kind == "restore":  # the communication point too
        s.setFMUstate(saved[0])
        t = saved[1]
    elif kind == "reset":
        s.reset()
        s.setupExperiment(startTime=0.0)
        s.enterInitializationMode()
        s.exitInitializationMode()
        t = 0.0
report(checks=checks, bad=bad, log=[m for _, level, m in LOG if level >= 3])
'''

#: The Real parameters restitution.impact takes, by FMU name.
IMPACT_REALS = {"sphere.E": "sphere_E", "sphere.nu": "sphere_nu", "sphere.Sy": "sphere_Sy", "sphere.rho": "sphere_rho",
                "sphere.d": "sphere_d", "plate.E": "plate_E", "plate.nu": "plate_nu", "plate.Sy": "plate_Sy",
                "plate.rho": "plate_rho", "plate.t": "plate_t", "plate.edge_distance": "plate_edge_distance",
                "effect_tolerance": "effect_tolerance"}
OPTIONS = {"restitution_model": r.RESTITUTION_MODELS, "zener_method": r.ZENER_METHODS,
           "plasticity": r.EFFECT_MODES, "plate_waves": r.EFFECT_MODES}


def _preset(code: int):
    """The material of a <body>.material code (the interface's codes, in restitution.MATERIALS)."""
    codes = {v.name: v for v in variables("SpherePlateImpact")}["sphere.material"].codes
    return r.MATERIALS[{c: name for name, c in codes.items()}[code]]


def expected_impact(values: dict):
    """restitution.impact for the FMU's variable values ``values``: (published result, tolerances, flips)."""
    kwargs = {arg: values[name] for name, arg in IMPACT_REALS.items()}
    for body in ("sphere", "plate"):
        if values[f"{body}.material"] > 0:
            m = _preset(values[f"{body}.material"])
            kwargs.update({f"{body}_E": m.E, f"{body}_nu": m.nu, f"{body}_Sy": m.Sy, f"{body}_rho": m.rho})
    if kwargs["plate_edge_distance"] == 0.0:
        kwargs["plate_edge_distance"] = math.inf  # the FMU's 0: an unbounded plate
    options = {k: OPTIONS[k][int(values[k]) - (1 if k in ("restitution_model", "zener_method") else 0)]
               for k in OPTIONS}
    v = values["v_approach"]
    keywords = {k: kwargs.pop(k) for k in ("plate_edge_distance", "effect_tolerance")}  # impact()'s keywords
    tol, flips = tolerances(v, kwargs, **keywords, **options)
    return published(r.impact(v, **kwargs, **keywords, **options).as_dict()), tol, flips


def run_scenario(fmu, tmp_path, ops):
    """Run ``ops`` in the child; for each check, the outputs the FMU gave and the parameters the test
    says it holds."""
    from fmpy import extract

    start = {v.name: v.start for v in variables("SpherePlateImpact") if v.causality in ("parameter", "input")}
    values, saved, expected = dict(start), None, []
    for op in ops:  # the test's own account of the FMU's variables
        if op[0] == "set":
            values.update(op[1])
        elif op[0] == "check":
            expected.append(dict(values))
        elif op[0] == "save":
            saved = dict(values)
        elif op[0] == "restore":
            values = dict(saved)
        elif op[0] == "reset":
            values = dict(start)
    outputs = {"reals": list(FMU_REALS), "flags": list(FMU_FLAGS)}
    child = run_child(SCENARIO, fmu, extract(str(fmu), str(tmp_path / "unzip")), json.dumps(ops),
                      json.dumps(outputs))
    assert child.returncode == 0 and child.report, child.explain()
    assert child.report["bad"] == [] and child.report["log"] == [], child.report
    assert len(child.report["checks"]) == len(expected)
    return list(zip(child.report["checks"], expected))


def assert_checks_match_the_package(pairs):
    for i, (got_values, values) in enumerate(pairs):
        names = list(FMU_REALS) + list(FMU_FLAGS)
        got = dict(zip(names, got_values))
        result = type("R", (), {**{FMU_REALS[k]: got[k] for k in FMU_REALS},
                                **{FMU_FLAGS[k]: got[k] for k in FMU_FLAGS}})
        expected, tol, flips = expected_impact(values)
        problems = disagreements(result, type("E", (), expected), tol, flips)
        assert not problems, f"check {i} with {values}: {problems}"


def test_parameters_set_between_steps_reach_the_physics(native_impact_fmu, tmp_path):
    """Each parameter kind set between steps (a geometry, a material, a preset material, the edge, an option,
    a tolerance) changes the next step's outputs as the package says; steps at new speeds in between
    reuse the terms."""
    ops = [["set", {"v_approach": 2.3}], ["step"], ["check"],
           ["set", {"v_approach": 1.1}], ["step"], ["check"],
           ["set", {"plate.t": 3e-3}], ["step"], ["check"],  # v_approach unchanged: only the terms changed
           ["set", {"v_approach": 0.4}], ["step"], ["check"],
           ["set", {"sphere.E": 110e9, "sphere.rho": 4500.0}], ["step"], ["check"],
           ["set", {"sphere.material": 9}], ["step"], ["check"],  # chrome steel: a preset replaces E, nu, Sy, rho
           ["set", {"sphere.material": 0, "plate.material": 6}], ["step"], ["check"],
           ["set", {"plate.edge_distance": 0.02, "v_approach": 3.0}], ["step"], ["check"],
           ["set", {"zener_method": 2}], ["step"], ["check"],
           ["set", {"restitution_model": 2, "plasticity": 1}], ["step"], ["check"],
           ["set", {"plate_waves": 1, "effect_tolerance": 1e-3}], ["step"], ["check"],
           ["set", {"sphere.d": 2e-2}], ["check"],  # read without a step: the outputs are evaluated lazily
           ["set", {"v_approach": 0.0}], ["step"], ["check"]]
    assert_checks_match_the_package(run_scenario(native_impact_fmu, tmp_path, ops))


def test_reset_and_restored_states_recompute_the_terms(native_impact_fmu, tmp_path):
    """After fmi2Reset the start values hold again, and after fmi2SetFMUstate the saved parameters: the
    outputs follow them, not the terms of the parameters set last."""
    ops = [["set", {"plate.t": 2e-3, "zener_method": 3, "v_approach": 1.5}], ["step"], ["check"],
           ["save"],
           ["set", {"plate.t": 5e-2, "zener_method": 1, "sphere.material": 3}], ["step"], ["check"],
           ["restore"], ["check"],  # the saved parameters and speed, read at once
           ["set", {"v_approach": 0.7}], ["step"], ["check"],
           ["restore"], ["set", {"v_approach": 0.9}], ["step"], ["check"],
           ["reset"], ["check"],  # the start values
           ["set", {"v_approach": 2.3}], ["step"], ["check"]]
    assert_checks_match_the_package(run_scenario(native_impact_fmu, tmp_path, ops))
