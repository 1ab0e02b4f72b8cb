"""Practical non-identifiability (restitution.fit.identifiability): brass (d = 6.35 mm) on S7 tool steel
(t = 6.35 mm). C(0.35) 393 MPa = 658 MPa < C(0.30) plate.Sy for every plate.Sy above ~407.7 MPa, so there
the sphere yields first (Eq. 2) and plate.Sy does not enter e: the data bound plate.Sy only from below.
Synthetic pairs made here: e from restitution.impact, 1 % relative noise, seeded."""
from __future__ import annotations

import json
import math

import numpy as np
import pytest
from scipy import stats

import restitution
from restitution.fit.calibration import Calibration
from restitution.fit.datasets import ReboundPairs
from restitution.fit.estimate import base_of, fit_parameters, profile_threshold
from restitution.fit.forward import rebound_speeds
from restitution.fit.report import band_params, table

BASE = base_of(restitution.Sphere(restitution.MATERIALS["brass_260"], 6.35e-3),
               restitution.Plate(restitution.MATERIALS["s7_tool_steel"], 6.35e-3))
SWITCH = 393e6 * math.exp(0.736 * (0.35 - 0.30))  # [Pa] where C(nu) Sy of the plate meets the sphere's: 407.7 MPa


def make_pairs(rng, truth, n=20):
    params = dict(BASE, plate_Sy=truth)
    v = rng.uniform(0.5, 5.0, n)
    return ReboundPairs(v, restitution.impact(v, **params).e * v * (1 + 0.01 * rng.standard_normal(n)))


def test_brass_on_s7_plate_sy_is_bounded_only_from_below():
    data = make_pairs(np.random.default_rng(1), truth=552e6)
    fit = fit_parameters(data, BASE, ["plate.Sy"])
    p = fit["plate.Sy"]
    assert p.identifiability == "practical" and not p.identifiable
    assert p.estimate is None and p.ci95 is None and set(p.bound) == {"lower"}
    assert 0.9 * SWITCH < p.bound["lower"] < SWITCH < 552e6
    # the bound is the end of the 95 % profile set: re-evaluate the likelihood there (written out here)

    def log_l(sy):
        m = rebound_speeds(data.v_in, dict(BASE, plate_Sy=sy))[0]
        s2 = np.mean(((data.v_out - m) / m) ** 2)
        return float(np.sum(-0.5 * np.log(2 * np.pi * s2 * m ** 2)) - 0.5 * data.n)

    assert abs(2 * (fit.log_likelihood - log_l(p.bound["lower"])) - profile_threshold(20, 1, True)) < 0.02
    d = json.loads(json.dumps(fit.to_dict()))["parameters"]["plate.Sy"]
    assert d["estimate"] is None and d["identifiable"] is False and d["identifiability"] == "practical"
    assert d["bound"]["lower"] == pytest.approx(p.bound["lower"])
    cal = Calibration(data, BASE, fit)
    words = table(cal)
    assert "plate.Sy  not identifiable from these data (practically): the data bound it only from below, " \
           "plate.Sy > 40" in words and "MPa at 95 %" in words and "Eq. 2" in words
    # the fitted curve: plate.Sy at the likelihood's maximum (in the flat part: the same e as the truth's)
    assert cal.fitted_params["plate_Sy"] >= p.bound["lower"]
    assert band_params(cal) == [cal.fitted_params]  # no interval: the band is the fitted curve
    assert not fit.lack_of_fit["detected"]


def test_the_plot_says_the_bound(tmp_path):
    pytest.importorskip("matplotlib")
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from restitution.fit import report

    data = make_pairs(np.random.default_rng(2), truth=552e6)
    cal = Calibration(data, BASE, fit_parameters(data, BASE, ["plate.Sy"]))
    titles = []
    real_close = plt.close
    plt.close = lambda fig=None: (titles.append(fig.axes[0].get_title()), real_close(fig))
    try:
        report.plot(tmp_path / "fit.png", cal)
    finally:
        plt.close = real_close
    assert "plate.Sy > 40" in titles[0] and "not identifiable" in titles[0]


# Coverage of the bound. Truth in the flat part (552 MPa): the statement "plate.Sy > bound" can only fail if
# the bound exceeds the switch, which the data never make it do. Truth just below the switch (404 MPa): the
# hardest case, where the data choose between an interval and a bound. A 95 % statement holds in >= 95 %
# of the data sets that get a bound; with N bounds the count of misses exceeds binom.isf(1e-3, N, 0.05)
# with probability < 1e-3 if the true rate is 95 % (N = 67: 10 misses allowed). Measured (seed 7):
# 191/191 at 552 MPa, 62 of 67 at 404 MPa (the choice chi2_1(0.90) = 2.706 would give 58 of 67).
@pytest.mark.slow
@pytest.mark.parametrize("truth, seed", [(552e6, 501), (404e6, 502)])
def test_coverage_of_the_lower_bound(truth, seed):
    rng = np.random.default_rng(seed)
    bounds = held = 0
    for _ in range(150):
        p = fit_parameters(make_pairs(rng, truth), BASE, ["plate.Sy"])["plate.Sy"]
        if p.bound:
            bounds += 1
            held += p.bound["lower"] <= truth
    misses = bounds - held
    print(f"\ntrue plate.Sy {truth / 1e6:.0f} MPa: {bounds} bounds of 150 data sets, {held} below the truth")
    assert bounds >= 20  # enough bounds for the statement to be tested
    assert misses <= stats.binom.isf(1e-3, bounds, 0.05)
