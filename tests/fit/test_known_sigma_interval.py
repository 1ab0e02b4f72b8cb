"""The known-sigma likelihood of rebound pairs (``sigma`` given) and the intervals it gives, against a closed
form computed here: with sigma_k known and the model locally linear in x = ln(plate.Sy), the log-likelihood
is -1/2 sum_k ((v_out_k - mu_k(x)) / sigma_k)^2 + const, so the profile-likelihood interval (threshold
chi2_1(0.95) = 1.96^2) and the Hessian's standard error are

    se(x) = 1 / sqrt(F),   F = sum_k (dmu_k/dx / sigma_k)^2,   95 % half-width = 1.96 se(x).

The sensitivities dmu_k/dx come from central differences of ``restitution.impact`` (the forward model, trusted
here: what is tested is how the likelihood weighs the residuals and how the interval follows from it).
Scaling the residuals by sigma^2 instead of sigma (or by anything but sigma) leaves the estimate in place but
changes every width by a factor of about 1/sigma (sigma in m/s): hundreds of times here.

The bodies are those of tests/fit/test_estimate.py: a chrome-steel ball (d = 6.35 mm) on a 6.35 mm Al 6061
plate, whose plate yields first, so plate.Sy enters e."""
from __future__ import annotations

import math

import numpy as np
import pytest

import restitution
from restitution.fit.datasets import ReboundPairs
from restitution.fit.estimate import base_of, fit_parameters

BASE = base_of(restitution.Sphere(restitution.MATERIALS["chrome_steel"], 6.35e-3),
               restitution.Plate(restitution.MATERIALS["al_6061"], 6.35e-3))
TRUE_SY = BASE["plate_Sy"]
#: The approach speeds [m/s] of the synthetic pairs.
V_IN = np.linspace(0.5, 5.0, 12)
#: z_(0.975), the 95 % two-sided normal quantile (sqrt(chi2_1(0.95))).
Z975 = 1.959963984540054
#: Central-difference step in ln(plate.Sy): truncation error ~h^2 f'''/6, ~1e-9 relative here; rounding
#: ~1e-16 / 1e-4 = 1e-12.
H = 1e-4


def mu(sy: float) -> np.ndarray:
    """The model's rebound speeds v_out = e(v_in) v_in [m/s] at plate.Sy = ``sy``, from restitution.impact."""
    return restitution.impact(V_IN, **dict(BASE, plate_Sy=sy)).e * V_IN


def fisher(sy: float, sigma: np.ndarray) -> float:
    """F = sum_k (dmu_k / d ln Sy / sigma_k)^2 at ``sy``, by central differences."""
    slope = (mu(sy * math.exp(H)) - mu(sy * math.exp(-H))) / (2.0 * H)
    return float(np.sum((slope / sigma) ** 2))


def pairs(z: np.ndarray, sigma: np.ndarray) -> ReboundPairs:
    """Pairs whose v_out = mu(true Sy) + sigma z (the test's own standard normal draws z), sigma given."""
    return ReboundPairs(V_IN, mu(TRUE_SY) + sigma * z, sigma=sigma)


# a different known sigma for each point (0.2-0.8 % of v_out, in m/s): the weights must be per point
SIGMA = 0.002 * mu(TRUE_SY) * (1.0 + np.arange(V_IN.size) % 4)
Z = np.random.default_rng(20261128).standard_normal(V_IN.size)


def test_known_sigma_interval_is_the_closed_form_of_a_locally_linear_model():
    fit = fit_parameters(pairs(Z, SIGMA), BASE, ["plate.Sy"])
    p = fit["plate.Sy"]
    assert fit.noise["model"] == "known"
    est = p.estimate
    lo, hi = p.ci95
    half = Z975 / math.sqrt(fisher(est, SIGMA))  # the closed-form 95 % half-width in ln Sy
    # How linear the model is across the interval: the closed-form half-width evaluated with the sensitivities
    # at either end differs from the one at the estimate by this much (1e-5 here), and the profile interval's
    # ends follow the linear ones to about that. Checked (< 0.1 %). The ends are found to 1e-5 in ln Sy, 0.2 %
    # of this half-width (0.005). A 2 % tolerance covers both several times over; the mistake is 200 times off.
    nonlinearity = max(abs(math.sqrt(fisher(est, SIGMA) / fisher(end, SIGMA)) - 1.0) for end in (lo, hi))
    assert nonlinearity < 1e-3
    assert math.log(hi / est) == pytest.approx(half, rel=0.02)
    assert math.log(est / lo) == pytest.approx(half, rel=0.02)
    # the Hessian's standard error of ln Sy (the Gauss-Newton curvature at the optimum): the same closed form,
    # without the interval's nonlinearity: 1 %
    assert p.se == pytest.approx(1.0 / math.sqrt(fisher(est, SIGMA)), rel=0.01)
    # the estimate itself (the scaling does not move it): within 4 closed-form standard errors of the truth
    assert abs(math.log(est / TRUE_SY)) < 4.0 * half / Z975


def test_known_sigma_chi2_and_log_likelihood_are_the_gaussian_ones():
    """The reported chi2 and log-likelihood at the estimate, written out here from the Gaussian density with the
    given sigma_k: rounding only (1e-9)."""
    data = pairs(Z, SIGMA)
    fit = fit_parameters(data, BASE, ["plate.Sy"], profile=False)
    r = (data.v_out - mu(fit["plate.Sy"].estimate)) / SIGMA
    assert fit.noise["chi2"] == pytest.approx(float(np.sum(r * r)), rel=1e-9)
    log_l = float(np.sum(-0.5 * r * r - 0.5 * np.log(2.0 * math.pi * SIGMA ** 2)))
    assert fit.log_likelihood == pytest.approx(log_l, rel=1e-9)


def test_known_sigma_interval_scales_as_sigma():
    """The same standardised noise z with sigma and with 3 sigma: in the linear regime every width is 3 times as
    large (the estimate's offset too). The nonlinearity over the wider interval (5e-5, measured as above) and the
    ends' root-finding tolerance (0.2 % of the narrower width) bound the departure from 3: 2 % covers them. A
    likelihood weighted by 1/sigma^2 would give 9, by 1/sqrt(sigma) 1.7."""
    widths = []
    for scale in (1.0, 3.0):
        lo, hi = fit_parameters(pairs(Z, scale * SIGMA), BASE, ["plate.Sy"])["plate.Sy"].ci95
        widths.append(math.log(hi / lo))
    assert widths[1] / widths[0] == pytest.approx(3.0, rel=0.02)
