"""The FMI 3.0 description files of the native FMUs (restitution.fmu.describe.fmi3), written from the
interface table alone: they validate against the FMI 3.0 schemas fmpy ships (and fmpy's own checks:
exactly one independent variable, structured names, a complete ModelStructure), reading them back with
fmpy gives the table back, and every unit's <BaseUnit> is its SI dimension as pint computes it from the
unit string (which checks the UNITS table from outside). No FMU is built: the files are written into a
temporary directory laid out as an unzipped FMU."""
import math
import re
from pathlib import Path

import pint
import pytest
from fmpy.model_description import ValidationError, read_build_description, read_model_description
from fmpy.validation import validate_fmu

from restitution.fmu.describe.fmi3 import (TIME_NAME, build_description, enumeration_type,
                                                model_description)
from restitution.fmu.models import FOLDERS, native_sources, table

TOKEN = "{8c4e810f-3df3-4a00-8276-176fa3c9ced8}"
#: fmpy's element for each table type (an Integer with choices is an Enumeration instead).
FMI3_TYPES = {"Real": "Float64", "Integer": "Int32", "Boolean": "Boolean"}
#: pint's dimensions -> the attributes of an FMI <BaseUnit>.
PINT_TO_FMI = {"[mass]": "kg", "[length]": "m", "[time]": "s", "[current]": "A", "[temperature]": "K",
               "[substance]": "mol", "[luminosity]": "cd"}
DEFINES = {"FMI3_FUNCTION_PREFIX": None, "RST_EXAMPLE": 1}


def _c_files(model):
    return [p.name for p in native_sources(model) if p.suffix == ".c"]


def _write_fmu_dir(directory: Path, model: str) -> Path:
    (directory / "sources").mkdir(parents=True)
    (directory / "modelDescription.xml").write_text(model_description(model, TOKEN), encoding="utf-8")
    (directory / "sources" / "buildDescription.xml").write_text(
        build_description(model, _c_files(model), DEFINES), encoding="utf-8")
    return directory


@pytest.fixture(params=list(FOLDERS))
def fmu_dir(request, tmp_path):
    """(model, a directory holding its FMI 3.0 modelDescription.xml and sources/buildDescription.xml)."""
    return request.param, _write_fmu_dir(tmp_path / request.param, request.param)


def test_validates_against_the_fmi3_schemas_and_fmpys_checks(fmu_dir):
    _model, directory = fmu_dir
    # the schema, unique names and value references, one independent variable, structured names,
    # start values, causality/variability/initial, units, the ModelStructure; and buildDescription.xml
    # against fmi3BuildDescription.xsd (fmpy reads it from sources/ of a directory)
    assert validate_fmu(str(directory)) == []


def test_the_schema_check_is_not_vacuous(tmp_path):
    """A broken file is refused: the validation above does run the FMI 3.0 schema."""
    directory = _write_fmu_dir(tmp_path / "broken", "BouncingBall")
    path = directory / "modelDescription.xml"
    path.write_text(path.read_text(encoding="utf-8").replace(f' instantiationToken="{TOKEN}"', ""), encoding="utf-8")
    with pytest.raises(ValidationError):
        read_model_description(str(directory), validate=True)
    build = directory / "sources" / "buildDescription.xml"
    text = build.read_text(encoding="utf-8")  # a SourceFile after the IncludeDirectory: out of schema order
    misplaced = '<IncludeDirectory name="." /><SourceFile name="x.c" />'
    build.write_text(text.replace('<IncludeDirectory name="." />', misplaced), encoding="utf-8")
    with pytest.raises(Exception, match="buildDescription"):
        read_build_description(str(directory), validate=True)


def test_build_description_round_trips(fmu_dir):
    model, directory = fmu_dir
    configurations = read_build_description(str(directory), validate=True)
    assert [c.modelIdentifier for c in configurations] == [model]
    (files,) = configurations[0].sourceFileSets
    assert files.language == "C99"
    assert files.sourceFiles == _c_files(model)
    assert files.includeDirectories == ["."]
    assert {(d.name, d.value) for d in files.preprocessorDefinitions} == {("FMI3_FUNCTION_PREFIX", None),
                                                                          ("RST_EXAMPLE", "1")}
    with pytest.raises(ValueError):
        build_description(model, [])


def _number(text):
    return None if text is None else float(text)


def test_table_round_trips_through_the_fmi3_model_description(fmu_dir):
    model, directory = fmu_dir
    rows = table(model).rows
    md = read_model_description(str(directory), validate=True)
    assert (md.fmiVersion, md.modelName, md.guid, md.description) == ("3.0", model, TOKEN, table(model).description)
    assert md.variableNamingConvention == "structured"
    cs = md.coSimulation
    assert cs.modelIdentifier == model and md.modelExchange.modelIdentifier == model and md.scheduledExecution is None
    assert cs.canHandleVariableCommunicationStepSize and cs.canGetAndSetFMUstate and cs.canSerializeFMUstate
    assert not (cs.needsExecutionTool or cs.canBeInstantiatedOnlyOncePerProcess
                or cs.providesIntermediateUpdate or cs.canReturnEarlyAfterIntermediateUpdate)
    # event mode and early return where the glue offers them (BouncingBall: each contact located in
    # closed form; tests/hosts/test_event_mode.py), neither for SpherePlateImpact (no events)
    events = model == "BouncingBall"
    assert (cs.hasEventMode, cs.mightReturnEarlyFromDoStep) == (events, events)
    # the categories the C front answers to (rst_log.c), described with FMI 3.0's status names
    assert [(c.name, c.description) for c in md.logCategories] == [
        (f"logStatus{status}", f"Log messages with fmi3{status} status.") for status in ("Warning", "Discard", "Error", "Fatal")
    ] + [("logAll", "Log all messages.")]

    variables = md.modelVariables
    assert [v.name for v in variables] == [row.name for row in rows] + [TIME_NAME]
    for row, got in zip(rows, variables):
        assert (got.valueReference, got.description, got.causality, got.variability) == (
            row.vr, row.description, row.causality, row.variability), row.name
        assert got.initial == (row.initial or "exact"), row.name  # fmpy fills in the standard's default
        assert got.unit == (row.unit if row.type == "Real" else None), row.name
        if row.choices is not None:
            assert got.type == "Enumeration", row.name
            if row.enumeration is not None:
                assert got.declaredType.name == row.enumeration, row.name
            words = row.item_descriptions or (None,) * len(row.choices)
            assert [(i.name, int(i.value), i.description) for i in got.declaredType.items] == [
                (word, code, text) for (word, code), text in zip(row.codes.items(), words)], row.name
        else:
            assert got.type == FMI3_TYPES[row.type] and got.declaredType is None, row.name
        if row.causality in ("parameter", "input"):
            start = {"Real": float, "Integer": int, "Boolean": lambda s: s in ("true", "1")}[row.type](got.start)
            assert start == row.start and type(start) is type(row.start), row.name  # exact: shortest repr
            # the declared bounds (every FMI 3.0 FMU is native: its narrower range where it has one)
            low, high = (row.native_interval or row.interval)[:2]
            assert _number(got.min) == (None if low == -math.inf else pytest.approx(low, rel=1e-15)), row.name
            assert _number(got.max) == (None if high == math.inf else pytest.approx(high, rel=1e-15)), row.name
        else:
            assert (got.start, got.min, got.max) == (None, None, None), row.name

    time = variables[-1]
    assert (time.valueReference, time.type, time.causality, time.variability, time.start, time.unit, time.initial) == (
        len(rows), "Float64", "independent", "continuous", None, "s", None)
    assert len({v.valueReference for v in variables}) == len(variables)

    inputs = [row.name for row in rows if row.causality == "input"]
    outputs = {u.variable.name: u for u in md.outputs}
    assert list(outputs) == [row.name for row in table(model).outputs]
    for row in table(model).outputs:
        unknown = outputs[row.name]
        expected = inputs if row.feedthrough else []
        assert [v.name for v in unknown.dependencies] == expected, row.name
        assert (unknown.dependenciesKind or []) == ["dependent"] * len(expected), row.name
    assert [u.variable.name for u in md.initialUnknowns] == [
        row.name for row in rows if row.causality in ("output", "calculatedParameter") or row.derivative is not None]
    for unknown in md.initialUnknowns:  # no declared dependencies: may depend on every known
        row = table(model)[unknown.variable.name]
        expected = None if row.initial_dependencies is None else sorted(row.initial_dependencies,
                                                                        key=lambda n: table(model)[n].vr)
        assert (None if unknown.dependencies is None else [v.name for v in unknown.dependencies]) == expected
    # model exchange: each derivative names its state; the event indicators
    by_name = {v.name: v for v in variables}
    assert [u.variable.name for u in md.derivatives] == [row.name for row in rows if row.derivative is not None]
    for row in rows:
        derivative_of = by_name[row.name].derivative
        assert (derivative_of.name if derivative_of is not None else None) == row.derivative, row.name
    assert [u.variable.name for u in md.eventIndicators] == [row.name for row in rows if row.event_indicator]


def _pint_base_unit(ureg, unit: str) -> tuple[dict, float]:
    """The SI base-unit exponents of ``unit`` as pint computes them, and the factor to SI."""
    quantity = ureg.Quantity(1.0, re.sub(r"([A-Za-z])(\d)", r"\1**\2", unit))  # "kg/m3" -> "kg/m**3"
    exponents = {PINT_TO_FMI[dim]: exp for dim, exp in quantity.dimensionality.items() if exp}
    assert all(float(e).is_integer() for e in exponents.values()), unit
    return {k: int(e) for k, e in exponents.items()}, quantity.to_base_units().magnitude


def test_base_units_are_the_si_dimensions_pint_computes(fmu_dir):
    model, directory = fmu_dir
    ureg = pint.UnitRegistry()
    md = read_model_description(str(directory), validate=True)
    declared = {u.name: u for u in md.unitDefinitions}
    used = {row.unit for row in table(model) if row.type == "Real" and row.unit is not None} | {"s"}
    assert set(declared) == used
    for name, unit in declared.items():
        exponents, factor = _pint_base_unit(ureg, name)
        base = unit.baseUnit
        got = {} if base is None else {k: getattr(base, k) for k in PINT_TO_FMI.values() if getattr(base, k)}
        if base is not None:
            assert (base.rad, base.factor, base.offset) == (0, 1.0, 0.0), name
        assert got == exponents, name
        assert factor == pytest.approx(1.0, rel=1e-15), name  # every unit used is coherent SI: no factor


def test_enumeration_type_names():
    impact, ball = table("SpherePlateImpact"), table("BouncingBall")
    assert enumeration_type(impact["zener_method"]) == "ZenerMethod"
    assert enumeration_type(impact["plate_waves"]) == "PlateWaves"
    assert enumeration_type(impact["sphere.material"]) == enumeration_type(impact["plate.material"]) == "Material"
    assert enumeration_type(ball["contact_mode"]) == "ContactMode"
