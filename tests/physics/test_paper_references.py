"""Every output against references from outside the code: closed forms, the equations as printed
evaluated in high precision (mpmath), and Zener's ODE solved here, independently of the package.

A misread paper (an exponent, a constant, d for r = d/2) changes one of these numbers; a test
that compared the package with itself would not notice.
"""
from __future__ import annotations

import math

import mpmath as mp
import numpy as np
import pytest
from scipy.optimize import curve_fit

import restitution as r
from restitution import jgm, zener

from independent import e44_printed, e45_printed, hertz_duration, solve_zener

M = r.MATERIALS
PAIRS = [("s2_tool_steel", "al_6061"), ("tungsten_carbide", "stainless_440c"), ("brass_260", "s7_tool_steel"),
         ("borosilicate_glass", "borosilicate_glass"), ("nitinol_60", "nitinol_60"), ("chrome_steel", "s7_tool_steel")]


def test_hertz_constant():
    assert float(2 * mp.quad(lambda x: 1 / mp.sqrt(1 - x ** 2.5), [0, 1])) == pytest.approx(2.94328, abs=5e-6)
    # the same duration through the paper's tau0(0) = 2 (5/4)^(2/5) (2/5) B(2/5, 1/2) and Eq. (9)'s T
    tau0 = 2 * (mp.mpf(5) / 4) ** 0.4 * mp.mpf(2) / 5 * mp.beta(mp.mpf(2) / 5, mp.mpf(1) / 2)
    assert float(tau0) == pytest.approx(2.94328 * 1.25 ** 0.4, rel=2e-6)


@pytest.mark.parametrize("sphere,plate", PAIRS)
@pytest.mark.parametrize("v", [1e-3, 0.5, 2.3, 20.0])
def test_contact_duration_on_a_half_space_is_hertz(sphere, plate, v):
    """plate_waves off (half-space): t_contact is the Hertz duration, to its constant's 6 digits."""
    d = 4.76e-3
    res = r.impact_between(r.Sphere(M[sphere], d), r.Plate(M[plate], 1e-2), v, plate_waves="off")
    assert res.t_contact == pytest.approx(hertz_duration(M[sphere], M[plate], d, v), rel=3e-6)


def test_contact_duration_at_small_lambda_tends_to_hertz():
    """A very thick plate: lambda ~ 1e-9, the Zener duration is Hertz's (exact and ode)."""
    sphere, plate, d, v = M["s2_tool_steel"], M["al_6061"], 6.35e-3, 2.3
    for method in ("exact", "ode"):
        res = r.impact_between(r.Sphere(sphere, d), r.Plate(plate, 1e4 * d), v, plate_waves="on", zener_method=method)
        assert res.lam < 1e-8
        assert res.t_contact == pytest.approx(hertz_duration(sphere, plate, d, v), rel=5e-6)


def test_contact_duration_scales_with_speed_diameter_and_modulus():
    """t ~ v^(-1/5), ~ d at fixed t/d (m ~ d^3, k ~ d^(1/2)), ~ E*^(-2/5), ~ rho^(2/5)."""
    base = dict(v=2.3, sphere_E=207e9, sphere_nu=0.3, sphere_Sy=2e9, sphere_rho=7861.0, sphere_d=6.35e-3,
                plate_E=69e9, plate_nu=0.33, plate_Sy=0.29e9, plate_rho=2700.0, plate_t=6.35e-3)

    def t(**change):
        return r.impact(**dict(base, **change), plate_waves="off").t_contact

    t0 = t()
    assert t(v=2.3 * 32) == pytest.approx(t0 / 2, rel=1e-12)
    assert t(sphere_d=2 * 6.35e-3, plate_t=2 * 6.35e-3) == pytest.approx(2 * t0, rel=1e-12)
    assert t(sphere_rho=7861.0 * 32) == pytest.approx(4 * t0, rel=1e-12)
    assert t(sphere_E=207e9 * 32, plate_E=69e9 * 32) == pytest.approx(t0 / 4, rel=1e-12)


# --- Eq. (23) --------------------------------------------------------------------------------------
def test_eq23_is_the_fit_of_eq22_on_the_studied_range():
    """Eq. (23)'s 1.72847 is the least-squares fit of exp(-b lambda) to the linear model's closed
    form (Eq. 22) sampled every 0.005 on [0, 1.5] (the continuum limit is 1.72818)."""
    lam = np.linspace(0.0, 1.5, 301)
    e_lin = np.exp(-math.pi * lam / np.sqrt(4 - lam ** 2))  # Eq. (22) solved in closed form (docs/paper_departures.md)
    (b,), _ = curve_fit(lambda x, b: np.exp(-b * x), lam, e_lin, p0=[1.5])
    assert b == pytest.approx(1.72847, abs=5e-6)
    for x in (0.1, 0.75, 1.5):
        assert zener.zener_linear_fit(x) == pytest.approx(math.exp(-b * x), rel=1e-5)
        assert zener.zener_linear(x)[0] == pytest.approx(math.exp(-math.pi * x / math.sqrt(4 - x * x)), rel=1e-14)


# --- JGM Eqs. (7), (8) as printed, in 30-digit arithmetic -----------------------------------------
@pytest.mark.parametrize("v_star", [1.0 + 1e-9, 1.001, 1.5, 10.0, 86.9, 500.0, 1000.0])
@pytest.mark.parametrize("eps_y", [0.001, 0.0050200821, 0.03])
def test_e45_equals_the_printed_equation(v_star, eps_y):
    """As printed, floored at 0 (the documented extension where the fit falls below 0)."""
    mp.mp.dps = 30
    want = max(float(e45_printed(v_star, eps_y)), 0.0)
    assert jgm.restitution_e45(v_star, eps_y) == pytest.approx(want, rel=1e-13, abs=1e-15)


@pytest.mark.parametrize("v_star", [1.0 + 1e-9, 1.001, 2.0, 30.0, 59.999, 60.0, 60.001, 100.0, 400.0, 1000.0])
def test_e44_equals_the_printed_equation(v_star):
    mp.mp.dps = 30
    want = max(float(e44_printed(v_star)), 0.0)
    assert jgm.restitution_e44(v_star) == pytest.approx(want, rel=1e-13, abs=1e-15)


def test_checkpoint_e45_at_the_paper_speed():
    """S2 on Al 6061 at 2.3 m/s (Sec. 7: V* = 86.9): e45 from the printed equation with the
    package's V* and eps_y."""
    res = r.impact_between(r.Sphere(M["s2_tool_steel"], 6.35e-3), r.Plate(M["al_6061"], 6.35e-3), 2.3)
    mp.mp.dps = 30
    assert res.e_ep == pytest.approx(float(e45_printed(res.V_star, res.eps_y)), rel=1e-13)
    # eps_y = Sy/E' of the plate (it yields first), Eq. (3), from the table values
    e_prime = 1 / ((1 - 0.30 ** 2) / 207e9 + (1 - 0.33 ** 2) / 69e9)
    assert res.eps_y == pytest.approx(0.290e9 / e_prime, rel=1e-14)


# --- Zener's ODE, Eq. (10), solved here ---------------------------------------------------------------
def test_first_order_loss_is_the_hertz_energy_integral():
    """1 - e_ze = c1 lambda + ...: to first order the energy the damping term takes from the Hertz
    trajectory, c1 = 3 int_0^sm sigma^(1/2) sqrt(1 - (4/5) sigma^(5/2)) dsigma, sm = (5/4)^(2/5)."""
    mp.mp.dps = 25
    sm = (mp.mpf(5) / 4) ** (mp.mpf(2) / 5)
    c1 = float(mp.re(3 * mp.quad(lambda s: mp.sqrt(s) * mp.sqrt(1 - mp.mpf(4) / 5 * s ** 2.5), [0, sm])))
    assert c1 == pytest.approx(1.7301733, abs=5e-8)
    # the ODE solved here, and the package's exact method, have that slope and the second-order term
    (e1, _), (e2, _) = solve_zener(1e-3), solve_zener(2e-3)
    # c2 = lim (c1 - (1 - e)/lambda)/lambda, Richardson-extrapolated from lambda and 2 lambda
    c2 = 2 * (c1 - (1 - e1) / 1e-3) / 1e-3 - (c1 - (1 - e2) / 2e-3) / 2e-3
    assert c2 == pytest.approx(1.7961, abs=2e-3)
    for lam in (1e-6, 1e-4, 1e-3):
        _, deficit, _ = zener.zener_solution(lam, "exact")
        assert deficit / lam == pytest.approx(c1 - 1.7961 * lam, rel=1e-7 + 2.0 * lam ** 2)


def test_large_lambda_limit():
    """e_ze lambda^5 -> 0.679293 (the ODE solved here at lambda = 6 and 10: the neglected terms
    decay like exp(-3 lambda^(5/3)))."""
    for lam in (6.0, 10.0):
        e, _ = solve_zener(lam)
        assert e * lam ** 5 == pytest.approx(0.679293, abs=2e-6)
        assert zener.zener_restitution(lam, "exact")[0] == pytest.approx(e, rel=1e-8)
    for lam in (150.0, 1e3):  # the exact method's large-lambda form
        assert zener.zener_restitution(lam, "exact")[0] * lam ** 5 == pytest.approx(0.679293, abs=2e-6)


@pytest.mark.parametrize("lam", [0.05, 0.5, 1.0, 1.5, 3.0])
def test_exact_and_ode_methods_equal_the_ode_solved_here(lam):
    e, tau0 = solve_zener(lam)
    for method in ("exact", "ode"):
        got_e, got_tau0 = zener.zener_restitution(lam, method)
        assert got_e == pytest.approx(e, rel=1e-8) and got_tau0 == pytest.approx(tau0, rel=1e-8), method
    # Sec. 7: e_ze = 0.066 and tau0 = 5.8 at lambda = 1.5
    if lam == 1.5:
        assert round(e, 3) == 0.066 and round(tau0, 1) == 5.8


# --- the underflow window of e45 ------------------------------------------------------------------
def test_e45_never_underflows_just_above_yield_onset_for_any_preset_pair():
    """A V* sweep in steps below 1e-3 near 1 (and 1e-5 inside the glass-on-glass window
    1.0867-1.0884 where 9.5 eps_y ln(V* - 1) is between -708 and -702) for every preset pair,
    scalar and array, under np.errstate(all="raise"): no underflow, e_ep in [0, 1], non-increasing."""
    v_star = np.unique(np.concatenate([1.0 + np.geomspace(1e-12, 1e-3, 200), np.arange(1.0, 1.2, 5e-4),
                                       np.arange(1.085, 1.09, 1e-5), np.geomspace(1.2, 1e3, 300)]))
    names = [n for n in M if n != "al_110_h16"]
    for a in names:
        for b in names:
            sa, sb = M[a], M[b]
            e_prime = jgm.effective_modulus(sa.E, sa.nu, sb.E, sb.nu)
            eps_y = jgm.yield_strain(e_prime, sa.nu, sa.Sy, sb.nu, sb.Sy)
            with np.errstate(all="raise"):
                e = jgm.restitution_e45(v_star, eps_y)
                scalars = [jgm.restitution_e45(float(x), eps_y) for x in v_star[::37]]
            assert np.all((e >= 0.0) & (e <= 1.0)), (a, b)
            assert np.all(np.diff(e) <= 1e-15), (a, b)
            np.testing.assert_allclose(scalars, e[::37], rtol=0, atol=1e-15)


@pytest.mark.parametrize("lam", [1e-12, 1e-6, 0.01, 0.5, 1.0, 1.5, 1.99])
def test_linear_method_equals_the_closed_form_of_eq22_in_mpmath(lam):
    """Eq. (22)'s closed form (docs/paper_departures.md): e = exp(-pi lam / sqrt(4 - lam^2)), tau0 = 2 pi / sqrt(4 - lam^2),
    evaluated in 40 digits; the deficit 1 - e to full relative accuracy (condition number ~1 in lam)."""
    mp.mp.dps = 40
    x = mp.mpf(lam)
    e_ref = mp.exp(-mp.pi * x / mp.sqrt(4 - x * x))
    tau_ref = 2 * mp.pi / mp.sqrt(4 - x * x)
    for arg in (lam, np.array([lam])):
        e, d, tau0 = zener.zener_solution(arg, "linear")
        assert float(np.squeeze(e)) == pytest.approx(float(e_ref), rel=4e-16)
        assert float(np.squeeze(d)) == pytest.approx(float(1 - e_ref), rel=4e-15)
        assert float(np.squeeze(tau0)) == pytest.approx(float(tau_ref), rel=4e-16)


@pytest.mark.parametrize("lam", [2.0, 2.5, 1e3])
def test_linear_method_beyond_critical_damping_holds_contact_without_a_floating_point_error(lam):
    """At and above lambda = 2 the linear oscillator never returns to sigma = 0: e = 0, 1 - e = 1,
    tau0 = inf (exactly, with no division by zero on the way)."""
    with np.errstate(all="raise"):
        for arg in (lam, np.array([lam, 0.5])):
            e, d, tau0 = zener.zener_solution(arg, "linear")
            assert float(np.ravel(e)[0]) == 0.0 and float(np.ravel(d)[0]) == 1.0
            assert math.isinf(float(np.ravel(tau0)[0]))


def test_eq3_sends_a_tie_to_the_sphere_as_printed():
    """Eq. (3) as printed: eps_y = S_ya / E' when C(nu_a) S_ya <= C(nu_b) S_yb. An exact floating-point
    tie with different nu and Sy (found by search around the real root) must take the sphere's Sy."""
    nu_a, nu_b, sy_a = 0.3, 0.2, 500e6
    target = jgm.poisson_coefficient(nu_a) * sy_a
    guess = target / jgm.poisson_coefficient(nu_b)
    tie = None
    for steps in range(-8, 9):
        sy_b = guess + steps * math.ulp(guess)
        if jgm.poisson_coefficient(nu_b) * sy_b == target:
            tie = sy_b
            break
    assert tie is not None and tie != sy_a
    assert jgm.sphere_yields_first(nu_a, sy_a, nu_b, tie)
    assert jgm.yield_strain(100e9, nu_a, sy_a, nu_b, tie) == sy_a / 100e9
    assert not jgm.sphere_yields_first(nu_a, sy_a, nu_b, tie - math.ulp(tie))
