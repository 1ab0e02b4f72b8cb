"""restitution: apparent coefficient of restitution of a sphere hitting a plate of finite
thickness, after I. Green, Nonlinear Dyn (2022): the Jackson-Green-Marghitu elastoplastic
model (Eqs. 1-8) fused with Zener's plate-wave model (Eqs. 9-13a) by Eq. (20).

Plain numpy/scipy functions; nothing here knows about FMI. Start with :func:`impact`. Physical
inputs are SI numbers or pint Quantities of any compatible unit (:mod:`restitution.quantities`).
"""
from .domain import DOMAIN, DomainWarning, check_in_domain, check_nonnegative
from .fusion import apparent_restitution, equivalent_plate_mass, velocities_after_impact
from .jgm import (critical_velocity, effective_modulus, poisson_coefficient, restitution_e44,
                  restitution_e45, yield_strain)
from .materials import (BRITTLE_SY, MATERIALS, TABLE1_CASES, TABLE4_CASES, Material, Plate, Sphere,
                        table4_case)
from .quantities import with_units
from .model import EFFECT_MODES, RESTITUTION_MODELS, ImpactResult, ImpactTerms, impact, impact_at, impact_terms
from .zener import (TAU0_HERTZ, ZENER_METHODS, inelasticity_parameter, zener_linear, zener_paper_fit,
                    zener_restitution)


@with_units(v="m/s")
def impact_between(sphere: Sphere, plate: Plate, v, **options) -> ImpactResult:
    """:func:`impact` for a :class:`Sphere` and a :class:`Plate` at approach speed ``v`` [m/s] (a number,
    an array, a pint Quantity or a string with its unit, "2 m/s"), which must lie in the model's domain,
    0 to 10 km/s, as the sphere's and the plate's properties do (a ValueError names a value outside it)."""
    if isinstance(v, str):
        from .units import python_quantity

        v = python_quantity("v_approach", v, "m/s")
    v = check_in_domain("v_approach", "v", check_nonnegative("v_approach", v, "m/s"), "m/s")
    return impact(v, **sphere.params(), **plate.params(), **options)


__all__ = [
    "impact", "impact_between", "DOMAIN", "DomainWarning", "impact_terms", "impact_at", "ImpactResult", "ImpactTerms", "Material", "Sphere", "Plate", "MATERIALS",
    "TABLE1_CASES", "TABLE4_CASES", "table4_case", "BRITTLE_SY", "RESTITUTION_MODELS",
    "ZENER_METHODS", "EFFECT_MODES", "TAU0_HERTZ", "apparent_restitution", "equivalent_plate_mass",
    "velocities_after_impact", "critical_velocity", "effective_modulus", "poisson_coefficient",
    "restitution_e44", "restitution_e45", "yield_strain", "inelasticity_parameter",
    "zener_linear", "zener_paper_fit", "zener_restitution", "__version__",
]


def __getattr__(name):
    """``restitution.__version__`` (:data:`restitution.about.VERSION`) and ``restitution.about``, loaded when
    asked: a command that does not show the version (``restitution cor``) does not load the module."""
    if name in ("__version__", "about"):
        from .about import VERSION  # the import makes the submodule this package's attribute `about`

        return VERSION if name == "__version__" else globals()["about"]
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
