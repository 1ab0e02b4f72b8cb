"""
A model-exchange bouncing ball with e(v) at each contact
========================================================

The native BouncingBall FMU in model exchange: the master integrates the ball's height and speed,
finds each contact as a zero crossing of the FMU's event indicator and, in the event, sets the ball's
``e`` to the apparent COR at that impact's speed. Here e(v) comes from the package
(:func:`restitution.cosim.package_rebound`); :func:`restitution.cosim.model_exchange_rebound` takes it
from the SpherePlateImpact FMU instead. The FMU is built by this script (FMI 3.0, about 10 s with zig's
cache warm); ``RESTITUTION_GALLERY_FMUS=DIR`` uses one built before.
"""

# %%
# Build the FMU
# -------------
import os
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import restitution as r
from restitution.cosim import bounce, bounce_model_exchange, package_rebound

workdir = tempfile.TemporaryDirectory(prefix="restitution-gallery-")
if os.environ.get("RESTITUTION_GALLERY_FMUS"):
    ball_fmu = Path(os.environ["RESTITUTION_GALLERY_FMUS"]) / "fmi3" / "BouncingBall.fmu"
else:
    from restitution.fmu.builders.native import build_native_one

    ball_fmu = build_native_one("BouncingBall", Path(workdir.name), fmi_version="3.0")

# %%
# Drop the ball
# -------------
# An S2 tool-steel ball (d = 6.35 mm) on an Al 6061 plate of t = 6.35 mm, dropped from 0.3 m; it rests
# once it rebounds slower than v_min = 5 cm/s. Each contact is located to 1e-12 s.
sphere = r.Sphere(r.MATERIALS["s2_tool_steel"], d=6.35e-3)  # [m]
plate = r.Plate(r.MATERIALS["al_6061"], t=6.35e-3)  # [m]
rebound = package_rebound(**sphere.params(), **plate.params())
me = bounce_model_exchange(str(ball_fmu), rebound, drop_height=0.3, v_min=0.05, event_tol=1e-12)
print(f"{me.n_impacts} contacts, at rest after {me.rest_time:.4f} s ({me.stop_reason}); "
      f"{me.extra['steps']} integrator steps")

# %%
# Against the event-exact co-simulation master
# --------------------------------------------
# :func:`restitution.cosim.bounce` flies the ball in closed form between impacts: the two agree to the
# event location's tolerance.
cs = bounce(rebound, drop_height=0.3, v_min=0.05)
print(f"largest difference of the contact instants: {np.max(np.abs(me.time - cs.time)):.2e} s; "
      f"of the impact speeds: {np.max(np.abs(me.v_approach - cs.v_approach)):.2e} m/s")
for k in range(3):
    print(f"contact {k + 1}: t = {me.time[k]:.6f} s, v = {me.v_approach[k]:.4f} m/s, e = {me.e[k]:.4f}")

# %%
# The drop
# --------
t = np.linspace(0.0, me.rest_time, 2000)
fig, ax = plt.subplots(figsize=(6.4, 3.2))
ax.plot(t, 1e3 * me.height(t), label="height (flights between the located contacts)")
ax.plot(me.time, np.zeros_like(me.time), "|", color="tab:red", markersize=10, label="contacts (model exchange)")
ax.set_xlabel("time [s]")
ax.set_ylabel("height [mm]")
ax.legend()
fig.tight_layout()
workdir.cleanup()
