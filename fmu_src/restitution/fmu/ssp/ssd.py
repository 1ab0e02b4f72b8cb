"""SystemStructure.ssd of the ball-on-plate system: BouncingBall (``ball``) and SpherePlateImpact
(``impact``), the FMUs in ``resources/``, wired ``ball.v_approach -> impact.v_approach`` and
``impact.e -> ball.e``, each component's parameters bound to an SSV file, and a default experiment.

The connectors are typed from each FMU's modelDescription.xml (Real with its unit in SSP 1.0, Float64 in
SSP 2.0), the units declared in ``<ssd:Units>``. The default experiment's communication step travels as
the Open Simulation Platform's annotation (``osp:FixedStepAlgorithm``), which ecos and libcosim read; SSP
itself has no step size.
"""
from __future__ import annotations

from dataclasses import dataclass
from xml.etree import ElementTree as ET

from .xml_common import check_version, tag, to_bytes, unit_of, units_element

__all__ = ["Component", "CONNECTIONS", "DEFAULT_EXPERIMENT", "system_structure"]

#: (start element, start connector, end element, end connector): the loop through the two FMUs.
CONNECTIONS = (("ball", "v_approach", "impact", "v_approach"), ("impact", "e", "ball", "e"))
#: startTime, stopTime and the communication step [s]: a 0.3 m drop shows five bounces within 1 s.
DEFAULT_EXPERIMENT = {"start": 0.0, "stop": 1.0, "step": 1e-3}


@dataclass(frozen=True)
class Component:
    """One FMU of the system: its name in the SSD, its archive entry, its variables (fmpy's, by name)
    and the SSV entries bound to its parameters, applied in order."""

    name: str
    source: str  #: "resources/<Model>.fmu"
    variables: dict
    parameter_sources: tuple[str, ...] = ()
    parameter_sets: tuple = ()  #: inline <ssv:ParameterSet> elements, after the sources

    def connectors(self):
        """(variable, kind) of each of its connected variables, in :data:`CONNECTIONS` order."""
        out = []
        for start, start_c, end, end_c in CONNECTIONS:
            if start == self.name:
                out.append((start_c, "output"))
            if end == self.name:
                out.append((end_c, "input"))
        return out


def _component(elements, component: Component, float_type: str, units: set):
    element = ET.SubElement(elements, tag("ssd", "Component"), name=component.name, source=component.source,
                            type="application/x-fmu-sharedlibrary")
    connectors = ET.SubElement(element, tag("ssd", "Connectors"))
    for variable, kind in component.connectors():
        if variable not in component.variables:
            raise KeyError(f"{component.source} has no variable {variable!r}")
        declared = component.variables[variable]
        if declared.causality != kind:
            raise ValueError(f"{component.source}: {variable} is an {declared.causality}, not an {kind}")
        connector = ET.SubElement(connectors, tag("ssd", "Connector"), name=variable, kind=kind)
        unit = unit_of(declared)
        ET.SubElement(connector, tag("ssc", float_type), {"unit": unit} if unit else {})
        if unit:
            units.add(unit)
    if component.parameter_sources or component.parameter_sets:
        bindings = ET.SubElement(element, tag("ssd", "ParameterBindings"))
        for source in component.parameter_sources:
            ET.SubElement(bindings, tag("ssd", "ParameterBinding"), source=source,
                          type="application/x-ssp-parameter-set")
        for parameter_set in component.parameter_sets:
            binding = ET.SubElement(bindings, tag("ssd", "ParameterBinding"))
            ET.SubElement(binding, tag("ssd", "ParameterValues")).append(parameter_set)


def system_structure(version: str, components, experiment=None, name: str = "BallOnPlate",
                     description: str = "") -> bytes:
    """The SystemStructure.ssd of SSP ``version`` ("1.0": FMI 2.0 FMUs; "2.0": FMI 3.0 FMUs) for
    ``components`` (:class:`Component`, wired as :data:`CONNECTIONS`); ``experiment``: start, stop, step
    [s] (default :data:`DEFAULT_EXPERIMENT`)."""
    _fmi, float_type = check_version(version)
    experiment = {**DEFAULT_EXPERIMENT, **(experiment or {})}
    attrs = {"version": version, "name": name}
    if description:
        attrs["description"] = description
    root = ET.Element(tag("ssd", "SystemStructureDescription"), attrs)
    system = ET.SubElement(root, tag("ssd", "System"), name=name)
    elements = ET.SubElement(system, tag("ssd", "Elements"))
    units: set = set()
    names = {c.name for c in components}
    for component in components:
        _component(elements, component, float_type, units)
    connections = ET.SubElement(system, tag("ssd", "Connections"))
    for start, start_c, end, end_c in CONNECTIONS:
        if start not in names or end not in names:
            raise KeyError(f"connection {start}.{start_c} -> {end}.{end_c}: no such component")
        ET.SubElement(connections, tag("ssd", "Connection"), startElement=start, startConnector=start_c,
                      endElement=end, endConnector=end_c)
    units_element(root, "ssd", units)
    default = ET.SubElement(root, tag("ssd", "DefaultExperiment"), startTime=repr(float(experiment["start"])),
                            stopTime=repr(float(experiment["stop"])))
    annotations = ET.SubElement(default, tag("ssd", "Annotations"))
    annotation = ET.SubElement(annotations, tag("ssc", "Annotation"), type="com.opensimulationplatform")
    algorithm = ET.SubElement(annotation, tag("osp", "Algorithm"))
    ET.SubElement(algorithm, tag("osp", "FixedStepAlgorithm"), baseStepSize=repr(float(experiment["step"])))
    return to_bytes(root)
