"""Every monitor of the assumptions (docs/assumptions.md: ``wave_delay``, ``concurrent``, ``edge_echo``,
``edge_clear``, with the ``tau0`` and ``t_contact`` they are made of) for EVERY Zener method
(restitution.model.ZENER_METHODS), from the package (:func:`restitution.impact`) and from the native C
physics (``rst_impact``, in a child process), against references from outside the code
(tests/independent.py: no import of restitution):

- lambda of Eq. (12) as printed and Zener's time unit T of Eq. (9), in mpmath;
- tau0 of each method from its own defining equation, written there: ``exact`` and ``ode``, Zener's
  Eq. (10) by an independent Radau solve, over the Hertz half-space value from its quadrature;
  ``paper_fit``, Eq. (13a) as printed (3.215 at lambda = 0); ``linear``, the first return of the damped
  oscillator of Eq. (22), pi / sqrt(1 - lambda^2/4) (pi at lambda = 0; never for lambda >= 2);
- wave_delay = tau0(lambda) / tau0(0) of the same method, concurrent = wave_delay <= 1.8136;
- t_contact = T tau0, edge_echo = (2 a / c_L) / t_contact with c_L from the Lame constants (+inf for an
  unbounded plate, a = 0 or +inf; 0 where the contact never ends), edge_clear = edge_echo >= 1.

Tolerances (relative), from each method's documented accuracy and the conditioning:
- ``paper_fit`` and ``linear`` are closed forms: only rounding separates them from the mpmath reference.
  lambda and T are products of powers of the inputs (a few tens of ulps at most); the delay's
  log-derivative in lambda is at most 0.48 lambda^1.5 = 5.3 (paper_fit, lambda = 5) and
  lambda^2/(4 - lambda^2) = 4.3 (linear, lambda = 1.8): well below 1e-13. Compared at 1e-12.
- ``exact``: its documented bound on tau0 is 1e-8 relative (docs/accuracy.md; measured 1.2e-11); the
  reference solve (rtol 1e-12) adds ~1e-11. Compared at 1e-8 + 1e-10.
- ``ode`` at its default rtol 1e-10: documented errors of tau0 up to 6.6e-11 (lambda <= 1.5) and
  4.0e-9 (lambda in (1.5, 100]) (docs/accuracy.md). Compared at 1e-8 + 1e-10 too.
- The flags are compared where the reference is farther than this tolerance from its threshold (the
  cases are chosen so, and the test checks that both values of every flag occur).
- ``paper_fit`` and ``linear`` are also compared with the true solution of Eq. (10), on lambda <= 1.5,
  within their documented accuracy there: tau0 within 1.24 % (paper_fit) and 19.6 % (linear) relative
  (docs/accuracy.md, max rel), their wave_delay within the same error of tau0(lambda) combined with that of
  their tau0(0) (3.215 and pi against 3.2181: 0.1 % and 2.4 %).
The native physics implements exact, paper_fit and linear; ``ode`` it refuses (status 2,
RST_PHYSICS_UNSUPPORTED, docs/native.md), which is checked too.
"""
from __future__ import annotations

import functools
import json
import math
import shutil
import subprocess
import sys
from pathlib import Path

import mpmath as mp
import pytest

import independent as ind
import restitution as r

METHODS = r.model.ZENER_METHODS
NATIVE = ("exact", "paper_fit", "linear")
#: The documented threshold of ``concurrent`` (docs/assumptions.md).
DELAY_LIMIT = 1.8136
#: Relative tolerance of each method against its own defining equation (see the module docstring).
TOL = {"paper_fit": 1e-12, "linear": 1e-12, "exact": 1e-8 + 1e-10, "ode": 1e-8 + 1e-10}
#: Documented max relative error of tau0 on lambda in [0, 1.5] against Eq. (10) (docs/accuracy.md), and the
#: method's tau0(0).
APPROXIMATE = {"paper_fit": (0.0124, 3.215), "linear": (0.196, math.pi)}
#: (sphere, plate) material pairs: a steel ball on aluminium (the paper's), a glass ball on steel.
PAIRS = (("s2_tool_steel", "al_6061"), ("borosilicate_glass", "stainless_440c"))
D = 6.35e-3  # [m]
SPEEDS = (2.3, 0.7)  # [m/s]
#: lambda targets: on both sides of every method's delay threshold (lambda ~ 1.5, 1.52, 1.67) and of the
#: linear method's endless contact (lambda >= 2); at 1.55 the linear delay (1.58) is between 1.5 and 1.8136
LAMBDAS = (0.05, 0.5, 1.0, 1.3, 1.55, 1.8, 2.5, 5.0)
#: edge echo ratios aimed at (from the reference contact time): inside and outside the contact; and the
#: unbounded plate, a = 0 and a = +inf
ECHOES = (0.5, 2.0)


def material(key):
    m = r.MATERIALS[key]
    return {"E": m.E, "nu": m.nu, "Sy": m.Sy, "rho": m.rho}


def mpm(x):
    return {k: mp.mpf(repr(float(value))) for k, value in x.items()}


@functools.lru_cache(maxsize=None)
def tau0_zener(lam: float):
    """tau0 of Eq. (10) by the independent solve (tests/independent.py), lambda > 0."""
    return mp.mpf(ind.solve_zener(lam)[1])


def tau0_half_space(method):
    """The method's tau0 at lambda = 0: the Hertz value (exact, ode), 3.215 (paper_fit), pi (linear)."""
    return {"paper_fit": ind.tau0_paper_fit(0.0), "linear": ind.tau0_linear(0.0)}.get(method, ind.tau0_hertz())


def tau0_of(method, lam):
    """(tau0(lambda), tau0(0)) of ``method``, independently."""
    if method in ("exact", "ode"):
        return tau0_zener(float(lam)), ind.tau0_hertz()
    return (ind.tau0_paper_fit if method == "paper_fit" else ind.tau0_linear)(lam), tau0_half_space(method)


def thickness_for(pair, v, lam):
    """The plate thickness [m] at which the independent lambda (Eq. 12, proportional to 1/t^2) is ``lam``."""
    a, b = (mpm(material(k)) for k in pair)
    lam_at_d = ind.printed_equations(a, b, D, D, v)[2]
    return float(D * mp.sqrt(lam_at_d / lam))


def reference(pair, v, t, edge, method):
    """The monitors of one case from the independent references (floats; +inf where they are)."""
    a, b = (material(k) for k in pair)
    lam = ind.printed_equations(mpm(a), mpm(b), D, t, v)[2]
    tau0, tau0_0 = tau0_of(method, lam)
    t_contact = ind.zener_time_unit(a, b, D, v) * tau0
    echo_time = mp.inf if edge in (0.0, math.inf) else 2 * mp.mpf(edge) / ind.p_wave_speed(b["E"], b["nu"], b["rho"])
    if echo_time == mp.inf:
        echo = math.inf
    else:
        echo = 0.0 if t_contact == mp.inf else float(echo_time / t_contact)
    delay = float(tau0 / tau0_0)
    return {"lam": float(lam), "tau0": float(tau0), "t_contact": float(t_contact), "wave_delay": delay,
            "edge_echo": echo, "concurrent": delay <= DELAY_LIMIT, "edge_clear": echo >= 1.0,
            "contact_ends": tau0 != mp.inf}


def cases(method):
    """(pair, v, t, edge) of every case for ``method``: each pair, speed and lambda target, with edges at
    the echo ratios of ECHOES from the method's reference contact time, and a = 0 and +inf."""
    out = []
    for pair in PAIRS:
        b = material(pair[1])
        c_l = float(ind.p_wave_speed(b["E"], b["nu"], b["rho"]))
        for v in SPEEDS:
            for lam in LAMBDAS:
                t = thickness_for(pair, v, lam)
                t_contact = reference(pair, v, t, 0.0, method)["t_contact"]
                edges = [0.01] if t_contact == math.inf else [ratio * c_l * t_contact / 2 for ratio in ECHOES]
                out += [(pair, v, t, edge) for edge in (*edges, 0.0, math.inf)]
    return out


def params(pair, t, edge):
    sphere, plate = (r.MATERIALS[k] for k in pair)
    return {**r.Sphere(sphere, D).params(), **r.Plate(plate, t).params(), "plate_edge_distance": edge}


def assert_monitors(got, want, method, where):
    """Every monitor (and tau0, t_contact, lambda) of ``got`` (a mapping) against the reference ``want``."""
    tol = TOL[method]
    assert got["lam"] == pytest.approx(want["lam"], rel=1e-12), where  # Eq. (12): a product of powers
    for name in ("tau0", "t_contact", "wave_delay", "edge_echo"):
        if math.isinf(want[name]) or want[name] == 0.0:
            assert got[name] == want[name], (where, name, got[name], want[name])
        else:
            assert got[name] == pytest.approx(want[name], rel=tol, abs=0.0), (where, name, got[name], want[name])
    assert bool(got["contact_ends"]) == want["contact_ends"], where
    # the flags, where the reference is clear of the threshold by more than the tolerance
    for flag, value, limit in (("concurrent", want["wave_delay"], DELAY_LIMIT), ("edge_clear", want["edge_echo"], 1.0)):
        assert math.isinf(value) or abs(value - limit) > 10 * tol * limit, (where, flag, value)
        assert bool(got[flag]) == want[flag], (where, flag, got[flag], value)


def flags_seen(found):
    return {(flag, bool(f[flag])) for f in found for flag in ("concurrent", "edge_clear", "contact_ends")}


@pytest.mark.parametrize("method", METHODS)
def test_the_packages_monitors_are_the_independent_ones(method):
    """plate_waves = "on": Zener computed at every lambda, by ``method``."""
    seen = []
    for pair, v, t, edge in cases(method):
        res = r.impact(v, **params(pair, t, edge), zener_method=method, plate_waves="on")
        got = {name: getattr(res, name) for name in ("lam", "tau0", "t_contact", "wave_delay", "edge_echo",
                                                      "concurrent", "edge_clear", "contact_ends")}
        assert_monitors(got, reference(pair, v, t, edge, method), method, (pair, v, t, edge))
        seen.append(got)
    expected = {("concurrent", True), ("concurrent", False), ("edge_clear", True), ("edge_clear", False),
                ("contact_ends", True)} | ({("contact_ends", False)} if method == "linear" else set())
    assert flags_seen(seen) == expected  # both sides of every threshold were tested


@pytest.mark.parametrize("method", METHODS)
def test_without_plate_waves_the_monitors_are_the_hertz_contacts(method):
    """plate_waves = "off" (a half-space, every method): wave_delay = 1, tau0 the Hertz value, t_contact the
    Hertz contact time T tau0(0); "auto" where the waves are skipped (a plate 10 m thick, lambda ~ 4e-7):
    wave_delay = 1 and tau0 the METHOD's tau0(0) (docs: 3.2181 for exact and ode, 3.215, pi)."""
    pair, v = PAIRS[0], 2.3
    a, b = (material(k) for k in pair)
    time_unit = ind.zener_time_unit(a, b, D, v)
    c_l = ind.p_wave_speed(b["E"], b["nu"], b["rho"])
    for mode, t, tau0 in (("off", D, ind.tau0_hertz()), ("auto", 10.0, tau0_half_space(method))):
        for edge in (0.01, 0.2):
            res = r.impact(v, **params(pair, t, edge), zener_method=method, plate_waves=mode)
            assert not res.plate_waves_used and res.wave_delay == 1.0 and res.concurrent, (mode, edge)
            assert res.tau0 == pytest.approx(float(tau0), rel=1e-12), (mode, res.tau0)
            assert res.t_contact == pytest.approx(float(time_unit * tau0), rel=1e-12), mode
            echo = float(2 * edge / c_l / (time_unit * tau0))
            assert res.edge_echo == pytest.approx(echo, rel=1e-12) and res.edge_clear == (echo >= 1.0), (mode, edge)


@pytest.mark.parametrize("method", sorted(APPROXIMATE))
def test_the_approximate_methods_are_within_their_documented_accuracy_of_zeners_equation(method):
    """On lambda <= 1.5 (the range their accuracy is documented on), tau0, t_contact and wave_delay of
    ``paper_fit`` and ``linear`` against those of Eq. (10) solved independently (see the module docstring)."""
    tau0_rel, tau0_0 = APPROXIMATE[method]
    hertz = float(ind.tau0_hertz())
    delay_rel = (1 + tau0_rel) / (1 - abs(tau0_0 / hertz - 1)) - 1
    for pair in PAIRS:
        for v in SPEEDS:
            for lam in (x for x in LAMBDAS if x <= 1.5):
                t = thickness_for(pair, v, lam)
                res = r.impact(v, **params(pair, t, math.inf), zener_method=method, plate_waves="on")
                true = reference(pair, v, t, math.inf, "exact")
                assert res.tau0 == pytest.approx(true["tau0"], rel=tau0_rel), (pair, v, lam)
                assert res.t_contact == pytest.approx(true["t_contact"], rel=tau0_rel), (pair, v, lam)
                assert res.wave_delay == pytest.approx(true["wave_delay"], rel=delay_rel), (pair, v, lam)


#: The child: the native physics (tests/physics_ctypes.py) on the library ARGS[0], for the cases of
#: ARGS[1]: the status and the monitors of each.
NATIVE_CHILD = r'''
import json, sys
sys.path.insert(0, sys.argv[1])
from physics_ctypes import NativePhysics
native = NativePhysics(sys.argv[2])
found = []
for v, p, method in json.loads(sys.argv[3]):
    status, out = native.call(v, p, zener_method=method, plate_waves="on")
    found.append({"status": status, **{n: getattr(out, n) for n in ("lam", "tau0", "t_contact", "wave_delay",
                 "edge_echo", "concurrent", "edge_clear", "contact_ends")}})
print("REPORT " + json.dumps(found))
'''


@pytest.fixture(scope="module")
def native_library(tmp_path_factory):
    if shutil.which("gcc") is None:
        pytest.skip("gcc is needed to compile the native physics")
    from restitution.fmu.builders.compile import compile_shared

    return compile_shared(tmp_path_factory.mktemp("monitors_native"))


def run_native(library, calls):
    tests = Path(__file__).resolve().parents[1]
    done = subprocess.run([sys.executable, "-c", NATIVE_CHILD, str(tests), str(library), json.dumps(calls)],
                          capture_output=True, text=True, timeout=600)
    reports = [line for line in done.stdout.splitlines() if line.startswith("REPORT ")]
    assert done.returncode == 0 and reports, f"exit {done.returncode}\n{done.stderr[-3000:]}"
    return json.loads(reports[-1][len("REPORT "):])


@pytest.mark.parametrize("method", METHODS)
def test_the_native_monitors_are_the_independent_ones(native_library, method):
    """The C physics, plate_waves = "on", the same cases and tolerances as the package; ``ode``: refused."""
    todo = cases(method)
    found = run_native(native_library, [[v, params(pair, t, edge), method] for pair, v, t, edge in todo])
    if method not in NATIVE:
        assert {f["status"] for f in found} == {2}  # RST_PHYSICS_UNSUPPORTED: only Python integrates Eq. (10)
        return
    for (pair, v, t, edge), got in zip(todo, found):
        assert got["status"] == 0, (pair, v, t, edge)
        assert_monitors(got, reference(pair, v, t, edge, method), method, (pair, v, t, edge))
    assert ("concurrent", False) in flags_seen(found) and ("edge_clear", False) in flags_seen(found)
