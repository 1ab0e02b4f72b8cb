"""Every FMI call returns: no hang, no deadlock, the same values in both implementations.

Each scenario that used to hang or deadlock runs in a child process under a watchdog (the child's
timeout), through both implementations of the FMU (pythonfmu behind the C front, and native):

* BouncingBall's fmi2DoStep with bounces shorter than the clock's resolution or a huge number of
  them in one step (it looped without bound); the counts are checked against closed forms and a
  one-by-one loop written here;
* a logger that calls back into the same instance (messages were delivered with the instance's
  lock held);
* BouncingBall's locals flight.* (the pythonfmu FMU read 0.0);
* the native FMUs' sources/: built with only the documented command they keep the binary's
  per-instance lock (several threads on one instance under ThreadSanitizer and AddressSanitizer),
  and compiled with FMI2_FUNCTION_PREFIX (the standard FMI 2.0 headers) both link into one
  executable.
"""
from __future__ import annotations

import math
import shutil
import subprocess
import zipfile
from pathlib import Path

import pytest
from fmpy import extract, read_model_description

from fmi_child import run_child

HERE = Path(__file__).resolve().parents[1]  # tests/
WATCHDOG = 60  # [s] a child that has not finished by then hangs: the test fails

#: Scenarios inside BouncingBall's declared ranges that never returned before: (parameters, start
#: time [s], step [s], steps). contact_mode = 2 (immediate) bounces inside the step.
ENDLESS_STEPS = {
    # g and v_min at their declared extremes: flights of 2 v_min/g = 2e-12 s, below the clock's 1.5e-11 s at 1e5 s
    "flights below the clock's resolution": ({"h0": 5e-19, "g": 1e6, "v_min": 1e-6, "contact_mode": 2, "e": 1.0},
                                             1e5, 1.0, 3),
    "largest gravity, elastic": ({"g": 1e6, "contact_mode": 2, "e": 1.0}, 0.0, 1.0, 3),
    "elastic, a 1e12 s step": ({"contact_mode": 2, "e": 1.0}, 0.0, 1e12, 2),
    "e just below 1, smallest v_min": ({"contact_mode": 2, "e": math.nextafter(1.0, 0.0), "v_min": 1e-6}, 0.0,
                                       1e12, 2),
}

_BALL_STEPS = r'''
params, t0, h, n = json.loads(ARGS[0]), float(ARGS[1]), float(ARGS[2]), int(ARGS[3])
s = slave()
s.instantiate(callbacks=CALLBACKS, loggingOn=True)
s.setupExperiment(startTime=t0)
s.enterInitializationMode()
for key, value in params.items():
    (s.setReal if TYPE[key] == "Real" else s.setInteger)([VR[key]], [value])
s.exitInitializationMode()
statuses, t = [], t0
for _ in range(n):
    statuses.append(status(s.doStep, t, h))
    t += h
names = [v.name for v in MD.modelVariables if v.type == "Real"]
report(statuses=statuses, reals=dict(zip(names, s.getReal([VR[x] for x in names]))),
       impacts=s.getInteger([VR["impacts"]])[0], at_rest=s.getBoolean([VR["at_rest"]])[0])
'''


def _unzip(fmu: Path, tmp_path: Path) -> Path:
    return Path(extract(str(fmu), str(tmp_path / "unzip")))


def _ball_steps(fmu, tmp_path, parameters, t0, h, n):
    import json

    result = run_child(_BALL_STEPS, fmu, _unzip(fmu, tmp_path), json.dumps(parameters), t0, h, n, timeout=WATCHDOG)
    assert result.returncode == 0 and result.report, result.explain()
    return result.report


@pytest.mark.parametrize("scenario", sorted(ENDLESS_STEPS))
def test_ball_step_returns_with_finite_outputs(any_ball_fmu, tmp_path, scenario):
    """Each step returns (within the watchdog) with fmi2OK; every Real is finite and inside the
    energy bounds of a ball that never gains energy (e <= 1): 0 <= h <= h0, |v| <= sqrt(2 g h0)."""
    parameters, t0, h, n = ENDLESS_STEPS[scenario]
    r = _ball_steps(any_ball_fmu, tmp_path, parameters, t0, h, n)
    assert r["statuses"] == [0] * n
    reals = r["reals"]
    assert all(math.isfinite(x) for x in reals.values()), reals
    h0, g = reals.get("h0", parameters.get("h0")), reals.get("g", parameters.get("g"))
    v_max = math.sqrt(2.0 * g * h0) * (1 + 1e-12)
    assert 0.0 <= reals["h"] <= h0 * (1 + 1e-12)
    assert abs(reals["v"]) <= v_max and reals["v_impact"] <= v_max and reals["flight.v_start"] <= v_max
    assert 1 <= r["impacts"] <= 2**31 - 1


def _impacts_one_by_one(h0, g, e, v_min, t_end):
    """Impacts of a ball dropped from h0 [m] at t = 0 that rebounds with e until its rebound speed
    falls below v_min, up to t_end [s], visited one by one (the loop the FMUs no longer run)."""
    t, v, count = math.sqrt(2.0 * h0 / g), math.sqrt(2.0 * g * h0), 0
    while t <= t_end + 1e-12:
        count += 1
        v *= e
        if v < v_min:
            break
        t += 2.0 * v / g
    return count


@pytest.mark.parametrize("e, v_min, t_end", [(1.0, 0.1, 1000.0), (0.999, 1e-3, 1000.0), (0.9, 1e-6, 50.0),
                                             (0.99999, 1e-6, 3000.0)])
def test_ball_counts_the_impacts_a_loop_counts(any_ball_fmu, tmp_path, e, v_min, t_end):
    """One long step jumps over the bounces in closed form; it counts what a one-by-one loop counts
    and lands on the same last impact (to the rounding of ~1e4 accumulated flight times, 1e-9 relative)."""
    h0, g = 0.3, 9.80665
    r = _ball_steps(any_ball_fmu, tmp_path, {"h0": h0, "v_min": v_min, "contact_mode": 2, "e": e}, 0.0, t_end, 1)
    assert r["statuses"] == [0]
    expected = _impacts_one_by_one(h0, g, e, v_min, t_end)
    assert r["impacts"] == expected
    if e == 1.0:  # elastic: the first impact at sqrt(2 h0/g), then one every 2 sqrt(2 h0/g)
        t1 = math.sqrt(2 * h0 / g)
        assert expected == math.floor((t_end - t1) / (2 * t1)) + 1
        assert r["reals"]["t_impact"] == pytest.approx(t1 * (2 * expected - 1), rel=1e-9)
        assert r["reals"]["v_impact"] == pytest.approx(math.sqrt(2 * g * h0), rel=1e-12)


def test_both_implementations_agree_on_every_variable(ball_fmu, native_ball_fmu, tmp_path):
    """Every variable a host can read, locals included, the same in both (within 1e-9 relative: the
    same formulas, different languages), after steps with contacts in both modes."""
    for mode, e in ((1, 0.8), (2, 0.8), (2, 1.0)):
        params = {"contact_mode": mode, "e": e}
        a = _ball_steps(ball_fmu, tmp_path / f"p{mode}{e}", params, 0.0, 0.37, 7)
        b = _ball_steps(native_ball_fmu, tmp_path / f"n{mode}{e}", params, 0.0, 0.37, 7)
        assert a["impacts"] == b["impacts"] and a["at_rest"] == b["at_rest"]
        for name, x in a["reals"].items():
            assert x == pytest.approx(b["reals"][name], rel=1e-9, abs=1e-15), name


def test_ball_locals_describe_the_current_flight(any_ball_fmu, tmp_path):
    """flight.t_start/h_start/v_start are the flight the outputs come from: h and v at the end of
    the step follow from them in closed form (they read 0.0 in the pythonfmu FMU)."""
    t_end = 1.05
    r = _ball_steps(any_ball_fmu, tmp_path, {"contact_mode": 2, "e": 0.8}, 0.0, t_end, 1)
    x = r["reals"]
    g, dt = x["g"], t_end - x["flight.t_start"]
    assert x["flight.t_start"] > 0.0 and x["flight.v_start"] > 0.0 and x["flight.h_start"] == 0.0
    assert x["flight.t_start"] == pytest.approx(x["t_rebound"], rel=1e-15)
    assert x["h"] == pytest.approx(x["flight.h_start"] + x["flight.v_start"] * dt - 0.5 * g * dt * dt, rel=1e-12)
    assert x["v"] == pytest.approx(x["flight.v_start"] - g * dt, rel=1e-12, abs=1e-12)


# --- a logger that calls back into the instance ------------------------------------------------
_REENTRANT_LOGGER = r'''
from fmpy.fmi2 import fmi2CallbackLoggerTYPE
nested = []
holder = {}

def reentrant_log(env, name, status, category, message):
    LOG.append((None, int(status), message.decode("utf-8", "replace") if message else ""))
    s = holder.get("s")
    if s is not None and int(status) >= 3 and not nested:  # on the first error: call the same instance
        value = (ctypes.c_double * 1)()
        vr = (ctypes.c_uint * 1)(VR[ARGS[0]])
        nested.append(int(s.fmi2GetReal(s.component, vr, 1, value)))
        nested.append(value[0])

CALLBACKS.logger = fmi2CallbackLoggerTYPE(reentrant_log)
s = instance()
holder["s"] = s
bad = status(s.setReal, [VR[ARGS[1]]], [float("nan")])  # refused: logged with fmi2Error
report(bad=bad, nested=nested, after=status(s.getReal, [VR[ARGS[0]]]))
'''


@pytest.mark.parametrize("model", ["SpherePlateImpact", "BouncingBall"])
@pytest.mark.parametrize("implementation", ["python", "fmi2"])
def test_logger_may_call_the_same_instance(built_fmus, tmp_path, model, implementation):
    """A logger that calls fmi2GetReal on the instance that is logging gets an answer (the message
    is delivered after the call released the instance), instead of a deadlock."""
    fmu = built_fmus / (f"{model}.fmu" if implementation == "python" else f"fmi2/{model}.fmu")
    if not fmu.is_file():
        pytest.skip(f"{fmu} not built here")
    output, parameter = ("e", "v_approach") if model == "SpherePlateImpact" else ("h", "e")
    result = run_child(_REENTRANT_LOGGER, fmu, _unzip(fmu, tmp_path), output, parameter, timeout=WATCHDOG)
    assert result.returncode == 0 and result.report, result.explain()
    r = result.report
    assert r["bad"] == 3  # fmi2Error: the value was refused
    assert r["nested"][0] == 0 and math.isfinite(r["nested"][1])  # the nested call: fmi2OK and a value
    assert r["after"] == 0


# --- sources/ -----------------------------------------------------------------------------------
def _standard_fmi2_headers() -> Path:
    """The FMI 2.0.x headers as the standard publishes them (fmu-manipulation-toolbox ships them;
    fmpy's copy has the function prefix removed)."""
    try:
        import fmu_manipulation_toolbox
    except ImportError:
        pytest.skip("fmu-manipulation-toolbox (the standard FMI 2.0 headers) is not installed")
    path = Path(fmu_manipulation_toolbox.__file__).resolve().parent / "resources" / "fmi"
    if not (path / "fmi2Functions.h").is_file():
        pytest.skip(f"no fmi2Functions.h in {path}")
    return path


def _sources(fmu: Path, into: Path) -> tuple[Path, dict, str]:
    with zipfile.ZipFile(fmu) as z:
        z.extractall(into)
    md = read_model_description(str(fmu))
    return into / "sources", {v.name: v.valueReference for v in md.modelVariables}, md.guid


def _gcc(args, cwd):
    if shutil.which("gcc") is None:
        pytest.skip("gcc not found")
    done = subprocess.run(["gcc", *args], capture_output=True, text=True, cwd=cwd)
    assert done.returncode == 0, done.stderr[-4000:]


def test_two_native_fmus_link_into_one_executable_with_prefixes(native_impact_fmu, native_ball_fmu, tmp_path):
    """Compiled with FMI2_FUNCTION_PREFIX, every external symbol of each FMU carries its prefix, so
    both link into one executable (18 internal names clashed before); the pair then bounces a ball
    (the COR of the first impact from 0.3 m, 2.43 m/s, is between 0 and 1)."""
    headers = _standard_fmi2_headers()
    objects = []
    vrs, guids = {}, {}
    for model, fmu in (("SpherePlateImpact", native_impact_fmu), ("BouncingBall", native_ball_fmu)):
        src, vrs[model], guids[model] = _sources(fmu, tmp_path / model)
        for c_file in sorted(src.glob("*.c")):
            obj = tmp_path / f"{model}_{c_file.stem}.o"
            _gcc(["-std=c99", "-O1", "-Wall", "-Wextra", "-Werror", "-c", f"-DFMI2_FUNCTION_PREFIX={model}_",
                  f"-I{src}", f"-I{headers}", "-o", str(obj), str(c_file)], tmp_path)
            objects.append(obj)
    defined = subprocess.run(["nm", "-g", "--defined-only", *map(str, objects)], capture_output=True, text=True).stdout
    unprefixed = sorted({line.split()[-1] for line in defined.splitlines() if len(line.split()) == 3
                         and not line.split()[-1].startswith(("SpherePlateImpact_", "BouncingBall_"))})
    assert unprefixed == []
    exe = tmp_path / "pair"
    _gcc(["-std=c99", "-Wall", "-Wextra", "-Werror", f"-I{headers}", "-o", str(exe),
          str(HERE / "c_host" / "two_prefixed_fmus.c"), *map(str, objects), "-lm", "-pthread"], tmp_path)
    imp, ball = vrs["SpherePlateImpact"], vrs["BouncingBall"]
    run = subprocess.run([str(exe), guids["SpherePlateImpact"], guids["BouncingBall"], str(imp["v_approach"]),
                          str(imp["e"]), str(ball["v_approach"]), str(ball["e"]), str(ball["h"]),
                          str(ball["impacts"]), str(ball["contact_mode"])],
                         capture_output=True, text=True, timeout=WATCHDOG)
    assert run.returncode == 0, run.stdout[-2000:] + run.stderr[-2000:]
    done = run.stdout.strip().splitlines()[-1].split()
    assert done[0] == "DONE" and int(done[1]) >= 2 and int(done[3]) == 0, run.stdout[-2000:]
    first = next(line.split() for line in run.stdout.splitlines() if line.startswith("BOUNCE "))
    assert 0.0 < float(first[4]) < 1.0


@pytest.mark.parametrize("sanitizer", ["thread", "address,undefined"])
def test_sources_keep_the_lock_of_the_binary(native_ball_fmu, tmp_path, sanitizer):
    """Built from sources/ with only the documented command (every .c file, the FMI 2.0 headers on
    the include path, no -D flag), an instance is still locked: four threads saving, restoring,
    serializing and freeing states, reading and stepping on one instance run clean under the
    sanitizer (four threads in fmi2FreeFMUstate segfaulted before)."""
    import fmpy

    src, vr, guid = _sources(native_ball_fmu, tmp_path / "fmu")
    exe = tmp_path / "threads"
    _gcc(["-std=c99", "-g", "-O1", f"-fsanitize={sanitizer}", "-fno-sanitize-recover=all", f"-I{src}",
          f"-I{Path(fmpy.__file__).parent / 'c-code'}", "-o", str(exe),
          str(HERE / "c_host" / "threads_on_one_instance.c"), *map(str, sorted(src.glob("*.c"))), "-lm", "-pthread"],
         tmp_path)
    run = subprocess.run([str(exe), guid, str(vr["h"])], capture_output=True, text=True, timeout=300,
                         env={"PATH": "/usr/bin:/bin", "TSAN_OPTIONS": "halt_on_error=1"})
    assert run.returncode == 0, run.stdout[-2000:] + run.stderr[-4000:]
    assert run.stdout.strip().splitlines()[-1] == "DONE 0", run.stdout[-2000:]
    assert "WARNING: ThreadSanitizer" not in run.stderr and "runtime error" not in run.stderr, run.stderr[-4000:]


# --- the whole declared domain ------------------------------------------------------------------
_BALL_DOMAIN_SEARCH = r'''
import time
from hypothesis import HealthCheck, given, settings, strategies as st
from fmpy import extract

NATIVE = ARGS[0]
native_md = read_model_description(NATIVE)
native_unzip = extract(NATIVE)
REALS = [v.name for v in MD.modelVariables if v.type == "Real"]
worst = {"seconds": 0.0}
failures = []


def run(unzip, guid, case):
    s = FMU2Slave(guid=guid, unzipDirectory=unzip, modelIdentifier="BouncingBall", instanceName="search")
    s.instantiate(callbacks=CALLBACKS, loggingOn=False)
    s.setupExperiment(startTime=case["t0"])
    s.enterInitializationMode()
    for key in ("h0", "g", "v_min", "e"):
        s.setReal([VR[key]], [case[key]])
    s.setInteger([VR["contact_mode"]], [case["mode"]])
    s.exitInitializationMode()
    t, statuses, trace = case["t0"], [], []
    for h in case["steps"]:
        begin = time.perf_counter()
        statuses.append(status(s.doStep, t, h))
        worst["seconds"] = max(worst["seconds"], time.perf_counter() - begin)
        t += h
        trace.append((list(s.getReal([VR[x] for x in REALS])), s.getInteger([VR["impacts"]])[0],
                      list(s.getBoolean([VR["in_contact"], VR["at_rest"]]))))
    s.terminate()
    s.freeInstance()
    return statuses, trace


# BouncingBall's declared ranges, bounds included: h0 in [0, 1e6] m, g in [1e-6, 1e6] m/s2, v_min >= 1e-6 m/s
height = st.floats(min_value=0.0, max_value=1e6, allow_subnormal=True)
gravity = st.floats(min_value=1e-6, max_value=1e6)


@settings(max_examples=int(ARGS[1]), deadline=None, database=None, derandomize=True,
          suppress_health_check=list(HealthCheck))
@given(h0=height, g=gravity, v_min=st.floats(min_value=1e-6, max_value=1e300),
       e=st.floats(min_value=-1.0, max_value=1.0), mode=st.sampled_from([1, 2]),
       t0=st.floats(min_value=-1e9, max_value=1e9),
       steps=st.lists(st.floats(min_value=1e-9, max_value=1e9), min_size=1, max_size=4))
def search(h0, g, v_min, e, mode, t0, steps):
    case = dict(h0=h0, g=g, v_min=v_min, e=e, mode=mode, t0=t0, steps=steps)
    s_py, tr_py = run(UNZIP, MD.guid, case)
    s_nat, tr_nat = run(native_unzip, native_md.guid, case)
    problems = []
    if s_py != [0] * len(steps) or s_nat != s_py:
        problems.append(f"statuses {s_py} / {s_nat}")
    for (r_py, n_py, b_py), (r_nat, n_nat, b_nat) in zip(tr_py, tr_nat):
        if not all(math.isfinite(x) for x in r_py + r_nat):
            problems.append("non-finite " + repr(dict(zip(REALS, zip(r_py, r_nat)))))
        if n_py != n_nat or b_py != b_nat or not 0 <= n_py <= 2**31 - 1:
            problems.append(f"impacts/flags {n_py} {b_py} / {n_nat} {b_nat}")
        for name, a, b in zip(REALS, r_py, r_nat):
            if not math.isclose(a, b, rel_tol=1e-9, abs_tol=1e-300):
                problems.append(f"{name}: {a!r} / {b!r}")
    if problems:
        failures.append({"case": case, "problems": problems[:5]})


search()
report(failures=failures[:5], n_failures=len(failures), worst_step_seconds=worst["seconds"])
'''


def test_ball_domain_search_returns_finite_and_agrees(ball_fmu, native_ball_fmu, tmp_path):
    """A hypothesis search of BouncingBall's whole declared domain (h0, g in (0, 1e6], any v_min > 0,
    e in [-1, 1], both contact modes, start times to +-1e9 s, steps from 1e-9 to 1e9 s), both
    implementations in one child under the watchdog: every step returns fmi2OK, every Real is finite,
    and the two agree on every variable, locals included (same formulas: 1e-9 relative)."""
    result = run_child(_BALL_DOMAIN_SEARCH, ball_fmu, _unzip(ball_fmu, tmp_path), native_ball_fmu, 150,
                       timeout=4 * WATCHDOG)
    assert result.returncode == 0 and result.report, result.explain()
    assert result.report["n_failures"] == 0, result.report["failures"]
