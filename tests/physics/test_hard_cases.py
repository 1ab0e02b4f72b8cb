"""Hard cases stay numerically sound, in the package (scalar and array paths) and in the FMU.

Everything runs under ``np.errstate(all="raise")`` with warnings as errors, so a hidden
overflow, underflow to a subnormal, 0/0 or inf - inf fails the test. Checked for a matrix of
material pairs (Tables 3 and 4, brittle on one or both sides, nu = 0 and 0.499), speeds from
1e-12 to 1e3 m/s, t/d from 0.01 to 1e3 (lambda from 0 to ~1e4), all Zener methods and both
elastoplastic models, and at targeted branch boundaries (V* = 1, 60, 1000, 1e6; lambda = 1.5,
2, 10, 100, the paper fit's cap, the auto thresholds):

* all package outputs finite, except the documented cases: m_eff = +inf exactly when e_ze = 1
  (half-space; mass_ratio = 0 there), tau0 = t_contact = +inf for the linear method at lambda >= 2
  (it never releases, e_ze = 0, contact_ends False), T = +inf at v = 0 (where t_contact = 0);
  every FMU output finite;
* e in [-1, 1], e_ep and e_ze in [0, 1], tau0 >= tau0(0) of the method (3.2180654597 for the
  nonlinear ODE: exact and ode);
* the flags say exactly where a model is used outside its validated range;
* no jump across any branch boundary beyond the stated tolerance;
* the FMU returns the package's numbers (1e-12 relative) and fmi2OK for every valid case.
"""
from __future__ import annotations

import itertools
import math
from types import SimpleNamespace

import numpy as np
import pytest

import restitution as r
from restitution import jgm, zener
from restitution.agreement import disagreements, tolerances
from restitution.cosim import FmuInstance
from restitution.cosim.fmu import FmiStatusError
from restitution.model import DOMAIN, ZENER_SLOPE_BOUND
from restitution.zener_exact import E_INF

from agree import assert_agree, stack
from cases import D, FMU_FLAGS, FMU_REALS, PAIRS, SPEEDS, T_OVER_D, params_for, runs_ode

# Any warning is an error (an overflow inside numpy, a division by zero), except the DomainWarning of
# impact(): these cases go beyond the FMUs' domain on purpose, to pin the equations' limits.
pytestmark = [pytest.mark.filterwarnings("error"),
              pytest.mark.filterwarnings("ignore::restitution.domain.DomainWarning")]

MODELS, METHODS = r.RESTITUTION_MODELS, r.ZENER_METHODS
TAU0_MIN = {"exact": zener.TAU0_HERTZ, "ode": zener.TAU0_HERTZ, "paper_fit": 3.215, "linear": math.pi}

REAL_FIELDS = ("e", "v_rebound", "e_ep", "V_c", "V_star", "eps_y", "e_ze", "lam", "tau0", "T", "t_contact",
               "m_a", "m_eff", "mass_ratio", "v_plate")
FLAG_FIELDS = ("plasticity_used", "plate_waves_used", "lambda_in_range", "vstar_in_range", "e_negative",
               "contact_ends", "valid")
MODE_CODE = {"off": 0, "on": 1, "auto": 2}





def run(v, params, **options):
    with np.errstate(all="raise"):
        return r.impact(v, **params, **options)


def check(res, method, v, context=""):
    """Finite, in range, flagged: the properties every result must have (scalar result)."""
    where = f"{context} v={v!r} method={method} lam={res.lam!r} V*={res.V_star!r}"
    linear_stuck = method == "linear" and res.plate_waves_used and res.lam >= 2.0
    for name in REAL_FIELDS:
        x = getattr(res, name)
        if name == "m_eff" and res.e_ze == 1.0:
            assert x == math.inf, where
        elif name in ("tau0", "t_contact") and linear_stuck:
            assert x == math.inf, where
        elif name == "T" and v == 0.0:
            assert x == math.inf, where
        else:
            assert math.isfinite(x), f"{name} = {x!r} at {where}"
    assert -1.0 <= res.e <= 1.0 and 0.0 <= res.e_ep <= 1.0 and 0.0 <= res.e_ze <= 1.0, where
    assert res.tau0 >= TAU0_MIN[method], where
    if res.e_ze < 1.0:
        assert 0.0 < res.m_eff < math.inf, where
    assert 0.0 <= res.mass_ratio <= 1.0 and (res.mass_ratio > 0.0 or res.e_ze == 1.0), where
    assert res.contact_ends == (not linear_stuck), where
    if linear_stuck:
        assert res.e_ze == 0.0, where
    if v == 0.0:
        assert res.t_contact == 0.0 and res.v_rebound == 0.0 and res.lam == 0.0 and res.e == 1.0, where
    else:
        assert res.t_contact > 0.0, where
    # flags: exactly where a model leaves its validated range
    assert res.lambda_in_range == (res.lam <= 1.5), where
    assert res.vstar_in_range == (res.V_star <= 1000.0), where
    assert res.valid == (res.lambda_in_range and res.vstar_in_range), where
    assert res.e_negative == (res.e < 0.0), where
    assert res.plasticity_used == (res.e_ep < 1.0), where
    # the fusion identities hold at the extremes too
    assert res.v_rebound == pytest.approx(res.e * v, rel=1e-15, abs=0.0)
    assert res.e == pytest.approx(0.5 * (res.e_ep + res.e_ze + res.e_ep * res.e_ze - 1.0), rel=0.0, abs=1e-15)


# --- the matrix, package -----------------------------------------------------------------------
# ode integrates the ODE per case (and does not depend on the JGM model): one sub-grid of it.
GRID = [(pair, model, method, mode) for pair in PAIRS for model in MODELS for method in METHODS
        for mode in ("on", "auto") if method != "ode" or (model, mode) == ("e45", "on")]


def _grid_case_ids():
    return [f"{p}-{m}-{z}-{w}" for p, m, z, w in GRID]


@pytest.mark.parametrize("pair,model,method,mode", GRID, ids=_grid_case_ids())
def test_matrix_package(pair, model, method, mode):
    speeds, ratios = SPEEDS, T_OVER_D
    if method == "ode":  # a sub-grid (lambda still up to ~3e3)
        speeds, ratios = [0.0, 1e-12, 1e-3, 1.0, 1e3], [0.01, 0.05, 1.0, 1e3]
    options = dict(restitution_model=model, zener_method=method, plasticity=mode, plate_waves=mode)
    v_grid, r_grid = (a.ravel() for a in np.meshgrid(speeds, ratios, indexing="ij"))
    arrays = run(v_grid, {k: (val if k != "plate_t" else r_grid * D) for k, val in params_for(pair).items()},
                 **options)
    scalars = []
    for v, ratio in zip(v_grid.tolist(), r_grid.tolist()):
        res = run(v, params_for(pair, ratio), **options)
        check(res, method, v, f"{pair} t/d={ratio}")
        scalars.append(res)
    # array path = scalar path, within each output's conditioning (tests/agree.py)
    params = {k: (val if k != "plate_t" else r_grid * D) for k, val in params_for(pair).items()}
    assert_agree(arrays, stack(scalars), v_grid, params, f"{pair} {model} {method} {mode}", **options)


def test_matrix_reaches_the_hard_regions():
    """The matrix is not tame: lambda from 0 to > 1e3, V* from 0 to > 1e6, negative e, e_ep = 0."""
    lam, vstar, e, e_ep = [], [], [], []
    for pair in PAIRS:
        v, ratio = (a.ravel() for a in np.meshgrid(SPEEDS, T_OVER_D, indexing="ij"))
        res = run(v, {k: (val if k != "plate_t" else ratio * D) for k, val in params_for(pair).items()})
        lam += res.lam.tolist()
        vstar += res.V_star.tolist()
        e += res.e.tolist()
        e_ep += res.e_ep.tolist()
    assert min(lam) == 0.0 and max(lam) > 1e3 and any(1.5 < x < 2.0 for x in lam) and any(2 < x < 100 for x in lam)
    assert max(vstar) > 1e6 and min(x for x in vstar if x > 0) < 1e-9
    assert min(e) < 0.0 and 0.0 in e_ep and 1.0 in e_ep


# --- targeted boundaries (package; the FMU runs the same cases below) -------------------------
def v_for_vstar(pair, vstar, t_over_d=1.0):
    return vstar * run(1.0, params_for(pair, t_over_d)).V_c


def t_over_d_for_lambda(pair, lam, v=1.0):
    """lambda ~ (d/t)^2: the plate thickness (over d) giving ``lam`` at speed v."""
    return math.sqrt(run(v, params_for(pair, 1.0), plate_waves="on").lam / lam)


VSTAR_PAIRS = ["s2/al6061", "glass/al6061", "wc/glass", "glass/glass", "nu0/nu0.499", "T4-A1"]


@pytest.mark.parametrize("pair", VSTAR_PAIRS)
@pytest.mark.parametrize("model", MODELS)
def test_vstar_boundaries(pair, model):
    def at(vstar, plasticity="on"):
        res = run(v_for_vstar(pair, vstar), params_for(pair), restitution_model=model, plasticity=plasticity)
        check(res, "exact", v_for_vstar(pair, vstar), pair)
        return res

    # V* = 1: e_ep = 1 up to it, continuous past it (brittle eps_y ~ 30 included)
    below, above = at(1.0 - 1e-12), at(1.0 + 1e-12)
    assert below.e_ep == 1.0 and not below.plasticity_used
    assert abs(above.e_ep - 1.0) < 1e-9
    assert at(1.0).e_ep == 1.0
    # V* = 60: e44 changes branch; both models continuous
    lo, hi = at(60.0 - 1e-9), at(60.0 + 1e-9)
    assert abs(lo.e_ep - hi.e_ep) < 1e-10
    if model == "e44":
        assert lo.e_ep == pytest.approx(1.0 - 0.1 * math.log(60.0), rel=1e-8)
    # V* = 1000: the end of the fits' range: flag flips, value does not jump
    inside, outside = at(1000.0 * (1 - 1e-12)), at(1000.0 * (1 + 1e-12))
    assert inside.vstar_in_range and not outside.vstar_in_range and not outside.valid
    assert abs(inside.e_ep - outside.e_ep) < 1e-9
    # far beyond: floored at 0 where the fit goes negative, never below, always flagged
    far = at(1e6)
    assert 0.0 <= far.e_ep <= inside.e_ep and not far.vstar_in_range
    # auto skips plasticity only where it changes e_ep by less than the tolerance
    for vstar in (1.0 + 1e-12, 1.0 + 1e-6, 1.5, 60.0, 1000.0):
        on, auto = at(vstar), at(vstar, "auto")
        assert abs(on.e_ep - auto.e_ep) < 1e-6 and (auto.e_ep == 1.0 or auto.e_ep == on.e_ep)


def test_brittle_pairs_never_overflow_and_stay_elastic_below_vc():
    for pair in ("glass/glass", "glass/al6061", "wc/glass"):
        params = params_for(pair)
        eps = run(1.0, params).eps_y
        v = np.geomspace(1e-12, 1e3, 200)
        res = run(v, params)
        assert np.all(res.e_ep[res.V_star <= 1.0] == 1.0)
        for model in MODELS:  # and past V_c, with eps_y up to ~30 in the exponent 9.5 eps_y
            vs = np.concatenate([np.linspace(0.5, 3.0, 501), np.geomspace(3.0, 1e6, 200)])
            e_ep = run(vs * run(1.0, params).V_c, params, restitution_model=model, plasticity="on").e_ep
            assert np.all(np.isfinite(e_ep)) and np.all((e_ep >= 0.0) & (e_ep <= 1.0))
            assert np.all(np.diff(e_ep) <= 0.0), (pair, model, eps)  # monotone: no jump up


LAMBDA_PAIRS = ["s2/al6061", "T4-A1", "glass/glass", "nu0.499/nu0"]


@pytest.mark.parametrize("pair", LAMBDA_PAIRS)
def test_lambda_boundaries(pair):
    def at(lam, method="exact", plate_waves="on", **kw):
        ratio = t_over_d_for_lambda(pair, lam)
        res = run(1.0, params_for(pair, ratio), zener_method=method, plate_waves=plate_waves, **kw)
        check(res, method, 1.0, f"{pair} t/d={ratio}")
        assert res.lam == pytest.approx(lam, rel=1e-12)
        return res

    # 1.5: the end of Zener's studied range (flag only, for every method)
    for method in METHODS:
        inside, outside = at(1.5 * (1 - 1e-12), method), at(1.5 * (1 + 1e-12), method)
        assert inside.lambda_in_range and not outside.lambda_in_range and not outside.valid
        assert abs(inside.e_ze - outside.e_ze) < 1e-10 and abs(inside.tau0 / outside.tau0 - 1.0) < 1e-10
    # 2: the linear model's critical damping: e_ze -> 0 continuously, then never releases
    below, above = at(2.0 * (1 - 1e-6), "linear"), at(2.0 * (1 + 1e-6), "linear")
    assert below.e_ze < 1e-300 and above.e_ze == 0.0 and zener.zener_linear(2.0) == (0.0, math.inf)
    assert math.isfinite(below.tau0) and below.tau0 > 1e3 and above.tau0 == above.t_contact == math.inf
    assert math.isfinite(at(2.0 * (1 - 1e-15), "linear").tau0)
    nonlinear = at(2.0)
    assert 0.0 < nonlinear.e_ze < 0.05 and math.isfinite(nonlinear.tau0)  # the ODE always releases
    # 10: the ode method switches integrator (DOP853 -> LSODA)
    lo, hi = at(10.0 * (1 - 1e-9), "ode"), at(10.0 * (1 + 1e-9), "ode")
    assert hi.e_ze / lo.e_ze == pytest.approx(1.0, abs=1e-7) and hi.tau0 / lo.tau0 == pytest.approx(1.0, abs=1e-8)
    assert at(10.0, "ode").e_ze == pytest.approx(at(10.0).e_ze, rel=1e-7)
    # 100: exact switches from its table to the large-lambda form
    lo, hi = at(100.0 * (1 - 1e-12)), at(100.0 * (1 + 1e-12))
    assert abs(hi.e_ze / lo.e_ze - 1.0) < 1e-9 and abs(hi.tau0 / lo.tau0 - 1.0) < 1e-9
    assert at(100.0, "ode").e_ze == pytest.approx(at(100.0).e_ze, rel=1e-7)
    # far beyond: e_ze ~ E_INF lambda^-5, tau0 ~ 5 lambda ln(lambda), all finite
    for lam in (1e3, 1e4, 1e5):
        far = at(lam)
        assert far.e_ze == pytest.approx(E_INF * lam ** -5, rel=1e-9) and far.tau0 > 5 * lam * math.log(lam) - lam
        assert not far.valid and far.e_negative == (far.e < 0.0)
    assert at(1e4, "ode").e_ze == pytest.approx(at(1e4).e_ze, rel=1e-6)
    # the paper fit's tau0 is held (finite) beyond lambda ~ 169, where exp would overflow
    cap = zener._PAPER_FIT_LAMBDA_CAP
    lo, hi = at(cap * (1 - 1e-12), "paper_fit"), at(cap * (1 + 1e-12), "paper_fit")
    # (tau0 ~ exp(700): d ln(tau0) / d ln(lambda) = 1050 just below the cap)
    assert hi.tau0 == pytest.approx(lo.tau0, rel=1050 * 3e-12) and math.isfinite(at(1e4, "paper_fit").tau0)


@pytest.mark.parametrize("method", METHODS)
def test_auto_plate_waves_threshold_is_continuous(method):
    """'auto' skips Zener below lambda = tol / ZENER_SLOPE_BOUND: e moves by < tol, tau0 barely."""
    tol = 1e-6
    lam_star = tol / ZENER_SLOPE_BOUND
    for pair in ("s2/al6061", "T4-B4"):
        ratio = t_over_d_for_lambda(pair, lam_star)
        skipped = run(1.0, params_for(pair, ratio * (1 + 1e-9)), zener_method=method, effect_tolerance=tol)
        used = run(1.0, params_for(pair, ratio * (1 - 1e-9)), zener_method=method, effect_tolerance=tol)
        on = run(1.0, params_for(pair, ratio * (1 + 1e-9)), zener_method=method, plate_waves="on")
        assert not skipped.plate_waves_used and used.plate_waves_used
        assert abs(skipped.e - used.e) < tol and abs(skipped.e - on.e) < tol
        assert abs(skipped.tau0 / used.tau0 - 1.0) < 1e-5, (skipped.tau0, used.tau0)
        assert abs(skipped.t_contact / used.t_contact - 1.0) < 1e-5
        check(skipped, method, 1.0, pair)
        check(used, method, 1.0, pair)
    off = run(1.0, params_for("s2/al6061"), zener_method=method, plate_waves="off")
    assert off.tau0 == zener.TAU0_HERTZ and off.e_ze == 1.0 and off.m_eff == math.inf  # half-space


def test_auto_plasticity_threshold_is_continuous():
    tol = 1e-6
    params = params_for("s2/al6061")
    V_c = run(1.0, params).V_c
    lo, hi = 1.0, 2.0  # bisect V* where 1 - e_ep = tol
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if 1.0 - run(mid * V_c, params, plasticity="on").e_ep < tol else (lo, mid)
    skipped, used = run(lo * V_c, params), run(hi * V_c, params)
    assert not skipped.plasticity_used and used.plasticity_used
    assert abs(skipped.e - used.e) <= tol and abs(skipped.e_ep - used.e_ep) <= tol * (1 + 1e-9)  # = tol, rounded


def test_speeds_down_to_1e_12_and_v_zero():
    params = params_for("s2/al6061")
    res = run(np.array([0.0, 1e-12, 1e-9, 1e-6]), params)
    assert res.t_contact[0] == 0.0  # documented: no impact, no contact
    assert np.all(np.diff(res.t_contact[1:]) < 0.0)  # T ~ v^(-1/5): longer contact when slower
    assert np.all(res.e[1:] <= 1.0) and np.all(res.e[1:] > 0.99)
    assert np.all(np.isfinite(res.t_contact))


def test_yield_rule_switch_is_the_papers_eq3():
    """Eq. (3) takes S_y of the body that yields first: at the switch C(nu_a) S_ya = C(nu_b) S_yb
    eps_y jumps by C(nu_a)/C(nu_b) (the paper's rule, confirmed as printed, docs/paper_departures.md); none when nu_a = nu_b."""
    for nu_a, nu_b in ((0.3, 0.3), (0.3, 0.33), (0.2, 0.45)):
        sy_b = 1e9
        sy_a_switch = jgm.poisson_coefficient(nu_b) * sy_b / jgm.poisson_coefficient(nu_a)
        eps = []
        for sy_a in (sy_a_switch * (1 - 1e-12), sy_a_switch * (1 + 1e-12)):
            params = {**r.Sphere(r.Material("a", 200e9, nu_a, sy_a, 7800.0), D).params(),
                      **r.Plate(r.Material("b", 70e9, nu_b, sy_b, 2700.0), D).params()}
            eps.append(run(1.0, params).eps_y)
        ratio = eps[1] / eps[0]  # sphere yields first below the switch, the plate above it
        assert ratio == pytest.approx(jgm.poisson_coefficient(nu_a) / jgm.poisson_coefficient(nu_b), rel=1e-9)
        if nu_a == nu_b:
            assert ratio == pytest.approx(1.0, abs=1e-11)


def test_dense_lambda_sweeps_are_monotone():
    """No hidden jump anywhere in lambda: e_ze falls and tau0 rises, for each method's own range."""
    lam = np.concatenate([np.linspace(0.0, 110.0, 200_001), np.geomspace(110.0, 1e6, 2000)])
    with np.errstate(all="raise"):
        for method, upper in (("exact", math.inf), ("paper_fit", math.inf), ("linear", 2.0)):
            part = lam[lam < upper]
            e, tau0 = zener.zener_restitution(part, method)
            assert np.all(np.diff(e) <= 0.0) and np.all(np.diff(tau0) >= 0.0), method
            assert np.all(np.isfinite(e)) and np.all(np.isfinite(tau0)), method
            assert e[0] == 1.0 and tau0[0] == TAU0_MIN[method]
        e, tau0 = zener.zener_restitution(np.array([0.0, 1e-9, 1e-3, 1.0]), "ode")
        assert np.all(np.diff(e) < 0.0) and np.all(np.diff(tau0) > 0.0) and e[0] == 1.0
        assert np.all(tau0 >= zener.TAU0_HERTZ)


@pytest.mark.parametrize("rtol", [1e-14, 1e-10, 1e-6, 1e-2])
def test_ode_method_respects_the_exact_bounds_at_any_tolerance(rtol):
    for lam in (0.0, 1e-12, 1e-6, 1e-3):
        e, tau0 = zener.zener_ode(lam, rtol=rtol)
        assert 0.0 < e <= 1.0 and tau0 >= zener.TAU0_HERTZ, (lam, rtol, e, tau0)
    e0, tau00 = zener.zener_ode(0.0, rtol=rtol)
    assert e0 == pytest.approx(1.0, abs=max(rtol, 1e-12) * 100)
    assert tau00 == pytest.approx(zener.TAU0_HERTZ, rel=max(rtol, 1e-12) * 100)


# --- the same through the FMU (every implementation: pythonfmu, native FMI 2.0, native FMI 3.0) -------
@pytest.fixture(scope="module")
def fmu(any_version_impact_fmu):
    with FmuInstance(any_version_impact_fmu, "hard") as instance:
        instance.native = not runs_ode(any_version_impact_fmu)  # ode (zener_method = 4) is the Python FMU's only
        yield instance


def fmu_eval(fmu, params, v, model="e45", method="exact", plasticity="auto", plate_waves="auto",
             effect_tolerance=1e-6):
    fmu.set(**{name.replace("_", ".", 1): value for name, value in params.items()},
            restitution_model=MODELS.index(model) + 1, zener_method=METHODS.index(method) + 1,
            plasticity=MODE_CODE[plasticity], plate_waves=MODE_CODE[plate_waves],
            effect_tolerance=effect_tolerance, v_approach=v)
    with np.errstate(all="raise"):
        fmu.do_step(step_size=1e-3)  # raises unless fmi2OK
        reals = dict(zip(FMU_REALS.values(), fmu.get_reals(list(FMU_REALS))))
        flags = dict(zip(FMU_FLAGS.values(), fmu.get(*FMU_FLAGS)))
    assert all(math.isfinite(x) for x in reals.values()), reals  # every FMU output is finite
    return {**reals, **flags}


def assert_fmu_matches(got, ref, context, v, params, **options):
    """Every output within its conditioning (restitution.agreement: the native FMU's libm and numpy
    may differ in last bits, amplified by each output's sensitivity), every flag equal unless a
    perturbation of an input by the difference step flips it."""
    problems = disagreements(SimpleNamespace(**got), ref, *tolerances(v, params, **options))
    assert not problems, (context, problems)


FMU_GRID = [(pair, model, method, mode) for pair in PAIRS for model in MODELS
            for method in ("exact", "paper_fit", "linear") for mode in ("on", "auto")]


def test_matrix_fmu(fmu):
    """The whole matrix (ode: a sub-grid) through one FMU instance: fmi2OK and the package's numbers."""
    n = 0
    cases = [(p, m, z, w, v, ratio) for p, m, z, w in FMU_GRID for v in SPEEDS for ratio in T_OVER_D]
    cases += [(p, "e45", "ode", "on", v, ratio) for p in PAIRS for v in (1e-12, 1.0, 1e3) for ratio in (0.05, 1.0, 1e3)]
    if fmu.native:
        cases = [case for case in cases if case[2] != "ode"]
    for pair, model, method, mode, v, ratio in cases:
        params = params_for(pair, ratio)
        got = fmu_eval(fmu, params, v, model, method, mode, mode)
        options = dict(restitution_model=model, zener_method=method, plasticity=mode, plate_waves=mode)
        ref = run(v, params, **options)
        assert_fmu_matches(got, ref, (pair, model, method, mode, v, ratio), v, params, **options)
        n += 1
    assert n == len(cases) > 5000


def test_boundaries_fmu(fmu):
    """The targeted V* and lambda boundaries, through the FMU."""
    cases = []
    for pair in VSTAR_PAIRS:
        for vstar in (1.0 - 1e-12, 1.0, 1.0 + 1e-12, 60.0 - 1e-9, 60.0 + 1e-9, 1000.0,
                      1000.0 * (1 + 1e-12), 1e6):
            for model in MODELS:
                cases.append((params_for(pair), v_for_vstar(pair, vstar), dict(model=model, plasticity="on")))
    for pair in LAMBDA_PAIRS:
        for lam, method in itertools.product((1.5 * (1 - 1e-12), 1.5 * (1 + 1e-12), 2.0 * (1 - 1e-6), 2.0, 2.5,
                                              100.0, 1e4), ("exact", "paper_fit", "linear")):
            cases.append((params_for(pair, t_over_d_for_lambda(pair, lam)), 1.0, dict(method=method, plate_waves="on")))
        cases.append((params_for(pair, t_over_d_for_lambda(pair, 10.0)), 1.0, dict(method="ode", plate_waves="on")))
        lam_star = 1e-6 / ZENER_SLOPE_BOUND
        for f, method in itertools.product((1 - 1e-9, 1 + 1e-9), METHODS):
            cases.append((params_for(pair, t_over_d_for_lambda(pair, lam_star) * f), 1.0, dict(method=method)))
    outside = 0
    if fmu.native:
        cases = [case for case in cases if case[2].get("method") != "ode"]
    for params, v, kw in cases:
        options = dict(restitution_model=kw.get("model", "e45"), zener_method=kw.get("method", "exact"),
                       plasticity=kw.get("plasticity", "auto"), plate_waves=kw.get("plate_waves", "auto"))
        ref = run(v, params, **options)
        check(ref, kw.get("method", "exact"), v)
        if not in_fmu_domain(params, v):  # the package computes it; the FMU declares and enforces DOMAIN
            with pytest.raises(FmiStatusError, match="outside the allowed range"):
                fmu_eval(fmu, params, v, **kw)
            outside += 1
            continue
        assert_fmu_matches(fmu_eval(fmu, params, v, **kw), ref, (params, v, kw), v, params, **options)
    assert 0 < outside < len(cases) // 4


def in_fmu_domain(params, v):
    values = dict(params, v=v)
    return all(low <= values[name] <= high for name, (low, high) in DOMAIN.items())
