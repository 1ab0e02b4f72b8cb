"""FMI 3.0 co-simulation with event mode and early return (restitution.cosim.event_mode): the native
BouncingBall.fmu returns from fmi3DoStep at each contact, the master sets the COR SpherePlateImpact.fmu
gives for that contact's speed in event mode, and the ball rebounds there. Checked against a ballistic
flight computed here, with the package's own impact model (restitution.impact) for the COR."""
from __future__ import annotations

import io
import math
import os
import subprocess
import sys
from pathlib import Path

import pytest
from fmpy import read_model_description

import restitution as r
from cases import params_for
from fmi_child import run_child
from restitution.cosim import FmuInstance
from restitution.cosim.bouncing import fmu_rebound
from restitution.cosim.event_mode import EventModeInstance, event_mode_bounce
from restitution.fmu.models.sphere_plate_impact.variables import fmu_values

G = 9.80665  # [m/s2]
H0 = 0.3  # [m]
V_MIN = 0.1  # [m/s]
PAIR = ("s2/al6061", 1.0)  # the paper's Table 3 materials, plate as thick as the ball


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


def test_a_master_without_events_meets_the_plate_late(pair, host_fmi3):
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


def test_early_return_without_event_mode_follows_the_contact_mode(pair, host_fmi3):
    """earlyReturnAllowed without eventModeUsed: every step ends at the contact inside it (earlyReturn,
    no eventHandlingNeeded: the FMU handles the contact itself, as contact_mode says). wait: the ball waits
    at the plate, so the COR the master sets at that communication point, for that contact's speed, is
    the one it rebounds with at the start of the next step: the ballistic times and zero lag, without
    event mode. immediate: it rebounds at once with the COR set at the previous point, the previous
    contact's (the first contact with e's start value, 1)."""
    _ball, impact = pair
    rebound = fmu_rebound(impact)
    expected = ballistic_contacts(H0, G, V_MIN, package_cor)
    for mode in ("wait", "immediate"):
        with EventModeInstance(host_fmi3["BouncingBall"], mode, event_mode=False, early_return=True,
                               parameters={"h0": H0, "g": G, "v_min": V_MIN, "contact_mode": mode}) as ball:
            contacts, applied, step, k, last_rebound = [], [], 1e-2, 1, -1.0
            while ball.time < 3.0 and not ball.get("at_rest")[0]:
                end = ball.step(ball.time, k * step - ball.time)
                assert not end.event_pending
                k += not end.early_return
                count, t_impact, v_impact, t_rebound, e_applied = ball.get(
                    "impacts", "t_impact", "v_impact", "t_rebound", "e_applied")
                if count > len(contacts):
                    assert end.early_return and t_impact == end.reached  # no contact falls on the 10 ms grid
                    contacts.append((t_impact, v_impact))
                if t_rebound > last_rebound:
                    applied.append(e_applied)
                    last_rebound = t_rebound
                if contacts:
                    ball.set(e=rebound(contacts[-1][1])["e"])  # the COR for the last contact's speed
        assert len(applied) == len(contacts)
        if mode == "wait":
            assert len(contacts) == len(expected)
            for (t, v), e, (t_ref, v_ref, _e_ref) in zip(contacts, applied, expected):
                assert t == pytest.approx(t_ref, rel=1e-12) and v == pytest.approx(v_ref, rel=1e-12)
                assert e == pytest.approx(package_cor(v), rel=1e-13)  # its own speed's
        else:
            assert contacts[0][1] == pytest.approx(expected[0][1], rel=1e-12) and applied[0] == 1.0
            for (_t, v_previous), e in zip(contacts, applied[1:]):
                assert e == pytest.approx(package_cor(v_previous), rel=1e-13)  # the previous contact's


HOSTILE = r'''
from fmpy.fmi3 import FMU3Slave, fmi3LogMessageCallback

def slave3(name, event_mode, early_return):
    s = FMU3Slave(guid=MD.instantiationToken, unzipDirectory=UNZIP, modelIdentifier=MD.coSimulation.modelIdentifier,
                  instanceName=name)
    s.instantiate(loggingOn=True, logMessage=log3, eventModeUsed=event_mode, earlyReturnAllowed=early_return)
    s.enterInitializationMode(startTime=0.0)
    s.exitInitializationMode()
    return s

def raw(s, name, *args):
    function = getattr(s.dll, name)
    function.restype = c_int
    return function(c_void_p(s.component), *args)

TIME = len(MD.modelVariables) - 1
got = {}
plain = slave3("plain", False, False)  # no event mode asked for: step mode after initialization
got["plain_update_discrete_states"] = status(plain.updateDiscreteStates)
got["plain_enter_event_mode"] = status(plain.enterEventMode)
got["plain_enter_step_mode"] = status(plain.enterStepMode)
got["plain_step"] = list(plain.doStep(0.0, 1.0))  # the contact at 0.247 s inside: a whole step, as always

s = slave3("events", True, True)  # initialization ends in event mode
got["step_in_event_mode"] = status(s.doStep, 0.0, 0.1)
got["continuous_time_mode"] = raw(s, "fmi3EnterContinuousTimeMode")
got["set_time"] = raw(s, "fmi3SetTime", c_double(1.0))
got["set_fixed_parameter"] = status(s.setFloat64, [VR["h0"]], [1.0])
got["update_null"] = raw(s, "fmi3UpdateDiscreteStates", None, None, None, None, None, None)
got["initial_update"] = list(s.updateDiscreteStates())
got["enter_step_mode"] = status(s.enterStepMode)
got["update_in_step_mode"] = status(s.updateDiscreteStates)
got["enter_step_mode_again"] = status(s.enterStepMode)
got["step_null"] = raw(s, "fmi3DoStep", c_double(0.0), c_double(1.0), ctypes.c_bool(True), None, None, None, None)
got["first_step"] = list(s.doStep(0.0, 1.0))
got["skipping_the_event"] = status(s.doStep, 1.0, 0.1)
got["time_at_event"] = list(s.getFloat64([TIME]))[0]
s.enterEventMode()
got["v_approach"] = list(s.getFloat64([VR["v_approach"]]))[0]
s.setFloat64([VR["e"]], [0.5])
in_event = s.getFMUState()
blob = s.serializeFMUState(in_event)
got["update"] = list(s.updateDiscreteStates())
got["after_update"] = list(s.getFloat64([VR["v"], VR["v_rebound"], VR["e_applied"], VR["t_rebound"]]))
got["event_state_into_plain"] = status(plain.deserializeFMUState, blob)
got["restore_event_state"] = status(s.setFMUState, in_event)
got["update_after_restore"] = status(s.updateDiscreteStates)
s.enterStepMode()
got["second_step"] = list(s.doStep(got["time_at_event"], 1.0))
for instance in (plain, s):
    instance.terminate()
    instance.freeInstance()
report_with_log3(**got)
'''


def test_hostile_call_sequences_are_refused_with_an_error(host_fmi3, tmp_path):
    """Event-mode calls out of sequence (run in a child process: a crash fails this test only) return
    fmi3Error (3), never fmi3Fatal, and leave the instance usable: fmi3UpdateDiscreteStates or
    fmi3EnterStepMode outside event mode, event mode without eventModeUsed, fmi3DoStep in event mode or
    skipping the event it returned early at, model-exchange calls on a co-simulation instance, NULL
    out-arguments, a state taken in event mode restored into an instance without event mode. The legal
    sequence in between runs as the module doc says: the first step ends at the free-fall time with
    the event pending, the event update rebounds at e = 0.5 from the contact speed sqrt(2 g h0)."""
    from fmpy import extract

    unzip = extract(str(host_fmi3["BouncingBall"]), str(tmp_path / "unzip"))
    child = run_child(HOSTILE, host_fmi3["BouncingBall"], unzip)
    assert child.returncode == 0 and child.report is not None, child.explain()
    got = child.report
    for key in ("plain_update_discrete_states", "plain_enter_event_mode", "plain_enter_step_mode",
                "step_in_event_mode", "continuous_time_mode", "set_time", "set_fixed_parameter", "update_null",
                "update_in_step_mode", "enter_step_mode_again", "step_null", "skipping_the_event",
                "event_state_into_plain"):
        assert got[key] == 3, f"{key}: status {got[key]}"
    for key in ("enter_step_mode", "restore_event_state", "update_after_restore"):
        assert got[key] == 0, f"{key}: status {got[key]}"
    t_fall, v_fall = math.sqrt(2 * H0 / G), math.sqrt(2 * G * H0)  # the FMU's defaults: h0 = 0.3 m, g = G
    assert got["plain_step"] == [False, False, False, 1.0]  # eventHandlingNeeded, terminate, early, reached
    assert got["initial_update"][:2] == [False, False]  # nothing pending at the start, no termination
    event, terminate, early, reached = got["first_step"]
    assert (event, terminate, early) == (True, False, True) and reached == pytest.approx(t_fall, rel=1e-15)
    assert got["time_at_event"] == reached and got["v_approach"] == pytest.approx(v_fall, rel=1e-15)
    assert got["update"][:2] == [False, False]
    v, v_rebound, e_applied, t_rebound = got["after_update"]
    assert (v, v_rebound, e_applied, t_rebound) == (0.5 * got["v_approach"], 0.5 * got["v_approach"], 0.5, reached)
    # after the rebound the next contact is 2 v_rebound / g later, inside the step from the event
    event, terminate, early, second = got["second_step"]
    assert (event, early) == (True, True) and second == pytest.approx(reached + 2 * v_rebound / G, rel=1e-14)
    assert 4 not in got["statuses_logged"]
    text = "\n".join(got["messages"])
    for needed in ("fmi3UpdateDiscreteStates is not allowed in step mode", "eventModeUsed = false; it has no event mode",
                   "fmi3EnterStepMode is not allowed in step mode", "fmi3DoStep is not allowed in event mode",
                   "fmi3EnterContinuousTimeMode: this instance is a co-simulation instance",
                   "fmi3SetTime: this instance is a co-simulation instance", "must not be NULL",
                   "does not continue the previous step",
                   "mode word 0x80 is not one mode of the co-simulation state machine"):
        assert needed in text, needed


#: The last commit before event mode and early return: with both flags off, BouncingBall must step as it did.
BEFORE_EVENTS = "f46177d"
ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def before_events(tmp_path_factory) -> dict:
    """BouncingBall.fmu (FMI 2.0 and FMI 3.0, this platform) built from the sources of BEFORE_EVENTS, by that
    commit's own build code in a child interpreter; skips where the history is not there (an archive)."""
    import shutil
    import tarfile

    out = tmp_path_factory.mktemp("before_events")
    if shutil.which("git") is None:
        pytest.skip("git not found: the build before event mode cannot be made")
    archive = subprocess.run(["git", "-C", str(ROOT), "archive", BEFORE_EVENTS, "fmu_src"], capture_output=True)
    if archive.returncode != 0:
        pytest.skip(f"commit {BEFORE_EVENTS} not in this checkout's history: {archive.stderr.decode()[:200]}")
    with tarfile.open(fileobj=io.BytesIO(archive.stdout)) as tar:
        tar.extractall(out / "src", filter="data")
    script = ("import sys; from pathlib import Path; from fmpy import platform, platform_tuple\n"
              "from restitution.fmu.build.native import build_native_one\n"
              "for version, folder in (('2.0', platform), ('3.0', platform_tuple)):\n"
              "    print(build_native_one('BouncingBall', Path(sys.argv[1]), fmi_version=version, folders=(folder,),"
              " log=lambda _l: None))\n")
    env = {**os.environ, "PYTHONPATH": str(out / "src" / "fmu_src")}
    built = subprocess.run([sys.executable, "-c", script, str(out / "fmus")], capture_output=True, text=True, env=env,
                           timeout=300)
    assert built.returncode == 0, built.stderr[-2000:]
    return {"2.0": out / "fmus" / "fmi2" / "BouncingBall.fmu", "3.0": out / "fmus" / "fmi3" / "BouncingBall.fmu"}


def _ball_run(fmu: Path, contact_mode: str, step: float) -> list[list]:
    """Every output and local of the ball at every communication point of a drop (plain FmuInstance: FMI
    2.0, or FMI 3.0 with eventModeUsed = earlyReturnAllowed = false), e set at each point from v_approach
    by a fixed smooth law, so that every contact sees a COR that changes with its speed."""
    names = [v.name for v in read_model_description(str(fmu)).modelVariables
             if v.causality in ("output", "local") and v.type in ("Float64", "Real")]
    rows = []
    code = {"wait": 1, "immediate": 2}[contact_mode]  # an Integer in FMI 2.0, an Enumeration in FMI 3.0
    with FmuInstance(fmu, "ball", parameters={"h0": H0, "contact_mode": code, "v_min": 0.05}) as ball:
        t = 0.0
        for _k in range(int(round(2.5 / step))):
            ball.do_step(t, step)
            t += step
            row = ball.get(*names)
            rows.append(row)
            (v_approach,) = ball.get("v_approach")
            ball.set(e=0.9 - 0.1 * math.tanh(v_approach))
    return rows


@pytest.mark.parametrize("version", ["2.0", "3.0"])
def test_with_both_flags_off_the_ball_steps_bit_for_bit_as_before(host_fmi3, before_events, version,
                                                                  tmp_path_factory):
    """With eventModeUsed and earlyReturnAllowed false (and for FMI 2.0, which has neither) the ball runs
    the step it ran before event mode existed: built from BEFORE_EVENTS and from the current sources,
    the same drop in both contact modes at 1 ms and 10 ms steps gives every output at every
    communication point identical to the bit (same code path, same compiler, same machine)."""
    before = before_events[version]
    if version == "3.0":
        now = host_fmi3["BouncingBall"]
    else:
        from fmpy import platform

        from restitution.fmu.builders.native import build_native_one

        now = build_native_one("BouncingBall", tmp_path_factory.mktemp("now"), fmi_version="2.0",
                               folders=(platform,), log=lambda _l: None)
    for contact_mode in ("wait", "immediate"):
        for step in (1e-3, 1e-2):
            old, new = _ball_run(before, contact_mode, step), _ball_run(now, contact_mode, step)
            assert new == old, (contact_mode, step)  # lists of floats: == is bit identity (no NaN outputs)


def _fmusim() -> str:
    """The Reference FMUs' fmusim: $RESTITUTION_FMUSIM, else `fmusim` on PATH; skips naming the tool."""
    import shutil

    found = os.environ.get("RESTITUTION_FMUSIM") or shutil.which("fmusim")
    if not found or not os.access(found, os.X_OK):
        pytest.skip("fmusim (the Modelica Reference FMUs' simulator, built from their public sources) not found: "
                    "put it on PATH or name it in RESTITUTION_FMUSIM")
    return found


def test_fmusim_runs_the_ball_with_early_return_and_event_mode(host_fmi3, tmp_path):
    """fmusim, an independent strict FMI 3.0 host, runs BouncingBall with --early-return-allowed and
    --event-mode-used (its e a constant 0.8, no impact FMU: fmusim runs one FMU): it records a row at each
    contact instant, where t_impact is that instant, and every contact is at the ballistic time for
    e = 0.8 to 1e-12 relative (fmusim writes 16 significant digits). Its log shows the calling sequence:
    early returns with eventHandlingNeeded, then fmi3EnterEventMode, fmi3UpdateDiscreteStates,
    fmi3EnterStepMode."""
    import csv

    out, calls = tmp_path / "out.csv", tmp_path / "calls.log"
    run = subprocess.run([_fmusim(), "--interface-type", "cs", "--early-return-allowed", "--event-mode-used",
                          "--start-value", "e", "0.8", "--stop-time", "3", "--output-interval", "0.1",
                          "--output-file", str(out), "--log-fmi-calls", "--fmi-log-file", str(calls),
                          str(host_fmi3["BouncingBall"])], capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stdout[-2000:] + run.stderr[-2000:]
    with open(out, newline="", encoding="utf-8") as f:
        rows = [{k: float(v) for k, v in row.items()} for row in csv.DictReader(f)]
    expected = ballistic_contacts(H0, G, V_MIN, lambda _v: 0.8)
    contacts = sorted({row["t_impact"] for row in rows if row["t_impact"] >= 0.0})
    assert len(contacts) == len(expected) and expected[-1][0] < 3.0  # the ball came to rest inside the run
    for t, (t_ref, _v, _e) in zip(contacts, expected):
        assert t == pytest.approx(t_ref, rel=1e-12)
        assert any(row["time"] == t for row in rows)  # a row at the contact instant itself
    log = calls.read_text(encoding="utf-8")
    early = [line for line in log.splitlines() if line.startswith("fmi3DoStep") and "earlyReturn=1" in line]
    assert len(early) == len(contacts) and all("eventHandlingNeeded=1" in line for line in early)
    assert log.count("fmi3EnterEventMode() -> OK") == len(contacts)
    assert log.count("fmi3EnterStepMode() -> OK") == len(contacts) + 1  # and once after initialization
    assert "-> Error" not in log and "-> Fatal" not in log
