"""Materials by name in every SpherePlateImpact FMU (pythonfmu, native FMI 2.0, native FMI 3.0; the
modelDescription test: the FMI 2.0 ones, test_fmi3_model_description.py has FMI 3.0's): sphere.material and
plate.material are Enumerations whose items are "custom" and every preset of docs/materials.md; a preset replaces the
body's four numeric parameters, and sphere.used.* / plate.used.* show the values the model uses.

The expected values come from the presets (restitution.MATERIALS, themselves checked against the
paper's tables in tests/physics/test_paper_tables.py) and from the same FMU given those numbers as a
custom material: the same doubles reach the same code, so e agrees to a few ulps (rel 1e-14)."""
import math
import zipfile
from xml.etree import ElementTree as ET

import pytest

import restitution as r
from restitution.cosim import FmiStatusError, FmuInstance
from restitution.materials import ALIASES

PRESETS = [key for key in r.MATERIALS if key not in ALIASES]
PROPS = ("E", "nu", "Sy", "rho")


def _used(fmu, body):
    return dict(zip(PROPS, fmu.get(*(f"{body}.used.{p}" for p in PROPS))))


def test_the_enumeration_lists_custom_and_every_preset(any_impact_fmu):
    with zipfile.ZipFile(any_impact_fmu) as z:
        root = ET.fromstring(z.read("modelDescription.xml"))
    items = [(i.get("name"), int(i.get("value"))) for i in root.find("TypeDefinitions/SimpleType/Enumeration")]
    assert items == list(zip(["custom", *PRESETS], range(len(PRESETS) + 1)))
    selectors = {sv.get("name"): sv[0] for sv in root.find("ModelVariables") if sv[0].tag == "Enumeration"}
    assert set(selectors) == {"sphere.material", "plate.material"}
    assert all(node.get("declaredType") == "Material" and node.get("start") == "0" for node in selectors.values())


@pytest.mark.parametrize("body", ["sphere", "plate"])
@pytest.mark.parametrize("preset", PRESETS)
def test_a_preset_by_name_is_the_same_as_its_numbers(any_version_impact_fmu, body, preset):
    material = r.MATERIALS[preset]
    numbers = {f"{body}.{p}": float(getattr(material, p)) for p in PROPS}
    with FmuInstance(any_version_impact_fmu, parameters={f"{body}.material": preset}) as by_name:
        by_name.set(v_approach=2.3)
        used = _used(by_name, body)
        e_by_name = by_name.get("e")[0]
    with FmuInstance(any_version_impact_fmu, parameters=numbers) as by_numbers:
        by_numbers.set(v_approach=2.3)
        e_by_numbers = by_numbers.get("e")[0]
    assert used == {p: float(getattr(material, p)) for p in PROPS}
    assert e_by_name == pytest.approx(e_by_numbers, rel=1e-14, abs=1e-15)


def test_custom_uses_the_numbers_and_a_preset_ignores_them(any_version_impact_fmu):
    with FmuInstance(any_version_impact_fmu, parameters={"plate.E": 100e9, "plate.rho": 3000.0}) as fmu:
        fmu.set(v_approach=2.3)
        assert _used(fmu, "plate")["E"] == 100e9 and _used(fmu, "plate")["rho"] == 3000.0
        custom = fmu.get("e")[0]
        fmu.set(**{"plate.material": "al_6061"})
        aluminium = fmu.get("e")[0]
        assert _used(fmu, "plate") == {p: float(getattr(r.MATERIALS["al_6061"], p)) for p in PROPS}
        fmu.set(**{"plate.E": 1e6})  # ignored while a preset is chosen
        assert fmu.get("e")[0] == aluminium and _used(fmu, "plate")["E"] == 69e9
        fmu.set(**{"plate.material": "custom"})
        assert _used(fmu, "plate")["E"] == 1e6 and fmu.get("e")[0] != custom  # the numbers as set now
        assert math.isfinite(aluminium) and aluminium != custom


@pytest.mark.parametrize("code", [-1, len(PRESETS) + 1, 2 ** 31 - 1])
def test_a_code_outside_the_items_is_refused_and_the_previous_kept(any_version_impact_fmu, code):
    with FmuInstance(any_version_impact_fmu, parameters={"sphere.material": "brass_260"}) as fmu:
        with pytest.raises(FmiStatusError, match=r"sphere\.material = -?\d+ is outside the allowed range"):
            fmu.set(**{"sphere.material": code})
        assert fmu.get("sphere.material") == [1] and _used(fmu, "sphere")["E"] == 103e9
    with pytest.raises(ValueError, match=r"'steel' is not one of its items: custom, brass_260"):
        FmuInstance(any_version_impact_fmu, parameters={"sphere.material": "steel"})


def test_the_used_values_cannot_be_set(any_version_impact_fmu):
    with FmuInstance(any_version_impact_fmu) as fmu:
        with pytest.raises(FmiStatusError, match=r"sphere\.used\.E is a calculated parameter and cannot be set"):
            fmu.set(**{"sphere.used.E": 1e9})


def test_an_fmu_state_carries_the_materials(any_version_impact_fmu):
    with FmuInstance(any_version_impact_fmu, parameters={"plate.material": "borosilicate_glass"}) as fmu:
        fmu.set(v_approach=1.0)
        state = fmu.get_state()
        glass = fmu.get("e")[0]
        fmu.set(**{"plate.material": "brass_260"})
        assert fmu.get("e")[0] != glass
        fmu.set_state(state)
        fmu.free_state(state)
        assert fmu.get("plate.material") == [6] and fmu.get("e")[0] == glass
        assert _used(fmu, "plate")["nu"] == 0.2
