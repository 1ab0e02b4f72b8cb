"""The linear spring-damper contact whose force is clamped at zero, and its exact inverse.

A host whose contact is a linear spring and dashpot on the penetration x (MuJoCo's soft constraint with
constant impedance, Modelica's ``ElastoGap``) pushes with F = m (omega^2 x + 2 zeta omega x') while the
bodies overlap. A host that never pulls (a unilateral contact) releases the sphere when that force
reaches zero, which happens before the penetration returns to zero: the rebound keeps more speed than
the unclamped oscillator's e = exp(-zeta pi / sqrt(1 - zeta^2)) says. The functions below are in the
oscillator's own time, tau = omega t (omega the undamped angular frequency), for the initial state
x(0) = 0, x'(0) = 1: everything scales out but the damping ratio zeta.
"""
from __future__ import annotations

import math

__all__ = ["clamped_release", "clamped_restitution", "clamped_damping_ratio", "unclamped_damping_ratio",
           "unclamped_restitution", "oscillator_state", "E_RANGE"]

#: The CORs the inverse answers for [1]: zeta from 1e-9 to 1e4.
E_RANGE = (1e-4, 1.0 - 1e-9)


def oscillator_state(zeta: float, tau: float) -> tuple[float, float]:
    """(x, x') of x'' + 2 zeta x' + x = 0, x(0) = 0, x'(0) = 1 at the dimensionless time ``tau`` [1]
    (x in units of v/omega, x' in units of v): under-, critically and over-damped alike."""
    gap = 1.0 - zeta * zeta
    if abs(gap) < 1e-12:  # critical damping: x = tau e^-tau
        decay = math.exp(-zeta * tau)
        return tau * decay, (1.0 - zeta * tau) * decay
    if gap > 0.0:
        decay = math.exp(-zeta * tau)
        w = math.sqrt(gap)
        s, c = math.sin(w * tau) / w, math.cos(w * tau)
        return s * decay, (c - zeta * s) * decay
    w = math.sqrt(-gap)  # over-damped: two decaying modes, written without sinh/cosh (they overflow)
    slow, fast = -1.0 / (zeta + w), -zeta - w  # the roots of s^2 + 2 zeta s + 1, the slow one without cancellation
    e_slow, e_fast = math.exp(slow * tau), math.exp(fast * tau)
    return (e_slow - e_fast) / (2.0 * w), (slow * e_slow - fast * e_fast) / (2.0 * w)


def _force(zeta: float, tau: float) -> float:
    """The contact force over m v omega: x + 2 zeta x' [1]."""
    x, xdot = oscillator_state(zeta, tau)
    return x + 2.0 * zeta * xdot


def clamped_release(zeta: float) -> float:
    """The dimensionless time omega t at which the force x + 2 zeta x' of the oscillator first reaches zero [1]:
    where a unilateral contact lets go."""
    from scipy.optimize import brentq

    if zeta <= 0.0:
        return math.pi
    if zeta < 1.0:  # the force is zero at the first root of tan(w tau) = -2 zeta w / (1 - 2 zeta^2)
        w = math.sqrt(1.0 - zeta * zeta)
        return (math.pi - math.atan2(2.0 * zeta * w, 1.0 - 2.0 * zeta * zeta)) / w
    high = 1.0
    while _force(zeta, high) > 0.0:  # over-damped: the slow mode pulls at last; bracket that time
        high *= 2.0
    return brentq(lambda tau: _force(zeta, tau), 0.5 * high if high > 1.0 else 1e-12, high, xtol=1e-14, rtol=1e-15)


def clamped_restitution(zeta: float) -> float:
    """The COR of the clamped linear contact of damping ratio ``zeta`` [1]: the rebound speed over the
    approach speed when the force reaches zero (:func:`clamped_release`)."""
    return -oscillator_state(zeta, clamped_release(zeta))[1]


def clamped_damping_ratio(e: float) -> float:
    """The damping ratio zeta [1] at which the clamped linear contact gives the COR ``e`` (in :data:`E_RANGE`):
    :func:`clamped_restitution` (which falls as zeta grows) inverted by brentq."""
    from scipy.optimize import brentq

    if not E_RANGE[0] <= e <= E_RANGE[1]:
        raise ValueError(f"e = {e!r}: the clamped linear contact is inverted for {E_RANGE[0]:g} <= e < 1")
    return brentq(lambda zeta: clamped_restitution(zeta) - e, 1e-9, 1e4, xtol=1e-15, rtol=1e-13)


def unclamped_damping_ratio(e: float) -> float:
    """The usual map zeta = -ln e / sqrt(pi^2 + ln^2 e) [1], exact only for a contact that may pull (the force
    released when the penetration, not the force, returns to zero); shown beside the exact one."""
    log = math.log(e)
    return -log / math.sqrt(math.pi * math.pi + log * log)


def unclamped_restitution(zeta: float) -> float:
    """e = exp(-zeta pi / sqrt(1 - zeta^2)) [1] of the oscillator released at zero penetration (zeta < 1)."""
    return math.exp(-zeta * math.pi / math.sqrt(1.0 - zeta * zeta))
