"""The monitors of the model's assumptions through every FMU (pythonfmu, native FMI 2.0, native FMI 3.0)
in fmpy: the outputs are the package's published values, and an impact outside the validated domain
is logged once per instance and condition, with fmi2Warning / fmi3Warning in category
logStatusWarning, in restitution.assumptions' words, while every call returns OK (fmpy's simulate_fmu
raises on anything worse). Each simulation runs in a child process: simulate_fmu deletes the pythonfmu
FMU's folder when done, which a later pythonfmu instantiation in the same process may not survive."""
import json
import math
import subprocess
import sys

import pytest

import restitution as r
from restitution.assumptions import departures
from restitution.model import published

MONITORS = ("monitor.wave_delay", "monitor.edge_echo", "monitor.concurrent", "monitor.edge_clear")
FIELDS = ("wave_delay", "edge_echo", "concurrent", "edge_clear")
WARNING = 1  # fmi2Warning and fmi3Warning
#: the issue's thin plate: 0.5 mm of Al 6061 under the default 1/4 in S2 steel ball at 3 m/s (lambda = 17,
#: e < 0), struck 10 mm from an edge; the FMUs' defaults are the paper's Table 3 pair
THIN = {"plate.t": 0.5e-3, "v_approach": 3.0, "plate.edge_distance": 0.01}


def package(v, t, edge):
    ball, plate = r.MATERIALS["s2_tool_steel"], r.MATERIALS["al_6061"]
    res = r.impact(v, **r.Sphere(ball, 6.35e-3).params(), **r.Plate(plate, t).params(), plate_edge_distance=edge)
    return published(res.as_dict())


#: The child: simulate_fmu with debug logging on; prints the last row and every (status, category, message).
CHILD = r"""
import json, sys
from fmpy import simulate_fmu
fmu, start, outputs, stop = sys.argv[1], json.loads(sys.argv[2]), json.loads(sys.argv[3]), float(sys.argv[4])
said = []
result = simulate_fmu(fmu, start_values=start, output=outputs, stop_time=stop, output_interval=stop / 10,
                      debug_logging=True, logger=lambda *args: said.append(args[-3:]))
last = {name: (bool(result[-1][name]) if result.dtype[name].kind == "b" else float(result[-1][name]))
        for name in outputs}
print(json.dumps({"last": last, "said": [[int(s), c.decode(), m.decode()] for s, c, m in said]}))
"""


def simulate(fmu, start_values, stop_time=0.01):
    """(the outputs at the last time, [(status, category, message), ...]) of one simulate_fmu run."""
    outputs = list(MONITORS) + ["e"]
    done = subprocess.run([sys.executable, "-c", CHILD, str(fmu), json.dumps(start_values), json.dumps(outputs),
                           repr(stop_time)], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    data = json.loads(done.stdout.strip().splitlines()[-1])
    return data["last"], [tuple(m) for m in data["said"]]


def test_the_monitors_are_the_packages_published_values(any_version_impact_fmu):
    last, _ = simulate(any_version_impact_fmu, THIN)
    want = package(3.0, 0.5e-3, 0.01)
    for name, field in zip(MONITORS, FIELDS):
        if isinstance(want[field], bool):
            assert bool(last[name]) == want[field], name
        else:  # ratios of tau0 and of a wave time to the contact time: a few ulps of conditioning
            assert last[name] == pytest.approx(want[field], rel=1e-12), name


def test_an_unbounded_plate_publishes_the_echo_cap(any_version_impact_fmu):
    last, messages = simulate(any_version_impact_fmu, {"v_approach": 2.3})
    assert last["monitor.edge_echo"] == 1e9 and bool(last["monitor.edge_clear"])
    assert not [m for m in messages if m[0] == WARNING]  # the paper's case: nothing to say
    assert math.isclose(last["monitor.wave_delay"], package(2.3, 6.35e-3, 0.0)["wave_delay"], rel_tol=1e-12)


def test_a_departure_is_logged_once_per_instance_and_condition(any_version_impact_fmu):
    """Ten steps of the same impact, one message per condition, in the package's words."""
    _, messages = simulate(any_version_impact_fmu, THIN)
    warned = [(category, text) for status, category, text in messages if status == WARNING]
    expected = [text for _name, text in departures(package(3.0, 0.5e-3, 0.01))]
    assert [text for _c, text in warned] == expected and len(expected) == 3
    assert {category for category, _t in warned} == {"logStatusWarning"}
