"""The interface table is the one source of what hosts see: table -> modelDescription.xml -> table
gives the table back, for both models and both implementations, and the C header names every value
reference and code the table has."""
import math
import re
import zipfile
from xml.etree import ElementTree as ET

import pytest

from restitution.fmu.describe.c_header import c_header, variables_from_model_description
from conftest import NATIVE_FOLDERS
from restitution.fmu.models import FOLDERS, table


def _model_description(fmu):
    with zipfile.ZipFile(fmu) as z:
        return z.read("modelDescription.xml").decode("utf-8")


def _assert_round_trip(fmu, model):
    native = fmu.parent.name in NATIVE_FOLDERS  # built under fmi2/ or fmi3/
    text = _model_description(fmu)
    rows = table(model).rows
    back = variables_from_model_description(text)
    assert [v.name for v in back] == [v.name for v in rows]
    for row, got in zip(rows, back):
        assert (got.vr, got.type, got.causality, got.variability, got.unit, got.description, got.enumeration) == (
            row.vr, row.type, row.causality, row.variability, row.unit, row.description, row.enumeration), row.name
        if row.start is None:
            assert got.start is None, row.name
        else:
            assert got.start == pytest.approx(row.start, rel=1e-15), row.name
        if row.interval is not None:  # the declared bounds: the native FMUs' narrower ones where they have them
            low, high = (row.native_interval if native and row.native_interval else row.interval)[:2]
            assert got.interval[:2] == (pytest.approx(low, rel=1e-15) if math.isfinite(low) else -math.inf,
                                        pytest.approx(high, rel=1e-15) if math.isfinite(high) else math.inf), row.name
    root = ET.fromstring(text)
    assert root.get("description") == table(model).description
    declared = {t.get("name"): {i.get("name"): int(i.get("value")) for i in t.find("Enumeration")}
                for t in root.findall("TypeDefinitions/SimpleType")}
    assert declared == {name: var.codes for name, var in table(model).enumerations.items()}
    index = {sv.get("name"): i + 1 for i, sv in enumerate(root.find("ModelVariables"))}
    outputs = {int(u.get("index")): u.get("dependencies") for u in root.find("ModelStructure/Outputs")}
    assert sorted(outputs) == sorted(index[v.name] for v in table(model).outputs)
    for row in table(model).outputs:
        assert bool(outputs[index[row.name]]) == row.feedthrough, row.name


def test_impact_table_round_trips_through_the_model_description(any_impact_fmu):
    _assert_round_trip(any_impact_fmu, "SpherePlateImpact")


def test_ball_table_round_trips_through_the_model_description(any_ball_fmu):
    _assert_round_trip(any_ball_fmu, "BouncingBall")


@pytest.mark.parametrize("model", list(FOLDERS))
def test_the_c_header_names_every_value_reference_and_code(model):
    header = c_header(model)
    names = dict(re.findall(r"^\s+(RST_\w+) = (-?\d+),$", header, re.M))
    upper = model.upper()
    for row in table(model):
        assert names[f"RST_{upper}_VR_{re.sub(r'[^0-9A-Za-z]', '_', row.name).strip('_').upper()}"] == str(row.vr)
        for word, code in (row.codes or {}).items():
            assert names[f"RST_{upper}_{re.sub(r'[^0-9A-Za-z]', '_', row.name).strip('_').upper()}_{word.upper()}"] == str(code)
    assert f"#define RST_{upper}_N_OUTPUTS {len(table(model).outputs)}" in header


def test_a_refusal_names_the_allowed_range_as_the_table_declares_it():
    spi = table("SpherePlateImpact")
    assert spi["zener_method"].allowed_text() == "1 = exact, 2 = paper_fit, 3 = linear or 4 = ode"
    assert spi["sphere.nu"].allowed_text() == "0 <= value <= 0.5"
    assert spi["sphere.nu"].accepts(0.5) and spi["sphere.nu"].accepts(0.0)
    assert not spi["sphere.nu"].accepts(math.nextafter(0.5, 1.0))
    assert not spi["v_approach"].accepts(math.nan) and not spi["effect_tolerance"].accepts(math.inf)
    assert spi["plasticity"].word(0) == "off" and spi["restitution_model"].codes == {"e45": 1, "e44": 2}
    with pytest.raises(ValueError):
        spi["zener_method"].word(5)


def test_package_names_and_words_translate_to_fmu_names_and_codes():
    import restitution as r
    from restitution.fmu.models.sphere_plate_impact.variables import fmu_values

    steel = r.MATERIALS["s2_tool_steel"]
    values = fmu_values(**r.Sphere(steel, 0.01).params(), v=2.0, zener_method="ode", plasticity="off")
    assert values == {"sphere.E": steel.E, "sphere.nu": steel.nu, "sphere.Sy": steel.Sy, "sphere.rho": steel.rho,
                      "sphere.d": 0.01, "v_approach": 2.0, "zener_method": 4, "plasticity": 0}
    with pytest.raises(KeyError, match="sphere_G"):
        fmu_values(sphere_G=1.0)
    with pytest.raises(ValueError, match="exact"):
        fmu_values(zener_method="exakt")
