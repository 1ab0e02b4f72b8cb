"""The monitors of the model's assumptions (docs/assumptions.md), checked against numbers from outside
the code: the wave delay against tau0 from an independent integration of Zener's Eq. (10) (scipy's
Radau, not the package's solver nor its table), the edge echo against the P-wave speed written with
the Lame constants (a different formula from the package's), the thresholds against their definitions,
and the messages against the conditions they name."""
import math
import warnings

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import restitution as r
from restitution.assumptions import AssumptionWarning, departures
from restitution.model import EDGE_ECHO_PUBLISHED_MAX, published
from restitution.zener import WAVE_DELAY_LIMIT

STEEL, AL = r.MATERIALS["s2_tool_steel"], r.MATERIALS["al_6061"]
D = 6.35e-3  # [m]


def params(t_over_d=1.0):
    return {**r.Sphere(STEEL, D).params(), **r.Plate(AL, t_over_d * D).params()}


def tau0_independent(lam):
    """First return of sigma to 0 for sigma'' + sigma^(3/2) + (3/2) lam sigma^(1/2) sigma' = 0, sigma(0) = 0,
    sigma'(0) = 1 (Eq. (10) with the derivative of sigma^(3/2) expanded), by Radau at rtol 1e-12."""
    def rhs(_tau, y):
        s = max(y[0], 0.0)
        return [y[1], -s ** 1.5 - 1.5 * lam * math.sqrt(s) * y[1]]

    def back_to_zero(_tau, y):
        return y[0]
    back_to_zero.terminal, back_to_zero.direction = True, -1
    sol = solve_ivp(rhs, (1e-12, 100.0), [1e-12, 1.0], method="Radau", rtol=1e-12, atol=1e-14, events=back_to_zero)
    return float(sol.t_events[0][0])


def test_the_wave_delay_is_tau0_over_its_half_space_value_by_an_independent_solve():
    """tau0(lambda)/tau0(0) within 1e-6 (the exact method's table is good to 1e-8; the ODE solve to ~1e-10)."""
    reference = tau0_independent(0.0)
    assert reference == pytest.approx(r.zener.TAU0_HERTZ, rel=1e-8)  # the Hertz closed form
    for t_over_d, v in ((1.0, 2.3), (0.3, 2.3), (0.2, 1.0), (0.15, 3.0)):
        res = r.impact(v, **params(t_over_d), plate_waves="on")
        assert res.wave_delay == pytest.approx(tau0_independent(res.lam) / reference, rel=1e-6, abs=0.0), res.lam


def test_the_delay_limit_is_the_delay_at_the_end_of_zeners_studied_range():
    """WAVE_DELAY_LIMIT = tau0(1.5)/tau0(0), rounded to 5 digits; ``concurrent`` switches there."""
    assert WAVE_DELAY_LIMIT == pytest.approx(tau0_independent(1.5) / tau0_independent(0.0), abs=1e-4)
    lam = np.linspace(1.4, 1.6, 201)
    delay = np.array([tau0_independent(x) for x in lam[::20]]) / tau0_independent(0.0)
    assert np.all(np.diff(delay) > 0)  # monotonic, so the flag and lambda <= 1.5 agree away from the rounding


@pytest.mark.parametrize("mode", ["off", "auto"])
def test_the_delay_is_one_where_zener_is_not_computed(mode):
    res = r.impact(2.3, **params(1000.0), plate_waves=mode)
    assert not res.plate_waves_used and res.wave_delay == 1.0 and res.concurrent


def test_the_linear_methods_endless_contact_has_an_endless_delay_published_as_zero():
    res = r.impact(3.0, **params(0.05), zener_method="linear")
    assert res.lam >= 2.0 and res.wave_delay == math.inf and not res.concurrent
    shown = published(res.as_dict())
    assert shown["wave_delay"] == 0.0 and not shown["contact_ends"]


def test_published_arrays_zero_the_endless_contacts_and_leave_the_others():
    """On arrays whose contacts partly never end (the linear method past lambda = 2) and wholly end: tau0,
    t_contact and wave_delay read 0 exactly where ``contact_ends`` is false, the result's values elsewhere."""
    v = np.array([0.05, 0.2, 1.0, 3.0, 6.0])
    for thickness, some_endless in ((0.2, True), (1.0, False)):
        res = r.impact(v, **params(thickness), zener_method="linear")
        ends = np.asarray(res.contact_ends)
        assert (not ends.all()) == some_endless and ends.any()
        shown = published(res.as_dict())
        for name in ("tau0", "t_contact", "wave_delay"):
            assert np.all(shown[name][~ends] == 0.0), name
            assert np.array_equal(shown[name][ends], np.asarray(getattr(res, name))[ends]), name


def p_wave_speed(E, nu, rho):
    """c_L = sqrt((lambda_L + 2 mu) / rho) with the Lame constants of E and nu."""
    lame = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))
    mu = E / (2.0 * (1.0 + nu))
    return math.sqrt((lame + 2.0 * mu) / rho)


@pytest.mark.parametrize("edge", [0.01, 0.0762, 1.0])
def test_the_edge_echo_is_the_p_wave_round_trip_over_the_contact(edge):
    res = r.impact(2.3, **params(), plate_edge_distance=edge)
    c_l = p_wave_speed(AL.E, AL.nu, AL.rho)
    assert c_l == pytest.approx(6.1e3, rel=0.05)  # aluminium's longitudinal sound speed, ~6.1-6.4 km/s
    assert res.edge_echo == pytest.approx(2.0 * edge / c_l / res.t_contact, rel=1e-12)
    assert res.edge_clear == (res.edge_echo >= 1.0)


def test_the_papers_152_mm_plate_echoes_within_the_contact():
    """Green's section 3 compares with plates 152.4 mm square, struck at the centre: the first P-wave echo
    (2 x 76.2 mm at ~6.2 km/s, 24 us) comes back before a 1/4 in steel ball leaves at 2.3 m/s (~25 us)."""
    res = r.impact(2.3, **params(), plate_edge_distance=0.0762)
    assert 0.9 < res.edge_echo < 1.0 and not res.edge_clear


@pytest.mark.parametrize("edge", [0.0, math.inf])
def test_an_unbounded_plate_has_no_echo_and_publishes_a_finite_cap(edge):
    res = r.impact(2.3, **params(), plate_edge_distance=edge)
    assert res.edge_echo == math.inf and res.edge_clear
    assert published(res.as_dict())["edge_echo"] == EDGE_ECHO_PUBLISHED_MAX


def test_an_incompressible_plate_echoes_at_once():
    """nu = 0.5: the P-wave is infinitely fast (c_L = inf), so any finite edge is inside the contact."""
    rubberlike = r.Material("incompressible", 1e9, 0.5, 1e7, 1000.0)
    res = r.impact(1.0, **{**params(), **r.Plate(rubberlike, D).params()}, plate_edge_distance=0.1)
    assert res.edge_echo == 0.0 and not res.edge_clear


def test_arrays_of_edge_distances_give_what_floats_give():
    edges = np.array([0.0, 0.01, 0.0762, math.inf])
    many = r.impact(2.3, **params(), plate_edge_distance=edges)
    for k, edge in enumerate(edges):
        one = r.impact(2.3, **params(), plate_edge_distance=float(edge))
        assert many.edge_echo[k] == pytest.approx(one.edge_echo, rel=1e-14) and many.edge_clear[k] == one.edge_clear


@pytest.mark.parametrize("bad", [-1.0, math.nan])
def test_a_negative_or_nan_edge_distance_is_refused_in_one_line(bad):
    with pytest.raises(ValueError, match=r"plate.edge_distance = .* m is outside the allowed range"):
        r.impact(2.3, **params(), plate_edge_distance=bad)


def test_the_edge_distance_takes_units():
    import pint
    with_unit = r.impact(2.3, **params(), plate_edge_distance=pint.get_application_registry().Quantity(76.2, "mm"))
    assert with_unit.edge_echo == pytest.approx(r.impact(2.3, **params(), plate_edge_distance=0.0762).edge_echo)


def test_each_departure_names_its_quantity_value_and_limit():
    """A thin plate (0.5 mm at 3 m/s: lambda = 17, e < 0) with a near edge."""
    res = r.impact(3.0, **{**params(), "plate_t": 0.5e-3}, plate_edge_distance=0.01)
    said = dict(departures(res.as_dict()))
    assert set(said) == {"lambda", "e_negative", "edge_echo"}
    assert said["lambda"].startswith(f"zener.lambda = {res.lam:.4g} is above 1.5")
    assert said["e_negative"].startswith(f"e = {res.e:.4g} is below 0")
    assert said["edge_echo"].startswith(f"monitor.edge_echo = {res.edge_echo:.4g} is below 1")
    inside = r.impact(2.3, **params())
    assert departures(inside.as_dict()) == []


def test_bounce_warns_once_per_condition():
    """restitution.cosim.bounce on a plate so thin that every impact is outside: one warning per condition."""
    from restitution.cosim import bounce, package_rebound

    rebound = package_rebound(**{**params(), "plate_t": 0.2e-3, "plate_edge_distance": 0.01})
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = bounce(rebound, drop_height=0.5)
    said = [str(w.message) for w in caught if issubclass(w.category, AssumptionWarning)]
    assert result.n_impacts >= 1
    assert len(said) == len(set(s.split(" = ")[0] for s in said)) >= 2  # one per condition
    assert any(s.startswith("zener.lambda") for s in said) and any(s.startswith("monitor.edge_echo") for s in said)
