"""What the FMI 2.0 and FMI 3.0 descriptions of every FMU share, written once: the generation date, the
generation tools, the log categories the C front answers to, the text of numbers, limits and starts, the
unit definitions and the XML text itself. Pure data in, text out."""
from __future__ import annotations

import math
from datetime import datetime, timezone
from xml.etree import ElementTree as ET

from ...about import AUTHOR, COPYRIGHT, LICENSE, VERSION
from ...reproducible import source_date_epoch
from ..table import UNITS, Table, Variable

__all__ = ["GENERATION_TOOL", "PYTHON_GENERATION_TOOL", "PARAMETER_CAUSALITIES", "generation_date_and_time",
           "log_categories", "float_text", "start_text", "limit_text", "unit_definitions", "xml_text",
           "model_attributes"]

#: ``generationTool`` of the native FMUs' descriptions (FMI 2.0 and 3.0).
GENERATION_TOOL = "restitution native build (C99 front + native physics)"
#: ``generationTool`` of the pythonfmu FMUs' description (written by this package, not by pythonfmu).
PYTHON_GENERATION_TOOL = "restitution build (Python physics on pythonfmu's runtime, behind the C guard)"
#: The causalities whose variables declare a start and the range they accept.
PARAMETER_CAUSALITIES = ("parameter", "input")
#: The log categories the C front answers to, in their order: (name, the status it logs or None for all).
_CATEGORIES = (("logStatusWarning", "Warning"), ("logStatusDiscard", "Discard"), ("logStatusError", "Error"),
               ("logStatusFatal", "Fatal"), ("logAll", None))


def generation_date_and_time(environ=None) -> str | None:
    """The ``generationDateAndTime`` of every modelDescription the build writes (FMI 2.0 and 3.0): the
    time in ``SOURCE_DATE_EPOCH`` (seconds since 1970-01-01 UTC, https://reproducible-builds.org/specs/source-date-epoch/)
    in the form the standard recommends (UTC, whole seconds, "Z": ``2026-11-25T10:00:00Z``); None where
    it is unset or empty, and the attribute (optional) is then left out, so that two builds of the same
    sources write the same files. ValueError for a value that is not a whole number of seconds."""
    seconds = source_date_epoch(environ)
    if seconds is None:
        return None
    try:
        return datetime.fromtimestamp(seconds, timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")
    except (OverflowError, OSError, ValueError):
        raise ValueError(f"SOURCE_DATE_EPOCH={seconds} is beyond the dates a modelDescription can state") from None


def model_attributes(table: Table, token_attribute: str, token: str, generation_tool: str) -> dict[str, str]:
    """The attributes of ``<fmiModelDescription>`` both versions share, in the order the files show them
    (``token_attribute``: FMI 2.0's ``guid``, FMI 3.0's ``instantiationToken``)."""
    date = generation_date_and_time()
    return {"modelName": table.model, token_attribute: token, "description": table.description,
            "author": AUTHOR, "version": VERSION, "copyright": COPYRIGHT, "license": LICENSE,
            "generationTool": generation_tool,
            **({"generationDateAndTime": date} if date is not None else {}),
            "variableNamingConvention": "structured"}


def log_categories(fmi_prefix: str) -> ET.Element:
    """``<LogCategories>``, each described with the status names of ``fmi_prefix`` ("fmi2", "fmi3")."""
    node = ET.Element("LogCategories")
    for name, status in _CATEGORIES:
        text = f"Log messages with {fmi_prefix}{status} status." if status else "Log all messages."
        ET.SubElement(node, "Category", name=name, description=text)
    return node


def float_text(value) -> str:
    """A Real/Float64 attribute: the shortest text that reads back as the same double (Python's repr,
    the 'minimal printer' the standards recommend), so a start value survives the XML exactly."""
    value = float(value)
    if not math.isfinite(value):
        raise ValueError(f"{value!r} is not a finite start value")
    return repr(value)


def start_text(row: Variable) -> str:
    """The ``start`` attribute of an input or parameter."""
    if row.type == "Boolean":
        return "true" if row.start else "false"
    if row.type == "Integer":
        return str(int(row.start))
    return float_text(row.start)


def limit_text(row: Variable, native: bool) -> tuple[str | None, str | None]:
    """(min, max) attributes of an input or parameter: the range the FMU accepts (``native``: the C FMUs'
    own where narrower); whole numbers for an Integer (%g would write 1e+06, not an integer literal)."""
    low, high = row.xml_limits(native=native)
    if row.type == "Integer":
        low, high = (None if text is None else str(int(float(text))) for text in (low, high))
    return low, high


def unit_definitions(table: Table, extra: tuple[str, ...] = ()) -> ET.Element:
    """``<UnitDefinitions>`` of every unit the table's Reals use (and ``extra``), by name, each with its
    SI base-unit exponents (none for "1": all exponents 0 is the schemas' default)."""
    used = {row.unit for row in table if row.type == "Real" and row.unit is not None} | set(extra)
    node = ET.Element("UnitDefinitions")
    for unit in sorted(used):
        unit_node = ET.SubElement(node, "Unit", name=unit)
        if UNITS[unit]:
            ET.SubElement(unit_node, "BaseUnit", {k: str(v) for k, v in UNITS[unit].items()})
    return node


def xml_text(root: ET.Element) -> str:
    """The file's text: an XML declaration, two-space indentation, a final newline."""
    ET.indent(root, "  ")
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n"
