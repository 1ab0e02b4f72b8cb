"""FMI 3.0 co-simulation with event mode and early return (restitution.cosim.event_mode): the native
BouncingBall.fmu returns from fmi3DoStep at each contact, the master sets the COR SpherePlateImpact.fmu
gives for that contact's speed in event mode, and the ball rebounds there. Checked against a ballistic
flight computed here, with the package's own impact model (restitution.impact) for the COR."""
from __future__ import annotations

import math

import pytest

import restitution as r
from cases import params_for
from restitution.cosim import FmuInstance
from restitution.cosim.bouncing import fmu_rebound
from restitution.cosim.event_mode import EventModeInstance, event_mode_bounce
from restitution.fmu.models.sphere_plate_impact.variables import fmu_values

G = 9.80665  # [m/s2]
H0 = 0.3  # [m]
V_MIN = 0.1  # [m/s]
PAIR = ("s2/al6061", 1.0)  # the paper's Table 3 materials, plate as thick as the ball


@pytest.fixture(scope="module")
def host_fmi3(tmp_path_factory):
    """The native FMI 3.0 BouncingBall.fmu and SpherePlateImpact.fmu of the current sources, built for this
    machine's platform only (seconds; the session's built_fmus builds every platform)."""
    from fmpy import platform_tuple

    from restitution.fmu.build.compile import NativeBuildSkipped
    from restitution.fmu.build.native import build_native_one

    out = tmp_path_factory.mktemp("fmi3_host")
    try:
        return {model: build_native_one(model, out, fmi_version="3.0", folders=(platform_tuple,), log=lambda _l: None)
                for model in ("BouncingBall", "SpherePlateImpact")}
    except NativeBuildSkipped as exc:
        pytest.skip(f"native FMI 3.0 FMUs not built here: {exc}")


def package_cor(v: float) -> float:
    """The package's COR for approach speed v [m/s] (restitution.impact), the same materials as the FMU."""
    return r.impact(v, **params_for(*PAIR)).e


def ballistic_contacts(h0: float, g: float, v_min: float, cor) -> list[tuple[float, float, float]]:
    """(time [s], approach speed [m/s], COR) of every contact of a ball released from rest at h0 [m] at
    t = 0: free fall to sqrt(2 h0 / g) at speed sqrt(2 g h0); after a contact at speed v with COR e it
    leaves at e v and comes back 2 e v / g later at the same speed; it rests when e <= 0 or e v < v_min."""
    t, v = math.sqrt(2.0 * h0 / g), math.sqrt(2.0 * g * h0)
    contacts = []
    while True:
        e = cor(v)
        contacts.append((t, v, e))
        if e <= 0.0 or e * v < v_min:
            return contacts
        v = e * v
        t += 2.0 * v / g


@pytest.fixture(scope="module")
def pair(host_fmi3):
    """The ball (event mode and early return) and SpherePlateImpact with PAIR's materials."""
    params = fmu_values(**params_for(*PAIR))
    with EventModeInstance(host_fmi3["BouncingBall"], "ball", parameters={"h0": H0, "g": G, "v_min": V_MIN}) as ball, \
            FmuInstance(host_fmi3["SpherePlateImpact"], "impact", parameters=params) as impact:
        yield ball, impact


@pytest.mark.parametrize("step", [1e-1, 1e-2, 1e-3, 1e-4])
def test_contacts_are_at_the_ballistic_times_with_the_cor_of_their_own_speed(pair, step):
    """At every communication step from 0.1 s to 0.1 ms: each contact time and speed equals the ballistic
    flight's to 1e-12 relative (the FMU solves the same parabolas in closed form: only roundings
    differ, a few ulps per flight over ten flights), the COR applied at each contact is the package's
    COR at that contact's own speed (zero lag: not the previous contact's), and the ball comes to rest
    after as many contacts. The steps that ended early are one per contact that fell inside a step."""
    ball, impact = pair
    ball.reset(parameters={"h0": H0, "g": G, "v_min": V_MIN})
    run = event_mode_bounce(ball, fmu_rebound(impact), step)
    expected = ballistic_contacts(H0, G, V_MIN, package_cor)
    assert run.stop_reason == "v_min" and len(run.t_impact) == len(expected) > 5
    for k, (t, v, _e) in enumerate(expected):
        assert run.t_impact[k] == pytest.approx(t, rel=1e-12), k
        assert run.v_impact[k] == pytest.approx(v, rel=1e-12), k
    for k, v in enumerate(run.v_impact):
        # C and Python implementations of the same model agree to a few ulps at these speeds (e about 0.5)
        assert run.e_applied[k] == pytest.approx(package_cor(v), rel=1e-13), k
        assert run.e_applied[k] == run.e_set[k]  # the ball applied exactly what the master set
    on_grid = sum(math.isclose(t / step, round(t / step), rel_tol=0, abs_tol=1e-9) for t in run.t_impact)
    assert run.early_returns == len(run.t_impact) - on_grid


def test_a_master_without_events_is_late_or_stale_where_this_one_is_not(pair, host_fmi3):
    """The reason for event mode, measured: the same drop through the FMI 3.0 ball without the flags (the
    wait contact mode, 10 ms steps) meets the plate a second time later than the ballistic flight, by
    up to a step (the first rebound waits for the next communication point); the event-mode run does
    not (the test above)."""
    expected = ballistic_contacts(H0, G, V_MIN, package_cor)
    with FmuInstance(host_fmi3["BouncingBall"], "plain", parameters={"h0": H0, "g": G, "v_min": V_MIN}) as plain:
        _ball, impact = pair
        rebound = fmu_rebound(impact)
        t, step, times = 0.0, 1e-2, []
        while len(times) < 2 and t < 2.0:
            plain.do_step(t, step)
            t += step
            (count, t_impact, v_approach) = plain.get("impacts", "t_impact", "v_approach")
            if count > len(times):
                times.append(t_impact)
            plain.set(e=rebound(v_approach)["e"] if v_approach > 0 else 1.0)
    late = times[1] - expected[1][0]
    assert 0.0 < late <= step
