"""SpherePlateImpact.fmu in a plain C FMI host, as a desktop simulation tool runs it: both
implementations (pythonfmu behind the C guard, and native), and the native FMU as FMI 2.0 and as FMI 3.0.

The host (tests/c_host/fmi_script_host.c, compiled here with the system C compiler, once per FMI
version, ``-DFMI_VERSION=2|3``) opens
the FMU binary with dlopen(RTLD_LOCAL) and runs with a minimal environment: ``env -i
PATH=/usr/bin:/bin`` (no LD_PRELOAD, no PYTHONPATH/PYTHONHOME, no virtual environment). The
pythonfmu FMU's loader must find the interpreter and packages it was built with by itself; the
native FMU never loads libpython (the host reports what is mapped into its process).

Checked: instantiate, set up, initialise, set (Real and Integer), step, get (Real and
Boolean), bad input (logged, fmi2Error, the previous value kept, the other instance unaffected),
FMU state and its serialization across instances, reset, terminate, free, a clean process exit;
every number against the package (within each output's conditioning, restitution.agreement).
And, for the pythonfmu FMU, when the interpreter or the packages are missing: a clear log
message, a NULL instance, no crash.
Model exchange (native FMUs, FMI 2.0 and 3.0): BouncingBall integrated by the host's own solver, its
contacts against the closed-form free-fall times; SpherePlateImpact's outputs in continuous-time mode
against the package.
"""
from __future__ import annotations

import math
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path
from xml.etree import ElementTree

import pytest

import numpy as np
import restitution as r
from restitution.agreement import tolerances
from restitution.cosim import impact_fmu_parameters

from script_host import ball_me_script, ball_run, build_host, check_ball_run, interface

ROOT = Path(__file__).resolve().parents[2]
MODEL = "SpherePlateImpact"

pytestmark = [
    pytest.mark.skipif(not sys.platform.startswith("linux"), reason="Linux-only (linux64 guard)"),
    pytest.mark.skipif(shutil.which("gcc") is None, reason="gcc not available"),
]

REALS = {"e": "e", "v_rebound": "v_rebound", "jgm.e": "e_ep", "jgm.V_c": "V_c", "jgm.V_star": "V_star",
         "zener.e": "e_ze", "zener.lambda": "lam", "zener.tau0": "tau0", "zener.t_contact": "t_contact",
         "plate.mass_ratio": "mass_ratio", "plate.v_after": "v_plate"}
FLAGS = {"valid": "valid", "zener.in_range": "lambda_in_range", "jgm.in_range": "vstar_in_range",
         "e_negative": "e_negative", "effects.plasticity": "plasticity_used", "effects.plate_waves": "plate_waves_used"}
MATERIALS = [
    (r.Sphere(r.MATERIALS["s2_tool_steel"], 6.35e-3), r.Plate(r.MATERIALS["al_6061"], 6.35e-3)),
    (r.Sphere(r.MATERIALS["tungsten_carbide"], 4.76e-3), r.Plate(r.MATERIALS["borosilicate_glass"], 1.0e-3)),
]
SPEEDS = [0.0, 1e-3, 0.5, 2.3, 30.0]


@pytest.fixture(scope="module")
def hosts(tmp_path_factory):
    """The script host built for FMI 2.0 and for FMI 3.0: {2: exe, 3: exe}."""
    out = tmp_path_factory.mktemp("c_host")
    return {v: build_host(out / f"fmi{v}_script_host", v) for v in (2, 3)}


@pytest.fixture(scope="module")
def host(hosts):
    return hosts[2]


@pytest.fixture(scope="module", params=["python", "fmi2", "fmi3"])
def host_impact_fmu(request):
    """SpherePlateImpact.fmu as pythonfmu (FMI 2.0), native FMI 2.0 and native FMI 3.0 (the native ones
    skip, saying so, where gcc did not build them)."""
    fixture = {"python": "impact_fmu", "fmi2": "native_impact_fmu", "fmi3": "fmi3_impact_fmu"}[request.param]
    return request.getfixturevalue(fixture)


@pytest.fixture(scope="module")
def fmu_info(impact_fmu):
    with zipfile.ZipFile(impact_fmu) as z:
        root = ElementTree.fromstring(z.read("modelDescription.xml"))
        config = z.read("resources/python_env.txt").decode()
    variables = {sv.get("name"): int(sv.get("valueReference")) for sv in root.find("ModelVariables")}
    types = {sv.get("name"): sv[0].tag for sv in root.find("ModelVariables")}
    return {"guid": root.get("guid"), "vr": variables, "type": types, "config": config}


def unpack(impact_fmu, dest: Path) -> Path:
    with zipfile.ZipFile(impact_fmu) as z:
        z.extractall(dest)
    return dest


class Run:
    """One run of the C host: its exit code, statuses, values and log lines, in order."""

    def __init__(self, proc):
        self.returncode, self.stdout, self.stderr = proc.returncode, proc.stdout, proc.stderr
        self.statuses, self.values, self.logs = [], [], []
        self.libpython = None
        for line in proc.stdout.splitlines():
            head, _, rest = line.partition(" ")
            if head == "LIBPYTHON":
                self.libpython = rest.strip() == "1"
            elif head == "STATUS":
                self.statuses.append(tuple(rest.split()))
            elif head in ("REAL", "BOOLEAN"):
                slot, vr, value = rest.split()
                self.values.append(float(value) if head == "REAL" else bool(int(value)))
            elif head == "LOG":
                self.logs.append(rest)


def run_host(host, unpacked, guid, script: list[str], model: str = MODEL) -> Run:
    proc = subprocess.run(["env", "-i", "PATH=/usr/bin:/bin", str(host), str(unpacked), model, guid],
                          input="\n".join(script) + "\n", capture_output=True, text=True, timeout=300,
                          env={"PATH": "/usr/bin:/bin"})
    return Run(proc)


def same(got, want, tol):
    """Equal, or within the conditioning-derived tolerance (restitution.agreement): the FMU's
    embedded interpreter is another process, and the ode method's adaptive steps may differ."""
    return got == want or (math.isnan(got) and math.isnan(want)) or abs(got - want) <= tol


def test_the_fmu_runs_in_a_plain_c_host_and_matches_the_package(hosts, host_impact_fmu, tmp_path):
    """The same script for the three FMUs; only the calls differ where the versions do (the host's
    -DFMI_VERSION: FMI 3.0 gives the start time to fmi3EnterInitializationMode, sets the Enumerations
    with fmi3SetInt64 and reads the Booleans as C bool)."""
    fmu = interface(host_impact_fmu)
    native = fmu.version == 3 or "fmi2" in host_impact_fmu.parts
    vr = fmu.vr
    script, expected = [], []  # expected: ("real"/"bool", reference value, context) per value printed
    clock = [0.0, 0.0]  # each instance's communication point

    def set_all(slot, settings):
        for name, value in settings.items():
            script.append(fmu.set(slot, name, value))

    def step(slot):
        script.append(f"step {slot} {clock[slot]!r} 0.001")
        clock[slot] += 0.001

    def read(slot, settings, context):
        ref, tol, flips = reference(settings)
        script.append(f"get_real {slot} " + " ".join(str(vr[n]) for n in REALS))
        expected.extend(("real", getattr(ref, f), (context, n), float(tol[f][0])) for n, f in REALS.items())
        script.append(f"get_boolean {slot} " + " ".join(str(vr[n]) for n in FLAGS))
        expected.extend(("bool", bool(getattr(ref, f)), (context, n), bool(flips[f][0])) for n, f in FLAGS.items())

    settings = [dict(impact_fmu_parameters(*pair)) for pair in MATERIALS]
    for slot, name in enumerate(("impact_a", "impact_b")):
        script.append(f"instantiate {name}")
    for slot in (0, 1):
        script += [f"setup {slot} 0.0", f"enter_init {slot}"]
        set_all(slot, settings[slot])
        script.append(f"exit_init {slot}")
    for method in (1, 2, 3) if native else (1, 2, 3, 4):  # ode (4) is the Python FMU's only
        for model in (1, 2):
            for v in SPEEDS:
                for slot in (0, 1):  # the two instances interleaved
                    settings[slot].update(zener_method=method, restitution_model=model, v_approach=v)
                    set_all(slot, {"zener_method": method, "restitution_model": model, "v_approach": v})
                    step(slot)
                    read(slot, settings[slot], (slot, method, model, v))
    # bad input in instance 1: refused with fmi2Error and logged; the previous value is kept
    script.append(f"set_real 1 {vr['plate.t']} nan")
    step(1)
    read(1, settings[1], "after the refused value")
    step(0)
    read(0, settings[0], "bystander")
    # FMU state: saved, changed, restored; serialized from instance 0 into instance 1
    script += ["get_state 0", "serialize 0", f"set_real 0 {vr['v_approach']} 7.5", f"set_real 0 {vr['plate.t']} 0.05"]
    saved = clock[0]
    read(0, {**settings[0], "v_approach": 7.5, "plate.t": 0.05}, "changed")
    step(0)
    script += ["set_state 0"]
    clock[0] = saved  # the state holds the communication point too
    read(0, settings[0], "restored")
    step(0)
    script += ["deserialize 1 0", "set_state 1"]
    clock[1] = saved
    step(1)
    read(1, settings[0], "deserialized into the other instance")
    # reset: start values again
    script += ["reset 1", "setup 1 0.0", "enter_init 1", "exit_init 1"]
    clock[1] = 0.0
    step(1)
    read(1, {}, "after reset")
    script += ["free_state 0", "free_state 1", "terminate 0", "terminate 1", "free 0", "free 1"]

    run = run_host(hosts[fmu.version], unpack(host_impact_fmu, tmp_path / "fmu"), fmu.token, script)
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr  # also: no crash at process exit
    assert run.stdout.startswith(f"INFO {fmu.version}.0 "), run.stdout[:200]
    assert run.libpython == (not native), "libpython is in the native FMU's process" if native else run.stdout[-300:]
    if not native:
        assert any("pythonfmu guard: started embedded Python" in line for line in run.logs), run.logs[:3]
    bad = [s for s in run.statuses if s[2] != "OK"]
    assert bad == [("set_real", "1", "Error")], bad
    assert any(line.startswith("impact_b Error") and "plate.t = nan is outside the allowed range: 1e-07 <= value <= 100"
               in line for line in run.logs), run.logs
    assert len(run.values) == len(expected) > 600
    for got, (kind, want, context, tol) in zip(run.values, expected):
        assert (got == want or tol) if kind == "bool" else same(got, want, tol), (context, got, want, tol)


@pytest.mark.parametrize("folder", ["fmi2", "fmi3"])
def test_model_exchange_in_a_plain_c_host(hosts, built_fmus, folder, tmp_path):
    """The native FMUs as model exchange in the plain C host (env -i, dlopen RTLD_LOCAL), FMI 2.0 and 3.0.

    BouncingBall, integrated by the host's own solver (fmi_script_host.c: integrate, Heun steps with each
    contact a state event): events bisected to 1e-10 s in steps of 1 ms, and located to the step alone in
    steps of 0.1 ms; the contacts at the closed-form free-fall times, no earlier than the exact crossing
    and no later than the resolution carried through the flights (script_host.check_ball_run), the ball
    at rest at the 8th with the indicator held at 1 m. SpherePlateImpact: no states, no indicators; its
    outputs after set_time in continuous-time mode, and after parameters changed in event mode, equal
    the package within each output's conditioning (restitution.agreement)."""
    ball_path, impact_path = (built_fmus / folder / f"{m}.fmu" for m in ("BouncingBall", MODEL))
    if not ball_path.is_file() or not impact_path.is_file():
        pytest.skip(f"{folder} FMUs not built here (needs gcc)")
    ball = interface(ball_path)
    unpacked = unpack(ball_path, tmp_path / "ball")
    for dt, tol in ((1e-3, 1e-10), (1e-4, 0.0)):
        run = run_host(hosts[ball.version], unpacked, ball.token, ball_me_script(ball, dt, tol), model="BouncingBall")
        assert run.returncode == 0, run.stdout[-3000:] + run.stderr
        assert run.libpython is False
        check_ball_run(ball_run(run.stdout), dt, tol)

    fmu = interface(impact_path)
    assert (fmu.n_states, fmu.n_indicators) == (0, 0)
    vr = fmu.vr
    settings = [dict(impact_fmu_parameters(*pair)) for pair in MATERIALS]
    script, expected, t = fmu.me_start(0, "impact_me", settings[0]), [], 0.0
    script += ["get_states 0 0", "get_indicators 0 0", "get_derivatives 0 0", "get_nominals 0 0"]
    for k, pair_settings in enumerate(settings):
        if k:  # parameters change in event mode
            script += ["enter_event 0", *(fmu.set(0, n, v) for n, v in pair_settings.items()), "update_discrete 0",
                       "enter_ct 0"]
        for method in (1, 2, 3):
            script += ["enter_event 0", fmu.set(0, "zener_method", method), "update_discrete 0", "enter_ct 0"]
            for v in SPEEDS:
                t += 1e-3
                script += [fmu.set(0, "v_approach", v), f"set_time 0 {t!r}", "completed_step 0",
                           "get_real 0 " + " ".join(str(vr[n]) for n in REALS)]
                ref, tol, _flips = reference({**pair_settings, "zener_method": method, "v_approach": v})
                expected += [(getattr(ref, f), float(tol[f][0]), (k, method, v, n)) for n, f in REALS.items()]
    script += ["terminate 0", "free 0"]
    run = run_host(hosts[fmu.version], unpack(impact_path, tmp_path / "impact"), fmu.token, script)
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr
    assert [s for s in run.statuses if s[2] != "OK"] == [], run.statuses
    assert "DISCRETE 0 0 0 0 0 0 0" in run.stdout and "COMPLETED 0 0 0" in run.stdout
    assert len(run.values) == len(expected)
    for got, (want, tol, context) in zip(run.values, expected):
        assert same(got, want, tol), (context, got, want, tol)


def reference(settings):
    """(package result, tolerance per output, flags that may differ) for the FMU's settings."""
    s = {"v_approach": 1.0, **impact_fmu_parameters(*MATERIALS[0]), "zener_method": 1, "restitution_model": 1}
    s.update(settings)
    params = {name.replace(".", "_"): s[name] for name in ("sphere.E", "sphere.nu", "sphere.Sy", "sphere.rho",
                                                           "sphere.d", "plate.E", "plate.nu", "plate.Sy",
                                                           "plate.rho", "plate.t")}
    options = dict(zener_method=r.ZENER_METHODS[s["zener_method"] - 1],
                   restitution_model=r.RESTITUTION_MODELS[s["restitution_model"] - 1])
    ref = r.impact(s["v_approach"], **params, **options)
    tol, flips = tolerances(np.array([float(s["v_approach"])]), {k: np.array([float(v)]) for k, v in params.items()},
                            **options)
    return ref, tol, flips


def test_the_fmu_requires_only_what_its_model_imports(fmu_info):
    """The loader checks the required modules at start-up; host-side helpers (fmpy, dask, ...) are not bundled."""
    lines = dict(line.split("=", 1) for line in fmu_info["config"].splitlines() if "=" in line and line[0] != "#")
    required = set(lines["require"].split(","))
    assert "numpy" in required and required <= {"numpy", "scipy"}, required
    assert lines["use_environment"] == "0" and Path(lines["libpython"]).is_file()


def _edit_config(unpacked: Path, **replace) -> None:
    cfg = unpacked / "resources" / "python_env.txt"
    lines = []
    for line in cfg.read_text().splitlines():
        key = line.split("=", 1)[0]
        if key in replace:
            if replace[key] is None:
                continue
            line = f"{key}={replace[key]}"
        lines.append(line)
    cfg.write_text("\n".join(lines) + "\n")


def test_missing_interpreter_gives_a_clear_message_and_no_crash(host, impact_fmu, fmu_info, tmp_path):
    """The FMU moved to a machine without its Python: NULL instance, a message saying what it needs."""
    unpacked = unpack(impact_fmu, tmp_path / "moved")
    gone = "/nonexistent/pyenv/versions/3.11.7"
    _edit_config(unpacked, libpython=f"{gone}/lib/libpython3.11.so.1.0", executable="/nonexistent/venv/bin/python",
                 home=gone)
    run = run_host(host, unpacked, fmu_info["guid"], ["instantiate impact", "setup 0 0.0"])
    assert run.returncode == 3, run.stdout + run.stderr  # NULL instance reported; no signal, no abort
    assert "INSTANTIATE_FAILED" in run.stdout
    errors = [line for line in run.logs if line.startswith("impact Error")]
    assert len(errors) == 1, run.logs
    message = errors[0]
    for needed in ("cannot load the Python shared library", f"{gone}/lib/libpython3.11.so.1.0", "python_env.txt",
                   "Python 3.11", "/nonexistent/venv/bin/python", "--enable-shared"):
        assert needed in message, (needed, message)


def test_environment_without_the_packages_names_them(host, impact_fmu, fmu_info, tmp_path):
    """The recorded interpreter exists but its environment lacks numpy and scipy (a fresh venv)."""
    venv = tmp_path / "empty_venv"
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(venv)], check=True)
    site = next((venv / "lib").glob("python3*/site-packages"))
    unpacked = unpack(impact_fmu, tmp_path / "fmu")
    _edit_config(unpacked, executable=str(venv / "bin" / "python"), site=str(site))
    run = run_host(host, unpacked, fmu_info["guid"], ["instantiate impact"])
    assert run.returncode == 3 and "INSTANTIATE_FAILED" in run.stdout, run.stdout + run.stderr
    message = next(line for line in run.logs if line.startswith("impact Error"))
    for needed in ("numpy", "scipy", "ModuleNotFoundError", str(venv / "bin" / "python"), "pip install",
                   "python_env.txt"):
        assert needed in message, (needed, message)


def test_missing_configuration_gives_a_clear_message(host, impact_fmu, fmu_info, tmp_path):
    unpacked = unpack(impact_fmu, tmp_path / "nocfg")
    (unpacked / "resources" / "python_env.txt").unlink()
    run = run_host(host, unpacked, fmu_info["guid"], ["instantiate impact"])
    assert run.returncode == 3 and "INSTANTIATE_FAILED" in run.stdout
    assert any("needs a Python interpreter" in line and "python_env.txt" in line for line in run.logs), run.logs
