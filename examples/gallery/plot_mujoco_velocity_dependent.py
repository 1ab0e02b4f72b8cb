"""
A speed-dependent COR in MuJoCo
===============================

MuJoCo gives each geom one ``solref``; this model's e falls with the impact speed. Since a ball's approach
speed is known before it touches, the geom's solref can be set for each contact: ``restitution export
mujoco`` maps e(v) to solref and solimp, solved on MuJoCo's own step for the time step they are tuned for
(t_contact/50 here; they hold to 1 % at it and every finer step). Needs MuJoCo (``pip install "restitution[export]"``).
"""

# %%
# The ball, the plate and the mapping per speed
# ---------------------------------------------
# An S2 tool-steel ball (d = 6.35 mm) on an Al 6061 plate of t = 6.35 mm, dropped from 0.3 m.
# :func:`restitution.export.mujoco_bounce.solref_from_model` gives (solref, solimp, the step they are tuned
# for) for an approach speed; :func:`~restitution.export.mujoco_bounce.bounce_in_mujoco` sets them just before
# each contact.
import matplotlib.pyplot as plt
import numpy as np

import restitution as r
from restitution.export.mujoco import ramp_solimp
from restitution.export.mujoco_bounce import bounce_in_mujoco, solref_from_model

sphere, plate, d, t = r.MATERIALS["s2_tool_steel"], r.MATERIALS["al_6061"], 6.35e-3, 6.35e-3  # [m]
mass = sphere.rho * np.pi * d**3 / 6  # [kg]
solref_at = solref_from_model(sphere, plate, d, t)
variable = bounce_in_mujoco(solref_at, d / 2, mass, height=0.3)

# %%
# The same drop with the first contact's solref kept: a constant e (solimp's ramp spans one step's approach,
# so it follows the speed)
first, _solimp, step = solref_at(variable.v_in[0])
constant = bounce_in_mujoco(lambda v: (first, ramp_solimp(v, step), step), d / 2, mass, height=0.3)


def model_e(v):
    """The model's e at the approach speeds v [m/s]."""
    return np.asarray(r.impact(np.asarray(v), **sphere.params("sphere"), sphere_d=d, **plate.params("plate"),
                               plate_t=t).e)


for v, e in zip(variable.v_in, variable.e):
    print(f"v = {v:.4f} m/s: MuJoCo e = {e:.4f}, model e = {float(model_e(v)):.4f}")

# %%
# Achieved e per bounce against the model's e(v)
# ----------------------------------------------
v = np.geomspace(min(variable.v_in) * 0.8, max(variable.v_in) * 1.1, 200)
fig, ax = plt.subplots(figsize=(7, 4), layout="constrained")
ax.plot(v, model_e(v), color="0.5", lw=2.5, label="model e(v)")
ax.plot(variable.v_in, variable.e, "o", label="MuJoCo, solref per contact")
ax.plot(constant.v_in, constant.e, "s", mfc="none", label="MuJoCo, first contact's solref kept")
ax.set(xscale="log", xlabel="approach speed [m/s]", ylabel="e")
ax.legend()
plt.show()
