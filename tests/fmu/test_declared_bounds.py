"""The declared range is the accepted range, bounds included, in every FMU (pythonfmu behind the
guard, native FMI 2.0 and FMI 3.0, both models).

FMI 2.0 and 3.0 read a variable's ``min`` and ``max`` as inclusive, and tools clip to them: each
declared bound must be accepted (and give finite outputs), and the next value outside it refused.
The bounds come from each FMU's own modelDescription.xml, read with fmpy: the test knows nothing of
the interface tables. Run in a child process: a crash fails this test, not the run."""
from __future__ import annotations

import json
import math
import subprocess
import sys

import pytest

CHILD = r'''
import json, math, sys
from fmpy import extract, read_model_description
from restitution.cosim.fmu import FmiStatusError, FmuInstance

def outside(value, bound_is_max, integer):
    if integer:
        return int(value) + (1 if bound_is_max else -1)
    return math.nextafter(float(value), math.inf if bound_is_max else -math.inf)

failures, checked = [], 0
for path in sys.argv[1:]:
    md = read_model_description(path)
    unzip = extract(path)
    outputs = [v.name for v in md.modelVariables if v.causality == "output" and v.type in ("Real", "Float64")]
    for var in md.modelVariables:
        if var.causality not in ("parameter", "input"):
            continue
        integer = var.type not in ("Real", "Float64")
        for bound_is_max, text in ((False, var.min), (True, var.max)):
            if text is None:
                continue
            value = int(text) if integer else float(text)
            checked += 1
            try:
                fmu = FmuInstance(path, unzip_dir=unzip, parameters={var.name: value})
                fmu.do_step(0.0, 1e-3)
                values = fmu.get(*outputs)
                fmu.close()
                if not all(math.isfinite(x) for x in values):
                    failures.append(f"{path}: {var.name} = {text}: non-finite outputs")
            except FmiStatusError as exc:
                failures.append(f"{path}: {var.name} = {text} (declared) refused: {exc}")
            beyond = outside(value, bound_is_max, integer)
            try:
                fmu = FmuInstance(path, unzip_dir=unzip, parameters={var.name: beyond})
                fmu.close()
                failures.append(f"{path}: {var.name} = {beyond!r} (outside the declared {text}) accepted")
            except FmiStatusError:
                pass
print("REPORT " + json.dumps({"failures": failures, "checked": checked}))
'''


def test_every_declared_min_and_max_is_accepted_and_the_next_value_refused(
        impact_fmu, ball_fmu, native_impact_fmu, native_ball_fmu, fmi3_impact_fmu, fmi3_ball_fmu):
    fmus = [impact_fmu, ball_fmu, native_impact_fmu, native_ball_fmu, fmi3_impact_fmu, fmi3_ball_fmu]
    proc = subprocess.run([sys.executable, "-c", CHILD, *map(str, fmus)], capture_output=True, text=True,
                          timeout=600)
    reports = [line for line in proc.stdout.splitlines() if line.startswith("REPORT ")]
    assert proc.returncode == 0 and reports, f"exit {proc.returncode}\n{proc.stderr[-3000:]}"
    found = json.loads(reports[-1][len("REPORT "):])
    # 6 FMUs, every bound of each: SpherePlateImpact's 10 material and geometry parameters, v_approach, the
    # tolerances and choices; BouncingBall's h0, g, v_min, e and contact_mode
    assert found["checked"] >= 6 * 8
    assert found["failures"] == []


@pytest.mark.parametrize("nu", [0.0, 0.5])
def test_the_package_accepts_the_poisson_ratio_bounds(nu):
    """nu = 0.5 (incompressible) enters the model only through E' = E/(1 - nu^2) and C(nu): finite."""
    from restitution import MATERIALS, impact

    ball, plate = MATERIALS["s2_tool_steel"], MATERIALS["al_6061"]
    params = dict(sphere_E=ball.E, sphere_nu=nu, sphere_Sy=ball.Sy, sphere_rho=ball.rho, sphere_d=6.35e-3,
                  plate_E=plate.E, plate_nu=nu, plate_Sy=plate.Sy, plate_rho=plate.rho, plate_t=6.35e-3)
    result = impact(2.0, **params)
    assert math.isfinite(result.e) and 0.0 < result.e < 1.0
    with pytest.raises(ValueError, match="0 <= nu <= 0.5"):
        impact(2.0, **dict(params, sphere_nu=math.nextafter(0.5, 1.0)))
