"""The contact laws of Chrono SMC (Hertz), LIGGGHTS (model hertz, limitForce on), Yade (Mindlin with en)
and Modelica's ElastoGap, written here again from the hosts' sources and manuals (never from
restitution.export), and a drop integrated independently: scipy's RK45 with events, ending at the
instant the host's force reaches zero on the way out (the sphere flies free from there) or at separation.

Signs follow each host: Chrono's and LIGGGHTS's relative normal velocity is negative while the bodies
approach; Yade's incident velocity likewise; ElastoGap's s_rel is negative in contact and v_rel its rate.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from scipy.integrate import solve_ivp


@dataclass(frozen=True)
class Pair:
    """A sphere on a fixed plate, SI: what the host modules read from an export case."""

    e: float
    v: float
    d: float
    rho: float
    E1: float
    nu1: float
    E2: float
    nu2: float
    t_contact: float = float("nan")  # not read by the host modules

    @property
    def R_sphere(self):
        return self.d / 2.0

    @property
    def m_sphere(self):
        return self.rho * math.pi * self.d ** 3 / 6.0

    @property
    def E_eff(self):  # Hertz's contact modulus, Johnson (Contact Mechanics) Eq. 4.22
        return 1.0 / ((1.0 - self.nu1 ** 2) / self.E1 + (1.0 - self.nu2 ** 2) / self.E2)


def _beta(restitution):
    """Tsuji's beta of the three DEM hosts: ln e / sqrt(ln^2 e + pi^2)."""
    log_e = math.log(restitution)
    return log_e / math.sqrt(log_e ** 2 + math.pi ** 2)


def chrono_normal_force(delta, relvel_n, E_eff, eff_radius, eff_mass, cr):
    """Chrono SMC Hertz with material properties, ChContactSMC.cpp, before its clamp (relvel_n < 0 closing)."""
    sqrt_rd = math.sqrt(eff_radius * delta)
    sn = 2.0 * E_eff * sqrt_rd
    kn = 2.0 / 3.0 * sn
    gn = -2.0 * math.sqrt(5.0 / 6.0) * _beta(cr) * math.sqrt(sn * eff_mass)
    return kn * delta - gn * relvel_n


def liggghts_normal_force(deltan, vn, Yeff, reff, meff, coefficient_restitution):
    """LIGGGHTS normal_model_hertz.h before limitForce (vn < 0 closing, as Fn_damping = -gamman vn)."""
    sqrtval = math.sqrt(reff * deltan)
    sn = 2.0 * Yeff * sqrtval
    kn = 4.0 / 3.0 * Yeff * sqrtval
    gamman = -2.0 * math.sqrt(5.0 / 6.0) * _beta(coefficient_restitution) * math.sqrt(sn * meff)
    return -gamman * vn + kn * deltan


def yade_normal_force(uN, incident_vn, E, R, mbar, en):
    """Yade Law2_ScGeom_MindlinPhys_Mindlin with Ip2's en (HertzMindlin.cpp), before the no-pull clamp."""
    kno = 4.0 / 3.0 * E * math.sqrt(R)
    alpha = -math.sqrt(5 / 6.0) * 2 * _beta(en) * math.sqrt(2 * E * math.sqrt(R))
    cn = alpha * math.sqrt(mbar) * uN ** 0.25
    return kno * uN ** 1.5 - cn * incident_vn


def elastogap_pushing_force(s_rel, v_rel, c, d, n):
    """ElastoGap.mo with s_rel0 = 0, s_ref = 1 m: minus f (f < 0 pushes the flanges apart), 0 out of contact."""
    if s_rel >= 0.0:
        return 0.0
    f_c = -c * abs(s_rel) ** n
    f_d2 = d * v_rel
    f_d = min(max(f_d2, f_c), -f_c)
    return -(f_c + f_d)


def drop(push, m, v, time_scale, clamp=True):
    """A sphere of mass ``m`` hitting the fixed plate at ``v``: ``push(x, xdot)`` the host's force before its
    clamp, x the penetration, xdot > 0 closing. Returns (e, contact time) with the contact ending where the
    clamped force reaches zero on the way out (``clamp``) or where x returns to 0."""
    def rhs(_t, y):
        force = push(y[0], y[1]) if y[0] > 0.0 else 0.0
        return [y[1], -(max(force, 0.0) if clamp else force) / m]

    def released(_t, y):
        return push(y[0], y[1]) if y[0] > 0.0 else 1.0
    released.terminal, released.direction = True, -1

    def separated(_t, y):
        return y[0]
    separated.terminal, separated.direction = True, -1

    events = [released, separated] if clamp else [separated]
    sol = solve_ivp(rhs, (0.0, 100.0 * time_scale), [0.0, v], method="RK45", events=events, rtol=1e-10,
                    atol=[1e-13 * v * time_scale, 1e-13 * v], max_step=time_scale / 50.0)
    hits = [(t[0], y[0]) for t, y in zip(sol.t_events, sol.y_events) if t.size]
    assert hits, "the sphere never left the plate"
    t_end, y_end = min(hits, key=lambda hit: hit[0])
    return -y_end[1] / v, t_end


def hertz_time(pair):
    """Zener's (Hertz's) time unit (m / (K v^1/2))^(2/5), K = 4/3 E* sqrt(R) [s]: the contact lasts 3.2 of them."""
    k = 4.0 / 3.0 * pair.E_eff * math.sqrt(pair.R_sphere)
    return (pair.m_sphere / (k * math.sqrt(pair.v))) ** 0.4
