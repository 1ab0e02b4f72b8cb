"""docs/names.md, the names of every variable in the FMUs and in Python: the generator's output, and each
Python name is what the package really takes or gives (read from impact()'s signature and
ImpactResult's fields here, not from the generator)."""
import dataclasses
import inspect
import re
from pathlib import Path

import restitution as r
from restitution.fmu.describe.names import markdown, rows

ROOT = Path(__file__).resolve().parents[2]


def test_docs_names_md_is_the_generated_page():
    doc = (ROOT / "docs" / "names.md").read_text(encoding="utf-8")
    assert doc == markdown(), "docs/names.md is stale: python -m restitution.fmu.describe.names > docs/names.md"


def test_every_python_name_is_an_argument_a_result_field_or_a_material_value():
    arguments = set(inspect.signature(r.impact).parameters)
    fields = {f.name for f in dataclasses.fields(r.ImpactResult)} | {"valid"}
    material = {f.name for f in dataclasses.fields(r.Material)}
    seen = set()
    for fmu_name, python, role, _unit, _description in rows():
        name = python.strip("`")
        if role.startswith("argument"):
            assert name in arguments, (fmu_name, name)
        elif role == "result field":
            assert name in fields, (fmu_name, name)
            assert name in r.impact(2.0, **r.Sphere("chrome_steel", d=0.01).params(),
                                    **r.Plate("al_6061", t=3e-3).params()).as_dict()
        elif role == "the material's value":
            assert name.split(".")[1] in material, (fmu_name, name)
        else:
            assert re.fullmatch(r"(Sphere\(material, d\)|Plate\(material, t\))", name), (fmu_name, name)
        seen.add(fmu_name)
    assert len(seen) == len(rows())  # one row per FMU variable
    assert fields <= {python.strip("`") for _f, python, role, _u, _d in rows() if role == "result field"} | {"eps_y", "T", "m_eff"}
