"""Elastoplastic restitution: the Jackson-Green-Marghitu (JGM) model as recast in
I. Green, Nonlinear Dyn (2022), Eqs. (1)-(8).

Every function accepts Python floats (fast path, returns floats) or numpy arrays
(broadcast, returns arrays). Subscript a is the sphere, b the plate.
"""
from __future__ import annotations

import math

import numpy as np

from ._num import exp, log, minimum, maximum, sqrt, where
from .quantities import si_only, with_units

__all__ = [
    "reduced_modulus", "effective_modulus", "poisson_coefficient", "critical_pressure",
    "sphere_yields_first", "vstar_in_fit_range", "yield_strain", "critical_interference", "critical_load",
    "sphere_mass", "critical_velocity", "restitution_e45", "restitution_e44",
    "VSTAR_FIT_MAX", "E44_BRANCH_JOIN",
]

#: Upper end of the V* range the JGM fits were made on [1].
VSTAR_FIT_MAX = 1000.0
#: V* where Eq. (7) switches branch [1].
E44_BRANCH_JOIN = 60.0
_LOG60 = math.log(60.0)
# exp() argument cap: beyond it the restitution term is astronomically larger
# than 1 and e is floored at 0 anyway; capping avoids a floating overflow.
_EXP_ARG_CAP = 700.0


@with_units(E="Pa", nu="dimensionless")
def reduced_modulus(E, nu):
    """E_i' = E_i / (1 - nu_i^2) [Pa], Eq. (1) right."""
    return E / (1.0 - nu * nu)


@with_units(E_a="Pa", nu_a="dimensionless", E_b="Pa", nu_b="dimensionless")
def effective_modulus(E_a, nu_a, E_b, nu_b):
    """E' = E_a' E_b' / (E_a' + E_b') [Pa], Eq. (1) left."""
    Ea = _reduced_modulus(E_a, nu_a)
    Eb = _reduced_modulus(E_b, nu_b)
    return Ea * Eb / (Ea + Eb)


def poisson_coefficient(nu):
    """C(nu) = 1.295 exp(0.736 nu) [1], Eq. (2): max pressure over max von Mises stress at yield onset."""
    return 1.295 * exp(0.736 * nu)


@with_units(nu_a="dimensionless", Sy_a="Pa", nu_b="dimensionless", Sy_b="Pa")
def critical_pressure(nu_a, Sy_a, nu_b, Sy_b):
    """C S_y = min[C(nu_a) S_ya, C(nu_b) S_yb] [Pa], Eq. (2): the body with the smaller value yields first."""
    return minimum(poisson_coefficient(nu_a) * Sy_a, poisson_coefficient(nu_b) * Sy_b)


def vstar_in_fit_range(v_star):
    """True where V* <= 1000 [1], the range JGM's Eqs. (7)-(8) were fitted on (V* = 1000 included)."""
    return v_star <= VSTAR_FIT_MAX


@with_units(nu_a="dimensionless", Sy_a="Pa", nu_b="dimensionless", Sy_b="Pa")
def sphere_yields_first(nu_a, Sy_a, nu_b, Sy_b):
    """True where C(nu_a) S_ya <= C(nu_b) S_yb, the condition of Eq. (3)."""
    return poisson_coefficient(nu_a) * Sy_a <= poisson_coefficient(nu_b) * Sy_b


@with_units(E_prime="Pa", nu_a="dimensionless", Sy_a="Pa", nu_b="dimensionless", Sy_b="Pa")
def yield_strain(E_prime, nu_a, Sy_a, nu_b, Sy_b):
    """eps_y = S_y / E' [1], Eq. (3), with S_y of the body that yields first.

    Not C S_y / E' as some public scripts use (docs/paper_departures.md).
    """
    Sy = where(_sphere_yields_first(nu_a, Sy_a, nu_b, Sy_b), Sy_a, Sy_b)
    return Sy / E_prime


@with_units(CSy="Pa", E_prime="Pa", R="m")
def critical_interference(CSy, E_prime, R):
    """omega_c = (pi C S_y / (2 E'))^2 R [m], Eq. (4); R = d/2 for a sphere on a plate."""
    x = math.pi * CSy / (2.0 * E_prime)
    return x * x * R


@with_units(CSy="Pa", E_prime="Pa", R="m")
def critical_load(CSy, E_prime, R):
    """P_c = 4/3 (R/E')^2 (pi/2 C S_y)^3 [N], Eq. (5)."""
    r = R / E_prime
    p = 0.5 * math.pi * CSy
    return (4.0 / 3.0) * r * r * p * p * p


@with_units(rho_a="kg/m**3", d="m")
def sphere_mass(rho_a, d):
    """m_a = rho_a pi d^3 / 6 [kg]."""
    return rho_a * math.pi * d * d * d / 6.0


@with_units(omega_c="m", P_c="N", m_a="kg")
def critical_velocity(omega_c, P_c, m_a):
    """V_c = sqrt(4 omega_c P_c / (5 m_a)) [m/s], Eq. (6): impact speed at the onset of yielding.

    With m_a = rho_a pi d^3/6, V_c does not depend on d (R cancels).
    """
    return sqrt(0.8 * omega_c * P_c / m_a)


def _above_one(v_star):
    """(mask V* > 1, V* - 1 where above else 1): keeps log/power arguments safe on every branch."""
    above = v_star > 1.0
    return above, where(above, v_star - 1.0, 1.0)


def restitution_e45(v_star, eps_y):
    """e45 [1], Eq. (8) (JGM Eq. 45), the paper's default elastoplastic COR.

    e = 1 - 0.0361 eps_y^-0.114 ln(V*) (V* - 1)^(9.5 eps_y) for V* > 1, e = 1 for V* <= 1.
    The fit covers 1 < V* <= 1000. Extension: beyond that range the fit can fall
    below 0, which no elastoplastic rebound can do; it is floored at 0 there
    (the caller flags V* > 1000 as outside the validated range).

    Reformulation: the plastic loss 0.0361 eps_y^-0.114 ln(V*) (V* - 1)^(9.5 eps_y) is computed
    as one exp of the sum of the factors' logarithms. Multiplied out, the factors can make a
    subnormal (glass on glass just above V* = 1: (V* - 1)^(9.5 eps_y) ~ 1e-306, the product
    ~ 1e-307, an underflow) or overflow (brittle pairs, eps_y ~ 10); in log space the loss is
    0 exactly below exp's range (no underflow flag) and capped above it.
    """
    if not (v_star.__class__ is float and eps_y.__class__ is float):
        if np.ndim(v_star) or np.ndim(eps_y):
            return _restitution_e45_array(np.asarray(v_star, dtype=float), eps_y)
        v_star, eps_y = float(v_star), float(eps_y)  # other scalars: numpy's, ints
    if not v_star > 1.0:  # V* <= 1 (or NaN): no plastic loss
        return 1.0
    log_loss = _LOG_E45_COEFFICIENT - 0.114 * log(eps_y) + log(log(v_star)) + 9.5 * eps_y * log(v_star - 1.0)
    e = 1.0 - exp(log_loss if log_loss <= _EXP_ARG_CAP else _EXP_ARG_CAP)  # the comparisons of _num's minimum
    return e if e >= 0.0 else 0.0  # and maximum (a NaN loss: the cap, e = 0), without their calls


def _restitution_e45_array(v_star, eps_y):
    """:func:`restitution_e45` of arrays, in place and without masks: V* is clamped at 1 first, where
    (V* - 1)^(9.5 eps_y) = 0 and ln V* = 0, so the loss is 0 and e = 1 exactly, the value Eq. (8) takes
    for V* <= 1. Above the clamp the loss is the product of its factors, the power as
    exp(9.5 eps_y ln(V* - 1)): the scalar form's logarithms (a few ulps of the loss apart, the rounding
    the conditioning bounds allow). Where the product underflows (below 1e-307) 1 - loss is 1 either way,
    and where the power overflows (loss = inf) e = 1 - inf is floored at 0 as the scalar form's capped
    exponent is; numpy's floating-point flags for both are not raised to the caller."""
    shape = np.broadcast_shapes(v_star.shape, np.shape(eps_y))
    clamped = np.maximum(v_star, 1.0, out=np.empty(shape))
    with np.errstate(divide="ignore", over="ignore", under="ignore"):
        loss = np.subtract(clamped, 1.0)
        np.log(loss, out=loss)  # -inf at V* <= 1
        loss *= 9.5 * eps_y
        np.exp(loss, out=loss)  # (V* - 1)^(9.5 eps_y)
        loss *= np.log(clamped, out=clamped)
        loss *= 0.0361 * eps_y ** -0.114
        e = np.subtract(1.0, loss, out=loss)
    return np.maximum(e, 0.0, out=e)


_LOG_E45_COEFFICIENT = math.log(0.0361)


def restitution_e44(v_star):
    """e44 [1], Eq. (7) (JGM Eqs. 43-44).

    1 < V* <= 60:  e = 1 - 0.1 ln(V*) ((V* - 1)/59)^0.156
    V* > 60:       e = 1 - 0.1 ln 60 - 0.11 ln(V*/60) ((V* - 60)/940)^2.366   (RECONSTRUCTED)
    V* <= 1:       e = 1

    Departure from the printed text: the OCR'd second branch reads (V* - 60)^2.366,
    which gives e ~ -350 at V* = 100 and cannot be right. The reconstruction
    ((V* - 60)/940)^2.366 (docs/paper_departures.md) mirrors the first branch's normalisation,
    joins it continuously at V* = 60 and gives e = 0.281 at V* = 1000. Treat the
    second branch as reconstructed. Floored at 0 beyond the fit range, as e45.
    """
    above, vm1 = _above_one(v_star)
    low = 1.0 - 0.1 * log(where(above, v_star, 1.0)) * (vm1 / 59.0) ** 0.156
    upper = v_star > E44_BRANCH_JOIN
    v_hi = where(upper, v_star, E44_BRANCH_JOIN)
    ratio = (v_hi - E44_BRANCH_JOIN) / 940.0
    high = 1.0 - 0.1 * _LOG60 - 0.11 * log(v_hi / E44_BRANCH_JOIN) * exp(minimum(2.366 * log(where(upper, ratio, 1.0)), _EXP_ARG_CAP))
    e = where(upper, high, low)
    return where(above, maximum(e, 0.0), 1.0)


# the module's own calls pass SI numbers: the equations without their unit layer
_reduced_modulus = si_only(reduced_modulus)
_sphere_yields_first = si_only(sphere_yields_first)
