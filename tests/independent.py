"""Independent references for the tests: the paper's equations as printed, evaluated in mpmath,
closed forms from the literature, and Zener's ODE solved with scipy here, written without the
package's code (no import of restitution). A misread paper shows up as a difference."""
from __future__ import annotations

import math
import tomllib
from fractions import Fraction
from pathlib import Path

import mpmath as mp
from scipy.integrate import solve_ivp

#: The paper's Tables 1-4 as printed (tests/data/paper_tables.toml).
TABLES = tomllib.loads((Path(__file__).parent / "data" / "paper_tables.toml").read_text())


def table_rows():
    """(table, preset key, row) of Tables 1-3."""
    for table in ("table1", "table2", "table3"):
        for key, row in TABLES[table].items():
            yield table, key, row


def table_material(key):
    """E, nu, Sy, rho [SI] of a preset, merged from the table rows (never from restitution), as mpmath numbers."""
    merged = {}
    for _table, k, row in table_rows():
        if k == key:
            merged.update({p: row[p] for p in ("E", "nu", "Sy", "rho") if p in row})
    return {p: mp.mpf(repr(float(merged[p]))) for p in ("E", "nu", "Sy", "rho")}


def hertz_duration(sphere, plate, d, v):
    """Hertz contact duration of a sphere on a half-space [s], written here from the textbook
    (Johnson, Contact Mechanics, Sec. 11.4): t = 2.94328 (5 m / (4 k))^(2/5) v^(-1/5), F = k delta^(3/2),
    k = (4/3) E* sqrt(R), R = d/2, 1/E* = (1 - nu_a^2)/E_a + (1 - nu_b^2)/E_b, m = rho pi d^3 / 6.
    2.94328 = 2 int_0^1 dx / sqrt(1 - x^(5/2)) (the constant is checked below)."""
    e_star = 1.0 / ((1 - sphere.nu ** 2) / sphere.E + (1 - plate.nu ** 2) / plate.E)
    k = 4.0 / 3.0 * e_star * math.sqrt(d / 2)
    m = sphere.rho * math.pi * d ** 3 / 6
    return 2.94328 * (5 * m / (4 * k)) ** 0.4 * v ** -0.2


def e45_printed(v_star, eps_y):
    v, eps = mp.mpf(v_star), mp.mpf(eps_y)
    return 1 - mp.mpf("0.0361") * eps ** mp.mpf("-0.114") * mp.log(v) * (v - 1) ** (mp.mpf("9.5") * eps)


def e44_printed(v_star):
    v = mp.mpf(v_star)
    if v <= 60:
        return 1 - mp.mpf("0.1") * mp.log(v) * ((v - 1) / 59) ** mp.mpf("0.156")
    # second branch as reconstructed (docs/paper_departures.md): ((V* - 60)/940)^2.366
    return 1 - mp.mpf("0.1") * mp.log(60) - mp.mpf("0.11") * mp.log(v / 60) * ((v - 60) / 940) ** mp.mpf("2.366")


def printed_equations(a, b, d, t, v):
    """(eps_y, V_c, lambda) of Eqs. (1)-(6), (12) as printed, in mpmath."""
    ea, eb = a["E"] / (1 - a["nu"] ** 2), b["E"] / (1 - b["nu"] ** 2)   # Eq. (1)
    e_prime = ea * eb / (ea + eb)
    ca, cb = 1.295 * mp.exp(mp.mpf("0.736") * a["nu"]), 1.295 * mp.exp(mp.mpf("0.736") * b["nu"])  # Eq. (2)
    c_sy = min(ca * a["Sy"], cb * b["Sy"])
    eps_y = (a["Sy"] if ca * a["Sy"] <= cb * b["Sy"] else b["Sy"]) / e_prime    # Eq. (3)
    R = mp.mpf(d) / 2
    omega_c = (mp.pi * c_sy / (2 * e_prime)) ** 2 * R                           # Eq. (4)
    p_c = mp.mpf(4) / 3 * (R / e_prime) ** 2 * (mp.pi / 2 * c_sy) ** 3           # Eq. (5)
    m_a = a["rho"] * mp.pi * mp.mpf(d) ** 3 / 6
    v_c = mp.sqrt(4 * omega_c * p_c / (5 * m_a))                                # Eq. (6)
    v_prime = mp.sqrt(eb / b["rho"])
    lam = (mp.pi ** (mp.mpf(3) / 5) / mp.sqrt(3) * (R / mp.mpf(t)) ** 2 * (mp.mpf(v) / v_prime) ** (mp.mpf(1) / 5)
           * (a["rho"] / b["rho"]) ** (mp.mpf(3) / 5) * (ea / (ea + eb)) ** (mp.mpf(2) / 5))  # Eq. (12)
    return eps_y, v_c, lam


def solve_zener(lam, rtol=1e-12):
    """e_ze and tau0 of Eq. (10)-(11) in Zener's p-form (sigma' = p - lambda sigma^1.5,
    p' = -sigma^1.5), Radau with its Jacobian, the rebound as a terminal event. Written for the
    tests, independent of restitution.zener_ode and of the exact method's table."""
    def rhs(t, y):
        s15 = max(y[0], 0.0) ** 1.5
        return [y[1] - lam * s15, -s15]

    def jac(t, y):
        s = max(y[0], 0.0)
        return [[-1.5 * lam * s ** 0.5, 1.0], [-1.5 * s ** 0.5, 0.0]]

    def back(t, y):
        return y[0]
    back.terminal, back.direction = True, -1
    t0 = 1e-6  # sigma = tau, p = 1 to O(tau^2.5) = 1e-15
    sol = solve_ivp(rhs, (t0, 50.0 + 20 * lam * math.log1p(lam)), [t0, 1.0], method="Radau", jac=jac,
                    rtol=rtol, atol=1e-14 * min(1.0, lam ** -5), events=back, first_step=1e-7)
    return -sol.y_events[0][0][1], sol.t_events[0][0]


def apparent_cor(a: dict, b: dict, d: float, t: float, v: float, half_space: bool = False) -> float:
    """e of Eq. (20) with e45 (Eq. 8) and Zener's e_ze from the ODE solved here at lambda of
    Eq. (12) (1 for a half-space): a and b hold E, nu, Sy, rho of the sphere and the plate (SI)."""
    mp.mp.dps = 30
    a = {k: mp.mpf(repr(float(x))) for k, x in a.items()}
    b = {k: mp.mpf(repr(float(x))) for k, x in b.items()}
    eps_y, v_c, lam = printed_equations(a, b, d, t, v)
    v_star = mp.mpf(v) / v_c
    e_ep = max(float(e45_printed(v_star, eps_y)), 0.0) if v_star > 1 else 1.0
    e_ze = 1.0 if half_space else solve_zener(float(lam))[0]
    return (e_ep + e_ze + e_ep * e_ze - 1.0) / 2.0


# --- The monitors of the assumptions (docs/assumptions.md): Zener's time unit and contact time, the
# --- half-space and the two approximate methods' tau0 as printed, the plate's P-wave speed

def zener_time_unit(a: dict, b: dict, d: float, v: float):
    """Zener's time unit T = (m / (k v^(1/2)))^(2/5) [s], Eq. (9), in mpmath: m = rho_a pi d^3/6 the
    sphere's mass, k = (4/3) E' sqrt(d/2) the Hertz stiffness with E' of Eq. (1); a and b hold E, nu,
    rho of the sphere and the plate (SI)."""
    mp.mp.dps = 30
    ea = mp.mpf(repr(float(a["E"]))) / (1 - mp.mpf(repr(float(a["nu"]))) ** 2)
    eb = mp.mpf(repr(float(b["E"]))) / (1 - mp.mpf(repr(float(b["nu"]))) ** 2)
    k = mp.mpf(4) / 3 * (ea * eb / (ea + eb)) * mp.sqrt(mp.mpf(d) / 2)
    m = mp.mpf(repr(float(a["rho"]))) * mp.pi * mp.mpf(d) ** 3 / 6
    return (m / (k * mp.sqrt(mp.mpf(v)))) ** (mp.mpf(2) / 5)


def tau0_hertz():
    """tau0 at lambda = 0, the Hertz impact on a half-space, in Zener's unit: the Hertz contact time
    2 (5 m / (4 k))^(2/5) v^(-1/5) int_0^1 dx / sqrt(1 - x^(5/2)) (Johnson, Contact Mechanics, 11.4)
    over T: 2 (5/4)^(2/5) int_0^1 dx / sqrt(1 - x^(5/2)), by mpmath's quadrature."""
    mp.mp.dps = 30
    return 2 * (mp.mpf(5) / 4) ** (mp.mpf(2) / 5) * mp.quad(lambda x: 1 / mp.sqrt(1 - x ** mp.mpf(2.5)), [0, 1])


def tau0_paper_fit(lam):
    """tau0 of Eq. (13a) as printed: 3.215 exp(0.318 lambda^(3/2)) (3.215 at lambda = 0)."""
    mp.mp.dps = 30
    return mp.mpf("3.215") * mp.exp(mp.mpf("0.318") * mp.mpf(lam) ** mp.mpf(1.5))


def tau0_linear(lam):
    """First return to 0 of the linearised Eq. (22), sigma'' + lambda sigma' + sigma = 0, sigma(0) = 0,
    sigma'(0) = 1: sigma = exp(-lambda tau/2) sin(w tau)/w with w = sqrt(1 - lambda^2/4), back at
    tau = pi/w (pi at lambda = 0); never for lambda >= 2 (critically or over-damped): +inf."""
    mp.mp.dps = 30
    lam = mp.mpf(lam)
    return mp.pi / mp.sqrt(1 - lam ** 2 / 4) if lam < 2 else mp.inf


def p_wave_speed(E: float, nu: float, rho: float):
    """The bulk P-wave speed c_L = sqrt((lambda_L + 2 mu) / rho) [m/s] with the Lame constants
    lambda_L = E nu / ((1 + nu)(1 - 2 nu)), mu = E / (2 (1 + nu)), in mpmath."""
    mp.mp.dps = 30
    E, nu, rho = (mp.mpf(repr(float(x))) for x in (E, nu, rho))
    lame = E * nu / ((1 + nu) * (1 - 2 * nu))
    return mp.sqrt((lame + 2 * E / (2 * (1 + nu))) / rho)


# --- BouncingBall's contact indicator (docs/host_contract.md): h + max(v, 0)^2/(2 g) in flight

#: (h [m], v [m/s]) in flight: rising, falling, at the apex (v = +0 and -0), below the plate either way.
INDICATOR_IN_FLIGHT = ((0.2, 1.5), (0.0, 3.0), (1.0, 0.25), (-0.05, 2.0), (0.2, -1.5), (0.7, -0.3), (-0.01, -2.0),
                       (0.3, 0.0), (0.3, -0.0))
#: (g [m/s2], h [m], v [m/s]) a host may set, far beyond any flight, up to the largest double.
_BIG = 1.7976931348623157e308
INDICATOR_EXTREME = ((9.80665, 1e308, _BIG), (9.80665, _BIG, _BIG), (9.80665, -_BIG, _BIG), (9.80665, 0.0, _BIG),
                     (9.80665, 1e308, -_BIG), (9.80665, -_BIG, -_BIG), (9.80665, 1.0, 1e154),
                     (9.80665, -1e308, 1.4e154), (1e6, 0.0, 2e154), (1e6, -1e308, 2e154), (1e6, _BIG, 2e154),
                     (1e6, -_BIG, 1e160), (1e-6, _BIG, _BIG), (1e-6, -_BIG, _BIG), (1e-6, -1e300, 1e150))


def apex_height_exact(h: float, v: float, g: float):
    """(h + max(v, 0)^2/(2 g), |h| + max(v, 0)^2/(2 g)) as exact Fractions: the indicator's closed form
    and the scale of its rounding error in doubles."""
    term = Fraction(max(v, 0.0)) ** 2 / (2 * Fraction(g))
    return Fraction(h) + term, abs(Fraction(h)) + term


def assert_indicator(got: float, h: float, v: float, g: float, ulps: float = 2):
    """``got`` is finite and the closed form within ``ulps`` eps of its scale (at most 3 roundings of
    half an ulp of the scale: v * v, the division by the exact 2 g, the sum; no cancellation amplifies
    an absolute bound); where the exact value is above the largest double, that double (the indicator's
    documented saturation)."""
    exact, scale = apex_height_exact(h, v, g)
    assert math.isfinite(got), (h, v, g, got)
    expected = min(exact, Fraction(_BIG))
    assert abs(Fraction(got) - expected) <= ulps * 2.0 ** -52 * min(scale, Fraction(_BIG)), (h, v, g, got,
                                                                                            float(expected))
