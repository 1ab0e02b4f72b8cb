"""FMU states that are not states are refused, whichever way they come in.

A state restored with ``fmi2SetFMUstate`` / ``fmi3SetFMUState`` or deserialized must hold exactly one mode
of its interface's state machine, the interface (co-simulation or model exchange) of the instance it is
restored into, finite times, every Real finite, and every input and parameter inside its declared range
(as a set call checks it). Anything else is an error (never fatal) with a one-line message, and the
instance and the state that an in-place deserialization would have overwritten stay as they were.

The hostile states are genuine ones, serialized by the FMU in each mode of each interface, with one word
changed and the checksum recomputed here, from the layout documented in ``cfront/rst_state.c`` (format 2:
the interface word after the variables) and FNV-1a written independently. The mode bits are the ones
``cfront/rst_front.h`` documents (rst_mode). Every scenario runs in a child process (a crash fails one
test): the native FMI 2.0 and FMI 3.0 FMUs in both interfaces, and the pythonfmu FMUs behind the C guard,
whose states go through the same front (co-simulation only).
"""
from __future__ import annotations

import json
import math

import pytest
from fmpy import extract

from fmi_child import run_child

FMI_ERROR = 3
#: rst_mode in cfront/rst_front.h: one bit per mode
MODE_BITS = {"instantiated": 0x1, "initialization": 0x2, "step complete": 0x4, "step failed": 0x8,
             "terminated": 0x10, "error": 0x20, "fatal": 0x40, "event": 0x80, "continuous": 0x100}
#: the modes each interface's states are taken in here (the running one last but one)
MODES = {"cs": ("instantiated", "initialization", "step complete", "terminated"),
         "me": ("instantiated", "initialization", "event", "continuous", "terminated")}
RUNNING = {"cs": "step complete", "me": "continuous"}
#: the interface word of the serialized layout
INTERFACE_WORD = {"cs": 0, "me": 1}
#: how the instance that refuses a state of the other interface names itself, and the state's origin
REFUSAL = {"cs": "the state was taken from a model-exchange instance; this one is co-simulation",
           "me": "the state was taken from a co-simulation instance; this one is model exchange"}
#: mode words that are not one mode of the interface: combinations, none, fatal, unknown bits, the
#: other interface's modes
BAD_MODE_WORDS = {
    "cs": (0x0, 0x3, 0x5, 0x6, 0x9, 0x11, 0x14, 0x24, 0x40, 0x80, 0x84, 0x100, 0x200, 0x80000000, 0xFFFFFFFF),
    "me": (0x0, 0x3, 0x5, 0x4, 0x8, 0x40, 0x81, 0x82, 0x84, 0x110, 0x180, 0x200, 0xFFFFFFFF),
}
#: a distinctive value planted in an input, to find it in a state's memory (FMU2/3 SetFMUState path)
PLANT = {"BouncingBall": ("e", 0.6180339887498949), "SpherePlateImpact": ("v_approach", 2.718281828459045)}

CHILD = r'''
import struct
from fmpy.fmi2 import FMU2Model

KIND, MODEL = ARGS[0], MD.coSimulation.modelIdentifier
MODES, RUNNING, BAD_MODE_WORDS, PLANT, REFUSAL = (json.loads(ARGS[1])[k] for k in
                                                 ("MODES", "RUNNING", "BAD_MODE_WORDS", "PLANT", "REFUSAL"))
V3 = MD.fmiVersion.startswith("3")
IFACES = ["cs", "me"] if (MD.modelExchange is not None and KIND != "python") else ["cs"]
BY_VR = {v.valueReference: v for v in MD.modelVariables}
N_STATES = sum(1 for v in MD.modelVariables if v.derivative is not None)  # model exchange's continuous states
if V3:
    from fmpy.fmi3 import FMU3Model, FMU3Slave, fmi3FMUState

    def _log3(env, st, category, message):
        LOG.append((None, int(st), message.decode("utf-8", "replace") if message else ""))


def fnv1a(data):  # the 64-bit FNV-1a the serialized layout ends with, written independently
    h = 0xcbf29ce484222325
    for b in data:
        h = ((h ^ b) * 0x100000001b3) & 0xFFFFFFFFFFFFFFFF
    return h


def parse(blob):
    """The serialized layout of cfront/rst_state.c (format 2): the offsets of its words."""
    pos = 8
    fmt, = struct.unpack_from("<I", blob, pos); pos += 4
    for _ in range(2):  # model identifier, GUID
        n, = struct.unpack_from("<I", blob, pos); pos += 4 + n
    count, = struct.unpack_from("<I", blob, pos); pos += 4
    at = {"format": 8, "mode": pos, "has_start": pos + 4, "has_time": pos + 8, "start_time": pos + 12,
          "next_time": pos + 20, "last_time": pos + 28}
    pos += 36
    rows = {}
    for _ in range(count):
        vr, typ = struct.unpack_from("<II", blob, pos)
        rows[vr] = (typ, pos + 8)
        pos += 16
    at["interface"] = pos
    return fmt, at, rows, pos + 4


def word(blob, offset):
    return struct.unpack_from("<I", blob, offset)[0]


def craft(blob, *edits, cut=None):
    """The blob with each (offset, struct format, value) written, bytes [cut) removed, resealed."""
    body = bytearray(blob[:-8])
    for offset, code, value in edits:
        struct.pack_into(code, body, offset, value)
    if cut is not None:
        del body[cut[0]:cut[1]]
    return bytes(body) + struct.pack("<Q", fnv1a(bytes(body)))


class Inst:
    """One instance of either interface and either FMI version, every call's status returned."""

    def __init__(self, iface, name):
        self.iface, self.t = iface, 0.0
        ident = (MD.coSimulation if iface == "cs" else MD.modelExchange).modelIdentifier
        if V3:
            cls = FMU3Slave if iface == "cs" else FMU3Model
            self.f = cls(guid=MD.instantiationToken, unzipDirectory=UNZIP, modelIdentifier=ident, instanceName=name)
            self.f.instantiate(loggingOn=True, logMessage=_log3)
        else:
            cls = FMU2Slave if iface == "cs" else FMU2Model
            self.f = cls(guid=MD.guid, unzipDirectory=UNZIP, modelIdentifier=ident, instanceName=name)
            self.f.instantiate(callbacks=CALLBACKS, loggingOn=True)

    def enter_init(self):
        return status(self.f.enterInitializationMode, None, 0.0) if V3 else status(self.f.enterInitializationMode)

    def to_mode(self, mode):
        """Through the modes of its interface, in order, to ``mode``: instantiated -> initialization ->
        step complete (a step of 0.1 s) | event -> continuous (at t = 0.05 s) -> terminated."""
        order = MODES[self.iface]
        for m in order[1:order.index(mode) + 1]:
            if m == "initialization":
                if not V3:
                    self.f.setupExperiment(startTime=0.0)
                st = self.enter_init()
            elif m in ("step complete", "event"):
                st = self.call("exitInitializationMode") or (self.step(0.1) if m == "step complete" else 0)
            elif m == "continuous":
                st = (self.call("updateDiscreteStates" if V3 else "newDiscreteStates")
                      or self.call("enterContinuousTimeMode") or self.set_time(0.05))
                if N_STATES and st == 0:  # as a host's solver would have moved them (distinct values)
                    x = (c_double * N_STATES)(*[0.2468013579 - 0.7 * k for k in range(N_STATES)])
                    st = self.call("setContinuousStates", x, N_STATES)
            else:
                st = self.call("terminate")
            assert st == 0, (m, LOG[-3:])

    def call(self, name, *args):
        return status(getattr(self.f, name), *args)

    def step(self, h):
        st = self.call("doStep", self.t, h)
        self.t += h if st == 0 else 0.0
        return st

    def set_time(self, t):
        return self.call("setTime", t)

    def set_real(self, name, value):
        return self.call("setFloat64" if V3 else "setReal", [VR[name]], [value])

    def values(self):
        """Every variable's value, by name."""
        out = {}
        groups = {}
        for v in MD.modelVariables:
            groups.setdefault(v.type, []).append(v)
        getters = ({"Float64": "getFloat64", "Int32": "getInt32", "Int64": "getInt64", "Enumeration": "getInt64",
                    "Boolean": "getBoolean"} if V3 else
                   {"Real": "getReal", "Integer": "getInteger", "Enumeration": "getInteger", "Boolean": "getBoolean"})
        for typ, variables in groups.items():
            got = getattr(self.f, getters[typ])([v.valueReference for v in variables])
            out.update({v.name: x for v, x in zip(variables, got)})
        return out

    def get_state(self):
        return self.f.getFMUState() if V3 else self.f.getFMUstate()

    def set_state(self, state):
        return status(self.f.fmi3SetFMUState if V3 else self.f.fmi2SetFMUstate, self.f.component, state)

    def serialize(self, state):
        return bytes(self.f.serializeFMUState(state) if V3 else self.f.serializeFMUstate(state))

    def deserialize(self, data, into=None):
        state = into if into is not None else (fmi3FMUState() if V3 else fmi2FMUstate())
        buffer = ctypes.create_string_buffer(data, max(len(data), 1))
        pointer = ctypes.cast(buffer, ctypes.POINTER(ctypes.c_uint8 if V3 else ctypes.c_char))
        function = self.f.fmi3DeserializeFMUState if V3 else self.f.fmi2DeSerializeFMUstate
        return status(function, self.f.component, pointer, len(data), byref(state)), state


def running(iface, name):
    inst = Inst(iface, name)
    inst.to_mode(RUNNING[iface])
    return inst


# genuine states, one per mode of each interface, and their layout
blobs, layout = {}, {}
for iface in IFACES:
    for mode in MODES[iface]:
        inst = Inst(iface, f"{iface} {mode}")
        inst.to_mode(mode)
        blob = inst.serialize(inst.get_state())
        fmt, at, rows, end = parse(blob)
        blobs[iface, mode] = blob
        layout[f"{iface}/{mode}"] = {"format": fmt, "end": end, "size": len(blob), "rows": len(rows),
                                     "checksum": struct.unpack_from("<Q", blob, len(blob) - 8)[0] == fnv1a(blob[:-8]),
                                     "mode": word(blob, at["mode"]), "interface": word(blob, at["interface"])}
# each restores into an instance of its interface
genuine = {}
for iface in IFACES:
    fresh = Inst(iface, f"fresh {iface}")
    for mode in MODES[iface]:
        st, state = fresh.deserialize(blobs[iface, mode])
        genuine[f"{iface}/{mode}"] = [st, fresh.set_state(state) if st == 0 else None]


def hostile(iface):
    """{case: (bytes, what the message must say)} made from the running state of ``iface``."""
    blob = blobs[iface, RUNNING[iface]]
    fmt, at, rows, end = parse(blob)
    machine = "co-simulation" if iface == "cs" else "model-exchange"
    cases = {}
    for w in BAD_MODE_WORDS[iface]:
        cases[f"mode word {w:#x}"] = (craft(blob, (at["mode"], "<I", w)),
                                      f"mode word {w:#x} is not one mode of the {machine} state machine")
    for w in (2, 7, 0xFFFFFFFF):
        cases[f"interface word {w}"] = (craft(blob, (at["interface"], "<I", w)), f"interface word {w} is neither")
    cases["interface word of the other"] = (craft(blob, (at["interface"], "<I", 1 if iface == "cs" else 0)),
                                           REFUSAL[iface])
    for key in ("start_time", "next_time", "last_time"):
        for x in (math.nan, math.inf, -math.inf):
            cases[f"{key} = {x}"] = (craft(blob, (at[key], "<d", x)), "times are not finite")
    for key in ("has_start", "has_time"):
        cases[f"{key} = 2"] = (craft(blob, (at[key], "<I", 2)), "time flags are not 0 or 1")
    no_interface = (at["interface"], at["interface"] + 4)
    cases["format 1 (no interface word)"] = (craft(blob, (8, "<I", 1), cut=no_interface), "another format version (1)")
    for f in (0, 3, 0xFFFFFFFF):
        cases[f"format {f}"] = (craft(blob, (8, "<I", f)), f"another format version ({f})")
    for vr, (typ, offset) in rows.items():
        v = BY_VR[vr]
        settable = v.causality in ("input", "parameter")
        if typ == 0:  # Real
            bad = [math.nan, math.inf, -math.inf]
            if settable:
                bad += [math.nextafter(float(v.min), -math.inf)] if v.min is not None else []
                bad += [math.nextafter(float(v.max), math.inf)] if v.max is not None else []
            for x in bad:
                said = "outside the allowed range" if settable else "not a finite Real"
                cases[f"{v.name} = {x!r}"] = (craft(blob, (offset, "<d", x)), f"the state has {v.name} = {x!r}, {said}")
        elif typ == 1:  # Integer
            bad = [1.5, math.nan] + ([float(v.min) - 1, float(v.max) + 1] if settable else [2.0 ** 31, -2.0 ** 31 - 1])
            for x in bad:
                # a settable Integer the front's table allows but this implementation does not offer (the
                # native FMU's zener_method = 4) is refused by the model's own check, which names it
                said = ("not a valid Integer", f"the state has {v.name} = ") if not settable else (v.name,)
                cases[f"{v.name} = {x!r}"] = (craft(blob, (offset, "<d", x)), *said)
        else:  # Boolean
            for x in (2.0, 0.5, -1.0, math.nan):
                said = "outside the allowed range" if settable else "not a valid Boolean"
                cases[f"{v.name} = {x!r}"] = (craft(blob, (offset, "<d", x)), f"the state has {v.name} = ", said)
    return cases


outcome, after, crossed, scribbled = {}, {}, {}, {}
for iface in IFACES:
    target, twin = running(iface, f"target {iface}"), running(iface, f"twin {iface}")
    before = target.values()
    existing = target.get_state()
    existing_blob = target.serialize(existing)
    for case, (data, *said) in hostile(iface).items():
        n = len(LOG)
        st_new, _ = target.deserialize(data)
        st_in_place, _ = target.deserialize(data, into=existing)
        outcome[f"{iface}: {case}"] = [st_new, st_in_place, target.values() == before,
                                      [(s_, m) for _, s_, m in LOG[n:]], said]
    # a state of the other interface, taken in every mode
    for other in IFACES:
        if other == iface:
            continue
        for mode in MODES[other]:
            n = len(LOG)
            st, _ = target.deserialize(blobs[other, mode])
            crossed[f"{other}/{mode} into {iface}"] = [st, target.values() == before,
                                                       [(s_, m) for _, s_, m in LOG[n:]]]
    # still the same instance: in its mode, with its state, usable
    n = len(LOG)
    record = {"existing kept": target.serialize(existing) == existing_blob,
              "enter init refused": target.enter_init(), "values": target.values() == before}
    record["enter init message"] = [m for _, _, m in LOG[n:]]
    record["restore existing"] = target.set_state(existing)
    record["values after restore"] = target.values() == before
    if iface == "cs":
        record["go on"] = [target.step(0.1), twin.step(0.1)]
    else:
        record["go on"] = [target.set_time(0.06), twin.set_time(0.06)]
    mine, theirs = target.values(), twin.values()
    record["like the twin"] = [k for k in mine if not math.isclose(float(mine[k]), float(theirs[k]),
                                                                   rel_tol=1e-12, abs_tol=0.0)]
    after[iface] = record
    # the FMUstate path: a state the host wrote over in memory is checked before it is restored
    sc = running(iface, f"scribbled {iface}")
    name, value = PLANT[MODEL]
    assert sc.set_real(name, value) == 0
    kept = sc.values()
    state = sc.get_state()
    rows = parse(sc.serialize(state))[2]
    memory = ctypes.string_at(state.value, 8 * len(rows))  # inside the state: its values alone are this long

    def once(x):  # where the 8 bytes of x are in the state's memory, if exactly once
        hits = [k for k in range(len(memory) - 7) if memory[k:k + 8] == struct.pack("<d", x)]
        return hits[0] if len(hits) == 1 else None

    plants = [("settable", once(value), value, math.nan, f"{name} = nan, outside the allowed range")]
    # an evolved Real (one the model computes, not settable) whose value is in the memory once
    evolved = [(BY_VR[vr].name, kept[BY_VR[vr].name]) for vr, (typ, _) in rows.items()
               if typ == 0 and BY_VR[vr].causality not in ("input", "parameter")]
    evolved = [(n_, x) for n_, x in evolved if x != 0.0 and once(x) is not None]
    if evolved:
        plants.append(("evolved", once(evolved[0][1]), evolved[0][1], math.inf,
                       f"{evolved[0][0]} = inf, not a finite Real"))
    for what, at, planted, bad, said in plants:
        if at is None:
            scribbled[f"{iface}: {what}"] = ["not found once in the state's memory"]
            continue
        ctypes.memmove(state.value + at, struct.pack("<d", bad), 8)
        sc.set_real(name, value * 0.5)  # move away, so that a restore would show
        moved = sc.values()
        n = len(LOG)
        refused = sc.set_state(state)
        unchanged = sc.values() == moved
        messages = [(s_, m) for _, s_, m in LOG[n:]]
        ctypes.memmove(state.value + at, struct.pack("<d", planted), 8)
        restored = sc.set_state(state)
        scribbled[f"{iface}: {what}"] = [refused, unchanged, messages, said, restored, sc.values() == kept]
report(ifaces=IFACES, layout=layout, genuine=genuine, outcome=outcome, crossed=crossed, after=after,
       scribbled=scribbled, fatal=[m for _, s_, m in LOG if s_ >= 4])
'''

FMUS = {("fmi2", "BouncingBall"): "native_ball_fmu", ("fmi2", "SpherePlateImpact"): "native_impact_fmu",
        ("fmi3", "BouncingBall"): "fmi3_ball_fmu", ("fmi3", "SpherePlateImpact"): "fmi3_impact_fmu",
        ("python", "BouncingBall"): "ball_fmu", ("python", "SpherePlateImpact"): "impact_fmu"}


@pytest.fixture(scope="module", params=sorted(FMUS), ids=lambda p: f"{p[0]}-{p[1]}")
def checked(request, tmp_path_factory):
    """The child's report for one FMU (kind, model): every hostile state against it."""
    kind, model = request.param
    fmu = request.getfixturevalue(FMUS[kind, model])
    unzip = extract(str(fmu), str(tmp_path_factory.mktemp(f"{kind}-{model}")))
    constants = json.dumps({"MODES": MODES, "RUNNING": RUNNING, "BAD_MODE_WORDS": BAD_MODE_WORDS, "PLANT": PLANT,
                            "REFUSAL": REFUSAL})
    run = run_child(CHILD, fmu, unzip, kind, constants, timeout=600)
    assert run.returncode == 0 and run.report is not None, run.explain()
    return kind, model, run.report


def _function(kind):
    return "fmi3DeserializeFMUState" if kind == "fmi3" else "fmi2DeSerializeFMUstate"


def test_genuine_states_have_the_documented_layout_and_restore(checked):
    """Every genuine state (each mode of each interface) is format 2, ends where the layout says, carries
    its mode as one rst_mode bit and its interface word, has a valid checksum, and restores."""
    kind, model, rep = checked
    assert rep["ifaces"] == (["cs"] if kind == "python" else ["cs", "me"])
    for iface in rep["ifaces"]:
        for mode in MODES[iface]:
            got = rep["layout"][f"{iface}/{mode}"]
            assert got == {"format": 2, "end": got["size"] - 8, "size": got["size"], "rows": got["rows"],
                           "checksum": True, "mode": MODE_BITS[mode], "interface": INTERFACE_WORD[iface]}, (iface, mode)
            assert rep["genuine"][f"{iface}/{mode}"] == [0, 0], (iface, mode)
    assert rep["fatal"] == []


def test_hostile_states_are_refused_with_one_line_and_change_nothing(checked):
    """Mode words that are not one mode of the interface (0x5: instantiated and step complete at once,
    ...), interface words, non-finite times, bad time flags, other format versions (format 1 has no
    interface word), every state Real NaN or infinite, every settable one just outside its declared
    range, bad Integers and Booleans: each deserialization returns Error (into a new state and in place
    over an existing one), logs exactly one line that says why, and the instance keeps every value."""
    kind, model, rep = checked
    function = _function(kind)
    cases = rep["outcome"]
    for iface in rep["ifaces"]:
        assert f"{iface}: mode word 0x5" in cases and f"{iface}: format 1 (no interface word)" in cases
    for iface in rep["ifaces"]:  # every state variable was tried (NaN, among others)
        tried = [c for c in cases if c.startswith(f"{iface}: ") and c.endswith(" = nan") and "_time" not in c]
        assert len(tried) == rep["layout"][f"{iface}/{RUNNING[iface]}"]["rows"] > 0, tried
    for case, (st_new, st_in_place, unchanged, messages, said) in cases.items():
        assert st_new == FMI_ERROR and st_in_place == FMI_ERROR, (case, messages)
        assert unchanged, case
        assert len(messages) == 2 and all(s == FMI_ERROR for s, _ in messages), (case, messages)
        for _, message in messages:
            assert "\n" not in message, (case, message)
            # every message names the call, but the model's own refusal of a settable Integer (as in a set call)
            variable = case.split(": ", 1)[1].split(" = ")[0]
            assert message.startswith(function + ": ") or said == [variable], (case, message)
            assert all(part in message for part in said), (case, said, message)
    assert rep["fatal"] == []


def test_the_instance_keeps_its_mode_and_state_and_goes_on(checked):
    """After every refusal the instance is in its mode (EnterInitializationMode still refused: a 0x5
    state did not make it 'instantiated'), the state an in-place deserialization targeted is intact and
    restores, and the instance steps (co-simulation) or takes a time (model exchange) as a twin that saw
    none of the hostile states."""
    kind, model, rep = checked
    prefix = "fmi3" if kind == "fmi3" else "fmi2"
    for iface, record in rep["after"].items():
        mode_text = "step mode" if iface == "cs" else "continuous-time mode"
        assert record["existing kept"] and record["values"] and record["values after restore"], record
        assert record["enter init refused"] == FMI_ERROR
        assert any(f"{prefix}EnterInitializationMode is not allowed in {mode_text}" in m
                   for m in record["enter init message"]), record["enter init message"]
        assert record["restore existing"] == 0
        assert record["go on"] == [0, 0] and record["like the twin"] == [], record


def test_a_state_of_the_other_interface_is_refused_in_every_mode(checked):
    """A co-simulation state taken instantiated, in initialization, after a step or terminated never
    restores into a model-exchange instance, and a model-exchange state of any mode never into a
    co-simulation one (the pythonfmu FMUs offer co-simulation only)."""
    kind, model, rep = checked
    if kind == "python":
        assert rep["crossed"] == {}
        return
    expected = {f"{o}/{m} into {i}" for i, o in (("cs", "me"), ("me", "cs")) for m in MODES[o]}
    assert set(rep["crossed"]) == expected
    for case, (st, unchanged, messages) in rep["crossed"].items():
        into = case.rsplit(" ", 1)[1]
        assert st == FMI_ERROR and unchanged, (case, messages)
        assert len(messages) == 1 and messages[0][0] == FMI_ERROR, (case, messages)
        assert messages[0][1] == f"{_function(kind)}: {REFUSAL[into]}", (case, messages)


def test_a_state_overwritten_in_memory_is_refused_by_set_state(checked):
    """The host owns the memory of an FMUstate: a Real written over with NaN or inf (found by its value,
    not by the struct's layout) makes SetFMUstate return Error with a message and change nothing; with
    the value written back the same state restores."""
    kind, model, rep = checked
    set_function = "fmi3SetFMUState" if kind == "fmi3" else "fmi2SetFMUstate"
    expected = {f"{i}: settable" for i in rep["ifaces"]}
    if model == "BouncingBall":  # SpherePlateImpact's state is its inputs and parameters
        expected |= {f"{i}: evolved" for i in rep["ifaces"]}
    assert set(rep["scribbled"]) == expected, rep["scribbled"]
    assert all(len(got) == 6 for got in rep["scribbled"].values()), rep["scribbled"]  # each value found once
    for case, (refused, unchanged, messages, said, restored, kept) in rep["scribbled"].items():
        assert refused == FMI_ERROR and unchanged, (case, messages)
        assert len(messages) == 1 and messages[0][0] == FMI_ERROR, (case, messages)
        assert messages[0][1].startswith(f"{set_function}: the state has ") and said in messages[0][1], messages
        assert restored == 0 and kept, case
