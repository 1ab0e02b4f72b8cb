"""
The FMI 3.0 FMU in fmpy
=======================

The native FMI 3.0 FMU (C, no Python inside) driven through fmpy's ``FMU3Slave``: the calls of the
FMI 2.0 recipe in FMI 3.0's names. The FMU is built by this script from the installed package: its
binaries for five platforms, compiled by gcc and zig (measured on two shared cores: about 10 s with
zig's cache warm, 35 s with it empty).
"""

# %%
# Build the FMU
# -------------
# ``build_native_one`` writes and validates ``fmi3/SpherePlateImpact.fmu`` in a folder; ``python -m
# restitution.fmu build --out DIR`` builds it with all the others. To use FMUs built before, point
# the environment variable ``RESTITUTION_GALLERY_FMUS`` at their folder (e.g. ``dist``), and this
# recipe builds nothing.
import os
import shutil
import tempfile
from pathlib import Path

from fmpy import extract, read_model_description
from fmpy.fmi3 import FMU3Slave

workdir = tempfile.TemporaryDirectory(prefix="restitution-gallery-")
if os.environ.get("RESTITUTION_GALLERY_FMUS"):
    path = Path(os.environ["RESTITUTION_GALLERY_FMUS"]) / "fmi3" / "SpherePlateImpact.fmu"
else:
    from restitution.fmu.builders.native import build_native_one

    path = build_native_one("SpherePlateImpact", Path(workdir.name), fmi_version="3.0")
print(path.parent.name + "/" + path.name, f"{path.stat().st_size / 1e3:.0f} kB")

# %%
# What the FMU declares
# ---------------------
# Its platforms, and the Enumeration type ``Material`` whose items name the presets.
md = read_model_description(str(path))
vr = {v.name: v.valueReference for v in md.modelVariables}
material_type = {t.name: t for t in md.typeDefinitions}["Material"]
code = {item.name: int(item.value) for item in material_type.items}
unzip_dir = extract(str(path))
print(f"FMI {md.fmiVersion}; binaries for:", ", ".join(sorted(os.listdir(Path(unzip_dir) / "binaries"))))
print(f"{len(code)} items of Material, e.g.:", ", ".join(list(code)[:4]), "...")

# %%
# Instantiate and set the bodies
# ------------------------------
# A chrome-steel ball of d = 4.76 mm on a brass plate of t = 3.18 mm; lengths in m. FMI 3.0 sets an
# Enumeration with ``setInt64`` and a real with ``setFloat64``.
fmu = FMU3Slave(guid=md.guid, unzipDirectory=unzip_dir, modelIdentifier=md.coSimulation.modelIdentifier,
                instanceName="impact")
fmu.instantiate()
fmu.enterInitializationMode(startTime=0.0)
fmu.setInt64([vr["sphere.material"], vr["plate.material"]], [code["chrome_steel"], code["brass_260"]])
fmu.setFloat64([vr["sphere.d"], vr["plate.t"]], [4.76e-3, 3.18e-3])  # [m]
fmu.exitInitializationMode()

# %%
# Impacts at a few speeds
# -----------------------
# Set ``v_approach`` [m/s], read ``e`` [1], ``v_rebound`` [m/s] and the validity flag ``valid``
# (a Boolean: inside both models' validated ranges) at once, no step needed.
for v in (0.5, 1.0, 2.3, 5.0):  # [m/s]
    fmu.setFloat64([vr["v_approach"]], [v])
    e, v_rebound = fmu.getFloat64([vr["e"], vr["v_rebound"]])
    valid, = fmu.getBoolean([vr["valid"]])
    print(f"v = {v:3.1f} m/s: e = {e:.4f}, v_rebound = {v_rebound:.4f} m/s, valid = {valid}")

# %%
# Free the instance and clean up.
fmu.terminate()
fmu.freeInstance()
shutil.rmtree(unzip_dir, ignore_errors=True)
workdir.cleanup()
