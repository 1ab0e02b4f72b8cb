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
import math
import shutil
import subprocess

import numpy as np
import pytest

from restitution.fmu.describe.c_header import variables
from restitution.fmu.build.native import write_backend
from restitution.fmu.build.compile import CFLAGS

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
