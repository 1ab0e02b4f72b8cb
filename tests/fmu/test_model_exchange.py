"""Model exchange of the native FMUs, FMI 2.0 (``fmi2/``) and FMI 3.0 (``fmi3/``): one archive offers
co-simulation and model exchange from the same binary. BouncingBall has the continuous states h and v,
one event indicator, and a contact is a state event that the host's solver locates; SpherePlateImpact
has no states and its outputs are a function of its inputs."""
from __future__ import annotations

import ctypes
import json
import math

import numpy as np
import pytest
from fmpy import extract, read_model_description, simulate_fmu

from fmi_child import run_child
from independent import INDICATOR_EXTREME, INDICATOR_IN_FLIGHT, assert_indicator
from script_host import free_fall_contacts

H0, G = 0.3, 9.80665
E, V_MIN = 0.8, 0.5
#: fmpy's CVode tolerance for these runs: an event time is located to about this relative accuracy
RTOL = 1e-8


@pytest.fixture(params=["fmi2", "fmi3"])
def me_ball(request, native_ball_fmu, fmi3_ball_fmu):
    return native_ball_fmu if request.param == "fmi2" else fmi3_ball_fmu


@pytest.fixture(params=["fmi2", "fmi3"])
def me_impact(request, native_impact_fmu, fmi3_impact_fmu):
    return native_impact_fmu if request.param == "fmi2" else fmi3_impact_fmu


def analytic_contacts(h0=H0, g=G, e=E, v_min=V_MIN):
    """Times [s] and approach speeds [m/s] of the contacts, in closed form (script_host.free_fall_contacts)."""
    return tuple(np.array(x) for x in free_fall_contacts(h0, g, e, v_min))


def test_both_interfaces_are_declared_in_one_archive(me_ball, me_impact):
    for fmu in (me_ball, me_impact):
        md = read_model_description(str(fmu))
        assert md.modelExchange is not None and md.coSimulation is not None
        assert md.modelExchange.modelIdentifier == md.coSimulation.modelIdentifier
    md = read_model_description(str(me_ball))
    states = [v.derivative.name for v in md.modelVariables if v.derivative is not None]
    assert states == ["h", "v"] and md.numberOfEventIndicators == 1


def test_the_ball_meets_the_plate_at_the_analytic_times_and_comes_to_rest(me_ball):
    """With e = 0.8 and v_min = 0.5 m/s the contacts fall at the closed-form times within the solver's
    tolerance (1e-6 s at RTOL = 1e-8 over 2 s: each located time carries the error of the flights
    before it); the ball comes to rest at the contact whose rebound would be slower than v_min, as
    an event, and stays on the plate to the end of a run 5x longer (no Zeno chatter: the count of
    contacts is exact)."""
    times, speeds = analytic_contacts()
    result = simulate_fmu(str(me_ball), fmi_type="ModelExchange", stop_time=5 * times[-1], output_interval=1e-3,
                          relative_tolerance=RTOL, start_values={"e": E, "v_min": V_MIN, "h0": H0},
                          output=["h", "v", "impacts", "t_impact", "v_impact", "at_rest"])
    assert result["impacts"][-1] == len(times)
    located = [result["t_impact"][np.argmax(result["impacts"] == k)] for k in range(1, len(times) + 1)]
    speeds_found = [result["v_impact"][np.argmax(result["impacts"] == k)] for k in range(1, len(times) + 1)]
    np.testing.assert_allclose(located, times, rtol=0, atol=1e-6)
    np.testing.assert_allclose(speeds_found, speeds, rtol=1e-5)
    rest = result[result["time"] > times[-1] + 1e-3]
    assert rest["at_rest"].all() and (rest["h"] == 0.0).all() and (rest["v"] == 0.0).all()
    assert (result["h"] >= -1e-6).all()  # the solver never lets the ball through the plate by more than it locates


def test_impact_outputs_follow_the_inputs_as_in_co_simulation(me_impact):
    """SpherePlateImpact has no states: run as model exchange with a speed held on its input, its
    outputs equal the co-simulation run of the same binary at the same speed (the same C evaluation)."""
    for v in (0.05, 2.3, 40.0):
        outputs = ["e", "jgm.e", "zener.e", "zener.lambda", "zener.t_contact"]
        me = simulate_fmu(str(me_impact), fmi_type="ModelExchange", stop_time=0.01, output_interval=0.005,
                          start_values={"v_approach": v}, output=outputs)
        cs = simulate_fmu(str(me_impact), fmi_type="CoSimulation", stop_time=0.01, output_interval=0.005,
                          start_values={"v_approach": v}, output=outputs)
        for name in outputs:
            assert me[name][-1] == pytest.approx(cs[name][-1], rel=1e-15, abs=0), (v, name)


HOSTILE_ME = r'''
from fmpy.fmi2 import FMU2Model, fmi2EventInfo
s = FMU2Model(guid=MD.guid, unzipDirectory=UNZIP, modelIdentifier=MD.modelExchange.modelIdentifier,
              instanceName="me")
s.instantiate(callbacks=CALLBACKS, loggingOn=True)
got = {}


def raw(fmu, name, *args):
    """The status of an FMI function the fmpy class does not wrap for this interface."""
    function = getattr(fmu.dll, name)
    function.restype = c_int
    return function(c_void_p(fmu.component), *args)


s.setupExperiment(startTime=0.0)
s.enterInitializationMode()
s.exitInitializationMode()
got["do_step_in_me"] = raw(s, "fmi2DoStep", c_double(0.0), c_double(1e-3), c_int(1))
info = fmi2EventInfo()
got["new_discrete_states"] = status(s.fmi2NewDiscreteStates, s.component, ctypes.byref(info))
s.enterContinuousTimeMode()
got["new_discrete_states_in_continuous"] = status(s.fmi2NewDiscreteStates, s.component, ctypes.byref(info))
x = (c_double * 2)(0.3, 0.0)
got["get_states"] = status(s.fmi2GetContinuousStates, s.component, x, 2)
got["states"] = list(x)
bad = (c_double * 2)(float("nan"), 1.0)
got["nan_state"] = status(s.fmi2SetContinuousStates, s.component, bad, 2)
got["wrong_count"] = status(s.fmi2GetDerivatives, s.component, x, 3)
got["null_array"] = status(s.fmi2GetEventIndicators, s.component, None, 1)
got["nan_time"] = status(s.fmi2SetTime, s.component, float("nan"))
s.fmi2GetContinuousStates(s.component, x, 2)
got["kept_states"] = list(x)
dx = (c_double * 2)()
s.fmi2GetDerivatives(s.component, dx, 2)
got["derivatives"] = list(dx)
z = (c_double * 1)()
s.fmi2GetEventIndicators(s.component, z, 1)
got["indicator"] = list(z)
got["null_out"] = status(s.fmi2CompletedIntegratorStep, s.component, 1, None, None)
state = s.getFMUstate()
data = s.serializeFMUstate(state)
got["round_trip"] = status(s.deSerializeFMUstate, data)
s.terminate()
s.freeInstance()
cs = FMU2Slave(guid=MD.guid, unzipDirectory=UNZIP, modelIdentifier=MD.coSimulation.modelIdentifier, instanceName="cs")
cs.instantiate(callbacks=CALLBACKS, loggingOn=True)
cs.setupExperiment(startTime=0.0)
cs.enterInitializationMode()
got["me_call_on_cs"] = raw(cs, "fmi2GetContinuousStates", x, c_size_t(2))
got["me_state_into_cs"] = status(cs.deSerializeFMUstate, data)
cs.freeInstance()
got["fatal_logged"] = any(st == 4 for _n, st, _m in LOG)
got["messages"] = [m for _n, _st, m in LOG]
report(**got)
'''


def test_hostile_model_exchange_calls_are_refused_and_keep_the_states(native_ball_fmu, tmp_path):
    """(FMI 2.0, in a child process.) Calls of the wrong interface or mode, wrong vector sizes, NULL arrays,
    a NaN state or time: fmi2Error with a message, the states kept; an FMU state of the model-exchange
    instance round-trips, and a co-simulation instance refuses it. Nothing is ever fatal."""
    unzip = extract(str(native_ball_fmu), str(tmp_path / "unzip"))
    child = run_child(HOSTILE_ME, native_ball_fmu, unzip)
    assert child.returncode == 0 and child.report is not None, child.explain()
    got = child.report
    for key in ("do_step_in_me", "new_discrete_states_in_continuous", "nan_state", "wrong_count", "null_array",
                "nan_time", "null_out", "me_call_on_cs", "me_state_into_cs"):
        assert got[key] == 3, f"{key}: status {got[key]}"
    assert got["new_discrete_states"] == 0 and got["get_states"] == 0 and got["round_trip"] == 0
    assert got["states"] == [H0, 0.0] and got["kept_states"] == [H0, 0.0]
    assert got["derivatives"] == [0.0, -G] and got["indicator"] == [H0]
    assert not got["fatal_logged"]
    text = "\n".join(got["messages"])
    for needed in ("fmi2DoStep is not allowed in event mode (FMI 2.0 model-exchange state machine)",
                   "h = nan must be finite; nothing was changed", "3 state derivatives asked for; BouncingBall has 2",
                   "this instance is a co-simulation instance (model exchange only)",
                   "the state was taken from a model-exchange instance; this one is co-simulation"):
        assert needed in text, needed


def test_derivatives_and_indicator_follow_a_restored_fmu_state(me_ball):
    """Repro: the derivatives and the event indicator after an FMU state is restored must be those of the
    restored states (a solver that restores a state and asks for the derivatives integrates from there)."""
    from fmpy.fmi2 import FMU2Model
    from fmpy.fmi3 import FMU3Model

    md = read_model_description(str(me_ball))
    unzip = extract(str(me_ball))
    if md.fmiVersion == "2.0":
        fmu = FMU2Model(guid=md.guid, unzipDirectory=unzip, modelIdentifier="BouncingBall", instanceName="me")
        fmu.instantiate()
        fmu.setupExperiment(startTime=0.0)
    else:
        fmu = FMU3Model(guid=md.guid, unzipDirectory=unzip, modelIdentifier="BouncingBall", instanceName="me")
        fmu.instantiate()
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    fmu.updateDiscreteStates() if md.fmiVersion == "3.0" else fmu.newDiscreteStates()
    fmu.enterContinuousTimeMode()
    v2 = md.fmiVersion == "2.0"

    def vector(*values):
        return (ctypes.c_double * len(values))(*values)

    fmu.setTime(0.1)
    fmu.setContinuousStates(vector(0.25, -1.0), 2)
    state = fmu.getFMUstate() if v2 else fmu.getFMUState()
    fmu.setTime(0.2)
    fmu.setContinuousStates(vector(0.1, 0.5), 2)
    fmu.setFMUstate(state) if v2 else fmu.setFMUState(state)
    x, dx, z = vector(0, 0), vector(0, 0), vector(0)
    fmu.getContinuousStates(x, 2)
    (fmu.getDerivatives if v2 else fmu.getContinuousStateDerivatives)(dx, 2)
    fmu.getEventIndicators(z, 1)
    fmu.terminate()
    fmu.freeInstance()
    assert list(x) == [0.25, -1.0]
    assert list(dx) == [-1.0, -G] and list(z) == [0.25], (list(dx), list(z))


# --- the event indicator by value: h + max(v, 0)^2/(2 g) in flight, 1 m at rest (docs/host_contract.md),
# --- against its closed form in exact rational arithmetic (tests/independent.py: apex_height_exact, with
# --- the error bound of its evaluation in doubles, assert_indicator), the host setting h and v

#: A gravity that is neither 1 nor a power of 2 (a factor 2 lost or doubled in 2 g shows at once).
G_INDICATOR = 3.7

#: The child: a model-exchange instance per (g, h0) of ARGS[0]; for each, the host sets every (h, v) in
#: continuous-time mode and reads the indicator, derivatives, nominals and v_approach with their statuses.
#: ARGS[1]: e, and (h, v) of a contact event (enterEventMode, one event update) at the end.
ME_CHILD = r'''
from fmpy.fmi2 import FMU2Model
from fmpy.fmi3 import FMU3Model

groups, (e, contact) = json.loads(ARGS[0]), json.loads(ARGS[1])
three = MD.fmiVersion.startswith("3")
out = []


def vector(*values):
    return (c_double * len(values))(*values)


def event_iteration(fmu):
    while (fmu.updateDiscreteStates() if three else fmu.newDiscreteStates())[0]:
        pass


def read(fmu):
    z, dx, nominal = vector(0.0), vector(0.0, 0.0), vector(0.0, 0.0)
    got = {"z_status": status(fmu.getEventIndicators, z, 1),
           "dx_status": status(fmu.getContinuousStateDerivatives if three else fmu.getDerivatives, dx, 2),
           "nominal_status": status(fmu.getNominalsOfContinuousStates, nominal, 2)}
    got.update(z=z[0], dx=list(dx), nominal=list(nominal),
               v_approach=(fmu.getFloat64 if three else fmu.getReal)([VR["v_approach"]])[0])
    return got


for g, h0, states in groups:
    cls = FMU3Model if three else FMU2Model
    fmu = cls(guid=MD.instantiationToken if three else MD.guid, unzipDirectory=UNZIP,
              modelIdentifier=MD.modelExchange.modelIdentifier, instanceName="indicator")
    fmu.instantiate()
    if three:
        fmu.enterInitializationMode(startTime=0.0)
    else:
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
    (fmu.setFloat64 if three else fmu.setReal)([VR["g"], VR["h0"], VR["e"]], [g, h0, e])
    fmu.exitInitializationMode()
    event_iteration(fmu)
    fmu.enterContinuousTimeMode()
    group = {"initial": read(fmu), "states": []}
    fmu.setTime(0.1)
    for h, v in states:
        got = {"set_status": status(fmu.setContinuousStates, vector(h, v), 2)}
        got.update(read(fmu))
        group["states"].append(got)
    if h0 > 0.0:  # a contact: the host puts the ball at the plate, falling, and hands over the event
        fmu.setContinuousStates(vector(*contact), 2)
        fmu.enterEventMode()
        event_iteration(fmu)
        fmu.enterContinuousTimeMode()
        x = vector(0.0, 0.0)
        fmu.getContinuousStates(x, 2)
        group["after_contact"] = dict(read(fmu), x=list(x))
    out.append(group)
    fmu.terminate()
    fmu.freeInstance()
report(groups=out)
'''


def run_model_exchange(fmu, tmp_path, groups, e=0.5, contact=(-1e-9, -2.0)):
    unzip = extract(str(fmu), str(tmp_path / "unzip"))
    child = run_child(ME_CHILD, fmu, unzip, json.dumps(groups), json.dumps([e, contact]))
    assert child.returncode == 0 and child.report is not None, child.explain()
    return child.report["groups"]


def test_the_native_indicator_is_the_apex_height_in_flight_and_1_m_at_rest(me_ball, tmp_path):
    """In flight the indicator is h + max(v, 0)^2/(2 g) (rising: the apex; falling or at the apex: h),
    for two gravities; right after exitInitializationMode it is h0 (released from rest); after a contact
    with e = 0.5 at 2 m/s the ball is at the plate rising at 1 m/s: (0.5 * 2)^2/(2 g); released on the
    plate (h0 = 0) the ball is at rest and the indicator is 1 m, whatever state the host sets."""
    states = [list(s) for s in INDICATOR_IN_FLIGHT]
    groups = run_model_exchange(me_ball, tmp_path, [[G_INDICATOR, 0.4, states], [G, 0.3, states],
                                                    [G_INDICATOR, 0.0, states]])
    for (g, h0), group in zip(((G_INDICATOR, 0.4), (G, 0.3)), groups):
        assert_indicator(group["initial"]["z"], h0, 0.0, g)
        for (h, v), got in zip(INDICATOR_IN_FLIGHT, group["states"]):
            assert got["set_status"] == 0 and got["z_status"] == 0, got
            assert_indicator(got["z"], h, v, g)
        after = group["after_contact"]
        assert after["x"] == [0.0, 1.0]  # h = 0, v = e |v| = 0.5 * 2 exactly
        assert_indicator(after["z"], 0.0, 1.0, g)
    at_rest = groups[2]
    assert at_rest["initial"]["z"] == 1.0  # the documented value at rest: no more contacts
    for got in at_rest["states"]:
        assert got["set_status"] == 0 and got["z"] == 1.0 and got["dx"] == [0.0, 0.0], got


def test_the_native_indicator_stays_finite_for_any_finite_state(me_ball, tmp_path):
    """Repro: (h, v) = (1e308, DBL_MAX) set by the host gave an indicator of +inf with status OK. Every
    finite state gives a finite indicator with status OK: the closed form where it is a double, DBL_MAX
    where it is above, within 4 eps of |h| + max(v, 0)^2/(2 g) (the rescaled form
    v' = v / sqrt(2 g) adds a square root and a rounding to the 3 of the closed form); -1e308 with a term of 1e302 stays
    negative (below the plate). The derivatives, nominals and v_approach are finite there too."""
    groups = {}
    for g, h, v in INDICATOR_EXTREME:
        groups.setdefault(g, []).append([h, v])
    found = run_model_exchange(me_ball, tmp_path, [[g, 0.3, states] for g, states in groups.items()])
    for (g, states), group in zip(groups.items(), found):
        for (h, v), got in zip(states, group["states"]):
            for key in ("set_status", "z_status", "dx_status", "nominal_status"):
                assert got[key] == 0, (h, v, g, key, got)
            assert_indicator(got["z"], h, v, g, ulps=4)
            assert all(math.isfinite(x) for x in (*got["dx"], *got["nominal"], got["v_approach"])), (h, v, got)
    below = found[list(groups).index(1e6)]["states"][1]  # (-1e308, 2e154) under g = 1e6
    assert below["z"] < -0.99e308
