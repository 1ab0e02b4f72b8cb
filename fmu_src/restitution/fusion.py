"""Fusion of the JGM and Zener effects through an equivalent plate mass,
I. Green, Nonlinear Dyn (2022), Eqs. (15)-(20)."""
from __future__ import annotations

import math

from ._num import where

__all__ = ["apparent_restitution", "equivalent_plate_mass", "velocities_after_impact"]


def apparent_restitution(e_ep, e_ze):
    """Apparent COR e = (e_ep + e_ze + e_ep e_ze - 1) / 2 [1], Eq. (20).

    e < 0 is a result, not an error: the sphere keeps moving with the plate after
    impact (possible for thin plates, where e_ze is small).
    """
    return 0.5 * (e_ep + e_ze + e_ep * e_ze - 1.0)


def equivalent_plate_mass(m_a, e_ze):
    """m_b = (1 + e_ze) m_a / (1 - e_ze) [kg], Eq. (19). +inf for e_ze = 1 (a half-space)."""
    gap = 1.0 - e_ze
    positive = gap > 0.0
    return where(positive, (1.0 + e_ze) * m_a / where(positive, gap, 1.0), math.inf)


def velocities_after_impact(v_a1, e_ep, e_ze):
    """(v_a2, v_b2) [m/s], Eq. (17), positive in the direction of approach, plate at rest before.

    With m_b from Eq. (19), m_a/(m_a + m_b) = (1 - e_ze)/2, so
    v_a2 = -e v_a1 (e of Eq. 20) and v_b2 = (1 + e_ep)(1 - e_ze)/2 v_a1; this form
    stays finite for the half-space (m_b = inf, v_b2 = 0).
    """
    share = 0.5 * (1.0 - e_ze)
    v_a2 = (share - e_ep * (1.0 - share)) * v_a1
    v_b2 = (1.0 + e_ep) * share * v_a1
    return v_a2, v_b2
