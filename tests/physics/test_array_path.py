"""The array mode of impact() against evaluations from outside it.

The array mode folds what depends on the parameters alone into Python floats, takes v^(1/5) once for
Eq. (9) and Eq. (12), evaluates Eq. (8) in place without masks and gathers the exact method's table
once per coefficient. These tests hold it to

* the paper's equations as printed, in mpmath (tests/independent.py), for e_ep, lambda and T, within
  bounds derived here from the rounding of each form (never bit identity);
* the scalar mode, one impact at a time, within the conditioning of each output (tests/agree.py), on
  arrays that mix several material pairs, speeds of 0, V* below 1 and beyond the fit range, lambda
  where ``plate_waves="auto"`` skips Zener and beyond the table, bounded and unbounded plates;
* broadcasting: scalar and array inputs of different shapes give the broadcast shape, case by case
  what the scalar mode gives;
* input checks: a bad value anywhere in an array is refused and named, as before the checks became
  two reductions.
"""
from __future__ import annotations

import math

import mpmath as mp
import numpy as np
import pytest

import restitution as r
from restitution import _num, jgm, zener
from agree import assert_agree, stack
from cases import PAIRS, params_for
from independent import e45_printed, printed_equations

EPS = float(np.finfo(float).eps)
NAMES = ("sphere_E", "sphere_nu", "sphere_Sy", "sphere_rho", "sphere_d",
         "plate_E", "plate_nu", "plate_Sy", "plate_rho", "plate_t")
OPTIONS = [dict(), dict(plasticity="on", plate_waves="on"), dict(plasticity="off", plate_waves="auto"),
           dict(restitution_model="e44", zener_method="paper_fit"), dict(zener_method="linear", plate_waves="on"),
           dict(effect_tolerance=1e-3)]


def one_by_one(v, params, edge, **options):
    """impact() of each case alone, in Python floats (the scalar mode), stacked field by field."""
    v, edge = np.broadcast_arrays(v, edge)
    arrays = {k: np.broadcast_to(x, v.shape) for k, x in params.items()}
    return stack([r.impact(float(v.flat[i]), **{k: float(x.flat[i]) for k, x in arrays.items()},
                           plate_edge_distance=float(edge.flat[i]), **options) for i in range(v.size)])


def mixed_cases():
    """Several pairs, speeds from 0 to 10 km/s and thickness ratios from 1e-3 to 1e3: V* below 1, near 1
    and above 1000, lambda from ~1e-12 (skipped by auto) to beyond the table (> 100), e < 0 for thin plates."""
    rng = np.random.default_rng(11)
    pairs = list(PAIRS)
    n = 240
    which = rng.integers(len(pairs), size=n)
    v = 10.0 ** rng.uniform(-8.0, 4.0, n)
    v[::13] = 0.0
    t_over_d = 10.0 ** rng.uniform(-3.0, 3.0, n)
    rows = [params_for(pairs[k], float(x)) for k, x in zip(which, t_over_d)]
    params = {name: np.array([row[name] for row in rows], dtype=float) for name in NAMES}
    edge = np.where(rng.random(n) < 0.5, 10.0 ** rng.uniform(-4.0, 1.0, n), 0.0)
    edge[::7] = math.inf
    return v, params, edge


@pytest.mark.parametrize("options", OPTIONS, ids=lambda o: ",".join(f"{k}={v}" for k, v in o.items()) or "default")
def test_mixed_pairs_and_regions_agree_with_one_impact_at_a_time(options):
    v, params, edge = mixed_cases()
    got = r.impact(v, **params, plate_edge_distance=edge, **options)
    lam, v_star = np.asarray(got.lam), np.asarray(got.V_star)
    # the regions this is meant to cover are in the set
    assert np.any(v == 0.0) and np.any((v_star > 0.0) & (v_star < 1.0)) and np.any(v_star > 1000.0)
    assert np.any(lam > 100.0) and np.any((lam > 0.0) & (r.model.ZENER_SLOPE_BOUND * lam < 1e-6))
    assert_agree(got, one_by_one(v, params, edge, **options), v, params, f"mixed cases {options}", **options)


def test_one_pair_with_scalar_parameters_agrees_with_one_impact_at_a_time():
    """The common sweep: one sphere on one pair, arrays of v and t (the parameters' terms computed once, as
    floats), with speeds of 0, an edge at a finite distance (the echo of one plate in one division)."""
    v = np.concatenate([[0.0, 1e-9], np.geomspace(1e-3, 5e3, 60)])
    t = np.geomspace(1e-5, 1.0, v.size)[::-1]
    params = dict(params_for("s2/al6061"), plate_t=t)
    for edge in (0.05, 0.0, math.inf):
        got = r.impact(v, **params, plate_edge_distance=edge)
        assert_agree(got, one_by_one(v, params, edge), v, params, f"edge {edge}")
        echo = np.asarray(got.edge_echo)
        assert np.all(echo[v == 0.0] == math.inf) and np.all(np.asarray(got.t_contact)[v == 0.0] == 0.0)
        assert np.all(np.asarray(got.T)[v == 0.0] == math.inf)
        if edge in (0.0, math.inf):
            assert np.all(echo == math.inf) and np.all(got.edge_clear)


def test_broadcasting_scalar_and_array_inputs():
    """v of shape (4, 1), t of shape (1, 5), the sphere's diameter an array of shape (5,), the rest floats:
    every field has the broadcast shape (4, 5) and its own memory, and each case is what it is alone."""
    v = np.array([[0.0], [0.3], [3.0], [300.0]])
    t = np.array([[1e-4, 1e-3, 6.35e-3, 0.05, 1.0]])
    d = np.array([1e-3, 3e-3, 6.35e-3, 2e-2, 5e-2])
    params = dict(params_for("glass/al6061"), plate_t=t, sphere_d=d)
    got = r.impact(v, **params, plate_edge_distance=0.1)
    arrays = [getattr(got, name) for name in r.ImpactResult.__dataclass_fields__]
    for a in arrays:
        assert a.shape == (4, 5) and a.flags.writeable and not np.shares_memory(a, v) and not np.shares_memory(a, t)
    assert not any(np.shares_memory(a, b) for i, a in enumerate(arrays) for b in arrays[i + 1:])
    flat = {k: np.broadcast_to(x, (4, 5)).ravel() for k, x in params.items()}
    v_flat = np.broadcast_to(v, (4, 5)).ravel()
    ones = one_by_one(v_flat, flat, 0.1)
    assert_agree(type("R", (), {k: np.ravel(getattr(got, k)) for k in vars(ones)}), ones, v_flat, flat, "broadcast")


def test_speed_scalar_with_array_parameters():
    """A scalar speed with an array of thicknesses: e_ep and V* are computed once and broadcast."""
    t = np.geomspace(1e-4, 1e-1, 9)
    params = dict(params_for("s2/al6061"), plate_t=t)
    got = r.impact(2.3, **params)
    assert got.e.shape == (9,) and np.all(got.e_ep == got.e_ep[0]) and np.all(got.V_star == got.V_star[0])
    assert_agree(got, one_by_one(np.full(9, 2.3), params, math.inf), np.full(9, 2.3), params, "scalar v")


@pytest.mark.parametrize("eps_y", [2e-4, 3.6e-3, 0.05, 2.0, 10.0])
def test_e45_of_arrays_against_the_printed_equation_in_mpmath(eps_y):
    """Eq. (8) as printed, at 40 digits, at the same float V*: the array form's error is what its
    rounding allows. The loss L = 0.0361 eps_y^-0.114 ln(V*) (V* - 1)^p, p = 9.5 eps_y, is a product of
    three factors; the power is exp(p ln(V* - 1)), whose argument carries an absolute error of
    ~ eps p (|ln(V* - 1)| + 1), so L's relative error is below 8 eps (4 + p (1 + |ln(V* - 1)|)) (8: numpy's
    log and exp are within 4 ulps, x2 margin) and e = 1 - L's absolute error below L times it plus an ulp of 1.
    V* <= 1 gives exactly 1 (the printed condition), and e is floored at 0."""
    mp.mp.dps = 40
    v_star = np.concatenate([[0.0, 0.5, 1.0, np.nextafter(1.0, 2.0), 1.0 + 1e-12, 1.0 + 1e-6],
                             np.geomspace(1.001, 1e5, 300)])
    got = jgm.restitution_e45(v_star, eps_y)
    assert np.all(got[v_star <= 1.0] == 1.0)
    p = 9.5 * eps_y
    for x, e in zip(v_star[v_star > 1.0], got[v_star > 1.0]):
        exact = e45_printed(float(x), eps_y)
        loss = 1.0 - exact
        bound = float(loss) * 8 * EPS * (4 + p * (1 + abs(math.log(x - 1.0)))) + 2 * EPS
        expected = max(float(exact), 0.0)
        assert abs(e - expected) <= bound, (x, e, expected, bound)


def test_e45_of_arrays_matches_its_scalar_form_at_both_ends():
    """Arrays and floats at the join V* = 1, deep in the plastic range, where the power underflows (glass
    on glass: eps_y ~ 10 at V* just above 1) and where it overflows (e floored at 0), within the bound above."""
    for eps_y in (3.6e-3, 10.0, 33.0):
        v_star = np.array([0.999, 1.0, 1.0 + 1e-9, 1.5, 2.0, 40.0, 1e3, 1e6, 1e12])
        with np.errstate(all="raise"):
            got = jgm.restitution_e45(v_star, eps_y)
        for x, e in zip(v_star, got):
            one = jgm.restitution_e45(float(x), eps_y)
            bound = (1.0 - one) * 8 * EPS * (4 + 9.5 * eps_y * (1 + abs(math.log(max(x - 1.0, 1e-300))))) + 2 * EPS
            assert abs(e - one) <= bound, (eps_y, x, e, one)


def test_lambda_and_time_scale_against_the_printed_equations():
    """lambda (Eq. 12) and T (Eq. 9) of the array mode against mpmath at 40 digits: v^(1/5) as
    exp(ln(v)/5) has a relative error below eps (4 + |ln v|/5) (the rounding of ln v carried through the
    exp), and each of the few multiplications and divisions adds one ulp: 16 eps (1 + |ln v|/5) bounds both."""
    mp.mp.dps = 40
    a, b = PAIRS["s2/al6061"]
    d = 6.35e-3
    v = np.geomspace(1e-9, 1e4, 40)
    t = np.geomspace(1e-7, 100.0, 40)
    params = dict(params_for("s2/al6061"), plate_t=t)
    got = r.impact(v, **params, plasticity="off", plate_waves="off")
    mats = ({k: mp.mpf(repr(float(getattr(a, k)))) for k in ("E", "nu", "Sy", "rho")},
            {k: mp.mpf(repr(float(getattr(b, k)))) for k in ("E", "nu", "Sy", "rho")})
    for i in range(v.size):
        _eps, _vc, lam = printed_equations(*mats, d, float(t[i]), float(v[i]))
        bound = 16 * EPS * (1 + abs(math.log(v[i])) / 5)
        assert abs(got.lam[i] / float(lam) - 1.0) <= bound, (v[i], t[i])
        e_star = 1 / ((1 - mats[0]["nu"] ** 2) / mats[0]["E"] + (1 - mats[1]["nu"] ** 2) / mats[1]["E"])
        k = mp.mpf(4) / 3 * e_star * mp.sqrt(mp.mpf(d) / 2)
        m = mats[0]["rho"] * mp.pi * mp.mpf(d) ** 3 / 6
        T = (m / (k * mp.sqrt(mp.mpf(float(v[i]))))) ** mp.mpf("0.4")
        assert abs(got.T[i] / float(T) - 1.0) <= bound, v[i]


def test_fifth_root_against_mpmath_and_at_zero():
    mp.mp.dps = 40
    x = np.concatenate([[0.0, 5e-324, 1e-300, 1.0, 1e300, np.finfo(float).max], np.geomspace(1e-12, 1e12, 200)])
    with np.errstate(all="raise"):
        got = _num.fifth_root(x)
    assert got[0] == 0.0 and _num.fifth_root(0.0) == 0.0
    for xi, g in zip(x[1:], got[1:]):
        exact = float(mp.mpf(float(xi)) ** (mp.mpf(1) / 5))
        assert abs(g / exact - 1.0) <= EPS * (4 + abs(math.log(xi)) / 5), xi


def test_plate_mass_from_the_ratio_is_infinite_exactly_for_a_half_space():
    """m_eff = m_a / ratio (Eq. 19) where the ratio is positive, +inf where it is 0 (Zener skipped, off, or
    e_ze = 1), in one array: m_eff ratio = m_a within two roundings."""
    lam = np.array([0.0, 1e-12, 1e-3, 0.5, 1.5, 80.0, 500.0])
    e_ze, d_ze, _tau0 = zener.zener_solution(lam)
    ratio = r.fusion.mass_ratio(e_ze, d_ze)
    m_eff = r.fusion.plate_mass_from_ratio(2e-3, ratio)
    assert m_eff[0] == math.inf and np.all(np.isfinite(m_eff[1:]))
    np.testing.assert_allclose(m_eff[1:] * ratio[1:], 2e-3, rtol=2 * EPS)
    assert r.fusion.plate_mass_from_ratio(2e-3, 0.0) == math.inf
    # the public form agrees: (1 + e_ze) m_a / (1 - e_ze)
    np.testing.assert_allclose(r.fusion.equivalent_plate_mass(2e-3, e_ze[1:], d_ze[1:]),
                               (1 + e_ze[1:]) * 2e-3 / d_ze[1:], rtol=4 * EPS)


@pytest.mark.parametrize("name,bad,shown", [
    ("v", [1.0, 2.0, math.nan, -1.0], "v_approach = nan m/s"),
    ("v", [1.0, -0.5, 2.0], "v_approach = -0.5 m/s"),
    ("v", [1.0, math.inf], "v_approach = inf m/s"),
    ("plate_t", [1e-3, 0.0, 1e-3], "plate.t = 0.0 m"),
    ("plate_t", [[1e-3, 2e-3], [math.nan, 1e-3]], "plate.t = nan m"),
    ("plate_nu", [0.3, 0.5, 0.5000001], "plate.nu = 0.5000001 is outside"),
    ("plate_edge_distance", [math.inf, 0.0, -1.0], "plate.edge_distance = -1.0 m"),
    ("plate_edge_distance", [math.inf, math.nan], "plate.edge_distance = nan m"),
])
def test_a_bad_value_anywhere_in_an_array_is_refused_and_named(name, bad, shown):
    """Arrays are checked by their minimum and maximum (NaN propagates through both); the message still
    names the parameter and the first bad value in the array."""
    args = dict(params_for("s2/al6061"), v=1.0)
    args[name] = np.array(bad)
    v = args.pop("v")
    with pytest.raises(ValueError, match="^" + shown.replace(".", r"\.").replace("+", r"\+")):
        r.impact(v, **args)


def test_good_arrays_at_the_ends_of_their_ranges_pass_the_checks():
    args = params_for("s2/al6061")
    args.update(plate_nu=np.array([0.0, 0.5]), plate_t=np.array([1e-7, 100.0]))
    got = r.impact(np.array([0.0, 1e4]), **args, plate_edge_distance=np.array([0.0, math.inf]), validate=True)
    assert got.e.shape == (2,)
    empty = r.impact(np.array([]), **params_for("s2/al6061"))
    assert empty.e.shape == (0,) and empty.valid.shape == (0,)


def test_exact_table_in_blocks_matches_the_scalar_evaluation():
    """The exact method's array path works in blocks of cases (zener_exact._BLOCK): a length that is not
    a multiple of the block, and a strided 2-D view, give each case what the scalar path gives, within
    the rounding bound of a cubic in Horner form, 8 eps sum_i |c_i| t^i (c_i the case's piece), for e_ze,
    1 - e_ze and tau0; the results own their memory and have lambda's shape."""
    from restitution import zener_exact

    rng = np.random.default_rng(5)
    n = 2 * zener_exact._BLOCK + 7
    flat = np.concatenate([[0.0, 100.0, 1e-300], rng.uniform(0.0, 100.0, n - 3)])
    square = rng.uniform(0.0, 6.0, (64, 2 * 64))[:, ::2]  # not contiguous
    for lam in (flat, square):
        got = zener_exact.zener_exact_solution(lam)
        assert all(g.shape == lam.shape and g.flags.owndata for g in got)
        for idx in list(np.ndindex(lam.shape))[:: max(1, lam.size // 3000)] + [np.unravel_index(lam.size - 1, lam.shape)]:
            x = float(lam[idx])
            cell = zener_exact._COEF_ARR[int(x * zener_exact._INV_H)]
            t = x * zener_exact._INV_H - cell[0]
            powers = np.array([1.0, t, t * t, t * t * t])
            for k, scalar in enumerate(zener_exact.zener_exact_solution(x)):
                bound = 8 * EPS * float(np.abs(cell[1 + 4 * k:5 + 4 * k]) @ powers)
                assert abs(got[k][idx] - scalar) <= bound, (x, k)


@pytest.mark.parametrize("tolerance", [0.0, 5e-324, 1e-17, 2.0 ** -53, 3e-16, 1e-6, 1e-3, 0.1, 0.25, 0.5])
def test_auto_skip_of_small_losses_by_one_comparison_selects_what_the_subtraction_selects(tolerance):
    """The array mode skips a plastic loss below ``effect_tolerance`` by comparing e_ep with one threshold
    (_array_steps._loss_threshold) instead of computing 1 - e_ep: on e_ep in [0, 1] (uniform, near 1 within a few
    tolerances, and the floats next to the threshold) it selects exactly the cases 1.0 - e_ep < tolerance
    selects in floating point (a comparison of two exact decisions, not of two roundings)."""
    from restitution._array_steps import _loss_threshold

    threshold = _loss_threshold(tolerance)
    rng = np.random.default_rng(3)
    e_ep = np.concatenate([rng.uniform(0.0, 1.0, 20000), 1.0 - rng.uniform(0.0, 3.0 * max(tolerance, 1e-15), 20000),
                           [0.0, 0.5, np.nextafter(0.5, 0.0), 1.0, threshold, np.nextafter(threshold, 0.0),
                            np.nextafter(threshold, 2.0)]])
    e_ep = e_ep[e_ep <= 1.0]
    assert np.array_equal(e_ep > threshold, (1.0 - e_ep) < tolerance)
    assert _loss_threshold(0.75) is None  # above 1/2 the array mode subtracts
    v, params, edge = mixed_cases()
    got = r.impact(v, **params, plate_edge_distance=edge, effect_tolerance=0.75)
    assert_agree(got, one_by_one(v, params, edge, effect_tolerance=0.75), v, params, "tolerance 0.75",
                 effect_tolerance=0.75)
