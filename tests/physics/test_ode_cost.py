"""The ``ode`` Zener method does bounded work over the whole declared domain and stays accurate.

Zener's ODE: I. Green, Nonlinear Dyn (2022), Eq. (10)-(11). What is checked, against numbers from
outside restitution.zener_ode:

* accuracy: ``ode`` agrees with an independent solve written out here (LSODA on Zener's first-order
  form, its own start series, its own event) from lambda = 0 up to the largest lambda the declared
  domain reaches (~6e18, computed here from Eq. (12) with the domain's corners), within the sum of
  the two accuracies; the paper's own value at lambda = 1.5; the limit e_ze lambda^5 -> 0.679293063936;
* work: right-hand-side evaluations counted here, by wrapping scipy's solve_ivp (not the counts the
  code reports about itself, which are compared with them), bounded on a grid over lambda in
  [0, 100] and the declared tolerances 1e-14 ... 1e-2, and zero above lambda = 100;
* the tolerance floor, the work guard and continuity/monotonicity at the switch lambda = 100.

No wall-clock time is asserted anywhere (benchmarks/bench_ode_cost.py measures time).
"""
import math
import warnings

import numpy as np
import pytest
import scipy.integrate

import restitution as r
import restitution.zener_ode as zo
from restitution.model import DOMAIN
from restitution.zener_ode import solve_zener_ode

pytestmark = pytest.mark.numerics

#: lim lambda^5 e_ze (large-lambda limit of Eq. (10)), as pinned in tests/physics/test_zener_exact.py
E_INF_LITERAL = 0.679293063936
#: the declared range of zener.ode_tolerance (the FMU's min/max)
RTOL_LOW, RTOL_HIGH = 1e-14, 1e-2
#: the documented bound on right-hand-side evaluations of one call (docs/ode_cost.md: ~18 000 measured)
DOCUMENTED_NFEV_BOUND = 25_000


def rel(a, b):
    return abs(a / b - 1.0)


def lambda_eq12(v, Ea, nua, rhoa, d, Eb, nub, rhob, t):
    """Eq. (12) written out: pi^(3/5)/sqrt(3) ((d/2)/t)^2 (v/v')^(1/5) (rhoa/rhob)^(3/5) (Ea'/(Ea'+Eb'))^(2/5)."""
    Ea_, Eb_ = Ea / (1.0 - nua**2), Eb / (1.0 - nub**2)
    vp = math.sqrt(Eb_ / rhob)
    return (math.pi**0.6 / math.sqrt(3.0) * (0.5 * d / t) ** 2 * (v / vp) ** 0.2 * (rhoa / rhob) ** 0.6
            * (Ea_ / (Ea_ + Eb_)) ** 0.4)


#: the corner of the declared domain with the largest lambda: fastest, densest, stiffest sphere; largest
#: sphere on the thinnest, lightest, softest plate (nu_b = 0 minimises E_b'; nu_a just below 0.5)
CORNER = dict(v=DOMAIN["v"][1], sphere_E=DOMAIN["sphere_E"][1], sphere_nu=0.4999, sphere_Sy=1e9,
              sphere_rho=DOMAIN["sphere_rho"][1], sphere_d=DOMAIN["sphere_d"][1], plate_E=DOMAIN["plate_E"][0],
              plate_nu=0.0, plate_Sy=1e9, plate_rho=DOMAIN["plate_rho"][0], plate_t=DOMAIN["plate_t"][0])
LAMBDA_MAX = lambda_eq12(CORNER["v"], CORNER["sphere_E"], CORNER["sphere_nu"], CORNER["sphere_rho"],
                         CORNER["sphere_d"], CORNER["plate_E"], CORNER["plate_nu"], CORNER["plate_rho"],
                         CORNER["plate_t"])


def reference(lam, rtol=1e-12):
    """Independent (e_ze, tau0): LSODA on sigma' = p - lam sigma^1.5, p' = -sigma^1.5, from
    sigma = tau - (2/5) lam tau^2.5, p = 1 - (2/5) tau^2.5 at a tiny tau (next terms < 1e-16 rel.)."""
    ts = min(1e-6, (1e-16 / max(lam, 1.0) ** 3) ** 0.25)
    y0 = [ts - 0.4 * lam * ts**2.5, 1.0 - 0.4 * ts**2.5]

    def f(t, y):
        q = y[0] * math.sqrt(y[0]) if y[0] > 0.0 else 0.0
        return [y[1] - lam * q, -q]

    def jac(t, y):
        s = 1.5 * math.sqrt(y[0]) if y[0] > 0.0 else 0.0
        return [[-lam * s, 1.0], [-s, 0.0]]

    def back(t, y):
        return y[0]

    back.terminal, back.direction = True, -1
    scale = min(1.0, lam**-5) if lam > 0 else 1.0
    t_end = 30.0 + 3.0 * lam * (5.0 * math.log1p(lam) + 1.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        sol = scipy.integrate.solve_ivp(f, (ts, t_end), y0, method="LSODA", jac=jac, rtol=rtol,
                                        atol=rtol * 1e-6 * scale, events=back)
    assert sol.status == 1, sol.message
    return -float(sol.y_events[0][0][1]), float(sol.t_events[0][0])


@pytest.fixture
def counted(monkeypatch):
    """Counts right-hand-side evaluations of every solve_ivp call made through scipy.integrate."""
    calls = {"nfev": 0, "solves": 0}
    original = scipy.integrate.solve_ivp

    def wrapper(fun, *args, **kwargs):
        calls["solves"] += 1

        def counting(t, y):
            calls["nfev"] += 1
            return fun(t, y)

        return original(counting, *args, **kwargs)

    monkeypatch.setattr(scipy.integrate, "solve_ivp", wrapper)
    return calls


def test_the_declared_domain_reaches_lambda_beyond_1e18():
    assert 1e18 < LAMBDA_MAX < 1e19
    assert rel(r.impact(**CORNER, zener_method="exact").lam, LAMBDA_MAX) <= 1e-12


@pytest.mark.parametrize("lam", [0.0, 0.5, 1.5, 5.0, 10.0, 10.5, 30.0, 99.9, 100.5, 1e3, 1e5, 1e10, 1e18,
                                 LAMBDA_MAX])
def test_ode_agrees_with_an_independent_solve_over_the_whole_range(lam):
    e_ref, t_ref = reference(lam)  # ~50 x 1e-12 = 5e-11 (LSODA's achieved error)
    e, t = solve_zener_ode(lam, rtol=1e-12)  # <= ~1.5e-11 (DOP853, LSODA, or the large-lambda form)
    assert rel(e, e_ref) <= 2e-10 and rel(t, t_ref) <= 2e-10, (lam, e, e_ref, t, t_ref)
    for rtol in (1e-6, RTOL_HIGH):  # loose tolerances: LSODA's error is up to ~10-50 rtol
        e, t = solve_zener_ode(lam, rtol=rtol)
        assert rel(e, e_ref) <= 100 * rtol and rel(t, t_ref) <= 100 * rtol, (lam, rtol, e, e_ref)


def test_paper_value_and_large_lambda_limit():
    """Sec. 4 of the paper: lambda = 1.5 gives e_ze = 0.066, tau0 = 5.8; and the large-lambda limits."""
    e, t = solve_zener_ode(1.5, rtol=RTOL_LOW)
    assert e == pytest.approx(0.066, abs=5e-4) and t == pytest.approx(5.8, abs=0.05)
    for lam in (150.0, 1e5, 1e10, 1e18, LAMBDA_MAX):
        e, t = solve_zener_ode(lam, rtol=RTOL_LOW)
        assert e * lam**5 == pytest.approx(E_INF_LITERAL, rel=1e-10)
        u = lam ** (-5.0 / 3.0)  # tau0/lambda = 5 ln lambda + G0 + 3 u + 0.9575 u^2 + O(u^3)
        assert t / lam == pytest.approx(5.0 * math.log(lam) - 0.359367056648 + 3.0 * u + 0.9575 * u * u, rel=1e-9)


def test_work_is_bounded_over_the_declared_tolerances_and_lambda(counted):
    worst = 0
    for lam in (0.0, 0.3, 1.5, 5.0, 9.99, 10.0, 10.01, 20.0, 55.0, 99.0, 100.0):
        for rtol in (RTOL_LOW, 1e-13, 1e-12, 1e-10, 1e-8, 1e-6, 1e-4, RTOL_HIGH):
            before = counted["nfev"]
            e, t, info = solve_zener_ode(lam, rtol=rtol, full_output=True)
            nfev = counted["nfev"] - before
            assert nfev == info["nfev"], (lam, rtol, nfev, info)  # the self-report is honest
            assert nfev <= DOCUMENTED_NFEV_BOUND, (lam, rtol, nfev)
            assert info["method"] in ("DOP853", "LSODA"), (lam, rtol, info)  # no Radau fallback
            assert 0.0 < e <= 1.0 and t >= 3.21806545, (lam, rtol, e, t)
            worst = max(worst, nfev)
    assert worst < zo.MAX_RHS_EVALUATIONS / 2  # the guard is far from the work done on the domain
    # above lambda = 100, no solve at all, whatever the tolerance
    solves = counted["solves"]
    for lam in (100.000001, 1.4e5, 1.3e18, LAMBDA_MAX):
        for rtol in (RTOL_LOW, 1e-10, RTOL_HIGH):
            e, t = solve_zener_ode(lam, rtol=rtol)
            assert math.isfinite(e) and math.isfinite(t) and e > 0.0
    assert counted["solves"] == solves


def test_tolerances_tighter_than_the_floor_give_the_floors_result(counted):
    for lam, floor in ((5.0, zo.RTOL_FLOOR_NONSTIFF), (50.0, zo.RTOL_FLOOR_STIFF)):
        a = solve_zener_ode(lam, rtol=RTOL_LOW, full_output=True)
        b = solve_zener_ode(lam, rtol=floor, full_output=True)
        assert a[:2] == b[:2] and a[2]["rtol"] == floor
    assert zo.RTOL_FLOOR_NONSTIFF == pytest.approx(100 * np.finfo(float).eps)
    with pytest.raises(ValueError, match="rtol"):
        solve_zener_ode(1.0, rtol=0.0)


def test_the_work_guard_stops_a_runaway_call(monkeypatch, counted):
    monkeypatch.setattr(zo, "MAX_RHS_EVALUATIONS", 400)
    for lam, method in ((50.0, None), (50.0, "Radau"), (8.0, None)):
        before = counted["nfev"]
        with pytest.raises(RuntimeError, match="work bound"):
            solve_zener_ode(lam, rtol=1e-12, method=method)
        assert counted["nfev"] - before <= 400 + 1
    with pytest.raises(RuntimeError, match="work bound"):  # what the model (and the FMU's slave) sees
        r.zener.zener_solution(50.0, "ode", 1e-12)


def test_continuous_and_monotonic_across_the_switch_at_lambda_100():
    lams = (99.0, 99.999999, 100.0, math.nextafter(100.0, math.inf), 101.0)
    sols = [solve_zener_ode(x, rtol=1e-12) for x in lams]
    e = [s[0] for s in sols]
    t = [s[1] for s in sols]
    assert rel(e[2], e[3]) <= 1e-10 and rel(t[2], t[3]) <= 1e-10  # solve at 100, form just above
    assert e[0] > e[2] > e[4] and t[0] < t[2] < t[4]


def test_the_fmu_domain_corner_through_impact():
    res = r.impact(**CORNER, zener_method="ode", ode_rtol=RTOL_LOW, plate_waves="on")
    assert rel(res.lam, LAMBDA_MAX) <= 1e-12
    assert res.e_ze * res.lam**5 == pytest.approx(E_INF_LITERAL, rel=1e-10)
    for name, value in res.as_dict().items():
        if not isinstance(value, bool) and name != "edge_echo":  # +inf: the plate is unbounded (the default)
            assert math.isfinite(value), name
