"""Building the project's FMUs from the installed package (``python -m restitution.fmu build``).

The slave scripts (``slaves/``), the plain-C-host loader (``native_host/``) and the build ship
with the package, so an installed ``restitution[fmu]`` builds the same FMUs as a source checkout.
This subpackage is host-side: the FMUs bundle only the physics modules.
"""
from .build import FMUS, BuildError, build_all, build_one, default_fmu, default_fmu_dir

__all__ = ["FMUS", "BuildError", "build_all", "build_one", "default_fmu", "default_fmu_dir"]
