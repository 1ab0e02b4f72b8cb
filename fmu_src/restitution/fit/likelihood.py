"""Gaussian likelihoods of the measurements (:mod:`restitution.fit.datasets`) given the model's parameters,
written as least squares: each likelihood gives a residual vector r whose sum of squares S decides the
deviance D = -2 log L (noise profiled out analytically, i.e. maximised over).

* :class:`PairsLikelihood`, rebound pairs: v_out_k ~ N(m_k, sigma_k^2), m_k = e(v_in_k) v_in_k.
  - ``sigma`` unknown (the default): relative noise sigma_k = s m_k, s profiled:
    s^2 = (1/n) sum((v_out_k - m_k)/m_k)^2 and D = n log(S/n) + n (1 + log 2 pi), S = G^2 sum(((v_out_k - m_k)/m_k)^2)
    with G the geometric mean of the m_k: the term sum(log sigma_k) of the Gaussian density, which depends
    on theta through m_k, is carried by G, so that least squares on r_k = G (v_out_k - m_k)/m_k
    maximises the likelihood itself (not only the relative sum of squares).
  - ``sigma`` given: absolute and known, r_k = (v_out_k - m_k)/sigma_k, D = S + sum(log(2 pi sigma_k^2)).
* :class:`TimesLikelihood`, the impact times of one drop: t_k ~ N(t_1 + T_k, sigma_t^2) i.i.d. (timing
  jitter), T_k the model's flight-time sums (:func:`restitution.fit.forward.bounce_train`). The origin t_1
  is profiled analytically (the mean offset), sigma_t too: D = n log(S/n) + n (1 + log 2 pi). The first
  impact speed v_1 is a nuisance coordinate of the fit unless given.

The fitted quantities are :class:`Coordinate` s: x = ln(value/ref) for the positive quantities (they span
decades), x = value - ref for Poisson's ratios, bounded by the physical domain
(:func:`restitution.fit.forward.domain`, :data:`restitution.domain.DOMAIN`). :class:`Problem` puts a
likelihood, the fixed parameters and the fitted coordinates together: x -> residuals, deviance.

A noise-free data set would make S = 0 and D = -inf: S is floored at relative residuals of 1e-12
(times: 1e-12 of the drop's duration).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import stats

from .datasets import DataError, ImpactTimes, ReboundPairs, Recording
from .forward import (G_STANDARD, KEYS, UNITS, bounce_train, domain, drop_speed, rebound_speeds, restitution_at)

__all__ = ["CHI2_1_95", "Coordinate", "parameter_coordinate", "PairsLikelihood", "TimesLikelihood",
           "make_likelihood", "Problem"]

#: chi2 quantile of 1 degree of freedom at 0.95: the profile-likelihood threshold of a 95 % interval.
CHI2_1_95 = float(stats.chi2.ppf(0.95, 1))  # 3.8414588...

_LOG_2PI = math.log(2.0 * math.pi)
#: Speeds [m/s] a first impact may have (v_1, when fitted).
V1_DOMAIN = (1e-6, 1e4)
#: Poisson's ratio's upper end inside the fit (0.5 itself is allowed by the model; the margin keeps x finite).
_NU_TOP = 0.5 - 1e-9
#: Relative floor of the residuals (a noise-free data set stays finite).
_FLOOR = 1e-12


@dataclass(frozen=True)
class Coordinate:
    """One fitted quantity: ``name`` (FMU name, or "v1"), ``key`` (impact keyword, or "v1"), ``unit``;
    x = ln(value/ref) when ``log`` (else value - ref), value in [``low``, ``high``]."""

    name: str
    key: str
    unit: str
    ref: float
    low: float
    high: float
    log: bool = True

    def to_x(self, value):
        return np.log(np.asarray(value, dtype=float) / self.ref) if self.log else np.asarray(value, float) - self.ref

    def to_value(self, x):
        return self.ref * np.exp(x) if self.log else self.ref + np.asarray(x, dtype=float)

    @property
    def x_bounds(self) -> tuple[float, float]:
        return float(self.to_x(self.low)), float(self.to_x(self.high))

    def clip(self, value: float) -> float:
        return float(min(max(value, self.low), self.high))


def parameter_coordinate(name: str, ref: float) -> Coordinate:
    """The coordinate of the model parameter ``name`` (FMU name) about ``ref`` [SI]."""
    low, high = domain(name)
    key = KEYS[name]
    if key.endswith("_nu"):
        return Coordinate(name, key, UNITS[name], float(ref), low, _NU_TOP, log=False)
    return Coordinate(name, key, UNITS[name], float(ref), low, high, log=True)


class PairsLikelihood:
    """Rebound pairs (:class:`ReboundPairs`): relative noise profiled, or ``sigma`` known (module doc)."""

    kind = ReboundPairs.kind

    def __init__(self, data: ReboundPairs, options: dict | None = None):
        self.data = data
        self.options = options
        self.n = data.n
        self.relative = data.sigma is None
        self.profiled = self.relative  # the noise level is estimated (one more fitted quantity)
        self.nuisance: tuple[Coordinate, ...] = ()
        self._floor = self.n * (_FLOOR * float(np.mean(data.v_out) or np.mean(data.v_in))) ** 2

    def speeds(self, params: dict) -> np.ndarray:
        """The impact speeds the data cover [m/s]."""
        return self.data.v_in

    def model(self, params: dict, z=None) -> np.ndarray:
        return rebound_speeds(self.data.v_in, params, self.options)[0]

    def residuals(self, params: dict, z=None) -> np.ndarray:
        """The weighted residuals r (shape (n,), or (B, n) for a batch), sum r^2 = S."""
        m = self.model(params)
        if not self.relative:
            return (self.data.v_out - m) / self.data.sigma
        # a model speed <= 0 (e <= 0) cannot carry relative noise: its sigma is floored (the residual is huge)
        m = np.maximum(m, 1e-6 * self.data.v_in)
        log_g = np.mean(np.log(m), axis=-1, keepdims=True)
        return np.exp(log_g) * (self.data.v_out - m) / m

    def deviance(self, S):
        """-2 log L for the sum of squares S (the profiled noise level at its maximum)."""
        if self.relative:
            S = np.maximum(S, self._floor)
            return self.n * (np.log(S / self.n) + 1.0 + _LOG_2PI)
        return S + float(np.sum(np.log(self.data.sigma ** 2))) + self.n * _LOG_2PI

    def data_residuals(self, params: dict, z=None) -> np.ndarray:
        """v_out - v_out_model [m/s]."""
        return self.data.v_out - self.model(params)

    def noise(self, params: dict, z, n_fitted: int) -> dict:
        """The noise estimate at ``params`` (``n_fitted``: the fitted parameters, for the degrees of freedom)."""
        m = self.model(params)
        dof = self.n - n_fitted
        if self.relative:
            s = math.sqrt(float(np.mean(((self.data.v_out - m) / np.maximum(m, 1e-6 * self.data.v_in)) ** 2)))
            return {"model": "relative", "s": s, "s_dof": s * math.sqrt(self.n / max(dof, 1)), "dof": dof,
                    "description": "sigma_k = s * v_out_model_k; s: maximum likelihood (s_dof: divided by n - p)"}
        chi2 = float(np.sum(((self.data.v_out - m) / self.data.sigma) ** 2))
        return {"model": "known", "chi2": chi2, "dof": dof, "chi2_per_dof": chi2 / max(dof, 1),
                "p_value": float(stats.chi2.sf(chi2, max(dof, 1))),
                "description": "sigma_k given (absolute, known); chi2 of the fit and its upper-tail probability"}

    def flags(self, params: dict, z=None) -> dict:
        """Per point: the model outside its validated ranges (lambda > 1.5, V* > 1000) or e < 0."""
        result = restitution_at(self.data.v_in, params, self.options)
        return _flags(result.lam, result.V_star, result.e, self.n)


class TimesLikelihood:
    """The impact times of one drop (:class:`ImpactTimes`): timing jitter sigma_t and the time origin
    profiled; v_1 fitted (a nuisance coordinate) unless ``v1`` is given."""

    kind = ImpactTimes.kind

    def __init__(self, data: ImpactTimes, options: dict | None = None, g: float = G_STANDARD,
                 v1: float | None = None, base: dict | None = None):
        if not (g > 0.0 and math.isfinite(g)):
            raise ValueError(f"g = {g!r} m/s^2: finite and > 0")
        self.data = data
        self.options = options
        self.g = float(g)
        self.n = data.n
        self.profiled = True
        self.t = data.t
        self._floor = self.n * (_FLOOR * float(data.t[-1] - data.t[0])) ** 2
        self.v1 = None if v1 is None else float(v1)
        if self.v1 is not None and not (V1_DOMAIN[0] <= self.v1 <= V1_DOMAIN[1]):
            raise ValueError(f"v1 = {v1!r} m/s is outside [{V1_DOMAIN[0]:g}, {V1_DOMAIN[1]:g}]")
        if self.v1 is None:
            ref = float(self.v1_guess(base)) if base is not None else float(self.rebound_speeds_observed()[0])
            self.nuisance = (Coordinate("v1", "v1", "m/s", min(max(ref, V1_DOMAIN[0]), V1_DOMAIN[1]), *V1_DOMAIN),)
        else:
            self.nuisance = ()

    def rebound_speeds_observed(self) -> np.ndarray:
        """v_2 ... v_n [m/s] from the flight times: v_(k+1) = g (t_(k+1) - t_k)/2 (exact in the model)."""
        return 0.5 * self.g * np.diff(self.t)

    def v1_guess(self, params: dict, iterations: int = 8):
        """The first impact speed that makes e(v_1) v_1 = v_2 (observed) with ``params`` (a fixed point;
        arrays of parameters give an array)."""
        v2 = float(self.rebound_speeds_observed()[0])
        v1 = v2 / 0.8
        for _ in range(iterations):
            e = np.asarray(restitution_at(v1, params, self.options).e)
            v1 = v2 / np.maximum(e, 0.05)
        return np.clip(v1, *V1_DOMAIN)

    def speeds(self, params: dict) -> np.ndarray:
        """The impact speeds the data cover [m/s]: v_1 (given, or its guess) and the observed v_2 ... v_n."""
        v1 = self.v1 if self.v1 is not None else float(self.v1_guess(params))
        return np.concatenate([[v1], self.rebound_speeds_observed()])

    def _v1(self, z):
        if self.v1 is not None:
            return self.v1
        z = np.asarray(z, dtype=float)
        return float(z[0]) if z.ndim == 1 else z[..., 0]

    def train(self, params: dict, z=None):
        return bounce_train(self._v1(z), self.n, params, g=self.g, options=self.options)

    def _offsets(self, params, z):
        return self.t - self.train(params, z).times

    def residuals(self, params: dict, z=None) -> np.ndarray:
        """t_k - (t_1 + T_k) with the profiled origin t_1 (mean offset) [s]; sum r^2 = S."""
        c = self._offsets(params, z)
        return c - np.mean(c, axis=-1, keepdims=True)

    def deviance(self, S):
        S = np.maximum(S, self._floor)
        return self.n * (np.log(S / self.n) + 1.0 + _LOG_2PI)

    def t1(self, params: dict, z=None) -> float:
        """The profiled time origin [s] (the first impact's time, as the model places it)."""
        return float(np.mean(self._offsets(params, z)))

    def data_residuals(self, params: dict, z=None) -> np.ndarray:
        """t_k - t_k,model [s] (with the profiled origin)."""
        return self.residuals(params, z)

    def noise(self, params: dict, z, n_fitted: int) -> dict:
        S = float(np.sum(self.residuals(params, z) ** 2))
        dof = self.n - n_fitted - 1 - (1 if self.v1 is None else 0)  # the origin t_1 and v_1 are fitted too
        return {"model": "timing_jitter", "sigma_t": math.sqrt(S / self.n),
                "sigma_t_dof": math.sqrt(S / max(dof, 1)), "dof": dof,
                "description": "i.i.d. Gaussian jitter on each impact time; sigma_t: maximum likelihood "
                               "(sigma_t_dof: divided by n - p)"}

    def flags(self, params: dict, z=None) -> dict:
        train = self.train(params, z)
        return _flags(train.lam, train.V_star, train.e, self.n)


def _flags(lam, V_star, e, n) -> dict:
    lam_out = np.broadcast_to(np.asarray(lam) > 1.5, (n,))
    vstar_out = np.broadcast_to(np.asarray(V_star) > 1000.0, (n,))
    negative = np.broadcast_to(np.asarray(e) < 0.0, (n,))
    return {"lambda_above_1_5": lam_out.copy(), "vstar_above_1000": vstar_out.copy(), "e_negative": negative.copy(),
            "any": lam_out | vstar_out | negative}


def make_likelihood(data, *, options: dict | None = None, g: float = G_STANDARD, v1: float | None = None,
                    h0: float | None = None, base: dict | None = None):
    """The likelihood of ``data`` (:class:`ReboundPairs`, :class:`ImpactTimes` or a :class:`Recording`'s
    times). For impact times, v_1 is ``v1`` [m/s], sqrt(2 g ``h0``) [m], or fitted (neither given)."""
    if isinstance(data, Recording):
        data = data.times
    if isinstance(data, ReboundPairs):
        if v1 is not None or h0 is not None:
            raise ValueError("v1 and h0 are for impact times (a drop), not rebound pairs")
        return PairsLikelihood(data, options)
    if isinstance(data, ImpactTimes):
        if v1 is not None and h0 is not None:
            raise ValueError("give v1 or h0, not both")
        if h0 is not None:
            v1 = drop_speed(float(h0), g)
        return TimesLikelihood(data, options, g=g, v1=v1, base=base)
    raise DataError(f"cannot fit {type(data).__name__}: ReboundPairs, ImpactTimes or Recording")


class Problem:
    """A likelihood with the parameters ``base`` (impact keyword -> value) of which ``coordinates`` are
    fitted, followed by the likelihood's nuisance coordinates: x (shape (k,), or (B, k) for a batch)
    -> parameters, residuals, deviance."""

    def __init__(self, likelihood, base: dict, coordinates: tuple[Coordinate, ...]):
        self.likelihood = likelihood
        self.base = dict(base)
        self.parameters = tuple(coordinates)
        self.coordinates = self.parameters + tuple(likelihood.nuisance)
        self.k = len(self.coordinates)
        bounds = np.array([c.x_bounds for c in self.coordinates], dtype=float).reshape(self.k, 2)
        self.lower, self.upper = bounds[:, 0], bounds[:, 1]
        self.evaluations = 0

    def split(self, x):
        """(parameters dict, nuisance values) at x."""
        x = np.asarray(x, dtype=float)
        params = dict(self.base)
        for i, c in enumerate(self.parameters):
            value = c.to_value(x[..., i])
            params[c.key] = float(value) if np.ndim(value) == 0 else value
        z = np.stack([c.to_value(x[..., len(self.parameters) + j]) for j, c in enumerate(self.likelihood.nuisance)],
                     axis=-1) if self.likelihood.nuisance else None
        return params, z

    def x_of(self, values: dict) -> np.ndarray:
        """x from {coordinate name: value}."""
        return np.array([float(c.to_x(values[c.name])) for c in self.coordinates])

    def values(self, x) -> dict:
        """{coordinate name: value} at x."""
        return {c.name: float(c.to_value(xi)) for c, xi in zip(self.coordinates, np.asarray(x, dtype=float))}

    def residuals(self, x) -> np.ndarray:
        self.evaluations += 1
        params, z = self.split(x)
        return self.likelihood.residuals(params, z)

    def deviance(self, x):
        """-2 log L at x (the noise profiled); +inf outside the bounds."""
        r = self.residuals(x)
        return self.likelihood.deviance(np.sum(r * r, axis=-1))

    def log_likelihood(self, x):
        return -0.5 * self.deviance(x)

    def clip(self, x) -> np.ndarray:
        return np.clip(np.asarray(x, dtype=float), self.lower, self.upper)
