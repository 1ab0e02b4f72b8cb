"""Fusion of the JGM and Zener effects through an equivalent plate mass,
I. Green, Nonlinear Dyn (2022), Eqs. (15)-(20).

Zener's COR enters through its deficit d = 1 - e_ze wherever 1 - e_ze appears: a plate that
barely takes energy has e_ze within a few ulps of 1, where 1 - e_ze computed by subtraction
keeps only the last bits of e_ze (relative condition number ~ 1/d). The callers pass d as each
Zener method computes it without cancellation (:func:`restitution.zener.zener_solution`).
"""
from __future__ import annotations

import math

import numpy as np

from ._num import where
from .quantities import with_units

__all__ = ["apparent_restitution", "equivalent_plate_mass", "mass_ratio", "velocities_after_impact",
           "plate_velocity_after_impact", "plate_mass_from_ratio"]


def apparent_restitution(e_ep, e_ze):
    """Apparent COR e = (e_ep + e_ze + e_ep e_ze - 1) / 2 [1], Eq. (20).

    Evaluated as e = (e_ze (1 + e_ep) - (1 - e_ep)) / 2, the same quantity regrouped as the
    difference of two non-negative terms: with e_ep = 1 (no plasticity) it is e_ze exactly,
    and the sign of e (``e_negative``) is the comparison e_ze (1 + e_ep) < 1 - e_ep, decided the
    same way on every code path. Its absolute error is a few ulps of 1 whatever the inputs (the
    printed form sums four terms of mixed sign and can give -5.6e-17 where e = 0).

    e < 0 is a result, not an error: the sphere keeps moving with the plate after
    impact (possible for thin plates, where e_ze is small).
    """
    if e_ep.__class__ is np.ndarray and e_ze.__class__ is np.ndarray and e_ep.shape == e_ze.shape:
        e = np.add(1.0, e_ep)  # arrays: the same operations in two temporaries instead of four
        e *= e_ze
        e -= np.subtract(1.0, e_ep)
        e *= 0.5
        return e
    return 0.5 * (e_ze * (1.0 + e_ep) - (1.0 - e_ep))


@with_units(m_a="kg")
def equivalent_plate_mass(m_a, e_ze, deficit=None):
    """m_b = (1 + e_ze) m_a / (1 - e_ze) [kg], Eq. (19). +inf for e_ze = 1 (a half-space).

    ``deficit``: 1 - e_ze [1] as the Zener method computed it. Relative condition number of
    m_b in the deficit: 1 + d/(2 - d) <= 2; by subtraction, 1 - e_ze would bring in ~ 1/(1 - e_ze)
    (1.3 % between two CPUs' last-bit exp at e_ze within an ulp of 1). Without ``deficit`` it is
    1 - e_ze, exact only where e_ze is exact (a given value, not a computed one).
    Computed as m_a over :func:`mass_ratio` (:func:`plate_mass_from_ratio`).
    """
    return plate_mass_from_ratio(m_a, mass_ratio(e_ze, deficit))


def plate_mass_from_ratio(m_a, ratio):
    """m_b = m_a / (m_a / m_b) [kg], Eq. (19) from :func:`mass_ratio` (``ratio`` [1]); +inf where the
    ratio is 0 (a half-space). One division per case: the model computes the ratio, an output itself,
    once for both."""
    if ratio.__class__ is float or np.ndim(ratio) == 0:
        return m_a / ratio if ratio > 0.0 else math.inf
    with np.errstate(divide="ignore"):  # a positive mass over a ratio of 0: +inf, the half-space
        m_b = np.divide(m_a, ratio)
    if not (ratio.size and ratio.min() > 0.0):  # a ratio <= 0 (or NaN) anywhere: the half-space's +inf there
        np.copyto(m_b, math.inf, where=~(ratio > 0.0))
    return m_b


def mass_ratio(e_ze, deficit=None):
    """m_a / m_b = (1 - e_ze) / (1 + e_ze) [1], Eq. (19) solved for the ratio of the sphere's mass to
    the equivalent plate mass. In [0, 1]: 0 for a half-space (e_ze = 1, where m_b itself is +inf),
    1 where the plate takes the whole motion (e_ze = 0). The finite form of Eq. (19) that the FMUs
    publish (a result writer drops a time point with an infinite value).

    ``deficit``: 1 - e_ze as in :func:`equivalent_plate_mass`; relative condition number in it
    1 + d/(2 - d) <= 2.
    """
    gap = 1.0 - e_ze if deficit is None else deficit
    denominator = 1.0 + e_ze
    if denominator.__class__ is np.ndarray and np.shape(gap) == denominator.shape:  # arrays: in its own temporary
        return np.divide(gap, denominator, out=denominator)
    return gap / denominator


@with_units(v_a1="m/s")
def velocities_after_impact(v_a1, e_ep, e_ze, deficit=None):
    """(v_a2, v_b2) [m/s], Eq. (17), positive in the direction of approach, plate at rest before.

    With m_b from Eq. (19), m_a/(m_a + m_b) = (1 - e_ze)/2, so v_a2 = -e v_a1 (e of Eq. 20)
    and v_b2 = (1 + e_ep)(1 - e_ze)/2 v_a1; this form stays finite for the half-space
    (m_b = inf, v_b2 = 0). ``deficit``: 1 - e_ze as in :func:`equivalent_plate_mass` (v_b2 is
    proportional to it, condition number 1 in d).
    """
    gap = 1.0 - e_ze if deficit is None else deficit
    return -apparent_restitution(e_ep, e_ze) * v_a1, plate_velocity_after_impact(v_a1, e_ep, gap)


def plate_velocity_after_impact(v_a1, e_ep, deficit):
    """v_b2 = (1 + e_ep)(1 - e_ze)/2 v_a1 [m/s], the plate's velocity after impact, Eq. (17) with m_b from
    Eq. (19) (see :func:`velocities_after_impact`); ``deficit``: 1 - e_ze [1] as the Zener method computed it."""
    return 0.5 * (1.0 + e_ep) * deficit * v_a1
