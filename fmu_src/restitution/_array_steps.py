"""The steps of :func:`restitution.model.impact`'s pipeline that only its array mode takes: owned result
arrays, the masks of the effect modes' skips and of speed 0 (Zener where a mask holds is
:func:`restitution.zener.zener_solution_where`). The pipeline itself (one code for floats and arrays)
stays in :mod:`restitution.model`."""
from __future__ import annotations

import math
from fractions import Fraction
from functools import lru_cache

import numpy as np

from ._num import where


def _own_array(x, shape, dtype):
    """``x`` as an array of ``shape`` and ``dtype`` that no other field or input shares.

    A temporary that already is one is used as is (copying 1e5-element results cost as
    much as computing them); anything else (scalars, views) is broadcast and copied. Every value
    the pipeline hands over is a fresh temporary or a scalar, never an input and never the same
    object twice (tests/physics/test_model_contract.py checks that no field shares memory with an input
    or another field, in every effect mode), so an owned array of the right kind is safe to keep.
    """
    if x.__class__ is np.ndarray and x.shape == shape and x.dtype == dtype and x.flags.owndata:
        return x
    if np.ndim(x) == 0:  # a value shared by every case (a material term, a flag): one fill
        return np.full(shape, x, dtype=dtype)
    return np.broadcast_to(x, shape).astype(dtype)


def _skip_small_loss(e_ep, tolerance):
    """``plasticity="auto"`` on arrays: e_ep = 1 where the plastic loss 1 - e_ep is below ``tolerance``, in
    place (e_ep is a fresh result of Eq. 7 or 8, no one else's), by one comparison with
    :func:`_loss_threshold`: the same cases as 1 - e_ep < tolerance, without the array of 1 - e_ep."""
    if np.ndim(e_ep) == 0:
        return where(1.0 - e_ep < tolerance, 1.0, e_ep)
    threshold = _loss_threshold(tolerance)
    if threshold is not None and e_ep.size and e_ep.max() <= threshold:  # no case to skip: one reduction, no mask
        return e_ep  # (NaN: max is NaN, not <= threshold, and the mask decides)
    np.copyto(e_ep, 1.0, where=(e_ep > threshold) if threshold is not None else np.subtract(1.0, e_ep) < tolerance)
    return e_ep


@lru_cache(maxsize=8)
def _loss_threshold(tolerance):
    """The largest float below or at 1 - ``tolerance`` (exactly, not rounded to nearest), or None for a
    tolerance above 1/2. For e_ep in [1/2, 1], 1 - e_ep is exact (Sterbenz), so the floating-point
    1 - e_ep < tolerance holds exactly where e_ep > 1 - tolerance, i.e. where e_ep exceeds this float;
    below 1/2 neither holds (1 - e_ep > 1/2 >= tolerance, and the threshold is >= 1/2); e_ep never exceeds 1."""
    if not 0.0 <= tolerance <= 0.5:
        return None
    exact = Fraction(1) - Fraction(tolerance)
    threshold = float(exact)  # rounded to nearest: one step down if that went up
    return threshold if Fraction(threshold) <= exact else math.nextafter(threshold, -math.inf)


def _moving(v):
    """v > 0 [m/s], an impact at all, of an array: one True when every speed is positive (the masks it
    selects by then cost nothing), else the mask."""
    if v.size and v.min() > 0.0:  # min propagates NaN: not > 0, and the mask decides
        return True
    return v > 0.0


def _waves_needed(lam, tolerance, slope_bound):
    """Where ``plate_waves="auto"`` computes Zener on arrays: ``slope_bound`` * lambda >= ``tolerance``;
    one True when the smallest lambda passes (the product is non-decreasing in lambda, so then every case
    does), else the mask."""
    lam = np.asarray(lam)
    if lam.size and slope_bound * lam.min() >= tolerance:
        return True
    return slope_bound * lam >= tolerance
