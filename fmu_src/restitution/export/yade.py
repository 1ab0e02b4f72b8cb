"""Yade, Hertz-Mindlin (``Law2_ScGeom_MindlinPhys_Mindlin`` with ``Ip2_FrictMat_FrictMat_MindlinPhys(en=...)``):
the ``en`` that makes Yade's own clamped law return the model's e (docs/exports_clamped_hosts.md)."""
from __future__ import annotations

from ..jgm import effective_modulus
from .clamped import tsuji_drop, tsuji_parameters

__all__ = ["NAME", "FORCE_LAW", "SCHEME", "CR_MIN", "parameters", "snippet", "simulate_drop"]

NAME = "yade"
FORCE_LAW = (
    "Yade, Ip2_FrictMat_FrictMat_MindlinPhys with en and Law2_ScGeom_MindlinPhys_Mindlin, as read in its source "
    "(pkg/dem/HertzMindlin.cpp): kno = (4/3) E sqrt(R), 1/E = (1 - nu1^2)/E1 + (1 - nu2^2)/E2, "
    "alpha = -2 sqrt(5/6) beta sqrt(2 E sqrt(R)) with beta = ln(en) / sqrt(ln(en)^2 + pi^2) (Tsuji), "
    "c_n = alpha sqrt(m) uN^(1/4) (m the dynamic body's mass when the other is not dynamic), "
    "F_n = kno uN^(3/2) + c_n uN'. Without adhesion it clamps: where the total normal force would pull, "
    "it is set to zero. R = R1 R2/(R1 + R2) of the geometry's reference radii: for a sphere on a Box, Facet "
    "or Wall Yade takes the plate's radius equal to the sphere's (or twice it) unless the geometry functor "
    "has hertzian=True, which the snippet sets so that R is the sphere's. The en formula gives back en only "
    "without the clamp, so the exported en is the exact inverse of the clamped law. Mapped: en; young and "
    "poisson of both materials as they are.")
#: Yade's NewtonIntegrator: leapfrog, the force from the position and the previous half-step velocity.
SCHEME = "symplectic_euler"
#: Yade takes ln(en) of any en > 0; the smallest double above 0 that keeps beta away from -1 in floating point.
CR_MIN = 1e-300


def parameters(case) -> dict:
    """The JSON of ``restitution export yade`` for ``case`` (an ExportCase): "e", "en" (of the
    Ip2_FrictMat_FrictMat_MindlinPhys functor), "young" [Pa] and "poisson" (sphere, plate), "E_eff" [Pa],
    "t_contact" [s] (Yade's Hertz contact), "cr_naive_gives" (the e Yade returns for en = e), "R" [m],
    "m" [kg], "v" [m/s], "scheme". UnreachableRestitution where e < 0.136."""
    params = tsuji_parameters(case, CR_MIN, "Yade", "en")
    en = params.pop("cr")
    return {"e": params.pop("e"), "en": en, "young": [case.E1, case.E2], "poisson": [case.nu1, case.nu2],
            **params, "scheme": SCHEME}


def snippet(params: dict) -> str:
    """Yade's materials and engines for the sphere on a plate (Python in Yade, ready to paste)."""
    (young1, young2), (nu1, nu2) = params["young"], params["poisson"]
    return "\n".join([
        f"# restitution export yade: e = {params['e']:.6g} at v = {params['v']:.6g} m/s "
        f"(contact {params['t_contact']:.3g} s: O.dt below a fiftieth of it)",
        f"sphere_material = O.materials.append(FrictMat(young={young1:.9g}, poisson={nu1:.9g}, frictionAngle=0))",
        f"plate_material = O.materials.append(FrictMat(young={young2:.9g}, poisson={nu2:.9g}, frictionAngle=0))",
        "O.engines = [ForceResetter(), InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Box_Aabb()]),",
        "    InteractionLoop([Ig2_Sphere_Sphere_ScGeom(), Ig2_Box_Sphere_ScGeom(hertzian=True)],",
        f"                    [Ip2_FrictMat_FrictMat_MindlinPhys(en={params['en']:.9g})],",
        "                    [Law2_ScGeom_MindlinPhys_Mindlin()]),",
        "    NewtonIntegrator(damping=0)]  # damping=0: no numerical damping on top of the contact's",
    ])


def simulate_drop(params: dict, case, dt: float | None) -> dict:
    """The drop of ``case``'s sphere at ``case.v`` on Yade's published Mindlin law with ``params``'s en and
    moduli (Yade is not installed here): dt None finely, else Yade's leapfrog step [s]."""
    (young1, young2), (nu1, nu2) = params["young"], params["poisson"]
    e_eff = effective_modulus(young1, nu1, young2, nu2)  # Yade's E
    result = tsuji_drop(params["en"], e_eff, params["R"], case.m_sphere, case.v, dt, SCHEME)
    return {"e": result.e, "t_contact": result.t_contact, "law": "published force law, integrated here"}
