"""Compatibility information for the FMI standard's tools page (the FMI Cross-Check's format):
:func:`~.writer.write_compat` (``restitution fmu compat --out DIR``), references from the package
(:mod:`.references`)."""
from .references import ball_trajectory, impact_outputs
from .writer import EXPERIMENT, platform_folder, write_compat

__all__ = ["EXPERIMENT", "ball_trajectory", "impact_outputs", "platform_folder", "write_compat"]
