"""What strongly correlated parameters determine together (the fit's ``combinations``, the report's
"determined together" line), whatever the SIGN of their correlation: two parameters are linked when
|correlation| > CORRELATED (0.95). Anti-correlated pairs are as common as correlated ones: sphere.E and
plate.E (both enter e through the effective modulus 1/E* = (1 - nu_s^2)/E_s + (1 - nu_p^2)/E_p, so raising
one and lowering the other leaves e nearly unchanged: correlation ~ -0.999), plate.Sy and plate.t.

The expected correlation and combination are computed here, from outside the fit: for relative noise the
Gauss-Newton covariance of x = (ln theta_1, ln theta_2) is proportional to (J^T J)^-1, J_kj = d ln mu_k /
d x_j (central differences of ``restitution.impact``, the forward model, trusted here), so the correlation
is -cos(J_1, J_2) and the determined combination theta_1^a1 theta_2^a2 has (a1, a2) along the eigenvector
of J^T J with the largest eigenvalue. The fit weighs its residuals by the fitted model (relative noise),
which moves each column of J by O(noise) = 1 %: hence the tolerances below.

Synthetic data: rebound pairs of a chrome-steel ball (d = 6.35 mm) on an Al 6061 plate, from the presets'
properties, with the test's own seeded 1 % relative noise."""
from __future__ import annotations

import math

import numpy as np
import pytest

import restitution
from restitution.fit import fit
from restitution.fit.datasets import ReboundPairs
from restitution.fit.estimate import CORRELATED
from restitution.fit.forward import KEYS

BALL = restitution.Sphere(restitution.MATERIALS["chrome_steel"], 6.35e-3)


def plate(t):
    return restitution.Plate(restitution.MATERIALS["al_6061"], t)


def params(t) -> dict:
    return {**BALL.params(), **plate(t).params()}


def make_pairs(base: dict, v_in: np.ndarray, seed: int, rel: float = 0.01) -> ReboundPairs:
    rng = np.random.default_rng(seed)
    m = restitution.impact(v_in, **base).e * v_in
    return ReboundPairs(v_in, m * (1.0 + rel * rng.standard_normal(v_in.size)))


def own_jacobian(v_in, base: dict, names, at: dict, h: float = 1e-4) -> np.ndarray:
    """d ln mu_k / d ln theta_j at the parameters ``at`` (FMU name -> value), central differences (truncation
    ~h^2 = 1e-8 relative)."""
    p0 = {**base, **{KEYS[n]: v for n, v in at.items()}}
    cols = []
    for name in names:
        key = KEYS[name]
        up = restitution.impact(v_in, **dict(p0, **{key: p0[key] * math.exp(h)})).e
        dn = restitution.impact(v_in, **dict(p0, **{key: p0[key] * math.exp(-h)})).e
        cols.append((np.log(up) - np.log(dn)) / (2.0 * h))
    return np.stack(cols, axis=1)


def own_correlation_and_exponents(J: np.ndarray):
    """(correlation of the two estimates, exponents of the determined combination normalised so that the larger
    is 1): the covariance (J^T J)^-1 up to a scale."""
    cov = np.linalg.inv(J.T @ J)
    rho = cov[0, 1] / math.sqrt(cov[0, 0] * cov[1, 1])
    w, V = np.linalg.eigh(cov)
    a = V[:, 0] / V[np.argmax(np.abs(V[:, 0])), 0]
    return float(rho), a


def check_combination(cal, names, v_in, base, sign: int):
    result = cal.result
    estimates = {n: result[n].estimate for n in names}
    rho_own, a_own = own_correlation_and_exponents(own_jacobian(v_in, base, names, estimates))
    assert sign * rho_own > 0.99  # the case is what it is meant to be, by the test's own numbers
    rho = result.correlation[names[0]][names[1]]
    # 1 - |rho| is what a 1 % change of the columns moves (observed within 1 %); 25 % leaves room
    assert sign * rho > CORRELATED
    assert (1.0 - abs(rho)) == pytest.approx(1.0 - abs(rho_own), rel=0.25)
    assert len(result.combinations) == 1, result.combinations
    comb = result.combinations[0]
    assert set(comb["parameters"]) == set(names)
    assert sign * comb["correlation"] > CORRELATED and comb["correlation"] == pytest.approx(rho, rel=1e-9)
    # the stiff direction is well conditioned (eigenvalues ~1000 apart): the exponents to 0.01
    a = np.array([comb["exponents"][n] for n in names])
    np.testing.assert_allclose(a, a_own, atol=0.01)
    # anti-correlated estimates: a product with exponents of one sign is determined; correlated: a ratio
    assert np.sign(a[0] * a[1]) == -sign
    # its value is the product at the estimates (not compared with the truth: the product of powers is the
    # local, linear form of what the data fix, and along the sloppy direction the estimates can lie far from
    # the truth, e.g. sphere.E 116 GPa and plate.E 140 GPa for 210 and 69 GPa, with the same E*)
    at_estimate = sum(ai * math.log(estimates[n]) for ai, n in zip(a, names))
    assert math.log(comb["value"]) == pytest.approx(at_estimate, abs=1e-9 * abs(at_estimate))
    # the report says so, naming both
    line = [row for row in str(cal).splitlines() if "determined together" in row]
    assert len(line) == 1 and all(n in line[0] for n in names), str(cal)


def test_anticorrelated_moduli_are_reported_as_determined_together():
    """sphere.E and plate.E from 20 pairs over 0.5-5 m/s: correlation ~ -0.999."""
    base = params(6.35e-3)
    v_in = np.random.default_rng(3).uniform(0.5, 5.0, 20)
    names = ["sphere.E", "plate.E"]
    cal = fit(make_pairs(base, v_in, seed=4), BALL, plate(6.35e-3), names)
    check_combination(cal, names, v_in, base, sign=-1)


def test_correlated_yield_strength_and_modulus_are_reported_as_determined_together():
    """plate.Sy and plate.E from the same kind of data: correlation ~ +0.999 (the other sign)."""
    base = params(6.35e-3)
    v_in = np.random.default_rng(5).uniform(0.5, 5.0, 20)
    names = ["plate.Sy", "plate.E"]
    cal = fit(make_pairs(base, v_in, seed=6), BALL, plate(6.35e-3), names)
    check_combination(cal, names, v_in, base, sign=+1)


def test_moderately_anticorrelated_parameters_are_not_grouped():
    """plate.E and sphere.d on a 3 mm plate, 30 speeds log-uniform over 0.003-5 m/s (below the critical speed,
    V_c = 0.027 m/s, only the plate waves and Hertz act; above it plasticity too): correlation ~ -0.9 by the
    test's own numbers, under the 0.95 that links two parameters. No combination is reported."""
    base = params(3e-3)
    v_in = np.exp(np.random.default_rng(1).uniform(math.log(0.003), math.log(5.0), 30))
    names = ["plate.E", "sphere.d"]
    cal = fit(make_pairs(base, v_in, seed=2), BALL, plate(3e-3), names)
    estimates = {n: cal.result[n].estimate for n in names}
    rho_own, _ = own_correlation_and_exponents(own_jacobian(v_in, base, names, estimates))
    assert -0.93 < rho_own < -0.8
    rho = cal.result.correlation[names[0]][names[1]]
    assert rho == pytest.approx(rho_own, abs=0.02)
    assert cal.result.combinations == ()
    assert "determined together" not in str(cal)
