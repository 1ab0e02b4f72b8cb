"""The two-FMU bounce through ecospy's Python API (the ecos engine, plain C++, loaded into a Python
process): the native FMI 3.0 pair bounces as the native FMI 2.0 pair does under the same engine, and
its first contact falls at the closed-form free-fall time. Each run is a child process (ecos is C++
loaded into the interpreter: a crash fails one test)."""
from __future__ import annotations

import importlib.util
import json
import math
import subprocess
import sys

import pytest

H0, G = 0.3, 9.80665  # BouncingBall's defaults [m], [m/s2]

CHILD = r'''
import json, sys
from ecospy import EcosSimulation, EcosSimulationStructure
impact, ball, step = sys.argv[1], sys.argv[2], float(sys.argv[3])
readings = []
with EcosSimulationStructure() as ss:
    ss.add_model("impact", impact)
    ss.add_model("ball", ball)
    ss.make_real_connection("ball::v_approach", "impact::v_approach")
    ss.make_real_connection("impact::e", "ball::e")
    with EcosSimulation(structure=ss, step_size=step) as sim:
        sim.init()
        for until in map(float, sys.argv[4:]):
            sim.step_until(until)
            reading = {k: sim.get_real(f"ball::{k}") for k in ("t_impact", "v_impact", "e_applied", "h", "v")}
            reading["impacts"] = sim.get_integer("ball::impacts")
            reading["time"] = sim.get_time()
            readings.append(reading)
        sim.terminate()
print("REPORT " + json.dumps(readings))
'''


def _ecospy_run(impact, ball, step, *until):
    if importlib.util.find_spec("ecospy") is None:
        pytest.skip("ecospy not installed (in the dev extra)")
    proc = subprocess.run([sys.executable, "-c", CHILD, str(impact), str(ball), repr(step), *map(repr, until)],
                          capture_output=True, text=True, timeout=300)
    if "libtbb" in proc.stderr:
        pytest.skip("ecos needs Debian's libtbb12 (build_scripts/system_packages.sh installs it)")
    report = [line for line in proc.stdout.splitlines() if line.startswith("REPORT ")]
    assert proc.returncode == 0 and report, f"exit {proc.returncode}\n{proc.stdout[-2000:]}\n{proc.stderr[-3000:]}"
    return json.loads(report[-1][len("REPORT "):])


def test_ecospy_bounces_the_fmi3_pair_as_the_fmi2_pair(native_impact_fmu, native_ball_fmu, fmi3_impact_fmu,
                                                        fmi3_ball_fmu):
    """Under the same engine and step, the FMI 3.0 pair's readings equal the FMI 2.0 pair's (the same C
    physics and ball behind both versions' layers: a few ulps at most, 1e-12 relative here); the first
    contact, located inside the step in closed form, is at sqrt(2 h0 / g) whatever the coupling."""
    until = (0.3, 0.6, 1.5)
    two = _ecospy_run(native_impact_fmu, native_ball_fmu, 1e-3, *until)
    three = _ecospy_run(fmi3_impact_fmu, fmi3_ball_fmu, 1e-3, *until)
    assert [r["impacts"] for r in three] == [r["impacts"] for r in two] and three[-1]["impacts"] >= 3
    for a, b in zip(two, three):
        for key in ("t_impact", "v_impact", "e_applied", "h", "v", "time"):
            assert math.isclose(a[key], b[key], rel_tol=1e-12, abs_tol=1e-15), (key, a, b)
    first = three[0]
    assert first["impacts"] == 1
    assert math.isclose(first["t_impact"], math.sqrt(2 * H0 / G), rel_tol=1e-12)
    assert math.isclose(first["v_impact"], math.sqrt(2 * G * H0), rel_tol=1e-12)
    assert 0.0 < three[-1]["e_applied"] < 1.0
