"""The FMUs never take their host down: the C front in front of pythonfmu, and the same
front in the native FMUs.

Every hostile scenario runs in a child process (tests/fmi_child.py) whose exit code is asserted, so
a crash fails one test. Covered, through fmpy (raw calls, statuses collected) and the plain C host:

* resources: unzip paths with a non-ASCII character, '#', '%', '[', spaces and a literal "%20";
  fmpy's own extraction under a non-ASCII TMPDIR; a missing slave script or resource directory
  gives a NULL instance and a message naming the path;
* fmi2Fatal (a slave that raises): latched, every later call fmi2Error without reaching Python,
  the instance freed without touching freed memory, new instances fine afterwards;
* FMU states: garbage, truncated, corrupted, another model's, an older format, a crafted one with a
  valid checksum but a value out of range, one variable short, a pointer that is not a state: each
  fmi2Error with a message and the instance unchanged;
* leaks: 2,000 instantiate/free cycles and in-place state get/deserialize keep memory flat;
* the FMI 2.0 call sequence and doStep's time and step size; fmi2Instantiate's arguments (wrong or
  NULL GUID, NULL or empty name, NULL logger or allocator, an unknown fmuType, model exchange where the
  FMU does not offer it);
* every wrong-type and unknown-reference call: fmi2Error, and the instance still correct after;
* Ctrl-C during a long zener_method = 4 loop reaches the Python host as KeyboardInterrupt;
* values at the ends of the declared ranges: finite results equal to the package's, or fmi2Discard
  with a logged message (never a silent NaN or inf).
"""
from __future__ import annotations

import math
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest
from fmpy import extract

import restitution as r
from restitution.agreement import tolerances
from restitution.fmu.describe.c_header import variables

from fmi_child import run_child
from toy_fmu import build_toy_fmu

FMI_OK, FMI_WARNING, FMI_DISCARD, FMI_ERROR, FMI_FATAL = range(5)
CRASHES = (-signal.SIGSEGV, -signal.SIGABRT, -signal.SIGBUS, 128 + signal.SIGSEGV, 128 + signal.SIGABRT)
ROOT = Path(__file__).resolve().parents[2]

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the guard is the Linux binary")


@pytest.fixture(scope="module")
def unzipped(any_impact_fmu, tmp_path_factory):
    return extract(str(any_impact_fmu), str(tmp_path_factory.mktemp("unzipped")))


def _package_e(v, **settings):
    """e from the package for the FMU's default case (S2 ball on Al 6061, d = t = 6.35 mm)."""
    sphere = r.Sphere(r.MATERIALS["s2_tool_steel"], 6.35e-3)
    plate = r.Plate(r.MATERIALS["al_6061"], settings.pop("t", 6.35e-3))
    return r.impact_between(sphere, plate, v).e


def _close(got, want, v=2.3):
    """Equal within e's conditioning at the default case (restitution.agreement)."""
    params = {**r.Sphere(r.MATERIALS["s2_tool_steel"], 6.35e-3).params(), **r.Plate(r.MATERIALS["al_6061"], 6.35e-3).params()}
    tol, _ = tolerances(v, params)
    return abs(got - want) <= float(tol["e"])


# --- resources ---------------------------------------------------------------------------------------
ODD_DIRECTORIES = ["Übung", "a#b", "50%off", "x[1]", "with space", "lit%20eral", "tmp_José"]

USE_ONE = """
s = instance("odd")
s.setReal([VR["v_approach"]], [2.3])
e, = reals(s, ["e"])
s.terminate()
s.freeInstance()
report(e=e, log=LOG)
"""


@pytest.mark.parametrize("directory", ODD_DIRECTORIES)
def test_unzipped_under_any_legal_path(any_impact_fmu, tmp_path, directory):
    unzip = tmp_path / directory / "fmu"
    extract(str(any_impact_fmu), str(unzip))
    run = run_child(USE_ONE, any_impact_fmu, unzip)
    assert run.returncode == 0 and run.report is not None, run.explain()
    assert _close(run.report["e"], _package_e(2.3)), run.report


def test_fmpy_extraction_under_a_non_ascii_tmpdir(impact_fmu, tmp_path):
    """The issue's reproducer: TMPDIR=/tmp/tmp_José and fmpy's own extraction (it percent-encodes the URI)."""
    tmpdir = tmp_path / "tmp_José"
    tmpdir.mkdir()
    code = """
    from restitution.cosim import FmuInstance
    with FmuInstance(FMU, "quickstart") as fmu:
        assert "José" in str(fmu.unzip_dir)
        fmu.set(v_approach=2.3)
        fmu.do_step(step_size=1e-3)
        report(e=fmu.get("e")[0])
    """
    run = run_child(code, impact_fmu, tmp_path, env={**os.environ, "TMPDIR": str(tmpdir)})
    assert run.returncode == 0 and run.report is not None, run.explain()
    assert _close(run.report["e"], _package_e(2.3))


@pytest.fixture(scope="module")
def c_host(tmp_path_factory):
    from script_host import build_host

    return build_host(tmp_path_factory.mktemp("c_host") / "fmi2_script_host", 2)


def _c_host(host, unzip, guid, script, model="SpherePlateImpact"):
    return subprocess.run(["env", "-i", "PATH=/usr/bin:/bin", str(host), str(unzip), model, guid],
                          input="\n".join(script) + "\n", capture_output=True, text=True, timeout=300)


def _guid(fmu):
    from fmpy import read_model_description

    return read_model_description(str(fmu)).guid


@pytest.mark.parametrize("directory", ["Übung", "a#b", "50%off", "x[1]", "with space"])
def test_plain_c_host_under_any_legal_path(any_impact_fmu, c_host, tmp_path, directory):
    unzip = tmp_path / directory / "fmu"
    extract(str(any_impact_fmu), str(unzip))
    vr = {v.name: v.vr for v in variables("SpherePlateImpact")}
    proc = _c_host(c_host, unzip, _guid(any_impact_fmu), [
        "instantiate odd", "setup 0 0.0", "enter_init 0", "exit_init 0", f"set_real 0 {vr['v_approach']} 2.3",
        "step 0 0.0 0.001", f"get_real 0 {vr['e']}", "terminate 0", "free 0"])
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    e = float(next(line.split()[3] for line in proc.stdout.splitlines() if line.startswith("REAL ")))
    assert _close(e, _package_e(2.3))


def test_missing_slave_script_or_resources_give_a_message_naming_the_path(impact_fmu, tmp_path):
    unzip = Path(extract(str(impact_fmu), str(tmp_path / "fmu")))
    script = unzip / "resources" / "sphere_plate_impact_slave.py"
    script.rename(script.with_suffix(".moved"))
    code = """
    s = slave("broken")
    component = s.fmi2Instantiate(b"broken", 1, MD.guid.encode(), ("file://" + UNZIP + "/resources").encode(),
                                  byref(CALLBACKS), 0, 0)
    elsewhere = s.fmi2Instantiate(b"elsewhere", 1, MD.guid.encode(), b"file:///nonexistent/resources",
                                  byref(CALLBACKS), 0, 0)
    report(null=[component is None, elsewhere is None], log=LOG)
    """
    run = run_child(code, impact_fmu, unzip)
    assert run.returncode == 0 and run.report is not None, run.explain()
    assert run.report["null"] == [True, True]
    messages = [m for _, status, m in run.report["log"] if status == FMI_ERROR]
    assert any(str(script) in m and "does not exist" in m for m in messages), messages
    assert any("/nonexistent/resources" in m and "not a directory" in m for m in messages), messages


# --- fmi2Fatal is latched -------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def raising_fmu(tmp_path_factory):
    """ToyGain (tests/toys/toy_gain_slave.py): its do_step raises for x < 0."""
    return build_toy_fmu(tmp_path_factory.mktemp("toy"), "toy_gain_slave")


def test_fatal_is_latched_and_never_reaches_freed_memory(raising_fmu, tmp_path):
    code = """
    import gc
    s = instance("doomed")
    s.setReal([VR["x"]], [-1.0])
    fatal = status(s.doStep, 0.0, 0.1)
    later = [status(s.getReal, [VR["y"]]), status(s.doStep, 0.1, 0.1), status(s.setReal, [VR["x"]], [4.0]),
             status(s.terminate), status(s.reset), status(s.getFMUstate)]
    s.freeInstance()
    gc.collect()
    values = []
    for k in range(10):  # free and start new instances: pythonfmu's broken one is never touched again
        t = instance(f"fresh{k}")
        t.setReal([VR["x"]], [4.0 + k])
        t.doStep(0.0, 0.1)
        values.append(reals(t, ["y"])[0])
        t.terminate()
        t.freeInstance()
        gc.collect()
    report(fatal=fatal, later=later, values=values, log=LOG)
    """
    run = run_child(code, raising_fmu, extract(str(raising_fmu), str(tmp_path / "toy")))
    assert run.returncode == 0 and run.report is not None, run.explain()
    rep = run.report
    assert rep["fatal"] == FMI_FATAL
    assert rep["later"] == [FMI_ERROR] * 6
    assert rep["values"] == [math.sqrt(4.0 + k) for k in range(10)]  # gain 1
    latched = [m for name, status, m in rep["log"] if name == "doomed" and "reported fmi2Fatal earlier" in m]
    assert len(latched) == 6, rep["log"]


# --- FMU states ------------------------------------------------------------------------------------------
STATE_CODE = r"""
import struct

def fnv1a(data):  # the checksum the serialized layout ends with (64-bit FNV-1a), written independently
    h = 0xcbf29ce484222325
    for b in data:
        h = ((h ^ b) * 0x100000001b3) & 0xFFFFFFFFFFFFFFFF
    return h

def parse(blob):
    # layout documented in cfront/rst_state.c: magic, format, identifier, GUID, count, mode, flags, times,
    # then (vr, type, value) per state variable, then the checksum
    pos = 8
    fmt, = struct.unpack_from("<I", blob, pos); pos += 4
    n_id, = struct.unpack_from("<I", blob, pos); pos += 4 + n_id
    n_guid, = struct.unpack_from("<I", blob, pos); pos += 4 + n_guid
    count_at = pos
    n, = struct.unpack_from("<I", blob, pos); pos += 4 + 12 + 24
    rows = {}
    for _ in range(n):
        vr, typ = struct.unpack_from("<II", blob, pos)
        rows[vr] = pos + 8
        pos += 16
    return count_at, rows

def sealed(body):
    return body + struct.pack("<Q", fnv1a(body))

def bad_states(blob, foreign):
    body = blob[:-8]
    count_at, rows = parse(blob)
    crafted = bytearray(body)
    struct.pack_into("<d", crafted, rows[VR["plate.t"]], -6.35e-3)
    older = bytearray(body)
    struct.pack_into("<I", older, 8, 0)
    short = bytearray(body[:max(rows.values()) - 8])  # the last variable cut off, the count lowered
    struct.pack_into("<I", short, count_at, len(rows) - 1)
    nan_code = bytearray(body)
    struct.pack_into("<d", nan_code, rows[VR["zener_method"]], 2.5)
    flipped = bytearray(blob)
    flipped[len(blob) // 2] ^= 0x40
    return {
        "empty": b"", "garbage": bytes(range(256)) * 3, "json": b'{"schema": {}, "values": {}}',
        "header only": blob[:16], "truncated by one": blob[:-1], "truncated half": blob[:len(blob) // 2],
        "one bit flipped": bytes(flipped), "another model's state": foreign,
        "older format": sealed(bytes(older)), "crafted plate.t < 0": sealed(bytes(crafted)),
        "one variable short": sealed(bytes(short)), "zener_method = 2.5": sealed(bytes(nan_code)),
    }
"""


def test_hostile_states_are_refused_and_change_nothing(any_impact_fmu, unzipped, any_ball_fmu, tmp_path):
    code = STATE_CODE + textwrap.dedent(r"""
    from fmpy import extract
    ball_md = read_model_description(ARGS[0])
    ball = FMU2Slave(guid=ball_md.guid, unzipDirectory=extract(ARGS[0], ARGS[1]), modelIdentifier="BouncingBall",
                     instanceName="ball")
    ball.instantiate(callbacks=CALLBACKS)
    foreign = bytes(ball.serializeFMUstate(ball.getFMUstate()))

    s = instance("target", {"plate.t": 3e-3})
    s.setReal([VR["v_approach"]], [2.3])
    names = ["e", "v_rebound", "zener.lambda", "plate.t", "v_approach"]
    before = reals(s, names)
    good = s.getFMUstate()
    blob = bytes(s.serializeFMUstate(good))
    outcome = {}
    for case, data in bad_states(blob, foreign).items():
        n = len(LOG)
        state = fmi2FMUstate()
        buffer = (ctypes.c_char * max(len(data), 1)).from_buffer_copy(data or b"\0")
        st = status(s.fmi2DeSerializeFMUstate, s.component, buffer, len(data), byref(state))
        outcome[case] = [st, reals(s, names) == before, [m for _, _, m in LOG[n:]]]
    # pointers that are not states of this instance
    other = instance("other")
    theirs = other.getFMUstate()
    pointers = [status(s.fmi2SetFMUstate, s.component, c_void_p(12345)), status(s.fmi2SetFMUstate, s.component, theirs),
                status(s.fmi2SetFMUstate, s.component, ball.getFMUstate())]
    s.setFMUstate(s.deSerializeFMUstate(blob))  # the good one still restores
    report(outcome=outcome, pointers=pointers, after=reals(s, names) == before)
    """)
    run = run_child(code, any_impact_fmu, unzipped, any_ball_fmu, tmp_path / "ball")
    assert run.returncode == 0 and run.report is not None, run.explain()
    rep = run.report
    for case, (st, unchanged, messages) in rep["outcome"].items():
        assert st == FMI_ERROR and unchanged, (case, st, messages)
        assert messages and "fmi2DeSerializeFMUstate" in messages[-1], (case, messages)
    reasons = {case: out[2][-1] for case, out in rep["outcome"].items()}
    assert "another model" in reasons["another model's state"] or "checksum" in reasons["another model's state"]
    assert "another format version" in reasons["older format"]
    assert "plate.t = -0.00635" in reasons["crafted plate.t < 0"] and "allowed range" in reasons["crafted plate.t < 0"]
    assert "number of variables" in reasons["one variable short"]
    assert "zener_method" in reasons["zener_method = 2.5"]
    assert "checksum" in reasons["one bit flipped"]
    assert "checksum" in reasons["truncated by one"] or "truncated" in reasons["truncated by one"]
    assert rep["pointers"] == [FMI_ERROR] * 3 and rep["after"]


# --- leaks -----------------------------------------------------------------------------------------------
LEAK_CODE = """
import gc
def rss_kib():
    with open("/proc/self/status") as f:
        return next(int(line.split()[1]) for line in f if line.startswith("VmRSS:"))
s = slave("cycles")
for k in range(2200):
    if k == 200:
        gc.collect()
        start = rss_kib()
    s.instantiate(callbacks=CALLBACKS)
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    s.exitInitializationMode()
    s.setReal([VR["v_approach"]], [0.5 + k % 7])
    s.doStep(0.0, 1e-3)
    s.getReal([VR["e"]])
    s.terminate()
    s.fmi2FreeInstance(s.component)
gc.collect()
grown_cycles = rss_kib() - start

t = instance("states")
state = fmi2FMUstate()
blob = bytes(t.serializeFMUstate(t.getFMUstate()))
buffer = (ctypes.c_char * len(blob)).from_buffer_copy(blob)
for k in range(22000):
    if k == 2000:
        gc.collect()
        start = rss_kib()
    assert t.fmi2GetFMUstate(t.component, byref(state)) == 0  # into the same state, in place
    assert t.fmi2DeSerializeFMUstate(t.component, buffer, len(blob), byref(state)) == 0
gc.collect()
report(cycles=grown_cycles, states=rss_kib() - start, errors=[m for _, st, m in LOG if st >= 3])
"""


@pytest.mark.slow
def test_instantiate_free_and_state_cycles_keep_memory_flat(any_impact_fmu, unzipped):
    run = run_child(LEAK_CODE, any_impact_fmu, unzipped, timeout=900)
    assert run.returncode == 0 and run.report is not None, run.explain()
    assert run.report["errors"] == []
    assert run.report["cycles"] < 2048, f"2,000 instantiate/free cycles grew RSS by {run.report['cycles']} KiB"
    assert run.report["states"] < 512, f"20,000 in-place state cycles grew RSS by {run.report['states']} KiB"


# --- the call sequence and the arguments ---------------------------------------------------------------------
SEQUENCE_CODE = """
s = slave("sequence")
s.instantiate(callbacks=CALLBACKS)
e_vr = [VR["e"]]
steps = {}
steps["instantiated"] = [status(s.doStep, 0.0, 0.1), status(s.getReal, e_vr), status(s.exitInitializationMode),
                         status(s.terminate)]
steps["setup"] = [status(s.setupExperiment, None, 0.0), status(s.enterInitializationMode),
                  status(s.setupExperiment, None, 0.0), status(s.doStep, 0.0, 0.1), status(s.exitInitializationMode)]
steps["bad steps"] = [status(s.doStep, 0.0, math.nan), status(s.doStep, 0.0, -0.1), status(s.doStep, 0.0, 0.0),
                      status(s.doStep, math.nan, 0.1), status(s.doStep, 0.0, math.inf),
                      status(s.doStep, 0.5, 0.1)]
steps["good then wrong times"] = [status(s.doStep, 0.0, 0.1), status(s.doStep, 0.05, 0.1),
                                  status(s.doStep, 0.1, 0.1), status(s.doStep, 0.3, 0.1),
                                  status(s.doStep, 0.2 - 1e-13, 0.1)]
s.setReal([VR["v_approach"]], [2.3])
e_running = reals(s, ["e"])[0]
steps["terminated"] = [status(s.terminate), status(s.doStep, 0.3, 0.1), status(s.setReal, [VR["v_approach"]], [1.0]),
                       status(s.getReal, e_vr), status(s.enterInitializationMode), status(s.terminate)]
e_terminated = reals(s, ["e"])[0]
steps["reset"] = [status(s.reset), status(s.getReal, e_vr), status(s.setupExperiment, None, 5.0),
                  status(s.enterInitializationMode), status(s.exitInitializationMode), status(s.doStep, 5.0, 0.1)]
s.setReal([VR["v_approach"]], [2.3])
report(steps=steps, e=[e_running, e_terminated, reals(s, ["e"])[0]], log=LOG)
s.terminate()
s.freeInstance()
"""


def test_the_fmi2_call_sequence_and_step_times_are_enforced(any_impact_fmu, unzipped):
    run = run_child(SEQUENCE_CODE, any_impact_fmu, unzipped)
    assert run.returncode == 0 and run.report is not None, run.explain()
    steps, E = run.report["steps"], FMI_ERROR
    assert steps["instantiated"] == [E, E, E, E]
    assert steps["setup"] == [0, 0, E, E, 0]
    assert steps["bad steps"] == [E] * 6
    assert steps["good then wrong times"] == [0, E, 0, E, 0]  # 0.2 - 1e-13 is 0.2 within a rounding
    assert steps["terminated"] == [0, E, E, 0, E, E]
    assert steps["reset"] == [0, E, 0, 0, 0, 0]
    for e in run.report["e"]:
        assert _close(e, _package_e(2.3))
    messages = " ".join(m for _, st, m in run.report["log"] if st == E)
    for needed in ("fmi2DoStep is not allowed in instantiated", "fmi2GetReal is not allowed in instantiated",
                   "communicationStepSize = nan", "communicationStepSize = -0.1", "does not continue the previous step",
                   "fmi2SetReal is not allowed in terminated"):
        assert needed in messages, needed


INSTANTIATE_CODE = """
import ctypes
good = slave("args")
f = good.fmi2Instantiate
loc = ("file://" + UNZIP + "/resources").encode()
guid = MD.guid.encode()
no_logger = fmi2CallbackFunctions()
no_logger.allocateMemory = CALLBACKS.allocateMemory
no_logger.freeMemory = CALLBACKS.freeMemory
no_alloc = fmi2CallbackFunctions()
no_alloc.logger = CALLBACKS.logger
results = {
    "wrong GUID": f(b"a", 1, b"{00000000-0000-0000-0000-000000000000}", loc, byref(CALLBACKS), 0, 0),
    "NULL GUID": f(b"a", 1, None, loc, byref(CALLBACKS), 0, 0),
    "empty name": f(b"", 1, guid, loc, byref(CALLBACKS), 0, 0),
    "NULL name": f(None, 1, guid, loc, byref(CALLBACKS), 0, 0),
    "NULL callbacks": f(b"a", 1, guid, loc, None, 0, 0),
    "NULL logger": f(b"a", 1, guid, loc, byref(no_logger), 0, 0),
    "NULL allocator": f(b"a", 1, guid, loc, byref(no_alloc), 0, 0),
    "neither interface": f(b"a", 7, guid, loc, byref(CALLBACKS), 0, 0),
}
nulls = {k: v is None for k, v in results.items()}
# model exchange: refused where the modelDescription does not offer it (the pythonfmu FMU), else an instance
me = f(b"me", 0, guid, loc, byref(CALLBACKS), 0, 0)
nulls["model exchange as declared"] = (me is None) == (MD.modelExchange is None)
s = instance("after")  # and a normal instance still works
s.setReal([VR["v_approach"]], [2.3])
report(nulls=nulls, e=reals(s, ["e"])[0], log=LOG)
"""


def test_fmi2instantiate_refuses_bad_arguments_without_crashing(any_impact_fmu, unzipped):
    run = run_child(INSTANTIATE_CODE, any_impact_fmu, unzipped)
    assert run.returncode == 0 and run.report is not None, run.explain()
    assert all(run.report["nulls"].values()), run.report["nulls"]
    assert _close(run.report["e"], _package_e(2.3))
    messages = " ".join(m for _, st, m in run.report["log"] if st == FMI_ERROR)
    for needed in ("does not match this FMU's", "GUID (NULL)", "instance name is NULL or empty",
                   "allocateMemory or freeMemory is NULL", "is neither fmi2ModelExchange (0) nor fmi2CoSimulation (1)"):
        assert needed in messages, needed
    assert "no logger" in run.stderr  # where there is no logger, the message goes to stderr


TYPES_CODE = """
output, an_input, kept = ARGS[0], ARGS[1], float(ARGS[2])
watched = ARGS[3:]
s = instance("types")
s.setReal([VR[an_input]], [kept])
before = reals(s, watched)
calls = {"Real": (s.getReal, s.setReal, 1.0), "Integer": (s.getInteger, s.setInteger, 1),
         "Boolean": (s.getBoolean, s.setBoolean, True)}
out = {}
for name, vr in VR.items():
    for kind, (get, put, value) in calls.items():
        if kind != TYPE[name]:
            out[f"get {kind} {name}"] = status(get, [vr])
            out[f"set {kind} {name}"] = status(put, [vr], [value])
for kind, (get, put, value) in calls.items():
    out[f"get {kind} unknown"] = status(get, [10 ** 6])
    out[f"set {kind} unknown"] = status(put, [10 ** 6], [value])
    out[f"get {kind} max vr"] = status(get, [2 ** 32 - 1])
out["set output"] = status(s.setReal, [VR[output]], [0.5])
out["vector with one unknown"] = status(s.setReal, [VR[an_input], 10 ** 6], [0.25, 1.0])
report(out=out, same=reals(s, watched) == before, kept=reals(s, [an_input])[0], log=len(LOG))
"""


@pytest.mark.parametrize("model", ["impact", "ball"])
def test_every_wrong_type_and_unknown_reference_is_an_error(model, any_impact_fmu, unzipped, any_ball_fmu,
                                                            tmp_path):
    if model == "ball":
        unzip = extract(str(any_ball_fmu), str(tmp_path / "ball"))
        run = run_child(TYPES_CODE, any_ball_fmu, unzip, "v_approach", "e", 0.7, "h", "t_impact")
        kept = 0.7
    else:
        run = run_child(TYPES_CODE, any_impact_fmu, unzipped, "e", "v_approach", 2.3, "e", "zener.tau0")
        kept = 2.3
    assert run.returncode == 0 and run.report is not None, run.explain()
    bad = {k: v for k, v in run.report["out"].items() if v != FMI_ERROR}
    assert not bad, bad
    assert len(run.report["out"]) > 40 and run.report["same"] and run.report["kept"] == kept
    assert run.report["log"] >= len(run.report["out"])  # every refusal logged


# --- Ctrl-C ----------------------------------------------------------------------------------------------
SIGINT_CODE = """
s = instance("ctrl-c", {"zener_method": 4, "plate_waves": 1, "effect_tolerance": 0.0, "plate.t": 2e-3,
                        "zener.ode_tolerance": 1e-12})
t, k, outcome = 0.0, 0, "finished"
try:
    while k < 100000:
        s.setReal([VR["v_approach"]], [0.5 + 1e-3 * k])
        s.doStep(t, 1e-3)
        t += 1e-3
        reals(s, ["e", "zener.tau0"])
        k += 1
        if k == 3:
            print("RUNNING", flush=True)
except KeyboardInterrupt:
    outcome = "KeyboardInterrupt"
except FMICallException as exc:
    outcome = f"status {exc.status}"
# the instance is intact: it goes on from where it stopped
s.setReal([VR["v_approach"]], [2.3])
e = reals(s, ["e"])[0]
s.terminate()
s.freeInstance()
report(outcome=outcome, steps=k, e=e, fatal=[m for _, st, m in LOG if st == 4])
"""


@pytest.fixture(scope="module")
def python_unzipped(impact_fmu, tmp_path_factory):
    return extract(str(impact_fmu), str(tmp_path_factory.mktemp("python_unzipped")))


@pytest.mark.parametrize("attempt", range(3))
def test_ctrl_c_in_a_long_ode_loop_reaches_the_python_host(impact_fmu, python_unzipped, attempt):
    import json
    from fmi_child import PRELUDE

    script = PRELUDE + "\n" + textwrap.dedent(SIGINT_CODE)
    proc = subprocess.Popen([sys.executable, "-c", script, str(impact_fmu), str(python_unzipped)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    for line in proc.stdout:
        if line.startswith("RUNNING"):
            break
    time.sleep(0.3 + 0.37 * attempt)
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=120)
    assert proc.returncode == 0 and proc.returncode not in CRASHES, f"exit {proc.returncode}: {err[-3000:]}"
    rep = json.loads(next(line for line in out.splitlines() if line.startswith("REPORT "))[7:])
    assert rep["outcome"] in ("KeyboardInterrupt", f"status {FMI_ERROR}"), rep
    assert rep["fatal"] == [] and rep["steps"] < 100000
    want = r.impact_between(r.Sphere(r.MATERIALS["s2_tool_steel"], 6.35e-3), r.Plate(r.MATERIALS["al_6061"], 2e-3),
                            2.3, zener_method="ode", plate_waves="on", effect_tolerance=0.0, ode_rtol=1e-12).e
    assert abs(rep["e"] - want) <= 1e-9  # the same integration at rtol 1e-12, in another process
