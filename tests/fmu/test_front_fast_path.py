"""The C front's cheap common path keeps every promise of docs/host_contract.md.

The front skips what a call does not need: the range check (and the backend's own check) of a value the
variable already holds bit for bit, the message bookkeeping of a call that logged nothing, the checks of
host-given value references where a model-exchange getter reads the model's own vectors, and the
lock's slow path where no other thread holds the instance. Here, through raw fmi2 calls in a child
process (tests/fmi_child.py; a crash fails one test), with the bounds read from the modelDescription:

* an unchanged value is accepted, a changed bad one is still refused and the previous value kept, in a
  single call and in a vector call that mixes both; an unchanged value of a variable that may not be set
  (an output, a fixed parameter after initialization) is still refused;
* after thousands of calls that log nothing, a refused call's message still reaches the logger, once;
* the premise of the skip: every input's and parameter's start value (what the store holds before any
  set) is inside its declared range;
* the lock's fallback (a plain pthread mutex, -DRST_FRONT_PLAIN_MUTEX) still serializes four threads on
  one instance under ThreadSanitizer, and the default lock does so at -O2 without a sanitizer.
"""
from __future__ import annotations

import math
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest
from fmpy import extract, read_model_description

from fmi_child import run_child

TESTS = Path(__file__).resolve().parents[1]
WATCHDOG = 120  # [s]

_UNCHANGED_VALUES = r'''
md = {v.name: v for v in MD.modelVariables}
first, second, output = ARGS[0], ARGS[1], ARGS[2]
lo, hi = float(md[first].min), float(md[first].max)
good, other = lo + 0.25 * (hi - lo), lo + 0.75 * (hi - lo)
s = instance()
r = {"bounds": [lo, hi]}
r["new"] = status(s.setReal, [VR[first]], [good])
r["same"] = status(s.setReal, [VR[first]], [good])
r["above"] = status(s.setReal, [VR[first]], [hi * 2.0])
r["nan"] = status(s.setReal, [VR[first]], [float("nan")])
r["below"] = status(s.setReal, [VR[first]], [lo - (hi - lo)])
r["kept"] = s.getReal([VR[first]])[0]
second_before = s.getReal([VR[second]])[0]
# one call: the first variable unchanged (valid), the second out of its range: nothing changes
r["mixed"] = status(s.setReal, [VR[first], VR[second]], [good, float(md[second].max) * 2.0])
r["mixed_kept"] = [s.getReal([VR[first]])[0], s.getReal([VR[second]])[0], second_before]
# one call: the first unchanged, the second changed to a valid value: both taken
r["mixed_ok"] = status(s.setReal, [VR[first], VR[second]], [good, second_before])
r["changed"] = status(s.setReal, [VR[first]], [other])
r["changed_value"] = s.getReal([VR[first]])[0]
r["back_to_bad"] = status(s.setReal, [VR[first]], [hi * 2.0])
r["after_step"] = status(s.doStep, 0.0, 1e-3)
# an output set to the value it reads is still refused (what may be set is checked on every call)
now = s.getReal([VR[output]])[0]
r["output"] = status(s.setReal, [VR[output]], [now])
r["log"] = [m for _, _, m in LOG]
report(**r)
'''


def _unzip(fmu: Path, tmp_path: Path) -> Path:
    return Path(extract(str(fmu), str(tmp_path / "unzip")))


def _run(code, fmu, tmp_path, *args):
    result = run_child(code, fmu, _unzip(fmu, tmp_path), *args, timeout=WATCHDOG)
    assert result.returncode == 0 and result.report is not None, result.explain()
    return result.report


@pytest.mark.parametrize("model, first, second, output", [
    ("SpherePlateImpact", "v_approach", "sphere.d", "e"),
    ("BouncingBall", "e", "e", "h"),
])
def test_an_unchanged_value_passes_a_changed_bad_one_is_refused(built_fmus, tmp_path, model, first, second,
                                                                output):
    """Inputs and tunable parameters of both native FMUs and of the pythonfmu impact FMU (the same front
    behind the guard): setting the value a variable holds is accepted; a value above, below or NaN is
    refused (fmi2Error = 3) afterwards as before, the previous value kept; a vector call with an unchanged
    valid value and a bad one changes nothing; setting an output to its own value is still an error."""
    fmus = [built_fmus / "fmi2" / f"{model}.fmu"]
    if model == "SpherePlateImpact":
        fmus.append(built_fmus / f"{model}.fmu")
    for fmu in fmus:
        if not fmu.is_file():
            pytest.skip(f"{fmu.name} not built here")
        r = _run(_UNCHANGED_VALUES, fmu, tmp_path / fmu.parent.name, first, second, output)
        lo, hi = r["bounds"]
        good = lo + 0.25 * (hi - lo)
        assert (r["new"], r["same"]) == (0, 0), r["log"]
        assert (r["above"], r["nan"], r["below"]) == (3, 3, 3), r["log"]
        assert r["kept"] == good
        assert r["mixed"] == 3
        assert r["mixed_kept"][0] == good and r["mixed_kept"][1] == r["mixed_kept"][2]
        assert r["mixed_ok"] == 0
        assert r["changed"] == 0 and r["changed_value"] == lo + 0.75 * (hi - lo)
        assert r["back_to_bad"] == 3
        assert r["after_step"] <= 1
        assert r["output"] == 3
        refusals = [m for m in r["log"] if "outside the allowed range" in m]
        assert len(refusals) == 5, r["log"]  # above, nan, below, mixed (the second variable), back_to_bad
        assert any(f"{first} = nan" in m for m in refusals), refusals


_FIXED_PARAMETER = r'''
s = instance(parameters={"h0": 0.5})
held = s.getReal([VR["h0"]])[0]
report(held=held, same=status(s.setReal, [VR["h0"]], [held]), log=[m for _, _, m in LOG])
'''


def test_a_fixed_parameter_set_to_its_own_value_after_initialization_is_refused(native_ball_fmu, tmp_path):
    """BouncingBall's h0 is fixed: after initialization even its current value is refused (fmi2Error), with a
    message naming it."""
    r = _run(_FIXED_PARAMETER, native_ball_fmu, tmp_path)
    assert r["held"] == 0.5
    assert r["same"] == 3
    assert any("h0" in m and "fixed" in m for m in r["log"]), r["log"]


_NATIVE_ACCEPT = r'''
s = instance()
held = s.getInteger([VR["zener_method"]])[0]
report(held=held, same=status(s.setInteger, [VR["zener_method"]], [held]),
       ode=status(s.setInteger, [VR["zener_method"]], [4]), kept=s.getInteger([VR["zener_method"]])[0],
       log=[m for _, _, m in LOG])
'''


def test_the_backends_own_check_still_refuses_a_changed_value(native_impact_fmu, tmp_path):
    """The native impact FMU refuses zener_method = 4 (ode; the pythonfmu FMU integrates it) by its own
    check beyond the declared range (1..4): its current value passes, 4 is still refused and not taken."""
    r = _run(_NATIVE_ACCEPT, native_impact_fmu, tmp_path)
    assert r["same"] == 0
    assert r["ode"] == 3 and r["kept"] == r["held"]
    assert any("zener_method" in m for m in r["log"]), r["log"]


_QUIET_THEN_LOUD = r'''
s = instance(parameters={"contact_mode": 2, "h0": 1.0})
vr_e, out = [VR["e"]], [VR["h"], VR["v"]]
t, counts = 0.0, [len(LOG)]


def quiet(n):
    global t
    for k in range(n):
        s.setReal(vr_e, [0.5 + 0.4 * (k % 100) / 100.0])
        s.doStep(t, 1e-3)
        t += 1e-3
        s.getReal(out)


quiet(3000)
counts.append(len(LOG))
first = status(s.setReal, vr_e, [2.0])
counts.append(len(LOG))
quiet(3000)
counts.append(len(LOG))
second = status(s.setReal, vr_e, [-3.0])
counts.append(len(LOG))
report(counts=counts, statuses=[first, second], log=[[n, st, m] for n, st, m in LOG])
'''


def test_a_message_after_a_quiet_period_reaches_the_logger(native_ball_fmu, tmp_path):
    """Thousands of set, step and get calls log nothing (debug logging is on: not even OK messages); the
    refused set after them reaches the logger with its message, status and instance name, exactly once,
    and so does the next one after another quiet period."""
    r = _run(_QUIET_THEN_LOUD, native_ball_fmu, tmp_path)
    c = r["counts"]
    assert r["statuses"] == [3, 3]
    assert c[1] == c[0] and c[3] == c[2], r["log"]  # the quiet periods
    assert c[2] == c[1] + 1 and c[4] == c[3] + 1, r["log"]
    name, status, message = r["log"][c[1]]
    assert (name, status) == ("child", 3) and message.startswith("e = 2.0 is outside the allowed range"), r["log"]
    assert r["log"][c[3]][2].startswith("e = -3.0 is outside the allowed range"), r["log"]


def _declared_rows():
    from restitution.fmu.models import FOLDERS, table

    for model in sorted(FOLDERS):
        for row in table(model).rows:
            if row.causality in ("input", "parameter") and row.interval is not None:
                yield model, row


@pytest.mark.parametrize("model, row", list(_declared_rows()), ids=lambda x: getattr(x, "name", x))
def test_every_start_value_is_inside_its_declared_range(model, row):
    """The store starts from the start values and the front skips the range check of a value the variable
    holds: each start value must itself pass the declared range (bounds inclusive unless open), in the
    native FMUs' narrower range too where they declare one."""
    for interval in (row.interval, row.native_interval):
        if interval is None:
            continue
        low, high, low_open, high_open = interval
        x = float(row.start)
        assert math.isfinite(x)
        assert (x > low) if low_open else (x >= low), (model, row.name, x, interval)
        assert (x < high) if high_open else (x <= high), (model, row.name, x, interval)


@pytest.mark.skipif(not sys.platform.startswith("linux") or shutil.which("gcc") is None, reason="gcc on Linux")
@pytest.mark.parametrize("flags", [
    ["-O1", "-g", "-fsanitize=thread", "-DRST_FRONT_PLAIN_MUTEX"],  # the fallback lock
    ["-O2"],  # the default lock, optimized, no sanitizer: a broken lock corrupts the states the threads save
])
def test_four_threads_on_one_instance(native_ball_fmu, tmp_path, flags):
    """tests/c_host/threads_on_one_instance.c (four threads saving, restoring, serializing and freeing
    states, reading and stepping on one instance) compiled with the native ball's sources/: it ends with
    DONE 0 and no sanitizer report, with either lock."""
    import fmpy

    with zipfile.ZipFile(native_ball_fmu) as z:
        z.extractall(tmp_path / "fmu")
    md = read_model_description(str(native_ball_fmu))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    src = tmp_path / "fmu" / "sources"
    exe = tmp_path / "threads"
    cmd = ["gcc", "-std=c99", *flags, "-fno-sanitize-recover=all" if any("sanitize" in f for f in flags) else "-Wall",
           f"-I{src}", f"-I{Path(fmpy.__file__).parent / 'c-code'}", "-o", str(exe),
           str(TESTS / "c_host" / "threads_on_one_instance.c"), *map(str, sorted(src.glob("*.c"))), "-lm", "-pthread"]
    done = subprocess.run(cmd, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr[-4000:]
    run = subprocess.run([str(exe), md.guid, str(vr["h"])], capture_output=True, text=True, timeout=300,
                         env={"PATH": "/usr/bin:/bin", "TSAN_OPTIONS": "halt_on_error=1"})
    assert run.returncode == 0, run.stdout[-2000:] + run.stderr[-4000:]
    assert run.stdout.strip().splitlines()[-1] == "DONE 0", run.stdout[-2000:]
    assert "WARNING: ThreadSanitizer" not in run.stderr, run.stderr[-4000:]
