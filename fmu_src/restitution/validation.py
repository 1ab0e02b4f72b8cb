"""Checks on user input: a clear ValueError naming the parameter, its value and the allowed range."""
from __future__ import annotations

import math

import numpy as np

from ._num import is_scalar

__all__ = ["check_positive", "check_nonnegative", "check_nonnegative_or_infinite", "check_poisson", "check_choice"]


def _check(name, value, unit, ok_scalar, ok_array, allowed):
    if is_scalar(value):
        v = float(value)
        if not ok_scalar(v):
            raise ValueError(f"{name} = {v!r}{unit} is outside the allowed range: {allowed}")
        return v
    arr = np.asarray(value, dtype=float)
    if arr.size and ok_scalar(float(arr.min())) and ok_scalar(float(arr.max())):
        # every range allowed here is an interval, so its two ends decide for the whole array: two
        # reductions instead of an elementwise mask (NaN propagates through min and max: refused, and
        # the mask below finds it)
        return arr
    with np.errstate(invalid="ignore"):
        good = ok_array(arr)
    if not np.all(good):
        bad_value = float(arr[~good].flat[0]) if arr.ndim else float(arr)
        raise ValueError(f"{name} = {bad_value!r}{unit} is outside the allowed range: {allowed}")
    return arr


def check_positive(name: str, value, unit: str = ""):
    """Require finite values > 0."""
    if value.__class__ is float and 0.0 < value < math.inf:  # fast path, same result
        return value
    u = f" {unit}" if unit else ""
    return _check(name, value, u, lambda v: math.isfinite(v) and v > 0.0,
                  lambda a: np.isfinite(a) & (a > 0.0), "finite and > 0")


def check_nonnegative(name: str, value, unit: str = ""):
    """Require finite values >= 0."""
    if value.__class__ is float and 0.0 <= value < math.inf:  # fast path, same result
        return value
    u = f" {unit}" if unit else ""
    return _check(name, value, u, lambda v: math.isfinite(v) and v >= 0.0,
                  lambda a: np.isfinite(a) & (a >= 0.0), "finite and >= 0")


def check_nonnegative_or_infinite(name: str, value, unit: str = "", allowed: str = ">= 0"):
    """Require values >= 0, +inf included (NaN refused); ``allowed`` says what the range means."""
    if value.__class__ is float and value >= 0.0:  # fast path, same result
        return value
    u = f" {unit}" if unit else ""
    return _check(name, value, u, lambda v: v >= 0.0, lambda a: a >= 0.0, allowed)


def check_poisson(name: str, value):
    """Require a Poisson's ratio in [0, 0.5] (0.5: incompressible; the model uses nu only through
    E' = E/(1 - nu^2), Eq. 1, and C(nu), Eq. 2, both finite there)."""
    if value.__class__ is float and 0.0 <= value <= 0.5:  # fast path, same result
        return value
    return _check(name, value, "", lambda v: 0.0 <= v <= 0.5,
                  lambda a: (a >= 0.0) & (a <= 0.5), "0 <= nu <= 0.5")


def check_choice(name: str, value, choices):
    if value not in choices:
        raise ValueError(f"{name} = {value!r} is not one of {sorted(choices)}")
    return value
