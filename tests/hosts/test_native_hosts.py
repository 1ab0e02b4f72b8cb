"""The native FMUs (C only, no Python: DIR/fmi2/*.fmu) in real hosts, each test skipping
with the reason where its tool is missing. (The win64 DLL under Wine: tests/fmu/test_native_win64.py.)

1. OSP libcosim (libcosimpy): BouncingBall + SpherePlateImpact from the OspSystemStructure.xml that
   examples/two_fmu_cosim.py writes and runs (its ``run_libcosim``), native pair and pythonfmu pair,
   each in a child process. Checked as tests/docs/test_examples.py checks the pythonfmu pair: five bounces,
   bounce times within 5 steps of the event-exact master (restitution.cosim.bounce on the package),
   the one-step lag visible in the apex, apex heights within what the step allows; and, for every one
   of the five rebounds, the COR applied is the package's for the ball's speed at the last communication
   point before the contact (libcosim's documented lag); native and pythonfmu bounce times and heights
   agree within the error of the CORs (restitution.agreement) carried through the flights.
2. The ``ecos`` command-line engine of the ecospy wheel (plain C++, reads SSP): an SSP of the two native
   FMUs written here, run by ``ecos simulate`` in a child process; its CSV (6 decimals) against the same
   run through fmpy (a master stepping the same FMUs in ecos's order, read from ecos's
   fixed_step_algorithm.cpp and simulation.cpp: step every FMU and read its outputs, transfer the
   connections from those values, set, read again), and against the event-exact master as for libcosim.
   ecos exits 0 and writes zeros when an FMU fails to instantiate: the values are checked, never the
   exit code alone. It divides by numSteps / 10 (SIGFPE below 10 steps): the runs here take 99 and
   999 steps (ecos steps while t + h <= stop, t summed step by step, as the fmpy run does).
   The same with the FMI 3.0 pair (fmi3/*.fmu), against the same fmpy run of the FMI 2.0 pair (the FMI 3.0
   FMUs compute what the FMI 2.0 ones do, to 4e-16: tests/fmu/test_fmi3.py). ecos 0.7.2 (fmi4c inside)
   loads FMI 3.0 FMUs and handles Float64, Int32 and Boolean variables, but skips every Enumeration
   ("is of unsupported type, skipping"): the SSP cannot set the ball's contact_mode, whose start value is
   the 1 the SSP asks for, so the run is still the one compared.
3. ``fmutool -check`` (fmu-manipulation-toolbox) says "No semantic error" and fmpy's validation finds no
   problem, for both native FMUs, FMI 2.0 and FMI 3.0; both checkers do flag an FMU with one start value
   removed (so they read what they are given). The platforms fmutool lists are the archive's binaries/
   folders; the Windows one is asserted where the build produced it (mingw-w64 or zig installed), else that test
   skips naming the compiler (tests/fmu_platforms.py).
"""
from __future__ import annotations

import importlib.util
import json
import math
import os
import re
import subprocess
import sys
import textwrap
import zipfile
from pathlib import Path

import numpy as np
import pytest

import restitution as r
from restitution.agreement import EPS, tolerances
from restitution.fmu.ssp import CONNECTIONS  # the SSP's: ball.v_approach -> impact.v_approach, impact.e -> ball.e
from restitution.cosim import CosimResult, ball_bounces, bounce, impact_fmu_parameters, package_rebound

from fmu_platforms import binary_folders, skip_unless_built

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "two_fmu_cosim.py"
G = 9.80665
DROP = 0.3  # [m]
T_END = 1.0  # [s]
N_BOUNCES = 5
STEPS = (1e-2, 1e-3)  # [s] communication steps, as tests/docs/test_examples.py
#: The ball's parameters in the SSP (ecos): contact_mode 1 waits at the plate for the COR; v_min is not its
#: default (0.1 m/s), to show that the SSP's parameter set reaches the FMU.
BALL = {"h0": DROP, "g": G, "contact_mode": 1, "v_min": 0.05}


def _example():
    spec = importlib.util.spec_from_file_location("native_hosts_two_fmu_cosim", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def system():
    """The example's system (S2 tool-steel ball, d = 6.35 mm, on Al 6061, t/d = 1), its FMU parameters,
    the package's parameters, and the event-exact reference: restitution.cosim.bounce on the package."""
    example = _example()
    sphere, plate = example.default_system()
    package_params = {**sphere.params(), **plate.params()}
    exact = bounce(package_rebound(**package_params), drop_height=DROP, gravity=G)
    assert exact.n_impacts >= N_BOUNCES and exact.time[N_BOUNCES - 1] < T_END
    return {"example": example, "fmu_params": {k: float(v) for k, v in impact_fmu_parameters(sphere, plate).items()},
            "params": package_params, "exact": exact}


def _package_e(params, v):
    """(e, tolerance of e) from the package at speed v: restitution.agreement's per-case bound."""
    e = float(r.impact(v, **params).e)
    tol, _flips = tolerances(np.array([v]), {k: np.array([x]) for k, x in params.items()})
    return e, float(tol["e"][0])


def _log_slope(params, v, step=1e-6):
    """|d ln e / d ln v| at v, by central differences on the package."""
    up, down = (float(r.impact(v * (1 + f), **params).e) for f in (step, -step))
    return abs(math.log(up) - math.log(down)) / (2 * step)


def _speeds_before_contacts(time, bounces, n):
    """The ball's approach speed at the last communication point before each of its first ``n``
    contacts, from the flight it was on (released from rest, or the previous rebound)."""
    speeds = []
    for k in range(n):
        t_before = float(time[time < bounces["t_impact"][k]].max())
        if k == 0:
            v = G * t_before
        else:
            v = G * (t_before - bounces["t_rebound"][k - 1]) - bounces["v_rebound"][k - 1]
        assert v > 0.0, (k, t_before)  # falling at that point: the flights here are longer than a step
        speeds.append(v)
    return speeds


def _assert_coupled_like_the_reference(result, system, h, resolution=0.0):
    """The assertions of tests/docs/test_examples.py for libcosim's fixedStep, and the lag for every rebound.

    ``resolution``: how finely the host wrote its values (ecos's CSV: 6 decimals, so 5e-7)."""
    cmp = system["example"].compare(result, system["exact"], N_BOUNCES)
    assert cmp["bounces"] == N_BOUNCES, cmp
    assert cmp["dt_max"] < 5 * h + resolution, cmp["dt_max"]  # each rebound waits for a communication point
    assert cmp["apex_rel_max"] > 1e-5  # the one-step lag of the COR is visible
    b = cmp["bounce_data"]
    for k, v in enumerate(_speeds_before_contacts(result.time, b, N_BOUNCES)):
        want, tol = _package_e(system["params"], v)
        assert abs(b["e_applied"][k] - want) <= tol + resolution, (k, v, b["e_applied"][k], want, tol)
    # What the step allows in the heights: each COR is taken at a speed at most g h below the impact speed, so
    # it is off by at most s g h / v relatively (s = |d ln e / d ln v|); that error is carried into every later
    # impact speed (and through s once more into its COR). Apex = v_rebound^2 / 2g: twice the relative error.
    exact, carried = system["exact"], 0.0
    for k in range(N_BOUNCES):
        v, s = exact.v_approach[k], _log_slope(system["params"], exact.v_approach[k])
        carried = carried * (1 + s) + s * G * h / v
        allowed = 2 * (2 * carried) + 2 * resolution / b["v_rebound"][k]  # x2: margin
        assert abs(b["apex"][k] / exact.apex[k] - 1.0) <= allowed, (k, b["apex"][k], exact.apex[k], allowed)
    return b


# --- 1. OSP libcosim --------------------------------------------------------------------------------
LIBCOSIM_CHILD = textwrap.dedent('''
    import importlib.util, json, sys
    from pathlib import Path

    cfg = json.loads(sys.argv[1])
    spec = importlib.util.spec_from_file_location("two_fmu_cosim", cfg["example"])
    example = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(example)
    runs = []
    for step in cfg["steps"]:
        res = example.run_libcosim(cfg["ball"], cfg["impact"], cfg["params"], cfg["drop_height"], step,
                                   cfg["t_end"], Path(cfg["work_dir"]))
        runs.append({"step": step, "time": res.time.tolist(), "steps": res.steps, "structure": res.extra["structure"],
                     "values": {k: v.tolist() for k, v in res.values.items()}})
    print("RESULT " + json.dumps(runs))
''')


def _libcosim(fmu_dir: Path, system, work_dir: Path) -> dict:
    cfg = {"example": str(EXAMPLE), "ball": str(fmu_dir / "BouncingBall.fmu"),
           "impact": str(fmu_dir / "SpherePlateImpact.fmu"), "params": system["fmu_params"], "drop_height": DROP,
           "t_end": T_END, "steps": list(STEPS), "work_dir": str(work_dir)}
    proc = subprocess.run([sys.executable, "-c", LIBCOSIM_CHILD, json.dumps(cfg)], capture_output=True, text=True,
                          timeout=600)
    assert proc.returncode == 0, f"libcosim child exited {proc.returncode}\n{proc.stdout[-2000:]}\n{proc.stderr[-4000:]}"
    line = next(line for line in proc.stdout.splitlines() if line.startswith("RESULT "))
    runs = {}
    for run in json.loads(line[len("RESULT "):]):
        runs[run["step"]] = CosimResult(time=np.array(run["time"]), values={k: np.array(v) for k, v in run["values"].items()},
                                        step_size=run["step"], wall_time=0.0, steps=run["steps"],
                                        master="libcosim fixedStep", extra={"structure": run["structure"]})
    return runs


@pytest.fixture(scope="module")
def libcosim_runs(built_fmus, native_ball_fmu, native_impact_fmu, system, tmp_path_factory):
    pytest.importorskip("libcosimpy", reason="libcosimpy (OSP libcosim) not installed")
    work = tmp_path_factory.mktemp("libcosim")
    return {"fmi2": _libcosim(native_impact_fmu.parent, system, work / "fmi2"),
            "python": _libcosim(built_fmus, system, work / "python")}


@pytest.mark.parametrize("h", STEPS)
def test_libcosim_runs_the_native_pair_from_the_examples_system_structure(libcosim_runs, native_impact_fmu, system,
                                                                           h):
    from xml.etree import ElementTree as ET

    res = libcosim_runs["fmi2"][h]
    structure = ET.parse(res.extra["structure"]).getroot()
    ns = {"osp": "http://opensimulationplatform.com/MSMI/OSPSystemStructure"}
    sources = {s.get("name"): (Path(res.extra["structure"]).parent / s.get("source")).resolve()
               for s in structure.findall("osp:Simulators/osp:Simulator", ns)}
    assert sources == {"ball": (native_impact_fmu.parent / "BouncingBall.fmu").resolve(),
                       "impact": native_impact_fmu.resolve()}
    assert float(structure.find("osp:BaseStepSize", ns).text) == h
    assert res.steps == round(T_END / h) and res.time[-1] == pytest.approx(T_END, abs=1e-12)
    _assert_coupled_like_the_reference(res, system, h)


@pytest.mark.parametrize("h", STEPS)
def test_libcosim_native_pair_agrees_with_the_pythonfmu_pair(libcosim_runs, system, h):
    """Same libcosim, same OspSystemStructure.xml, the two implementations: the pythonfmu pair passes the
    same checks, rebounds at the same communication points, and the first five bounce times and heights
    agree within what the CORs may differ by (restitution.agreement), carried from flight to flight."""
    native = ball_bounces(libcosim_runs["fmi2"][h], G)
    python = _assert_coupled_like_the_reference(libcosim_runs["python"][h], system, h)
    assert native["t_rebound"].size == python["t_rebound"].size >= N_BOUNCES
    np.testing.assert_allclose(native["t_rebound"], python["t_rebound"], rtol=0, atol=1e-12)  # communication points
    speeds = _speeds_before_contacts(libcosim_runs["python"][h].time, python, N_BOUNCES)
    drift = 0.0  # bound on the relative difference of the rebound speeds so far
    for k, v in enumerate(speeds):
        if k == 0:  # free fall from the drop height
            assert native["t_impact"][0] == pytest.approx(python["t_impact"][0], rel=64 * EPS, abs=0)
        else:  # the flight to contact k started at rebound k - 1
            allowed = 2 * (2.0 / G * python["v_rebound"][k - 1] * drift) + 64 * EPS * python["t_impact"][k]
            assert abs(native["t_impact"][k] - python["t_impact"][k]) <= allowed, k
        e, tol = _package_e(system["params"], v)
        # the COR's own tolerance, plus its response to the approach speed's difference carried so far
        drift = drift * (1 + _log_slope(system["params"], v)) + tol / abs(e) + 32 * EPS
        assert abs(native["apex"][k] / python["apex"][k] - 1.0) <= 2 * (2 * drift), k


# --- 2. ecos (the ecospy wheel's command-line engine) ------------------------------------------------
PARAMETER_SET = "initialValues"
#: Compared with the fmpy run, every communication point: all the ball's outputs and its COR input, the
#: impact FMU's input and outputs the bounces depend on.
ECOS_COMPARED = {
    "ball": ("h", "v", "v_approach", "impacts", "t_impact", "v_impact", "t_rebound", "v_rebound", "e_applied",
             "in_contact", "at_rest", "e"),
    "impact": ("v_approach", "e", "v_rebound", "jgm.e", "jgm.V_c", "zener.e", "zener.lambda", "zener.t_contact",
               "valid"),
}
CSV_RESOLUTION = 5e-7  # ecos writes every value with 6 decimals


def write_ssp(path: Path, ball_fmu: Path, impact_fmu: Path, impact_params: dict, step: float) -> Path:
    """An SSP 1.0 archive (restitution.fmu.ssp.inline_ssp): SystemStructure.ssd with the two components,
    their parameters as the inline parameter set PARAMETER_SET (Enumerations as Integer codes, which ecos
    reads), the two connections, the step as OSP's FixedStepAlgorithm annotation; the FMUs in resources/."""
    from restitution.fmu.ssp import inline_ssp

    return inline_ssp(path, {"ball": ball_fmu, "impact": impact_fmu}, {"ball": BALL, "impact": impact_params},
                      step, set_name=PARAMETER_SET)


@pytest.fixture(scope="module")
def ecos_exe(tmp_path_factory):
    """The wheel's ``ecos`` engine and its environment (tests/ecos_engine.py)."""
    from ecos_engine import ecos_engine

    return ecos_engine(tmp_path_factory.mktemp("ecos"))


def run_ecos(ecos, ssp: Path, step: float, stop: float, cwd: Path, log: list | None = None) -> dict:
    """``ecos simulate`` in a child process; the CSV it writes ({column: values}, column = "instance::variable");
    its output is appended to ``log`` when given."""
    assert round(stop / step) >= 10, "ecos divides by numSteps / 10: fewer than 10 steps crash it (SIGFPE)"
    cwd.mkdir(parents=True, exist_ok=True)
    proc = subprocess.run([str(ecos.exe), "simulate", "--path", str(ssp), "--stepSize", repr(step), "--stopTime",
                           repr(stop), "--parameterSet", PARAMETER_SET, "--logLevel", "warn"],
                          cwd=cwd, capture_output=True, text=True, timeout=300, env=ecos.env)
    assert proc.returncode == 0, f"ecos exited {proc.returncode}\n{proc.stdout[-2000:]}\n{proc.stderr[-2000:]}"
    if log is not None:
        log.append(proc.stdout + proc.stderr)
    csv = cwd / f"{ssp.stem}.csv"
    assert csv.is_file(), proc.stdout[-2000:] + proc.stderr[-2000:]
    lines = csv.read_text().splitlines()
    header = [c.strip() for c in lines[0].split(",")]
    rows = [[float(x) for x in line.split(",")] for line in lines[1:] if line.strip()]
    data = np.array(rows, dtype=float)
    columns = {}
    for i, name in enumerate(header):
        columns[name.rsplit("[", 1)[0]] = data[:, i]
    return columns


#: The same run through fmpy, in a child process: the two native FMUs stepped in the order ecos uses
#: (ecos 0.7.2, src/ecos/algorithm/fixed_step_algorithm.cpp and src/ecos/simulation.cpp): each FMU does
#: its fmi2DoStep and its outputs are read; the connections are transferred from those values; the
#: inputs are set and the outputs read again; time advances as ecos's, t = t + h, while t + h <= stop (so a
#: run to 1 s with h = 0.01 takes 99 steps: the sum of 99 steps is 0.99000000000000066).
FMPY_CHILD = textwrap.dedent('''
    import json, sys
    from restitution.cosim import FmuInstance

    cfg = json.loads(sys.argv[1])
    conns = cfg["connections"]
    with FmuInstance(cfg["impact"], "impact", parameters=cfg["impact_params"]) as impact, \\
            FmuInstance(cfg["ball"], "ball", parameters=cfg["ball_params"]) as ball:
        fmus = {"ball": ball, "impact": impact}

        def transfer():
            values = [fmus[a].get(av)[0] for a, av, _b, _bv in conns]  # every source first (ecos caches them)
            for (_a, _av, b, bv), value in zip(conns, values):
                fmus[b].set(**{bv: value})

        def row(t):
            return [t] + [float(x) for name, variables in cfg["compared"].items() for x in fmus[name].get(*variables)]

        for _ in range(3):  # ecos's initialisation: two transfers before fmi2ExitInitializationMode, one after
            transfer()
        t, rows = 0.0, [row(0.0)]
        while t + cfg["step"] <= cfg["stop"]:
            for fmu in fmus.values():
                fmu.do_step(t, cfg["step"])
            transfer()
            t = t + cfg["step"]
            rows.append(row(t))
    print("RESULT " + json.dumps(rows))
''')


def run_fmpy_like_ecos(ball_fmu, impact_fmu, impact_params, step, stop) -> dict:
    cfg = {"ball": str(ball_fmu), "impact": str(impact_fmu), "impact_params": impact_params, "ball_params": BALL,
           "connections": CONNECTIONS, "compared": ECOS_COMPARED, "step": step, "stop": stop}
    proc = subprocess.run([sys.executable, "-c", FMPY_CHILD, json.dumps(cfg)], capture_output=True, text=True,
                          timeout=600)
    assert proc.returncode == 0, f"fmpy child exited {proc.returncode}\n{proc.stderr[-4000:]}"
    line = next(line for line in proc.stdout.splitlines() if line.startswith("RESULT "))
    data = np.array(json.loads(line[len("RESULT "):]), dtype=float)
    names = ["time"] + [f"{inst}::{v}" for inst, variables in ECOS_COMPARED.items() for v in variables]
    return {name: data[:, i] for i, name in enumerate(names)}


@pytest.fixture(scope="module")
def fmpy_like_ecos_runs(ecos_exe, native_ball_fmu, native_impact_fmu, system):
    """The reference of every ecos run: the FMI 2.0 native pair stepped by fmpy in ecos's order, per step."""
    return {h: run_fmpy_like_ecos(native_ball_fmu, native_impact_fmu, system["fmu_params"], h, T_END) for h in STEPS}


@pytest.fixture(scope="module", params=["fmi2", "fmi3"])
def ecos_runs(request, ecos_exe, built_fmus, fmpy_like_ecos_runs, system, tmp_path_factory):
    """ecos running the native pair of one FMI version (fmi2/: FMI 2.0, fmi3/: FMI 3.0) from an SSP."""
    folder = request.param
    ball, impact = (built_fmus / folder / f"{m}.fmu" for m in ("BouncingBall", "SpherePlateImpact"))
    if not (ball.is_file() and impact.is_file()):
        pytest.skip(f"{folder}/ FMUs not built here (needs gcc)")
    work = tmp_path_factory.mktemp(f"ecos_runs_{folder}")
    runs, log = {}, []
    for h in STEPS:
        ssp = write_ssp(work / f"bounce_{h:.0e}.ssp", ball, impact, system["fmu_params"], h)
        runs[h] = {"ecos": run_ecos(ecos_exe, ssp, h, T_END, work / f"run_{h:.0e}", log), "fmpy": fmpy_like_ecos_runs[h]}
    if folder == "fmi3":
        _assert_ecos_skips_only_enumerations(ball, impact, "\n".join(log))
    return runs


def _assert_ecos_skips_only_enumerations(ball: Path, impact: Path, log: str):
    """ecos 0.7.2 with FMI 3.0 FMUs: the variables it skips are exactly the Enumerations, and the one the SSP
    sets (the ball's contact_mode) starts at the value the SSP gives it, so the run is the compared one."""
    from xml.etree import ElementTree as ET

    enumerations = set()
    for fmu in (ball, impact):
        with zipfile.ZipFile(fmu) as z:
            root = ET.fromstring(z.read("modelDescription.xml"))
        for v in root.find("ModelVariables"):
            if v.tag == "Enumeration":
                enumerations.add(v.get("name"))
                if fmu == ball and v.get("name") == "contact_mode":
                    assert int(v.get("start")) == BALL["contact_mode"]
    skipped = set(re.findall(r"Variable named '([^']+)' is of unsupported type, skipping", log))
    assert skipped == enumerations, (skipped, enumerations)


def _ecos_result(columns, h) -> CosimResult:
    n = columns["iterations"].size
    time = columns["iterations"] * h  # the CSV's time column has 6 significant digits
    values = {name.replace("::", ".", 1): column for name, column in columns.items() if name.startswith("ball::")}
    return CosimResult(time=time, values=values, step_size=h, wall_time=0.0, steps=n - 1, master="ecos")


@pytest.mark.parametrize("h", STEPS)
def test_ecos_runs_the_native_pair_from_an_ssp_like_fmpy(ecos_runs, system, h):
    """ecos's CSV equals, to its 6 decimals, fmpy stepping the FMI 2.0 native pair in ecos's order (for the
    FMI 3.0 pair too: both versions run one C core; the values differ by at most a few ulps)."""
    ecos, fmpy = ecos_runs[h]["ecos"], ecos_runs[h]["fmpy"]
    n = fmpy["time"].size - 1  # steps while t + h <= T_END, t summed step by step
    assert round(T_END / h) - 1 <= n <= round(T_END / h)
    np.testing.assert_array_equal(ecos["iterations"], np.arange(n + 1))
    # real values, not the zeros ecos writes when an FMU failed to instantiate: the drop height, the parameter
    # set (v_min, the impact FMU's parameters), the paper's V_c = 0.0265 m/s (Green 2022, Sec. 7), bounces
    assert ecos["ball::h"][0] == DROP and np.all(ecos["ball::v_min"] == BALL["v_min"])
    for name, value in system["fmu_params"].items():
        assert np.all(np.abs(ecos[f"impact::{name}"] - value) <= CSV_RESOLUTION + 4 * EPS * value), name
    assert np.all(np.abs(ecos["impact::jgm.V_c"] - 0.0265) < 5e-5) and ecos["ball::impacts"][-1] >= N_BOUNCES
    for name, want in fmpy.items():
        if name == "time":
            continue
        got = ecos[name]
        same = (got == want) | (np.isnan(got) & np.isnan(want))
        close = np.abs(got - want) <= CSV_RESOLUTION * (1 + 1e-9) + 4 * EPS * np.abs(want)
        bad = np.flatnonzero(~(same | close))
        assert bad.size == 0, f"{name}: first at iteration {bad[0]}: ecos {got[bad[0]]!r}, fmpy {want[bad[0]]!r}"


@pytest.mark.parametrize("h", STEPS)
def test_ecos_bounces_agree_with_the_event_exact_master(ecos_runs, system, h):
    _assert_coupled_like_the_reference(_ecos_result(ecos_runs[h]["ecos"], h), system, h, resolution=CSV_RESOLUTION)


# --- 3. FMI checkers ------------------------------------------------------------------------------
def _fmutool():
    script = Path(sys.executable).parent / "fmutool"
    if importlib.util.find_spec("fmu_manipulation_toolbox") is None or not script.is_file():
        pytest.skip("fmu-manipulation-toolbox not installed (pip install fmu-manipulation-toolbox==2.0; "
                    "in the dev extra)")
    return script


def run_fmutool_check(fmu: Path) -> tuple[int, str]:
    """``fmutool -input FMU -summary -check`` in a child process: (exit code, whole output). Its exit code
    is nonzero when -check finds errors (7 for the FMU below), but an exception inside fmutool (seen
    with a ModelStructure index out of range) is printed with exit code 0: the output is checked too."""
    proc = subprocess.run([str(_fmutool()), "-input", str(fmu), "-summary", "-check"], capture_output=True,
                          text=True, timeout=300, env=dict(os.environ, NO_COLOR="1"))
    return proc.returncode, proc.stdout + proc.stderr


_FMUTOOL_REPORTS: dict = {}


def fmutool_report(fmu: Path) -> tuple[int, str]:
    """:func:`run_fmutool_check` of a built FMU, run once per test session (two tests read it)."""
    if fmu not in _FMUTOOL_REPORTS:
        _FMUTOOL_REPORTS[fmu] = run_fmutool_check(fmu)
    return _FMUTOOL_REPORTS[fmu]


def fmutool_platforms(report: str) -> set[str]:
    """The binaries/ folders fmutool's summary lists under "Supported platforms" (without its "RT
    (sources available)", which says that sources/ is there)."""
    lines = report.splitlines()
    start = next(i for i, line in enumerate(lines) if "Supported platforms:" in line)
    listed = set()
    for line in lines[start + 1:]:
        item = line.split("|")[-1].strip()
        if not item.startswith("- "):
            break
        listed.add(item[2:])
    return listed - {"RT (sources available)"}


def _native_fmu(built_fmus, folder, model) -> Path:
    fmu = built_fmus / folder / f"{model}.fmu"
    if not fmu.is_file():
        pytest.skip(f"{folder}/{model}.fmu not built here (needs gcc)")
    return fmu


def _without_a_start_value(fmu: Path, out: Path) -> Path:
    """A copy of ``fmu`` whose first parameter has lost its start value (FMI 2.0 section 2.2.7 wants one)."""
    with zipfile.ZipFile(fmu) as src, zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED) as dst:
        for item in src.infolist():
            data = src.read(item.filename)
            if item.filename == "modelDescription.xml":
                text = data.decode("utf-8")
                at = text.index('causality="parameter"')
                start = text.index(" start=", at)
                end = text.index('"', start + len(' start="'))
                data = (text[:start] + text[end + 1:]).encode("utf-8")
            dst.writestr(item, data)
    return out


@pytest.mark.parametrize("folder", ["fmi2", "fmi3"])
@pytest.mark.parametrize("model", ["SpherePlateImpact", "BouncingBall"])
def test_fmutool_and_fmpy_find_no_problem_in_the_native_fmu(built_fmus, native_impact_fmu, native_ball_fmu, model,
                                                            folder, tmp_path):
    """Each native FMU, FMI 2.0 (fmi2/) and FMI 3.0 (fmi3/): fmutool's conformity and semantic checks of
    its version and fmpy's validation find nothing; both flag the FMU with one start value removed. The
    platforms fmutool lists are the binaries/ folders in the archive, the Linux one among them (the
    Windows one where mingw-w64 or zig built it: test_fmutool_lists_the_windows_binary_platform)."""
    from fmpy.validation import validate_fmu

    fmu = _native_fmu(built_fmus, folder, model)
    version, linux = ("2", "linux64") if folder == "fmi2" else ("3", "x86_64-linux")
    code, report = fmutool_report(fmu)
    assert code == 0, report[-3000:]
    assert f"fmiVersion = {version}.0" in report, report[-3000:]
    assert f"This FMU seems to be compliant with FMI-{version}.0." in report, report[-3000:]
    assert f"No semantic error against the FMI-{version} standard." in report, report[-3000:]
    assert "ERROR" not in report and "Traceback" not in report, report[-3000:]
    assert f"modelIdentifier = {model}" in report, report[-3000:]
    assert fmutool_platforms(report) == set(binary_folders(fmu)) and linux in binary_folders(fmu), report[-3000:]
    assert "- RT (sources available)" in report, report[-3000:]
    assert validate_fmu(str(fmu)) == []
    # both checkers read what they are given: one start value removed is one error for each
    broken = _without_a_start_value(fmu, tmp_path / f"{model}_broken.fmu")
    code, report = run_fmutool_check(broken)
    assert code != 0 and f"1 semantic error(s) against the FMI-{version} standard." in report, report[-3000:]
    assert "a start value is required" in report, report[-3000:]
    assert validate_fmu(str(broken)) != []


@pytest.mark.parametrize("folder", ["fmi2", "fmi3"])
@pytest.mark.parametrize("model", ["SpherePlateImpact", "BouncingBall"])
def test_fmutool_lists_the_windows_binary_platform(built_fmus, model, folder):
    """Where the build produced the Windows x64 binary (mingw-w64 or zig installed; skipped, naming them, where
    not), fmutool lists its platform (FMI 2.0: win64, FMI 3.0: x86_64-windows) beside the Linux one (and the
    others the build wrote: macOS, Linux aarch64)."""
    fmu = _native_fmu(built_fmus, folder, model)
    windows = skip_unless_built(fmu, "win64")
    code, report = fmutool_report(fmu)
    linux = "linux64" if folder == "fmi2" else "x86_64-linux"
    assert code == 0 and {linux, windows} <= fmutool_platforms(report) == set(binary_folders(fmu)), report[-3000:]
