"""The native FMI 3.0 co-simulation FMUs (``fmi3/``): the same C core as the FMI 2.0 native FMUs behind
a thin FMI 3.0 layer. They must validate, compute what the FMI 2.0 native FMU computes, refuse every
hostile call with an error (never fmi3Fatal) and keep the previous values, carry their states across
FMI versions, and bounce a ball at the analytic free-fall times."""
from __future__ import annotations

import math
import shutil
import zipfile
from pathlib import Path
from xml.etree import ElementTree as ET

import pytest
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi2 import FMU2Slave
from fmpy.fmi3 import FMU3Slave
from fmpy.validation import validate_fmu

from hypothesis import given, settings

from cases import CASES, FMU_FLAGS, FMU_REALS, PAIRS, SPEEDS, T_OVER_D, params_for
from fmi_child import run_child
from restitution.fmu.models import table

IMPACT = table("SpherePlateImpact")
FMU_NAME = {key: row.name for key, row in IMPACT.by_key().items()}  # package keyword -> FMU name


@pytest.fixture(scope="module")
def fmi3_impact(fmi3_impact_fmu):
    return fmi3_impact_fmu


@pytest.fixture(scope="module")
def fmi3_ball(fmi3_ball_fmu):
    return fmi3_ball_fmu


class Loaded:
    """An FMU unzipped once, instantiated as an FMI 2.0 or 3.0 slave, initialised at t = 0."""

    def __init__(self, fmu: Path, name="t"):
        self.md = read_model_description(str(fmu))
        self.dir = extract(str(fmu))
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}
        self.fmi3 = self.md.fmiVersion.startswith("3")
        cls = FMU3Slave if self.fmi3 else FMU2Slave
        token = self.md.instantiationToken if self.fmi3 else self.md.guid
        self.s = cls(guid=token, unzipDirectory=self.dir, modelIdentifier=self.md.coSimulation.modelIdentifier,
                     instanceName=name)
        self.s.instantiate()

    def initialise(self, parameters: dict):
        if self.fmi3:
            self.s.enterInitializationMode(startTime=0.0)
        else:
            self.s.setupExperiment(startTime=0.0)
            self.s.enterInitializationMode()
        self.set_reals(parameters)
        self.s.exitInitializationMode()

    def set_reals(self, values: dict):
        setter = self.s.setFloat64 if self.fmi3 else self.s.setReal
        setter([self.vr[n] for n in values], list(values.values()))

    def reals(self, names):
        getter = self.s.getFloat64 if self.fmi3 else self.s.getReal
        return list(getter([self.vr[n] for n in names]))

    def flags(self, names):
        return [bool(x) for x in self.s.getBoolean([self.vr[n] for n in names])]

    def close(self):
        self.s.terminate()
        self.s.freeInstance()
        shutil.rmtree(self.dir, ignore_errors=True)


def test_fmi3_fmus_validate_and_declare_their_sources(fmi3_impact, fmi3_ball):
    """fmpy's validation (FMI 3.0 schema and its checks) finds nothing; sources/buildDescription.xml names
    exactly the .c files in sources/, and the FMI 3.0 layer, not the FMI 2.0 one, is among them."""
    for fmu in (fmi3_impact, fmi3_ball):
        assert validate_fmu(str(fmu)) == []
        with zipfile.ZipFile(fmu) as z:
            names = z.namelist()
            build = ET.fromstring(z.read("sources/buildDescription.xml"))
        c_files = sorted(n.split("/", 1)[1] for n in names if n.startswith("sources/") and n.endswith(".c"))
        declared = sorted(f.get("name") for f in build.iter("SourceFile"))
        assert declared == c_files and "rst_fmi3.c" in c_files and "rst_fmi2.c" not in c_files
        assert any(n.startswith("binaries/x86_64-linux/") for n in names)


def test_fmi3_impact_equals_the_fmi2_native_fmu_over_the_hard_cases(native_impact_fmu, fmi3_impact):
    """Over the hard-case matrix (8 material pairs x 10 speeds x 7 thickness ratios), every output of the
    FMI 3.0 FMU equals the FMI 2.0 native FMU's. Both run the same C physics built with the same flags;
    the version layers only copy doubles, so the tolerance is a few ulps (4e-16 relative), which a
    layer that converted a value through another type (float, integer) or mixed up two value
    references would exceed by orders of magnitude."""
    reals, flags = list(FMU_REALS), list(FMU_FLAGS)
    two, three = Loaded(native_impact_fmu), Loaded(fmi3_impact)
    try:
        for pair in PAIRS:
            for t_over_d in T_OVER_D:
                params = {FMU_NAME[k]: v for k, v in params_for(pair, t_over_d).items()}
                for fmu in (two, three):
                    fmu.s.reset()
                    fmu.initialise(params)
                for v in SPEEDS:
                    outs = []
                    for fmu in (two, three):
                        fmu.set_reals({"v_approach": v})
                        outs.append((fmu.reals(reals), fmu.flags(flags)))
                    (r2, f2), (r3, f3) = outs
                    context = f"{pair}, t/d = {t_over_d}, v = {v}"
                    assert f3 == f2, context
                    for name, a, b in zip(reals, r2, r3):
                        assert math.isclose(a, b, rel_tol=4e-16, abs_tol=0.0), f"{name}: {a} != {b} ({context})"
    finally:
        two.close()
        three.close()


@pytest.fixture(scope="module")
def both_versions(native_impact_fmu, fmi3_impact_fmu):
    """The native FMI 2.0 and FMI 3.0 SpherePlateImpact, initialised, for a search over the domain."""
    pair = (Loaded(native_impact_fmu, "two"), Loaded(fmi3_impact_fmu, "three"))
    for fmu in pair:
        fmu.initialise({})
    yield pair
    for fmu in pair:
        fmu.close()


@settings(max_examples=300, deadline=None)
@given(CASES)
def test_fmi3_impact_equals_the_fmi2_native_fmu_over_the_declared_domain(both_versions, case):
    """A hypothesis search of the declared domain (every parameter log-uniform over its range, every
    choice): the FMI 3.0 FMU's outputs equal the FMI 2.0 native FMU's to a few ulps (the same C
    evaluation; see the hard-case test), flags exactly, and the choices read back as set."""
    reals = {FMU_NAME[k]: float(v) for k, v in case.items() if IMPACT[FMU_NAME[k]].type == "Real"}
    codes = {FMU_NAME[k]: IMPACT[FMU_NAME[k]].codes[v] for k, v in case.items() if IMPACT[FMU_NAME[k]].choices}
    outs = []
    for fmu in both_versions:
        fmu.set_reals(reals)
        set_codes = fmu.s.setInt64 if fmu.fmi3 else fmu.s.setInteger
        set_codes([fmu.vr[n] for n in codes], list(codes.values()))
        get_codes = fmu.s.getInt64 if fmu.fmi3 else fmu.s.getInteger
        assert list(get_codes([fmu.vr[n] for n in codes])) == list(codes.values())
        outs.append((fmu.reals(list(FMU_REALS)), fmu.flags(list(FMU_FLAGS))))
    (r2, f2), (r3, f3) = outs
    assert f3 == f2
    for name, a, b in zip(FMU_REALS, r2, r3):
        assert math.isclose(a, b, rel_tol=4e-16, abs_tol=0.0), f"{name}: {a} != {b} ({case})"


def test_fmi3_materials_are_enumerations_set_with_int64(fmi3_impact):
    """plate.material is an Enumeration (got and set with fmi3Get/SetInt64): naming a preset makes the
    calculated parameters plate.used.* that preset's properties (the package's values)."""
    from restitution.fmu.models.sphere_plate_impact.variables import MATERIAL_CHOICES
    import restitution as r

    md = read_model_description(str(fmi3_impact))
    material = next(v for v in md.modelVariables if v.name == "plate.material")
    assert material.type == "Enumeration" and material.declaredType.name == "Material"
    fmu = Loaded(fmi3_impact)
    try:
        code = MATERIAL_CHOICES.index("tungsten_carbide")
        fmu.s.enterInitializationMode(startTime=0.0)
        fmu.s.setInt64([fmu.vr["plate.material"]], [code])
        fmu.s.exitInitializationMode()
        assert list(fmu.s.getInt64([fmu.vr["plate.material"]])) == [code]
        used = fmu.reals(["plate.used.E", "plate.used.nu", "plate.used.Sy", "plate.used.rho"])
        preset = r.MATERIALS["tungsten_carbide"]
        assert used == [preset.E, preset.nu, preset.Sy, preset.rho]
    finally:
        fmu.close()


HOSTILE = r'''
from fmpy.fmi3 import FMU3Slave, fmi3IntermediateUpdateCallback, fmi3LogMessageCallback
import ctypes
LOG3 = []
def log3(env, status, category, message):
    LOG3.append((int(status), message.decode("utf-8", "replace")))
CB = fmi3LogMessageCallback(log3)

def status3(function, *args):
    try:
        function(*args)
        return 0
    except FMICallException as exc:
        return exc.status

def slave3():
    s = FMU3Slave(guid=MD.instantiationToken, unzipDirectory=UNZIP, modelIdentifier=MD.coSimulation.modelIdentifier,
                  instanceName="hostile")
    s.instantiate(loggingOn=True, logMessage=log3)
    return s

results = {}
s = slave3()
results["step_before_init"] = status3(s.doStep, 0.0, 1e-3)
s.enterInitializationMode(startTime=0.0)
s.exitInitializationMode()
v = VR["v_approach"]
s.setFloat64([v], [2.0])
results["negative_speed"] = status3(s.setFloat64, [v], [-1.0])
results["nan_speed"] = status3(s.setFloat64, [v], [float("nan")])
results["kept_speed"] = list(s.getFloat64([v]))[0]
results["int32_on_enumeration"] = status3(s.setInt32, [VR["zener_method"]], [2])
results["enumeration_out_of_range"] = status3(s.setInt64, [VR["zener_method"]], [99])
results["kept_method"] = list(s.getInt64([VR["zener_method"]]))[0]
results["set_time"] = status3(s.setFloat64, [len(MD.modelVariables) - 1], [5.0])
results["set_output"] = status3(s.setFloat64, [VR["e"]], [0.5])
results["unknown_vr"] = status3(s.getFloat64, [10**6])
results["get_string"] = status3(s.getString, [v])
vrs = (ctypes.c_uint32 * 1)(v)
vals = (ctypes.c_double * 1)(3.0)
lib = s.dll
lib.fmi3SetFloat64.restype = ctypes.c_int
results["n_values_mismatch"] = lib.fmi3SetFloat64(ctypes.c_void_p(s.component), vrs, ctypes.c_size_t(1), vals, ctypes.c_size_t(0))
lib.fmi3DoStep.restype = ctypes.c_int
results["null_out_arguments"] = lib.fmi3DoStep(ctypes.c_void_p(s.component), ctypes.c_double(0.0), ctypes.c_double(1e-3),
                                               ctypes.c_bool(True), None, None, None, None)
results["kept_speed_after_all"] = list(s.getFloat64([v]))[0]
results["time_before_step"] = list(s.getFloat64([len(MD.modelVariables) - 1]))[0]
s.doStep(0.0, 1e-3)
results["time_after_step"] = list(s.getFloat64([len(MD.modelVariables) - 1]))[0]
results["skipped_step"] = status3(s.doStep, 5.0, 1e-3)
results["bad_state_bytes"] = status3(s.deserializeFMUState, b"RSTFMUST" + b"\0" * 40)
results["enter_event_mode"] = status3(s.enterEventMode)
# instantiation refusals: another token, event mode, model exchange (before freeInstance unloads the library)
lib.fmi3InstantiateCoSimulation.restype = ctypes.c_void_p
lib.fmi3InstantiateModelExchange.restype = ctypes.c_void_p
results["wrong_token"] = lib.fmi3InstantiateCoSimulation(b"x", b"{not-the-token}", None, False, True, False, False,
                                                         None, ctypes.c_size_t(0), None, CB, fmi3IntermediateUpdateCallback())
results["event_mode"] = lib.fmi3InstantiateCoSimulation(b"x", MD.instantiationToken.encode(), None, False, True, True,
                                                        False, None, ctypes.c_size_t(0), None, CB, fmi3IntermediateUpdateCallback())
results["model_exchange_wrong_token"] = lib.fmi3InstantiateModelExchange(b"x", b"{not-the-token}", None, False,
                                                                         True, None, CB)
s.terminate()
s.freeInstance()
results["statuses_logged"] = sorted({st for st, _m in LOG3})
results["messages"] = [m for _st, m in LOG3]
report(**results)
'''


def test_fmi3_hostile_calls_are_refused_with_an_error_and_keep_the_values(fmi3_impact, tmp_path):
    """Each bad call (run in a child process: a crash fails this test only) returns fmi3Error (3), never
    fmi3Fatal, logs why, and leaves the values as they were; instantiations that cannot be honoured return
    NULL with a message. `time` is read-only and follows the communication points."""
    unzip = extract(str(fmi3_impact), str(tmp_path / "unzip"))
    child = run_child(HOSTILE, fmi3_impact, unzip)
    assert child.returncode == 0 and child.report is not None, child.explain()
    got = child.report
    for key in ("step_before_init", "negative_speed", "nan_speed", "int32_on_enumeration", "enumeration_out_of_range",
                "set_time", "set_output", "unknown_vr", "get_string", "n_values_mismatch", "null_out_arguments",
                "skipped_step", "bad_state_bytes", "enter_event_mode"):
        assert got[key] == 3, f"{key}: status {got[key]}"
    assert got["kept_speed"] == 2.0 and got["kept_speed_after_all"] == 2.0 and got["kept_method"] == 1
    assert got["time_before_step"] == 0.0 and got["time_after_step"] == 1e-3
    assert got["wrong_token"] is None and got["event_mode"] is None and got["model_exchange_wrong_token"] is None
    assert 4 not in got["statuses_logged"]
    text = "\n".join(got["messages"])
    for needed in ("v_approach = -1.0 is outside the allowed range", "is an Enumeration variable, not Int32",
                   "time is the independent variable and cannot be set", "fmi3DoStep is not allowed in instantiated",
                   "1 value references", "must not be NULL", "instantiation token {not-the-token} does not match",
                   "event mode is not provided", "fmi3InstantiateModelExchange: instantiation token",
                   "a step cannot be skipped or repeated without fmi3SetFMUState"):
        assert needed in text, needed


def test_fmi3_states_serialize_and_move_to_the_fmi2_native_fmu(native_impact_fmu, fmi3_impact):
    """A state serialized by the FMI 3.0 FMU restores into the FMI 2.0 native FMU (one core, one state
    format) and brings its inputs and parameters: the same outputs afterwards."""
    three, two = Loaded(fmi3_impact), Loaded(native_impact_fmu)
    try:
        params = {FMU_NAME[k]: v for k, v in params_for("T4-A1", 0.2).items()}
        three.initialise(params)
        three.set_reals({"v_approach": 3.7})
        state = three.s.getFMUState()
        data = three.s.serializeFMUState(state)
        three.s.freeFMUState(state)
        two.initialise({})
        two.s.setFMUstate(two.s.deSerializeFMUstate(data))
        names = list(FMU_REALS)
        assert two.reals(["v_approach"]) == [3.7]
        assert two.reals(names) == three.reals(names)
    finally:
        three.close()
        two.close()


def test_fmi3_bouncing_ball_meets_the_plate_at_the_free_fall_time(fmi3_ball):
    """Dropped from h0 = 0.3 m with e = 1, the ball meets the plate at t = sqrt(2 h0 / g) (closed form),
    located inside the step to rounding (the ball's flight is a parabola solved exactly), and
    rebounds to h0 (energy kept with e = 1) half a period later."""
    h0, g = 0.3, 9.80665
    t1 = math.sqrt(2 * h0 / g)
    result = simulate_fmu(str(fmi3_ball), stop_time=2.5 * t1, output_interval=1e-3,
                          output=["h", "impacts", "t_impact", "v_impact"])
    assert result["impacts"][-1] == 1
    first = result[result["impacts"] == 1]
    assert math.isclose(first["t_impact"][0], t1, rel_tol=1e-12)
    assert math.isclose(first["v_impact"][0], g * t1, rel_tol=1e-12)
    apex = result["h"][abs(result["time"] - 2 * t1) < 1e-3]
    assert apex.size and max(apex) == pytest.approx(h0, rel=1e-5)


def test_fmi3_source_fmus_link_into_one_library_with_prefixes(fmi3_impact_fmu, fmi3_ball_fmu, tmp_path):
    """Compiled from their sources/ with FMI3_FUNCTION_PREFIX (the FMI 3.0 headers prefix the fmi3
    functions, the project's rst_prefix.h every other external name), both FMI 3.0 FMUs link into one
    shared library: every external symbol carries its FMU's prefix, none clashes."""
    import shutil
    import subprocess

    from restitution.fmu.build_native import fmi_include_dir

    if shutil.which("gcc") is None or shutil.which("nm") is None:
        pytest.skip("gcc and nm are needed")
    objects = []
    for model, fmu in (("SpherePlateImpact", fmi3_impact_fmu), ("BouncingBall", fmi3_ball_fmu)):
        with zipfile.ZipFile(fmu) as z:
            z.extractall(tmp_path / model)
        sources = tmp_path / model / "sources"
        for c_file in sorted(sources.glob("*.c")):
            obj = tmp_path / f"{model}_{c_file.stem}.o"
            done = subprocess.run(["gcc", "-std=c99", "-O1", "-Wall", "-Wextra", "-Werror", "-fPIC", "-c",
                                   f"-DFMI3_FUNCTION_PREFIX={model}_", f"-I{sources}", f"-I{fmi_include_dir('3.0')}",
                                   "-o", str(obj), str(c_file)], capture_output=True, text=True)
            assert done.returncode == 0, done.stderr[-3000:]
            objects.append(obj)
    defined = subprocess.run(["nm", "-g", "--defined-only", *map(str, objects)], capture_output=True,
                             text=True).stdout
    names = {line.split()[-1] for line in defined.splitlines() if len(line.split()) == 3}
    assert names and not {n for n in names if not n.startswith(("SpherePlateImpact_", "BouncingBall_"))}
    assert {"SpherePlateImpact_fmi3DoStep", "BouncingBall_fmi3InstantiateModelExchange"} <= names
    linked = subprocess.run(["gcc", "-shared", "-o", str(tmp_path / "pair.so"), *map(str, objects), "-lm", "-pthread"],
                            capture_output=True, text=True)
    assert linked.returncode == 0, linked.stderr[-3000:]
