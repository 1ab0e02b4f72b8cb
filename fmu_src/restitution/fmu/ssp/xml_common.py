"""What the SSP files share: the XML namespaces, the SSP versions written, the units of the FMUs'
variables as SI base-unit exponents, and writing a document (UTF-8, indented, the same bytes for the
same content).

SSP 1.0 and SSP 2.0 use the same namespaces (``http://ssp-standard.org/SSP1/...``): SSP 2.0 keeps every
SSP 1.0 file valid and tells them apart by the ``version`` attribute; FMI 3.0's Float64 is written as
SSP 2.0's ``Float64`` (SSP 1.0 has ``Real`` only)."""
from __future__ import annotations

from xml.etree import ElementTree as ET

NAMESPACES = {
    "ssc": "http://ssp-standard.org/SSP1/SystemStructureCommon",
    "ssd": "http://ssp-standard.org/SSP1/SystemStructureDescription",
    "ssv": "http://ssp-standard.org/SSP1/SystemStructureParameterValues",
    "osp": "http://opensimulationplatform.com/SSP/OSPAnnotations",
}
for _prefix, _uri in NAMESPACES.items():
    ET.register_namespace(_prefix, _uri)

#: The SSP versions written: SSP version -> (FMI version of the FMUs inside, name of a 64-bit float type).
SSP_VERSIONS = {"1.0": ("2.0", "Real"), "2.0": ("3.0", "Float64")}

#: The units of the FMUs' variables, as exponents of the SI base units (ssc:BaseUnit's attributes).
BASE_UNITS = {
    "m": {"m": 1}, "s": {"s": 1}, "m/s": {"m": 1, "s": -1}, "m/s2": {"m": 1, "s": -2},
    "Pa": {"kg": 1, "m": -1, "s": -2}, "kg/m3": {"kg": 1, "m": -3}, "kg": {"kg": 1}, "1": {},
}


def fmu_variables(fmu) -> dict:
    """{name: fmpy's variable} of the FMU ``fmu`` (its modelDescription.xml: type, unit, declared type)."""
    from fmpy import read_model_description

    return {v.name: v for v in read_model_description(str(fmu)).modelVariables}


def unit_of(variable) -> str | None:
    """The unit of an fmpy variable (its own or its declared type's), None where it has none."""
    unit = getattr(variable, "unit", None)
    if unit is None and getattr(variable, "declaredType", None) is not None:
        unit = getattr(variable.declaredType, "unit", None)
    return unit


def enumeration_items(variable) -> tuple[str, dict] | None:
    """(type name, {item name: value}) of an Enumeration variable, None for any other."""
    declared = getattr(variable, "declaredType", None)
    if variable.type != "Enumeration" or declared is None:
        return None
    return declared.name, {item.name: int(item.value) for item in declared.items}


def tag(prefix: str, name: str) -> str:
    """The qualified name ``{namespace}name`` of ``prefix:name``."""
    return f"{{{NAMESPACES[prefix]}}}{name}"


def check_version(version: str) -> tuple[str, str]:
    """(FMI version, float type) of SSP ``version``; ValueError for another version."""
    if version not in SSP_VERSIONS:
        raise ValueError(f"SSP version {version!r}: one of {', '.join(SSP_VERSIONS)}")
    return SSP_VERSIONS[version]


def units_element(parent, prefix: str, units) -> None:
    """``<prefix:Units>`` (ssc:TUnits) below ``parent`` declaring each unit of ``units`` (sorted), none if
    empty."""
    units = sorted(set(units))
    if not units:
        return
    holder = ET.SubElement(parent, tag(prefix, "Units"))
    for unit in units:
        if unit not in BASE_UNITS:
            raise KeyError(f"unit {unit!r} has no base-unit definition here (restitution.fmu.ssp.BASE_UNITS)")
        element = ET.SubElement(holder, tag("ssc", "Unit"), name=unit)
        ET.SubElement(element, tag("ssc", "BaseUnit"), {k: str(v) for k, v in sorted(BASE_UNITS[unit].items())})


def enumerations_element(parent, prefix: str, enumerations: dict) -> None:
    """``<Enumerations>`` below ``parent``: {name: {item name: value}}, none if empty."""
    if not enumerations:
        return
    holder = ET.SubElement(parent, tag(prefix, "Enumerations"))
    for name, items in enumerations.items():
        element = ET.SubElement(holder, tag("ssc", "Enumeration"), name=name)
        for item, value in items.items():
            ET.SubElement(element, tag("ssc", "Item"), name=item, value=str(int(value)))


def to_bytes(root) -> bytes:
    """The document of ``root``: an XML declaration, two-space indentation, UTF-8, a final newline."""
    ET.indent(root, "  ")
    return b'<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="utf-8",
                                                                        xml_declaration=False) + b"\n"
