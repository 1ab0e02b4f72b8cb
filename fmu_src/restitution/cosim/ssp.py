"""Run an SSP (System Structure and Parameterization) archive with fmpy: a master that reads the
system structure, applies its parameter bindings and steps the components through
:class:`~restitution.cosim.fixed_step.FixedStepMaster`.

fmpy's own ``fmpy.ssp.simulate_ssp`` handles FMI 2.0 only and sets an Enumeration parameter from a
number; SSV files give an enumeration's item *name* (``<ssv:Enumeration value="al_6061"/>``), which
:class:`~restitution.cosim.fmu.FmuInstance` sets by name, and SSP 2.0 types (Float64, Int32, ...) for
FMI 3.0 FMUs. So an SSP 1.0 archive is validated by fmpy's ``read_ssd`` (the SSP 1.0 schema) and the
structure and parameter values are read here.

Parameter bindings are applied in the SSD's order, later values replacing earlier ones; ``bindings``
replaces a component's bound SSV files (``{"impact": "resources/custom.ssv"}``) to choose another set
shipped in the archive. The step and stop time default to the SSD's DefaultExperiment (stop) and its
OSP FixedStepAlgorithm annotation (step).
"""
from __future__ import annotations

import shutil
import tempfile
import zipfile
from pathlib import Path
from xml.etree import ElementTree as ET

from .fixed_step import BALL_RECORD, CosimResult, FixedStepMaster

__all__ = ["ssp_parameters", "default_experiment", "run_ssp"]

_SSD = "http://ssp-standard.org/SSP1/SystemStructureDescription"
_SSV = "http://ssp-standard.org/SSP1/SystemStructureParameterValues"
_OSP = "http://opensimulationplatform.com/SSP/OSPAnnotations"
_FLOATS = {"Real", "Float64", "Float32"}
_INTEGERS = {"Integer", "Int8", "UInt8", "Int16", "UInt16", "Int32", "UInt32", "Int64", "UInt64"}


def _parameter_values(parameter_set) -> dict:
    """{name: value} of an ``<ssv:ParameterSet>`` element: floats, ints, bools, enumeration item names."""
    values = {}
    for parameter in parameter_set.iter(f"{{{_SSV}}}Parameter"):
        typed = next(child for child in parameter if child.tag.startswith(f"{{{_SSV}}}"))
        kind, raw = typed.tag.split("}")[1], typed.get("value")
        if kind in _FLOATS:
            values[parameter.get("name")] = float(raw)
        elif kind in _INTEGERS:
            values[parameter.get("name")] = int(raw)
        elif kind == "Boolean":
            values[parameter.get("name")] = raw in ("true", "1")
        elif kind in ("Enumeration", "String"):
            values[parameter.get("name")] = raw
        else:
            raise ValueError(f"parameter {parameter.get('name')}: {kind} values are not applied here")
    return values


def ssp_parameters(ssp, bindings: dict | None = None) -> dict:
    """{component: {variable: value}} from the parameter bindings of ``ssp``'s SystemStructure.ssd
    (``bindings``: replacement SSV entries per component, module doc)."""
    bindings = bindings or {}
    out = {}
    with zipfile.ZipFile(ssp) as archive:
        root = ET.fromstring(archive.read("SystemStructure.ssd"))
        for component in root.iter(f"{{{_SSD}}}Component"):
            name, values = component.get("name"), {}
            if name in bindings:
                sources = [bindings[name]] if isinstance(bindings[name], str) else list(bindings[name])
                sets = [ET.fromstring(archive.read(s)) for s in sources]
            else:
                sets = []
                for binding in component.iter(f"{{{_SSD}}}ParameterBinding"):
                    if binding.get("source"):
                        sets.append(ET.fromstring(archive.read(binding.get("source"))))
                    sets += list(binding.iter(f"{{{_SSV}}}ParameterSet"))
            for parameter_set in sets:
                values.update(_parameter_values(parameter_set))
            out[name] = values
    unknown = set(bindings) - set(out)
    if unknown:
        raise KeyError(f"bindings for {', '.join(sorted(unknown))}: no such component in {ssp}")
    return out


def default_experiment(ssp) -> dict:
    """{"start", "stop", "step"} [s] of ``ssp``'s DefaultExperiment (step: its OSP annotation; None where
    a value is absent)."""
    with zipfile.ZipFile(ssp) as archive:
        root = ET.fromstring(archive.read("SystemStructure.ssd"))
    experiment = root.find(f"{{{_SSD}}}DefaultExperiment")
    out = {"start": 0.0, "stop": None, "step": None}
    if experiment is not None:
        out["start"] = float(experiment.get("startTime", 0.0))
        if experiment.get("stopTime") is not None:
            out["stop"] = float(experiment.get("stopTime"))
        fixed = experiment.find(f".//{{{_OSP}}}FixedStepAlgorithm")
        if fixed is not None:
            out["step"] = float(fixed.get("baseStepSize"))
    return out


def _structure(ssp, version: str):
    """(components {name: source}, connections [("a.x", "b.y")]) of the SSD's top-level system; an SSP 1.0
    SSD (and each SSV it binds) is first read by fmpy's read_ssd, which validates it against the SSP 1.0
    schema (fmpy has no SSP 2.0 schema, and reads no SSP 2.0 types)."""
    if version.startswith("1."):
        from fmpy.ssp.ssd import read_ssd

        read_ssd(str(ssp), validate=True)
    with zipfile.ZipFile(ssp) as archive:
        system = ET.fromstring(archive.read("SystemStructure.ssd")).find(f"{{{_SSD}}}System")
    components = {c.get("name"): c.get("source") for c in system.iterfind(f"{{{_SSD}}}Elements/{{{_SSD}}}Component")}
    connections = [(f"{c.get('startElement')}.{c.get('startConnector')}", f"{c.get('endElement')}.{c.get('endConnector')}")
                   for c in system.iterfind(f"{{{_SSD}}}Connections/{{{_SSD}}}Connection")]
    return components, connections


def run_ssp(ssp, step: float | None = None, stop: float | None = None, bindings: dict | None = None,
            record=BALL_RECORD) -> CosimResult:
    """Co-simulate ``ssp`` from its DefaultExperiment start to ``stop`` [s] with communication step
    ``step`` [s] (defaults: the SSD's, module doc), its parameters applied (``bindings``: other SSV
    entries per component); records ``record`` ("component.variable") at every communication point."""
    from .fmu import FmuInstance

    ssp = Path(ssp)
    with zipfile.ZipFile(ssp) as archive:
        version = ET.fromstring(archive.read("SystemStructure.ssd")).get("version", "")
    components, connections = _structure(ssp, version)
    parameters = ssp_parameters(ssp, bindings)
    experiment = default_experiment(ssp)
    step = step if step is not None else experiment["step"]
    stop = stop if stop is not None else experiment["stop"]
    if step is None or stop is None:
        raise ValueError(f"{ssp}: give step and stop (its DefaultExperiment lacks them)")
    work = Path(tempfile.mkdtemp(prefix="restitution_ssp_"))
    instances = {}
    try:
        with zipfile.ZipFile(ssp) as archive:
            archive.extractall(work)
        for name, source in components.items():
            instances[name] = FmuInstance(work / source, name, start_time=experiment["start"],
                                          parameters=parameters.get(name) or None)
        master = FixedStepMaster(instances, connections)
        result = master.run(step, stop, record=record, start_time=experiment["start"])
        result.master = f"fmpy SSP {version} master ({result.master})"
        return result
    finally:
        for instance in instances.values():
            instance.close()
        shutil.rmtree(work, ignore_errors=True)
