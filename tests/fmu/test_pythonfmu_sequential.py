"""The two pythonfmu FMUs in one process, one after the other, each extraction folder deleted after use.

pythonfmu puts an FMU's resources/ first on sys.path and imports its slave module by name; each FMU
ships its own copy of ``restitution`` there, and a host may delete the folder when it is done
(``fmpy.simulate_fmu`` does). The second FMU used to fail to instantiate (``No module named
'restitution.fmu.models...'``: sys.modules still held the first FMU's package, whose folder was gone).
The slaves' start-up (fmu/models/restitution_slave_support.py) now decides which code an instance
runs: its FMU's own, or a copy verified to be the same, file for file.

Every scenario runs in a child process (a crash fails one test, not the run), through a hand-made
fmpy ``FMU2Slave`` loop (extract, instantiate, step, free, delete the folder) or ``simulate_fmu``:

* SpherePlateImpact then BouncingBall and the reverse, each three times alternating;
* the same through ``simulate_fmu``;
* in a process that imported ``restitution`` (the installed package) first: it stays the one
  ``import restitution`` gives, whole (``restitution.cosim`` imports);
* both FMUs alive at once in a co-simulation, in either instantiation order; then BouncingBall
  freed and its folder deleted while SpherePlateImpact goes on, through the path that imports a module
  at call time (Zener's ``ode`` method beyond its integration range imports ``zener_exact``);
* a different build of the FMU in the same process (its package, or its slave script, differs by one
  line): it runs its own code, and the original after it runs the original's;
* the slave imported from the package first (as the tests can): the FMU runs it, the same code;
* a build whose package raises on import: it fails to instantiate, with the error logged, before or
  after a good build, and the process goes on.

Numbers: SpherePlateImpact's ``e`` and ``v_rebound`` for its defaults at 2.3 m/s against
:func:`restitution.impact` within each output's conditioning (:mod:`restitution.agreement`), with
0 < e < 1 and v_rebound = e v; BouncingBall's number of impacts against the closed-form bounce times;
in the co-simulation every impact's COR against the package at that impact's speed. No message of
status Warning or worse may be logged.
"""
from __future__ import annotations

import math
import zipfile
from pathlib import Path

import pytest

import restitution as r
from restitution.agreement import tolerances
from restitution.assumptions import departures
from restitution.model import published
from restitution.fmu.models.bouncing_ball.variables import TABLE as BALL

from fmi_child import run_child

V = 2.3  # [m/s] SpherePlateImpact's approach speed in every run
E_BALL = 0.8  # BouncingBall's COR when it runs alone
T_BALL, DT = 1.0, 1e-3  # [s] BouncingBall's run and communication step
H0, G = BALL["h0"].start, BALL["g"].start  # BouncingBall's default drop height [m] and gravity [m/s2]

#: Child helpers, after fmi_child.PRELUDE (FMU: SpherePlateImpact.fmu, ARGS[0]: BouncingBall.fmu, ARGS[1]: the
#: sequence). Each run extracts its FMU into a new folder and deletes it after fmi2FreeInstance.
HELPERS = f"V, E_BALL, T_BALL, DT = {V!r}, {E_BALL!r}, {T_BALL!r}, {DT!r}\n" + r'''
import os, shutil
from fmpy import extract, simulate_fmu

PATHS = {"impact": FMU, "ball": ARGS[0]}
SEQUENCE = ARGS[1].split(",")
SLAVES = {"impact": "sphere_plate_impact_slave", "ball": "bouncing_ball_slave"}


class Run:
    """One FMU extracted into a folder of its own, instantiated and initialised at t = 0."""

    def __init__(self, which, path=None, name=None):
        self.which, self.path = which, str(path or PATHS[which])
        self.md = read_model_description(self.path)
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}
        self.dir = str(extract(self.path))
        self.s = FMU2Slave(guid=self.md.guid, unzipDirectory=self.dir,
                           modelIdentifier=self.md.coSimulation.modelIdentifier, instanceName=name or which)
        self.s.instantiate(callbacks=CALLBACKS, loggingOn=True)
        self.s.setupExperiment(startTime=0.0)
        self.s.enterInitializationMode()
        self.s.exitInitializationMode()
        self.t = 0.0

    def set(self, **values):
        for name, value in values.items():
            if isinstance(value, int):
                self.s.setInteger([self.vr[name]], [value])
            else:
                self.s.setReal([self.vr[name]], [value])

    def reals(self, *names):
        return list(self.s.getReal([self.vr[n] for n in names]))

    def integer(self, name):
        return self.s.getInteger([self.vr[name]])[0]

    def step(self):
        self.s.doStep(self.t, DT)
        self.t += DT

    def close(self):
        self.s.terminate()
        self.s.freeInstance()
        shutil.rmtree(self.dir)
        return not os.path.exists(self.dir)


def impact_once(path=None):
    run = Run("impact", path)
    run.set(v_approach=V)
    run.step()
    e, v_rebound = run.reals("e", "v_rebound")
    return {"which": "impact", "e": e, "v_rebound": v_rebound, "deleted": run.close()}


def ball_once(path=None):
    run = Run("ball", path)
    run.set(e=E_BALL)
    while run.t < T_BALL - DT / 2:
        run.step()
    impacts = run.integer("impacts")
    return {"which": "ball", "impacts": impacts, "deleted": run.close()}


ONCE = {"impact": impact_once, "ball": ball_once}


def simulated(which):
    """One run through fmpy.simulate_fmu, which extracts the FMU and deletes the folder itself."""
    if which == "impact":
        res = simulate_fmu(PATHS[which], start_values={"v_approach": V}, stop_time=DT, output_interval=DT,
                           output=["e", "v_rebound"], logger=_log, debug_logging=True)
        out = {"which": which, "e": float(res["e"][-1]), "v_rebound": float(res["v_rebound"][-1])}
    else:
        res = simulate_fmu(PATHS[which], start_values={"e": E_BALL}, stop_time=T_BALL, output_interval=DT,
                           output=["impacts"], logger=_log, debug_logging=True)
        out = {"which": which, "impacts": int(res["impacts"][-1])}
    out["deleted"] = not os.path.isdir(sys.path[0])  # pythonfmu's entry for this run's resources/
    return out


def instance_code(run):
    """The module globals the class of the slave object pythonfmu created for ``run`` runs with."""
    import gc
    found = [o for o in gc.get_objects()
             if type(o).__name__ == "SpherePlateImpact" and str(getattr(o, "resources", "")).startswith(run.dir)]
    return type(found[0]).__init__.__globals__


def sys_path_state():
    """sys.path entries of FMU resources/ folders: how many, how many of them are gone."""
    entries = [p for p in sys.path if isinstance(p, str) and os.path.basename(os.path.normpath(p)) == "resources"]
    return {"resources_entries": len(entries), "gone": sum(not os.path.isdir(p) for p in entries)}
'''

SEQUENTIAL = HELPERS + r'''
host = None
if "import-first" in ARGS[2:]:
    import restitution as host
    host_file = host.__file__
runs = [(simulated(which) if "simulate" in ARGS[2:] else ONCE[which]()) for which in SEQUENCE]
found = {}
if host is not None:
    import restitution.cosim  # the host's package is still whole
    found = {"host_kept": sys.modules["restitution"] is host and host.__file__ == host_file,
             "cosim": restitution.cosim.__file__.startswith(os.path.dirname(host_file)),
             "bound_host": [sys.modules[SLAVES[w]]._restitution is host for w in sorted(set(SEQUENCE))],
             "bound": [sys.modules[SLAVES[w]]._restitution.__name__ for w in sorted(set(SEQUENCE))]}
report(runs=runs, log=LOG, **sys_path_state(), **found)
'''

COSIM = HELPERS + r'''
# Both FMUs alive at once, coupled: BouncingBall.v_approach -> SpherePlateImpact.v_approach,
# SpherePlateImpact.e -> BouncingBall.e, exchanged at each contact (contact_mode 1: the ball waits at the
# plate for the COR of exactly its impact speed).
runs = {w: Run(w, name=w) for w in SEQUENCE}  # instantiated in the order given
ball, impact = runs["ball"], runs["impact"]
pairs = []
while ball.t < T_BALL - DT / 2:
    ball.step()
    impact.step()
    if ball.s.getBoolean([ball.vr["in_contact"]])[0]:
        v = ball.reals("v_approach")[0]
        impact.set(v_approach=v)
        e = impact.reals("e")[0]
        ball.set(e=e)
        pairs.append((v, e))
impacts = ball.integer("impacts")
# the ball goes, its folder deleted; SpherePlateImpact goes on, also through the import at call time
# (when the ball came first, the package both ran came from the ball's folder, gone now)
deleted = {"ball": ball.close()}
impact.set(**{"zener_method": 4, "plate.t": 1e-4, "v_approach": V})
impact.step()
later = {"ode": impact.reals("e", "zener.lambda")}
impact.set(**{"zener_method": 1, "plate.t": 6.35e-3})
impact.step()
later["exact"] = impact.reals("e", "v_rebound")
deleted["impact"] = impact.close()
# and each again, after both folders are gone
again = [impact_once(), ball_once()]
report(pairs=pairs, impacts=impacts, later=later, deleted=deleted, again=again, log=LOG, **sys_path_state())
'''

VARIANTS = HELPERS + r'''
# ARGS[3:]: (label, impact FMU path) pairs; each is run once, in order, then BouncingBall.
host = None
if ARGS[2] == "import-first":
    import restitution as host
runs = []
items = ARGS[3:]
for label, path in zip(items[::2], items[1::2]):
    run = Run("impact", path)
    run.set(v_approach=V)
    run.step()
    e, v_rebound = run.reals("e", "v_rebound")
    code = instance_code(run)
    package = code["_restitution"]
    runs.append({"label": label, "e": e, "v_rebound": v_rebound,
                 "slave_here": code["__file__"].startswith(run.dir),
                 "cached": code is sys.modules[SLAVES["impact"]].__dict__,
                 "package": package.__name__,
                 "package_here": package.__file__.startswith(run.dir),
                 "about_here": package.about.__file__.startswith(run.dir)})
    run.close()
ball = ball_once()
named = sys.modules.get("restitution")
report(runs=runs, ball=ball, log=LOG, host_kept=(host is None or named is host),
       restitution_file=getattr(named, "__file__", None))
'''

SOURCE_SLAVE = HELPERS + r'''
# The slave imported from the package first, as tests/conftest.py makes possible (ARGS[2:]: the model
# folders): pythonfmu then finds it cached, and the FMU runs it when it is the code the FMU ships.
sys.path[:0] = ARGS[2:]
import sphere_plate_impact_slave as source
run = Run("impact")
run.set(v_approach=V)
run.step()
e, v_rebound = run.reals("e", "v_rebound")
code = instance_code(run)
found = {"source_runs": code is source.__dict__, "source_cached": sys.modules[SLAVES["impact"]] is source,
         "runs_here": code["__file__"].startswith(run.dir)}
deleted = run.close()
report(run={"which": "impact", "e": e, "v_rebound": v_rebound, "deleted": deleted}, log=LOG, **found)
'''

BROKEN = HELPERS + r'''
# ARGS[2:]: (label, impact FMU path) pairs, run in order; a run that cannot instantiate reports why.
runs = []
items = ARGS[2:]
for label, path in zip(items[::2], items[1::2]):
    try:
        run = Run("impact", path, name=label)
    except Exception as exc:  # fmpy: "Failed to instantiate model"
        runs.append({"label": label, "failed": repr(exc)})
        continue
    run.set(v_approach=V)
    run.step()
    e, v_rebound = run.reals("e", "v_rebound")
    runs.append({"label": label, "e": e, "v_rebound": v_rebound, "deleted": run.close()})
report(runs=runs, log=LOG)
'''


def _reference():
    """SpherePlateImpact's defaults (S2 tool steel ball, d = t = 6.35 mm, on Al 6061) at V through the
    package, with the tolerances of e and v_rebound from their conditioning."""
    sphere, plate = r.Sphere(r.MATERIALS["s2_tool_steel"], 6.35e-3), r.Plate(r.MATERIALS["al_6061"], 6.35e-3)
    params = {**sphere.params(), **plate.params()}
    tol, _ = tolerances(V, params)
    return r.impact(V, **params), {k: float(tol[k]) for k in ("e", "v_rebound")}, params


REF, TOL, PARAMS = _reference()


def _ball_impacts(e=E_BALL, t_end=T_BALL):
    """Impacts within t_end of a ball dropped from H0 rebounding with a constant e (contact_mode 1
    rebounds at the next communication point: each flight starts less than DT late, which moves no
    impact across t_end here)."""
    t, v, times = math.sqrt(2.0 * H0 / G), math.sqrt(2.0 * G * H0), []
    while t < t_end:
        times.append(t)
        v *= e
        t += 2.0 * v / G
    assert all(abs(t_end - x) > 20 * DT for x in times) and abs(t_end - t) > 20 * DT
    return len(times)


BALL_IMPACTS = _ball_impacts()


def _check_impact(run, context):
    e, v_rebound = run["e"], run["v_rebound"]
    assert 0.0 < e < 1.0, context
    assert abs(e - REF.e) <= TOL["e"], (context, e, REF.e, TOL["e"])
    assert abs(v_rebound - REF.v_rebound) <= TOL["v_rebound"], (context, v_rebound, REF.v_rebound)
    assert abs(v_rebound - e * V) <= TOL["v_rebound"], context


def _check_runs(runs, sequence):
    assert [run["which"] for run in runs] == sequence
    for k, run in enumerate(runs):
        context = f"run {k + 1} ({run['which']})"
        assert run["deleted"], f"{context}: its extraction folder was not deleted"
        if run["which"] == "impact":
            _check_impact(run, context)
        else:
            assert run["impacts"] == BALL_IMPACTS, context


def _check_log(log, thin_plate=None):
    """No message of status Warning (1) or worse, but the model's own word that an impact left the validated
    domain, where the scenario makes one on purpose (``thin_plate``: the impact() result of that case): the
    lines of restitution.assumptions for it, each once."""
    expected = []
    if thin_plate is not None:
        expected = [text for _name, text in departures(published(thin_plate.as_dict()))]
    said = [entry[2] for entry in log if entry[1] == 1]
    bad = [entry for entry in log if entry[1] > 1 or (entry[1] == 1 and entry[2] not in expected)]
    assert not bad, bad
    assert len(said) == len(set(said)), said  # once per instance and condition


PACKAGE_ROOT = Path(r.__file__).resolve().parent
MODELS = PACKAGE_ROOT / "fmu" / "models"
#: The slave scripts and the support module an FMU ships beside its package, and their files in the package.
SCRIPTS = {"resources/sphere_plate_impact_slave.py": MODELS / "sphere_plate_impact" / "sphere_plate_impact_slave.py",
           "resources/bouncing_ball_slave.py": MODELS / "bouncing_ball" / "bouncing_ball_slave.py",
           "resources/restitution_slave_support.py": MODELS / "restitution_slave_support.py"}


def _same_as_host(*fmus, scripts=False) -> bool:
    """Whether every file the FMUs ship in resources/restitution (and with ``scripts``, their slave script
    and support module) is, byte for byte, the file of the package this process imported (the FMUs are
    built from the working tree, which others may be editing meanwhile)."""
    for fmu in fmus:
        with zipfile.ZipFile(fmu) as z:
            for name in z.namelist():
                if name.startswith("resources/restitution/") and not name.endswith("/"):
                    path = PACKAGE_ROOT.parent / name[len("resources/"):]
                elif scripts and name in SCRIPTS:
                    path = SCRIPTS[name]
                else:
                    continue
                if not path.is_file() or path.read_bytes() != z.read(name):
                    return False
    return True


def _host_child(code, impact_fmu, ball_fmu, tmp_path, *args, scripts=False):
    """``_child`` for a child that imports restitution first, and whether the host's package was the same
    code as the FMUs' before and after it (the test cannot tell what to expect when that changed)."""
    same = _same_as_host(impact_fmu, ball_fmu, scripts=scripts)
    got = _child(code, impact_fmu, ball_fmu, tmp_path, *args)
    if _same_as_host(impact_fmu, ball_fmu, scripts=scripts) != same:
        pytest.skip("the package's files changed on disk during the test")
    return got, same


def _sequence(first):
    other = "ball" if first == "impact" else "impact"
    return [first, other] * 3


def _child(code, impact_fmu, ball_fmu, tmp_path, *args):
    result = run_child(code, impact_fmu, tmp_path, ball_fmu, *args)
    assert result.returncode == 0 and result.report is not None, result.explain()
    return result.report


@pytest.mark.parametrize("first", ["impact", "ball"])
@pytest.mark.parametrize("host", ["fmu2slave", "simulate_fmu"])
def test_one_after_the_other_with_each_folder_deleted(impact_fmu, ball_fmu, tmp_path, first, host):
    sequence = _sequence(first)
    args = [",".join(sequence)] + (["simulate"] if host == "simulate_fmu" else [])
    got = _child(SEQUENTIAL, impact_fmu, ball_fmu, tmp_path, *args)
    _check_runs(got["runs"], sequence)
    _check_log(got["log"])
    # pythonfmu adds an entry per instantiation; the start-up leaves only the last run's (deleted after it)
    assert got["resources_entries"] <= 1 and got["gone"] <= 1, got


@pytest.mark.parametrize("host", ["fmu2slave", "simulate_fmu"])
def test_a_host_that_imported_restitution_first_keeps_it(impact_fmu, ball_fmu, tmp_path, host):
    """The host's own restitution (the installed package, the same files as the FMUs ship) stays what
    ``import restitution`` gives, whole, and the slaves run it: the same code, verified file by file."""
    sequence = _sequence("ball")
    args = [",".join(sequence), "import-first"] + (["simulate"] if host == "simulate_fmu" else [])
    got, same = _host_child(SEQUENTIAL, impact_fmu, ball_fmu, tmp_path, *args)
    _check_runs(got["runs"], sequence)
    _check_log(got["log"])
    assert got["host_kept"] and got["cosim"], got
    if same:
        assert all(got["bound_host"]), got
    else:  # the working tree has moved on since the build: the FMUs' own copy, under a private name
        assert not any(got["bound_host"]) and all(n.startswith("_restitution_fmu_") for n in got["bound"]), got


@pytest.mark.parametrize("first", ["impact", "ball"])
def test_both_alive_at_once_then_the_ball_goes_and_the_impact_goes_on(impact_fmu, ball_fmu, tmp_path, first):
    other = "ball" if first == "impact" else "impact"
    got = _child(COSIM, impact_fmu, ball_fmu, tmp_path, f"{first},{other}")
    _check_log(got["log"], thin_plate=r.impact(V, **dict(PARAMS, plate_t=1e-4), zener_method="ode"))
    assert got["impacts"] > 0 and len(got["pairs"]) == got["impacts"], got
    for v, e in got["pairs"]:  # every impact's COR is the package's for that impact's speed
        tol, _ = tolerances(v, PARAMS)
        assert 0.0 < e < 1.0 and abs(e - r.impact(v, **PARAMS).e) <= float(tol["e"]), (v, e)
    assert got["deleted"] == {"ball": True, "impact": True}
    params = dict(PARAMS, plate_t=1e-4)
    ref = r.impact(V, **params, zener_method="ode")
    assert ref.lam > 100.0  # beyond the ODE's range: zener_ode imports zener_exact at call time
    tol, _ = tolerances(V, params, zener_method="ode")
    e, lam = got["later"]["ode"]
    assert abs(e - ref.e) <= float(tol["e"]) and abs(lam - ref.lam) <= float(tol["lam"]), (e, lam, ref)
    _check_impact(dict(zip(("e", "v_rebound"), got["later"]["exact"])), "after the ball's folder went")
    _check_runs(got["again"], ["impact", "ball"])


def _variant(source, target, member, line=b"# another build"):
    """A copy of the FMU ``source`` with ``line`` appended to ``member``: another build, other code."""
    with zipfile.ZipFile(source) as zin, zipfile.ZipFile(target, "w", zipfile.ZIP_DEFLATED) as zout:
        assert member in zin.namelist()
        for info in zin.infolist():
            data = zin.read(info)
            zout.writestr(info, data + b"\n" + line + b"\n" if info.filename == member else data)
    return target


@pytest.mark.parametrize("host", ["fmu-only", "import-first"])
def test_a_different_build_runs_its_own_code(impact_fmu, ball_fmu, tmp_path, host):
    """A build whose package differs gets its own copy under a private name (the restitution already
    loaded stays as it is); a build whose slave script differs gets its own slave class; the original
    after them runs the original's code again (pythonfmu would have kept the cached module's class).
    Checked on the slave object pythonfmu created: the module globals its class runs with."""
    package_variant = _variant(impact_fmu, tmp_path / "package_variant.fmu", "resources/restitution/about.py")
    slave_variant = _variant(impact_fmu, tmp_path / "slave_variant.fmu", "resources/sphere_plate_impact_slave.py")
    items = ["original", impact_fmu, "package", package_variant, "slave", slave_variant, "original again", impact_fmu]
    if host == "import-first":
        got, same = _host_child(VARIANTS, impact_fmu, ball_fmu, tmp_path, "", host, *items)
    else:
        got, same = _child(VARIANTS, impact_fmu, ball_fmu, tmp_path, "", host, *items), False
    _check_log(got["log"])
    runs = {run["label"]: run for run in got["runs"]}
    for run in got["runs"]:
        _check_impact(run, run["label"])
        assert run["cached"], run  # the module the next instantiation finds is the one this instance runs
    assert runs["original"]["slave_here"]
    # the package variant: a slave of its own, bound to its own package under a private name
    assert runs["package"]["slave_here"] and runs["package"]["package"].startswith("_restitution_fmu_")
    assert runs["package"]["package_here"] and runs["package"]["about_here"]
    # the slave variant and the original again: their own slave scripts, bound to the package they ship
    # (the same files as the first run's, or the host's when that is the same code)
    for label in ("slave", "original again"):
        assert runs[label]["slave_here"] and runs[label]["package"] == runs["original"]["package"], runs[label]
    assert got["host_kept"]
    if host == "import-first":
        assert got["restitution_file"] == r.__file__  # the host's restitution is still the one of its name
    if same:  # the host's package, verified the same
        assert runs["original"]["package"] == "restitution" and not runs["original"]["package_here"]
    elif host == "import-first":  # the working tree has moved on since the build: the FMU's own copy
        assert runs["original"]["package"].startswith("_restitution_fmu_") and runs["original"]["package_here"]
    else:  # no restitution in the process: the first FMU's copy took the name
        assert runs["original"]["package"] == "restitution" and runs["original"]["package_here"]
    assert got["ball"]["impacts"] == BALL_IMPACTS and got["ball"]["deleted"]


def test_a_slave_imported_from_the_package_first_runs_when_it_is_the_same_code(impact_fmu, ball_fmu, tmp_path):
    """The tests import a slave from the package (conftest.py) and may then instantiate the FMU in the same
    process: pythonfmu finds that module cached. It runs when it is the code the FMU ships (its script,
    the support module and the package, compared file by file), else the FMU's own script is loaded."""
    folders = [MODELS / "sphere_plate_impact", MODELS]
    got, same = _host_child(SOURCE_SLAVE, impact_fmu, ball_fmu, tmp_path, "", *folders, scripts=True)
    _check_log(got["log"])
    _check_runs([got["run"]], ["impact"])
    if same:
        assert got["source_runs"] and got["source_cached"], got
    else:  # the working tree has moved on since the build: the FMU's own script
        assert got["runs_here"] and not got["source_runs"] and not got["source_cached"], got


def test_a_build_whose_code_fails_to_start_fails_to_instantiate_and_the_process_goes_on(
        impact_fmu, ball_fmu, tmp_path):
    """A build whose package raises on import fails to instantiate with that error logged, first in the
    process (pythonfmu's import fails) or after another build (pythonfmu's second execution, on which an
    exception would crash the process: the start-up hands pythonfmu a callable that raises it instead);
    the good build before and after it runs."""
    broken = _variant(impact_fmu, tmp_path / "broken.fmu", "resources/restitution/about.py",
                      b'raise RuntimeError("a broken build")')
    for items in (["good", impact_fmu, "broken", broken, "good", impact_fmu, "broken", broken],
                  ["broken", broken, "good", impact_fmu, "broken", broken, "good", impact_fmu]):
        got = _child(BROKEN, impact_fmu, ball_fmu, tmp_path, "", *items)
        assert [run["label"] for run in got["runs"]] == items[::2]
        for run in got["runs"]:
            if run["label"] == "good":
                _check_impact(run, "good")
                assert run["deleted"]
            else:
                assert "Failed to instantiate" in run["failed"], run
        problems = [entry for entry in got["log"] if entry[1] >= 1]
        assert problems and all(name == "broken" for name, _status, _text in problems), problems
        fatal = [text for _name, status, text in problems if status == 4]
        assert len(fatal) == 2 and all("a broken build" in text for text in fatal), fatal
