"""The forward models a calibration fits: what the model predicts for each kind of measurement
(:mod:`restitution.fit.datasets`), from :func:`restitution.impact`'s apparent COR e(v).

* rebound pairs: v_out = e(v_in; theta) v_in (:func:`rebound_speeds`);
* the impact times of one drop (:func:`bounce_train`): v_(k+1) = e(v_k) v_k, t_(k+1) - t_k = 2 v_(k+1) / g
  (free flight, no drag), from the first impact speed v_1 and the time origin t_1.

Parameters are passed as a dict of :func:`restitution.impact` keywords (``sphere_E``, ..., ``plate_t``).
Every function also takes a batch: parameter values (and v_1) may be arrays of shape (B,), giving
predictions of shape (B, n) (one row per parameter set; the posterior sampler evaluates its walkers so).

The FMU names (``plate.Sy``) of the parameters map to the keywords by :data:`KEYS`
(the interface table of SpherePlateImpact gives the same: tests/fit check it).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..flight import flight_to_plate
from ..model import DOMAIN, PARAMETERS, impact

__all__ = ["G_STANDARD", "PARAMETER_NAMES", "KEYS", "UNITS", "FIT_OPTIONS", "check_base", "check_names",
           "restitution_at", "rebound_speeds", "BounceTrain", "bounce_train", "drop_speed", "domain"]

#: Standard gravity [m/s^2].
G_STANDARD = 9.80665

#: The model parameters by their FMU names, in :func:`restitution.impact`'s order.
PARAMETER_NAMES = tuple(key.replace("_", ".", 1) for key, _unit, _kind in PARAMETERS)
#: FMU name -> :func:`restitution.impact` keyword.
KEYS = {name: key for name, (key, _unit, _kind) in zip(PARAMETER_NAMES, PARAMETERS)}
#: FMU name -> SI unit.
UNITS = {name: unit for name, (_key, unit, _kind) in zip(PARAMETER_NAMES, PARAMETERS)}

#: The options a fit passes to :func:`restitution.impact` unless told otherwise: both effects always on.
#: "auto" skips an effect below ``effect_tolerance`` (1e-6 in e), a step that finite-difference
#: derivatives (steps of ~1e-6 in log theta) would see as a huge slope; "on" is smooth and differs from
#: "auto" by less than that tolerance.
FIT_OPTIONS = {"plasticity": "on", "plate_waves": "on"}

#: Poisson's ratio: [0, 0.5] (:func:`restitution.domain.check_poisson`); the fit stays just below 0.5.
_NU_DOMAIN = (0.0, 0.5)


def domain(name: str) -> tuple[float, float]:
    """The physical range (low, high) [SI] of the parameter ``name`` (FMU name): :data:`restitution.domain.DOMAIN`,
    and [0, 0.5] for Poisson's ratios."""
    key = KEYS[name]
    return _NU_DOMAIN if key.endswith("_nu") else DOMAIN[key]


def check_names(names) -> tuple[str, ...]:
    """``names`` (FMU parameter names) as a tuple, each known and given once; ValueError otherwise."""
    if isinstance(names, str):
        names = (names,)
    names = tuple(names)
    if not names:
        raise ValueError("no parameter to fit: name at least one of " + ", ".join(PARAMETER_NAMES))
    for name in names:
        if name not in KEYS:
            hint = f" (did you mean {name.replace('_', '.', 1)!r}?)" if name.replace("_", ".", 1) in KEYS else ""
            raise ValueError(f"unknown parameter {name!r}{hint}: one of {', '.join(PARAMETER_NAMES)}")
    if len(set(names)) != len(names):
        raise ValueError(f"a parameter is named twice in {list(names)}")
    return names


def check_base(base: dict) -> dict:
    """``base`` (impact keyword or FMU name -> value) as {impact keyword: float}, every parameter given once,
    inside its domain (:func:`domain`); ValueError naming the fault otherwise."""
    out = {}
    for name, value in dict(base).items():
        key = KEYS.get(name, name)
        if key not in KEYS.values():
            raise ValueError(f"base: unknown parameter {name!r}: impact keywords ({', '.join(KEYS.values())}) "
                             "or FMU names")
        if key in out:
            raise ValueError(f"base: {key} is given twice")
        out[key] = float(value)
    missing = [key for key in KEYS.values() if key not in out]
    if missing:
        raise ValueError(f"base: missing {', '.join(missing)} (give every parameter: the named materials and "
                         "geometry, e.g. dict(**Sphere(...).params(), **Plate(...).params()))")
    for name, key in KEYS.items():
        low, high = domain(name)
        if not (math.isfinite(out[key]) and low <= out[key] <= high):
            raise ValueError(f"base: {name} = {out[key]!r} is outside its domain [{low:g}, {high:g}]")
    return {key: out[key] for key in KEYS.values()}


def _batched(params: dict, trailing: int) -> dict:
    """``params`` with every array value given ``trailing`` new trailing axes (a batch of parameter sets
    against the points of one data set)."""
    if not trailing:
        return params
    return {key: (value if np.ndim(value) == 0 else np.asarray(value, dtype=float)[(...,) + (None,) * trailing])
            for key, value in params.items()}


def restitution_at(v, params: dict, options: dict | None = None):
    """:func:`restitution.impact` at speeds ``v`` [m/s] with ``params`` (impact keywords; checked by the
    caller) and ``options`` (default :data:`FIT_OPTIONS`)."""
    return impact(v, **params, **(FIT_OPTIONS if options is None else options), validate=False)


def rebound_speeds(v_in, params: dict, options: dict | None = None):
    """(v_out [m/s], the :class:`restitution.ImpactResult`) predicted for approach speeds ``v_in`` [m/s]:
    e(v_in; params) v_in. A batch of B parameter sets (array values of shape (B,)) gives shape (B, n)."""
    v_in = np.asarray(v_in, dtype=float)
    batch = any(np.ndim(value) for value in params.values())
    result = restitution_at(v_in, _batched(params, v_in.ndim) if batch else params, options)
    return np.asarray(result.e) * v_in, result


def drop_speed(h0: float, g: float = G_STANDARD) -> float:
    """Speed [m/s] of the first impact after a drop from rest at height ``h0`` [m] (no drag): sqrt(2 g h0)."""
    if not (h0 > 0.0 and math.isfinite(h0)):
        raise ValueError(f"h0 = {h0!r} m: a drop height is finite and > 0")
    return math.sqrt(2.0 * g * h0)


@dataclass(frozen=True)
class BounceTrain:
    """The impacts of one drop as the model predicts them, shape (n,) (or (B, n) for a batch):
    ``times`` [s] (the first at ``t1``), approach ``speeds`` v_k [m/s], and at each impact ``e``, ``lam``
    (Zener's lambda) and ``V_star`` (JGM's v/V_c). An impact with e < 0 ends the train (the sphere moves
    on with the plate): the later speeds are 0 and their times repeat the last one."""

    times: np.ndarray
    speeds: np.ndarray
    e: np.ndarray
    lam: np.ndarray
    V_star: np.ndarray

    @property
    def intervals(self) -> np.ndarray:
        """t_(k+1) - t_k [s], shape (n - 1,) (or (B, n - 1))."""
        return np.diff(self.times, axis=-1)


def bounce_train(v1, n: int, params: dict, *, g: float = G_STANDARD, t1=0.0,
                 options: dict | None = None) -> BounceTrain:
    """The first ``n`` impacts of a sphere bouncing on the plate, from the first impact speed ``v1`` [m/s] and
    time ``t1`` [s]: v_(k+1) = e(v_k) v_k, t_(k+1) = t_k + 2 v_(k+1) / g (free flight under ``g`` [m/s^2],
    no drag). Python floats take :func:`restitution.impact`'s scalar path (~10 us an impact); arrays of
    shape (B,) (``v1``, ``t1`` or parameter values) give a batch of B trains, shape (B, n)."""
    if n < 1:
        raise ValueError(f"n = {n}: at least one impact")
    batch = np.ndim(v1) > 0 or any(np.ndim(value) for value in params.values())
    if batch:
        v = np.broadcast_to(np.asarray(v1, dtype=float),
                            np.broadcast_shapes(np.shape(v1), *(np.shape(x) for x in params.values()))).copy()
    else:
        v = float(v1)
        params = {key: float(value) for key, value in params.items()}
    speeds, es, lams, vstars = [], [], [], []
    for _ in range(n):
        result = restitution_at(v, params, options)
        speeds.append(v)
        es.append(result.e)
        lams.append(result.lam)
        vstars.append(result.V_star)
        v = np.maximum(result.e, 0.0) * v if batch else max(result.e, 0.0) * v
    speeds, es, lams, vstars = (np.stack(np.broadcast_arrays(*x), axis=-1) if batch else np.array(x)
                                for x in (speeds, es, lams, vstars))
    flights = flight_to_plate(0.0, speeds[..., 1:], g)[0]
    times = np.concatenate([np.zeros(speeds.shape[:-1] + (1,)), np.cumsum(flights, axis=-1)], axis=-1)
    times = times + np.asarray(t1, dtype=float)[..., None] if np.ndim(t1) else times + float(t1)
    return BounceTrain(times=times, speeds=speeds, e=es, lam=lams, V_star=vstars)
