"""
A Monte Carlo of the COR: how uncertain inputs spread e
=======================================================

Nobody knows a ball's approach speed, the plate's yield strength or its thickness exactly. Draw
them from distributions, run the model on every draw, and look at the spread of e. Here with
:func:`restitution.sweep.run_sweep`, which records the draws beside the results (and can run
millions of cases on a Dask cluster), then once more with plain numpy and :func:`restitution.impact`.
"""

# %%
# The uncertain inputs
# --------------------
# A brass ball (d = 6.35 mm) on an Al 6061 plate of nominal thickness 3 mm:
#
# * the approach speed is 2 m/s with a standard deviation of 10 cm/s,
# * the plate's yield strength is within +-15 % of the preset's 290 MPa (uniform),
# * the thickness is within +-5 % of 3 mm (uniform).
#
# Names are the FMU's (``v_approach``, ``plate.Sy``, ...); values take units as strings, and a
# relative spread is a plain number. ``scheduler="serial"`` runs in this process, without Dask.
import matplotlib.pyplot as plt
import numpy as np

import restitution as r
from restitution.sweep import SweepSpec, run_sweep

spec = SweepSpec(
    pairs=["brass_260/al_6061"],
    fixed={"sphere.d": "6.35 mm", "plate.t": "3 mm"},
    random={"v_approach": {"normal": ["2 m/s", "10 cm/s"]},
            "plate.Sy": {"uniform_rel": 0.15},
            "plate.t": {"uniform_rel": 0.05}},
    samples=20_000,
    seed=7,
)
result = run_sweep(spec, scheduler="serial")
table = result.columns  # name -> array, one value per case; SI units
e = table["e"]  # [1]
print(f"{e.size} cases, {np.count_nonzero(table['valid'])} inside the validated ranges")
print(f"v_approach: mean {table['v_approach'].mean():.3f} m/s, sd {table['v_approach'].std():.3f} m/s")
print(f"e: mean {e.mean():.4f}, sd {e.std():.4f}, 2.5-97.5 % [{np.percentile(e, 2.5):.4f}, "
      f"{np.percentile(e, 97.5):.4f}]")

# %%
# The distribution of e
# ---------------------
fig, ax = plt.subplots(figsize=(7, 4.2))
ax.hist(e, bins=60, density=True, color="tab:blue", alpha=0.75)
ax.axvline(np.median(e), color="k", linewidth=1, label=f"median e = {np.median(e):.4f}")
ax.set_xlabel("apparent COR e [1]")
ax.set_ylabel("probability density [1]")
ax.set_title("Brass ball on a 3 mm Al 6061 plate: v, Sy and t uncertain")
ax.legend()
fig.tight_layout()

# %%
# The same with numpy alone
# -------------------------
# :func:`restitution.impact` broadcasts arrays, so a Monte Carlo is one call on the draws. Its own
# random numbers differ from the sweep's, so its statistics agree within sampling error, not digit
# for digit.
rng = np.random.default_rng(7)
n = 20_000
ball = r.Sphere(r.MATERIALS["brass_260"], d=6.35e-3)  # d [m]
aluminium = r.MATERIALS["al_6061"]
draws = dict(
    v=rng.normal(2.0, 0.10, n),  # [m/s]
    plate_Sy=aluminium.Sy * rng.uniform(0.85, 1.15, n),  # [Pa]
    plate_t=3e-3 * rng.uniform(0.95, 1.05, n),  # [m]
)
params = {**ball.params(), **aluminium.params("plate")}  # the presets' values, SI
e_numpy = r.impact(**{**params, **draws}).e  # the draws replace the preset's plate_Sy
print(f"numpy: e mean {e_numpy.mean():.4f}, sd {e_numpy.std():.4f}")
plt.show()
