"""Host-side helpers that drive the project's FMUs through fmpy (needs the ``fmu`` extra).

Nothing in the physics modules imports this subpackage.
"""
from .bouncing import Bounces, bounce, fmu_rebound, package_rebound
from .fmu import FmiStatusError, FmuInstance, impact_fmu_parameters
from .fixed_step import CosimResult, FixedStepMaster, ball_bounces
from .model_exchange import ModelExchangeInstance, bounce_model_exchange, model_exchange_rebound

__all__ = ["FmuInstance", "FmiStatusError", "impact_fmu_parameters",
           "Bounces", "bounce", "fmu_rebound", "package_rebound",
           "CosimResult", "FixedStepMaster", "ball_bounces",
           "ModelExchangeInstance", "bounce_model_exchange", "model_exchange_rebound"]
