"""BouncingBall's model exchange in hosts that detect events differently (native FMUs, FMI 2.0 and 3.0).

- A forward-Euler host that detects a crossing as z * z_prev < 0, with z_prev read once after each
  event and nowhere else (the FMI Compliance Checker's loop): it must see every contact of a drop, so
  after every event the indicator must be strictly positive (in flight) or the ball at rest.
- fmpy's CVode (``simulate_fmu``): with slow rebounds (v_min down to its declared minimum) and e up to
  0.95, the solver hands over events where the interpolated velocity has either sign; the ball must
  end at rest, never below the plate by more than the integration error.

Each run is in a child process (a crash fails one test, not the run). The references are the closed
form of a bouncing ball (script_host.free_fall_contacts) and properties of the physics."""
from __future__ import annotations

import json
import math
import subprocess
import sys

import pytest

from script_host import free_fall_contacts

EULER_HOST = r'''
import ctypes, json, math, sys
import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Model
from fmpy.fmi3 import FMU3Model

path, h0, e, v_min, dt, stop = sys.argv[1], *map(float, sys.argv[2:7])
md = read_model_description(path)
vr = {v.name: v.valueReference for v in md.modelVariables}
three = md.fmiVersion.startswith("3")
unzip = extract(path)
cls = FMU3Model if three else FMU2Model
fmu = cls(guid=md.instantiationToken if three else md.guid, unzipDirectory=unzip,
          modelIdentifier=md.modelExchange.modelIdentifier, instanceName="euler")
set_real = fmu.setFloat64 if three else fmu.setReal
get_real = fmu.getFloat64 if three else fmu.getReal
if three:
    fmu.instantiate()
    fmu.enterInitializationMode(startTime=0.0)
else:
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
set_real([vr["h0"], vr["v_min"]], [h0, v_min])
set_real([vr["e"]], [e])
fmu.exitInitializationMode()
x, dx, z = np.zeros(2), np.zeros(2), np.zeros(1)
px, pdx, pz = (a.ctypes.data_as(ctypes.POINTER(ctypes.c_double)) for a in (x, dx, z))

def event_iteration():
    while True:
        if three:
            needed = fmu.updateDiscreteStates()[0]
        else:
            needed = fmu.newDiscreteStates()[0]
        if not needed:
            break
    fmu.enterContinuousTimeMode()

def indicators():
    fmu.getEventIndicators(pz, 1)
    return float(z[0])

event_iteration()
z_prev = indicators()
t, lowest, after_events = 0.0, 0.0, []
fmu.getContinuousStates(px, 2)
while t < stop:
    (fmu.getContinuousStateDerivatives if three else fmu.getDerivatives)(pdx, 2)
    t += dt
    x += dt * dx
    fmu.setTime(t)
    fmu.setContinuousStates(px, 2)
    lowest = min(lowest, float(x[0]))
    if indicators() * z_prev < 0.0:
        fmu.enterEventMode()
        event_iteration()
        fmu.getContinuousStates(px, 2)
        z_prev = indicators()
        after_events.append(z_prev)
    fmu.completedIntegratorStep()
impacts = (fmu.getInt32 if three else fmu.getInteger)([vr["impacts"]])[0]
at_rest = (fmu.getBoolean)([vr["at_rest"]])[0]
v_approach = get_real([vr["v_approach"]])[0]
print("REPORT " + json.dumps({"impacts": int(impacts), "at_rest": bool(at_rest), "lowest": lowest,
                              "v_approach_sign": math.copysign(1.0, v_approach),
                              "h_end": float(x[0]), "after_events": after_events}))
'''

CVODE_HOST = r'''
import json, sys
import numpy as np
from fmpy import simulate_fmu

path, h0, stop = sys.argv[1], float(sys.argv[2]), float(sys.argv[3])
runs = json.loads(sys.argv[4])
found = []
for e, v_min in runs:
    result = simulate_fmu(path, fmi_type="ModelExchange", stop_time=stop, output_interval=1e-3, relative_tolerance=1e-8,
                          start_values={"e": e, "v_min": v_min, "h0": h0}, output=["h", "v", "impacts", "at_rest"])
    found.append({"e": e, "v_min": v_min, "lowest": float(np.min(result["h"])), "h_end": float(result["h"][-1]),
                  "v_end": float(result["v"][-1]), "at_rest": bool(result["at_rest"][-1]),
                  "impacts": int(result["impacts"][-1])})
print("REPORT " + json.dumps(found))
'''


def _child(script, *args, timeout=600):
    proc = subprocess.run([sys.executable, "-c", script, *map(str, args)], capture_output=True, text=True,
                          timeout=timeout)
    reports = [line for line in proc.stdout.splitlines() if line.startswith("REPORT ")]
    assert proc.returncode == 0 and reports, f"exit {proc.returncode}\n{proc.stderr[-3000:]}"
    return json.loads(reports[-1][len("REPORT "):])


@pytest.fixture(params=["fmi2", "fmi3"])
def me_ball(request, native_ball_fmu, fmi3_ball_fmu):
    return native_ball_fmu if request.param == "fmi2" else fmi3_ball_fmu


G = 9.80665


def test_a_host_comparing_with_the_indicator_after_the_last_event_sees_every_contact(me_ball):
    """Forward Euler (dt = 10 us) with the z * z_prev < 0 rule: the count of contacts is the closed
    form's. Euler changes each approach speed by at most g dt per step of lateness plus its own
    O(g dt t) drift, about 1e-4 m/s here: the closed form's rest decision has a margin of more than
    10 % on both sides (checked below), so the count is exact. After every event the indicator is > 0
    (in flight) or the ball at rest (1 m), and the ball goes below the plate by at most one step."""
    h0, e, v_min, dt = 0.3, 0.8, 0.45, 1e-5
    times, speeds = free_fall_contacts(h0, G, e, v_min)
    assert e * speeds[-2] > 1.1 * v_min and e * speeds[-1] < v_min / 1.1  # the margin the count relies on
    found = _child(EULER_HOST, me_ball, h0, e, v_min, dt, times[-1] + 0.5)
    assert found["impacts"] == len(times)
    assert found["at_rest"] and found["h_end"] == 0.0
    assert found["v_approach_sign"] == 1.0  # +0.0 at rest: a host printing it shows no "-0"
    assert all(z > 0.0 for z in found["after_events"])
    assert found["lowest"] >= -(speeds[0] + G * dt) * dt


@pytest.mark.parametrize("v_min", [1e-3, 1e-6])
def test_slow_rebounds_in_the_euler_host_never_sink_through_the_plate(me_ball, v_min):
    """Rebounds down to v_min = 1 mm/s and to the declared minimum, 1 um/s, whose last flights (2 v/g,
    0.2 ns) are far shorter than the step. Forward Euler finds a contact up to one step late, with up
    to 2 g dt = 2e-4 m/s more approach speed than it had when it left: so with e = 0.5 the ball comes
    to rest where that floor rebounds below v_min (1e-3), and otherwise keeps hopping on the energy the
    host's own steps give it (as any model would in that host). Either way no contact is missed: after
    every event the indicator is > 0, and the ball never sinks below the plate by more than one step
    of travel."""
    h0, e, dt = 0.05, 0.5, 1e-5
    found = _child(EULER_HOST, me_ball, h0, e, v_min, dt, 1.0)
    assert all(z > 0.0 for z in found["after_events"])
    assert found["lowest"] >= -(math.sqrt(2 * G * h0) + G * dt) * dt
    assert found["h_end"] >= -(math.sqrt(2 * G * h0) + G * dt) * dt
    if e * 2 * G * dt < v_min:
        assert found["at_rest"] and found["h_end"] == 0.0
    else:
        assert found["impacts"] > len(free_fall_contacts(h0, G, e, 1e-3)[0])


def test_cvode_runs_with_slow_rebounds_end_at_rest_and_never_below_the_plate(me_ball):
    """fmpy's CVode over 10 s, e up to 0.95, v_min from 1e-5 m/s down to the declared minimum: every run
    ends at rest (the closed form's rest time is at most t_fall + (2 v_0/g)/(1 - e) = 5.9 s from
    h0 = 0.1 m), with h never below -1e-9 m at any output point or event. CVode's absolute tolerance on
    h is its relative one times h's nominal (here h0, the first flight's scale: fmpy reads nominals
    once), and a flight's h is computed no better than that: at RELATIVE_TOLERANCE = 1e-8, 1e-9 m; at
    fmpy's default 1e-5 the rebounds near rest (micrometres high) dip 1e-7 m below the plate before
    CVode locates their contact, the solver's own error, which the FMU then takes as the contact."""
    from fmpy import read_model_description

    declared = float(next(v.min for v in read_model_description(str(me_ball)).modelVariables if v.name == "v_min"))
    h0 = 0.1
    v0 = math.sqrt(2 * G * h0)
    assert v0 / G + 2 * v0 / G / (1 - 0.95) < 10.0
    runs = [(e, v_min) for e in (0.8, 0.9, 0.95) for v_min in (1e-5, 1e-6, declared)]
    for run in _child(CVODE_HOST, me_ball, h0, 10.0, json.dumps(runs)):
        where = f"e = {run['e']}, v_min = {run['v_min']}"
        assert run["at_rest"] and run["h_end"] == 0.0 and run["v_end"] == 0.0, where
        assert run["lowest"] >= -1e-9, where
        assert run["impacts"] > 10, where
