"""The model-exchange master (restitution.cosim.model_exchange) on the native BouncingBall FMU, FMI 2.0 and 3.0,
with e(v) from SpherePlateImpact (the package, the FMU in model exchange, the FMU in co-simulation) at each
contact.

The reference is the closed form of a drop with a speed-dependent COR, computed here from
``restitution.impact`` alone: v_1 = sqrt(2 g h0), t_1 = sqrt(2 h0 / g); at contact k the rebound is
u_k = e(v_k) v_k, the next contact comes at speed v_{k+1} = u_k after a flight of 2 u_k / g; the ball rests
at the first contact whose rebound is below v_min.

The tolerance, from the event location alone (the Runge-Kutta flight is exact up to rounding, module doc):
the master places each contact past the true crossing by 0 <= delta <= event_tol, where the ball, falling,
is faster by g delta. So the impact speed error grows by at most g event_tol per contact, times the slope
du/dv of u(v) = e(v) v for the errors already there; with 0 <= du/dv <= 1 (checked at every contact
below), |dv_k| <= k g event_tol. The instant t_k carries the earlier lateness and the flight times
2 u_j / g computed from the faster speeds: |dt_k| <= sum_{j<=k} (event_tol + 2 |dv_j| / g)
<= k (k + 2) event_tol. Rounding adds a few ulps per flight; we allow 64 ulps of the largest time (speed)
per contact on top.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import restitution as r
from restitution.cosim import FmuInstance, bounce, fmu_rebound, impact_fmu_parameters, package_rebound
from restitution.cosim.model_exchange import ModelExchangeInstance, bounce_model_exchange, model_exchange_rebound

G = 9.80665
H0 = 0.3
EPS = np.finfo(float).eps
SPHERE = r.Sphere(r.MATERIALS["s2_tool_steel"], 6.35e-3)
PLATE = r.Plate(r.MATERIALS["al_6061"], 6.35e-3)
PACKAGE = {**SPHERE.params(), **PLATE.params()}


@pytest.fixture(params=["fmi2", "fmi3"])
def me_fmus(request, native_ball_fmu, native_impact_fmu, fmi3_ball_fmu, fmi3_impact_fmu):
    """(BouncingBall.fmu, SpherePlateImpact.fmu) of one FMI version, native (model exchange and co-simulation)."""
    return (native_ball_fmu, native_impact_fmu) if request.param == "fmi2" else (fmi3_ball_fmu, fmi3_impact_fmu)


def closed_form(h0=H0, g=G, v_min=0.1, e=None):
    """(contact instants, impact speeds, rebound speeds u_k = e(v_k) v_k, slopes du/dv) until the ball rests."""
    e = e or (lambda v: r.impact(v, **PACKAGE).e)
    v, t = math.sqrt(2.0 * g * h0), math.sqrt(2.0 * h0 / g)
    times, speeds, rebounds, slopes = [], [], [], []
    while True:
        u = e(v) * v
        dv = 1e-6 * v
        slopes.append((e(v + dv) * (v + dv) - e(v - dv) * (v - dv)) / (2.0 * dv))
        times.append(t), speeds.append(v), rebounds.append(u)
        if u <= 0.0 or u < v_min:
            return tuple(np.array(a) for a in (times, speeds, rebounds, slopes))
        t += 2.0 * u / g
        v = u


def bounds(times, speeds, event_tol):
    """Per-contact tolerances (time [s], speed [m/s]) of the module doc's derivation."""
    k = np.arange(1, times.size + 1)
    return (k * (k + 2) * event_tol + 64 * k * EPS * times.max(),
            k * G * event_tol + 64 * k * EPS * speeds.max())


@pytest.mark.parametrize("event_tol", [0.0, 1e-12, 1e-6])
def test_contacts_follow_the_closed_form(me_fmus, event_tol):
    """With e(v) from the package, every contact instant and impact speed, the apex heights and the count of
    contacts are the closed form's within the event-location bound; the ball's own record of each contact
    (t_impact, v_impact, e_applied, v_rebound) is what the master located and gave it."""
    ball_fmu, _impact = me_fmus
    v_min = 1e-2
    times, speeds, rebounds, slopes = closed_form(v_min=v_min)
    assert np.all((slopes >= 0.0) & (slopes <= 1.0)), slopes  # the derivation's 0 <= du/dv <= 1
    b = bounce_model_exchange(ball_fmu, package_rebound(**PACKAGE), H0, gravity=G, v_min=v_min, event_tol=event_tol)
    assert b.n_impacts == times.size and b.stop_reason == "v_min"
    dt, dv = bounds(times, speeds, event_tol)
    late = b.time - times
    assert np.all(np.abs(late) <= dt), np.max(np.abs(late) / dt)
    assert np.all(np.abs(b.v_approach - speeds) <= dv), np.max(np.abs(b.v_approach - speeds) / dv)
    assert late[0] >= -64 * EPS * times[0]  # the first contact is never placed before the true crossing
    # the apex after each contact: u^2 / 2g, u within the slope-weighted speed bound
    np.testing.assert_allclose(b.apex, rebounds ** 2 / (2 * G), rtol=0, atol=float(2 * speeds.max() * dv[-1] / G
                                                                                       + 1e-15))
    ball = b.extra["ball"]
    assert np.array_equal(ball["t_impact"], b.time) and np.array_equal(ball["v_impact"], b.v_approach)
    assert np.array_equal(ball["e_applied"], b.e) and np.array_equal(ball["impacts"], np.arange(1, b.n_impacts + 1))
    # the ball's rebound is its own e v (in C): one correctly rounded product, so within an ulp of numpy's
    np.testing.assert_allclose(ball["v_rebound"][:-1], b.e[:-1] * b.v_approach[:-1], rtol=2 * EPS, atol=0)
    assert ball["v_rebound"][-1] == 0.0
    assert ball["at_rest"][-1] and not ball["at_rest"][:-1].any()
    assert b.extra["points"]["h"].min() >= -speeds[0] * (event_tol + 64 * EPS)  # below the plate: one bracket


def test_same_contacts_as_the_co_simulation_master(me_fmus):
    """The model-exchange master and restitution.cosim.bounce (the event-exact co-simulation master, closed-form
    flights) with the same package_rebound: the same count, stop reason and COR sequence, instants and
    speeds within the event-location bound."""
    ball_fmu, _impact = me_fmus
    rebound = package_rebound(**PACKAGE)
    ref = bounce(rebound, H0, gravity=G, v_min=1e-2)
    event_tol = 1e-12
    b = bounce_model_exchange(ball_fmu, rebound, H0, gravity=G, v_min=1e-2, event_tol=event_tol)
    assert (b.n_impacts, b.stop_reason) == (ref.n_impacts, ref.stop_reason)
    dt, dv = bounds(ref.time, ref.v_approach, event_tol)
    assert np.all(np.abs(b.time - ref.time) <= dt)
    assert np.all(np.abs(b.v_approach - ref.v_approach) <= dv)
    # e at speeds that differ by dv: |de/dv| < 1/v here, so e differs by less than dv / v
    assert np.all(np.abs(b.e - ref.e) <= dv / ref.v_approach + 1e-15)
    assert b.rest_time == pytest.approx(ref.rest_time, abs=float(dt[-1]))
    t = np.linspace(0.0, ref.rest_time + 0.1, 2001)
    np.testing.assert_allclose(b.height(t), ref.height(t), rtol=0, atol=1e-9)


def test_impact_fmu_in_model_exchange_and_co_simulation(me_fmus):
    """SpherePlateImpact as the impact model at each contact, in model exchange and in co-simulation (the same
    binary: the same e at the same speed, within a few ulps accumulated over the contacts), against the package's recursion within the
    event-location bound plus the FMU's agreement with the package (1e-12 relative in e here)."""
    ball_fmu, impact_fmu = me_fmus
    params = impact_fmu_parameters(SPHERE, PLATE)
    with ModelExchangeInstance(impact_fmu, "impact-me", parameters=params) as me, \
            FmuInstance(impact_fmu, "impact-cs", parameters=params) as cs:
        b_me = bounce_model_exchange(ball_fmu, model_exchange_rebound(me), H0, gravity=G, v_min=1e-2)
        b_cs = bounce_model_exchange(ball_fmu, fmu_rebound(cs), H0, gravity=G, v_min=1e-2)
        assert me.time == b_me.time[-1] and cs.time == pytest.approx(b_cs.time[-1], abs=1e-15)  # clocks follow
    # the two interfaces run one physics function: differences, if any, are rounding carried from contact to
    # contact (each |du/dv| <= 1), far below the event-location bound
    dt_me, dv_me = bounds(b_me.time, b_me.v_approach, 1e-12)
    np.testing.assert_allclose(b_me.time, b_cs.time, rtol=0, atol=float(dt_me[-1]))
    for name in ("v_approach", "e", "e_ep", "e_ze", "lam", "t_contact", "v_rebound"):
        np.testing.assert_allclose(getattr(b_me, name), getattr(b_cs, name), rtol=1e-12, err_msg=name)
    times, speeds, _u, _s = closed_form(v_min=1e-2)
    assert b_me.n_impacts == times.size
    np.testing.assert_allclose(b_me.e, [r.impact(v, **PACKAGE).e for v in b_me.v_approach], rtol=1e-12)
    k = np.arange(1, times.size + 1)
    dt, dv = bounds(times, speeds, 1e-12)
    # an e off by 1e-12 relative adds 1e-12 v_k to each rebound: k of them in speed, 2/g of that in time
    assert np.all(np.abs(b_me.time - times) <= dt + 2 * k * k * 1e-12 * speeds[0] / G)
    assert np.all(np.abs(b_me.v_approach - speeds) <= dv + k * 1e-12 * speeds[0])


def test_a_run_stops_at_stop_time_or_max_bounces_and_an_instance_is_reused(me_fmus):
    """stop_time before the rest: the contacts so far (each run's contacts within the event-location bound of
    the other's), "stop_time", rest_time inf; max_bounces: that many contacts; a ModelExchangeInstance passed
    in is reset for each drop (two drops through one instance give the same contacts as a fresh FMU), and
    stays open for the caller."""
    ball_fmu, _impact = me_fmus
    rebound = package_rebound(**PACKAGE)
    full = bounce_model_exchange(ball_fmu, rebound, H0, gravity=G, v_min=1e-2)
    cut = bounce_model_exchange(ball_fmu, rebound, H0, gravity=G, v_min=1e-2, stop_time=float(full.time[3]) + 1e-3)
    assert cut.stop_reason == "stop_time" and cut.rest_time == math.inf and cut.n_impacts == 4
    # a finite horizon changes the steps scipy takes (its first step scales with the interval), not the flight
    dt, _dv = bounds(full.time, full.v_approach, 1e-12)
    assert np.all(np.abs(cut.time - full.time[:4]) <= 2 * dt[:4])
    assert cut.extra["points"]["t"][-1] == float(full.time[3]) + 1e-3
    three = bounce_model_exchange(ball_fmu, rebound, H0, gravity=G, v_min=1e-2, max_bounces=3)
    assert three.stop_reason == "max_bounces" and np.all(np.abs(three.time - full.time[:3]) <= 2 * dt[:3])
    after_rest = bounce_model_exchange(ball_fmu, rebound, H0, gravity=G, v_min=1e-2, stop_time=full.rest_time + 0.5)
    assert after_rest.stop_reason == "v_min" and after_rest.n_impacts == full.n_impacts
    assert np.all(np.abs(after_rest.time - full.time) <= 2 * dt)
    assert after_rest.extra["points"]["h"][-1] == 0.0
    with ModelExchangeInstance(ball_fmu, "ball") as inst:
        for _ in range(2):
            again = bounce_model_exchange(inst, rebound, H0, gravity=G, v_min=1e-2)
            assert np.all(np.abs(again.time - full.time) <= 2 * dt)
            np.testing.assert_allclose(again.e, full.e, rtol=1e-12)
        assert inst.get("impacts") == [full.n_impacts]


@pytest.mark.parametrize("kwargs, needle", [
    ({"drop_height": -0.3}, "drop_height = -0.3 m is outside the allowed range"),
    ({"drop_height": 0.0}, "drop_height = 0.0 m"),
    ({"drop_height": math.nan}, "drop_height = nan m"),
    ({"gravity": 0.0}, "gravity = 0.0 m/s2"),
    ({"v_min": 0.0}, "v_min = 0.0 m/s"),
    ({"stop_time": -1.0}, "stop_time = -1.0 s"),
    ({"max_bounces": 0}, "max_bounces = 0"),
    ({"event_tol": -1e-9}, "event_tol = -1e-09 s"),
    ({"method": "Euler"}, "method = 'Euler' is not one of RK45, DOP853, RK23"),
])
def test_bad_input_is_one_line(native_ball_fmu, kwargs, needle):
    args = {"drop_height": H0, **kwargs}
    with pytest.raises(ValueError) as info:
        bounce_model_exchange(native_ball_fmu, package_rebound(**PACKAGE), **args)
    assert needle in str(info.value) and "\n" not in str(info.value)


def test_wrong_fmus_are_one_line(ball_fmu, native_ball_fmu, native_impact_fmu):
    """The pythonfmu ball (co-simulation only), an impact FMU as the ball, the ball as the impact model."""
    rebound = package_rebound(**PACKAGE)
    with pytest.raises(ValueError, match="has no model-exchange interface") as info:
        bounce_model_exchange(ball_fmu, rebound, H0)
    with pytest.raises(ValueError, match="not a BouncingBall FMU") as info2:
        bounce_model_exchange(native_impact_fmu, rebound, H0)
    with ModelExchangeInstance(native_ball_fmu, "ball") as ball:
        with pytest.raises(ValueError, match="2 continuous states and 1 event indicators") as info3:
            model_exchange_rebound(ball)
    for exc in (info, info2, info3):
        assert "\n" not in str(exc.value)


def test_a_rejected_rebound_stops_with_value_error(native_ball_fmu):
    """A rebound that reads NaN (the FMU's sign of rejected inputs) stops the drop with one line."""
    with pytest.raises(ValueError, match=r"rebound at v_approach = .* gave e = nan.*impact 1") as info:
        bounce_model_exchange(native_ball_fmu, lambda v: {"e": math.nan, "v_rebound": math.nan}, H0)
    assert "\n" not in str(info.value)


def test_the_example_runs_on_both_fmi_versions(me_fmus, tmp_path):
    """examples/model_exchange_bounce.py with --fmu-dir pointing at the native FMUs: the model-exchange drop
    (e from SpherePlateImpact in model exchange) matches the co-simulation reference contact for contact."""
    import importlib.util

    path = Path(__file__).resolve().parents[2] / "examples" / "model_exchange_bounce.py"
    spec = importlib.util.spec_from_file_location("example_model_exchange_bounce", path)
    example = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(example)
    got = example.run(fmu_dir=me_fmus[0].parent, out_dir=tmp_path, verbose=False)
    me, ref = got["me"], got["ref"]
    assert me.n_impacts == ref.n_impacts and got["png"].is_file()
    dt, dv = bounds(ref.time, ref.v_approach, 1e-12)
    k = np.arange(1, ref.n_impacts + 1)  # plus the FMU's 1e-12 relative agreement in e, as above
    assert np.all(np.abs(me.time - ref.time) <= dt + 2 * k * k * 1e-12 * ref.v_approach[0] / G)
    with pytest.raises(ValueError, match="no native BouncingBall.fmu"):
        example.run(fmu_dir=tmp_path, out_dir=tmp_path, verbose=False)
