"""The COR in the simulators users already run: ``restitution export HOST`` writes a host's own contact
parameters for one sphere, plate and speed (or the model's table over a speed range) and verifies them by
re-simulating a drop with the host's contact law (docs/exports.md).

The parts: :mod:`.hosts` (the case to export and the interface every host module follows), one module
per host (:mod:`.mujoco`, :mod:`.chrono`, :mod:`.liggghts`, :mod:`.yade`, :mod:`.elastogap`), :mod:`.table`
(the model over a speed range, also Solfec's list) and :mod:`.command` (the command line).
"""
from .hosts import HOST_MODULES, HOSTS, ExportCase, export_case, host_module

__all__ = ["ExportCase", "export_case", "HOSTS", "HOST_MODULES", "host_module"]
