"""SpherePlateImpact's interface: one row per variable, in value-reference order.

Inputs and parameters carry :func:`restitution.impact`'s keyword, outputs the field of
:meth:`restitution.ImpactResult.as_dict` as :func:`restitution.model.published` gives it (every
output finite). Ranges are the package's declared domain (:data:`restitution.domain.DOMAIN`), inside
which every output is finite; the defaults are the paper's Table 3 pair (S2 tool-steel ball on Al 6061).
"""
from __future__ import annotations

import math

from ....materials import ALIASES, MATERIALS
from ....domain import DOMAIN, EFFECT_MODES, RESTITUTION_MODELS, ZENER_METHODS
from ...table import Table, calculated_parameter, input_, output, parameter

_BALL, _PLATE = MATERIALS["s2_tool_steel"], MATERIALS["al_6061"]
_D = 6.35e-3  # [m] the paper's default ball diameter and plate thickness (1/4 in)
_NU = (0.0, 0.5, False, False)  # 0.5: incompressible (E' = E/(1 - nu^2) stays finite)


def _domain(key):
    low, high = DOMAIN[key]
    return low, high, False, False


def _feedthrough(name, key, unit, description, vtype="Real"):
    return output(name, key, unit, description, vtype=vtype, feedthrough=True)


#: The materials a body can be given by name: code 0 "custom" (the body's numeric parameters), then
#: every preset of restitution.MATERIALS (aliases excluded), in its order.
PRESETS = tuple(key for key in MATERIALS if key not in ALIASES)
MATERIAL_CHOICES = ("custom", *PRESETS)
#: The material properties a preset sets: (FMU suffix, unit, what it is)
MATERIAL_PROPERTIES = (("E", "Pa", "elastic modulus"), ("nu", "1", "Poisson's ratio"),
                       ("Sy", "Pa", "yield strength"), ("rho", "kg/m3", "density"))
#: The selectors: FMU name -> the body whose parameters they replace
MATERIAL_SELECTORS = {"sphere.material": "sphere", "plate.material": "plate"}


def _material(body, default_text):
    codes = ", ".join(f"{code} = {word}" for code, word in enumerate(MATERIAL_CHOICES))
    return parameter(
        f"{body}.material", f"{body}_material", None, 0,
        f"{body.capitalize()} material by name: custom (default) uses {body}.E, {body}.nu, {body}.Sy and {body}.rho "
        f"as set ({default_text}); a preset uses its own values (docs/materials.md) and those four are ignored; "
        f"{body}.used.* show the values used. Codes: {codes}",
        vtype="Integer", choices=MATERIAL_CHOICES, first_code=0, enumeration="Material",
        item_descriptions=("the body's own numeric parameters",
                           *(f"{MATERIALS[k].name} ({MATERIALS[k].source})"
                             + (f". Note: {MATERIALS[k].note}" if MATERIALS[k].note else "") for k in PRESETS)))


def _used(body):
    return [calculated_parameter(f"{body}.used.{prop}", f"{body}_{prop}", unit,
                                 f"{body.capitalize()} {what} used: the preset's when {body}.material names one, "
                                 f"else {body}.{prop}")
            for prop, unit, what in MATERIAL_PROPERTIES]


def resolve_materials(values: dict) -> dict:
    """``values`` (FMU name -> value of the inputs and parameters) with each body's material properties
    taken from its preset where ``<body>.material`` names one (code > 0): the values the model uses."""
    out = dict(values)
    for selector, body in MATERIAL_SELECTORS.items():
        code = int(values[selector])
        if code:
            preset = MATERIALS[MATERIAL_CHOICES[code]]
            for prop, _unit, _what in MATERIAL_PROPERTIES:
                out[f"{body}.{prop}"] = float(getattr(preset, prop))
    return out


TABLE = Table("SpherePlateImpact", "Apparent coefficient of restitution of a sphere hitting a plate of finite "
              "thickness: JGM elastoplastic model fused with Zener's plate-wave model, I. Green, Nonlinear Dyn (2022)", (
    input_("v_approach", "v", "m/s", 1.0, "Normal approach speed of the sphere toward the plate, 0 to 1e4 m/s",
           _domain("v")),
    parameter("sphere.E", "sphere_E", "Pa", float(_BALL.E),
              "Sphere elastic modulus, 1e5 to 1e13 Pa (default: S2 tool steel, Table 3)", _domain("sphere_E")),
    parameter("sphere.nu", "sphere_nu", "1", float(_BALL.nu), "Sphere Poisson's ratio, 0 <= nu <= 0.5", _NU),
    parameter("sphere.Sy", "sphere_Sy", "Pa", float(_BALL.Sy),
              "Sphere yield strength, 1e3 to 1e13 Pa (1e12 for brittle materials)", _domain("sphere_Sy")),
    parameter("sphere.rho", "sphere_rho", "kg/m3", float(_BALL.rho), "Sphere density, 1 to 1e5 kg/m3",
              _domain("sphere_rho")),
    parameter("sphere.d", "sphere_d", "m", _D, "Sphere diameter, 1e-6 to 10 m", _domain("sphere_d")),
    parameter("plate.E", "plate_E", "Pa", float(_PLATE.E),
              "Plate elastic modulus, 1e5 to 1e13 Pa (default: Al 6061, Table 3)", _domain("plate_E")),
    parameter("plate.nu", "plate_nu", "1", float(_PLATE.nu), "Plate Poisson's ratio, 0 <= nu <= 0.5", _NU),
    parameter("plate.Sy", "plate_Sy", "Pa", float(_PLATE.Sy),
              "Plate yield strength, 1e3 to 1e13 Pa (1e12 for brittle materials)", _domain("plate_Sy")),
    parameter("plate.rho", "plate_rho", "kg/m3", float(_PLATE.rho), "Plate density, 1 to 1e5 kg/m3",
              _domain("plate_rho")),
    parameter("plate.t", "plate_t", "m", _D, "Plate thickness, 1e-7 to 100 m", _domain("plate_t")),
    parameter("restitution_model", "restitution_model", None, 1,
              "Elastoplastic COR: 1 = e45 (Eq. 8, default), 2 = e44 (Eq. 7, second branch reconstructed)",
              vtype="Integer", choices=RESTITUTION_MODELS),
    parameter("zener_method", "zener_method", None, 1,
              "Zener COR and contact time: 1 = exact (tabulated ODE solution), 2 = paper_fit (Eqs. 13, 13a), "
              "3 = linear (Eq. 22), 4 = ode (Eq. 10 integrated at every evaluation; the pythonfmu FMU only)",
              vtype="Integer", choices=ZENER_METHODS, native_interval=(1, 3, False, False)),
    parameter("plasticity", "plasticity", None, 2,
              "Elastoplastic effect: 0 = off (e_ep = 1), 1 = on, 2 = auto (skipped where 1 - e_ep < effect_tolerance)",
              vtype="Integer", choices=EFFECT_MODES, first_code=0),
    parameter("plate_waves", "plate_waves", None, 2,
              "Plate-wave effect: 0 = off (e_ze = 1, half-space), 1 = on, "
              "2 = auto (skipped where 1 - e_ze < effect_tolerance is guaranteed)",
              vtype="Integer", choices=EFFECT_MODES, first_code=0),
    parameter("effect_tolerance", "effect_tolerance", "1", 1e-6, "Largest change in e that auto may neglect, >= 0",
              (0.0, math.inf, False, True)),
    parameter("zener.ode_tolerance", "ode_rtol", "1", 1e-10,
              "Relative tolerance of zener_method = 4 (ode), 1e-14 <= tol <= 1e-2 (below what the integrator "
              "honours it is raised to 2.2e-14 for lambda <= 10, 1e-13 above)",
              (1e-14, 1e-2, False, False), range_text="1e-14 <= value <= 1e-2"),
    _feedthrough("e", "e", "1",
                 "Apparent coefficient of restitution, Eq. (20); < 0: sphere moves on with the plate"),
    _feedthrough("v_rebound", "v_rebound", "m/s", "Sphere speed away from the plate after impact, e * v_approach"),
    _feedthrough("jgm.e", "e_ep", "1", "Elastoplastic COR e_ep, Eq. (7) or (8)"),
    output("jgm.V_c", "V_c", "m/s", "Critical velocity at the onset of yielding, Eq. (6)"),
    _feedthrough("jgm.V_star", "V_star", "1", "Normalised impact speed V* = v_approach / V_c"),
    _feedthrough("zener.e", "e_ze", "1", "Zener's COR e_ze (1 where plate waves are off or skipped)"),
    _feedthrough("zener.lambda", "lam", "1", "Zener's inelasticity parameter lambda, Eq. (12)"),
    _feedthrough("zener.tau0", "tau0", "1", "Dimensionless contact time tau0 (plate_waves off: 3.2180655, Hertz; "
                 "skipped by auto: the method's value at lambda = 0; 0 where zener.contact_ends is false)"),
    _feedthrough("zener.t_contact", "t_contact", "s", "Contact duration T * tau0 (0 when v_approach = 0 "
                 "or where zener.contact_ends is false)"),
    _feedthrough("plate.mass_ratio", "mass_ratio", "1", "Sphere mass over the equivalent plate mass of Eq. (19), "
                 "m_a/m_b = (1 - e_ze)/(1 + e_ze): 0 for a half-space (plate waves off or negligible), 1 when e_ze = 0"),
    _feedthrough("plate.v_after", "v_plate", "m/s",
                 "Plate velocity after impact, Eq. (17), positive along the approach"),
    output("sphere.m", "m_a", "kg", "Sphere mass m_a = rho pi d^3/6 (equivalent plate mass m_b = "
           "sphere.m / plate.mass_ratio)"),
    _feedthrough("valid", "valid", None, "Inside both models' validated ranges: lambda <= 1.5 and V* <= 1000",
                 "Boolean"),
    _feedthrough("zener.in_range", "lambda_in_range", None, "lambda <= 1.5, Zener's studied range", "Boolean"),
    _feedthrough("jgm.in_range", "vstar_in_range", None, "V* <= 1000, the range of the JGM fits", "Boolean"),
    _feedthrough("e_negative", "e_negative", None, "e < 0: the sphere keeps moving with the plate after impact",
                 "Boolean"),
    _feedthrough("effects.plasticity", "plasticity_used", None, "The elastoplastic effect was applied (e_ep < 1)",
                 "Boolean"),
    _feedthrough("effects.plate_waves", "plate_waves_used", None, "The plate-wave effect was computed", "Boolean"),
    _feedthrough("zener.contact_ends", "contact_ends", None, "The sphere leaves the plate after a finite contact "
                 "time (false only for the linear method at lambda >= 2: e_ze = 0, tau0 and t_contact read 0)",
                 "Boolean"),
    # appended after the outputs so that the value references above stay as they were
    _material("sphere", "default: S2 tool steel"),
    _material("plate", "default: Al 6061"),
    *_used("sphere"),
    *_used("plate"),
    # the monitors of the model's assumptions (docs/assumptions.md), appended: the references above stay
    parameter("plate.edge_distance", "plate_edge_distance", "m", 0.0,
              "Distance from the impact point to the plate's nearest edge, for monitor.edge_echo only; "
              "0 (default): an unbounded plate, Zener's assumption", (0.0, math.inf, False, True)),
    _feedthrough("monitor.wave_delay", "wave_delay", "1",
                 "Zener's ejection time over its half-space value, tau0(lambda)/tau0(0) by the same method: 1 for "
                 "a half-space, 1.81 at lambda = 1.5; above 1.8136 the plastic and wave processes may no longer be "
                 "concurrent as Eq. (20) assumes (monitor.concurrent); 0 where zener.contact_ends is false"),
    _feedthrough("monitor.edge_echo", "edge_echo", "1",
                 "Return time of the first dilatational (P-) wave reflected from the nearest edge, "
                 "2 plate.edge_distance / c_L, over the contact time (conservative: the fastest wave); below 1 an "
                 "edge echo arrives during the contact (monitor.edge_clear); 1e9 for an unbounded plate "
                 "(plate.edge_distance = 0) or no contact"),
    _feedthrough("monitor.concurrent", "concurrent", None,
                 "monitor.wave_delay <= 1.8136, its value at lambda = 1.5: the wave delay is within what the "
                 "paper validated", "Boolean"),
    _feedthrough("monitor.edge_clear", "edge_clear", None,
                 "monitor.edge_echo >= 1: no wave reflected from the plate's edge returns during the contact",
                 "Boolean"),
), constants={f"MATERIAL_{prop.upper()}": (math.nan, *(float(getattr(MATERIALS[k], prop)) for k in PRESETS))
              for prop, _unit, _what in MATERIAL_PROPERTIES})


def fmu_values(**package_values) -> dict:
    """FMU name -> value for :func:`restitution.impact`'s keyword arguments (``sphere_E=...``,
    ``zener_method="exact"``, ``v=...``): the one translation from the package's names and words to
    the FMU's names and codes (``{"sphere.E": ..., "zener_method": 1, "v_approach": ...}``)."""
    by_key = TABLE.by_key()
    unknown = [key for key in package_values if key not in by_key]
    if unknown:
        raise KeyError(f"not an input or parameter of {TABLE.model}: {', '.join(unknown)}")
    out = {}
    for key, value in package_values.items():
        var = by_key[key]
        if var.choices is not None and isinstance(value, str):
            if value not in var.codes:
                raise ValueError(f"{key} = {value!r} is not one of {', '.join(var.choices)}")
            value = var.codes[value]
        out[var.name] = value
    return out
