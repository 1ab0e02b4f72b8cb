"""The numpy floor of the performance goals: e and v_rebound of many impacts of one sphere on one plate,
written as a plain numpy expression with every term that depends on the parameters alone computed once.

What it computes (I. Green, Nonlinear Dyn 2022): V* = v / V_c and the elastoplastic COR by Eq. (8) (e45),
lambda by Eq. (12), Zener's COR by the paper's fit, Eq. (13), e_ze = exp(-1.68374 lambda), the apparent COR
by Eq. (20) and v_rebound = e v. The parameter terms (Eqs. 1-6, and the speed-free factor of Eq. 12) are
Python floats made once by :func:`floor_terms`. No checks, no effect modes, no other output: the least a
numpy program computing e and v_rebound does. bench_impact.py and bench_uncertainty.py time the package
against it; :func:`floor_terms` and :func:`e_and_rebound` are written here from the paper, not from the
package.
"""
from __future__ import annotations

import math

import numpy as np

ZENER_FIT = 1.68374  #: the paper's fit of e_ze, Eq. (13) [1]


def floor_terms(p: dict) -> tuple:
    """(V_c [m/s], the loss coefficient 0.0361 eps_y^-0.114 [1], the loss exponent 9.5 eps_y [1], lambda / v^(1/5)
    [(s/m)^(1/5)]) of impact()'s parameters ``p`` (sphere_E ... plate_t, SI), as Python floats."""
    Ea = p["sphere_E"] / (1.0 - p["sphere_nu"] ** 2)  # Eq. (1)
    Eb = p["plate_E"] / (1.0 - p["plate_nu"] ** 2)
    E_prime = Ea * Eb / (Ea + Eb)
    c_a = 1.295 * math.exp(0.736 * p["sphere_nu"]) * p["sphere_Sy"]  # Eq. (2)
    c_b = 1.295 * math.exp(0.736 * p["plate_nu"]) * p["plate_Sy"]
    CSy = min(c_a, c_b)
    eps_y = (p["sphere_Sy"] if c_a <= c_b else p["plate_Sy"]) / E_prime  # Eq. (3)
    R = 0.5 * p["sphere_d"]
    omega_c = (math.pi * CSy / (2.0 * E_prime)) ** 2 * R  # Eq. (4)
    P_c = 4.0 / 3.0 * (R / E_prime) ** 2 * (0.5 * math.pi * CSy) ** 3  # Eq. (5)
    m_a = p["sphere_rho"] * math.pi * p["sphere_d"] ** 3 / 6.0
    V_c = math.sqrt(0.8 * omega_c * P_c / m_a)  # Eq. (6)
    lam_per_speed = (math.pi ** 0.6 / math.sqrt(3.0) * (R / p["plate_t"]) ** 2 * (p["plate_rho"] / Eb) ** 0.1
                     * (p["sphere_rho"] / p["plate_rho"]) ** 0.6 * (Ea / (Ea + Eb)) ** 0.4)  # Eq. (12) / v^(1/5)
    return V_c, 0.0361 * eps_y ** -0.114, 9.5 * eps_y, lam_per_speed


def e_and_rebound(v, terms):
    """(e, v_rebound) of the speeds ``v`` [m/s] (an array) with :func:`floor_terms`' ``terms``."""
    V_c, loss_coefficient, loss_exponent, lam_per_speed = terms
    v_star = v / V_c
    with np.errstate(invalid="ignore", divide="ignore"):  # V* <= 1: not selected
        e_ep = np.where(v_star > 1.0, np.maximum(1.0 - loss_coefficient * np.log(v_star)
                                                 * (v_star - 1.0) ** loss_exponent, 0.0), 1.0)  # Eq. (8)
    e_ze = np.exp(-ZENER_FIT * lam_per_speed * v ** 0.2)  # Eqs. (12), (13)
    e = 0.5 * (e_ze * (1.0 + e_ep) - (1.0 - e_ep))  # Eq. (20)
    return e, e * v
