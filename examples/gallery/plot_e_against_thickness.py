"""
The COR against plate thickness, for a few ball sizes
=====================================================

A thin plate takes energy from the impact into its waves (Zener's effect); a thick plate acts like a
half-space, where only plasticity (the JGM model) lowers the COR. Plotted against the plate
thickness t, each ball size has its own curve; plotted against the ratio t/d of thickness to ball
diameter, they fall onto one.
"""

# %%
# The bodies and the speed
# ------------------------
# Chrome-steel balls on an aluminium 6061 plate, dropped from 0.3 m (v = sqrt(2 g h) = 2.43 m/s).
# For these bodies at this speed, e falls below 0 (flag ``e_negative``: the ball keeps moving with
# the plate) where t/d < 0.34, and Zener's parameter lambda leaves the range his model was studied
# on (lambda <= 1.5, flag ``lambda_in_range``) where t/d < 0.26: the plot starts at t/d = 0.35.
import matplotlib.pyplot as plt
import numpy as np

import restitution as r

steel = r.MATERIALS["chrome_steel"]
aluminium = r.MATERIALS["al_6061"]
v = np.sqrt(2 * 9.80665 * 0.3)  # approach speed [m/s]
diameters_mm = [3.0, 6.35, 12.7, 25.4]  # ball diameters [mm]
t_over_d = np.geomspace(0.35, 20, 200)  # plate thickness over ball diameter [1]

# %%
# One vectorized call per ball
# ----------------------------
# :func:`restitution.impact` takes numpy arrays and broadcasts them: here the plate thickness
# ``plate_t`` [m] is an array, everything else a number, and one call gives e for every thickness.
curves = {}  # ball diameter [mm] -> (plate thicknesses [m], e [1])
for d_mm in diameters_mm:
    d = d_mm * 1e-3  # [m]
    params = {**r.Sphere(steel, d).params(), **aluminium.params("plate")}
    t = t_over_d * d  # [m]
    result = r.impact(v, **params, plate_t=t)
    assert result.valid.all() and not result.e_negative.any()  # inside the validated ranges
    curves[d_mm] = (t, result.e)

# %%
# The half-space limit: the plate's waves switched off (``plate_waves="off"``), plasticity alone.
half_space = r.impact(v, **params, plate_t=1.0, plate_waves="off")
print(f"half-space e = {half_space.e:.4f}")

# %%
# Against t, then against t/d
# ---------------------------
fig, (by_thickness, by_ratio) = plt.subplots(1, 2, figsize=(10, 4.2), sharey=True)
line_styles = ["-", "--", "-.", (0, (1, 1))]  # on the right the curves overlap: dashes tell them apart
for (d_mm, (t, e)), style in zip(curves.items(), line_styles):
    by_thickness.semilogx(t * 1e3, e, label=f"d = {d_mm:g} mm")
    by_ratio.semilogx(t_over_d, e, linestyle=style, label=f"d = {d_mm:g} mm")
for ax in (by_thickness, by_ratio):
    ax.axhline(half_space.e, color="0.5", linewidth=3, alpha=0.4, label="half-space (plasticity only)")
    ax.grid(True, which="both", alpha=0.3)
by_thickness.set_xlabel("plate thickness t [mm]")
by_ratio.set_xlabel("plate thickness / ball diameter, t/d [1]")
by_thickness.set_ylabel("apparent COR e [1]")
by_thickness.legend(fontsize="small")
fig.suptitle(f"Chrome-steel balls on Al 6061 at v = {v:.2f} m/s")
fig.tight_layout()
plt.show()

# %%
# Against t/d the curves lie on top of each other: Zener's parameter lambda (Eq. 12) depends on the
# sizes through (d/t)^2 only, and the elastoplastic part not at all (the critical velocity V_c of
# Eq. 6 does not depend on d). The largest difference between the curves at equal t/d:
spread = np.ptp([e for _t, e in curves.values()], axis=0).max()
print(f"largest spread of e over the ball sizes at equal t/d: {spread:.1e}")
