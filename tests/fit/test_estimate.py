"""The estimation core of the calibration (restitution.fit.forward, .likelihood, .estimate) on synthetic data
made here, from known parameters, with its own noise: rebound pairs with 1 % relative noise on v_out, and the
impact times of a drop with 30 us of Gaussian jitter from a bounce-train generator written in this file.

The bodies: a chrome-steel ball (d = 6.35 mm) on an Al 6061 plate (t = 6.35 mm). The plate yields first
(C(0.33) 290 MPa = 479 MPa < C(0.30) 1380 MPa = 2.23 GPa, Eq. 2), so plate.Sy is identifiable and the
sphere's Sy does not enter e.

How precise the fits should be (the tolerances below derive from this): over 0.5-5 m/s,
d ln e / d ln plate.Sy = 0.30 ... 0.45 (mean ~0.38), so 20 pairs with 1 % noise determine ln plate.Sy to
~0.01 / (0.38 sqrt(20)) = 0.6 %. A drop's impact times determine it far better (hundreds of ms of flight
measured to 30 us): ~0.01 %.
"""
from __future__ import annotations

import json
import math
import time

import numpy as np
import pytest

import restitution
from restitution.fit.datasets import DataError, ImpactTimes, ReboundPairs
from restitution.fit.estimate import CORRELATED, base_of, fit_parameters, structural_reason
from restitution.fit.forward import (G_STANDARD, KEYS, PARAMETER_NAMES, bounce_train, drop_speed,
                                     rebound_speeds)
from restitution.fit.likelihood import CHI2_1_95

BALL = restitution.Sphere(restitution.MATERIALS["chrome_steel"], 6.35e-3)
PLATE = restitution.Plate(restitution.MATERIALS["al_6061"], 6.35e-3)
BASE = base_of(BALL, PLATE)
TRUE_SY = BASE["plate_Sy"]
G = G_STANDARD
H0 = 0.30  # [m] drop height of the synthetic drops: v_1 = 2.43 m/s
N_IMPACTS = 20
JITTER = 30e-6  # [s]
REL_NOISE = 0.01


# ------------------------------------------------------------------------------------------------------
# the synthetic data, made independently of restitution.fit (restitution.impact with its defaults for e)


def own_bounce_train(v1: float, n: int, params: dict, g: float = G) -> np.ndarray:
    """Impact times of a drop from t = 0: v_(k+1) = e(v_k) v_k, flight 2 v_(k+1)/g (written here, not
    restitution.fit's)."""
    times, t, v = [], 0.0, v1
    for _ in range(n):
        times.append(t)
        v = restitution.impact(v, **params).e * v
        t += 2.0 * v / g
    return np.array(times)


def make_pairs(rng, n=20, rel=REL_NOISE, params=BASE, v_range=(0.5, 5.0)) -> ReboundPairs:
    v_in = rng.uniform(*v_range, n)
    e = restitution.impact(v_in, **params).e
    return ReboundPairs(v_in, e * v_in * (1.0 + rel * rng.standard_normal(n)))


CLEAN_TRAIN = own_bounce_train(drop_speed(H0), N_IMPACTS, BASE)


def make_times(rng, jitter=JITTER, origin=0.0) -> ImpactTimes:
    return ImpactTimes(CLEAN_TRAIN + origin + jitter * rng.standard_normal(N_IMPACTS))


# ------------------------------------------------------------------------------------------------------
# names and forward models


def test_names_map_to_the_fmu_interface_keys():
    from restitution.fmu.models import table

    rows = table("SpherePlateImpact")
    assert set(KEYS) == set(PARAMETER_NAMES) and len(KEYS) == 10
    for name, key in KEYS.items():
        assert rows[name].key == key


def test_rebound_speeds_are_e_times_v_in():
    v = np.linspace(0.5, 5.0, 7)
    v_out, _ = rebound_speeds(v, BASE)
    e = restitution.impact(v, **BASE).e
    # FIT_OPTIONS ("on") against impact's "auto": neither effect is skipped here (V* >> 1, lambda ~ 0.1),
    # so the arithmetic is the same; 1e-13 allows for rounding only
    np.testing.assert_allclose(v_out, e * v, rtol=1e-13)


def test_bounce_train_matches_an_independent_generator():
    train = bounce_train(drop_speed(H0), N_IMPACTS, BASE, g=G, t1=0.5)
    # 20 compounded products and a running sum: rounding of ~20 ulp; 1e-12 of the span
    np.testing.assert_allclose(train.times - 0.5, CLEAN_TRAIN, rtol=0.0, atol=1e-12 * CLEAN_TRAIN[-1])
    np.testing.assert_allclose(train.intervals, np.diff(CLEAN_TRAIN), rtol=1e-10)
    # a batch of 3 trains (B, n), one row per parameter set
    batch = dict(BASE, plate_Sy=np.array([0.5, 1.0, 2.0]) * TRUE_SY)
    times = bounce_train(np.full(3, drop_speed(H0)), N_IMPACTS, batch, g=G).times
    assert times.shape == (3, N_IMPACTS)
    np.testing.assert_allclose(times[1], CLEAN_TRAIN, rtol=0.0, atol=1e-12 * CLEAN_TRAIN[-1])
    # e grows with the plate's Sy here (d ln e / d ln Sy > 0): the harder the plate, the longer the train
    assert times[0, -1] < times[1, -1] < times[2, -1]


# ------------------------------------------------------------------------------------------------------
# single fits


def test_pairs_fit_recovers_plate_sy():
    rng = np.random.default_rng(11)
    data = make_pairs(rng)
    t0 = time.perf_counter()
    fit = fit_parameters(data, BASE, ["plate.Sy"])
    elapsed = time.perf_counter() - t0
    print(f"1-parameter fit of 20 pairs: {elapsed * 1e3:.1f} ms, {fit.evaluations} model evaluations")
    p = fit["plate.Sy"]
    assert p.identifiable and p.reason == "" and p.unit == "Pa"
    lo, hi = p.ci95
    assert lo < p.estimate < hi
    # 0.6 % expected standard error (module doc): 3 % is 5 of them ("within a few %")
    assert abs(p.estimate / TRUE_SY - 1.0) < 0.03
    assert 0.003 < p.se < 0.012  # the Hessian's standard error of ln Sy: 0.6 % within a factor 2
    # a profile interval of a nearly Gaussian profile: hi/lo ~ exp(2 1.96 se); 30 % slack for the
    # curvature of the model in ln Sy
    assert abs(math.log(hi / lo) / (2 * 1.96 * p.se) - 1.0) < 0.3
    # the profiled noise level: s^2 n / sigma^2 ~ chi2(19) -> s/sigma within +-40 % is > 2.5 sd
    assert 0.6 * REL_NOISE < fit.noise["s"] < 1.4 * REL_NOISE
    assert fit.noise["model"] == "relative"
    assert fit.residuals.shape == (20,) and fit.out_of_range == 0
    assert np.allclose(fit.residuals, data.v_out - rebound_speeds(data.v_in, dict(BASE, plate_Sy=p.estimate))[0],
                       rtol=1e-9, atol=1e-12)
    d = json.loads(json.dumps(fit.to_dict()))
    assert d["data"] == {"kind": "rebound_pairs", "n": 20}
    assert set(d["parameters"]["plate.Sy"]) >= {"estimate", "ci95", "identifiable", "reason", "unit"}
    assert d["out_of_range"] == 0 and len(d["residuals"]) == 20
    assert d["correlation"] == {"plate.Sy": {"plate.Sy": 1.0}}


def test_the_small_sample_threshold_is_the_t_interval_of_a_linear_model():
    """With the noise level estimated, the threshold n ln(1 + F/(n - p)) is the likelihood-ratio form of
    Student's t interval: F(1, nu) = t_nu^2, so it must equal n ln(1 + t_(0.975, nu)^2 / nu) (computed here
    from the t distribution); it tends to chi2_1(0.95) as n grows and is chi2_1(0.95) with a known noise."""
    from scipy import stats

    from restitution.fit.estimate import profile_threshold

    for n, p in ((20, 1), (20, 3), (17, 2), (200, 1)):
        t = stats.t.ppf(0.975, n - p)
        assert math.isclose(profile_threshold(n, p, True), n * math.log1p(t * t / (n - p)), rel_tol=1e-9)
    assert profile_threshold(20, 1, True) > profile_threshold(200, 1, True) > CHI2_1_95
    assert abs(profile_threshold(10**6, 1, True) - CHI2_1_95) < 1e-4
    assert profile_threshold(20, 1, False) == CHI2_1_95


def test_profile_interval_ends_sit_on_the_threshold():
    """At each end of the interval, 2 (log L_max - log L) = the threshold: re-evaluate the likelihood there."""
    from restitution.fit.estimate import profile_threshold

    rng = np.random.default_rng(5)
    data = make_pairs(rng)
    fit = fit_parameters(data, BASE, ["plate.Sy"])
    lo, hi = fit["plate.Sy"].ci95

    def log_l(sy):  # the relative-noise likelihood, s at its maximum, written out here
        m = rebound_speeds(data.v_in, dict(BASE, plate_Sy=sy))[0]
        s2 = np.mean(((data.v_out - m) / m) ** 2)
        return float(np.sum(-0.5 * np.log(2 * np.pi * s2 * m ** 2)) - 0.5 * data.n)

    assert math.isclose(log_l(fit["plate.Sy"].estimate), fit.log_likelihood, rel_tol=1e-9)
    for end in (lo, hi):
        # the root is found to 1e-5 in ln Sy; the slope of 2 dlogL there is ~2 1.96 / se ~ 650 per unit ln Sy:
        # the threshold is met to ~0.01
        assert abs(2 * (fit.log_likelihood - log_l(end)) - profile_threshold(data.n, 1, True)) < 0.02


def test_known_sigma_uses_the_absolute_noise():
    rng = np.random.default_rng(8)
    v_in = rng.uniform(0.5, 5.0, 20)
    m = restitution.impact(v_in, **BASE).e * v_in
    sigma = np.full(20, 0.01 * float(np.mean(m)))
    data = ReboundPairs(v_in, m + sigma * rng.standard_normal(20), sigma=sigma)
    fit = fit_parameters(data, BASE, ["plate.Sy"])
    assert fit.noise["model"] == "known"
    # chi2 of 19 degrees of freedom: 19 +- 6.2; 2.5 sd either way
    assert 3.0 < fit.noise["chi2"] < 35.0
    lo, hi = fit["plate.Sy"].ci95
    assert lo < fit["plate.Sy"].estimate < hi
    # absolute noise of 1 % of the mean v_out (~1.5 % of the slow rebounds): se(ln Sy) ~0.5 %, so 3 % is 6 sd
    assert abs(fit["plate.Sy"].estimate / TRUE_SY - 1) < 0.03


def test_times_fit_recovers_plate_sy_v1_and_origin():
    rng = np.random.default_rng(21)
    origin = 1.234  # any time origin
    data = make_times(rng, origin=origin)
    t0 = time.perf_counter()
    fit = fit_parameters(data, BASE, ["plate.Sy"])
    print(f"1-parameter fit of {N_IMPACTS} impact times (v1, t1 fitted): {(time.perf_counter() - t0) * 1e3:.0f} ms")
    p = fit["plate.Sy"]
    lo, hi = p.ci95
    assert lo < p.estimate < hi
    # se of ln Sy ~1e-4 (module doc): 1e-3 is 10 of them, still a very tight check
    assert abs(p.estimate / TRUE_SY - 1.0) < 1e-3
    assert abs(fit.nuisance["v1"]["estimate"] / drop_speed(H0) - 1.0) < 1e-3 and fit.nuisance["v1"]["fitted"]
    # the origin is the mean offset: to ~ JITTER / sqrt(20) plus the model's share; 5 JITTER is generous
    assert abs(fit.nuisance["t1"]["estimate"] - origin) < 5 * JITTER
    # sigma_t^2 n / JITTER^2 ~ chi2(17): within +-40 % is > 2 sd
    assert 0.6 * JITTER < fit.noise["sigma_t"] < 1.4 * JITTER
    assert fit.kind == "impact_times" and fit.residuals.shape == (N_IMPACTS,)
    json.dumps(fit.to_dict())


def test_times_fit_with_the_drop_height_given():
    rng = np.random.default_rng(22)
    data = make_times(rng)
    fit = fit_parameters(data, BASE, ["plate.Sy"], h0=H0)
    assert fit.nuisance["v1"] == {"estimate": drop_speed(H0), "unit": "m/s", "fitted": False}
    lo, hi = fit["plate.Sy"].ci95
    assert lo < fit["plate.Sy"].estimate < hi
    assert abs(fit["plate.Sy"].estimate / TRUE_SY - 1.0) < 1e-3


# ------------------------------------------------------------------------------------------------------
# coverage of the 95 % profile interval


def _coverage(make, n_sets: int, seed: int):
    rng = np.random.default_rng(seed)
    hits, t0 = 0, time.perf_counter()
    for _ in range(n_sets):
        lo, hi = fit_parameters(make(rng), BASE, ["plate.Sy"])["plate.Sy"].ci95
        hits += lo <= TRUE_SY <= hi
    return hits / n_sets, (time.perf_counter() - t0) / n_sets


# With the noise level profiled, chi2_1(0.95) would make the interval slightly short for small n (for a model
# linear in its parameters, coverage P(F(1, n - p) <= (n - p)(exp(3.841/n) - 1)): 94.0 % for 20 pairs, 92.9 %
# for 20 impact times, p = 3: Sy, v_1, t_1); the fit's small-sample threshold makes it 95 % for such a model.
# The binomial sd of the measured coverage is 2.2 % over 100 data sets (pairs: ~10 ms a fit) and 2.8 % over 60
# (impact times: ~80 ms a fit): 85 % is 4.5 and 3.6 sd below 95 % (the seeds are fixed: the outcome is
# reproducible, not drawn anew each run).
N_PAIR_SETS, N_TIME_SETS = 100, 60


def test_coverage_of_the_profile_interval_for_pairs():
    coverage, per_fit = _coverage(make_pairs, N_PAIR_SETS, seed=1000)
    print(f"pairs: coverage {100 * coverage:.1f} % over {N_PAIR_SETS} data sets, {per_fit * 1e3:.0f} ms a fit")
    assert 0.85 <= coverage <= 1.0


def test_coverage_of_the_profile_interval_for_impact_times():
    coverage, per_fit = _coverage(make_times, N_TIME_SETS, seed=2000)
    print(f"impact times: coverage {100 * coverage:.1f} % over {N_TIME_SETS} data sets, {per_fit * 1e3:.0f} ms a fit")
    assert 0.85 <= coverage <= 1.0


# ------------------------------------------------------------------------------------------------------
# identifiability


def test_sphere_sy_is_not_identifiable_when_the_plate_yields_first():
    data = make_pairs(np.random.default_rng(31))
    fit = fit_parameters(data, BASE, ["sphere.Sy", "plate.Sy"])
    s = fit["sphere.Sy"]
    assert not s.identifiable and s.ci95 is None and s.estimate is None and s.identifiability == "structural"
    assert "Eq. 2" in s.reason and "plate yields first" in s.reason and "\n" not in s.reason
    assert fit["plate.Sy"].identifiable and fit["plate.Sy"].ci95 is not None
    assert fit.correlation_names == ("plate.Sy",)  # only what was fitted
    d = json.loads(json.dumps(fit.to_dict()))["parameters"]["sphere.Sy"]
    assert d["ci95"] is None and d["identifiable"] is False and "Eq. 2" in d["reason"]


def test_plate_sy_is_not_identifiable_when_the_sphere_yields_first():
    base = base_of(restitution.Sphere(restitution.MATERIALS["al_6061"], 6.35e-3),
                   restitution.Plate(restitution.MATERIALS["chrome_steel"], 6.35e-3))
    data = make_pairs(np.random.default_rng(32), params=base)
    fit = fit_parameters(data, base, ["plate.Sy"])
    p = fit["plate.Sy"]
    assert not p.identifiable and p.ci95 is None
    assert "Eq. 2" in p.reason and "sphere yields first" in p.reason
    # the same from the impact times of a drop
    times = ImpactTimes(own_bounce_train(2.0, 12, base) + 30e-6 * np.random.default_rng(33).standard_normal(12))
    assert "Eq. 2" in fit_parameters(times, base, ["plate.Sy"])["plate.Sy"].reason


def test_yield_strength_below_the_critical_velocity_is_not_identifiable():
    # speeds below V_c = 0.027 m/s, also when Sy is halved (V_c ~ Sy^2.5: 0.0047 m/s): every impact elastic,
    # no Sy enters (JGM e_ep = 1)
    slow = np.linspace(0.001, 0.004, 5)
    reason = structural_reason(slow, BASE, "plate.Sy")
    assert reason is not None and "elastic" in reason
    assert structural_reason(np.array([1.0, 2.0]), BASE, "plate.Sy") is None


def test_bounded_on_one_side_only_is_practically_non_identifiable_with_a_bound():
    """plate.Sy 1.5 x the sphere's (same nu family): the sphere yields first; halving plate.Sy makes the plate
    yield, so the data bound plate.Sy from below only. The 95 % profile set reaches the domain's top: practically
    non-identifiable (Raue et al. 2009), no estimate, no interval, the lower bound and the Eq. 2 hint in words."""
    sphere = restitution.Sphere(restitution.MATERIALS["al_6061"], 6.35e-3)
    base = dict(base_of(sphere, restitution.Plate(restitution.MATERIALS["chrome_steel"], 6.35e-3)),
                plate_Sy=1.5 * restitution.MATERIALS["al_6061"].Sy)
    fit = fit_parameters(make_pairs(np.random.default_rng(34), params=base), base, ["plate.Sy"])
    p = fit["plate.Sy"]
    assert not p.identifiable and p.identifiability == "practical"
    assert p.estimate is None and p.ci95 is None and set(p.bound) == {"lower"}
    assert "only from below" in p.reason and "Eq. 2" in p.reason
    # the bound: near where the plate's C(nu) Sy meets the sphere's (a factor C(0.33)/C(0.30) = 1.022 above the
    # sphere's Sy); the noise moves it by a few %
    threshold = restitution.MATERIALS["al_6061"].Sy * math.exp(0.736 * (0.33 - 0.30))
    assert 0.9 * threshold < p.bound["lower"] < 1.1 * threshold
    d = json.loads(json.dumps(fit.to_dict()))["parameters"]["plate.Sy"]
    assert d["estimate"] is None and d["identifiable"] is False and d["identifiability"] == "practical"
    assert d["bound"] == {"lower": p.bound["lower"]}


def test_a_parameter_the_data_cannot_bound_is_not_identifiable():
    # sphere.nu enters e (through E' and C(nu)) by a few % over [0, 0.5): 3 pairs with 30 % noise cannot
    # bound it on either side (the profile's drop stays below 3.84 across the whole range)
    data = make_pairs(np.random.default_rng(35), n=3, rel=0.3)
    p = fit_parameters(data, BASE, ["sphere.nu"])["sphere.nu"]
    assert not p.identifiable and p.ci95 is None and p.estimate is None and p.bound is None
    assert "do not bound sphere.nu" in p.reason and p.identifiability == "practical"
    # plate.t from the same data: bounded below (a thin plate rings: e_ze -> 0), not above: practically
    # non-identifiable with a lower bound
    t = fit_parameters(data, BASE, ["plate.t"])["plate.t"]
    assert not t.identifiable and t.estimate is None and t.identifiability == "practical"
    assert set(t.bound) == {"lower"} and 0.0 < t.bound["lower"] < BASE["plate_t"] and "only from below" in t.reason


# ------------------------------------------------------------------------------------------------------
# two parameters


@pytest.mark.parametrize("kind", ["pairs", "times"])
def test_two_parameter_fit_reports_the_correlation_and_the_combination(kind):
    rng = np.random.default_rng(41)
    data = make_pairs(rng) if kind == "pairs" else make_times(rng)
    fit = fit_parameters(data, BASE, ["plate.E", "plate.Sy"])
    rho = fit.correlation["plate.E"]["plate.Sy"]
    assert abs(rho) > CORRELATED and math.isclose(fit.correlation["plate.Sy"]["plate.E"], rho, rel_tol=1e-12)
    assert len(fit.combinations) == 1
    comb = fit.combinations[0]
    assert set(comb["parameters"]) == {"plate.E", "plate.Sy"}
    a_e, a_sy = comb["exponents"]["plate.E"], comb["exponents"]["plate.Sy"]
    assert max(abs(a_e), abs(a_sy)) == 1.0  # normalised: the larger exponent is 1
    assert a_e * a_sy < 0  # a harder plate (Sy up) and a stiffer one (E up) pull e opposite ways
    # the combination is determined far better than either parameter alone
    se = {name: fit[name].se for name in ("plate.E", "plate.Sy")}
    assert comb["relative_sd"] < 0.2 * min(se.values())
    # ... and it holds the truth: its interval is +-1.96 sd; the Gaussian approximation in log space, 3 sd
    truth = TRUE_SY ** a_sy * BASE["plate_E"] ** a_e
    assert abs(math.log(truth / comb["value"])) < 3 * comb["relative_sd"]
    for name in ("plate.E", "plate.Sy"):
        lo, hi = fit[name].ci95
        assert lo < fit[name].estimate < hi
        assert lo < BASE[KEYS[name]] < hi  # seed 41: inside; a 95 % interval, so not a law
    assert comb["expression"].count("^") == 2
    json.dumps(fit.to_dict())


# ------------------------------------------------------------------------------------------------------
# range flags and arguments


def test_points_outside_the_validated_range_are_kept_and_flagged():
    # V* > 1000 above 1000 V_c = 26.5 m/s
    rng = np.random.default_rng(51)
    v_in = np.concatenate([rng.uniform(1.0, 5.0, 10), [40.0, 60.0, 80.0]])
    e = restitution.impact(v_in, **BASE).e
    data = ReboundPairs(v_in, e * v_in * (1 + 0.01 * rng.standard_normal(v_in.size)))
    fit = fit_parameters(data, BASE, ["plate.Sy"])
    expected = ~restitution.impact(v_in, **dict(BASE, plate_Sy=fit["plate.Sy"].estimate)).vstar_in_range
    assert fit.out_of_range == int(expected.sum()) == 3
    assert np.array_equal(fit.flags["vstar_above_1000"], expected)
    assert fit.to_dict()["out_of_range_rows"] == [11, 12, 13]  # rows counted from 1, as error messages count them
    assert fit.residuals.shape == (13,)


def test_bad_arguments():
    data = make_pairs(np.random.default_rng(61))
    with pytest.raises(ValueError, match="unknown parameter 'plate_Sy'.*plate.Sy"):
        fit_parameters(data, BASE, ["plate_Sy"])
    with pytest.raises(ValueError, match="missing plate_t"):
        fit_parameters(data, {k: v for k, v in BASE.items() if k != "plate_t"}, ["plate.Sy"])
    with pytest.raises(ValueError, match="zener_method"):
        fit_parameters(data, BASE, ["plate.Sy"], zener_method="nope")
    with pytest.raises(ValueError, match="impact times"):
        fit_parameters(data, BASE, ["plate.Sy"], h0=1.0)
    times = ImpactTimes(CLEAN_TRAIN[:3])
    with pytest.raises(DataError, match="too few"):
        fit_parameters(times, BASE, ["plate.Sy"])  # Sy, v_1, t_1 and sigma_t from 3 times
    # FMU names are accepted in base as well
    fit = fit_parameters(data, {name: BASE[key] for name, key in KEYS.items()}, "plate.Sy", profile=False)
    assert fit["plate.Sy"].ci95 is None and fit["plate.Sy"].identifiable


def test_a_calibration_without_profile_prints_its_estimates_without_an_interval():
    """fit(..., profile=False) (estimates and the Hessian only) prints a table: no interval, said in words
    (it raised TypeError indexing the missing interval)."""
    import restitution as r
    from restitution.fit import ReboundPairs, fit

    sphere = r.Sphere(r.MATERIALS["chrome_steel"], 6.35e-3)
    plate = r.Plate(r.MATERIALS["al_6061"], 6.35e-3)
    v = np.linspace(0.5, 3.0, 8)
    e = np.asarray(r.impact_between(sphere, plate, v=v).e)
    cal = fit(ReboundPairs(v, e * v * (1 + 0.01 * np.sin(7 * v))), sphere, plate, ["plate.Sy"], profile=False)
    text = str(cal)
    line = next(line for line in text.splitlines() if "plate.Sy" in line)
    assert "no 95 % interval" in line and "profile not computed" in line, text
    assert cal["plate.Sy"].estimate > 0
