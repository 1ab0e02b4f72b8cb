"""Building the FMUs, by product, each builder from the package alone (none reads another's output):

* :mod:`.python_fmu`: ``DIR/<model>.fmu``, pythonfmu behind the C guard (:mod:`.guard`);
* :mod:`.native`: ``DIR/fmi2/<model>.fmu`` and ``DIR/fmi3/<model>.fmu``, the C front, backends and physics;
* :mod:`.products`: all of them (``python -m restitution.fmu build``) and the default FMUs of the host tools;
* :mod:`.plan` (which products, platforms and compilers a build takes; which a directory lacks) and
  :mod:`.progress` (the line per product and platform a build prints as it goes);
* :mod:`.compile` (C flags, the C physics, FMI headers), :mod:`.sources` (what an FMU is built from and
  its source hash), :mod:`.files` (archives put in place atomically), :mod:`.licenses` (``documentation/``).

The texts they write come from :mod:`restitution.fmu.describe`.
"""
from .products import FMUS, SCOPES, BuildError, build_all, build_one, default_fmu, default_fmu_dir

__all__ = ["FMUS", "SCOPES", "BuildError", "build_all", "build_one", "default_fmu", "default_fmu_dir"]
