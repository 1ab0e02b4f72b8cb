"""SpherePlateImpact.fmu through fmpy: interface, numbers against the package, feedthrough,
caching and bad input."""
import itertools
import math
import zipfile
from xml.etree import ElementTree as ET

import numpy as np
import pytest
from fmpy.validation import validate_fmu

import restitution as r

from independent import apparent_cor, table_material
from restitution.cosim import FmiStatusError, FmuInstance, impact_fmu_parameters
from restitution.model import published

CONTRACT = {  # name: (causality, unit, start) from the public interface table
    "v_approach": ("input", "m/s", 1.0),
    "sphere.E": ("parameter", "Pa", 207e9), "sphere.nu": ("parameter", "1", 0.30),
    "sphere.Sy": ("parameter", "Pa", 2.0e9), "sphere.rho": ("parameter", "kg/m3", 7861.0),
    "sphere.d": ("parameter", "m", 6.35e-3),
    "plate.E": ("parameter", "Pa", 69e9), "plate.nu": ("parameter", "1", 0.33),
    "plate.Sy": ("parameter", "Pa", 0.290e9), "plate.rho": ("parameter", "kg/m3", 2700.0),
    "plate.t": ("parameter", "m", 6.35e-3),
    "restitution_model": ("parameter", None, 1), "zener_method": ("parameter", None, 1),
    "plasticity": ("parameter", None, 2), "plate_waves": ("parameter", None, 2),
    "effect_tolerance": ("parameter", "1", 1e-6),
    "e": ("output", "1", None), "v_rebound": ("output", "m/s", None), "jgm.e": ("output", "1", None),
    "jgm.V_c": ("output", "m/s", None), "jgm.V_star": ("output", "1", None), "zener.e": ("output", "1", None),
    "zener.lambda": ("output", "1", None), "zener.tau0": ("output", "1", None),
    "zener.t_contact": ("output", "s", None), "plate.mass_ratio": ("output", "1", None),
    "plate.v_after": ("output", "m/s", None), "sphere.m": ("output", "kg", None),
    "valid": ("output", None, None), "zener.contact_ends": ("output", None, None),
}
REAL_OUTPUTS = {"e": "e", "v_rebound": "v_rebound", "jgm.e": "e_ep", "jgm.V_c": "V_c", "jgm.V_star": "V_star",
                "zener.e": "e_ze", "zener.lambda": "lam", "zener.tau0": "tau0", "zener.t_contact": "t_contact",
                "plate.mass_ratio": "mass_ratio", "plate.v_after": "v_plate"}


def test_validates_and_keeps_the_public_contract(impact_fmu):
    assert validate_fmu(str(impact_fmu)) == []
    with zipfile.ZipFile(impact_fmu) as z:
        root = ET.fromstring(z.read("modelDescription.xml"))
    units = {u.get("name") for u in root.find("UnitDefinitions")}
    found = {}
    for sv in root.find("ModelVariables"):
        typ = sv[0]
        assert sv.get("description"), sv.get("name")
        found[sv.get("name")] = (sv.get("causality"), typ.get("unit"), typ.get("start"), typ.tag)
        if typ.tag == "Real":
            assert typ.get("unit") in units, sv.get("name")
    for name, (causality, unit, start) in CONTRACT.items():
        got = found[name]
        assert got[0] == causality and got[1] == unit, name
        if start is not None:
            assert float(got[2]) == start, name
    cosim = root.find("CoSimulation")
    assert cosim.get("canGetAndSetFMUstate") == "true" and cosim.get("canSerializeFMUstate") == "true"
    # direct feedthrough: every output but V_c and the sphere's mass depends on the input v_approach
    index = {sv.get("name"): str(i + 1) for i, sv in enumerate(root.find("ModelVariables"))}
    deps = {u.get("index"): u.get("dependencies") for u in root.find("ModelStructure/Outputs")}
    assert deps[index["e"]] == index["v_approach"] and deps[index["jgm.V_c"]] == deps[index["sphere.m"]] == ""
    assert deps[index["zener.contact_ends"]] == index["v_approach"]


CASES = list(itertools.product(
    [("s2_tool_steel", 6.35e-3, "al_6061"), ("tungsten_carbide", 4.76e-3, "al_6061"),
     ("borosilicate_glass_t1", 6.35e-3, "borosilicate_glass_t1"), ("brass_260", 4.76e-3, "s7_tool_steel")],
    [0.0, 1e-3, 0.5, 2.3, 6.9, 30.0],
    [0.25, 1.0, 4.0],
    [(1, 1), (2, 2), (1, 3), (2, 4)],
))


def test_fmu_matches_the_package_on_a_grid(impact_fmu):
    with FmuInstance(impact_fmu) as fmu:
        for (s_key, d, p_key), v, t_over_d, (model, method) in CASES:
            sphere, plate = r.Sphere(r.MATERIALS[s_key], d), r.Plate(r.MATERIALS[p_key], t_over_d * d)
            fmu.set(**impact_fmu_parameters(sphere, plate), restitution_model=model, zener_method=method,
                    v_approach=v)
            fmu.do_step(step_size=1e-3)
            got = dict(zip(REAL_OUTPUTS, fmu.get_reals(list(REAL_OUTPUTS))))
            ref = published(r.impact_between(sphere, plate, v, restitution_model=r.RESTITUTION_MODELS[model - 1],
                                             zener_method=r.ZENER_METHODS[method - 1]).as_dict())
            for name, field in REAL_OUTPUTS.items():  # the same Python code on both sides: 1e-12
                assert got[name] == pytest.approx(ref[field], rel=1e-12, abs=0.0), (name, s_key, v, t_over_d, method)
            assert fmu.get("valid", "zener.contact_ends") == [ref["valid"], ref["contact_ends"]]


def test_outputs_follow_set_real_before_any_step(impact_fmu):
    """Direct feedthrough: after fmi2SetReal the outputs already match the new input."""
    with FmuInstance(impact_fmu) as fmu:
        fmu.do_step(0.0, 0.1)
        for v in (0.3, 2.3, 9.0):
            fmu.set(v_approach=v)
            e, v_reb = fmu.get_reals(["e", "v_rebound"])
            ref = r.impact_between(r.Sphere(r.MATERIALS["s2_tool_steel"], 6.35e-3),
                                   r.Plate(r.MATERIALS["al_6061"], 6.35e-3), v)
            assert e == pytest.approx(ref.e, rel=1e-12) and v_reb == pytest.approx(v * ref.e, rel=1e-12)


def test_nothing_is_recomputed_when_nothing_changed(impact_fmu, monkeypatch):
    """The slave caches: reading outputs again, or stepping with unchanged inputs, evaluates nothing."""
    import sphere_plate_impact_slave as slave_module  # the module the FMU imported in this process

    calls = []
    real_impact = slave_module._impact_si
    monkeypatch.setattr(slave_module, "_impact_si", lambda *a, **k: calls.append(1) or real_impact(*a, **k))
    with FmuInstance(impact_fmu) as fmu:
        calls.clear()  # initialisation evaluated the start values
        fmu.set(v_approach=2.0)
        fmu.get_reals(list(REAL_OUTPUTS))
        n = len(calls)
        assert n == 1
        for k in range(5):
            fmu.do_step(step_size=0.01)
            fmu.get_reals(list(REAL_OUTPUTS))
            fmu.set(v_approach=2.0)
        assert len(calls) == n
        fmu.set(v_approach=2.5)
        fmu.get_reals(["e", "v_rebound"])
        assert len(calls) == n + 1


#: e of the FMU's default case (S2 ball, d = t = 6.35 mm, on Al 6061) at 2.3 m/s, from the printed
#: equations and the ODE solved independently (tests/independent.py): 0.50419039...
E_DEFAULT_AT_2_3 = apparent_cor(table_material("s2_tool_steel"), table_material("al_6061"), 6.35e-3, 6.35e-3, 2.3)


@pytest.mark.parametrize("name,value", [("v_approach", -1.0), ("v_approach", math.nan), ("plate.nu", 0.6),
                                        ("sphere.E", math.inf), ("plate.t", 0.0), ("zener_method", 7)])
def test_bad_input_is_refused_not_fatal(any_version_impact_fmu, name, value):
    """Error (fmi2Error, fmi3Error) with a message naming the variable, the value and the range; the
    previous value is kept, so the instance goes on computing the right numbers; the other instance is
    untouched."""
    fmu = any_version_impact_fmu
    with FmuInstance(fmu, "bad") as bad, FmuInstance(fmu, "good") as good:
        good.set(v_approach=2.3)
        bad.set(v_approach=2.3)
        with pytest.raises(FmiStatusError) as err:
            bad.set(**{name: value})
        assert err.value.status == 3  # Error, never Fatal (4)
        logged = " ".join(m for _, m in bad.messages)
        assert name in logged and repr(value) in logged and "allowed range" in logged
        bad.do_step(step_size=0.01)
        assert bad.get("e")[0] == pytest.approx(E_DEFAULT_AT_2_3, rel=1e-8)
        good.do_step(step_size=0.01)
        assert good.get("e")[0] == pytest.approx(E_DEFAULT_AT_2_3, rel=1e-8)


def test_the_fmi_version_and_variable_kinds_are_read_from_the_model_description(any_version_impact_fmu):
    """FmuInstance takes the version from the modelDescription and names every variable's kind in FMI 2.0's
    words for both versions (an FMI 3.0 Float64 is a Real); an Enumeration is set by item name or code."""
    from fmpy import read_model_description

    md = read_model_description(str(any_version_impact_fmu))
    with FmuInstance(any_version_impact_fmu) as fmu:
        assert fmu.fmi_version == md.fmiVersion and fmu.fmi_version in ("2.0", "3.0")
        assert fmu.slave.__class__.__name__ == ("FMU3Slave" if md.fmiVersion == "3.0" else "FMU2Slave")
        assert [fmu.kind(n) for n in ("e", "valid", "plate.material")] == ["Real", "Boolean", "Enumeration"]
        # zener_method: an Integer in FMI 2.0 (its codes in the description), an Enumeration in FMI 3.0
        assert fmu.kind("zener_method") == ("Enumeration" if md.fmiVersion == "3.0" else "Integer")
        fmu.set(**{"plate.material": "brass_260", "sphere.material": 0})
        assert fmu.get("plate.material", "sphere.material", "plate.used.E") == [1, 0, 103e9]  # Table 3: brass


def test_an_unknown_variable_is_a_key_error_naming_the_model_and_the_close_names(any_version_impact_fmu):
    with pytest.raises(KeyError, match=r"SpherePlateImpact has no variable 'plate\.thickness' \(did you mean 'plate\.t'"):
        FmuInstance(any_version_impact_fmu, parameters={"plate.thickness": 3e-3})
    with FmuInstance(any_version_impact_fmu) as fmu:
        with pytest.raises(KeyError, match="no variable 'v_aproach' .*'v_approach'"):
            fmu.set(v_aproach=2.0)
        with pytest.raises(KeyError, match="no variable 'rebound'"):
            fmu.get("rebound")


def test_state_round_trip(any_version_impact_fmu):
    with FmuInstance(any_version_impact_fmu) as fmu:
        fmu.set(v_approach=1.7, **{"plate.t": 3e-3})
        before = fmu.get_reals(list(REAL_OUTPUTS))
        state = fmu.get_state()
        blob = fmu.serialize_state(state)
        fmu.set(v_approach=4.0, **{"plate.t": 1e-2})
        assert fmu.get_reals(["e"])[0] != before[0]
        copy = fmu.deserialize_state(blob)
        fmu.set_state(copy)
        assert fmu.get_reals(list(REAL_OUTPUTS)) == before
        fmu.free_state(copy)
        fmu.free_state(state)


def test_a_non_finite_output_is_an_evaluation_failure(impact_fmu, monkeypatch):
    """A NaN or an infinity in any output makes the outputs NaN and valid false, is logged with the
    inputs, and fmi2DoStep returns fmi2Discard. Where the physics is infinite the FMU publishes a finite
    encoding instead: mass_ratio = 0 for a half-space, tau0 = t_contact = 0 beside contact_ends = false."""
    import sphere_plate_impact_slave as slave_module  # the module the FMU imported in this process
    from restitution.model import RECORD

    real_impact = slave_module._impact_si  # one impact's record (restitution.model.impact_record_at)
    broken = {}
    monkeypatch.setattr(slave_module, "_impact_si", lambda *a, **k: tuple(
        broken.get(name, value) for name, value in zip(RECORD, real_impact(*a, **k))))
    for field, value, name in (("tau0", math.nan, "zener.tau0"), ("v_plate", math.inf, "plate.v_after")):
        broken.clear()
        broken[field] = value
        with FmuInstance(impact_fmu) as fmu:
            fmu.set(v_approach=2.0)
            assert all(math.isnan(x) for x in fmu.get_reals(list(REAL_OUTPUTS)))
            assert fmu.get("valid") == [False]
            failure = fmu.messages[-1]
            assert failure[0] == 3 and "evaluation failed for v_approach = 2.0" in failure[1]
            assert f"non-finite output {name} = {value!r}" in failure[1]
            with pytest.raises(FmiStatusError) as err:
                fmu.do_step(step_size=1e-3)
            assert err.value.status == 2  # fmi2Discard
    broken.clear()
    with FmuInstance(impact_fmu) as fmu:
        fmu.set(v_approach=2.0, plate_waves=0)  # a half-space: m_b = +inf in the package
        fmu.do_step(step_size=1e-3)
        assert fmu.get("plate.mass_ratio", "zener.e", "valid") == [0.0, 1.0, True]
        fmu.set(plate_waves=1, zener_method=3, **{"plate.t": 1e-4})  # linear, lambda >= 2: never releases
        fmu.do_step(step_size=1e-3)
        assert fmu.get("zener.lambda")[0] >= 2.0
        assert fmu.get("zener.tau0", "zener.t_contact", "zener.contact_ends", "zener.e") == [0.0, 0.0, False, 0.0]


def test_the_slaves_own_states_are_validated(tmp_path):
    """Without the C guard (pythonfmu's own binaries, e.g. win64), the slave still refuses a state
    that is not its own or holds a value the setters would refuse, logs why and changes nothing."""
    from bouncing_ball_slave import BouncingBall
    from sphere_plate_impact_slave import SpherePlateImpact

    slave = SpherePlateImpact(instance_name="direct")
    good = slave._fmu_state_to_bytes(slave._get_fmu_state())
    slave.vars[next(vr for vr, v in slave.vars.items() if v.name == "plate.t")].setter(3e-3)
    crafted = SpherePlateImpact._fmu_state_from_bytes(good)
    crafted["values"]["plate.t"] = -6.35e-3
    code = SpherePlateImpact._fmu_state_from_bytes(good)
    code["values"]["zener_method"] = 2.5
    ball_state = BouncingBall(instance_name="ball")._get_fmu_state()
    for bad in (SpherePlateImpact._fmu_state_from_bytes(b"\x00garbage"), crafted, code, ball_state,
                {"schema": crafted["schema"], "values": {}}, [1, 2, 3]):
        n = len(slave.log_queue)
        slave._set_fmu_state(bad)
        assert slave._values["plate.t"] == 3e-3, bad
        assert len(slave.log_queue) == n + 1 and slave.log_queue[-1].status == 3, bad
    slave._set_fmu_state(SpherePlateImpact._fmu_state_from_bytes(good))
    assert slave._values["plate.t"] == 6.35e-3


def test_one_pass_reads_equal_the_getters_whatever_the_request(impact_fmu):
    """get_real/get_boolean keep the reader of the last request: any sequence of requests (repeated,
    changed, one variable, none, mixed with an input) gives what pythonfmu's getter per variable gives."""
    from pythonfmu import Boolean, Real
    from sphere_plate_impact_slave import SpherePlateImpact

    slave = SpherePlateImpact(instance_name="direct")
    by_name = {v.name: vr for vr, v in slave.vars.items()}
    outputs = {vr: v for vr, v in slave.vars.items() if v.causality.name == "output"}
    reals = [vr for vr, v in outputs.items() if isinstance(v, Real)]
    bools = [vr for vr, v in outputs.items() if isinstance(v, Boolean)]
    from restitution.fmu.models import table as model_table

    expected = [v.type for v in model_table("SpherePlateImpact").outputs]
    assert (len(reals), len(bools)) == (expected.count("Real"), expected.count("Boolean")) and len(reals) >= 12
    requests = {"get_real": [reals, reals, reals[:1], [], reals[::-1], [by_name["v_approach"], reals[0]], reals],
                "get_boolean": [bools, bools, bools[2:3], [], bools[::-1], bools]}
    for v in (0.4, 2.3, 0.4):
        slave.vars[by_name["v_approach"]].setter(v)
        for method, lists in requests.items():
            for vrs in lists:
                got = getattr(slave, method)(list(vrs))
                assert got == [slave.vars[vr].getter() for vr in vrs], (method, vrs)
