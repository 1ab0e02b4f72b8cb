"""
Fitting the plate's yield strength to a drop test
=================================================

Drop a ball on a plate, record when it hits, and ask which plate yield strength Sy makes the model
bounce the ball at the same instants. The drop here is synthetic, made in this script from a known
Sy, so that you can see the fit find it; with a real drop you would read the times from a file
(``restitution.fit.fit("times.csv", ...)``) or a sound recording (docs: Calibrating from a drop test).
"""

# %%
# A synthetic drop test
# ---------------------
# A chrome-steel ball (d = 6.35 mm) released from h0 = 0.3 m onto an Al 6061 plate (t = 6.35 mm)
# whose true yield strength is 250 MPa (the ``al_6061`` preset says 290 MPa). Each impact at speed
# v_k sends the ball up at e(v_k) v_k, and the next impact comes one free flight later:
# t_(k+1) - t_k = 2 e(v_k) v_k / g.
import matplotlib.pyplot as plt
import numpy as np

import restitution as r
from restitution.fit import ImpactTimes, fit

g = 9.80665  # [m/s^2]
h0 = 0.3  # drop height [m]
ball = r.Sphere(r.MATERIALS["chrome_steel"], d=6.35e-3)  # d [m]
plate = r.Plate(r.MATERIALS["al_6061"], t=6.35e-3)  # t [m], the preset's Sy = 290 MPa
true_Sy = 250e6  # [Pa]
truth = {**ball.params(), **plate.params(), "plate_Sy": true_Sy}

v = np.sqrt(2 * g * h0)  # first impact speed [m/s]
times = [np.sqrt(2 * h0 / g)]  # first impact time after the release [s]
for _ in range(9):  # ten impacts
    v = r.impact(v, **truth).e * v  # rebound speed [m/s]
    times.append(times[-1] + 2 * v / g)

# %%
# A real timer is not perfect: 30 microseconds of Gaussian jitter on each time.
rng = np.random.default_rng(2026)
measured = np.array(times) + rng.normal(0.0, 30e-6, len(times))  # [s]
print("impact times [s]:", np.round(measured, 5))

# %%
# The fit
# -------
# :func:`restitution.fit.fit` takes the data (here an :class:`~restitution.fit.ImpactTimes` made in
# memory), the two bodies with everything known about them, and the names of the parameters to fit,
# spelt as the FMU's variables. ``h0`` [m] fixes the first impact speed; without it, it is fitted.
cal = fit(ImpactTimes(measured), sphere=ball, plate=plate, fit=["plate.Sy"], h0=h0)
print(cal)

# %%
# The estimate and its 95 % interval, in Pa:
sy = cal["plate.Sy"]
low, high = sy.ci95
print(f"plate.Sy = {sy.estimate / 1e6:.2f} MPa, 95 % interval [{low / 1e6:.2f}, {high / 1e6:.2f}] MPa "
      f"(true: {true_Sy / 1e6:g} MPa)")

# %%
# What the fit sees
# -----------------
# The intervals between impacts, measured and as the model gives them at the preset's Sy and at the
# fitted one: the preset's stronger plate yields less, loses less energy, and sends the ball
# higher, so its intervals are longer.
def intervals(plate_Sy):
    """The model's intervals between impacts [s] for a plate yield strength [Pa]."""
    params = {**truth, "plate_Sy": plate_Sy}
    speed, out = np.sqrt(2 * g * h0), []
    for _ in range(len(measured) - 1):
        speed = r.impact(speed, **params).e * speed
        out.append(2 * speed / g)
    return np.array(out)


k = np.arange(1, len(measured))
fig, ax = plt.subplots(figsize=(7, 4.2))
ax.plot(k, np.diff(measured) * 1e3, "o", label="measured (synthetic)")
ax.plot(k, intervals(plate.material.Sy) * 1e3, "--", label=f"model, preset Sy = {plate.material.Sy / 1e6:g} MPa")
ax.plot(k, intervals(sy.estimate) * 1e3, "-", label=f"model, fitted Sy = {sy.estimate / 1e6:.1f} MPa")
ax.set_xlabel("interval after impact k [1]")
ax.set_ylabel("time between impacts [ms]")
ax.legend()
ax.grid(True, alpha=0.3)
fig.tight_layout()
plt.show()
