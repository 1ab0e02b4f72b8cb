"""Project Chrono, SMC (penalty) contact with the Hertz force model: the restitution ``cr`` to give
``ChContactMaterialSMC`` so that Chrono's own clamped law returns the model's e (docs/exports_clamped_hosts.md)."""
from __future__ import annotations

import sys

from ..jgm import effective_modulus
from .clamped import tsuji_drop, tsuji_parameters

__all__ = ["NAME", "FORCE_LAW", "SCHEME", "CR_MIN", "parameters", "snippet", "simulate_drop"]

NAME = "chrono"
FORCE_LAW = (
    "Project Chrono, ChSystemSMC with ContactForceModel Hertz and material properties (the default), as read in "
    "its source (the Hertz case of the SMC contact force in physics/ChContactSMC.cpp; the composite material in "
    "ChContactMaterialSMC.cpp): S_n = 2 E_eff sqrt(R_eff delta), k_n = (2/3) S_n, "
    "beta = ln(cr) / sqrt(ln(cr)^2 + pi^2), g_n = -2 sqrt(5/6) beta sqrt(S_n m_eff), "
    "F_n = k_n delta + g_n delta', with 1/E_eff = (1 - nu1^2)/E1 + (1 - nu2^2)/E2 and cr the smaller of the "
    "two materials' restitution. It clamps: a negative F_n is set to 0 (no adhesion). The beta formula returns "
    "cr exactly only without that clamp; with it the sphere leaves early and faster, so the exported cr is "
    "the exact inverse of the clamped law (brentq on the drop), not e. Mapped: cr; E and nu of both bodies "
    "as they are (Chrono forms E_eff itself). Chrono takes R_eff from the collision system (the default "
    "curvature radius, 0.1 m, unless set) and m_eff = m1 m2/(m1 + m2) even for a fixed body: the snippet sets "
    "the curvature radius to the sphere's and gives the fixed plate a mass 1e6 times the sphere's.")
#: Chrono's SMC step with the default EULER_IMPLICIT_LINEARIZED stepper and non-stiff contact.
SCHEME = "symplectic_euler"
#: The smallest cr Chrono's Hertz branch distinguishes: it replaces a cr below machine epsilon by epsilon.
CR_MIN = sys.float_info.epsilon
#: The fixed plate's mass over the sphere's in the snippet: Chrono's m_eff is then the sphere's to 1e-6.
PLATE_MASS_RATIO = 1e6


def parameters(case) -> dict:
    """The JSON of ``restitution export chrono`` for ``case`` (an ExportCase): "e", "cr" (give it to both
    materials, SetRestitution), "E_eff" [Pa] (what Chrono forms from E1, nu1, E2, nu2), "E1", "nu1", "E2",
    "nu2", "t_contact" [s] (Chrono's contact, Hertz), "R" [m] (set as the effective curvature radius), "m" [kg],
    "plate_mass" [kg] (the fixed plate's mass to give Chrono), "cr_naive_gives" (the e Chrono returns for
    cr = e), "v" [m/s], "contact_model": "Hertz", "scheme". UnreachableRestitution where e < 0.136."""
    params = tsuji_parameters(case, CR_MIN, "Chrono SMC", "restitution")
    return {**params, "plate_mass": PLATE_MASS_RATIO * case.m_sphere, "contact_model": "Hertz", "scheme": SCHEME}


def snippet(params: dict) -> str:
    """A PyChrono set-up of the two SMC materials and the system (Python, ready to paste)."""
    return "\n".join([
        f"# restitution export chrono: e = {params['e']:.6g} at v = {params['v']:.6g} m/s "
        f"(contact {params['t_contact']:.3g} s: keep the step below a fiftieth of it)",
        "import pychrono as chrono",
        "system = chrono.ChSystemSMC()",
        "system.SetContactForceModel(chrono.ChSystemSMC.Hertz)",
        "system.UseMaterialProperties(True)",
        f"chrono.ChCollisionInfo.SetDefaultEffectiveCurvatureRadius({params['R']:.9g})  # the sphere's radius [m]",
        *(line for body, (E, nu) in (("sphere", ("E1", "nu1")), ("plate", ("E2", "nu2"))) for line in (
            f"{body}_material = chrono.ChContactMaterialSMC()",
            f"{body}_material.SetYoungModulus({params[E]:.9g})",
            f"{body}_material.SetPoissonRatio({params[nu]:.9g})",
            f"{body}_material.SetRestitution({params['cr']:.9g})  # Chrono takes the smaller of the two",
        )),
        f"# the sphere: mass {params['m']:.9g} kg, radius {params['R']:.9g} m, sphere_material;",
        f"# the plate: fixed (SetFixed(True)) with SetMass({params['plate_mass']:.9g}), plate_material",
    ])


def simulate_drop(params: dict, case, dt: float | None) -> dict:
    """The drop of ``case``'s sphere at ``case.v`` on Chrono's published Hertz law with ``params``'s cr and
    moduli (Chrono itself is not installed here): dt None finely, else Chrono's semi-implicit Euler step [s]."""
    e_eff = effective_modulus(params["E1"], params["nu1"], params["E2"], params["nu2"])  # as Chrono forms it
    m_eff = case.m_sphere * params["plate_mass"] / (case.m_sphere + params["plate_mass"])
    result = tsuji_drop(params["cr"], e_eff, params["R"], case.m_sphere, case.v, dt, SCHEME, damping_mass=m_eff)
    return {"e": result.e, "t_contact": result.t_contact, "law": "published force law, integrated here"}
