"""The FMUs' interface as data, from the one source: each slave's ``VARIABLES`` table.

:func:`variables` lists every variable of an FMU as pythonfmu registers it (value reference,
type, causality, variability, initial, start) joined with the slave's table (unit, description)
and its ``allowed_interval`` (range of inputs and parameters). The C guard in front of pythonfmu
and the native FMU are compiled against :func:`c_header`, generated at build time, so no C code
parses XML at run time and no C table is edited by hand.

    python -m restitution.fmu.interface SpherePlateImpact > interface.h
"""
from __future__ import annotations

import math
import sys
from dataclasses import dataclass

#: The layout of the C row (``cfront/rst_variable.h``'s RST_VARIABLE_LAYOUT): the generated header
#: refuses to compile against another.
TABLE_VERSION = 2


@dataclass(frozen=True)
class Variable:
    """One scalar variable of an FMU's interface (units and ranges in SI, as in the modelDescription)."""

    vr: int
    name: str
    type: str  #: "Real", "Integer" or "Boolean"
    causality: str  #: "parameter", "input", "output" or "local"
    variability: str  #: "fixed", "tunable", "discrete" or "continuous"
    initial: str | None  #: "exact", "calculated", ... or None (not declared)
    start: float | int | bool | None
    unit: str | None
    description: str
    #: allowed values of an input or parameter: (low, high, low_open, high_open); None for outputs
    interval: tuple | None
    range_text: str | None  #: the allowed range as an error message shows it
    #: part of the FMU state: inputs, parameters, and outputs/locals the model evolves (those the
    #: slave can set back, i.e. registered with a setter); other outputs are recomputed from them
    state: bool = False


def _slave_class(module):
    from pythonfmu import Fmi2Slave

    classes = [obj for obj in vars(module).values()
               if isinstance(obj, type) and issubclass(obj, Fmi2Slave) and obj is not Fmi2Slave]
    if len(classes) != 1:
        raise RuntimeError(f"{module.__name__} defines {len(classes)} Fmi2Slave classes, expected one")
    return classes[0]


def variables(model: str) -> list[Variable]:
    """Every variable of ``model`` (a key of :data:`restitution.fmu.build.FMUS`), by value reference."""
    from .build import _slave_module

    module = _slave_module(model)
    rows = {row[0]: row for row in module.VARIABLES}
    slave = _slave_class(module)(instance_name="interface-table", visible=False)
    out = []
    for vr, var in sorted(slave.vars.items()):
        _name, vtype, causality, unit, _start, description, _key = rows[var.name]
        interval = text = None
        if causality in ("parameter", "input"):
            interval = tuple(module.allowed_interval(var.name))
            text = module.allowed_range(var.name)[1]
        initial = getattr(var, "initial", None)
        out.append(Variable(
            vr=vr, name=var.name, type=vtype, causality=var.causality.name, variability=var.variability.name,
            initial=initial.name if initial is not None else None, start=getattr(var, "start", None),
            unit=unit, description=description, interval=interval, range_text=text,
            state=causality in ("parameter", "input") or getattr(var, "setter", None) is not None))
    return out


def variables_from_model_description(xml_text: str) -> list[Variable]:
    """The variables of any pythonfmu FMU, from its modelDescription.xml, for FMUs without a
    ``VARIABLES`` table (a foreign or toy FMU given to ``make_standalone``). Read at build time only.
    Ranges are the declared min/max (closed), or any finite value; every input and parameter is
    part of the state, outputs and locals are not (pythonfmu cannot say which the model evolves)."""
    from xml.etree import ElementTree as ET

    out = []
    for sv in ET.fromstring(xml_text).find("ModelVariables"):
        node = sv[0]
        vtype = node.tag
        if vtype not in ("Real", "Integer", "Boolean"):
            raise ValueError(f"variable {sv.get('name')}: type {vtype} is not supported by the C front")
        causality = sv.get("causality", "local")
        start = node.get("start")
        if start is not None:
            start = {"Real": float, "Integer": int, "Boolean": lambda s: s in ("true", "1")}[vtype](start)
        interval = text = None
        if causality in ("parameter", "input"):
            low = float(node.get("min", "-inf"))
            high = float(node.get("max", "inf"))
            interval = (low, high, math.isinf(low), math.isinf(high))
            text = "finite" if interval[2] and interval[3] else f"{node.get('min', '-inf')} <= value <= {node.get('max', 'inf')}"
        out.append(Variable(
            vr=int(sv.get("valueReference")), name=sv.get("name"), type=vtype, causality=causality,
            variability=sv.get("variability", "continuous"), initial=sv.get("initial"), start=start,
            unit=node.get("unit"), description=sv.get("description", ""), interval=interval, range_text=text,
            state=causality in ("parameter", "input")))
    return sorted(out, key=lambda v: v.vr)


def model_info(xml_text: str) -> tuple[str, str]:
    """(modelIdentifier of the co-simulation part, guid) of a modelDescription.xml."""
    from xml.etree import ElementTree as ET

    root = ET.fromstring(xml_text)
    identifier = root.find("CoSimulation").get("modelIdentifier")
    guid = root.get("guid")
    if not all(c.isalnum() or c in "{}-_" for c in identifier + guid):
        raise ValueError(f"unexpected characters in modelIdentifier {identifier!r} or guid {guid!r}")
    return identifier, guid


def model_info_header(xml_text: str) -> str:
    """``rst_model_info.h``: the model identifier and the GUID of the modelDescription (the front's
    fmi2Instantiate checks the GUID a host passes against it)."""
    identifier, guid = model_info(xml_text)
    return ("/* Generated by restitution.fmu.interface from modelDescription.xml. Do not edit. */\n"
            "#ifndef RST_MODEL_INFO_H\n#define RST_MODEL_INFO_H\n"
            f'#define RST_MODEL_IDENTIFIER "{identifier}"\n#define RST_MODEL_GUID "{guid}"\n#endif\n')


def _c_string(text: str | None) -> str:
    """A C string literal of ``text``'s UTF-8 bytes; anything but printable ASCII as a 3-digit octal
    escape (a hex escape would swallow the hex digits that follow it)."""
    if text is None:
        return "NULL"
    out = []
    for byte in text.encode("utf-8"):
        char = chr(byte)
        out.append(char if 32 <= byte < 127 and char not in '"\\?' else f"\\{byte:03o}")
    return '"' + "".join(out) + '"'


def _c_double(x) -> str:
    if x is None:
        return "0.0"
    x = float(x)
    if math.isinf(x):
        return "INFINITY" if x > 0 else "-INFINITY"
    return repr(x)


def c_header(model: str, rows: list[Variable] | None = None) -> str:
    """A C99 header with ``model``'s variable table (one row per variable, indexed by value reference):
    ``RST_<MODEL>_VARIABLES`` and ``RST_MODEL_VARIABLES`` (the same table under a generic name, for the
    front's glue). ``rows`` defaults to :func:`variables` (the slave's VARIABLES)."""
    rows = variables(model) if rows is None else rows
    if [v.vr for v in rows] != list(range(len(rows))):
        raise RuntimeError(f"{model}: value references are not 0..n-1")
    upper = model.upper()
    lines = [
        f"/* {model}: the FMU interface, generated by restitution.fmu.interface from the slave's",
        " * VARIABLES table at build time. Do not edit: rebuild. */",
        f"#ifndef RST_{upper}_INTERFACE_H",
        f"#define RST_{upper}_INTERFACE_H",
        "#include <math.h>",
        "#include <stddef.h>",
        '#include "rst_variable.h"',
        f"#if RST_VARIABLE_LAYOUT != {TABLE_VERSION}",
        '#error "this table was generated for another rst_variable layout: rebuild"',
        "#endif",
        "",
        f"#define RST_{upper}_N_VARIABLES {len(rows)}",
        f"static const rst_variable RST_{upper}_VARIABLES[RST_{upper}_N_VARIABLES] = {{",
    ]
    for v in rows:
        low, high, low_open, high_open = v.interval if v.interval else (0.0, 0.0, 0, 0)
        lines.append(
            f"    {{{v.vr}, {_c_string(v.name)}, RST_{v.type.upper()}, RST_{v.causality.upper()}, "
            f"RST_{v.variability.upper()}, {int(v.state)}, {_c_double(v.start)}, {_c_double(low)}, "
            f"{_c_double(high)}, {int(bool(low_open))}, {int(bool(high_open))}, {_c_string(v.range_text)}, "
            f"{_c_string(v.unit)}, {_c_string(v.description)}}},")
    lines += ["};", f"#define RST_MODEL_N_VARIABLES RST_{upper}_N_VARIABLES",
              f"#define RST_MODEL_VARIABLES RST_{upper}_VARIABLES", "#endif", ""]
    return "\n".join(lines)


if __name__ == "__main__":
    sys.stdout.write(c_header(sys.argv[1] if len(sys.argv) > 1 else "SpherePlateImpact"))
