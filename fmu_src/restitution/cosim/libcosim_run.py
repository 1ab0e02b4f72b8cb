"""Run connected FMUs with OSP libcosim (``pip install libcosimpy``), from an OSP system structure.

libcosim reads a system as ``OspSystemStructure.xml`` (the Open Simulation Platform's
format: simulators with their FMU and initial values, variable connections, base step
size and algorithm). :func:`write_system_structure` writes one; :func:`run_system_structure`
loads it with ``CosimExecution.from_osp_config_file``, records chosen variables with a
time-series observer and returns a :class:`~restitution.cosim.fixed_step.CosimResult`.

Times: the XML holds seconds (``BaseStepSize``); libcosim's own API counts integer
**nanoseconds** (a float step such as 1e-3 silently becomes 0 and the execution then
crashes, docs/fmi_tools.md), so every duration passed to libcosimpy here is converted with
:func:`to_ns`.

libcosim's ``fixedStep`` algorithm steps every FMU, reads each FMU's outputs right after
its own step and transfers them to the connected inputs. A loop through a
direct-feedthrough FMU (ball -> impact -> ball) therefore lags by one communication step:
the COR the impact FMU outputs at a communication point belongs to the approach speed it
received at the previous one. Measured with BouncingBall (contact_mode = wait): the ball,
waiting at the plate, receives the COR for the speed it had at the last communication
point *before* the contact, not for its impact speed.
"""
from __future__ import annotations

import time as _time
from pathlib import Path
from xml.etree import ElementTree as ET

import numpy as np

from .fixed_step import BALL_IMPACT_CONNECTIONS, CosimResult

__all__ = ["to_ns", "write_system_structure", "run_system_structure", "OSP_NAMESPACE"]

OSP_NAMESPACE = "http://opensimulationplatform.com/MSMI/OSPSystemStructure"
_NS_PER_S = 1_000_000_000


def to_ns(seconds: float) -> int:
    """A duration in integer nanoseconds, as libcosim's API wants it (rounded, must be > 0)."""
    ns = int(round(float(seconds) * _NS_PER_S))
    if ns <= 0:
        raise ValueError(f"duration = {seconds!r} s is below 1 ns: libcosim counts integer nanoseconds")
    return ns


def _variable_types(fmu) -> dict:
    from fmpy import read_model_description

    return {v.name: v.type for v in read_model_description(str(fmu)).modelVariables}


def _value_element(parent, value, vtype=None):
    if vtype == "Real":
        ET.SubElement(parent, "Real", value=repr(float(value)))
    elif vtype in ("Integer", "Enumeration"):
        ET.SubElement(parent, "Integer", value=str(int(value)))
    elif vtype == "Boolean" or isinstance(value, bool):
        ET.SubElement(parent, "Boolean", value="true" if value else "false")
    elif isinstance(value, int):
        ET.SubElement(parent, "Integer", value=str(value))
    elif isinstance(value, str):
        ET.SubElement(parent, "String", value=value)
    else:
        ET.SubElement(parent, "Real", value=repr(float(value)))


def write_system_structure(path, simulators: dict, step_size: float, connections=BALL_IMPACT_CONNECTIONS,
                           start_time: float = 0.0, algorithm: str = "fixedStep") -> Path:
    """Write an ``OspSystemStructure.xml`` and return its path.

    ``simulators``: {name: (fmu_path, {variable: initial value})}; ``connections``:
    ("sim.variable", "sim.variable") pairs, source first. Each initial value is written with
    its variable's type from the FMU's modelDescription.xml. FMU paths are written relative to the file
    when possible (libcosim resolves ``source`` against the file's folder).
    """
    path = Path(path)
    if path.suffix.lower() != ".xml":
        path = path / "OspSystemStructure.xml"
    path.parent.mkdir(parents=True, exist_ok=True)
    root = ET.Element("OspSystemStructure", xmlns=OSP_NAMESPACE, version="0.1")
    ET.SubElement(root, "StartTime").text = repr(float(start_time))
    ET.SubElement(root, "BaseStepSize").text = repr(float(step_size))
    ET.SubElement(root, "Algorithm").text = algorithm
    sims = ET.SubElement(root, "Simulators")
    for name, (fmu, initial) in simulators.items():
        fmu = Path(fmu).resolve()
        try:
            source = fmu.relative_to(path.parent.resolve()).as_posix()
        except ValueError:
            source = fmu.as_posix()
        sim = ET.SubElement(sims, "Simulator", name=name, source=source)
        if initial:
            types = _variable_types(fmu)
            values = ET.SubElement(sim, "InitialValues")
            for variable, value in initial.items():
                if variable not in types:
                    raise KeyError(f"{name}: {fmu.name} has no variable {variable!r}")
                _value_element(ET.SubElement(values, "InitialValue", variable=variable), value, types[variable])
    conns = ET.SubElement(root, "Connections")
    for source, target in connections:
        conn = ET.SubElement(conns, "VariableConnection")
        for end in (source, target):
            sim, _, variable = end.partition(".")
            ET.SubElement(conn, "Variable", simulator=sim, name=variable)
    ET.indent(root, "  ")
    text = ET.tostring(root, encoding="unicode")  # xmlns is a plain attribute: unprefixed tags, as libcosim's examples
    path.write_text('<?xml version="1.0" encoding="utf-8"?>\n' + text + "\n")
    return path


def _samples(observer, index: int, reference: int, count: int, real: bool):
    """(time points [ns], values) of one observed variable from step 0 on.

    Calls libcosimc directly: libcosimpy 0.0.6's time_series_*_samples trims its result by
    counting zero step numbers, which drops the (valid) sample of step 0.
    """
    from ctypes import POINTER, c_double, c_int, c_int64, c_size_t, c_uint32

    from libcosimpy._internal import libcosimc, wrap_function
    from libcosimpy.CosimObserver import CosimObserver

    c_type = c_double if real else c_int
    get = wrap_function(lib=libcosimc(),
                        funcname="cosim_observer_slave_get_real_samples" if real
                        else "cosim_observer_slave_get_integer_samples",
                        argtypes=[POINTER(CosimObserver), c_int, c_uint32, c_int64, c_size_t,
                                  c_type * count, c_int64 * count, c_int64 * count],
                        restype=c_int64)
    values, steps, times = (c_type * count)(), (c_int64 * count)(), (c_int64 * count)()
    n = get(observer.ptr(), index, reference, 0, count, values, steps, times)
    if n < 0:
        raise RuntimeError(f"libcosim returned no samples for slave {index}, variable {reference}")
    return np.asarray(times[:n], dtype=np.int64), np.asarray(values[:n], dtype=float)


def run_system_structure(path, stop_time: float, record=(), log_level: str = "ERROR") -> CosimResult:
    """Load an OspSystemStructure.xml into libcosim, simulate to ``stop_time`` [s], record ``record``.

    ``record``: "simulator.variable" names (Real, Integer or Boolean outputs), sampled after
    every macro step by a buffered time-series observer (Booleans are read as last values
    only, at the end). Wall time covers ``simulate_until`` only (not loading the FMUs).
    """
    from libcosimpy.CosimEnums import CosimVariableType
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver

    log_output_level(CosimLogLevel[log_level])
    path = Path(path)
    root = ET.parse(path).getroot()
    step_size = float(root.find(f"{{{OSP_NAMESPACE}}}BaseStepSize").text)
    start_el = root.find(f"{{{OSP_NAMESPACE}}}StartTime")
    start_time = float(start_el.text) if start_el is not None else 0.0
    n_steps = int(round((stop_time - start_time) / step_size))

    execution = CosimExecution.from_osp_config_file(str(path))
    observer = CosimObserver.create_time_series(buffer_size=n_steps + 16)
    execution.add_observer(observer)
    plan = []
    for name in record:
        sim, _, variable = name.partition(".")
        index = execution.slave_index_from_instance_name(sim)
        if index is None:
            raise KeyError(f"{name}: no simulator named {sim!r} in {path}")
        found = [v for v in execution.slave_variables(index) if v.name.decode() == variable]
        if not found:
            raise KeyError(f"{name}: simulator {sim!r} has no variable {variable!r}")
        vtype = CosimVariableType(found[0].type)
        if vtype not in (CosimVariableType.REAL, CosimVariableType.INTEGER):
            raise ValueError(f"{name}: only Real and Integer variables can be recorded")
        observer.start_time_series(index, found[0].reference, vtype)
        plan.append((name, index, found[0].reference, vtype))

    wall = _time.perf_counter()
    ok = execution.simulate_until(to_ns(stop_time))
    wall = _time.perf_counter() - wall
    if not ok:
        raise RuntimeError(f"libcosim failed to simulate {path} to {stop_time} s")

    values, time_ns = {}, None
    for name, index, reference, vtype in plan:
        times, samples = _samples(observer, index, reference, n_steps + 16, vtype == CosimVariableType.REAL)
        values[name] = samples
        if time_ns is None:
            time_ns = times
    time = time_ns / _NS_PER_S if time_ns is not None else np.array([])
    return CosimResult(time=time, values=values, step_size=step_size, wall_time=wall, steps=n_steps,
                       master="libcosim fixedStep", extra={"structure": str(path)})
