"""The C front under AddressSanitizer, UndefinedBehaviorSanitizer and LeakSanitizer, with hostile calls.

The native FMUs, FMI 2.0 and FMI 3.0 (front + version layer + backend + physics, from their own
sources/), and the guard in front of pythonfmu (front + pythonfmu backend + Python loader) are recompiled
with ``-fsanitize=address,undefined -fno-sanitize-recover=all`` and driven by the plain C host
(tests/c_host/fmi_script_host.c, built for the FMU's FMI version, sanitized too) through a script of
hostile calls generated from
the interface table: every variable set to NaN, infinities, values just outside its range and the
wrong type; unknown value references; String calls; calls in the wrong mode; bad step sizes and
times; garbage, truncated, flipped and foreign serialized states; a pointer that is no state;
instantiation with each bad argument (each version's own); instances freed with states still allocated;
and for model exchange (both models, both versions) the hostile calls of _hostile_me_script followed by a
legitimate integration by the host's own solver across BouncingBall's first contacts. Any memory
error, undefined behaviour or leak (native FMUs: the process ends with every instance freed)
makes the sanitizer exit non-zero with a report, which the test shows.
"""
from __future__ import annotations

import math
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

from restitution.fmu.describe.c_header import variables

from script_host import BALL_ME, build_host, interface

ROOT = Path(__file__).resolve().parents[2]
SANITIZE = ["-g", "-O1", "-fno-omit-frame-pointer", "-fsanitize=address,undefined", "-fno-sanitize-recover=all"]

pytestmark = [
    pytest.mark.skipif(not sys.platform.startswith("linux"), reason="Linux sanitizers"),
    pytest.mark.skipif(shutil.which("gcc") is None, reason="gcc not available"),
]


def _fmi_headers(version: int):
    from restitution.fmu.builders.native import fmi_include_dir

    return fmi_include_dir(f"{version}.0")


@pytest.fixture(scope="module")
def hosts(tmp_path_factory):
    """The script host, sanitized, for FMI 2.0 and FMI 3.0: {2: exe, 3: exe}."""
    out = tmp_path_factory.mktemp("asan_host")
    return {v: build_host(out / f"fmi{v}_script_host", v, flags=SANITIZE) for v in (2, 3)}


@pytest.fixture(scope="module")
def host(hosts):
    return hosts[2]


def _unpack(fmu, dest):
    with zipfile.ZipFile(fmu) as z:
        z.extractall(dest)
    return dest


def _sanitized_native(fmu, model, dest):
    """The native FMU unpacked, its Linux binary rebuilt from its own sources/ with the sanitizers."""
    unpacked = _unpack(fmu, dest)
    fmi = interface(fmu)
    sources = sorted(str(p) for p in (unpacked / "sources").glob("*.c"))
    binary = unpacked / "binaries" / fmi.binary_dirs[0] / f"{model}.so"
    assert binary.is_file()  # replaced by the sanitized build
    subprocess.run(["gcc", "-std=c99", *SANITIZE, "-Wall", "-Wextra", "-Werror", "-pedantic", "-ffp-contract=off",
                    "-shared", "-fPIC", "-pthread", f"-I{unpacked / 'sources'}",
                    f"-I{_fmi_headers(fmi.version)}", "-o", str(binary), *sources, "-lm"],
                   check=True, capture_output=True, text=True)
    return unpacked


def _sanitized_guard(fmu, model, dest):
    """The pythonfmu FMU unpacked, its guard rebuilt with the sanitizers."""
    from restitution.fmu.describe.c_header import c_header
    from restitution.fmu.builders import guard as ms

    unpacked = _unpack(fmu, dest)
    real = unpacked / "binaries" / "linux64" / f"{model}{ms.REAL_SUFFIX}.so"
    headers = dest.parent / f"{model}_guard_headers"
    headers.mkdir()
    ms.write_guard_headers(headers, (unpacked / "modelDescription.xml").read_text(encoding="utf-8"), c_header(model))
    info = ms.describe_interpreter(sys.executable)
    cmd = ms.guard_command(unpacked / "binaries" / "linux64" / f"{model}.so", headers, real.name, "gcc",
                           info["include"], real.read_bytes(), extra_flags=SANITIZE)
    subprocess.run(cmd, check=True, capture_output=True, text=True)
    return unpacked


#: the bad instantiations of each FMI version (the script host's instantiate_bad kinds)
BAD_INSTANTIATIONS = {
    2: ("null_name", "empty_name", "wrong_guid", "null_guid", "null_callbacks", "null_logger", "null_alloc",
        "model_exchange", "bad_uri"),
    3: ("null_name", "empty_name", "wrong_guid", "null_guid", "wrong_guid_no_logger", "event_mode",
        "intermediate_update", "model_exchange", "scheduled_execution"),
}


def _hostile_script(model, state_files, other_model_state, fmi):
    """The hostile calls, from the interface table; ``fmi`` (script_host.Interface) says with which call
    each variable is got and set (FMI 3.0: Enumerations with Int64) and which calls are the wrong ones."""
    rows = variables(model)
    n = len(rows)
    all_kinds = {"real", "integer", "boolean"} | ({"enumeration"} if fmi.version == 3 else set())
    lines = [f"instantiate_bad {kind}" for kind in BAD_INSTANTIATIONS[fmi.version]]
    lines += ["instantiate hostile", "instantiate spare",
              # wrong mode: before initialization
              "step 0 0.0 0.1", "get_real 0 0", "exit_init 0", "terminate 0", "get_state 0", "serialize 0",
              "setup 0 0.0", "setup 0 1.0", "enter_init 0"]
    for v in rows:
        kind = fmi.kind[v.name]
        for wrong in sorted(all_kinds - {kind}):
                lines.append(f"get_{wrong} 0 {v.vr}")
                lines.append(f"set_{wrong} 0 {v.vr} 1" if wrong != "real" else f"set_real 0 {v.vr} 1.5")
        if v.causality in ("parameter", "input") and v.type == "Real":
            low, high = v.interval[0], v.interval[1]
            for bad in ("nan", "inf", "-inf", repr(math.nextafter(low, -math.inf)),
                        repr(math.nextafter(high, math.inf)) if math.isfinite(high) else "1e308", "-1e308"):
                lines.append(f"set_real 0 {v.vr} {bad}")
        if v.causality in ("parameter", "input") and v.type == "Integer":
            for bad in (-2147483648, 2147483647, int(v.interval[0]) - 1, int(v.interval[1]) + 1):
                lines.append(f"set_{kind} 0 {v.vr} {bad}")
            if kind == "enumeration" and fmi.version == 3:  # Int64: beyond any Int32 and any double's integer
                for bad in (-9223372036854775808, 9223372036854775807, 2 ** 53 + 1):
                    lines.append(f"set_enumeration 0 {v.vr} {bad}")
        if v.causality in ("output", "local"):
            lines.append(f"set_{kind} 0 {v.vr} 0")
    for vr in (n, n + 1, 2 ** 31, 2 ** 32 - 1):
        lines += [f"get_real 0 {vr}", f"set_real 0 {vr} 1.0", f"get_integer 0 {vr}", f"get_boolean 0 {vr}",
                  f"get_string 0 {vr}", f"set_string 0 {vr}"]
    lines += ["get_string 0 0", "set_string 0 0", "exit_init 0",
              "step 0 0.0 nan", "step 0 0.0 -1", "step 0 0.0 0", "step 0 nan 0.1", "step 0 0.0 inf",
              "step 0 0.0 0.1", "step 0 0.0 0.1", "step 0 1.0 0.1", "step 0 0.1 1e308",
              "get_real 0 " + " ".join(str(v.vr) for v in rows if v.type == "Real"),
              "get_state 0", "serialize 0", "get_state 0", "set_state 0", "deserialize 0 0", "set_state 0"]
    for path in state_files:
        lines.append(f"deserialize_file 0 {path}")
    lines += [f"deserialize_file 0 {other_model_state}", "set_foreign_state 0",
              "setup 1 0.0", "enter_init 1", "exit_init 1", "get_state 1", "serialize 1",
              "deserialize 0 1", "set_state 0", "step 0 0.0 0.1",  # another instance's bytes: fine, same model
              "terminate 0", "step 0 0.1 0.1", "terminate 0", "get_real 0 0", "reset 0", "get_real 0 0",
              "setup 0 0.0", "enter_init 0", "exit_init 0", "step 0 0.0 0.1", "get_state 0",
              "free 0", "free 1"]  # freed with their states still allocated: the front frees them
    return lines


#: the legitimate model-exchange run at the end of the hostile one: BouncingBall across its first 3 contacts
ME_RUN = {"t_end": 1.0, "dt": 1e-3, "tol": 1e-9}


def _hostile_me_script(model, fmi):
    """Hostile model-exchange calls, from the interface table and the modelDescription's vector sizes:
    every model-exchange call before initialization and in each wrong mode; vectors one too long, one too
    short, empty and huge; NULL arrays and out-arguments; NaN and infinite states and time; doStep on the
    model-exchange instance and every model-exchange call on a co-simulation one; FMU states taken in
    model exchange, restored there, and refused by a co-simulation instance (and the reverse); terminate,
    reset; then a legitimate run (BouncingBall: Heun integration across its first contacts, an FMU state
    taken mid-run and restored to integrate the same stretch again). Slots 2 (ME), 3 (CS) and 4 (ME)."""
    n, z = fmi.n_states, fmi.n_indicators
    tunable = [v for v in variables(model) if v.causality == "parameter" and v.variability == "tunable"]
    every_me_call = [f"set_time {{s}} 0.0", f"set_states {{s}} {n} " + " ".join(["0.25"] * n),
                     f"get_states {{s}} {n}", f"get_derivatives {{s}} {n}", f"get_indicators {{s}} {z}",
                     f"get_nominals {{s}} {n}", "enter_event {s}", "enter_ct {s}", "update_discrete {s}",
                     "completed_step {s}"]
    sizes = sorted({n + 1, n + 2, 256} | ({n - 1, 0} if n > 0 else set()))
    lines = ["instantiate_me me_hostile", "instantiate cs_target"]
    lines += [c.format(s=2) for c in every_me_call] + ["step 2 0.0 0.1", "get_state 2"]  # before initialization
    lines += ["setup 2 0.0", "enter_init 2"] + [c.format(s=2) for c in every_me_call] + ["exit_init 2"]
    lines += ["step 2 0.0 0.1", "completed_step 2", "enter_event 2", "update_discrete 2 null", "update_discrete 2"]
    for k in sizes:
        lines += [f"get_states 2 {k}", f"get_derivatives 2 {k}", f"get_nominals 2 {k}",
                  f"set_states 2 {k} " + " ".join(["0.5"] * min(k, 8))]
    lines += [f"get_indicators 2 {k}" for k in sorted({z + 1, 256} | ({z - 1, 0} if z > 0 else set()))]
    lines += [f"get_states 2 {n} null", f"get_derivatives 2 {n} null", f"get_indicators 2 {z} null",
              f"get_nominals 2 {n} null", f"set_states 2 {n} null"]
    for bad in ("nan", "inf", "-inf", "1e308"):
        lines += [f"set_time 2 {bad}"]
        lines += [f"set_states 2 {n} " + " ".join([bad] + ["0.1"] * (n - 1))] if n else []
    lines += [f"get_states 2 {n}", "enter_ct 2", "update_discrete 2", "enter_ct 2", "completed_step 2 null",
              "completed_step 2", "step 2 0.0 0.1", "set_time 2 -1e300"]
    lines += [f"set_real 2 {v.vr} {v.start!r}" for v in tunable[:3] if fmi.kind[v.name] == "real"]  # wrong mode
    # FMU states: taken in model exchange, restored there, refused by co-simulation (and the reverse)
    lines += ["set_time 2 0.5", "get_state 2", "serialize 2", f"set_states 2 {n} " + " ".join(["0.125"] * n),
              "set_time 2 0.75", "set_state 2", f"get_states 2 {n}", "deserialize 2 2", "set_state 2",
              "setup 3 0.0", "enter_init 3", "exit_init 3"] + [c.format(s=3) for c in every_me_call]
    lines += ["deserialize 3 2", "set_state 3", "get_state 3", "serialize 3", "deserialize 2 3", "set_state 2",
              "step 3 0.0 0.1", "terminate 2", f"get_states 2 {n}", f"set_states 2 {n} " + " ".join(["0.5"] * n),
              "set_time 2 1.0", "reset 2", "enter_event 2", "setup 2 0.0", "enter_init 2", "exit_init 2",
              "enter_ct 2", "get_state 2", "free_state 2", "get_state 2", "terminate 3"]
    # the legitimate run (free 2 with its state still allocated)
    settings = {k: v for k, v in BALL_ME.items()} if model == "BouncingBall" else {}
    half = ME_RUN["t_end"] / 2
    lines += fmi.me_start(4, "me_run", settings)
    lines += [fmi.integrate(4, 0.0, half, ME_RUN["dt"], ME_RUN["tol"]), "get_state 4",
              fmi.integrate(4, half, ME_RUN["t_end"], ME_RUN["dt"], ME_RUN["tol"]), "set_state 4",
              fmi.integrate(4, half, ME_RUN["t_end"], ME_RUN["dt"], ME_RUN["tol"]), f"get_states 4 {n}",
              "terminate 4", "free 4", "free 2", "free 3"]
    return lines


def _state_files(directory, blob_source):
    """Hostile serialized states: garbage, empty, truncated and flipped versions of a real one."""
    directory.mkdir()
    real = blob_source.read_bytes()
    cases = {"empty": b"", "garbage": bytes(range(256)) * 4, "header": real[:12], "truncated": real[:-1],
             "half": real[:len(real) // 2], "huge_length": real[:12] + b"\xff\xff\xff\xff" + real[16:],
             "flipped": bytes(b ^ 0x55 if i == len(real) // 3 else b for i, b in enumerate(real))}
    files = []
    for name, data in cases.items():
        path = directory / name
        path.write_bytes(data)
        files.append(path)
    return files


def _serialized_state(unpacked, model, directory):
    """A genuine serialized state of ``model``, written by fmpy into ``directory``."""
    from fmpy import read_model_description
    from fmpy.fmi2 import FMU2Slave

    md = read_model_description(str(unpacked / "modelDescription.xml"))
    slave = FMU2Slave(guid=md.guid, unzipDirectory=str(unpacked), modelIdentifier=model, instanceName="blob")
    slave.instantiate()
    slave.setupExperiment(startTime=0.0)
    slave.enterInitializationMode()
    slave.exitInitializationMode()
    blob = bytes(slave.serializeFMUstate(slave.getFMUstate()))
    slave.terminate()
    slave.freeInstance()
    path = directory / f"{model}.state"
    path.write_bytes(blob)
    return path


@pytest.fixture(scope="module")
def genuine_states(built_fmus, tmp_path_factory):
    """Serialized states of both models, written by the (unsanitized) native FMUs in this process."""
    out = tmp_path_factory.mktemp("states")
    paths = {}
    for model in ("SpherePlateImpact", "BouncingBall"):
        fmu = built_fmus / "fmi2" / f"{model}.fmu"
        if not fmu.is_file():
            pytest.skip("native FMUs not built here")
        paths[model] = _serialized_state(_unpack(fmu, out / model), model, out)
    return paths


def _run(host, unpacked, model, script, leaks: bool, guid: str):
    env = {"PATH": "/usr/bin:/bin",
           "ASAN_OPTIONS": f"detect_leaks={int(leaks)}:abort_on_error=0:exitcode=99",
           "UBSAN_OPTIONS": "print_stacktrace=1:halt_on_error=1:exitcode=98"}
    return subprocess.run(["env", "-i", *(f"{k}={v}" for k, v in env.items()), str(host), str(unpacked), model, guid],
                          input="\n".join(script) + "\n", capture_output=True, text=True, timeout=600)


def _assert_clean(proc, script, kinds, model_exchange=False, event_mode=False):
    """The run was clean and went to its end, nothing was fatal, and every bad instantiation of
    ``kinds`` returned NULL, but model exchange where the FMU offers it (``model_exchange``) and FMI 3.0's
    event mode where it declares hasEventMode (``event_mode``)."""
    report = proc.stderr[-6000:]
    assert proc.returncode == 0, f"exit {proc.returncode}\n{report}"
    for marker in ("ERROR: AddressSanitizer", "runtime error:", "ERROR: LeakSanitizer"):
        assert marker not in proc.stderr, report
    statuses = [line.split() for line in proc.stdout.splitlines() if line.startswith("STATUS ")]
    assert len(statuses) > len(script) // 2  # the script ran to its end
    assert not any(s[3] == "Fatal" for s in statuses)
    bad = [line for line in proc.stdout.splitlines() if line.startswith("BAD_INSTANCE")]
    # every bad instantiation refused; model exchange is no bad argument where the FMU offers it
    offered = {"model_exchange": model_exchange, "event_mode": event_mode}
    expected = {f"BAD_INSTANCE {kind} {'NONNULL' if offered.get(kind) else 'NULL'}" for kind in kinds}
    assert set(bad) == expected and len(bad) == len(kinds), bad


@pytest.mark.parametrize("folder", ["fmi2", "fmi3"])
@pytest.mark.parametrize("model", ["SpherePlateImpact", "BouncingBall"])
def test_native_fmu_hostile_calls_under_sanitizers(built_fmus, hosts, genuine_states, model, folder, tmp_path):
    """The native FMU of each FMI version (fmi2/: FMI 2.0, fmi3/: FMI 3.0). The hostile states are made
    from states the FMI 2.0 FMU serialized: both versions share one state format (the core's rst_state.c),
    so the genuine one restores in either and its damaged versions must be refused by both."""
    fmu = built_fmus / folder / f"{model}.fmu"
    if not fmu.is_file():
        pytest.skip(f"{folder}/{model}.fmu not built here (needs gcc)")
    fmi = interface(fmu)
    unpacked = _sanitized_native(fmu, model, tmp_path / "fmu")
    other = genuine_states["BouncingBall" if model == "SpherePlateImpact" else "SpherePlateImpact"]
    script = _hostile_script(model, _state_files(tmp_path / "states", genuine_states[model]), other, fmi)
    me_script = _hostile_me_script(model, fmi)
    script += me_script
    proc = _run(hosts[fmi.version], unpacked, model, script, leaks=True, guid=fmi.token)
    _assert_clean(proc, script, BAD_INSTANTIATIONS[fmi.version], model_exchange=True,
                  event_mode=_has_event_mode(fmu))
    assert proc.stdout.startswith(f"INFO {fmi.version}.0 "), proc.stdout[:200]
    # the genuine state (serialized by another instance) restores; a damaged one never does
    statuses = [line.split() for line in proc.stdout.splitlines() if line.startswith("STATUS deserialize")]
    assert [s[3] for s in statuses if s[1] == "deserialize" and s[2] in ("0", "1")] == ["OK", "OK"], statuses
    assert all(s[3] == "Error" for s in statuses if s[1] == "deserialize_file"), statuses
    _assert_model_exchange(proc.stdout, me_script, model, fmi)


def _has_event_mode(fmu) -> bool:
    from fmpy import read_model_description

    cs = read_model_description(str(fmu)).coSimulation
    return bool(cs is not None and cs.hasEventMode)


def _event_mode_script(e_vr: int, t_contact: float) -> list[str]:
    """FMI 3.0 co-simulation with event mode and early return on slot 0, out of sequence and in sequence:
    initialization ends in event mode (a step, continuous-time mode, setTime, a NULL update refused), the
    update and step mode; step mode twice and an update there refused; the first step ends at the contact;
    a step that skips it refused; event mode, e set, a state taken there, the update, step mode, the next
    step; the event-mode state restored and handled again; terminated and freed with its state held."""
    return ["instantiate_ev ev", "setup 0 0.0", "enter_init 0", "exit_init 0",
            "step 0 0.0 0.1", "enter_ct 0", "set_time 0 1.0", "update_discrete 0 null", "update_discrete 0",
            "enter_step 0", "enter_step 0", "update_discrete 0",
            "step 0 0.0 1.0", "step 0 1.0 0.1",
            "enter_event 0", f"set_real 0 {e_vr} 0.5", "get_state 0", "serialize 0", "update_discrete 0",
            "enter_step 0", f"step 0 {t_contact!r} 1.0",
            "set_state 0", "update_discrete 0", "enter_step 0", "deserialize 0", "set_state 0",
            "terminate 0", "free 0"]


def test_event_mode_calls_under_sanitizers(host_fmi3, hosts, tmp_path):
    """FMI 3.0 BouncingBall with eventModeUsed and earlyReturnAllowed (host_fmi3: this platform's build, its
    sources recompiled with the sanitizers) through _event_mode_script: clean under ASan, UBSan and LSan;
    each call out of sequence an Error, each legal one OK; the step returns early at the free-fall time
    with the event pending (eventHandlingNeeded 1, earlyReturn 1)."""
    model = "BouncingBall"
    fmu = host_fmi3[model]
    fmi = interface(fmu)
    unpacked = _sanitized_native(fmu, model, tmp_path / "fmu")
    rows = {v.name: v for v in variables(model)}
    t_contact = math.sqrt(2 * rows["h0"].start / rows["g"].start)
    script = _event_mode_script(rows["e"].vr, t_contact)
    proc = _run(hosts[3], unpacked, model, script, leaks=True, guid=fmi.token)
    _assert_clean(proc, script, ())
    statuses = [line.split()[1:] for line in proc.stdout.splitlines() if line.startswith("STATUS ")]
    got = [(command, status) for command, _slot, status in statuses]
    errors = {"step": 2, "enter_ct": 1, "set_time": 1, "update_discrete": 2, "enter_step": 1}  # refused calls
    for command, n in errors.items():
        assert sum(1 for c, st in got if c == command and st == "Error") == n, (command, got)
    assert sum(1 for _c, st in got if st == "Error") == sum(errors.values()), got
    stepped = [line.split() for line in proc.stdout.splitlines() if line.startswith("STEPPED ")]
    assert [s[2:5] for s in stepped] == [["1", "0", "1"], ["1", "0", "1"]]
    assert float(stepped[0][5]) == pytest.approx(t_contact, rel=1e-15)


def _assert_model_exchange(stdout, script, model, fmi):
    """What the hostile model-exchange part (``script``, the run's last lines) must show beyond a clean run,
    call by call (each of its lines but instantiate, free and FMI 3.0's setup prints one STATUS): doStep on the model-exchange instance,
    every model-exchange call on the co-simulation one, wrong vector sizes, NULL arrays, non-finite states
    and time, a state of one interface into the other: Error; the legitimate run: every call OK, and
    BouncingBall's contacts before the FMU state was taken at the closed-form times, and the stretch
    integrated again after that state is restored finds the same contacts."""
    silent = {"instantiate", "instantiate_me", "free"} | ({"setup"} if fmi.version == 3 else set())
    commands = [line for line in script if line.split()[0] not in silent]
    statuses = [line.split() for line in stdout.splitlines() if line.startswith("STATUS ")][-len(commands):]
    calls = [(line.split(), st[3]) for line, st in zip(commands, statuses)]
    assert all(words[0] == st_cmd[1] for (words, _), st_cmd in zip(calls, statuses))
    me = [(words, st) for words, st in calls if words[1] in ("2", "3", "4")]
    n, z = fmi.n_states, fmi.n_indicators
    size = {"get_states": n, "get_derivatives": n, "get_nominals": n, "set_states": n, "get_indicators": z}
    for words, st in me:
        cmd, slot = words[0], words[1]
        must_fail = (
            (cmd == "step" and slot == "2")
            or (slot == "3" and cmd in ("set_time", "enter_event", "enter_ct", "update_discrete", "completed_step",
                                         *size))
            or (cmd in size and (int(words[2]) != size[cmd] or "null" in words[3:4]) and not (
                "null" in words[3:4] and size[cmd] == 0 and int(words[2]) == 0))
            or (cmd in ("set_time", "set_states") and any(w in ("nan", "inf", "-inf") for w in words[2:]))
            or (cmd == "deserialize" and words[1] != words[2]))  # a state of the other interface
        if must_fail:
            assert st == "Error", (words, st)
        if slot == "4":
            assert st == "OK", (words, st)
    if model == "BouncingBall":
        from script_host import events, free_fall_contacts, located_contact_bounds

        half = ME_RUN["t_end"] / 2
        contacts = [t for t, changed in events(stdout, 4) if changed]
        times, _ = free_fall_contacts(**BALL_ME)
        first = [t for t in times if t <= ME_RUN["t_end"]]
        late, _ = located_contact_bounds(len(first), BALL_ME["g"], BALL_ME["e"], ME_RUN["tol"])
        assert len(first) == 3 and len(contacts) == 3 + sum(t > half for t in first), contacts
        for got, want, bound in zip(contacts[:3], first, late):
            assert -1e-12 <= got - want <= bound + 1e-12, (got, want, bound)
        # the stretch integrated again from the restored state finds the same contacts (same calls, same state)
        again = [t for t in contacts[:3] if t > half]
        assert contacts[3:] == pytest.approx(again, rel=0, abs=1e-12), (contacts, again)


@pytest.mark.slow
@pytest.mark.parametrize("model", ["SpherePlateImpact", "BouncingBall"])
def test_guard_hostile_calls_under_sanitizers(built_fmus, host, genuine_states, model, tmp_path):
    """The guard in a plain C host that starts Python: memory errors and undefined behaviour only
    (the embedded interpreter is never finalized, so its memory is left to the process exit)."""
    fmu = built_fmus / f"{model}.fmu"
    fmi = interface(fmu)
    unpacked = _sanitized_guard(fmu, model, tmp_path / "fmu")
    other = genuine_states["BouncingBall" if model == "SpherePlateImpact" else "SpherePlateImpact"]
    script = _hostile_script(model, _state_files(tmp_path / "states", genuine_states[model]), other, fmi)
    _assert_clean(_run(host, unpacked, model, script, leaks=False, guid=fmi.token), script,
                  BAD_INSTANTIATIONS[fmi.version])
