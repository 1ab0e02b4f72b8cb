"""Elastic waves in the plate: Zener's model as recast in I. Green, Nonlinear Dyn (2022), Eqs. (9)-(13a), (22)-(23).

Zener's ODE, Eq. (10): sigma'' + (1 + lambda d/dtau) sigma^(3/2) = 0, sigma(0) = 0,
sigma'(0) = 1 (Eq. 11). The rebound is the first return of sigma to 0, at tau = tau0;
Zener's COR is e_ze = -sigma'(tau0). Four ways to get (e_ze, tau0) from lambda:

``exact``      the ODE's solution, tabulated offline and interpolated (rel. error <= 1e-8, default)
``paper_fit``  Eq. (13) and (13a) as published
``linear``     Eq. (22), the linearised ODE, in closed form
``ode``        Eq. (10) integrated at every call, with a settable tolerance
"""
from __future__ import annotations

import math

import numpy as np

from ._num import exp, expm1, is_scalar, minimum, sqrt, where
from .domain import ZENER_METHODS
from .quantities import si_only, with_units
from .jgm import reduced_modulus
from .zener_exact import zener_exact_restitution, zener_exact_solution

__all__ = [
    "ZENER_METHODS", "LAMBDA_STUDIED_MAX", "lambda_in_studied_range", "TAU0_HERTZ", "plate_wave_speed", "inelasticity_parameter",
    "lambda_material_factor", "lambda_speed_factor", "lambda_from_root", "hertz_stiffness", "time_scale",
    "time_scale_factor", "time_scale_from_root", "zener_paper_fit", "zener_paper_fit_deficit", "zener_linear",
    "zener_linear_deficit", "zener_linear_fit", "zener_ode", "zener_restitution", "zener_restitution_only", "zener_solution",
    "zener_solution_where", "zener_restitution_where",
    "contact_duration", "WAVE_DELAY_LIMIT", "wave_delay", "waves_concurrent", "dilatational_wave_speed",
    "dilatational_slowness", "edge_echo_time", "edge_echo_ratio", "edge_echo_ratio_from_time", "edge_clear",
]

#: Largest lambda Zener (and the paper's fits) studied [1].
LAMBDA_STUDIED_MAX = 1.5
#: tau0 at lambda = 0 (Hertz impact on a half-space): 2 (5/4)^(2/5) (2/5) B(2/5, 1/2) [1].
TAU0_HERTZ = 2.0 * 1.25 ** 0.4 * 0.4 * math.gamma(0.4) * math.gamma(0.5) / math.gamma(0.9)


@with_units(E_b="Pa", nu_b="dimensionless", rho_b="kg/m**3")
def plate_wave_speed(E_b, nu_b, rho_b):
    """v' = sqrt(E_b' / rho_b) [m/s], the plate's sound speed under Eq. (12)."""
    return sqrt(_reduced_modulus(E_b, nu_b) / rho_b)


@with_units(v0="m/s", E_a="Pa", nu_a="dimensionless", rho_a="kg/m**3", d="m", E_b="Pa", nu_b="dimensionless", rho_b="kg/m**3", t="m")
def inelasticity_parameter(v0, E_a, nu_a, rho_a, d, E_b, nu_b, rho_b, t):
    """Zener's "inelasticity" parameter lambda [1], Eq. (12).

    lambda = pi^(3/5)/sqrt(3) ((d/2)/t)^2 (v0/v')^(1/5) (rho_a/rho_b)^(3/5) (E_a'/(E_a' + E_b'))^(2/5),
    with v0 the impact speed [m/s], d the sphere diameter [m], t = 2h the plate thickness [m].
    It depends on t/d only, not on t and d separately.
    """
    material_factor = lambda_material_factor(E_a, nu_a, rho_a, E_b, nu_b, rho_b)
    return lambda_from_root(v0 ** 0.2, lambda_speed_factor(material_factor, d, t))


def lambda_material_factor(E_a, nu_a, rho_a, E_b, nu_b, rho_b):
    """The factor of Eq. (12) that depends on the materials only, in SI [(s/m)^(1/5)]:
    pi^(3/5)/sqrt(3) v'^(-1/5) (rho_a/rho_b)^(3/5) (E_a'/(E_a' + E_b'))^(2/5), v' the plate's wave speed
    (:func:`plate_wave_speed`). Split from the speed and the geometry so that the model computes it once
    per pair of materials (:func:`restitution.model._material_terms`)."""
    Ea = _reduced_modulus(E_a, nu_a)
    Eb = _reduced_modulus(E_b, nu_b)
    return (_LAMBDA_PREFACTOR * (rho_a / rho_b) ** 0.6 * (Ea / (Ea + Eb)) ** 0.4
            / _plate_wave_speed(E_b, nu_b, rho_b) ** 0.2)


def lambda_speed_factor(material_factor, d, t):
    """lambda / v0^(1/5) [(s/m)^(1/5)], Eq. (12) without the speed: :func:`lambda_material_factor` times
    ((d/2)/t)^2, d the sphere's diameter [m], t the plate's thickness [m], as
    (material_factor (d/2)^2) / t / t. Everything in lambda but the speed: the model computes it once per
    parameter set (:func:`restitution.model.impact_terms`); the bracket holds what does not depend on the
    thickness, so one sphere on one pair of materials (a sweep in t) pays two divisions per case, in one
    array (numpy reuses the temporary of the first; t^2 would be a second one)."""
    return material_factor * (0.25 * d * d) / t / t


def lambda_from_root(v0_root, speed_factor):
    """lambda [1], Eq. (12), from v0^(1/5) (``v0_root``, shared with Zener's time unit, Eq. (9),
    :func:`time_scale_from_root`) and :func:`lambda_speed_factor`: one product per impact."""
    return speed_factor * v0_root


_LAMBDA_PREFACTOR = math.pi ** 0.6 / math.sqrt(3.0)


@with_units(E_prime="Pa", d="m")
def hertz_stiffness(E_prime, d):
    """k = (4/3) r^(1/2) E' [N/m^1.5], with r = d/2 (text after Eq. 10): F = k s^(3/2)."""
    return (4.0 / 3.0) * sqrt(0.5 * d) * E_prime


@with_units(m_a="kg", k="N/m**1.5", v0="m/s")
def time_scale(m_a, k, v0):
    """Zener's time unit T = (m / (k v0^(1/2)))^(2/5) [s], Eq. (9). Infinite at v0 = 0."""
    return time_scale_from_root(time_scale_factor(m_a, k), v0 ** 0.2)


def time_scale_factor(m_a, k):
    """(m_a / k)^(2/5) [s^(4/5) m^(1/5)]: the part of Zener's time unit, Eq. (9), that does not depend on
    the speed (sphere mass m_a [kg], Hertz stiffness k [N/m^1.5])."""
    return (m_a / k) ** 0.4


def time_scale_from_root(factor, v0_root, out=None):
    """T = (m_a / k)^(2/5) / v0^(1/5) [s], Eq. (9), from :func:`time_scale_factor` and v0^(1/5)
    (``v0_root``, shared with Eq. (12), :func:`lambda_from_root`). +inf at v0 = 0 (no impact).
    ``out``: an array of the result's shape to write T into (the model passes v0_root's own, once
    lambda no longer needs it)."""
    if v0_root.__class__ is float or is_scalar(v0_root):
        return factor / v0_root if v0_root > 0.0 else math.inf
    with np.errstate(divide="ignore"):  # a positive factor over v0 = 0: +inf, the value for no impact
        return np.divide(factor, v0_root, out=out)


def lambda_in_studied_range(lam):
    """True where lambda <= 1.5 [1], the range on which Zener's Eqs. (13)-(13a) were fitted and studied."""
    return lam <= LAMBDA_STUDIED_MAX


@with_units(T="s", tau0="dimensionless")
def contact_duration(T, tau0):
    """t_contact = T tau0 [s]: the time sphere and plate stay in compressive contact."""
    return T * tau0


# --- Monitors of Zener's assumptions (I. Green, Nonlinear Dyn (2022), sections 3 and 4) ---------------

#: The delay :func:`wave_delay` at the end of Zener's studied range, lambda = 1.5, with the exact solution:
#: tau0(1.5)/tau0(0) = 1.81359 [1] (rounded up in the 5th digit; tests/physics/test_monitors.py checks it against
#: an independent solve of Eq. (10)). Above it the wave process outlasts the half-space contact by more
#: than the paper validated.
WAVE_DELAY_LIMIT = 1.8136


def wave_delay(tau0, tau0_half_space):
    """tau0(lambda) / tau0(0) [1]: how much the plate waves lengthen the contact, Zener's ejection time over
    its half-space (Hertz) value, both by the same method. 1 for a half-space, 1.36 at lambda = 1, 1.81 at
    lambda = 1.5, +inf where the contact never ends.

    A monitor of the paper's section 4: Eq. (20) fuses the elastoplastic and the wave COR, which holds
    only if "the underlying physical processes of both models occur concurrently". JGM's plastic
    deformation happens within a Hertz-like contact; the longer the waves delay the ejection beyond it,
    the less the two processes overlap (threshold :data:`WAVE_DELAY_LIMIT`, :func:`waves_concurrent`).
    Not an equation of the paper: an extension that makes its caveat measurable."""
    return tau0 / tau0_half_space


def waves_concurrent(delay):
    """True where :func:`wave_delay` <= :data:`WAVE_DELAY_LIMIT` [1]: the delay is within what the paper
    validated (lambda <= 1.5 under the exact solution)."""
    return delay <= WAVE_DELAY_LIMIT


@with_units(E_b="Pa", nu_b="dimensionless", rho_b="kg/m**3")
def dilatational_wave_speed(E_b, nu_b, rho_b):
    """c_L = sqrt(E_b (1 - nu_b) / (rho_b (1 + nu_b)(1 - 2 nu_b))) [m/s]: the plate's bulk dilatational
    (P-) wave speed, the fastest elastic wave in it; +inf for nu_b = 0.5 (incompressible).
    Not in the paper: it times the edge echo of :func:`edge_echo_ratio`."""
    return 1.0 / _dilatational_slowness(E_b, nu_b, rho_b)


@with_units(E_b="Pa", nu_b="dimensionless", rho_b="kg/m**3")
def dilatational_slowness(E_b, nu_b, rho_b):
    """1 / c_L [s/m] of :func:`dilatational_wave_speed`, written as a slowness so that nu_b = 0.5 gives 0
    (an infinitely fast wave) without a division by zero."""
    return sqrt(rho_b * (1.0 + nu_b) * (1.0 - 2.0 * nu_b) / (E_b * (1.0 - nu_b)))


@with_units(edge_distance="m", slowness="s/m")
def edge_echo_time(edge_distance, slowness):
    """2 a / c_L [s]: the time the first dilatational wave reflected from the plate's nearest edge, at distance
    a [m] from the impact point, takes to come back (``slowness`` = 1/c_L [s/m], :func:`dilatational_slowness`);
    +inf where a = 0 or +inf, an unbounded plate (Zener's assumption): no echo ever returns. Depends on the
    plate only: the model computes it once per parameter set (:func:`edge_echo_ratio_from_time`)."""
    if edge_distance.__class__ is float and slowness.__class__ is float:
        return math.inf if edge_distance == 0.0 or edge_distance == math.inf else 2.0 * edge_distance * slowness
    unbounded = (edge_distance == 0.0) | (edge_distance == math.inf)
    return where(unbounded, math.inf, 2.0 * where(unbounded, 0.0, edge_distance) * slowness)


@with_units(edge_distance="m", slowness="s/m", t_contact="s")
def edge_echo_ratio(edge_distance, slowness, t_contact):
    """(2 a / c_L) / t_contact [1]: the time the first dilatational wave reflected from the plate's nearest
    edge, at distance a [m] from the impact point, takes to come back, over the contact time [s].

    A monitor of the paper's section 3, which takes Zener's plate as infinite: waves reflected from its
    edges must not return before the sphere leaves. Below 1 an echo arrives during the contact
    (:func:`edge_clear`). Conservative: the bulk dilatational wave (``slowness`` = 1/c_L,
    :func:`dilatational_slowness`) is the fastest; the flexural waves that carry Zener's energy loss
    come back later. a = 0 or +inf means an unbounded plate (Zener's assumption): +inf, as for no
    contact (t_contact = 0); 0 where the contact never ends (t_contact = +inf).
    :func:`edge_echo_time` and :func:`edge_echo_ratio_from_time`, the parameter-only part and the rest."""
    return edge_echo_ratio_from_time(_edge_echo_time(edge_distance, slowness), t_contact)


def edge_echo_ratio_from_time(echo_time, t_contact):
    """:func:`edge_echo_ratio` [1] from :func:`edge_echo_time` [s] and the contact time [s]: echo_time /
    t_contact, +inf where the plate is unbounded (echo_time = +inf) or there is no contact (t_contact = 0),
    0 where a bounded plate's contact never ends (t_contact = +inf)."""
    if t_contact.__class__ is float and echo_time.__class__ is float:
        return math.inf if echo_time == math.inf or t_contact == 0.0 else echo_time / t_contact
    if is_scalar(echo_time) and not is_scalar(t_contact):  # one plate, many contacts
        if echo_time == math.inf:
            return np.full(np.shape(t_contact), math.inf)
        if echo_time > 0.0:  # a positive echo time over t_contact is +inf at 0 and 0 at +inf: no masks
            with np.errstate(divide="ignore"):
                return np.divide(echo_time, t_contact)
    silent = (echo_time == math.inf) | (t_contact == 0.0)  # no echo, or no contact
    return where(silent, math.inf, where(silent, 0.0, echo_time) / where(silent, 1.0, t_contact))


def edge_clear(ratio):
    """True where :func:`edge_echo_ratio` >= 1 [1]: no edge echo returns while the sphere is in contact."""
    return ratio >= 1.0


def zener_paper_fit(lam):
    """(e_ze, tau0) [1] from Eqs. (13) and (13a) as published.

    e_ze = exp(-1.68374 lambda), tau0 = 3.215 exp(0.318 lambda^(3/2)).
    Fitted on 0 <= lambda <= 1.5: absolute error in e up to 0.0136 (relative 20 %
    at lambda = 1.5); tau0 within ~1 % there but diverging above lambda ~ 2.
    Extension: tau0 is held at its value for lambda = _PAPER_FIT_LAMBDA_CAP (~169,
    tau0 ~ 3e304) beyond it, where the formula would overflow (the result is far outside
    the fit's range and flagged there anyway); it stays finite and non-decreasing.
    """
    return _paper_fit_restitution(lam), 3.215 * exp(0.318 * minimum(lam, _PAPER_FIT_LAMBDA_CAP) ** 1.5)


def _paper_fit_restitution(lam):
    """e_ze = exp(-1.68374 lambda) [1], Eq. (13)."""
    return exp(-1.68374 * lam)


def zener_paper_fit_deficit(lam):
    """1 - e_ze [1] of the paper fit, Eq. (13), as -expm1(-1.68374 lambda).

    Computing 1 - exp(-1.68374 lambda) by subtraction has relative condition number
    ~ 1/(1 - e_ze) ~ 1/(1.68 lambda) (1e16 near lambda = 1e-16: a last-bit difference in exp,
    as between numpy's SIMD kernels and the C library, changes the result by 100 %); expm1
    has condition number ~ 1 in lambda.
    """
    return -expm1(-1.68374 * lam)


#: lambda above which Eq. (13a)'s exponent 0.318 lambda^1.5 would pass 700 (exp overflows at ~709.8).
_PAPER_FIT_LAMBDA_CAP = (700.0 / 0.318) ** (2.0 / 3.0)


def zener_linear(lam):
    """(e_ze, tau0) [1] of the linearised ODE, Eq. (22): sigma'' + lambda sigma' + sigma = 0.

    Closed form (docs/paper_departures.md), for lambda < 2: e = exp(-pi lambda / sqrt(4 - lambda^2)),
    tau0 = pi / sqrt(1 - lambda^2/4). For lambda >= 2 the oscillator is (over)damped
    and never returns to sigma = 0: e = 0 and tau0 = +inf (contact is never lost).
    Note tau0(0) = pi, not the Hertz value 3.2180655: a different contact law.
    """
    under = lam < 2.0
    lam_u = where(under, lam, 0.0)
    root = sqrt(4.0 - lam_u * lam_u)
    e = where(under, exp(-math.pi * lam_u / root), 0.0)
    tau0 = where(under, 2.0 * math.pi / root, math.inf)
    return e, tau0


def zener_linear_deficit(lam):
    """1 - e_ze [1] of the linearised ODE, Eq. (22): -expm1(-pi lambda / sqrt(4 - lambda^2)) for
    lambda < 2, 1 beyond. The expm1 form avoids the cancellation of 1 - e_ze near lambda = 0
    (condition number ~ 1/(pi lambda / 2) by subtraction, ~ 1 this way)."""
    under = lam < 2.0
    lam_u = where(under, lam, 0.0)
    return where(under, -expm1(-math.pi * lam_u / sqrt(4.0 - lam_u * lam_u)), 1.0)


def zener_linear_fit(lam):
    """(e_ze)_linear = exp(-1.72847 lambda) [1], Eq. (23): the paper's fit to Eq. (22)."""
    return exp(-1.72847 * lam)


def zener_ode(lam, rtol: float = 1e-10):
    """(e_ze, tau0) [1] by integrating Eq. (10) at every call, relative tolerance ``rtol``.

    The reference and the slow end of the accuracy scale. Bounded work per element: tolerances
    are floored at what the integrator honours, and above lambda = 100 the verified large-lambda
    form is returned instead of a solve (see :mod:`restitution.zener_ode`, "Bounded cost").
    """
    from .zener_ode import solve_zener_ode  # the ODE solver, loaded by the few that ask for it

    if is_scalar(lam):
        return solve_zener_ode(float(lam), rtol=rtol)
    lam = np.asarray(lam)  # each element goes through float() below
    e = np.empty(lam.shape)
    tau0 = np.empty(lam.shape)
    for i, value in np.ndenumerate(lam):
        e[i], tau0[i] = solve_zener_ode(float(value), rtol=rtol)
    return e, tau0


def zener_solution(lam, method: str = "exact", rtol: float = 1e-10):
    """(e_ze, 1 - e_ze, tau0) [1] for Zener's parameter lambda [1] by ``method`` (see module doc).

    The deficit 1 - e_ze is computed directly by each method (``exact``: its own interpolant,
    ``paper_fit`` and ``linear``: expm1 forms), never as 1 - e_ze, which has relative condition
    number ~ 1/(1 - e_ze) and would make the equivalent plate mass, Eq. (19), and the plate
    velocity, Eq. (17), depend on the last bit of exp (see :func:`zener_paper_fit_deficit`).
    ``ode``: 1 - e_ze of the integrated solution, accurate to the solve's tolerance ``rtol``
    in absolute terms (the method's own accuracy, not a conditioning loss).
    """
    if method == "exact":
        return zener_exact_solution(lam)
    if method == "paper_fit":
        e, tau0 = zener_paper_fit(lam)
        return e, zener_paper_fit_deficit(lam), tau0
    if method == "linear":
        e, tau0 = zener_linear(lam)
        return e, zener_linear_deficit(lam), tau0
    if method == "ode":
        e, tau0 = zener_ode(lam, rtol=rtol)
        return e, 1.0 - e, tau0
    raise ValueError(f"zener_method = {method!r} is not one of {ZENER_METHODS}")


def zener_restitution_only(lam, method: str = "exact", rtol: float = 1e-10):
    """e_ze [1] alone for Zener's parameter lambda [1] by ``method``: :func:`zener_solution`'s first value,
    by the same operations, without the contact time where the method can skip it (exact, paper_fit)."""
    if method == "exact":
        return zener_exact_restitution(lam)
    if method == "paper_fit":
        return _paper_fit_restitution(lam)
    return zener_solution(lam, method, rtol)[0]


def zener_solution_where(lam, needed, method: str, rtol: float, skipped_tau0):
    """:func:`zener_solution` of an array ``lam`` [1], computed only where the mask ``needed`` holds (or
    everywhere, for one True); (1, 0, ``skipped_tau0``) elsewhere: ``plate_waves="auto"`` on arrays."""
    lam = np.asarray(lam)  # float already: Eq. (12) of float arrays
    needed = np.broadcast_to(needed, lam.shape)
    if needed.all():  # elementwise methods: same values as the masked evaluation, no gather/scatter
        return zener_solution(lam, method, rtol)
    e_ze, d_ze, tau0 = np.ones(lam.shape), np.zeros(lam.shape), np.full(lam.shape, skipped_tau0)
    if needed.any():
        e_ze[needed], d_ze[needed], tau0[needed] = zener_solution(lam[needed], method, rtol)
    return e_ze, d_ze, tau0


def zener_restitution_where(lam, needed, method: str, rtol: float):
    """e_ze of an array alone (:func:`zener_solution_where`'s first value, by the same operations)."""
    lam = np.asarray(lam)
    needed = np.broadcast_to(needed, lam.shape)
    if needed.all():
        return zener_restitution_only(lam, method, rtol)
    e_ze = np.ones(lam.shape)
    if needed.any():
        e_ze[needed] = zener_restitution_only(lam[needed], method, rtol)
    return e_ze


def zener_restitution(lam, method: str = "exact", rtol: float = 1e-10):
    """(e_ze, tau0) [1] for Zener's parameter lambda [1] by ``method`` (see module doc)."""
    e, _, tau0 = zener_solution(lam, method, rtol)
    return e, tau0


# the module's own calls pass SI numbers: the equations without their unit layer
_reduced_modulus = si_only(reduced_modulus)
_plate_wave_speed = si_only(plate_wave_speed)
_dilatational_slowness = si_only(dilatational_slowness)
_edge_echo_time = si_only(edge_echo_time)
