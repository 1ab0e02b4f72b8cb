"""The presets from handbooks (common engineering materials, not from the paper): each one's values are the
numbers of the reference its source names (written here, not read back from the code), each runs through
restitution.impact as a sphere and as a plate, the polymers and the cast iron say where Green's model is not
validated, the paper's twelve presets keep their FMU codes 1-12 (the new ones come after), and
`restitution materials` groups the presets by source. tests/fmu/test_materials_by_name.py runs every preset
(these included) by name through each FMU, native C ones included, against the same FMU given the numbers."""
import math
import re
import subprocess
import sys
from pathlib import Path

import pytest

import restitution as r
from restitution.materials import ALIASES, BRITTLE_SY
from restitution.materials_table import markdown, text

ROOT = Path(__file__).resolve().parents[2]
CAL = "Callister & Rethwisch"
ASM = "ASM Aerospace Specification Metals"

#: key -> (E [GPa], nu, Sy [MPa] or None for brittle, rho [kg/m3], references the source must name).
#: Callister & Rethwisch App. B: Table B.1 density, B.2 modulus, B.3 Poisson's ratio, B.4 yield strength.
CITED = {
    # Callister: C11000 115 GPa, 0.31, 8.89 g/cm3; ASM Handbook Vol. 2: annealed (O60) yield 69 MPa
    "copper_c110_annealed": (115, 0.31, 69, 8890, (CAL, "ASM Handbook Vol. 2", "O60")),
    # ASM Handbook Vol. 2 / CDA: C11000 H02 flat products, yield 250 MPa
    "copper_c110_h02": (115, 0.31, 250, 8890, (CAL, "ASM Handbook Vol. 2", "H02")),
    # ASM Aerospace Specification Metals (MatWeb), Ti-6Al-4V Grade 5 annealed: 113.8 GPa, 0.342, 880 MPa, 4.43
    "ti_6al_4v": (113.8, 0.342, 880, 4430, (ASM, CAL, "not MMPDS")),
    # ASM Aerospace Specification Metals, AISI 304 annealed: 193 GPa, 0.29, 215 MPa, 8.00 g/cm3
    "stainless_304": (193, 0.29, 215, 8000, (ASM, CAL)),
    # Callister: 316 193 GPa, 8.00 g/cm3, 205 MPa hot finished and annealed (min.); nu 0.30 (ASM Handbook Vol. 1)
    "stainless_316": (193, 0.30, 205, 8000, (CAL, "ASTM A240", "ASM Handbook Vol. 1")),
    # ASM Handbook Vol. 1 / Callister G3000: 90-113 GPa (100 taken), 0.26, no yield point; 7.15-7.30 g/cm3
    "gray_cast_iron_30": (100, 0.26, None, 7200, ("ASM Handbook Vol. 1", CAL, "1e12 Pa")),
    # ASM Aerospace Specification Metals, 7075-T6: 71.7 GPa, 0.33, 503 MPa, 2.81 g/cm3
    "al_7075_t6": (71.7, 0.33, 503, 2810, (ASM, CAL)),
    # Dowling, Mechanical Behavior of Materials, Table 5.2: 2.7 GPa, 0.35; Callister: yield 53.8-73.1, 1.19 g/cm3
    "pmma": (2.7, 0.35, 70, 1190, ("Dowling", CAL, "53.8-73.1")),
    # Callister: polycarbonate 2.38 GPa, 0.36, yield 62.1 MPa, 1.20 g/cm3
    "polycarbonate": (2.38, 0.36, 62.1, 1200, (CAL,)),
}
#: The FMU material codes (Enumeration items) hosts may have stored: the paper's twelve, as they were.
PAPER_CODES = ("brass_260", "al_1100_h16", "tungsten_carbide", "s2_tool_steel", "low_carbon_steel",
               "borosilicate_glass", "al_6061", "borosilicate_glass_t1", "chrome_steel", "nitinol_60",
               "s7_tool_steel", "stainless_440c")
PRESETS = [key for key in r.MATERIALS if key not in ALIASES]


@pytest.mark.parametrize("key", CITED)
def test_each_handbook_preset_is_its_cited_numbers(key):
    E_gpa, nu, sy_mpa, rho, references = CITED[key]
    m = r.MATERIALS[key]
    assert m.E == pytest.approx(E_gpa * 1e9, rel=1e-12) and m.nu == nu and m.rho == rho
    assert m.Sy == (BRITTLE_SY if sy_mpa is None else pytest.approx(sy_mpa * 1e6, rel=1e-12))
    assert m.brittle == (sy_mpa is None)
    assert not m.source.startswith("Green (2022)"), "a handbook preset must not read as the paper's"
    for reference in references:
        assert reference in m.source, (key, reference, m.source)


def test_every_preset_not_from_the_paper_is_cited_here():
    assert [k for k in PRESETS if not r.MATERIALS[k].source.startswith("Green (2022)")] == list(CITED)


@pytest.mark.parametrize("key", ["pmma", "polycarbonate"])
def test_polymers_say_the_model_is_not_validated_for_them(key):
    note = r.MATERIALS[key].note
    assert "not validated for polymers" in note and "viscoelastic" in note and "strain-rate" in note


def test_cast_iron_is_brittle_and_says_so():
    m = r.MATERIALS["gray_cast_iron_30"]
    assert m.Sy == BRITTLE_SY and m.brittle
    assert "brittle" in m.note and "not validated for cast iron" in m.note


def test_the_papers_presets_carry_no_note():
    assert all(not r.MATERIALS[k].note for k in PAPER_CODES)


@pytest.mark.parametrize("key", CITED)
def test_each_handbook_preset_runs_through_impact(key):
    """As the plate under a chrome-steel ball, and as the sphere on an S7 tool-steel plate (Table 1's)."""
    for sphere, plate in ((r.Sphere("chrome_steel", 6.35e-3), r.Plate(key, 6.35e-3)),
                          (r.Sphere(key, 6.35e-3), r.Plate("s7_tool_steel", 6.35e-3))):
        res = r.impact(2.0, **sphere.params(), **plate.params())
        assert math.isfinite(res.e) and -1.0 < res.e <= 1.0, (key, res.e)
        assert 0.0 < res.e_ep <= 1.0 and 0.0 <= res.e_ze <= 1.0
    # under a brittle glass ball, only a material that yields dissipates energy plastically at 2 m/s
    glass = r.impact(2.0, **r.Sphere("borosilicate_glass", 6.35e-3).params(), **r.Plate(key, 6.35e-3).params())
    assert (glass.e_ep == 1.0) == r.MATERIALS[key].brittle


def test_the_papers_presets_keep_their_fmu_codes_and_the_new_ones_follow():
    from restitution.fmu.models.sphere_plate_impact.variables import MATERIAL_CHOICES

    assert MATERIAL_CHOICES[:13] == ("custom", *PAPER_CODES)
    assert MATERIAL_CHOICES[13:] == tuple(CITED)


def test_hosts_page_lists_every_code():
    from restitution.fmu.models.sphere_plate_impact.variables import MATERIAL_CHOICES

    page = " ".join((ROOT / "docs" / "hosts.md").read_text(encoding="utf-8").split())
    listed = re.findall(r"\b(\d+) ([a-z][a-z0-9_]+)", page.split("The material")[1].split("([materials]")[0])
    assert [(int(c), k) for c, k in listed] == list(enumerate(MATERIAL_CHOICES))


def test_the_listing_groups_the_presets_by_source():
    out = text()
    paper, handbook = out.split("\n\nsources:")[0].split("Handbook values, not from the paper:")
    assert paper.startswith("From the paper's tables (Green 2022, Tables 1-3):")

    def keys(block):
        return [line.split()[0] for line in block.splitlines() if line.split()[:1] and line.split()[0] in PRESETS]

    assert keys(paper) == list(PAPER_CODES) and keys(handbook) == list(CITED)
    for block in (paper, handbook):
        assert "E [GPa]  nu [1]  Sy [MPa]  rho [kg/m3]" in re.sub(r" {2,}", "  ", block)
    notes = out.split("each preset's note):")[1]
    for key in ("pmma", "polycarbonate", "gray_cast_iron_30"):
        assert f"  {key}: {r.MATERIALS[key].note}" in notes
    md = markdown()
    assert md.index("## From the paper's tables") < md.index("`stainless_440c`") < md.index(
        "## Handbook values, not from the paper") < md.index("`copper_c110_annealed`")
    assert f"- `pmma`: {r.MATERIALS['pmma'].note}." in md


def test_restitution_materials_command_prints_the_groups():
    out = subprocess.run([sys.executable, "-m", "restitution", "materials"], capture_output=True, text=True,
                         check=True).stdout
    assert "From the paper's tables" in out and "Handbook values, not from the paper:" in out
    assert "not validated for polymers" in out
