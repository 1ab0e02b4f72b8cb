"""Materials, spheres and plates, with the material presets of I. Green, Nonlinear Dyn (2022) and common
engineering materials from handbooks (appended after the paper's; their notes say where the model is not validated).

Units: E [Pa], nu [1], Sy [Pa], rho [kg/m^3], d and t [m]; each also accepts a pint Quantity of any
compatible unit (:mod:`restitution.quantities`) or a string with its unit, as the command lines read it
(``Plate(m, t="2 mm")``, ``Material("Cu", "115 GPa", 0.31, "69 MPa", "8960 kg/m3")``), stored in SI.

Brittle materials carry Sy = 1e12 Pa "to ward off yielding", as the paper does
(Table 1 footnote). Tables 1 and 2 give no elastic moduli: E is taken from
Table 3 where the material is the same, otherwise from a handbook value, which
the preset's ``source`` marks as such.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

from .domain import check_in_domain, check_poisson, check_positive
from .quantities import to_si

__all__ = ["Material", "Sphere", "Plate", "BRITTLE_SY", "MATERIALS", "ALIASES", "TABLE4_CASES", "table4_case"]

#: Yield strength the paper assigns to brittle materials [Pa].
BRITTLE_SY = 1.0e12


@dataclass(frozen=True)
class Material:
    """An isotropic, elastic-perfectly plastic material."""

    name: str  #: what messages and tables call it
    E: float  #: elastic modulus [Pa]
    nu: float  #: Poisson's ratio [1]
    Sy: float  #: yield strength [Pa] (BRITTLE_SY for brittle materials)
    rho: float  #: density [kg/m^3]
    source: str = ""  #: where each value comes from
    note: str = ""  #: where the model is not validated for the material ("" for the paper's own)

    def __post_init__(self):
        for field, unit in (("E", "Pa"), ("nu", "dimensionless"), ("Sy", "Pa"), ("rho", "kg/m**3")):
            object.__setattr__(self, field, _si(f"{self.name}.{field}", getattr(self, field), unit))
        for field, unit in (("E", "Pa"), ("Sy", "Pa"), ("rho", "kg/m3")):  # a sphere's and a plate's domain alike
            label = f"{self.name}.{field}"
            check_in_domain(label, f"sphere_{field}", check_positive(label, getattr(self, field), unit), unit)
        check_poisson(f"{self.name}.nu", self.nu)

    def params(self, role: str) -> dict:
        """The material's keyword arguments for :func:`restitution.impact` as the ``role``
        ("sphere" or "plate"): ``sphere_E``, ``sphere_nu``, ``sphere_Sy``, ``sphere_rho`` or ``plate_*``."""
        if role not in ("sphere", "plate"):
            raise ValueError(f"role = {role!r}: 'sphere' or 'plate'")
        return {f"{role}_E": self.E, f"{role}_nu": self.nu, f"{role}_Sy": self.Sy, f"{role}_rho": self.rho}

    @property
    def brittle(self) -> bool:
        return self.Sy >= BRITTLE_SY


@dataclass(frozen=True)
class Sphere:
    """Impacting sphere: material and diameter d [m]."""

    material: Material  #: what the sphere is made of (or a preset's name: "chrome_steel")
    d: float  #: diameter [m]

    def __post_init__(self):
        object.__setattr__(self, "material", _material(self.material, "sphere"))
        object.__setattr__(self, "d", _si("sphere.d", self.d, "m"))
        check_in_domain("sphere.d", "sphere_d", check_positive("sphere.d", self.d, "m"), "m")

    def params(self) -> dict:
        """Keyword arguments for :func:`restitution.impact` (``sphere_*``)."""
        return dict(self.material.params("sphere"), sphere_d=self.d)


@dataclass(frozen=True)
class Plate:
    """Target plate: material and thickness t [m]."""

    material: Material  #: what the plate is made of (or a preset's name: "al_6061")
    t: float  #: thickness [m]

    def __post_init__(self):
        object.__setattr__(self, "material", _material(self.material, "plate"))
        object.__setattr__(self, "t", _si("plate.t", self.t, "m"))
        check_in_domain("plate.t", "plate_t", check_positive("plate.t", self.t, "m"), "m")

    def params(self) -> dict:
        """Keyword arguments for :func:`restitution.impact` (``plate_*``)."""
        return dict(self.material.params("plate"), plate_t=self.t)

    def with_thickness(self, t: float) -> "Plate":
        return replace(self, t=t)


def _si(name: str, value, unit: str):
    """``value`` in SI: a pint Quantity converted, a string with its unit read as the command lines read
    it (``"2 mm"``, ``"115 GPa"``; :func:`restitution.units.python_quantity`), a number as it is."""
    if isinstance(value, str):
        from .units import python_quantity  # host side only: the FMUs never pass text

        return python_quantity(name, value, unit)
    return to_si(name, value, unit)


def _material(material, role: str) -> Material:
    """A :class:`Material`, or the preset of that name (a KeyError naming the close ones if there
    is none); a TypeError, at once, for anything else."""
    if isinstance(material, Material):
        return material
    if isinstance(material, str):
        return MATERIALS[material]
    raise TypeError(f"{role}.material = {material!r}: a restitution.Material or a preset's name "
                    f"(restitution.MATERIALS, e.g. 'chrome_steel')")


_T1 = "Green (2022) Table 1"
_T2 = "Green (2022) Table 2"
_T3 = "Green (2022) Table 3"
_HB = "handbook value, not from the paper"
_CAL = "Callister & Rethwisch, Materials Science and Engineering, App. B"
_ASM = "ASM Aerospace Specification Metals data sheet (MatWeb)"
#: What the presets from handbooks say about where Green's model is not validated for them.
_POLYMER = ("polymer: viscoelastic and strain-rate dependent, so Sy and E at impact rates differ from the "
            "quasi-static values; Green's elastic-perfectly plastic JGM model is not validated for polymers")
_WORK_HARDENING = ("strongly work-hardening (tensile strength 2.3-3.2 times Sy): the elastic-perfectly plastic "
                   "JGM model uses Sy alone")

class MaterialTable(dict):
    """The presets by short name; an unknown name raises a KeyError that lists the known names
    and suggests the closest ones (by spelling, or by the material's full name)."""

    def __missing__(self, name):
        hint = suggest_material(name, self)
        raise KeyError(f"unknown material {name!r}{hint}; known: {', '.join(sorted(self))}")


def suggest_material(name, materials) -> str:
    """" (did you mean 'a' or 'b'?)" for an unknown material ``name`` among ``materials`` (a mapping
    of short names to :class:`Material`, or just names), or "" when nothing is close.

    At most two names close in spelling (difflib's similarity >= 0.6, its default cutoff), closest
    first; if none, at most three presets whose full name contains every word of ``name`` that has
    three letters or more (underscores separate words), in the order of ``materials``."""
    import difflib

    query = str(name).lower()
    close = difflib.get_close_matches(query, list(materials), n=2)
    if not close and hasattr(materials, "items"):
        words = [w for w in query.replace("_", " ").split() if len(w) >= 3]
        close = [key for key, mat in materials.items()
                 if isinstance(mat, Material) and words and all(w in mat.name.lower() for w in words)][:3]
    if not close:
        return ""
    return " (did you mean " + " or ".join(repr(c) for c in close) + "?)"


#: Every material of the paper's Tables 1-3, then common engineering materials from handbooks,
#: keyed by a short name.
MATERIALS: dict[str, Material] = MaterialTable({
    # Table 3 (Patil & Higgs 2018): complete property sets.
    "brass_260": Material("Brass alloy 260", 103e9, 0.35, 0.393e9, 8525, _T3),
    "al_1100_h16": Material("Aluminum 1100-H16", 70e9, 0.33, 0.103e9, 2710, _T3),
    "tungsten_carbide": Material("Tungsten carbide", 621e9, 0.18, 1.720e9, 14950, _T3),
    "s2_tool_steel": Material("S2 tool steel", 207e9, 0.30, 2.00e9, 7861, _T3),
    "low_carbon_steel": Material("Low carbon steel", 200e9, 0.30, 0.303e9, 7833, _T3),
    "borosilicate_glass": Material("Borosilicate glass", 63e9, 0.20, BRITTLE_SY, 2214,
                                   f"{_T3}; Sy N/A (brittle), set to 1e12 Pa as in Table 1"),
    "al_6061": Material("Aluminum 6061", 69e9, 0.33, 0.290e9, 2700, _T3),
    # Table 1 spheres (Marinack et al. 2013) that differ from Table 3.
    "borosilicate_glass_t1": Material("Borosilicate glass (Table 1)", 63e9, 0.30, BRITTLE_SY, 2214,
                                      f"{_T1}; E from {_T3}; nu = 0.30 as Table 1 gives (0.20 in Table 3)"),
    "chrome_steel": Material("Chrome steel (AISI 52100)", 210e9, 0.30, 1.38e9, 7700,
                             f"{_T1}; E = 210 GPa is a {_HB} (AISI 52100)"),
    "nitinol_60": Material("NiTiNOL 60", 114e9, 0.34, BRITTLE_SY, 6700,
                           f"{_T1}/{_T2}; E = 114 GPa is a {_HB} (60NiTi, NASA Glenn)"),
    # Table 2 plates.
    "s7_tool_steel": Material("S7 tool steel", 207e9, 0.30, 0.552e9, 7760,
                              f"{_T2}; E = 207 GPa is a {_HB} (AISI S7)"),
    "stainless_440c": Material("Stainless steel 440C", 200e9, 0.30, 0.448e9, 7750,
                               f"{_T2}; E = 200 GPa is a {_HB} (AISI 440C)"),
    # Handbook presets, not from the paper: appended, so that the paper's keep their FMU codes 1-12.
    "copper_c110_annealed": Material("Copper C11000 (ETP), annealed", 115e9, 0.31, 69e6, 8890,
                                     f"{_CAL} (C11000: E 115 GPa, nu 0.31, 8.89 g/cm3); Sy 69 MPa: ASM Handbook "
                                     f"Vol. 2, C11000 annealed (O60) flat products", _WORK_HARDENING),
    "copper_c110_h02": Material("Copper C11000 (ETP), half hard H02", 115e9, 0.31, 250e6, 8890,
                                f"E, nu, rho as copper_c110_annealed ({_CAL}); Sy 250 MPa: ASM Handbook Vol. 2 / "
                                f"Copper Development Association, C11000 H02 flat products, typical"),
    "ti_6al_4v": Material("Titanium Ti-6Al-4V (Grade 5), annealed", 113.8e9, 0.342, 880e6, 4430,
                          f"{_ASM}, Ti-6Al-4V Grade 5 annealed, typical (not MMPDS design values); {_CAL}: "
                          f"E 114 GPa, Sy 830 MPa (min.), 4.43 g/cm3"),
    "stainless_304": Material("Stainless steel 304, annealed", 193e9, 0.29, 215e6, 8000,
                              f"{_ASM}, AISI 304 annealed, typical; {_CAL}: E 193 GPa, 8.00 g/cm3, "
                              f"Sy 205 MPa (min.)", _WORK_HARDENING),
    "stainless_316": Material("Stainless steel 316, annealed", 193e9, 0.30, 205e6, 8000,
                              f"{_CAL}: E 193 GPa, 8.00 g/cm3, Sy 205 MPa (hot finished and annealed, min.; "
                              f"the ASTM A240 minimum); nu 0.30 typical (ASM Handbook Vol. 1); typical annealed "
                              f"bar: Sy 240 MPa ({_ASM})", _WORK_HARDENING),
    "gray_cast_iron_30": Material("Gray (grey) cast iron, ASTM A48 class 30", 100e9, 0.26, BRITTLE_SY, 7200,
                                  f"ASM Handbook Vol. 1 / {_CAL} (class 30 = grade G3000): E 90-113 GPa in "
                                  f"tension, 100 GPa taken (66-157 GPa over classes 20-60), nu 0.26, tensile "
                                  f"strength 214 MPa typical and no yield point; rho 7.15-7.30 g/cm3 in handbook "
                                  f"tables, 7200 taken; Sy N/A (brittle), set to 1e12 Pa as in Table 1",
                                  "brittle: no yield point, so Sy = 1e12 Pa as the paper does for its brittle "
                                  "materials and the model sees a purely elastic body; Green's model is not "
                                  "validated for cast iron, which may crack or crush under the contact"),
    "al_7075_t6": Material("Aluminum 7075-T6", 71.7e9, 0.33, 503e6, 2810,
                           f"{_ASM}, 7075-T6, typical; {_CAL}: E 71 GPa, Sy 505 MPa, 2.80 g/cm3"),
    "pmma": Material("PMMA (acrylic)", 2.7e9, 0.35, 70e6, 1190,
                     f"E 2.7 GPa, nu 0.35: Dowling, Mechanical Behavior of Materials, Table 5.2; Sy 70 MPa within "
                     f"{_CAL}'s yield strength 53.8-73.1 MPa (E 2.24-3.24 GPa); 1.19 g/cm3 ({_CAL})", _POLYMER),
    "polycarbonate": Material("Polycarbonate (PC)", 2.38e9, 0.36, 62.1e6, 1200,
                              f"{_CAL}: E 2.38 GPa, nu 0.36, Sy 62.1 MPa, 1.20 g/cm3 (Dowling, Table 5.2: "
                              f"2.4 GPa, 0.38)", _POLYMER),
})
#: Other keys for a preset: alias -> (preset key, why the alias exists).
ALIASES = {
    "al_110_h16": ("al_1100_h16", "Table 1 prints the alloy as 'Aluminum, 110-H16'; it is Table 3's Aluminum "
                                  "1100-H16, with the same values, so the key as printed names the same preset"),
}
for _alias, (_key, _why) in ALIASES.items():
    MATERIALS[_alias] = MATERIALS[_key]

_T4 = "Green (2022) Table 4 (Patil & Higgs 2017), nu = 0.3"
_T4_SPHERE_SY = (f"{_T4}; sphere Sy not given (elastic in the FEA of [11]): "
                 f"set to 1e12 Pa, so the plate yields first")


def table4_case(case: str) -> tuple[Material, Material]:
    """(sphere material, plate material) of Table 4 case A1-A4 or B1-B4.

    Table 4's fourth column is the *plate* modulus (mislabelled "Sphere" in the
    text, see docs/paper_departures.md). Cases A: heavy, stiff sphere on a light, soft plate;
    cases B the reverse. The plate yield strength is 10, 100, 1000, 10000 MPa
    for cases 1-4.
    """
    family, number = case[:1].upper(), case[1:]
    if family not in ("A", "B") or number not in ("1", "2", "3", "4"):
        raise ValueError(f"Table 4 case = {case!r} is not one of A1-A4, B1-B4")
    heavy = dict(E=800e9, rho=15000.0)
    light = dict(E=10e9, rho=2000.0)
    sphere_props, plate_props = (heavy, light) if family == "A" else (light, heavy)
    plate_sy = 10e6 * 10 ** (int(number) - 1)
    case = family + number  # "a1" names the same case as "A1"
    sphere = Material(f"Table 4 {case} sphere", sphere_props["E"], 0.3, BRITTLE_SY, sphere_props["rho"], _T4_SPHERE_SY)
    plate = Material(f"Table 4 {case} plate", plate_props["E"], 0.3, plate_sy, plate_props["rho"], _T4)
    return sphere, plate


TABLE4_CASES = tuple(f"{f}{n}" for f in "AB" for n in "1234")

#: Table 1 cases: (sphere material key, sphere diameter [m], plate material key).
TABLE1_CASES = {
    1: ("al_110_h16", 6.35e-3, "s7_tool_steel"),
    2: ("borosilicate_glass_t1", 4.76e-3, "s7_tool_steel"),
    3: ("borosilicate_glass_t1", 4.76e-3, "borosilicate_glass_t1"),
    4: ("borosilicate_glass_t1", 6.35e-3, "s7_tool_steel"),
    5: ("borosilicate_glass_t1", 6.35e-3, "borosilicate_glass_t1"),
    6: ("brass_260", 4.76e-3, "s7_tool_steel"),
    7: ("brass_260", 6.35e-3, "s7_tool_steel"),
    8: ("chrome_steel", 4.76e-3, "s7_tool_steel"),
    9: ("chrome_steel", 4.76e-3, "stainless_440c"),
    10: ("low_carbon_steel", 4.76e-3, "s7_tool_steel"),
    11: ("low_carbon_steel", 6.35e-3, "s7_tool_steel"),
    12: ("nitinol_60", 6.35e-3, "s7_tool_steel"),
    13: ("nitinol_60", 6.35e-3, "nitinol_60"),
    14: ("s2_tool_steel", 6.35e-3, "nitinol_60"),
    15: ("s2_tool_steel", 4.76e-3, "s7_tool_steel"),
    16: ("tungsten_carbide", 4.76e-3, "s7_tool_steel"),
    17: ("tungsten_carbide", 4.76e-3, "stainless_440c"),
}
__all__.append("TABLE1_CASES")
