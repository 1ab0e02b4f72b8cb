"""
The FMI 2.0 FMU in fmpy
=======================

The model as an FMI 2.0 co-simulation FMU, driven call by call through fmpy's ``FMU2Slave``: set
the bodies once, then set an approach speed and read the COR, as a co-simulation master does at each
impact. The FMU is built by this script from the installed package (about two seconds).
"""

# %%
# Build the FMU
# -------------
# ``build_one`` writes the pythonfmu FMU ``SpherePlateImpact.fmu`` (FMI 2.0, co-simulation) into a
# folder and validates it. ``python -m restitution.fmu build --out DIR`` builds it and all the
# others from the command line. To use FMUs built before, point the environment variable
# ``RESTITUTION_GALLERY_FMUS`` at their folder (e.g. ``dist``), and this recipe builds nothing.
import os
import shutil
import tempfile
from pathlib import Path

from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

import restitution as r

workdir = tempfile.TemporaryDirectory(prefix="restitution-gallery-")
if os.environ.get("RESTITUTION_GALLERY_FMUS"):
    path = Path(os.environ["RESTITUTION_GALLERY_FMUS"]) / "SpherePlateImpact.fmu"
else:
    from restitution.fmu.builders.products import build_one

    path = build_one("SpherePlateImpact", Path(workdir.name))
print(path.name, f"{path.stat().st_size / 1e3:.0f} kB")

# %%
# What the FMU declares
# ---------------------
# Variables are addressed by value reference; the modelDescription gives each name's reference and
# unit. The materials are an Enumeration: ``custom`` (the body's E, nu, Sy, rho as set) or a preset.
md = read_model_description(str(path))
vr = {v.name: v.valueReference for v in md.modelVariables}
unit = {v.name: v.declaredType.unit if v.declaredType is not None else v.unit for v in md.modelVariables}
material = {item.name: int(item.value) for item in md.typeDefinitions[0].items}
print(f"FMI {md.fmiVersion}, {len(vr)} variables; inputs:",
      ", ".join(f"{v.name} [{unit[v.name] or 1}]" for v in md.modelVariables if v.causality == "input"))

# %%
# Instantiate and set the bodies
# ------------------------------
# A chrome-steel ball of d = 4.76 mm on a brass plate of t = 3.18 mm; lengths in m.
unzip_dir = extract(str(path))
fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzip_dir, modelIdentifier=md.coSimulation.modelIdentifier,
                instanceName="impact")
fmu.instantiate()
fmu.setupExperiment(startTime=0.0)
fmu.enterInitializationMode()
fmu.setInteger([vr["sphere.material"], vr["plate.material"]], [material["chrome_steel"], material["brass_260"]])
fmu.setReal([vr["sphere.d"], vr["plate.t"]], [4.76e-3, 3.18e-3])  # [m]
fmu.exitInitializationMode()

# %%
# Impacts at a few speeds
# -----------------------
# The outputs follow the input at once (direct feedthrough): set ``v_approach`` [m/s], read ``e``
# [1] and ``v_rebound`` [m/s]; no step is needed. ``plate.used.E`` shows the modulus the preset gave.
for v in (0.5, 1.0, 2.3, 5.0):  # [m/s]
    fmu.setReal([vr["v_approach"]], [v])
    e, v_rebound, t_contact = fmu.getReal([vr["e"], vr["v_rebound"], vr["zener.t_contact"]])
    print(f"v = {v:3.1f} {unit['v_approach']}: e = {e:.4f}, v_rebound = {v_rebound:.4f} {unit['v_rebound']}, "
          f"t_contact = {t_contact * 1e6:.2f} us")
plate_E, = fmu.getReal([vr["plate.used.E"]])
print(f"plate.used.E = {plate_E / 1e9:g} GPa (brass)")

# %%
# The package gives the same numbers without FMI: :func:`restitution.impact_between`.
same = r.impact_between(r.Sphere(r.MATERIALS["chrome_steel"], 4.76e-3), r.Plate(r.MATERIALS["brass_260"], 3.18e-3),
                        v=2.3)
print(f"package: e = {same.e:.4f} at 2.3 m/s")

# %%
# Free the instance and clean up. :class:`restitution.cosim.FmuInstance` wraps these calls by
# variable name, for FMI 2.0 and FMI 3.0 alike.
fmu.terminate()
fmu.freeInstance()
shutil.rmtree(unzip_dir, ignore_errors=True)
workdir.cleanup()
