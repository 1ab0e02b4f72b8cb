"""The SSV parameter sets shipped in the SSP (``resources/*.ssv``) and writing them.

The set SystemStructure.ssd binds by default, :data:`DEFAULT_SET`, holds Real parameters only: E, nu, Sy,
rho of both bodies, d and t of the Table 3 pair the FMUs default to (S2 tool steel, d = 6.35 mm, on Al
6061, t = d), written out from the presets. The FMUs' materials default to ``custom`` (those numbers are
used), so the default binding needs no enumeration and every importer that reads ``ssv:Real`` applies it
(libcosim 0.0.6 and ecos 0.7.2 read no ``ssv:Enumeration``: docs/ssp.md).

The alternative sets name their materials by enumeration item (``<ssv:Enumeration
value="s7_tool_steel"/>``), never by code: one per material pair of the paper's experiments, the 17
cases of Table 1 (Marinack et al., spheres of 4.76 and 6.35 mm on thick plates: t = 10 d, a half-space
for the plate-wave term, since the cases give no thickness) and the Table 3 pair by preset name; and
``custom``, the default set's numbers with both materials named ``custom``. ``ball`` holds the ball's
drop: h0, g, contact_mode, v_min (the BouncingBall FMU's own defaults, written out).

The Real values of a set are written with the unit of the variable they set (the FMU's
modelDescription.xml), which the set declares in its ``<ssv:Units>``.
"""
from __future__ import annotations

from dataclasses import dataclass
from xml.etree import ElementTree as ET

from ...materials import ALIASES, MATERIALS, TABLE1_CASES
from .xml_common import check_version, enumeration_items, enumerations_element, tag, to_bytes, unit_of, \
    units_element

__all__ = ["ParameterSet", "impact_parameter_sets", "BALL_SET", "DEFAULT_SET", "PRESET_PAIR_SET", "write_parameter_set"]

#: Table 1 gives no plate thickness; the experiments dropped the spheres on thick plates [m per m of d].
TABLE1_THICKNESS_OVER_D = 10.0
#: The Table 3 pair the FMUs default to: (sphere preset, d [m], plate preset, t [m]).
TABLE3_DEFAULT = ("s2_tool_steel", 6.35e-3, "al_6061", 6.35e-3)


@dataclass(frozen=True)
class ParameterSet:
    """A named parameter set: FMU variable name -> value (a number, or an enumeration item's name)."""

    name: str  #: the set's name (its file is resources/<name>.ssv)
    description: str
    values: dict

    @property
    def entry(self) -> str:
        """Its path in the SSP archive."""
        return f"resources/{self.name}.ssv"


def _preset(key: str) -> str:
    """The enumeration item of a preset key (an alias names its preset's item)."""
    return ALIASES[key][0] if key in ALIASES else key


def _pair(name, description, sphere, d, plate, t) -> ParameterSet:
    return ParameterSet(name, description, {"sphere.material": _preset(sphere), "sphere.d": float(d),
                                            "plate.material": _preset(plate), "plate.t": float(t)})


def _table3_properties(name: str, description: str, material_names: bool) -> ParameterSet:
    """The Table 3 pair's E, nu, Sy, rho of both bodies, d and t, from the presets; ``material_names``:
    also both materials set to the item ``custom`` (an ``ssv:Enumeration``)."""
    sphere_key, d, plate_key, t = TABLE3_DEFAULT
    values = {"sphere.material": "custom", "plate.material": "custom"} if material_names else {}
    for body, key in (("sphere", sphere_key), ("plate", plate_key)):
        material = MATERIALS[key]
        values.update({f"{body}.E": material.E, f"{body}.nu": material.nu, f"{body}.Sy": material.Sy,
                       f"{body}.rho": material.rho})
    values.update({"sphere.d": d, "plate.t": t})
    return ParameterSet(name, description, values)


def impact_parameter_sets() -> list[ParameterSet]:
    """SpherePlateImpact's sets: the Table 3 pair as numbers (the default) and by preset name, the 17
    Table 1 cases, custom (module doc)."""
    sphere, d, plate, t = TABLE3_DEFAULT
    pair_text = "S2 tool steel sphere, d = 6.35 mm, on Al 6061, t = 6.35 mm"
    sets = [_table3_properties(DEFAULT_SET, f"Green (2022) Table 3 pair, the FMUs' defaults, every property a "
                                            f"number with its unit (materials left 'custom'): {pair_text}", False),
            _pair(PRESET_PAIR_SET, f"Green (2022) Table 3 pair by preset name: {pair_text}", sphere, d, plate, t)]
    for case, (sphere, d, plate) in sorted(TABLE1_CASES.items()):
        t = TABLE1_THICKNESS_OVER_D * d
        sets.append(_pair(f"table1_case{case:02d}",
                          f"Green (2022) Table 1 case {case}: {MATERIALS[sphere].name} sphere, d = {d * 1e3:g} mm, "
                          f"on {MATERIALS[plate].name} (thickness not given: t = {TABLE1_THICKNESS_OVER_D:g} d)",
                          sphere, d, plate, t))
    return sets + [_table3_properties("custom", "Every property given explicitly with its unit, both materials "
                                                f"named 'custom': here the values of {pair_text}", True)]


#: The set SystemStructure.ssd binds to the impact component: Real parameters only (module doc).
DEFAULT_SET = "table3_s2_tool_steel_on_al_6061_properties"
#: The same pair by preset name (``ssv:Enumeration``), an alternative set.
PRESET_PAIR_SET = "table3_s2_tool_steel_on_al_6061"
#: The ball's set: dropped from 0.3 m under standard gravity, waiting at the plate for the COR
#: (contact_mode 1 = wait), at rest below 0.1 m/s. contact_mode is an Integer in the FMI 2.0 FMU and an
#: Enumeration in the FMI 3.0 one: there the code is written as its item's name ("wait").
BALL_SET = ParameterSet("ball", "BouncingBall: drop height, gravity, contact mode, rest speed",
                        {"h0": 0.3, "g": 9.80665, "contact_mode": 1, "v_min": 0.1})


def _parameter(parent, name, value, variable, float_type, int_type, units, enumerations, codes):
    """One ``<ssv:Parameter>`` typed as ``variable`` (an fmpy variable of the FMU it sets); ``codes``:
    an Enumeration as its Integer code instead of its item's name."""
    element = ET.SubElement(parent, tag("ssv", "Parameter"), name=name)
    enumeration = enumeration_items(variable)
    if enumeration is not None and codes:
        type_name, items = enumeration
        code = items[value] if isinstance(value, str) else int(value)
        if code not in items.values():
            raise ValueError(f"{name} = {value!r}: not an item of {type_name} ({', '.join(items)})")
        ET.SubElement(element, tag("ssv", int_type), value=str(code))
    elif enumeration is not None:
        type_name, items = enumeration
        item = value if isinstance(value, str) else {v: k for k, v in items.items()}[int(value)]
        if item not in items:
            raise ValueError(f"{name} = {item!r}: not an item of {type_name} ({', '.join(items)})")
        enumerations[type_name] = items
        ET.SubElement(element, tag("ssv", "Enumeration"), value=item, name=type_name)
    elif variable.type in ("Real", "Float64"):
        attrs = {"value": repr(float(value))}
        unit = unit_of(variable)
        if unit is not None:
            attrs["unit"] = unit
            units.add(unit)
        ET.SubElement(element, tag("ssv", float_type), attrs)
    elif variable.type in ("Integer", "Int32"):
        if isinstance(value, str) or int(value) != value:
            raise ValueError(f"{name} = {value!r}: an Integer parameter takes a whole number")
        ET.SubElement(element, tag("ssv", int_type), value=str(int(value)))
    elif variable.type == "Boolean":
        ET.SubElement(element, tag("ssv", "Boolean"), value="true" if value else "false")
    else:
        raise ValueError(f"{name}: parameters of type {variable.type} are not written")


def parameter_set_element(pset: ParameterSet, variables: dict, version: str, enumeration_codes: bool = False):
    """The ``<ssv:ParameterSet>`` element of ``pset`` for SSP ``version``, typed by ``variables`` ({name:
    fmpy variable} of the FMU it sets). ``enumeration_codes``: Enumerations as Integer codes, for the hosts
    that read no ``<ssv:Enumeration>`` (libcosim 0.0.6, ecos 0.7.2: docs/ssp.md)."""
    _fmi, float_type = check_version(version)
    int_type = "Integer" if version == "1.0" else "Int32"
    root = ET.Element(tag("ssv", "ParameterSet"), version=version, name=pset.name, description=pset.description)
    parameters = ET.SubElement(root, tag("ssv", "Parameters"))
    units, enumerations = set(), {}
    for name, value in pset.values.items():
        if name not in variables:
            raise KeyError(f"parameter set {pset.name}: the FMU has no variable {name!r}")
        _parameter(parameters, name, value, variables[name], float_type, int_type, units, enumerations,
                   enumeration_codes)
    enumerations_element(root, "ssv", enumerations)
    units_element(root, "ssv", units)
    return root


def write_parameter_set(pset: ParameterSet, variables: dict, version: str) -> bytes:
    """The SSV file of ``pset`` (see :func:`parameter_set_element`), enumerations by item name."""
    return to_bytes(parameter_set_element(pset, variables, version))
