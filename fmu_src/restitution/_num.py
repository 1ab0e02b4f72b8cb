"""Elementwise maths that serves both Python floats and numpy arrays.

The FMU evaluates one impact at a time with Python floats, sweeps evaluate
millions with arrays. Writing each equation once against these helpers keeps a
single source of truth while the scalar path avoids numpy's per-call overhead
(a ``math.exp`` costs ~50 ns, ``np.exp`` on a float ~1 us).
"""
from __future__ import annotations

import math

import numbers

import numpy as np

__all__ = ["decimal_like", "POW10", "DECIMAL_BLOCK", "is_scalar", "exp", "expm1", "log", "sqrt", "fifth_root", "where", "minimum", "maximum", "as_output"]


def is_scalar(x) -> bool:
    """True for real scalars (float, int, numpy's, Fraction: ``numbers.Real`` but not bool), False for
    arrays (even 0-d ones) and anything else."""
    if x.__class__ is float:  # the common case first: ~40 ns instead of ~130 ns
        return True
    return isinstance(x, numbers.Real) and not isinstance(x, (bool, np.bool_))


# Below this argument exp() would return a subnormal or 0 and raise numpy's
# underflow flag; the result is returned as an exact 0 instead.
_EXP_MIN_ARG = -708.0


def exp(x):
    """exp(x); 0 (not a subnormal, no underflow flag) for x < -708."""
    if x.__class__ is float or is_scalar(x):
        return math.exp(x) if x >= _EXP_MIN_ARG else 0.0
    x = np.asarray(x, dtype=float)
    return np.where(x < _EXP_MIN_ARG, 0.0, np.exp(np.maximum(x, _EXP_MIN_ARG)))


def expm1(x):
    """exp(x) - 1 without cancellation for small |x|; -1 (no underflow flag) for x < -708."""
    if x.__class__ is float or is_scalar(x):
        return math.expm1(x) if x >= _EXP_MIN_ARG else -1.0
    x = np.asarray(x, dtype=float)
    return np.where(x < _EXP_MIN_ARG, -1.0, np.expm1(np.maximum(x, _EXP_MIN_ARG)))


def log(x):
    return math.log(x) if x.__class__ is float or is_scalar(x) else np.log(x)


def sqrt(x):
    return math.sqrt(x) if x.__class__ is float or is_scalar(x) else np.sqrt(x)


def fifth_root(x):
    """x^(1/5) of x >= 0: pow for floats; exp(0.2 ln x) for arrays, a third cheaper than numpy's pow, within
    eps (4 + |ln x| / 5) of the exact root (the rounding of ln x carried through exp), and 0 at x = 0
    (ln 0 = -inf, no divide-by-zero flag raised)."""
    if x.__class__ is float or np.ndim(x) == 0:
        return float(x) ** 0.2
    with np.errstate(divide="ignore"):
        root = np.log(x)
    root *= 0.2
    return np.exp(root, out=root)


def where(cond, a, b):
    """``a`` where ``cond`` else ``b``; both branches must already be safe to evaluate."""
    if cond.__class__ is bool or isinstance(cond, np.bool_):
        return a if cond else b
    return np.where(cond, a, b)


def minimum(a, b):
    if (a.__class__ is float or is_scalar(a)) and (b.__class__ is float or is_scalar(b)):
        return a if a <= b else b
    return np.minimum(a, b)


def maximum(a, b):
    if (a.__class__ is float or is_scalar(a)) and (b.__class__ is float or is_scalar(b)):
        return a if a >= b else b
    return np.maximum(a, b)


def as_output(x):
    """Python float for scalar results, ndarray otherwise."""
    if is_scalar(x) or (isinstance(x, np.ndarray) and x.ndim == 0):
        return float(x)
    return x


#: A computed value within SNAP_ULPS ulps of a decimal of SNAP_DIGITS significant digits is that decimal's
#: double (an ulp taken as 2**-52 of the value: at the foot of a binade, up to twice as many).
SNAP_DIGITS = 12
SNAP_ULPS = 2
_SNAP_REL = SNAP_ULPS * 2.0**-52
#: 10**k for k = 0 ... 22, each exact as a double.
POW10 = np.array([float(10**k) for k in range(23)])
#: For k = -22 ... 22 (index k + 22), a decimal with k places is digits * _MUL / _DIV, one exact factor 1.
_MUL = np.concatenate([POW10[:0:-1], np.ones(23)])
_DIV = np.concatenate([np.ones(22), POW10])
#: Values handled at a time (bounds the temporaries of an axis of 10^8 values, and keeps them in cache).
DECIMAL_BLOCK = 1 << 16


def decimal_like(values) -> np.ndarray:
    """``values`` with each one that lies within :data:`SNAP_ULPS` ulps of a decimal of
    :data:`SNAP_DIGITS` significant digits replaced by the double nearest that decimal (the others,
    zeros and non-finite values as they are): the rounding of a computation, an ulp or two, taken off a
    value that is a short decimal (7.999999999999999 is 8, 0.0045000000000000005 is 0.0045)."""
    x = np.array(values, dtype=float, ndmin=1)
    for lo in range(0, x.size, DECIMAL_BLOCK):
        block = x[lo:lo + DECIMAL_BLOCK]
        with np.errstate(all="ignore"):
            size = np.abs(block)
            places = (SNAP_DIGITS - 1 + 22) - np.floor(np.log10(size))  # of a SNAP_DIGITS-digit decimal, + 22
            fine = (places >= 0) & (places <= 44)  # False where NaN: zeros, non-finite values
            k = np.where(fine, places, 22).astype(np.intp)
            mul, div = _MUL[k], _DIV[k]
            digits = np.rint(block * div / mul)  # an integer below 10^13: exact
            near = digits * mul / div  # one correctly rounded operation (the other is by 1)
            fine &= np.abs(near - block) <= _SNAP_REL * size
        np.copyto(block, near, where=fine)
    return x if np.ndim(values) else x[:1].reshape(())
