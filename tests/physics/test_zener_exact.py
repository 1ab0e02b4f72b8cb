"""The "exact" Zener method (tabulated ODE solution) and the "ode" method it is checked against.

Zener's ODE: I. Green, Nonlinear Dyn (2022), Eq. (10)-(11).  The reference below is an
independent solve: LSODA (scipy) at rtol = 1e-13 on Zener's first-order form, written out
here, whereas the table was made with a three-phase DOP853/Radau solve in sqrt(sigma) as the
variable near the ends (build_scripts/make_zener_table.py).  The reference agrees with that
solver to ~1e-11.
"""
import math
import warnings

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.special import beta

from restitution.zener_exact import (E_INF, LAMBDA_TABLE_MAX, TAU0_LAMBDA0, _asym,
                                     zener_exact, zener_exact_solution)
from restitution.zener_ode import solve_zener_ode, solve_zener_ode_array

TAU0_HERTZ = 2.0 * (5.0 / 4.0) ** 0.4 * 0.4 * beta(0.4, 0.5)  # closed form at lambda = 0


def reference(lam, rtol=1e-13):
    """Independent (e_ze, tau0): LSODA on sigma' = p - lam sigma^1.5, p' = -sigma^1.5."""
    # start series: sigma = tau - (2/5) lam tau^2.5 - (4/35) tau^3.5 + (3/20) lam^2 tau^4,
    # p = 1 - (2/5) tau^2.5 + (3/20) lam tau^4
    ts = 1e-6
    y0 = [ts - 0.4 * lam * ts**2.5 - 4.0 / 35.0 * ts**3.5 + 0.15 * lam**2 * ts**4,
          1.0 - 0.4 * ts**2.5 + 0.15 * lam * ts**4]

    def f(t, y):
        q = y[0] * math.sqrt(y[0]) if y[0] > 0.0 else 0.0
        return [y[1] - lam * q, -q]

    def jac(t, y):
        r = 1.5 * math.sqrt(y[0]) if y[0] > 0.0 else 0.0
        return [[-lam * r, 1.0], [-r, 0.0]]

    def hit(t, y):
        return y[0]

    hit.terminal, hit.direction = True, -1
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sol = solve_ivp(f, (ts, 50.0 + 3.0 * lam * (5.0 * math.log1p(lam) + 1.0)), y0,
                        method="LSODA", jac=jac, rtol=rtol, atol=1e-40, events=hit)
    assert sol.status == 1, sol.message
    return -float(sol.y_events[0][0][1]), float(sol.t_events[0][0])


def rel(a, b):
    return abs(a / b - 1.0)


# ~40 lambda values over [0, 100]: mostly where the physics is, all but a few between the
# table nodes (k/128), a few exactly on nodes and the end points
_rng = np.random.default_rng(2022)
LAMS = np.unique(np.concatenate([
    [0.0, 0.75, 1.5, 100.0],
    _rng.uniform(0.0, 1.5, 14),
    _rng.uniform(1.5, 6.0, 10),
    np.exp(_rng.uniform(math.log(6.0), math.log(100.0), 12)),
    [1.0 / 256.0, 2.390625 + 1.0 / 256.0],
]))


@pytest.fixture(scope="module")
def ref_values():
    return {float(x): reference(float(x)) for x in LAMS}


# (a) ----------------------------------------------------------------------------------------
def test_exact_matches_independent_solution(ref_values):
    worst = {"[0,1.5]": [0.0, 0.0], "(1.5,100]": [0.0, 0.0]}
    for lam, (e_ref, t_ref) in ref_values.items():
        e, t = zener_exact(lam)
        key = "[0,1.5]" if lam <= 1.5 else "(1.5,100]"
        worst[key][0] = max(worst[key][0], rel(e, e_ref))
        worst[key][1] = max(worst[key][1], rel(t, t_ref))
        assert rel(e, e_ref) <= 1e-8, (lam, e, e_ref)
        assert rel(t, t_ref) <= 1e-8, (lam, t, t_ref)
    print("max rel err (e, tau0):", worst)


# (b) ----------------------------------------------------------------------------------------
def test_lambda_zero_closed_form():
    e, t = zener_exact(0.0)
    assert abs(e - 1.0) <= 1e-9
    assert abs(t - TAU0_HERTZ) <= 1e-9 * TAU0_HERTZ
    assert t == pytest.approx(3.2180655, abs=5e-8)
    assert zener_exact(0) == (e, t)
    assert abs(TAU0_LAMBDA0 - TAU0_HERTZ) <= 1e-12
    e, t = solve_zener_ode(0.0, rtol=1e-12)
    assert abs(e - 1.0) <= 1e-10 and abs(t / TAU0_HERTZ - 1.0) <= 1e-10


# (c) ----------------------------------------------------------------------------------------
def test_zener_values_quoted_in_paper():
    """Sec. 4 (after Eq. (20)): lambda = 1.5 gives e_ze = 0.066 and tau0 = 5.8."""
    e, t = zener_exact(1.5)
    assert e == pytest.approx(0.066, abs=5e-4)
    assert t == pytest.approx(5.8, abs=0.05)


# (d) ----------------------------------------------------------------------------------------
def test_monotonic_on_dense_grid():
    lam = np.concatenate([np.linspace(0.0, 100.0, 400_001), np.geomspace(100.0, 1e6, 5001)[1:]])
    e, t = zener_exact(lam)
    assert np.all(np.diff(e) < 0.0)
    assert np.all(np.diff(t) > 0.0)
    assert np.all(e > 0.0) and np.all(e <= 1.0)


# (e) ----------------------------------------------------------------------------------------
def test_array_and_scalar_paths_agree_to_rounding():
    """Not bit identity between the two paths: within a few ulps. Up to lambda = 100 both evaluate
    the same cubic by Horner's rule with + and * (4 ulps covers a compiler contracting a step into
    an FMA); above, e_ze = E_INF lambda^-5 and tau0 = lambda (5 ln lambda + g) go through pow/log,
    where numpy's SIMD kernels and libm differ by an ulp, and both forms have condition number <= 5
    in their arguments (1e-15 = 4.5 ulps)."""
    eps = np.finfo(float).eps
    lam = np.concatenate([LAMS, [0.0, 1e-300, 99.999999, 100.0, 100.0 + 1e-12, 150.0, 1e3, 1e7]])
    e_arr, t_arr = zener_exact(lam)
    for i, x in enumerate(lam):
        e, t = zener_exact(float(x))
        assert type(e) is float and type(t) is float
        if x <= LAMBDA_TABLE_MAX:
            assert rel(e, e_arr[i]) <= 4 * eps and rel(t, t_arr[i]) <= 4 * eps, x
        else:
            assert rel(e, e_arr[i]) <= 1e-15 and rel(t, t_arr[i]) <= 1e-15, x
        assert zener_exact(np.float64(x)) == (e, t)
    # shapes: any shape in, same shape out; lists; 0-d arrays; empty arrays
    grid = lam.reshape(2, -1) if lam.size % 2 == 0 else lam[:-1].reshape(2, -1)
    e2, t2 = zener_exact(grid)
    assert e2.shape == grid.shape and np.array_equal(e2.ravel(), zener_exact(grid.ravel())[0])
    assert np.array_equal(t2.ravel(), zener_exact(grid.ravel())[1])
    e3, t3 = zener_exact([[0.5, 2.0], [7.0, 30.0]])
    assert isinstance(e3, np.ndarray) and e3.shape == (2, 2) and e3[1, 1] == zener_exact(30.0)[0]
    e0, t0 = zener_exact(np.array(1.5))
    assert isinstance(e0, np.ndarray) and e0.shape == () and float(t0) == zener_exact(1.5)[1]
    ee, te = zener_exact(np.zeros((0, 3)))
    assert ee.shape == (0, 3) and te.shape == (0, 3)
    assert zener_exact(3) == zener_exact(3.0)


# (f) ----------------------------------------------------------------------------------------
@pytest.mark.parametrize("lam", [0.0, 0.5, 1.5, 5.0, 30.0])
def test_ode_method_converges_with_rtol(lam):
    e_ref, t_ref = reference(lam)
    errs = []
    for rtol in (1e-3, 1e-6, 1e-9, 1e-12):
        e, t = solve_zener_ode(lam, rtol=rtol)
        err = max(rel(e, e_ref), rel(t, t_ref))
        errs.append(err)
        assert err <= 100.0 * rtol + 2e-11, (lam, rtol, err)
    assert errs[-1] < errs[1] < errs[0]
    assert errs[-1] <= 1e-10
    # and the exact method agrees with the tightest ode solve
    e, t = zener_exact(lam)
    assert rel(e, e_ref) <= 1e-8 and rel(t, t_ref) <= 1e-8


def test_ode_array_wrapper_and_large_lambda_robustness():
    e, t = solve_zener_ode_array(np.array([[0.0, 1.5], [20.0, 1e4]]), rtol=1e-8)
    assert e.shape == (2, 2)
    e_x, t_x = zener_exact(np.array([[0.0, 1.5], [20.0, 1e4]]))
    assert np.all(np.abs(e / e_x - 1.0) < 1e-6) and np.all(np.abs(t / t_x - 1.0) < 1e-6)
    for rtol in (1e-3, 1e-10):  # LSODA at loose tolerance falls back to Radau up there
        e, t = solve_zener_ode(1e6, rtol=rtol)
        assert rel(e, E_INF * 1e-30) < 1e3 * rtol + 1e-9


# (g) ----------------------------------------------------------------------------------------
@pytest.mark.parametrize("lam", [150.0, 1000.0, 1e4])
def test_large_lambda_form(lam):
    e_ref, t_ref = reference(lam)
    e, t = zener_exact(lam)
    assert rel(e, e_ref) <= 1e-8 and rel(t, t_ref) <= 1e-8
    assert e == pytest.approx(E_INF * lam**-5, rel=1e-14)
    # the deficit 1 - e_ze (~1e-11 below 1 here): to rounding of 1, from the scalar and the array path
    for d in (zener_exact_solution(lam)[1], zener_exact_solution(np.array([lam]))[1][0]):
        assert d <= 1.0 and abs(d - (1.0 - e_ref)) <= 1e-15, (lam, d)
    u = lam ** (-5.0 / 3.0)
    assert t == pytest.approx(lam * (5.0 * math.log(lam) - 0.359367056648 + 3.0 * u), rel=1e-8)


def test_continuous_at_table_end():
    assert LAMBDA_TABLE_MAX == 100.0
    for d in (1e-12, 1e-9):  # table just below, large-lambda form just above
        lo, hi = zener_exact(100.0 - d), zener_exact(100.0 + d)
        assert rel(lo[0], hi[0]) <= 1e-7 and rel(lo[1], hi[1]) <= 1e-7
    # the table node at 100 and the large-lambda form evaluated at 100 agree to rounding
    table = zener_exact(100.0)
    form = _asym(100.0)[::2]
    assert rel(table[0], form[0]) <= 1e-13 and rel(table[1], form[1]) <= 1e-13
    # the slopes match too (C^1): one-sided differences over 1e-4 agree to ~1e-8
    h = 1e-4
    for k in (0, 1):
        left = (zener_exact(100.0)[k] - zener_exact(100.0 - h)[k]) / h
        right = (zener_exact(100.0 + h)[k] - zener_exact(100.0)[k]) / h
        assert rel(left, right) <= 1e-3


def test_asymptotic_constants():
    """e_ze lambda^5 -> E_INF already for lambda >= 4 (corrections ~exp(-3 lambda^(5/3)))."""
    assert E_INF == pytest.approx(0.679293063936, abs=1e-11)
    for lam in (4.0, 10.0, 60.0):
        assert zener_exact(lam)[0] * lam**5 == pytest.approx(E_INF, rel=1e-9)


# (h) ----------------------------------------------------------------------------------------
@pytest.mark.parametrize("bad", [-1, -1.0, -1e-300, float("nan"), float("inf"), -math.inf,
                                 np.float64("nan")])
def test_invalid_lambda_raises(bad):
    with pytest.raises(ValueError, match=r"lambda.*\[0, inf\).*got lambda="):
        zener_exact(bad)
    with pytest.raises(ValueError, match="lambda"):
        zener_exact(np.array([0.5, bad, 2.0]))
    with pytest.raises(ValueError, match="lambda"):
        solve_zener_ode(bad)


def test_invalid_message_names_value():
    with pytest.raises(ValueError, match=r"got lambda=-1\.0"):
        zener_exact(-1.0)
    with pytest.raises(ValueError, match=r"got lambda=nan \(at index \(1, 0\)\)"):
        zener_exact(np.array([[1.0, 2.0], [np.nan, 3.0]]))


# (h) ----------------------------------------------------------------------------------------
# Everything the method reads from its data file (the pieces, h, the table end, the large-lambda
# constants) is built once at import, by _tables. Rebuilding it here, at test time, from the data
# file, installing it in the module and checking the rebuilt method against the independent solves
# tests the loader and the construction themselves (a mutation tool switches mutants on per call,
# after import, so the import-time build is out of its reach otherwise).
_TABLE_GLOBALS = ("_H", "_INV_H", "LAMBDA_TABLE_MAX", "E_INF", "TAU0_LAMBDA0", "_U_MAX", "_G_CHEB", "_COEF",
                  "_COEF_ARR", "_COEF_COLS")


def _rebuilt(monkeypatch, table):
    import restitution.zener_exact as ze

    built = ze._tables(table)
    assert len(built) == len(_TABLE_GLOBALS)
    for name, value in zip(_TABLE_GLOBALS, built):
        monkeypatch.setattr(ze, name, value)
    return ze


def test_table_rebuilt_at_test_time_matches_independent_solution(monkeypatch, ref_values):
    import restitution.zener_exact as ze

    table = ze._load_table()
    assert {"k", "e", "de", "tau0", "dtau0", "h"} <= set(table)
    ze = _rebuilt(monkeypatch, table)
    # the documented layout: nodes on lambda = k/128 up to lambda = 100; the constants as the closed forms
    # and the independent solves give them
    assert ze._H == 1.0 / 128.0 and ze._INV_H * ze._H == 1.0 and ze.LAMBDA_TABLE_MAX == 100.0
    assert abs(ze.TAU0_LAMBDA0 / TAU0_HERTZ - 1.0) <= 1e-12
    e10 = reference(10.0)[0]  # e_ze lambda^5 = E_INF to < 1e-13 from lambda = 4 (module doc)
    assert rel(ze.E_INF, e10 * 1e5) <= 1e-9
    lams = np.array(sorted(ref_values))
    e_arr, d_arr, t_arr = ze.zener_exact_solution(lams)
    for i, lam in enumerate(lams):
        e_ref, t_ref = ref_values[float(lam)]
        e, d, t = ze.zener_exact_solution(float(lam))
        for got in ((e, d, t), (e_arr[i], d_arr[i], t_arr[i])):
            assert rel(got[0], e_ref) <= 1e-8 and rel(got[2], t_ref) <= 1e-8, (lam, got, e_ref, t_ref)
            # the deficit pieces: 1 - e_ze to the reference's absolute accuracy, and
            # relative accuracy where it is small (lambda -> 0: 1.7302 lambda)
            assert abs(got[1] - (1.0 - e_ref)) <= 1e-8 * max(e_ref, 1e-3), (lam, got[1], 1.0 - e_ref)
    tiny = 1e-9
    assert rel(ze.zener_exact_solution(tiny)[1], 1.7301733 * tiny) < 1e-6
    # above the table: the large-lambda form with the rebuilt constants, scalar and array paths
    big = [150.0, 1000.0, 1e4]
    e_big, d_big, t_big = ze.zener_exact_solution(np.array(big + [50.0]))
    for i, lam in enumerate(big):
        e_ref, t_ref = reference(lam)
        for e, d, t in (ze.zener_exact_solution(lam), (e_big[i], d_big[i], t_big[i])):
            assert rel(e, e_ref) <= 1e-8 and rel(t, t_ref) <= 1e-8, (lam, e, t, e_ref, t_ref)
    assert rel(e_big[3], reference(50.0)[0]) <= 1e-8  # the table's share of a mixed array


def test_table_must_end_at_lambda_100():
    """zener_exact_solution's fast path has lambda = 100 written out: a data file that ends elsewhere is refused,
    with a message naming the file and both ends."""
    import restitution.zener_exact as ze

    good = ze._load_table()
    for end in (50.0, 100.5):
        with pytest.raises(RuntimeError, match=r"^zener_table\.npz: expected a table up to lambda = 100, got "
                                               + str(end).replace(".", r"\.") + "$"):
            ze._tables(dict(good, lam_table_max=np.float64(end)))


def test_table_with_a_bad_node_layout_is_refused():
    import restitution.zener_exact as ze

    good = ze._load_table()
    k = good["k"]
    swapped = k.copy()
    swapped[[5, 6]] = swapped[[6, 5]]
    repeated = k.copy()
    repeated[6] = repeated[5]
    ends_at_table_max = k[: int(np.searchsorted(k * good["h"], 100.0)) + 1]
    assert ends_at_table_max[-1] * good["h"] == 100.0  # the table has a node at lambda = 100
    for broken_k in (k + 1, k[::-1], k[:-200], swapped, repeated, ends_at_table_max):
        with pytest.raises(RuntimeError, match="bad node layout"):
            ze._tables(dict(good, k=broken_k))
