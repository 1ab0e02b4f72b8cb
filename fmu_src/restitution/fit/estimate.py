"""Estimating model parameters from measurements: maximum likelihood, profile-likelihood intervals and
identifiability (:func:`fit_parameters`).

Identifiability comes before any number (:mod:`restitution.fit.identifiability`). A requested parameter
that does not enter e for these bodies at the data's speeds is not fitted (structurally non-identifiable:
Eq. 2 of the paper, or every impact elastic). One whose 95 % profile interval reaches the edge of its
domain is practically non-identifiable: no estimate, no interval, and where the other side is bounded the
bound the data give (``bound``: the end of the 95 % profile set). Parameters that the data determine only
in combination (|correlation| > 0.95) get a ``combinations`` entry: the product of powers (exponents from the stiff
eigenvector of the Hessian in log space) that is determined, and the direction that is not. Whether the
model describes the data at all is checked too (:mod:`restitution.fit.goodness`: ``lack_of_fit``).

The fit: least squares (:func:`scipy.optimize.least_squares`, trust-region reflective within the domain)
on the coordinates of :mod:`restitution.fit.likelihood` (log of each positive parameter), from the given
values, and for a single parameter also from the best point of a coarse log grid over its domain. The 95 %
interval of each parameter is its profile-likelihood interval: the set where
2 (log L_max - log L_profile(theta_i)) <= a threshold, the profile re-optimising the other fitted
parameters and the nuisance ones (v_1 of a drop), each end found by root finding (brentq) after stepping
out from the optimum. The threshold is chi2_1(0.95) = 3.841 where the noise is known; where its level is
estimated from the same n points (the default), n ln(1 + F_(1, n-p)(0.95) / (n - p)), p the fitted
quantities of the mean: the exact 95 % threshold of the profile likelihood of a linear Gaussian model
with unknown variance (:func:`profile_threshold`). chi2_1 alone held the truth only 92-94 % of the time
on 20 points; the small-sample threshold brings it to the nominal rate (tests/fit/test_estimate.py).
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np
from scipy import stats
from scipy.optimize import brentq, least_squares

from ..model import impact
from .datasets import DataError
from .forward import FIT_OPTIONS, G_STANDARD, KEYS, UNITS, check_base, check_names, domain
from .goodness import jacobian, lack_of_fit
from .identifiability import (CORRELATED, IDENTIFIABLE, PRACTICAL, STRUCTURAL, combinations, correlation_of,
                              practical_reason, structural_reason)
from .likelihood import CHI2_1_95, Problem, make_likelihood, parameter_coordinate

__all__ = ["fit_parameters", "FitResult", "ParameterEstimate", "base_of", "structural_reason", "CORRELATED"]

#: Finite-difference step of the least-squares Jacobian in the fit coordinates (ln theta): 1e-7 relative
#: (truncation ~1e-7 of the slope; rounding: e ~1e-15 / 1e-7, a drop's 20 compounded impacts ~1e-14 / 1e-7).
_DIFF_STEP = 1e-7
#: The level of the profile-likelihood set whose end is the ``bound`` of a practically non-identifiable
#: parameter: 0.95, the same set that is the 95 % interval of an identifiable one (:mod:`.identifiability`).
BOUND_LEVEL = 0.95
#: Root-finding tolerance on an interval end, in the fit coordinate (ln theta): 1e-5 relative.
_XTOL = 1e-5


def base_of(sphere, plate) -> dict:
    """The ``base`` of :func:`fit_parameters` for a :class:`restitution.Sphere` and :class:`restitution.Plate`."""
    return {**sphere.params(), **plate.params()}


@dataclass(frozen=True)
class ParameterEstimate:
    """One requested parameter: ``estimate`` [``unit``] and ``ci95`` (lo, hi) its 95 % profile-likelihood
    interval, both None unless ``identifiable``; ``identifiability`` "identifiable", "structural" (it does not
    enter e) or "practical" (its profile interval reaches the domain's edge: :mod:`.identifiability`);
    ``bound`` {"lower": value} or {"upper": value}, the bound (the end of the 95 % profile set) of a practically
    non-identifiable parameter open on one side (None otherwise); ``reason`` why not identifiable, in words;
    ``note`` on the interval; ``se`` the standard error of its fit coordinate (ln theta; nu itself) from the
    Hessian; ``best`` where the likelihood is largest (the fitted curve's value; not an estimate when the
    parameter is not identifiable, and not reported)."""

    name: str
    key: str
    unit: str
    estimate: float | None
    ci95: tuple[float, float] | None
    identifiable: bool
    reason: str = ""
    note: str = ""
    se: float | None = None
    identifiability: str = IDENTIFIABLE
    bound: dict | None = None
    best: float | None = None

    def to_dict(self) -> dict:
        return {"estimate": self.estimate, "ci95": None if self.ci95 is None else [float(v) for v in self.ci95],
                "identifiable": self.identifiable, "identifiability": self.identifiability,
                "bound": None if self.bound is None else {k: float(v) for k, v in self.bound.items()},
                "reason": self.reason, "unit": self.unit, "note": self.note}


@dataclass(frozen=True, eq=False)
class FitResult:
    """What :func:`fit_parameters` found. ``parameters``: name -> :class:`ParameterEstimate`, in the order
    asked; ``noise``: the noise model and its estimate; ``nuisance``: v_1 and the time origin t_1 (impact
    times); ``residuals``: data - model [m/s or s]; ``correlation_names`` / ``correlation_matrix``: of the
    fitted parameters' coordinates (ln theta), from the Hessian at the optimum (nuisances profiled out);
    ``combinations``: what strongly correlated parameters determine together; ``flags``: per point,
    the model outside its validated range (lambda > 1.5, V* > 1000) or e < 0 ("any"), ``out_of_range``
    their count (the points are kept); ``lack_of_fit``: the checks of :mod:`restitution.fit.goodness` and
    their verdict ``detected``."""

    kind: str
    n: int
    parameters: dict
    noise: dict
    nuisance: dict
    residuals: np.ndarray
    correlation_names: tuple
    correlation_matrix: np.ndarray
    combinations: tuple
    out_of_range: int
    flags: dict
    log_likelihood: float
    evaluations: int
    elapsed: float
    options: dict = field(default_factory=dict)
    lack_of_fit: dict = field(default_factory=dict)

    def __getitem__(self, name: str) -> ParameterEstimate:
        return self.parameters[name]

    @property
    def estimates(self) -> dict:
        """name -> estimate [SI] (None where not identifiable from the model)."""
        return {name: p.estimate for name, p in self.parameters.items()}

    @property
    def correlation(self) -> dict:
        """{name: {name: rho}} of the fitted parameters (None where the Hessian gives none)."""
        names, m = self.correlation_names, self.correlation_matrix
        return {a: {b: (float(m[i, j]) if np.isfinite(m[i, j]) else None) for j, b in enumerate(names)}
                for i, a in enumerate(names)}

    def to_dict(self) -> dict:
        """The result as plain JSON-ready values."""
        return {"parameters": {name: p.to_dict() for name, p in self.parameters.items()},
                "data": {"kind": self.kind, "n": self.n},
                "noise": _plain(self.noise),
                "nuisance": _plain(self.nuisance),
                "residuals": [float(r) for r in self.residuals],
                "out_of_range": int(self.out_of_range),
                "out_of_range_rows": [int(i) + 1 for i in np.flatnonzero(self.flags["any"])],  # from 1
                "correlation": self.correlation,
                "combinations": [_plain(c) for c in self.combinations],
                "lack_of_fit": _plain(self.lack_of_fit),
                "log_likelihood": float(self.log_likelihood)}

    def __str__(self) -> str:
        lines = [f"fit of {self.n} {self.kind.replace('_', ' ')} ({self.evaluations} model evaluations, "
                 f"{self.elapsed:.3g} s)"]
        if self.lack_of_fit.get("detected"):
            lines.append(f"  WARNING: the model does not describe these data: {self.lack_of_fit['words']}")
        for p in self.parameters.values():
            if not p.identifiable:
                lines.append(f"  {p.name}: not identifiable from these data ({p.identifiability}ly): {p.reason}")
                continue
            lines.append(f"  {p.name} = {p.estimate:.5g} {p.unit}, 95 % [{p.ci95[0]:.5g}, {p.ci95[1]:.5g}]"
                         + (f" ({p.note})" if p.note else ""))
        for c in self.combinations:
            lines.append(f"  determined together: {c['expression']} = {c['value']:.5g} "
                         f"(+-{100 * c['relative_sd']:.2g} %), correlation {c['correlation']:+.3f}")
        lines.append("  noise: " + ", ".join(f"{k} = {v:.4g}" for k, v in self.noise.items()
                                             if isinstance(v, float)))
        if self.out_of_range:
            lines.append(f"  {self.out_of_range} points outside the model's validated range (kept)")
        return "\n".join(lines)


def _plain(d):
    if isinstance(d, dict):
        return {k: _plain(v) for k, v in d.items()}
    if isinstance(d, (list, tuple)):
        return [_plain(v) for v in d]
    if isinstance(d, np.ndarray):
        return d.tolist()
    if isinstance(d, (np.floating, np.integer, np.bool_)):
        return d.item()
    return d


# ---------------------------------------------------------------------------------------------------------
# the fit


def _nan_to_inf(d):
    return np.where(np.isfinite(d), d, np.inf)


class _Fitter:
    """Least squares of one :class:`Problem`, with one coordinate held fixed or none."""

    def __init__(self, problem: Problem):
        self.problem = problem

    def deviance(self, x) -> float:
        return float(_nan_to_inf(self.problem.deviance(x)))

    def solve(self, x0, fixed: int | None = None):
        """(x, deviance) minimising S from x0 (with coordinate ``fixed`` held at x0's value)."""
        p = self.problem
        x0 = p.clip(x0)
        free = np.array([j for j in range(p.k) if j != fixed], dtype=int)
        if free.size == 0:
            return x0, self.deviance(x0)

        lo, hi = p.lower[free], p.upper[free]
        last = {}

        def fun(y):
            x = x0.copy()
            x[free] = y
            r = p.residuals(x)
            r = np.where(np.isfinite(r), r, 1e150)
            last["y"], last["r"] = y.copy(), r
            return r

        def jac(y):
            # forward differences with an absolute step in the coordinates (ln theta): least_squares'
            # own relative step (diff_step * |x|) shrinks to nothing near x = 0, the start value
            r0 = last["r"] if "y" in last and np.array_equal(last["y"], y) else fun(y)
            J = np.empty((r0.size, y.size))
            for j in range(y.size):
                h = _DIFF_STEP if y[j] + _DIFF_STEP <= hi[j] else -_DIFF_STEP
                yj = y.copy()
                yj[j] += h
                J[:, j] = (fun(yj) - r0) / h
            last["y"], last["r"] = y.copy(), r0
            return J

        y0 = np.clip(x0[free], lo, hi)
        # least_squares wants a strictly feasible start when bounds are active: nudge off the bound
        span = hi - lo
        y0 = np.clip(y0, lo + 1e-10 * span, hi - 1e-10 * span)
        res = least_squares(fun, y0, jac=jac, bounds=(lo, hi), method="trf", x_scale=1.0,
                            ftol=1e-12, xtol=1e-12, gtol=1e-12, max_nfev=100 * (free.size + 1))
        x = x0.copy()
        x[free] = res.x
        return x, self.deviance(x)


def _grid_start(problem: Problem, grid: int) -> np.ndarray | None:
    """The best point of a log grid of ``grid`` values over the single fitted parameter's domain (the
    nuisance v_1 set by its fixed point at each value), or None."""
    if grid < 2 or len(problem.parameters) != 1:
        return None
    lo, hi = problem.lower[0], problem.upper[0]
    xs = np.linspace(lo, hi, grid)
    X = np.zeros((grid, problem.k))
    X[:, 0] = xs
    lik = problem.likelihood
    if lik.nuisance:  # v_1 of a drop: the value that makes the first rebound match the observed one
        params, _ = problem.split(X)
        with np.errstate(all="ignore"):
            v1 = lik.v1_guess(params)
        X[:, 1] = lik.nuisance[0].to_x(v1)
    with np.errstate(all="ignore"):
        d = _nan_to_inf(problem.deviance(problem.clip(X)))
    if not np.isfinite(d).any():
        return None
    return problem.clip(X[int(np.argmin(d))])


def _covariance(problem: Problem, x) -> np.ndarray:
    """Covariance of the fit coordinates at the optimum x from the Gauss-Newton Hessian of the deviance
    (central differences of the residuals): sigma^2 (J^T J)^-1, sigma^2 = S/n when the noise is profiled."""
    if problem.k == 0:
        return np.zeros((0, 0))
    r0 = problem.residuals(x)
    J = jacobian(problem, x, r0=r0)
    scale = float(np.sum(r0 * r0)) / r0.size if problem.likelihood.profiled else 1.0
    return scale * np.linalg.pinv(J.T @ J)


class _BetterOptimum(Exception):
    def __init__(self, x, d):
        self.x, self.d = x, d


def profile_threshold(n: int, p: int, noise_estimated: bool, level: float = 0.95) -> float:
    """The rise of the deviance -2 log L that bounds a two-sided profile-likelihood interval of one parameter
    at ``level``: chi2_1(level) (3.841 at 0.95) with a known noise; with the noise level estimated from the
    same ``n`` points and ``p`` fitted quantities of the mean, n ln(1 + F_(1, n-p)(level)/(n - p)) (for a
    linear Gaussian model the likelihood-ratio statistic is that function of an F(1, n-p) variable; it tends
    to chi2_1(level) as n grows). At ``level`` 0.90 each end of the interval would be a one-sided 95 % bound
    of a regular likelihood (chi2_1(0.90) = 2.706 = 1.645^2; F_(1, nu)(0.90) = t_nu(0.95)^2); the ``bound``
    of a practically non-identifiable parameter uses 0.95 instead (:data:`BOUND_LEVEL`, the reasons in
    :mod:`restitution.fit.identifiability`).
    """
    dof = n - p
    if not noise_estimated or dof < 1:
        return CHI2_1_95 if level == 0.95 else float(stats.chi2.ppf(level, 1))
    return n * math.log1p(float(stats.f.ppf(level, 1, dof)) / dof)


def _profile_end(fitter: _Fitter, x_hat, d_min, i: int, direction: int, se: float, strict: bool = True,
                 threshold: float = CHI2_1_95):
    """(x_i at the interval's end, the full x there, reached the domain bound) on one side of the optimum;
    ``strict``: raise :class:`_BetterOptimum` where the profile finds a higher likelihood than the optimum's."""
    p = fitter.problem
    bound = p.upper[i] if direction > 0 else p.lower[i]
    target = d_min + threshold
    tol = 1e-7 * max(1.0, abs(d_min))
    warm = {"x": x_hat.copy()}

    def profile(xi):
        x0 = warm["x"].copy()
        x0[i] = xi
        x, d = fitter.solve(x0, fixed=i)
        if strict and d < d_min - tol:
            raise _BetterOptimum(x, d)
        warm["x"] = x
        return d, x

    if abs(bound - x_hat[i]) < 1e-12:
        return bound, x_hat.copy(), True
    step = min(max(2.0 * se, 1e-3), 1.0) if np.isfinite(se) and se > 0 else 0.1
    x_in, x_full_in = x_hat[i], x_hat.copy()
    while True:
        x_try = x_in + direction * step
        if (x_try - bound) * direction >= 0.0:
            x_try = bound
        d_try, x_full = profile(x_try)
        if d_try > target:
            warm["x"] = x_full_in
            try:
                root = brentq(lambda xi: profile(xi)[0] - target, min(x_in, x_try), max(x_in, x_try), xtol=_XTOL)
            except ValueError:  # re-solved from another start the profile no longer brackets (a flat, nearly
                root = x_try    # degenerate direction): the first point found above the threshold, a wider end
            d_root, x_root = profile(root)
            return root, x_root, False
        if x_try == bound:
            return bound, x_full, True
        x_in, x_full_in = x_try, x_full
        step *= 2.0


def _n_mean(lik, free) -> int:
    """The quantities fitted to the mean: the free parameters, the nuisance coordinates (v_1 of a drop) and
    a drop's profiled time origin."""
    return len(free) + len(lik.nuisance) + (1 if lik.kind == "impact_times" else 0)


def _setup(data, base, names, *, g, v1, h0, restitution_model, zener_method, model_options, start):
    """What a fit and a posterior share: (names, base, options, likelihood, the structural reason of each
    name (None: it enters e), the names fitted, the :class:`Problem`)."""
    names = check_names(names)
    base = check_base(base)
    options = {**FIT_OPTIONS, **(model_options or {}), "restitution_model": restitution_model,
               "zener_method": zener_method}
    impact(1.0, **base, **options)  # checks the options (ValueError naming a bad one)
    values = dict(base)
    for name, value in (start or {}).items():
        if value is None:  # a fit's estimate of a parameter that does not enter e
            continue
        check_names([name])
        low, high = domain(name)
        values[KEYS[name]] = min(max(float(value), low), high)
    lik = make_likelihood(data, options=options, g=g, v1=v1, h0=h0, base=values)
    speeds = lik.speeds(base)
    reasons = {name: structural_reason(speeds, base, name, options) for name in names}
    free = [name for name in names if reasons[name] is None]
    n_mean = _n_mean(lik, free)
    if lik.n < n_mean + (1 if lik.profiled else 0):  # a profiled noise level needs one degree of freedom
        raise DataError(f"{lik.n} data points for {n_mean} fitted quantities"
                        f"{' and the noise level' if lik.profiled else ''}: too few")
    coords = tuple(parameter_coordinate(name, values[KEYS[name]]) for name in free)
    return names, base, options, lik, reasons, free, Problem(lik, base, coords)


def _optimum(problem: Problem, grid: int):
    """(x, deviance) of the best fit from x = 0 (the start values) and, for one parameter, the grid's best."""
    fitter = _Fitter(problem)
    candidates = [problem.clip(np.zeros(problem.k))]
    grid_x = _grid_start(problem, grid)
    if grid_x is not None:
        candidates.append(grid_x)
    return min((fitter.solve(x) for x in candidates), key=lambda t: t[1])


def _estimate(name, reason, free, problem, fitter, x_hat, d_min, se, ends, threshold,
              one_sided) -> ParameterEstimate:
    """The :class:`ParameterEstimate` of ``name``: structurally non-identifiable (``reason``), or from its
    profile ``ends`` (None: not computed): both inside the domain, identifiable; one or both at the domain's
    bound, practically non-identifiable, with the bound the data give on the other side (the profile's end at
    ``one_sided``, the threshold of :data:`BOUND_LEVEL`: the end of the 95 % profile set)."""
    if reason is not None:
        return ParameterEstimate(name, KEYS[name], UNITS[name], None, None, False, reason,
                                 identifiability=STRUCTURAL)
    i = free.index(name)
    c = problem.parameters[i]
    est = float(c.to_value(x_hat[i]))
    if ends is None:
        return ParameterEstimate(name, c.key, c.unit, est, None, True, "", "profile not computed", float(se[i]),
                                 best=est)
    (x_lo, full_lo, at_lo), (x_hi, full_hi, at_hi) = ends[i]
    if not (at_lo or at_hi):
        return ParameterEstimate(name, c.key, c.unit, est, (float(c.to_value(x_lo)), float(c.to_value(x_hi))), True,
                                 se=float(se[i]), best=est)
    if at_lo and at_hi:
        return ParameterEstimate(name, c.key, c.unit, None, None, False, practical_reason(name, c, None, None, {}),
                                 se=float(se[i]), identifiability=PRACTICAL, best=est)
    side = -1 if at_hi else +1  # the side the data bound
    x_end, at_bound = (x_lo, at_lo) if side < 0 else (x_hi, at_hi)
    if one_sided != threshold:  # the bound's own level (BOUND_LEVEL)
        x_end, _, at_bound = _profile_end(fitter, x_hat, d_min, i, side, se[i], False, one_sided)
    value = float(c.to_value(x_end)) if not at_bound else (c.low if side < 0 else c.high)
    open_side, full_open = ("upper", full_hi) if at_hi else ("lower", full_lo)
    return ParameterEstimate(name, c.key, c.unit, None, None, False,
                             practical_reason(name, c, open_side, value, problem.split(full_open)[0]),
                             se=float(se[i]), identifiability=PRACTICAL,
                             bound={"lower" if side < 0 else "upper": value}, best=est)


def fit_parameters(data, base: dict, names, *, g: float = G_STANDARD, v1: float | None = None,
                   h0: float | None = None, restitution_model: str = "e45", zener_method: str = "exact",
                   model_options: dict | None = None, start: dict | None = None, profile: bool = True,
                   grid: int = 25) -> FitResult:
    """Estimate the model parameters ``names`` (FMU names: ``plate.Sy``, ...) from ``data``
    (:class:`restitution.fit.datasets.ReboundPairs`, ``ImpactTimes`` or a ``Recording``), the other
    parameters at ``base`` (impact keyword or FMU name -> value [SI]: the named materials and geometry,
    :func:`base_of`).

    ``g`` [m/s^2]: gravity of a drop; its first impact speed is ``v1`` [m/s], sqrt(2 g ``h0``) [m], or fitted
    (a nuisance parameter, as is the time origin). ``restitution_model``, ``zener_method``: as
    :func:`restitution.impact`; ``model_options``: more of its keywords (default both effects "on",
    :data:`restitution.fit.forward.FIT_OPTIONS`). ``start``: FMU name -> start value (default: ``base``);
    a single parameter also starts from the best of a ``grid``-point log grid over its domain.
    ``profile=False`` skips the profile-likelihood intervals (``ci95`` None; the estimates and the Hessian
    only). The noise level is estimated (profiled) unless ``data`` gives sigma. Returns a :class:`FitResult`;
    ValueError / DataError for bad arguments or too few data."""
    t_start = time.perf_counter()
    setup = _setup(data, base, names, g=g, v1=v1, h0=h0, restitution_model=restitution_model,
                   zener_method=zener_method, model_options=model_options, start=start)
    names, base, options, lik, reasons, free, problem = setup
    coords = problem.parameters
    fitter = _Fitter(problem)
    threshold = profile_threshold(lik.n, _n_mean(lik, free), lik.profiled)
    x_hat, d_min = _optimum(problem, grid)

    ends = {}
    attempts = 4
    for attempt in range(attempts):
        cov = _covariance(problem, x_hat)
        se = np.sqrt(np.clip(np.diag(cov), 0.0, None))
        if not profile:
            break
        strict = attempt < attempts - 1  # the last attempt takes the optimum as it is
        try:
            ends = {i: tuple(_profile_end(fitter, x_hat, d_min, i, side, se[i], strict, threshold)
                             for side in (-1, +1))
                    for i in range(len(coords))}
            break
        except _BetterOptimum as better:  # the profile found a higher likelihood: start again from there
            x_hat, d_min = fitter.solve(better.x)
            ends = {}

    params_hat, z_hat = problem.split(x_hat)
    one_sided = profile_threshold(lik.n, _n_mean(lik, free), lik.profiled, level=BOUND_LEVEL)
    estimates = {name: _estimate(name, reasons[name], free, problem, fitter, x_hat, d_min, se,
                                 ends if profile else None, threshold, one_sided)
                 for name in names}

    cov_p = cov[np.ix_(range(len(free)), range(len(free)))]
    corr = correlation_of(cov_p) if free else np.zeros((0, 0))
    combined = combinations(problem, x_hat, cov, corr, list(range(len(free)))) if len(free) > 1 else ()

    nuisance = {}
    if lik.kind == "impact_times":
        v1_value = lik.v1 if lik.v1 is not None else float(z_hat[0])
        entry = {"estimate": v1_value, "unit": "m/s", "fitted": lik.v1 is None}
        if lik.v1 is None:
            entry["se_log"] = float(se[len(coords)])
        nuisance = {"v1": entry, "t1": {"estimate": lik.t1(params_hat, z_hat), "unit": "s", "fitted": True}}
    flags = lik.flags(params_hat, z_hat)
    lof = lack_of_fit(problem, x_hat)
    d_final = fitter.deviance(x_hat)
    return FitResult(
        kind=lik.kind, n=lik.n, parameters=estimates, noise=lik.noise(params_hat, z_hat, len(free)),
        nuisance=nuisance, residuals=np.asarray(lik.data_residuals(params_hat, z_hat), dtype=float),
        correlation_names=tuple(free), correlation_matrix=corr, combinations=combined,
        out_of_range=int(np.count_nonzero(flags["any"])), flags=flags, log_likelihood=-0.5 * d_final,
        evaluations=problem.evaluations, elapsed=time.perf_counter() - t_start, options=options,
        lack_of_fit=lof)
