"""The native BouncingBall backend (rst_native_ball.c) moves the ball as the Python slave does.

The C is compiled with the generated BouncingBall interface header and driven through ctypes on a
value store by value reference; the Python slave (bouncing_ball_slave.BouncingBall, authoritative)
is driven through its own methods with the same parameters, COR inputs and steps. Both evaluate the
same closed forms (a square root and a few products per contact), so their states may differ by a
few ulps per contact, accumulated linearly over the contacts: compared at 1e-12 relative (times
plus 1e-12 s absolute), never bit for bit; the integer and Boolean state must be equal.
"""
from __future__ import annotations

import ctypes
import json
import math
import shutil
import subprocess

import numpy as np
import pytest
from fmpy import extract

from fmi_child import run_child
from independent import INDICATOR_EXTREME, INDICATOR_IN_FLIGHT, assert_indicator
from restitution.fmu.describe.c_header import variables
from restitution.fmu.builders.native import write_backend
from restitution.fmu.builders.compile import CFLAGS

pytestmark = pytest.mark.skipif(shutil.which("gcc") is None, reason="gcc is needed to compile the native backend")

TABLE = {v.name: v for v in variables("BouncingBall")}
STATE_KEYS = {"h": "h", "v": "v", "v_approach": "v_approach", "impacts": "impacts", "t_impact": "t_impact",
              "v_impact": "v_impact", "t_rebound": "t_rebound", "v_rebound": "v_rebound", "e_applied": "e_applied",
              "in_contact": "in_contact", "at_rest": "at_rest", "flight.t_start": "t_start",
              "flight.h_start": "h_start", "flight.v_start": "v_start"}


@pytest.fixture(scope="module")
def ball(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("ball")
    src = tmp / "src"
    src.mkdir()
    write_backend("BouncingBall", src)
    lib = tmp / "libball.so"
    subprocess.run(["gcc", *CFLAGS, "-fPIC", "-shared", "-o", str(lib), str(src / "rst_native_ball.c"), "-lm"],
                   check=True, capture_output=True, text=True)
    so = ctypes.CDLL(str(lib))
    so.rst_ball_initialize.argtypes = (ctypes.POINTER(ctypes.c_double), ctypes.c_double)
    so.rst_ball_do_step.argtypes = (ctypes.POINTER(ctypes.c_double), ctypes.c_double, ctypes.c_double)
    return so


def python_slave():
    import bouncing_ball_slave

    return bouncing_ball_slave.BouncingBall(instance_name="native-ball-test", visible=False)


def same(a, b):
    if isinstance(b, bool) or isinstance(b, int):
        return a == b
    if math.isnan(b):
        return math.isnan(a)
    return a == b or abs(a - b) <= 1e-12 * max(abs(a), abs(b)) + 1e-12


@pytest.mark.parametrize("contact_mode", [1, 2])
@pytest.mark.parametrize("h0,g,v_min,start,step", [(0.3, 9.80665, 0.1, 0.0, 1e-3), (1.0, 9.81, 0.05, 2.5, 7e-3),
                                                    (0.01, 1.62, 1e-3, 0.0, 0.05), (2.0, 9.81, 0.5, 0.0, 0.1)])
def test_ball_follows_the_python_slave(ball, contact_mode, h0, g, v_min, start, step):
    so = ball
    store = (ctypes.c_double * len(TABLE))()
    params = {"h0": h0, "g": g, "v_min": v_min, "contact_mode": contact_mode, "e": 1.0}
    for name, value in params.items():
        store[TABLE[name].vr] = value
    py = python_slave()
    py._values.update(params)
    py.setup_experiment(start)
    py.exit_initialization_mode()
    so.rst_ball_initialize(store, start)
    rng = np.random.default_rng(int(h0 * 1000) + contact_mode)
    t = start
    contacts = 0
    for k in range(3000):
        e = float(rng.choice([rng.uniform(0.3, 0.95), rng.uniform(-0.2, 0.3)], p=[0.97, 0.03]))
        py._values["e"] = e
        store[TABLE["e"].vr] = e
        assert py.do_step(t, step)
        so.rst_ball_do_step(store, t, step)
        t += step
        for name, key in STATE_KEYS.items():
            expected = py._s[key]
            got = store[TABLE[name].vr]
            if isinstance(expected, bool):
                got = bool(got)
            elif isinstance(expected, int):
                got = int(got)
            assert same(got, expected), f"step {k}: {name} = {got!r}, Python slave {expected!r}"
        contacts = py._s["impacts"]
        if py._s["at_rest"]:
            break
    assert contacts >= 3  # the comparison went through several contacts


# --- the contact indicator by value: h + max(v, 0)^2/(2 g) in flight, 1 m at rest (docs/host_contract.md),
# --- against its closed form in exact rational arithmetic (tests/independent.py: apex_height_exact, with
# --- the error bound of its evaluation in doubles, assert_indicator); the native model exchange's is in
# --- test_model_exchange.py


def python_ball(g):
    import bouncing_ball_slave

    ball = bouncing_ball_slave.BouncingBall(instance_name="indicator-test", visible=False)
    ball._values["g"] = g
    return ball


@pytest.mark.parametrize("g", [3.7, 9.80665])
def test_the_python_indicator_is_the_apex_height_in_flight_and_1_m_at_rest(g):
    """The Python ball's function and its derivative update (what its FMU reports): the same closed form
    and the same bound as the native one; at rest 1 m."""
    import bouncing_ball_slave

    ball = python_ball(g)
    for h, v in INDICATOR_IN_FLIGHT:
        assert_indicator(bouncing_ball_slave.contact_indicator(h, v, g), h, v, g)
        ball._s.update(h=h, v=v, at_rest=False, in_contact=False)
        ball._update_derivatives()
        assert_indicator(ball._s["contact_indicator"], h, v, g)
    ball._s.update(h=0.0, v=0.0, at_rest=True)
    ball._update_derivatives()
    assert ball._s["contact_indicator"] == 1.0


def test_the_python_indicator_stays_finite_for_any_finite_state():
    """The Python twin of the native repro: finite, and the closed form or DBL_MAX."""
    import bouncing_ball_slave

    for g, h, v in INDICATOR_EXTREME:
        assert_indicator(bouncing_ball_slave.contact_indicator(h, v, g), h, v, g, ulps=4)
        ball = python_ball(g)
        ball._s.update(h=h, v=v, at_rest=False, in_contact=False)
        ball._update_derivatives()
        assert_indicator(ball._s["contact_indicator"], h, v, g, ulps=4)
    assert bouncing_ball_slave.contact_indicator(-1e308, 2e154, 1e6) < -0.99e308


#: The child: co-simulation, contact_mode = 2 (immediate), e = 0.5; the indicator and the state at each
#: communication point of ARGS[0] (seconds).
CS_CHILD = r'''
points = json.loads(ARGS[0])
s = instance("cs", {"h0": 0.3, "g": 9.80665, "e": 0.5, "contact_mode": 2})
t, rows = 0.0, []
for end in points:
    s.doStep(currentCommunicationPoint=t, communicationStepSize=end - t)
    t = end
    rows.append(reals(s, ["h", "v", "contact_indicator", "flight.h_start", "flight.v_start"]))
s.terminate()
s.freeInstance()
report(rows=rows)
'''


def test_the_co_simulation_indicator_follows_the_flight(any_ball_fmu, tmp_path):
    """Both FMI 2.0 implementations (pythonfmu and native), co-simulation: the indicator reported at each
    communication point is the apex height of the flight, h_s + v_s^2/(2 g) of the flight's start while it
    rises, h(t) = 0.3 - g t^2/2 on the drop. Dropped from 0.3 m the ball meets the plate at t1 = 0.247 s
    and rebounds at half its speed, to an apex of 0.3/4 m at t1 + 0.124 s. The reported h and v come
    from a parabola (a few roundings of terms up to 2 h0 = 0.6 m): within 1e-13 m (about 100 ulps of 0.6 m)."""
    g, h0 = 9.80665, 0.3
    t1 = math.sqrt(2 * h0 / g)
    points = [0.1, 0.2, t1 + 0.02, t1 + 0.1, t1 + 0.2]
    unzip = extract(str(any_ball_fmu), str(tmp_path / "unzip"))
    child = run_child(CS_CHILD, any_ball_fmu, unzip, json.dumps(points))
    assert child.returncode == 0 and child.report is not None, child.explain()
    rows = child.report["rows"]
    for t, (h, v, z, h_start, v_start) in zip(points, rows):
        if t < t1:
            assert v < 0.0 and z == pytest.approx(h0 - g * t * t / 2, abs=1e-13) and z == h, (t, z)
        else:
            v_up = 0.5 * math.sqrt(2 * g * h0)
            apex = v_up ** 2 / (2 * g)  # = h0 / 4
            assert v_start == pytest.approx(v_up, rel=1e-14) and h_start == 0.0
            falling = t - t1 > v_up / g
            want = v_up * (t - t1) - g * (t - t1) ** 2 / 2 if falling else apex  # h(t), then the apex
            assert z == pytest.approx(want, abs=1e-13), (t, z, want)
            assert (v < 0.0) == falling


# --- the free flight: the C ball's contacts where restitution.flight.flight_to_plate, the one Python form
# --- the slave, the co-simulation master and the calibration share, puts them
#: Both sides evaluate v_hit = sqrt(v^2 + 2 g h) and t_start + (v + v_hit)/g: seven correctly rounded
#: operations on non-negative terms (no cancellation to amplify a rounding), each side within 4 ulps of the
#: exact value, so within 8 ulps of each other (the same expression in the same order: equal in practice).
FLIGHT_ULPS = 8


@pytest.mark.parametrize("h0,g,e", [(0.3, 9.80665, 0.8), (2.0, 1.62, 0.5), (1e-3, 9.81, 0.95), (50.0, 24.79, 0.3)])
def test_the_c_ball_lands_where_the_python_flight_puts_it(ball, h0, g, e):
    from restitution.flight import flight_to_plate

    store = (ctypes.c_double * len(TABLE))()
    for name, value in {"h0": h0, "g": g, "v_min": 1e-6, "contact_mode": 1, "e": e}.items():
        store[TABLE[name].vr] = value
    ball.rst_ball_initialize(store, 0.0)
    at = {name: TABLE[name].vr for name in ("impacts", "t_impact", "v_impact", "flight.t_start", "flight.h_start",
                                            "flight.v_start")}
    fall, v1 = flight_to_plate(h0, 0.0, g)
    step = min(fall, 2.0 * e**3 * v1 / g) / 3.7  # shorter than the first four flights: one contact a step
    t, checked = 0.0, 0
    while checked < 4:
        start = (store[at["flight.t_start"]], store[at["flight.h_start"]], store[at["flight.v_start"]])
        ball.rst_ball_do_step(store, t, step)
        t += step
        if store[at["impacts"]] > checked:
            checked = int(store[at["impacts"]])
            duration, v_hit = flight_to_plate(start[1], start[2], g)
            for got, want in ((store[at["t_impact"]], start[0] + duration), (store[at["v_impact"]], v_hit)):
                assert abs(got - want) <= FLIGHT_ULPS * math.ulp(want), (checked, got, want)
    assert start[1] == 0.0 < start[2]  # the last flight checked started at the plate, going up
