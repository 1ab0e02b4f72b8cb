"""
A custom material, with units
=============================

Describe a material the presets do not have, give its properties in the units you have them in
(pint converts them to SI), and compute one impact.
"""

# %%
# The properties, in whatever units the datasheet uses
# -----------------------------------------------------
# A :class:`restitution.Material` takes the elastic modulus E, Poisson's ratio nu, the yield
# strength Sy and the density rho. A plain number is SI (Pa, 1, Pa, kg/m^3); a pint Quantity may
# have any compatible unit and is converted on entry. Here: a polymer-like plate material with
# its datasheet's units, GPa, MPa and g/cm^3.
import pint

import restitution as r

u = pint.UnitRegistry()

polymer = r.Material(
    "Stiff polymer (made-up values)",
    E=3.2 * u.GPa,
    nu=0.37,
    Sy=85 * u.MPa,
    rho=1.19 * u.g / u.cm**3,
    source="illustrative values, not a measured material",
)

# %%
# The stored values are SI: E [Pa], Sy [Pa], rho [kg/m^3].
print(f"E = {polymer.E:.4g} Pa, Sy = {polymer.Sy:.4g} Pa, rho = {polymer.rho:.4g} kg/m^3")

# %%
# A ball of a preset material on a plate of the new one
# -----------------------------------------------------
# The sphere is given by its diameter d, the plate by its thickness t; both accept pint lengths.
ball = r.Sphere(r.MATERIALS["chrome_steel"], d=0.25 * u.inch)
plate = r.Plate(polymer, t=4 * u.mm)

# %%
# One impact at 1.5 m/s. ``print`` shows the apparent COR e, its two parts (e_ep from plasticity,
# e_ze from the plate's waves), the rebound speed, and whether the impact lies inside the ranges
# the model was validated on.
result = r.impact_between(ball, plate, v=1.5 * u.m / u.s)
print(result)

# %%
# Every field is an attribute, in SI units: e [1], v_rebound [m/s], t_contact [s], m_eff [kg] ...
print(f"e = {result.e:.4f}")
print(f"rebound speed = {result.v_rebound:.4f} m/s")
print(f"contact time = {result.t_contact * 1e6:.2f} us")
print(f"equivalent plate mass = {result.m_eff * 1e3:.3f} g (sphere: {result.m_a * 1e3:.3f} g)")

# %%
# A Quantity of the wrong kind is refused with a message that names the argument
try:
    r.Plate(polymer, t=4 * u.kg)
except ValueError as exc:
    print("ValueError:", exc)
