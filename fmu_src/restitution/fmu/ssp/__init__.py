"""The ball-on-plate system as SSP (System Structure and Parameterization, Modelica Association):
``BallOnPlate.ssp`` (SSP 1.0, FMI 2.0 FMUs) and ``BallOnPlate-SSP2.ssp`` (SSP 2.0, FMI 3.0 FMUs), with
SSV parameter sets per material pair (:mod:`.ssv`), the system structure (:mod:`.ssd`) and the archive
(:mod:`.package`)."""
from .package import SSD_ENTRY, SSP_FILES, build_ssp, deterministic_zip, inline_ssp, write_ssps
from .ssd import CONNECTIONS, DEFAULT_EXPERIMENT, Component, system_structure
from .ssv import BALL_SET, DEFAULT_SET, PRESET_PAIR_SET, ParameterSet, impact_parameter_sets, write_parameter_set

__all__ = ["SSD_ENTRY", "SSP_FILES", "build_ssp", "deterministic_zip", "inline_ssp", "write_ssps", "CONNECTIONS",
           "DEFAULT_EXPERIMENT", "Component", "system_structure", "BALL_SET", "DEFAULT_SET",
           "PRESET_PAIR_SET", "ParameterSet", "impact_parameter_sets", "write_parameter_set"]
