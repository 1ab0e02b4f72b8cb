"""Contacts whose normal force is clamped at zero, their drop and the inverse that finds the damping.

A host that never pulls (Chrono SMC, LIGGGHTS with ``limitForce on``, Yade's Mindlin law, Modelica's
``ElastoGap``) sets its spring-plus-damper force to zero once the damper outweighs the spring on the way
out. The sphere then leaves with the speed it had at that instant, higher than the speed the unclamped
law would let it keep: a damping chosen from the unclamped formula gives back a higher e than asked.
Here:

- :func:`bounce`: a sphere of mass m meeting a fixed plate at speed v under a host's force law (written
  in the host module from its source), integrated finely (``dt=None``) or with the host's own fixed-step
  scheme (:data:`SCHEMES`);
- :func:`solve_decreasing`: the damping parameter giving a COR, by brentq, for any law whose COR falls
  as its damping grows;
- the damped Hertz law that Chrono SMC, LIGGGHTS and Yade share (Tsuji's damping from a restitution
  coefficient, :func:`tsuji_force`) and its exact clamped inverse (:func:`tsuji_beta_for`).

Assumptions for every host: the plate is fixed (the sphere's mass is the contact's mass), no gravity
during the contact (its impulse over tens of microseconds is negligible), the contact radius is the
sphere's, and the stiffness is Hertz's from the model's contact modulus E' (Eq. 1): the host reproduces
the model's e, with Hertz's contact time rather than the model's (which includes the plate's waves).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

__all__ = ["Bounce", "UnreachableRestitution", "SCHEMES", "bounce", "solve_decreasing", "tsuji_beta",
           "restitution_of_beta", "tsuji_force", "tsuji_restitution", "tsuji_beta_for", "hertz_constant",
           "hertz_time_unit", "MAX_STEPS", "tsuji_drop", "tsuji_parameters"]

#: The fixed-step schemes of the hosts: the name -> what the host does with a step (docs/exports_clamped_hosts.md).
SCHEMES = {
    "symplectic_euler": "v += dt F(x, v)/m, then x += dt v (Chrono's default EULER_IMPLICIT_LINEARIZED with "
                        "non-stiff SMC contact; Yade's leapfrog NewtonIntegrator)",
    "velocity_verlet": "v += dt/2 F/m, x += dt v, F from the new x and the half-step v, v += dt/2 F/m "
                       "(LIGGGHTS fix nve/sphere)",
    "explicit_euler": "x += dt v and v += dt F(x, v)/m from the same state (the fixed-step Euler of Modelica tools)",
}
#: The most steps :func:`bounce` takes with a fixed step (a step this fine is no user's).
MAX_STEPS = 2_000_000
#: Tsuji's factor 2 sqrt(5/6) in the damping coefficient of Chrono, LIGGGHTS and Yade [1].
_TSUJI_FACTOR = 2.0 * math.sqrt(5.0 / 6.0)
#: The relative tolerance of the fine integration: far below the 0.5 % the exports promise.
_RTOL = 1e-10


@dataclass(frozen=True)
class Bounce:
    """One drop: the COR the host gives and its contact time."""

    e: float  #: rebound speed over approach speed [1]
    t_contact: float  #: from first touch to separation [s]


class UnreachableRestitution(ValueError):
    """The host's clamped law cannot give this COR with any value of its parameter (one line)."""


def hertz_constant(E_eff: float, R: float) -> float:
    """K = (4/3) E' R^(1/2) [N/m^1.5] of F = K x^(3/2), sphere of radius ``R`` [m] on a flat plate, contact
    modulus ``E_eff`` [Pa] (Eq. 1; the stiffness of the text after Eq. 10, with r = R)."""
    return 4.0 / 3.0 * E_eff * math.sqrt(R)


def hertz_time_unit(m: float, K: float, v: float) -> float:
    """Zener's time unit T = (m / (K v^(1/2)))^(2/5) [s] (Eq. 9), for mass ``m`` [kg], Hertz constant ``K``
    [N/m^1.5] and speed ``v`` [m/s]: Hertz's contact lasts 3.218 T, the penetration scale is v T [m]."""
    return (m / (K * math.sqrt(v))) ** 0.4


def bounce(force: Callable[[float, float], float], m: float, v: float, time_unit: float,
           dt: float | None = None, scheme: str = "symplectic_euler") -> Bounce:
    """The sphere of mass ``m`` [kg] meets the fixed plate at ``v`` [m/s]: x the penetration [m], x' its rate
    [m/s], m x'' = -force(x, x') from x = 0, x' = v until x returns to 0. ``force`` [N] is the host's law,
    clamp included (it pushes the sphere out, >= 0). ``time_unit`` [s]: the contact's time scale (Hertz:
    :func:`hertz_time_unit`). ``dt`` None: adaptive Dormand-Prince 8(5,3) at rtol 1e-10, up to where the
    force reaches zero on the way out, then the free flight (the clamped laws here never push again); else
    the host's fixed step [s] with ``scheme`` (:data:`SCHEMES`), the contact starting on a step boundary."""
    if not (m > 0.0 and v > 0.0 and time_unit > 0.0):
        raise ValueError(f"bounce needs m, v and the time unit > 0 (m = {m}, v = {v}, time unit = {time_unit})")
    if dt is None:
        return _bounce_fine(force, m, v, time_unit)
    if scheme not in SCHEMES:
        raise ValueError(f"unknown scheme {scheme!r}; one of {', '.join(SCHEMES)}")
    if not dt > 0.0 or dt * MAX_STEPS < 20.0 * time_unit:
        raise ValueError(f"dt = {dt:.3g} s: give a step above {20.0 * time_unit / MAX_STEPS:.3g} s "
                         f"(the contact lasts about {3.2 * time_unit:.3g} s)")
    return _bounce_stepped(force, m, v, dt, scheme)


def _bounce_fine(force, m: float, v: float, time_unit: float) -> Bounce:
    from scipy.integrate import solve_ivp

    def rhs(_t, y):
        return [y[1], -force(max(y[0], 0.0), y[1]) / m]

    def separated(_t, y):
        return y[0]

    def released(_t, y):
        # the clamped force reaching zero on the way out; it stays zero from there (the spring weakens as the
        # overlap closes, the damper's demand does not), so the sphere flies out at the speed it has
        return force(max(y[0], 0.0), y[1]) if y[1] < 0.0 else 1.0
    for event in (separated, released):
        event.terminal, event.direction = True, -1.0
    # x(0) = 0 is no crossing (an event counts g going from > 0 to <= 0); 200 T: a contact never lasts that long
    sol = solve_ivp(rhs, (0.0, 200.0 * time_unit), [0.0, v], method="DOP853", events=(separated, released),
                    rtol=_RTOL, atol=[_RTOL * v * time_unit, _RTOL * v], max_step=0.05 * time_unit)
    ends = [(float(t[0]), y[0]) for t, y in zip(sol.t_events, sol.y_events) if t.size]
    if not ends:
        raise RuntimeError("the sphere did not leave the plate within 200 contact time units")
    t_end, (x_end, u_end) = min(ends, key=lambda end: end[0])
    flight = max(x_end, 0.0) / -u_end  # the free flight from the release to separation [s]
    return Bounce(e=float(-u_end / v), t_contact=float(t_end + flight))


def _bounce_stepped(force, m: float, v: float, dt: float, scheme: str) -> Bounce:
    x, u = 0.0, v
    for step in range(1, MAX_STEPS + 1):
        if scheme == "symplectic_euler":
            u -= dt * force(max(x, 0.0), u) / m
            x += dt * u
        elif scheme == "velocity_verlet":
            u -= 0.5 * dt * force(max(x, 0.0), u) / m
            x += dt * u
            u -= 0.5 * dt * force(max(x, 0.0), u) / m  # the force from the new x and the half-step velocity
        else:
            x, u = x + dt * u, u - dt * force(max(x, 0.0), u) / m
        if x <= 0.0:
            # separated within this step: the force is zero from here on, the speed is the rebound's
            return Bounce(e=-u / v, t_contact=step * dt)
    raise RuntimeError(f"the sphere did not leave the plate within {MAX_STEPS} steps of {dt:.3g} s")


def solve_decreasing(restitution_of: Callable[[float], float], e: float, low: float, high: float,
                     what: str, grow: bool = False) -> float:
    """The parameter p in [``low``, ``high``] with ``restitution_of(p) == e``, ``restitution_of`` falling as p
    grows (a damping), by brentq to 1e-12 relative. ``grow``: double ``high`` until it brackets e (for an
    unbounded damping). :class:`UnreachableRestitution` naming ``what`` where e lies outside the range the
    law covers."""
    from scipy.optimize import brentq

    top = restitution_of(low)
    if top <= e <= top + _RTOL * 100:  # e at the undamped end, within the integration's error
        return low
    bottom = restitution_of(high)
    while grow and bottom > e and high < 1e12:
        high *= 2.0
        bottom = restitution_of(high)
    if not bottom <= e <= top:
        raise UnreachableRestitution(f"e = {e:.4g} is outside what {what} can give ({bottom:.4g} to {top:.4g})")
    return brentq(lambda p: restitution_of(p) - e, low, high, xtol=1e-14, rtol=1e-12)


# --- The damped Hertz law of Chrono SMC (Hertz), LIGGGHTS (model hertz) and Yade (Mindlin with en) ---------


def tsuji_beta(cr: float) -> float:
    """beta = ln(cr) / sqrt(ln(cr)^2 + pi^2) [1], in (-1, 0], of the restitution coefficient ``cr`` [1] in
    (0, 1] given to the host: the damping ratio of the linear oscillator whose COR is cr."""
    log_cr = math.log(cr)
    return log_cr / math.sqrt(log_cr * log_cr + math.pi * math.pi)


def restitution_of_beta(beta: float) -> float:
    """The cr [1] whose :func:`tsuji_beta` is ``beta`` in (-1, 0]: cr = exp(pi beta / sqrt(1 - beta^2))."""
    return math.exp(math.pi * beta / math.sqrt(1.0 - beta * beta))


def tsuji_force(x: float, xdot: float, E_eff: float, R: float, m: float, beta: float, clamp: bool = True) -> float:
    """The normal force [N] of the three hosts at penetration ``x`` [m] and rate ``xdot`` [m/s] (> 0 closing):
    S_n = 2 E' sqrt(R x), k_n = (2/3) S_n, g_n = -2 sqrt(5/6) beta sqrt(S_n m), F = k_n x + g_n x'; the
    hosts set F < 0 to 0 (``clamp``). ``E_eff`` [Pa], ``R`` [m], ``m`` [kg], ``beta`` [1] from
    :func:`tsuji_beta`."""
    if x <= 0.0:
        return 0.0
    s_n = 2.0 * E_eff * math.sqrt(R * x)
    push = 2.0 / 3.0 * s_n * x - _TSUJI_FACTOR * beta * math.sqrt(s_n * m) * xdot
    return max(push, 0.0) if clamp else push


def tsuji_restitution(beta: float, clamp: bool = True) -> float:
    """The COR [1] of :func:`tsuji_force` with ``beta`` [1]: the same for every mass, radius, modulus and
    speed (the damping grows as x^(1/4), as the Hertz stiffness's square root), so computed for unit values."""
    unit_modulus = 0.75  # K = 1 with R = 1
    return bounce(lambda x, xdot: tsuji_force(x, xdot, unit_modulus, 1.0, 1.0, beta, clamp), 1.0, 1.0, 1.0).e


def tsuji_beta_for(e: float, cr_min: float, host: str, parameter: str = "cr") -> float:
    """The beta [1] at which the clamped :func:`tsuji_force` gives the COR ``e`` [1], for ``host`` whose
    restitution ``parameter`` accepts values >= ``cr_min`` [1]. e = 1: beta = 0 (no damping). A clamped contact
    cannot go below the COR at the host's smallest parameter (0.136 as it tends to 0):
    :class:`UnreachableRestitution` there, naming the host and the parameter."""
    if e >= 1.0:
        return 0.0
    beta_min = tsuji_beta(cr_min)
    # brentq over -beta (the damping), which the COR falls with
    return -solve_decreasing(lambda damping: tsuji_restitution(-damping), e, 0.0, -beta_min,
                             f"{host}'s clamped Hertz law with {parameter} >= {cr_min:.3g}")


def tsuji_drop(cr: float, E_eff: float, R: float, m: float, v: float, dt: float | None = None,
               scheme: str = "symplectic_euler", clamp: bool = True, damping_mass: float | None = None) -> Bounce:
    """A drop on :func:`tsuji_force` with the restitution coefficient ``cr`` [1] given to the host, contact
    modulus ``E_eff`` [Pa], sphere radius ``R`` [m] and mass ``m`` [kg] at ``v`` [m/s] (:func:`bounce`).
    ``damping_mass`` [kg]: the mass the host puts in its damping coefficient where it is not m (Chrono's
    m1 m2/(m1 + m2) with a fixed plate's own mass)."""
    beta = tsuji_beta(cr)
    m_damping = m if damping_mass is None else damping_mass
    time_unit = hertz_time_unit(m, hertz_constant(E_eff, R), v)
    return bounce(lambda x, xdot: tsuji_force(x, xdot, E_eff, R, m_damping, beta, clamp), m, v, time_unit, dt,
                  scheme)


def tsuji_parameters(case, cr_min: float, host: str, parameter: str) -> dict:
    """What the three damped-Hertz hosts share for ``case`` (an ExportCase: e, v, m_sphere, R_sphere, E_eff,
    E1, nu1, E2, nu2), for ``host`` and its restitution ``parameter`` (>= ``cr_min``): "e"; "cr", the
    restitution coefficient to give the host, the exact inverse of its clamped law; "cr_naive_gives", the COR
    the host returns if given cr = e; "t_contact", the host's contact time [s]; the sphere's "R" [m] and "m"
    [kg]; "v" [m/s]; the bodies' moduli "E_eff", "E1", "E2" [Pa] and "nu1", "nu2". SI units."""
    cr = restitution_of_beta(tsuji_beta_for(case.e, cr_min, host, parameter))
    return {"e": case.e, "cr": cr,
            "cr_naive_gives": tsuji_restitution(tsuji_beta(min(max(case.e, cr_min), 1.0))),
            "t_contact": tsuji_drop(cr, case.E_eff, case.R_sphere, case.m_sphere, case.v).t_contact,
            "E_eff": case.E_eff, "E1": case.E1, "nu1": case.nu1, "E2": case.E2, "nu2": case.nu2,
            "R": case.R_sphere, "m": case.m_sphere, "v": case.v}
