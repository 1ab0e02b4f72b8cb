"""The native FMI 3.0 co-simulation FMUs (``fmi3/``): the same C core as the FMI 2.0 native FMUs behind
a thin FMI 3.0 layer. They must validate, compute what the FMI 2.0 native FMU computes, refuse every
hostile call with an error (never fmi3Fatal) and keep the previous values, carry their states across
FMI versions, and bounce a ball at the analytic free-fall times."""
from __future__ import annotations

import math
import zipfile
from types import SimpleNamespace
from xml.etree import ElementTree as ET

import pytest
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.validation import validate_fmu
from hypothesis import given, settings

from cases import CASES, FMU_FLAGS, FMU_REALS, PAIRS, SPEEDS, T_OVER_D, params_for
from fmi_child import run_child
from restitution.agreement import disagreements, tolerances
from restitution.cosim import FmuInstance
from restitution.fmu.models import table

IMPACT = table("SpherePlateImpact")
FMU_NAME = {key: row.name for key, row in IMPACT.by_key().items()}  # package keyword -> FMU name


def outputs(fmu: FmuInstance) -> SimpleNamespace:
    """Every output of a SpherePlateImpact instance under the package's field names."""
    reals = dict(zip(FMU_REALS.values(), fmu.get_reals(list(FMU_REALS))))
    flags = dict(zip(FMU_FLAGS.values(), (bool(x) for x in fmu.get(*FMU_FLAGS))))
    return SimpleNamespace(**reals, **flags)


def assert_versions_agree(two: FmuInstance, three: FmuInstance, v, params: dict, context, **options):
    """The FMI 3.0 and FMI 2.0 native FMUs' outputs agree within the outputs' conditioning
    (restitution.agreement: last-bit differences of exp, log and pow amplified by each output's
    sensitivity to its inputs), every flag equal unless an input perturbation flips it."""
    problems = disagreements(outputs(three), outputs(two), *tolerances(v, params, **options))
    assert not problems, (context, problems)


def test_fmi3_fmus_validate_and_declare_their_sources(fmi3_impact_fmu, fmi3_ball_fmu):
    """fmpy's validation (FMI 3.0 schema and its checks) finds nothing; sources/buildDescription.xml names
    exactly the .c files in sources/, and the FMI 3.0 layer, not the FMI 2.0 one, is among them."""
    for fmu in (fmi3_impact_fmu, fmi3_ball_fmu):
        assert validate_fmu(str(fmu)) == []
        with zipfile.ZipFile(fmu) as z:
            names = z.namelist()
            build = ET.fromstring(z.read("sources/buildDescription.xml"))
        c_files = sorted(n.split("/", 1)[1] for n in names if n.startswith("sources/") and n.endswith(".c"))
        declared = sorted(f.get("name") for f in build.iter("SourceFile"))
        assert declared == c_files and "rst_fmi3.c" in c_files and "rst_fmi2.c" not in c_files
        assert any(n.startswith("binaries/x86_64-linux/") for n in names)


def test_fmi3_impact_equals_the_fmi2_native_fmu_over_the_hard_cases(native_impact_fmu, fmi3_impact_fmu):
    """Over the hard-case matrix (8 material pairs x 10 speeds x 7 thickness ratios), every output of the
    FMI 3.0 FMU agrees with the FMI 2.0 native FMU's within its conditioning, every flag equal. Both run
    the same C physics: a version layer that converted a value through another type (float, integer)
    or mixed up two value references would exceed the bound by orders of magnitude."""
    with FmuInstance(native_impact_fmu, "two") as two, FmuInstance(fmi3_impact_fmu, "three") as three:
        for pair in PAIRS:
            for t_over_d in T_OVER_D:
                params = params_for(pair, t_over_d)
                for v in SPEEDS:
                    for fmu in (two, three):
                        fmu.set(**{FMU_NAME[k]: value for k, value in params.items()}, v_approach=v)
                    assert_versions_agree(two, three, v, params, (pair, t_over_d, v))


@pytest.fixture(scope="module")
def both_versions(native_impact_fmu, fmi3_impact_fmu):
    """The native FMI 2.0 and FMI 3.0 SpherePlateImpact, initialised, for a search over the domain."""
    with FmuInstance(native_impact_fmu, "two") as two, FmuInstance(fmi3_impact_fmu, "three") as three:
        yield two, three


@settings(max_examples=300, deadline=None)
@given(CASES)
def test_fmi3_impact_equals_the_fmi2_native_fmu_over_the_declared_domain(both_versions, case):
    """A hypothesis search of the declared domain (every parameter log-uniform over its range, every
    choice): the FMI 3.0 FMU's outputs agree with the FMI 2.0 native FMU's within their conditioning
    (as over the hard cases), and the choices read back as set (Int64 in FMI 3.0, Integer in 2.0)."""
    two, three = both_versions
    options = {k: v for k, v in case.items() if IMPACT[FMU_NAME[k]].choices}
    values = {FMU_NAME[k]: (IMPACT[FMU_NAME[k]].codes[v] if k in options else float(v)) for k, v in case.items()}
    for fmu in both_versions:
        fmu.set(**values)
        assert [int(x) for x in fmu.get(*(FMU_NAME[k] for k in options))] == [values[FMU_NAME[k]] for k in options]
    params = {k: v for k, v in case.items() if k not in options and k != "v"}
    assert_versions_agree(two, three, case["v"], params, case, **options)


def test_fmi3_materials_are_enumerations_set_with_int64(fmi3_impact_fmu):
    """plate.material is an Enumeration (got and set with fmi3Get/SetInt64): naming a preset makes the
    calculated parameters plate.used.* that preset's properties (the package's values, copied)."""
    import restitution as r

    md = read_model_description(str(fmi3_impact_fmu))
    material = next(v for v in md.modelVariables if v.name == "plate.material")
    assert material.type == "Enumeration" and material.declaredType.name == "Material"
    with FmuInstance(fmi3_impact_fmu, "materials", parameters={"plate.material": "tungsten_carbide"}) as fmu:
        assert fmu.get("plate.material") == [fmu.item_code("plate.material", "tungsten_carbide")]
        preset = r.MATERIALS["tungsten_carbide"]
        assert fmu.get_reals(["plate.used.E", "plate.used.nu", "plate.used.Sy", "plate.used.rho"]) == [
            preset.E, preset.nu, preset.Sy, preset.rho]


HOSTILE = r'''
from fmpy.fmi3 import FMU3Slave, fmi3IntermediateUpdateCallback, fmi3LogMessageCallback
import ctypes
CB = fmi3LogMessageCallback(log3)

def slave3():
    s = FMU3Slave(guid=MD.instantiationToken, unzipDirectory=UNZIP, modelIdentifier=MD.coSimulation.modelIdentifier,
                  instanceName="hostile")
    s.instantiate(loggingOn=True, logMessage=log3)
    return s

results = {}
s = slave3()
results["step_before_init"] = status(s.doStep, 0.0, 1e-3)
s.enterInitializationMode(startTime=0.0)
s.exitInitializationMode()
v = VR["v_approach"]
s.setFloat64([v], [2.0])
results["negative_speed"] = status(s.setFloat64, [v], [-1.0])
results["nan_speed"] = status(s.setFloat64, [v], [float("nan")])
results["kept_speed"] = list(s.getFloat64([v]))[0]
results["int32_on_enumeration"] = status(s.setInt32, [VR["zener_method"]], [2])
results["enumeration_out_of_range"] = status(s.setInt64, [VR["zener_method"]], [99])
results["kept_method"] = list(s.getInt64([VR["zener_method"]]))[0]
results["set_time"] = status(s.setFloat64, [len(MD.modelVariables) - 1], [5.0])
results["set_output"] = status(s.setFloat64, [VR["e"]], [0.5])
results["unknown_vr"] = status(s.getFloat64, [10**6])
results["get_string"] = status(s.getString, [v])
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
results["skipped_step"] = status(s.doStep, 5.0, 1e-3)
results["bad_state_bytes"] = status(s.deserializeFMUState, b"RSTFMUST" + b"\0" * 40)
results["enter_event_mode"] = status(s.enterEventMode)
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
report_with_log3(**results)
'''


def test_fmi3_hostile_calls_are_refused_with_an_error_and_keep_the_values(fmi3_impact_fmu, tmp_path):
    """Each bad call (run in a child process: a crash fails this test only) returns fmi3Error (3), never
    fmi3Fatal, logs why, and leaves the values as they were; instantiations that cannot be honoured return
    NULL with a message. `time` is read-only and follows the communication points."""
    unzip = extract(str(fmi3_impact_fmu), str(tmp_path / "unzip"))
    child = run_child(HOSTILE, fmi3_impact_fmu, unzip)
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


def test_fmi3_states_serialize_and_move_to_the_fmi2_native_fmu(native_impact_fmu, fmi3_impact_fmu):
    """A state serialized by the FMI 3.0 FMU restores into the FMI 2.0 native FMU (one core, one state
    format) and brings its inputs and parameters exactly (they are copied): the same outputs afterwards,
    within their conditioning."""
    params = params_for("T4-A1", 0.2)
    with FmuInstance(fmi3_impact_fmu, "three", parameters={FMU_NAME[k]: v for k, v in params.items()}) as three, \
            FmuInstance(native_impact_fmu, "two") as two:
        three.set(v_approach=3.7)
        state = three.get_state()
        data = three.serialize_state(state)
        three.free_state(state)
        restored = two.deserialize_state(data)
        two.set_state(restored)
        two.free_state(restored)
        assert two.get_reals(["v_approach", *(FMU_NAME[k] for k in params)]) == [3.7, *params.values()]
        assert_versions_agree(two, three, 3.7, params, "restored state")


def test_fmi3_bouncing_ball_meets_the_plate_at_the_free_fall_time(fmi3_ball_fmu):
    """Dropped from h0 = 0.3 m with e = 1, the ball meets the plate at t = sqrt(2 h0 / g) (closed form),
    located inside the step to rounding (the ball's flight is a parabola solved exactly), and
    rebounds to h0 (energy kept with e = 1) half a period later."""
    h0, g = 0.3, 9.80665
    t1 = math.sqrt(2 * h0 / g)
    result = simulate_fmu(str(fmi3_ball_fmu), stop_time=2.5 * t1, output_interval=1e-3,
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

    from restitution.fmu.builders.native import fmi_include_dir

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
