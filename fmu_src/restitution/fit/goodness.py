"""Lack of fit: does the model describe the data at all? (:func:`lack_of_fit`)

A fit always returns a best value and an interval, also for data the model cannot produce (e rising with
speed, clicks at random times, a ball that gains energy). The intervals then mean nothing. These checks
test the fitted model against the data, each giving a p-value under the hypothesis that the model and the
noise model are right:

* ``chi2`` (rebound pairs with a known ``sigma``): the upper tail of chi2_(n-p) at the fit's
  sum((r/sigma)^2). Too large: the scatter exceeds the stated noise, or the model misses the data.
* ``runs`` (every kind, noise estimated or known): the Wald-Wolfowitz runs test on the signs of the
  residuals, ordered by approach speed (rebound pairs) or by bounce index (impact times). A model that
  describes the data leaves signs in random order; a model that misses a trend leaves long runs of one
  sign. One-sided (too few runs), exact (the conditional distribution of the number of runs given the
  counts of each sign).
* ``trend`` (rebound pairs): the residuals' slope against ln v_in, once the directions the fitted
  parameters can move the model along are projected out (the added-variable t test: for a model linear in
  its parameters, t_(n-p-1) exactly; with a known sigma, a z test). Two-sided.
* ``growth`` (impact times): whether the intervals between impacts grow. In the model each rebound is
  slower than its impact (e < 1), so the intervals shrink (t_k is concave in k). The check fits
  t_k = a + b k + c k^2 by least squares and tests c > 0 (t_(n-3), one-sided). It does not use the model:
  a concave train makes c < 0 (the check is conservative), and for a train of constant intervals (e = 1,
  the least favourable case of the model) the test is exact at its level.

The checks are combined by Bonferroni: with k applicable checks each is run at ``ALPHA`` / k, so that on
data the model describes the chance of any alarm is at most ``ALPHA`` = 0.1 % per fit. A check that cannot
be run (too few points, a covariate the fitted parameters already span) gives p = None and does not count.
"""
from __future__ import annotations

import math

import numpy as np
from scipy import stats
from scipy.special import gammaln

__all__ = ["ALPHA", "lack_of_fit", "runs_test", "trend_test", "growth_test", "chi2_test", "combine", "jacobian"]

#: The false-alarm rate of the lack-of-fit verdict per fit (Bonferroni over the checks run).
ALPHA = 1e-3


def jacobian(problem, x, h: float = 1e-5, r0=None) -> np.ndarray:
    """d residuals / d x of a :class:`restitution.fit.likelihood.Problem` at x, shape (n, k): central
    differences of step ``h`` in the fit coordinates (one-sided at a bound); ``r0`` the residuals at x."""
    x = np.asarray(x, dtype=float)
    r0 = problem.residuals(x) if r0 is None else r0
    J = np.empty((r0.size, problem.k))
    for j in range(problem.k):
        step = np.zeros(problem.k)
        up = min(h, problem.upper[j] - x[j])
        dn = min(h, x[j] - problem.lower[j])
        step[j] = up
        rp = problem.residuals(x + step)
        step[j] = -dn
        rm = problem.residuals(x + step)
        J[:, j] = (rp - rm) / max(up + dn, 1e-300)
    return J


def _log_comb(n, k):
    return gammaln(n + 1) - gammaln(k + 1) - gammaln(n - k + 1)


def runs_test(residuals, order=None) -> dict:
    """Wald-Wolfowitz runs test on the signs of ``residuals`` taken in ``order`` (indices; default as given):
    p = P(R <= runs observed | n+ positive, n- negative signs), exact. Zero residuals are dropped. All of one
    sign: p = 2^(1-N) (the chance of that for independent symmetric signs). Fewer than 2 signs: p None."""
    r = np.asarray(residuals, dtype=float)
    if order is not None:
        r = r[np.asarray(order)]
    s = np.sign(r[np.isfinite(r)])
    s = s[s != 0]
    N = s.size
    out = {"statistic": None, "p_value": None, "n_positive": int(np.sum(s > 0)), "n_negative": int(np.sum(s < 0))}
    if N < 2:
        return out
    runs = 1 + int(np.count_nonzero(s[1:] != s[:-1]))
    n1, n2 = out["n_positive"], out["n_negative"]
    out["statistic"] = runs
    if n1 == 0 or n2 == 0:
        out["p_value"] = float(min(1.0, 2.0 ** (1 - N)))
        return out
    total = _log_comb(N, n1)
    p = 0.0
    for R in range(2, runs + 1):
        k = R // 2
        if R % 2 == 0:
            terms = [math.log(2.0) + _log_comb(n1 - 1, k - 1) + _log_comb(n2 - 1, k - 1)] \
                if k - 1 <= min(n1, n2) - 1 else []
        else:
            terms = [_log_comb(n1 - 1, a) + _log_comb(n2 - 1, b) for a, b in ((k - 1, k), (k, k - 1))
                     if a <= n1 - 1 and b <= n2 - 1]
        p += sum(math.exp(t - total) for t in terms)
    out["p_value"] = float(min(1.0, p))
    return out


def trend_test(residuals, J, covariate, known: bool) -> dict:
    """The added-variable test of ``covariate`` in the weighted ``residuals`` (unit variance when ``known``):
    the covariate with the columns of ``J`` (the residuals' Jacobian in the fitted coordinates) projected out,
    the residuals' least-squares slope on it, and its t (dof n - rank(J) - 1) or z (``known``). Two-sided.
    p None where the fitted directions span the covariate or no degree of freedom is left."""
    r = np.asarray(residuals, dtype=float)
    u = np.asarray(covariate, dtype=float)
    J = np.asarray(J, dtype=float).reshape(r.size, -1)
    rank = int(np.linalg.matrix_rank(J)) if J.size else 0
    u_perp = u - J @ np.linalg.lstsq(J, u, rcond=None)[0] if J.size else u.copy()
    r_perp = r - J @ np.linalg.lstsq(J, r, rcond=None)[0] if J.size else r.copy()
    uu = float(u_perp @ u_perp)
    dof = r.size - rank - 1
    out = {"statistic": None, "p_value": None, "dof": dof}
    if uu <= 1e-12 * float(u @ u) or (not known and dof < 1):
        return out
    slope = float(u_perp @ r_perp) / uu
    if known:
        z = slope * math.sqrt(uu)
        out.update(statistic=z, p_value=float(2.0 * stats.norm.sf(abs(z))), slope=slope)
        return out
    rest = r_perp - slope * u_perp
    s2 = float(rest @ rest) / dof
    t = slope / math.sqrt(s2 / uu) if s2 > 0 else math.copysign(math.inf, slope)
    out.update(statistic=t, p_value=float(2.0 * stats.t.sf(abs(t), dof)), slope=slope)
    return out


def growth_test(times) -> dict:
    """Whether a drop's intervals grow: t_k = a + b k + c k^2 by least squares, one-sided t test of c > 0
    (dof n - 3). ``statistic`` is c's t value; ``growth`` the mean change of the interval per bounce, 2c [s].
    p None below 4 impacts."""
    t = np.asarray(times, dtype=float)
    n = t.size
    out = {"statistic": None, "p_value": None, "dof": n - 3}
    if n < 4:
        return out
    k = (np.arange(n) - 0.5 * (n - 1)) / max(n - 1, 1)
    X = np.column_stack([np.ones(n), k, k * k])
    scale = float(np.ptp(t)) or 1.0
    coef, *_ = np.linalg.lstsq(X, (t - t[0]) / scale, rcond=None)
    rest = (t - t[0]) / scale - X @ coef
    dof = n - 3
    s2 = float(rest @ rest) / dof
    var_c = s2 * float(np.linalg.inv(X.T @ X)[2, 2])
    tc = coef[2] / math.sqrt(var_c) if var_c > 0 else math.copysign(math.inf, coef[2])
    growth = 2.0 * float(coef[2]) * scale / (n - 1) ** 2
    out.update(statistic=float(tc), p_value=float(stats.t.sf(tc, dof)), growth=growth)
    return out


def chi2_test(chi2: float, dof: int) -> dict:
    """Upper tail of chi2_dof at ``chi2`` (the fit's sum((r/sigma)^2) with a known sigma)."""
    if dof < 1:
        return {"statistic": chi2, "p_value": None, "dof": dof}
    return {"statistic": float(chi2), "p_value": float(stats.chi2.sf(chi2, dof)), "dof": int(dof)}


_DESCRIPTIONS = {
    "chi2": "the scatter about the model against the stated sigma (chi2 upper tail)",
    "runs": "the signs of the residuals in order ({order}): runs test, too few runs",
    "trend": "the residuals' trend against ln v_in, the fitted directions projected out (added-variable test)",
    "growth": "the intervals between impacts grow (t_k convex in k: quadratic fit, c > 0)",
}

_WORDS = {
    "chi2": "the scatter is larger than the stated sigma (chi2 = {statistic:.3g} for {dof} degrees of freedom, "
            "p = {p_value:.2g})",
    "runs": "the residuals run in long stretches of one sign ({statistic} runs of {n} residuals in order of "
            "{order}, p = {p_value:.2g})",
    "trend": "the residuals trend with speed, which the model's e(v) cannot follow (t = {statistic:.3g}, "
             "p = {p_value:.2g})",
    "growth": "the intervals between impacts grow, where a bouncing ball's shrink (p = {p_value:.2g})",
}


def combine(checks: dict, alpha: float = ALPHA, order: str = "") -> dict:
    """The verdict over ``checks`` (name -> dict with ``p_value``): Bonferroni, each applicable check at
    ``alpha`` / k. Returns {"alpha", "per_check", "checks" (each with ``threshold``, ``detected`` and a
    ``description``), "detected", "words" (why, in words; "" when nothing was detected)}."""
    applicable = [name for name, c in checks.items() if c.get("p_value") is not None]
    per_check = alpha / max(len(applicable), 1)
    out, words = {}, []
    for name, c in checks.items():
        p = c.get("p_value")
        hit = p is not None and p < per_check
        out[name] = {**c, "threshold": per_check if p is not None else None, "detected": bool(hit),
                     "description": _DESCRIPTIONS[name].format(order=order)}
        if hit:
            words.append(_WORDS[name].format(order=order, n=c.get("n_positive", 0) + c.get("n_negative", 0), **c))
    return {"alpha": alpha, "per_check": per_check, "checks": out, "detected": bool(words),
            "words": "; ".join(words)}


def lack_of_fit(problem, x, alpha: float = ALPHA) -> dict:
    """The lack-of-fit checks (module doc) of the fit of ``problem`` (a :class:`Problem`) at its optimum
    ``x``, combined (:func:`combine`)."""
    lik = problem.likelihood
    params, z = problem.split(x)
    r = np.asarray(lik.residuals(params, z), dtype=float)
    if lik.kind == "impact_times":
        checks = {"runs": runs_test(r), "growth": growth_test(lik.t)}
        return combine(checks, alpha, order="bounce index")
    v = lik.data.v_in
    order = np.argsort(v, kind="stable")
    checks = {}
    if not lik.profiled:
        checks["chi2"] = chi2_test(float(r @ r), lik.n - len(problem.parameters))
    checks["runs"] = runs_test(r, order)
    checks["trend"] = trend_test(r, jacobian(problem, x), np.log(v), known=not lik.profiled)
    return combine(checks, alpha, order="approach speed")
