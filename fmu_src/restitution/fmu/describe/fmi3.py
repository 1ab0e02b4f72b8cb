"""The FMI 3.0 description files of the native co-simulation FMUs, written from the interface table alone.

:func:`model_description` writes ``modelDescription.xml`` and :func:`build_description` writes
``sources/buildDescription.xml``. Nothing comes from pythonfmu (it writes FMI 2.0 only): names,
value references, types, causalities, variabilities, units, starts, limits, enumeration items and the
ModelStructure are all read from ``models/<model>/variables.py`` (:class:`restitution.fmu.table.Table`),
so the FMI 2.0 and FMI 3.0 files of one model cannot drift apart. Value references are the FMI 2.0
ones (the row's position), so a host or a C table indexed by them serves both versions.

What FMI 3.0 changes, and how the table's rows map onto it:

* Real -> ``<Float64>`` (with its ``unit``), Integer -> ``<Int32>``, Boolean -> ``<Boolean>``; an Integer
  with ``choices`` -> ``<Enumeration>`` of a type declared in ``<TypeDefinitions>`` (FMI 3.0 requires a
  ``declaredType`` on every Enumeration). A host gets and sets an Enumeration with fmi3Get/SetInt64,
  not Int32.
* Every FMI 3.0 FMU has exactly one variable of causality ``independent`` (the standard, "causality",
  and fmpy's validation); here it is ``time`` [s], value reference ``len(table)``, after every row.
* ModelStructure lists ``<Output>`` and ``<InitialUnknown>`` elements named by value reference (FMI
  2.0: ``<Unknown index>`` inside ``<Outputs>`` and ``<InitialUnknowns>``, by 1-based position).

Pure data in, text out: no compiler, no fmpy (tests validate the result against fmpy's FMI 3.0 schemas).
"""
from __future__ import annotations

import re
from xml.etree import ElementTree as ET

from ...about import VERSION
from ..models import table as _table
from ..table import Table, Variable
from .common import (GENERATION_TOOL, PARAMETER_CAUSALITIES, limit_text, log_categories, model_attributes,
                     start_text, unit_definitions, xml_text)

__all__ = ["model_description", "build_description", "co_simulation", "enumeration_type", "TIME_NAME", "ELEMENTS"]

#: The independent variable every FMI 3.0 FMU must have (its value reference: ``len(table)``).
TIME_NAME = "time"
TIME_UNIT = "s"
#: The co-simulation capabilities of the native front. Each flag is spelled out, false ones too, so a
#: reader sees what the FMU does not offer without knowing the schema's defaults: no event mode, no
#: early return (fmi3DoStep always completes the step or fails), no intermediate update (and so no
#: early return after one).
CO_SIMULATION = {
    "canHandleVariableCommunicationStepSize": "true",
    "canGetAndSetFMUState": "true",
    "canSerializeFMUState": "true",
    "needsExecutionTool": "false",
    "canBeInstantiatedOnlyOncePerProcess": "false",
    "hasEventMode": "false",
    "mightReturnEarlyFromDoStep": "false",
    "providesIntermediateUpdate": "false",
    "canReturnEarlyAfterIntermediateUpdate": "false",
}
#: The models whose native glue offers co-simulation events (rst_model.do_step_to_event): event mode
#: (eventModeUsed) and early return at each event (earlyReturnAllowed), each contact of BouncingBall
#: located in closed form. Still no intermediate update, hence no canReturnEarlyAfterIntermediateUpdate.
EVENT_MODELS = frozenset({"BouncingBall"})


def co_simulation(model: str) -> dict[str, str]:
    """The ``<CoSimulation>`` capability flags of ``model``'s native FMI 3.0 FMU."""
    if model in EVENT_MODELS:
        return {**CO_SIMULATION, "hasEventMode": "true", "mightReturnEarlyFromDoStep": "true"}
    return dict(CO_SIMULATION)
#: What the native front offers for model exchange (the same binary as co-simulation): no completed
#: integrator step needed (no step events), no discrete-state evaluation without an update.
MODEL_EXCHANGE = {
    "needsExecutionTool": "false",
    "canBeInstantiatedOnlyOncePerProcess": "false",
    "canGetAndSetFMUState": "true",
    "canSerializeFMUState": "true",
    "needsCompletedIntegratorStep": "false",
    "providesEvaluateDiscreteStates": "false",
}
#: Table type -> FMI 3.0 element (an Integer with choices becomes an Enumeration instead).
ELEMENTS = {"Real": "Float64", "Integer": "Int32", "Boolean": "Boolean"}


def enumeration_type(row: Variable) -> str:
    """The name of the ``<EnumerationType>`` an Integer-coded choice is declared with: the row's
    ``enumeration`` where the table gives one (shared by several rows: "Material"), else its FMU name in
    CamelCase ("zener_method" -> "ZenerMethod", "flight.mode" -> "FlightMode")."""
    if row.enumeration is not None:
        return row.enumeration
    return "".join(part[:1].upper() + part[1:] for part in re.split(r"[._]", row.name) if part)


def _enumeration_types(table: Table) -> dict[str, Variable]:
    """Type name -> the first row declared with it, in value-reference order. Two rows may share a
    type only with the same items (a host shows one list of words for both)."""
    types: dict[str, Variable] = {}
    for row in table:
        if not row.is_enumeration:
            continue
        name = enumeration_type(row)
        first = types.setdefault(name, row)
        if (first.codes, first.item_descriptions) != (row.codes, row.item_descriptions):
            raise ValueError(f"{table.model}: {first.name} and {row.name} share the enumeration type {name} "
                             "but not its items")
    return types


def _variable(parent: ET.Element, row: Variable, table: Table) -> None:
    element = "Enumeration" if row.is_enumeration else ELEMENTS[row.type]
    attrs = {"name": row.name, "valueReference": str(row.vr), "description": row.description,
             "causality": row.causality, "variability": row.variability}
    if row.initial is not None:  # the default for these, written out as the FMI 2.0 files do
        attrs["initial"] = row.initial
    if element == "Enumeration":
        attrs["declaredType"] = enumeration_type(row)
    if element == "Float64" and row.unit is not None:
        attrs["unit"] = row.unit
    if row.derivative is not None:
        attrs["derivative"] = str(table[row.derivative].vr)
    if row.causality in PARAMETER_CAUSALITIES:
        low, high = limit_text(row, native=True)  # every FMI 3.0 FMU is native
        if low is not None:
            attrs["min"] = low
        if high is not None:
            attrs["max"] = high
        attrs["start"] = start_text(row)
    ET.SubElement(parent, element, attrs)


def _type_definitions(table: Table) -> ET.Element | None:
    types = _enumeration_types(table)
    if not types:
        return None  # an empty <TypeDefinitions> is not allowed
    node = ET.Element("TypeDefinitions")
    for name, row in types.items():
        enum = ET.SubElement(node, "EnumerationType", name=name)
        descriptions = row.item_descriptions or (None,) * len(row.choices)
        for (word, code), text in zip(row.codes.items(), descriptions):
            item = {"name": word, "value": str(code)}
            if text:
                item["description"] = text
            ET.SubElement(enum, "Item", item)
    return node


def _model_structure(table: Table) -> ET.Element:
    """Outputs with their direct dependence on the inputs (``feedthrough``: every input, else none);
    the state derivatives and event indicators (model exchange); InitialUnknowns as in the FMI 2.0
    files: the outputs, the state derivatives and the calculated parameters, with the dependencies the
    table declares (``initial_dependencies``; none declared: no attribute, may depend on every known)."""
    node = ET.Element("ModelStructure")
    inputs = [str(row.vr) for row in table.inputs]
    for row in table.outputs:
        attrs = {"valueReference": str(row.vr), "dependencies": " ".join(inputs) if row.feedthrough else ""}
        if row.feedthrough and inputs:
            attrs["dependenciesKind"] = " ".join("dependent" for _ in inputs)
        ET.SubElement(node, "Output", attrs)
    for row in table.derivatives:  # may depend on every state, parameter and input (no dependencies given)
        ET.SubElement(node, "ContinuousStateDerivative", valueReference=str(row.vr))
    for row in table.initial_unknowns:
        attrs = {"valueReference": str(row.vr)}
        if row.initial_dependencies is not None:
            attrs["dependencies"] = " ".join(str(vr) for vr in sorted(table[name].vr for name in row.initial_dependencies))
        ET.SubElement(node, "InitialUnknown", attrs)
    for row in table.event_indicators:
        ET.SubElement(node, "EventIndicator", valueReference=str(row.vr))
    return node


def model_description(model: str, instantiation_token: str | None = None) -> str:
    """The FMI 3.0 ``modelDescription.xml`` of ``model``'s native co-simulation FMU, from its interface
    table (:func:`restitution.fmu.models.table`).

    ``instantiation_token`` is the string a host passes to fmi3InstantiateCoSimulation and the binary
    compares with its own (the FMI 2.0 guid's role); by default the table's
    (:meth:`restitution.fmu.table.Table.instantiation_token` of this version), the GUID of the model's
    FMI 2.0 FMUs. ``generationDateAndTime`` is :func:`~restitution.fmu.describe.common.generation_date_and_time` (absent without
    SOURCE_DATE_EPOCH). Element order is the schema's:
    CoSimulation, UnitDefinitions, TypeDefinitions, LogCategories, ModelVariables, ModelStructure (no
    DefaultExperiment: the FMI 2.0 files have none; the host chooses start, stop and step).
    """
    table = _table(model)
    token = instantiation_token or table.instantiation_token(VERSION)
    root = ET.Element("fmiModelDescription", {
        "fmiVersion": "3.0", **model_attributes(table, "instantiationToken", token, GENERATION_TOOL)})
    ET.SubElement(root, "ModelExchange", {"modelIdentifier": model, **MODEL_EXCHANGE})
    ET.SubElement(root, "CoSimulation", {"modelIdentifier": model, **co_simulation(model)})
    root.append(unit_definitions(table, extra=(TIME_UNIT,)))
    types = _type_definitions(table)
    if types is not None:
        root.append(types)
    root.append(log_categories("fmi3"))
    variables = ET.SubElement(root, "ModelVariables")
    for row in table:
        _variable(variables, row, table)
    # after every row, so that each row keeps its FMI 2.0 value reference; no start and no initial:
    # its value at the start is fmi3EnterInitializationMode's startTime
    ET.SubElement(variables, "Float64", {
        "name": TIME_NAME, "valueReference": str(len(table)), "description": "Simulation time",
        "causality": "independent", "variability": "continuous", "unit": TIME_UNIT})
    root.append(_model_structure(table))
    return xml_text(root)


def build_description(model: str, c_files: list[str], defines: dict | None = None) -> str:
    """The FMI 3.0 ``sources/buildDescription.xml`` of ``model``'s native FMU: one build configuration
    (every platform) compiling ``c_files`` (paths relative to ``sources/``) as C99.

    ``defines``: name -> value of the preprocessor definitions the sources need (value None: defined
    without a value). The headers sit beside the sources (include directory ``.``, that is ``sources/``
    itself); the C math library (libm) is declared external: the importer's toolchain provides it,
    the FMU does not carry it.
    """
    if not c_files:
        raise ValueError(f"{model}: a build configuration needs at least one source file")
    root = ET.Element("fmiBuildDescription", fmiVersion="3.0")
    config = ET.SubElement(root, "BuildConfiguration", modelIdentifier=model)
    files = ET.SubElement(config, "SourceFileSet", language="C99")
    # schema order inside a SourceFileSet: SourceFile+, PreprocessorDefinition*, IncludeDirectory*
    for name in c_files:
        ET.SubElement(files, "SourceFile", name=name)
    for name, value in (defines or {}).items():
        attrs = {"name": name}
        if value is not None:
            attrs["value"] = str(value)
        ET.SubElement(files, "PreprocessorDefinition", attrs)
    ET.SubElement(files, "IncludeDirectory", name=".")
    ET.SubElement(config, "Library", name="m", external="true", description="the C math library (libm)")
    return xml_text(root)
