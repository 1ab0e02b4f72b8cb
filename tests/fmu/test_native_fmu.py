"""The native SpherePlateImpact.fmu (C front + C physics, no Python at run time) is the same
component as the pythonfmu one: the same interface, variable by variable, and the package's numbers.

The interface test runs everywhere. The tests of the built FMU need gcc (they skip saying so). Numbers are
compared with restitution.agreement's per-case tolerances (derived from each output's conditioning),
never bit for bit: the C uses libm, the package numpy and CPython's math.
"""
from __future__ import annotations

import math
import shutil
import subprocess
import zipfile
from xml.etree import ElementTree as ET

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import restitution as r
from restitution.agreement import disagreements, tolerances
from restitution.model import published
from restitution.fmu.builders.native import NativeBuildSkipped, front_files
from restitution.fmu.describe import fmi2
from restitution.fmu.models import table

from cases import CASES, FMU_FLAGS, FMU_REALS, params_for  # CASES: the declared domain, drawn log-uniformly

INTERFACE_ATTRIBUTES = ("name", "valueReference", "causality", "variability", "initial", "description")
TYPE_ATTRIBUTES = ("unit", "start", "min", "max", "declaredType")


def _model_description(fmu):
    with zipfile.ZipFile(fmu) as z:
        return z.read("modelDescription.xml").decode("utf-8")


def _interface(root):
    rows = []
    for sv in root.find("ModelVariables"):
        typ = sv[0]
        rows.append((tuple(sv.get(a) for a in INTERFACE_ATTRIBUTES), typ.tag,
                     tuple(typ.get(a) for a in TYPE_ATTRIBUTES)))
    structure = ET.tostring(root.find("ModelStructure"))
    units = ET.tostring(root.find("UnitDefinitions"))
    return rows, structure, units


def test_model_description_has_the_same_interface(impact_fmu):
    """Every variable (name, vr, type, causality, variability, initial, unit, start, min/max, description),
    the ModelStructure and the units of the native FMI 2.0 description equal the pythonfmu FMU's, but for
    the limits of the rows the native FMUs accept less of (``native_interval``: their own); the C sources
    are declared in both interfaces, and nothing of it is pythonfmu's."""
    python_xml = _model_description(impact_fmu)
    native_xml = fmi2.model_description("SpherePlateImpact", native=True, c_files=["a.c", "b.c"])
    py, nat = ET.fromstring(python_xml), ET.fromstring(native_xml)
    narrower = {row.name for row in table("SpherePlateImpact") if row.native_interval is not None}
    assert narrower  # zener_method: ode is the pythonfmu FMU's only

    def without_narrowed_limits(interface):
        rows, structure, units = interface
        return [(attrs, tag, typed[:2] + (None, None) + typed[4:] if attrs[0] in narrower else typed)
                for attrs, tag, typed in rows], structure, units

    assert without_narrowed_limits(_interface(nat)) == without_narrowed_limits(_interface(py))
    assert _interface(nat) != _interface(py)
    assert nat.get("guid") == py.get("guid") and nat.get("modelName") == py.get("modelName")
    for part in ("CoSimulation", "ModelExchange"):
        node = nat.find(part)
        assert node.get("modelIdentifier") == "SpherePlateImpact" and node.get("needsExecutionTool") == "false"
        assert [f.get("name") for f in node.find("SourceFiles")] == ["a.c", "b.c"]
    assert "pythonfmu" not in nat.get("generationTool").lower() and "PythonFMU" not in python_xml  # written by us, both


def _front_missing():
    try:
        front_files()
    except NativeBuildSkipped as exc:
        return str(exc)
    return None


needs_front = pytest.mark.skipif(_front_missing() is not None or shutil.which("gcc") is None,
                                 reason=f"native FMU not buildable here: {_front_missing() or 'gcc missing'}")


@pytest.fixture(scope="module")
def native_fmu(native_impact_fmu):
    return native_impact_fmu


@needs_front
def test_native_fmu_validates_and_has_no_python(native_fmu):
    from fmpy.validation import validate_fmu

    assert validate_fmu(str(native_fmu)) == []
    with zipfile.ZipFile(native_fmu) as z:
        names = z.namelist()
        assert "binaries/linux64/SpherePlateImpact.so" in names
        assert not any(n.endswith(".py") for n in names)
        assert _interface(ET.fromstring(z.read("modelDescription.xml")))[0]


@needs_front
@pytest.mark.parametrize("version", ["native_impact_fmu", "fmi3_impact_fmu"])
@pytest.mark.parametrize("method", ["exact", "paper_fit", "linear"])
def test_native_fmu_equals_the_package(request, version, method):
    """The native FMU, FMI 2.0 and FMI 3.0 (the same C behind either version layer), through FmuInstance."""
    from restitution.cosim import FmuInstance

    native_fmu = request.getfixturevalue(version)
    rng = np.random.default_rng(7)
    for pair in ("s2/al6061", "T4-A1", "glass/glass", "nu0/nu0.499"):
        for t_over_d in (0.05, 1.0, 100.0):
            params = params_for(pair, t_over_d)
            options = dict(zener_method=method)
            v = np.concatenate([[0.0], np.exp(rng.uniform(np.log(1e-6), np.log(1e3), 8))])
            with FmuInstance(native_fmu, parameters={**_fmu_parameters(params), "zener_method": {"exact": 1,
                             "paper_fit": 2, "linear": 3}[method]}) as fmu:
                got = {}
                for name in list(FMU_REALS) + list(FMU_FLAGS):
                    got[name] = []
                for speed in v:
                    fmu.set(v_approach=float(speed))
                    values = fmu.get(*FMU_REALS, *FMU_FLAGS)
                    for name, value in zip(list(FMU_REALS) + list(FMU_FLAGS), values):
                        got[name].append(value)
            result = type("R", (), {**{FMU_REALS[k]: np.array(x, dtype=float) for k, x in got.items() if k in FMU_REALS},
                                    **{FMU_FLAGS[k]: np.array(x, dtype=bool) for k, x in got.items() if k in FMU_FLAGS}})
            expected = r.impact(v, **params, **options)
            tol, flips = tolerances(v, params, **options)
            problems = disagreements(result, expected, tol, flips)
            assert not problems, f"{pair} t/d={t_over_d}: {problems}"


def _fmu_parameters(params):
    return {name.replace("_", ".", 1): float(value) for name, value in params.items()}


@needs_front
def test_binaries_need_no_python_and_no_extra_dll(native_fmu, tmp_path):
    with zipfile.ZipFile(native_fmu) as z:
        z.extractall(tmp_path)
    so = tmp_path / "binaries/linux64/SpherePlateImpact.so"
    needed = subprocess.run(["objdump", "-p", str(so)], capture_output=True, text=True).stdout
    assert "libpython" not in needed
    dll = tmp_path / "binaries/win64/SpherePlateImpact.dll"
    if not dll.exists():
        pytest.skip("no win64 binary (x86_64-w64-mingw32-gcc missing at build time)")
    imports = subprocess.run(["objdump", "-p", str(dll)], capture_output=True, text=True).stdout
    dlls = {line.split()[-1].lower() for line in imports.splitlines() if "DLL Name:" in line}
    assert dlls <= {"kernel32.dll", "msvcrt.dll", "user32.dll", "advapi32.dll"} or all(
        d.startswith("api-ms-win-") or d in ("kernel32.dll", "msvcrt.dll") for d in dlls), dlls
    assert not any("python" in d or "libgcc" in d or "winpthread" in d for d in dlls), dlls


@needs_front
@pytest.mark.skipif(shutil.which("cmake") is None, reason="cmake is needed by fmpy's build_platform_binary")
@pytest.mark.parametrize("folder, model", [("fmi2", "SpherePlateImpact"), ("fmi3", "SpherePlateImpact"),
                                           ("fmi3", "BouncingBall")])
def test_rebuilt_from_sources_by_fmpy(built_fmus, folder, model, tmp_path):
    """The Linux binary removed and rebuilt from sources/ by fmpy's build_platform_binary (its CMake project),
    then simulated: the FMI 2.0 native FMU from <SourceFiles>, the FMI 3.0 FMUs from
    sources/buildDescription.xml (fmpy 0.3.32 reads its source files, include directories and
    preprocessor definitions, takes the FMI 3.0 headers from its own copy and installs into
    binaries/x86_64-linux/; it does not link the declared <Library name="m">, so, as for FMI 2.0, the
    rebuilt binary takes libm from the host process, which Python has loaded)."""
    from fmpy import extract, simulate_fmu
    from fmpy.build import build_platform_binary

    fmu = built_fmus / folder / f"{model}.fmu"
    if not fmu.is_file():
        pytest.skip(f"{folder}/{model}.fmu not built here")
    unzip = tmp_path / "unzipped"
    extract(str(fmu), str(unzip))
    binary = unzip / "binaries" / ("linux64" if folder == "fmi2" else "x86_64-linux") / f"{model}.so"
    binary.unlink()
    (tmp_path / "build").mkdir()
    build_platform_binary(unzip, build_dir=tmp_path / "build")
    assert binary.is_file()
    if model == "SpherePlateImpact":
        result = simulate_fmu(str(unzip), start_values={"v_approach": 2.3}, stop_time=1e-3, output_interval=1e-3,
                              output=["e", "jgm.V_star"])
        e, v_star = result["e"][-1], result["jgm.V_star"][-1]
        assert v_star == pytest.approx(86.9, abs=0.05)  # Green (2022) Sec. 7 checkpoint
        expected = r.impact(2.3, **params_for("s2/al6061")).e
        assert e == pytest.approx(expected, rel=1e-12, abs=1e-14)
    else:  # dropped from its start height h0 = 0.3 m: the first contact at the free-fall time (closed form)
        t1 = math.sqrt(2 * 0.3 / 9.80665)
        result = simulate_fmu(str(unzip), stop_time=1.5 * t1, output_interval=1e-3, output=["impacts", "t_impact"])
        assert result["impacts"][-1] == 1
        assert math.isclose(result["t_impact"][-1], t1, rel_tol=1e-12)


# --- a hypothesis search of the declared domain, through both FMUs ------------------------------------
FMU_CODES = {"restitution_model": {m: i + 1 for i, m in enumerate(r.RESTITUTION_MODELS)},
             "zener_method": {"exact": 1, "paper_fit": 2, "linear": 3},
             "plasticity": {m: i for i, m in enumerate(r.EFFECT_MODES)},
             "plate_waves": {m: i for i, m in enumerate(r.EFFECT_MODES)}}


@pytest.fixture(scope="module")
def any_instance(any_version_impact_fmu):
    from restitution.cosim import FmuInstance

    with FmuInstance(any_version_impact_fmu, "hypothesis") as fmu:
        yield fmu


@settings(max_examples=400, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow,
                                                                                    HealthCheck.function_scoped_fixture])
@given(CASES, st.sampled_from([0.0, 1e-6, 1e-3]))
def test_both_fmus_equal_the_package_over_the_declared_domain(any_instance, case, effect_tolerance):
    """For cases drawn from the whole declared domain (all methods both implementations run, models and
    effect modes), each FMU (pythonfmu, native FMI 2.0, native FMI 3.0) answers every set and the step with
    OK (FmuInstance raises otherwise), every Real output is finite, and every output and flag equals the package's
    published value within its conditioning; the two implementations then agree with each other within
    twice that."""
    fmu = any_instance
    params = {k: v for k, v in case.items() if k in r.model.DOMAIN and k != "v"}
    params.update(sphere_nu=case["sphere_nu"], plate_nu=case["plate_nu"])
    options = {k: case[k] for k in FMU_CODES}
    fmu.set(**_fmu_parameters(params), **{k: FMU_CODES[k][v] for k, v in options.items()},
            effect_tolerance=effect_tolerance, v_approach=case["v"])
    fmu.do_step(step_size=1e-3)
    values = fmu.get(*FMU_REALS, *FMU_FLAGS)
    reals = dict(zip(FMU_REALS, values))
    assert all(math.isfinite(x) for x in reals.values()), (case, reals)
    got = type("R", (), {**{FMU_REALS[k]: x for k, x in reals.items()},
                         **{FMU_FLAGS[k]: x for k, x in zip(FMU_FLAGS, values[len(FMU_REALS):])}})
    options["effect_tolerance"] = effect_tolerance
    expected = type("R", (), published(r.impact(case["v"], **params, **options).as_dict()))
    problems = disagreements(got, expected, *tolerances(case["v"], params, **options))
    assert not problems, (case, effect_tolerance, problems)


def test_serialized_states_move_between_the_two_implementations(impact_fmu, native_fmu):
    """One state layout (the C front's): the pythonfmu FMU's serialized state restores into the native
    FMU, inputs, parameters and communication point included, and back."""
    from restitution.cosim import FmuInstance

    with FmuInstance(impact_fmu, "python", parameters={"plate.t": 3e-3}) as python, \
            FmuInstance(native_fmu, "fmi2") as native:
        python.set(v_approach=2.3)
        python.do_step(step_size=0.1)
        native.slave.setFMUstate(native.slave.deSerializeFMUstate(
            python.slave.serializeFMUstate(python.slave.getFMUstate())))
        assert native.get("plate.t", "v_approach") == [3e-3, 2.3]
        native.do_step(0.1, 0.1)  # continues at the python instance's communication point
        native.set(v_approach=1.1)
        python.slave.setFMUstate(python.slave.deSerializeFMUstate(
            native.slave.serializeFMUstate(native.slave.getFMUstate())))
        assert python.get("v_approach", "plate.t") == [1.1, 3e-3]
        python.do_step(0.2, 0.1)
        e_python, = python.get("e")
        e_native, = native.get("e")
        params = {**r.Sphere(r.MATERIALS["s2_tool_steel"], 6.35e-3).params(), **r.Plate(r.MATERIALS["al_6061"], 3e-3).params()}
        tol, _ = tolerances(1.1, params)
        assert abs(e_python - e_native) <= float(tol["e"])
