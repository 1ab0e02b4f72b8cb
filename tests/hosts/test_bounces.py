"""Repeated bounces through SpherePlateImpact.fmu (fmpy; every implementation: pythonfmu, native FMI 2.0
and native FMI 3.0)
with the event-exact master (restitution.cosim.bounce), checked against the package and an
independent recursion.

For every material pair and thickness below (the paper's Tables 1, 3 and 4):
* every rebound the FMU gives equals the package's value for that approach speed, within each
  output's conditioning (restitution.agreement; the pythonfmu FMU runs the package itself);
* apex heights fall as e^2 (each apex = previous apex * e^2, the first = drop height * e^2);
* the ball's mechanical energy never rises, sampled along the whole trajectory;
* the number of impacts and every impact instant (hence the rest time) are finite and agree
  with a recursion written here from the package alone.
"""
from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

import restitution as r
from restitution.agreement import disagreements, tolerances
from restitution.cosim import FmiStatusError, FmuInstance, bounce, fmu_rebound, impact_fmu_parameters, package_rebound
from restitution.cosim.bouncing import STANDARD_GRAVITY

DROP = 0.3  # [m]
D = 6.35e-3  # [m] sphere diameter where a table gives none (Tables 3, 4)


def _case(sphere_mat, d, plate_mat, t):
    return r.Sphere(sphere_mat, d), r.Plate(plate_mat, t)


# Table 1 (Marinack et al.): sphere, diameter and plate as given; the plates are thick (10 d here).
TABLE1 = {f"T1-{k}": _case(r.MATERIALS[s], d, r.MATERIALS[p], 10.0 * d) for k, (s, d, p) in r.TABLE1_CASES.items()}
# Table 3 (Patil & Higgs): S2 tool steel on Al 6061 (the paper's checkpoint) at several thicknesses,
# and other Table 3 pairs.
TABLE3 = {f"T3-s2/al6061-t{t * 1e3:g}mm": _case(r.MATERIALS["s2_tool_steel"], D, r.MATERIALS["al_6061"], t)
          for t in (1.5875e-3, 3.175e-3, 6.35e-3, 12.7e-3)}
TABLE3.update({
    "T3-wc/al6061": _case(r.MATERIALS["tungsten_carbide"], D, r.MATERIALS["al_6061"], 3.175e-3),
    "T3-brass/lcsteel": _case(r.MATERIALS["brass_260"], D, r.MATERIALS["low_carbon_steel"], 6.35e-3),
    "T3-glass/al1100": _case(r.MATERIALS["borosilicate_glass"], D, r.MATERIALS["al_1100_h16"], 2.0 * D),
})
# Table 4 (thin plates; cases A: heavy stiff sphere on light soft plate, B the reverse).
TABLE4 = {f"T4-{c}-td{td:g}": _case(r.table4_case(c)[0], D, r.table4_case(c)[1], td * D)
          for c in r.TABLE4_CASES for td in (0.2, 1.0, 5.0)}
CASES = {**TABLE1, **TABLE3, **TABLE4}


def recursion(sphere, plate, drop_height=DROP, g=STANDARD_GRAVITY, v_min=0.1, max_impacts=100_000):
    """Independent bounce sequence from the package: (approach speeds, impact instants, stop reason).

    Impact k happens at speed v_k; v_{k+1} = e(v_k) v_k; flights between impacts last 2 v/g;
    the ball rests when e <= 0 or the rebound speed is below v_min.
    """
    params = {**sphere.params(), **plate.params()}
    v = math.sqrt(2.0 * g * drop_height)
    partials = []  # exact running sum of the flight times (Shewchuk's partials, as math.fsum)
    _exact_add(partials, math.sqrt(2.0 * drop_height / g))
    speeds, times = [], []
    for _ in range(max_impacts):
        speeds.append(v)
        times.append(math.fsum(partials))
        e = r.impact(v, **params).e
        if e <= 0.0:
            return speeds, times, "e<=0"
        if e * v < v_min:
            return speeds, times, "v_min"
        v = e * v
        _exact_add(partials, 2.0 * v / g)
    raise AssertionError("the recursion did not come to rest")


def _exact_add(partials, x):
    """Add x to the non-overlapping partials whose exact sum is the running total."""
    i = 0
    for y in partials:
        if abs(x) < abs(y):
            x, y = y, x
        hi = x + y
        lo = y - (hi - x)
        if lo:
            partials[i] = lo
            i += 1
        x = hi
    partials[i:] = [x]


@pytest.fixture(scope="module")
def fmu(any_version_impact_fmu):
    with FmuInstance(any_version_impact_fmu, "bounces") as instance:
        yield instance


def _impact(b, k):
    """Impact ``k`` of a bounce sequence, as an object with the result's field names."""
    return SimpleNamespace(**{f: getattr(b, f)[k] for f in ("e", "e_ep", "e_ze", "lam", "tau0", "t_contact",
                                                            "v_rebound")})


def _drop(fmu, sphere, plate, **kw):
    fmu.reset()
    fmu.set(**impact_fmu_parameters(sphere, plate))
    return bounce(fmu_rebound(fmu), drop_height=kw.pop("drop_height", DROP), **kw)


@pytest.mark.parametrize("name", list(CASES))
def test_bounces_through_the_fmu(fmu, name):
    sphere, plate = CASES[name]
    b = _drop(fmu, sphere, plate)
    params = {**sphere.params(), **plate.params()}

    # every rebound is the package's for that approach speed, within each output's conditioning
    # (array path; the first and last impacts also through the scalar path)
    ref = r.impact(b.v_approach, **params)
    tol, flips = tolerances(b.v_approach, params)
    assert not disagreements(b, ref, tol, flips), name
    for k in (0, b.n_impacts - 1):
        one = r.impact(float(b.v_approach[k]), **params)
        tol_k, flips_k = tolerances(float(b.v_approach[k]), params)
        assert not disagreements(_impact(b, k), one, tol_k, flips_k), (name, k)

    # apex heights fall as e^2
    e, apex = b.e, b.apex
    bouncing = e > 0.0
    assert apex[0] == pytest.approx(DROP * e[0] ** 2, rel=1e-12) or not bouncing[0]
    np.testing.assert_allclose(apex[1:][bouncing[1:]], (apex[:-1] * e[1:] ** 2)[bouncing[1:]], rtol=1e-12, atol=0)
    assert np.all(apex[~bouncing] == 0.0)

    # energy never rises: at the impacts, and along the trajectory
    assert np.all(b.v_rebound ** 2 <= b.v_approach ** 2)
    assert np.all(np.diff(np.concatenate([[DROP], apex])) <= 0.0)
    edges = np.concatenate([[0.0], b.time])
    t = np.unique(np.concatenate([np.linspace(0.0, b.rest_time * 1.01, 4001),
                                  edges[1:] * (1 - 1e-12), edges[1:] * (1 + 1e-12),
                                  0.5 * (edges[:-1] + edges[1:])]))
    energy = b.energy(t)
    assert energy[0] == pytest.approx(STANDARD_GRAVITY * DROP, rel=1e-15)
    assert np.all(np.diff(energy) <= 1e-9 * energy[0]), name
    assert np.all(b.height(b.time) <= 1e-9) and np.all(b.height(t) >= 0.0)

    # count, instants and rest time agree with the independent recursion: to 1e-12, plus what the
    # conditioning allows e at each impact to differ, which each later approach speed inherits
    speeds, times, reason = recursion(sphere, plate)
    assert b.n_impacts == len(speeds) and b.stop_reason == reason, name
    with np.errstate(divide="ignore", invalid="ignore"):
        drift = np.concatenate([[0.0], np.cumsum(np.where(b.e > 0, tol["e"] / np.abs(b.e), 0.0))[:-1]])
    rtol = 1e-12 + drift
    assert np.all(np.abs(b.v_approach - speeds) <= rtol * np.abs(speeds)), name
    assert np.all(np.abs(b.time - times) <= rtol * np.abs(times)), name
    assert math.isfinite(b.rest_time) and abs(b.rest_time - times[-1]) <= rtol[-1] * times[-1]
    if reason == "v_min":  # the stop rule fired at the first rebound below v_min, not before
        assert b.v_rebound[-1] < 0.1 and np.all(b.v_rebound[:-1] >= 0.1) and np.all(b.e > 0.0)
    else:
        assert b.e[-1] <= 0.0 and np.all(b.e[:-1] > 0.0)


def test_cases_cover_both_stop_rules_and_long_sequences(fmu):
    """The matrix above is not trivial: it has e <= 0 stops, long Zeno-like runs and many pairs."""
    reasons, counts = set(), []
    for name in ("T4-A1-td0.2", "T4-B3-td5", "T1-3", "T3-s2/al6061-t6.35mm"):
        speeds, _times, reason = recursion(*CASES[name])
        reasons.add(reason)
        counts.append(len(speeds))
    assert reasons == {"e<=0", "v_min"}
    assert counts[0] == 1 and counts[1] > 10_000 and counts[2] > 1_000


def test_python_fmu_and_package_masters_agree_bit_for_bit(impact_fmu):
    """The pythonfmu FMU runs the package's own code in this process: the same bits."""
    sphere, plate = CASES["T3-s2/al6061-t3.175mm"]
    with FmuInstance(impact_fmu, "bit for bit") as fmu:
        through_fmu = _drop(fmu, sphere, plate, drop_height=1.0, gravity=3.7, v_min=0.02)
        clock = fmu.time
    direct = bounce(package_rebound(**sphere.params(), **plate.params()), drop_height=1.0, gravity=3.7, v_min=0.02)
    assert through_fmu.n_impacts == direct.n_impacts > 5
    for field in ("time", "v_approach", "e", "e_ep", "e_ze", "lam", "tau0", "t_contact", "v_rebound", "apex"):
        assert np.array_equal(getattr(through_fmu, field), getattr(direct, field)), field
    # the FMU was stepped across every flight: its clock ends at the last impact
    assert clock == pytest.approx(direct.rest_time, rel=1e-12)


def test_fmi3_and_fmi2_native_fmus_bounce_alike(native_impact_fmu, fmi3_impact_fmu):
    """The FMI 3.0 FMU runs the FMI 2.0 native FMU's C core and physics behind another version layer that
    only copies doubles: through FmuInstance, the same drop gives the same impacts and clock. Not bit
    identity between two binaries: each impact's outputs agree within restitution.agreement's bound
    (~1e-13 relative on this case), and the drop carries each e into the next approach speed, so over
    its impacts a difference can grow by a factor of at most (1 + |d ln e / d ln v|) per impact (< 1.3
    here, where e varies slowly with v); 1e-9 covers that many times and still catches a layer that
    changes a value (a float32 conversion: ~1e-7; a wrong variable: O(1))."""
    sphere, plate = CASES["T3-s2/al6061-t3.175mm"]
    drops, clocks = [], []
    for path in (native_impact_fmu, fmi3_impact_fmu):
        with FmuInstance(path, "bit for bit") as fmu:
            drops.append(_drop(fmu, sphere, plate, drop_height=1.0, gravity=3.7, v_min=0.02))
            clocks.append(fmu.time)
    two, three = drops
    assert two.n_impacts == three.n_impacts > 5 and clocks[0] == pytest.approx(clocks[1], rel=1e-9)
    for field in ("time", "v_approach", "e", "e_ep", "e_ze", "lam", "tau0", "t_contact", "v_rebound", "apex"):
        np.testing.assert_allclose(getattr(three, field), getattr(two, field), rtol=1e-9, atol=0, err_msg=field)


def test_stop_rule_ends_a_zeno_like_sequence():
    """e -> 1 as v -> 0, so only v_min ends the drop; the rest time converges as v_min -> 0."""
    sphere, plate = CASES["T3-s2/al6061-t6.35mm"]
    rebound = package_rebound(**sphere.params(), **plate.params())
    runs = [bounce(rebound, DROP, v_min=v_min) for v_min in (1e-1, 1e-3, 1e-5, 1e-7)]
    n = [b.n_impacts for b in runs]
    assert n == sorted(n) and len(set(n)) == 4 and all(b.stop_reason == "v_min" for b in runs)
    assert runs[1].why_stopped == "the rebound speed fell below v_min = 0.001 m/s"
    assert runs[3].e[-1] > runs[2].e[-1] > runs[0].e[-1] > runs[0].e[0]  # e rises as the ball slows
    # each extra factor 100 in v_min adds more impacts but less and less time: Zeno-like
    rest = np.array([b.rest_time for b in runs])
    gained = np.diff(rest)
    assert np.all(gained > 0.0) and gained[1] < 0.1 * gained[0] and gained[2] < 0.1 * gained[1]


def test_perfectly_elastic_ball_hits_the_guard_and_keeps_its_energy():
    """Both effects off: e = 1 exactly; the ball never rests and max_bounces stops it."""
    sphere, plate = CASES["T3-s2/al6061-t6.35mm"]
    rebound = package_rebound(**sphere.params(), **plate.params(), plasticity="off", plate_waves="off")
    b = bounce(rebound, DROP, max_bounces=500)
    assert b.stop_reason == "max_bounces" and b.n_impacts == 500
    assert b.why_stopped == "500 impacts, the most asked for (max_bounces)"
    assert np.all(b.e == 1.0)
    np.testing.assert_allclose(b.apex, DROP, rtol=1e-14)
    period = 2.0 * math.sqrt(2.0 * DROP / STANDARD_GRAVITY)
    assert b.time[-1] == pytest.approx(period * 499.5, rel=1e-14)  # compensated sum: no drift


def test_invalid_model_output_stops_the_master_clearly(fmu):
    with pytest.raises(ValueError, match=r"v_approach = .* gave e = nan"):
        bounce(lambda v: {"e": math.nan, "e_ep": 1.0, "e_ze": 1.0, "lam": 0.0, "tau0": 3.2, "t_contact": 0.0,
                          "v_rebound": math.nan}, DROP)
    fmu.reset()
    with pytest.raises(FmiStatusError, match=r"plate.t = -1.0 is outside the allowed range"):
        fmu.set(**{"plate.t": -1.0})  # refused with Error: the previous value stays
    defaults = {**r.Sphere(r.MATERIALS["s2_tool_steel"], 6.35e-3).params(),
                **r.Plate(r.MATERIALS["al_6061"], 6.35e-3).params()}
    assert bounce(fmu_rebound(fmu), DROP).n_impacts == bounce(package_rebound(**defaults), DROP).n_impacts
    fmu.reset()


@pytest.mark.parametrize("bad", [dict(drop_height=0.0), dict(drop_height=math.inf), dict(drop_height=1.0, gravity=-9.8),
                                 dict(drop_height=1.0, v_min=math.nan)])
def test_master_rejects_bad_arguments(bad):
    with pytest.raises(ValueError, match="allowed range"):
        bounce(lambda v: {}, **bad)
