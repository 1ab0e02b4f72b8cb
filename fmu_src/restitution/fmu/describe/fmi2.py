"""The FMI 2.0 ``modelDescription.xml`` of every FMU, written from the interface table alone.

Two implementations share one interface, and so one description but for what they offer:

* the pythonfmu FMU (``native=False``): co-simulation only, needs its Python runtime
  (``needsExecutionTool``), and leaves memory to pythonfmu's binary (``canNotUseMemoryManagementFunctions``);
* the native FMU (``native=True``): model exchange and co-simulation from one C binary, which allocates
  through the host's callbacks, with its C sources declared (``<SourceFiles>``) for a host that compiles
  ``sources/``, the number of event indicators, and the native ranges where the table gives them
  (``native_interval``).

Nothing comes from pythonfmu: the build replaces the file pythonfmu writes with this one. Names, value
references (the row's position, the order in which the slave registers its variables), types,
causalities, variabilities, units, starts, limits, enumeration items and the ModelStructure are the
table's, so the FMI 2.0 and FMI 3.0 files of one model cannot drift apart (:mod:`.fmi3`). The GUID is
the table's instantiation token, the same in every build and every implementation.

What FMI 2.0 asks that FMI 3.0 does not: a ``<ScalarVariable>`` wrapping a type element; Integer choices
stay Integers (their codes listed in the description) unless the row names an ``enumeration``, declared as
a ``<SimpleType>``; ModelStructure refers to variables by 1-based position (``index``) in
``<Outputs>``, ``<Derivatives>`` and ``<InitialUnknowns>``; no independent variable.

Pure data in, text out: no compiler, no pythonfmu, no fmpy (tests validate the result with fmpy).
"""
from __future__ import annotations

from xml.etree import ElementTree as ET

from ...about import VERSION
from ..models import table as _table
from ..table import Table, Variable
from .common import (GENERATION_TOOL, PARAMETER_CAUSALITIES, PYTHON_GENERATION_TOOL, limit_text, log_categories,
                     model_attributes, start_text, unit_definitions, xml_text)

__all__ = ["model_description", "CO_SIMULATION", "PYTHON_CO_SIMULATION", "MODEL_EXCHANGE"]

#: Co-simulation as the native C FMU offers it: no Python needed, several instances per process, memory
#: through the host's callbacks, FMU states, variable communication steps; inputs held constant over a
#: step (no input derivatives, no interpolation).
CO_SIMULATION = {"needsExecutionTool": "false", "canHandleVariableCommunicationStepSize": "true",
                 "canInterpolateInputs": "false", "canBeInstantiatedOnlyOncePerProcess": "false",
                 "canNotUseMemoryManagementFunctions": "false", "canGetAndSetFMUstate": "true",
                 "canSerializeFMUstate": "true"}
#: Co-simulation as the pythonfmu FMU offers it (what pythonfmu's binary supports): the Python runtime is
#: its execution tool, and pythonfmu allocates with its own allocator.
PYTHON_CO_SIMULATION = {**CO_SIMULATION, "needsExecutionTool": "true", "canNotUseMemoryManagementFunctions": "true"}
#: Model exchange as the native FMU offers it (the same binary and front as co-simulation).
MODEL_EXCHANGE = {"needsExecutionTool": "false", "completedIntegratorStepNotNeeded": "true",
                  "canBeInstantiatedOnlyOncePerProcess": "false", "canNotUseMemoryManagementFunctions": "false",
                  "canGetAndSetFMUstate": "true", "canSerializeFMUstate": "true"}


def _interface(tag: str, model: str, capabilities: dict, c_files) -> ET.Element:
    node = ET.Element(tag, {"modelIdentifier": model, **capabilities})
    if c_files:
        files = ET.SubElement(node, "SourceFiles")
        for name in c_files:
            ET.SubElement(files, "File", name=name)
    return node


def _type_definitions(table: Table) -> ET.Element | None:
    """``<TypeDefinitions>`` with an Enumeration ``<SimpleType>`` for each ``enumeration`` the table
    names: its items are the variable's choices, valued by their codes; None when it names none."""
    if not table.enumerations:
        return None
    node = ET.Element("TypeDefinitions")
    for name, row in table.enumerations.items():
        items = ET.SubElement(ET.SubElement(node, "SimpleType", name=name), "Enumeration")
        for (word, code), text in zip(row.codes.items(), row.item_descriptions or [""] * len(row.codes)):
            ET.SubElement(items, "Item", {"name": word, "value": str(code), "description": text})
    return node


def _scalar_variable(parent: ET.Element, row: Variable, index: dict[str, int], native: bool) -> None:
    attrs = {"name": row.name, "valueReference": str(row.vr), "description": row.description,
             "causality": row.causality, "variability": row.variability}
    if row.initial is not None:
        attrs["initial"] = row.initial
    sv = ET.SubElement(parent, "ScalarVariable", attrs)
    element = "Enumeration" if row.enumeration is not None else row.type
    typed = {}
    if row.causality in PARAMETER_CAUSALITIES:
        typed["start"] = start_text(row)
    if row.enumeration is not None:
        typed["declaredType"] = row.enumeration
    if row.type == "Real" and row.unit is not None:
        typed["unit"] = row.unit
    if row.derivative is not None:
        typed["derivative"] = str(index[row.derivative])
    if row.causality in PARAMETER_CAUSALITIES:
        low, high = limit_text(row, native)
        typed.update({key: text for key, text in (("min", low), ("max", high)) if text is not None})
    ET.SubElement(sv, element, typed)


def _model_structure(table: Table, index: dict[str, int]) -> ET.Element:
    """Outputs with their direct dependence on the inputs (``feedthrough``: every input, else none), the
    state derivatives (may depend on every state, parameter and input: no dependencies given), and the
    InitialUnknowns with the dependencies the table declares (``initial_dependencies``; none declared:
    no attribute, may depend on every known)."""
    node = ET.Element("ModelStructure")
    inputs = [str(index[row.name]) for row in table.inputs]
    outputs = ET.SubElement(node, "Outputs")
    for row in table.outputs:
        attrs = {"index": str(index[row.name]), "dependencies": " ".join(inputs) if row.feedthrough else ""}
        if row.feedthrough and inputs:
            attrs["dependenciesKind"] = " ".join("dependent" for _ in inputs)
        ET.SubElement(outputs, "Unknown", attrs)
    if table.derivatives:
        derivatives = ET.SubElement(node, "Derivatives")
        for row in table.derivatives:
            ET.SubElement(derivatives, "Unknown", {"index": str(index[row.name])})
    initial = ET.SubElement(node, "InitialUnknowns")
    for row in table.initial_unknowns:
        attrs = {"index": str(index[row.name])}
        if row.initial_dependencies is not None:
            attrs["dependencies"] = " ".join(str(i) for i in sorted(index[name] for name in row.initial_dependencies))
        ET.SubElement(initial, "Unknown", attrs)
    return node


def model_description(model: str, native: bool, c_files: tuple[str, ...] | list[str] = ()) -> str:
    """The FMI 2.0 ``modelDescription.xml`` of ``model``'s pythonfmu FMU (``native`` False: co-simulation)
    or native FMU (``native`` True: model exchange and co-simulation, declaring the C ``c_files`` of
    ``sources/``), from its interface table (:func:`restitution.fmu.models.table`).

    The GUID is :meth:`restitution.fmu.table.Table.instantiation_token` of this version;
    ``generationDateAndTime`` is :func:`~restitution.fmu.describe.common.generation_date_and_time` (absent
    without SOURCE_DATE_EPOCH). Element order is the schema's: ModelExchange, CoSimulation,
    UnitDefinitions, TypeDefinitions, LogCategories, ModelVariables, ModelStructure (no
    DefaultExperiment: the host chooses start, stop and step).
    """
    table = _table(model)
    token = table.instantiation_token(VERSION)
    tool = GENERATION_TOOL if native else PYTHON_GENERATION_TOOL
    root = ET.Element("fmiModelDescription", {"fmiVersion": "2.0", **model_attributes(table, "guid", token, tool)})
    if native:
        root.set("numberOfEventIndicators", str(len(table.event_indicators)))
        root.append(_interface("ModelExchange", model, MODEL_EXCHANGE, c_files))
    root.append(_interface("CoSimulation", model, CO_SIMULATION if native else PYTHON_CO_SIMULATION,
                           c_files if native else ()))
    root.append(unit_definitions(table))
    types = _type_definitions(table)
    if types is not None:
        root.append(types)
    root.append(log_categories("fmi2"))
    index = {row.name: position for position, row in enumerate(table, start=1)}
    variables = ET.SubElement(root, "ModelVariables")
    for row in table:
        _scalar_variable(variables, row, index, native)
    root.append(_model_structure(table, index))
    return xml_text(root)
