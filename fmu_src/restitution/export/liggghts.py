"""LIGGGHTS, ``pair_style gran model hertz tangential history`` with ``limitForce on``: the
``coefficientRestitution`` that makes LIGGGHTS's own clamped Hertz law return the model's e
(docs/exports_clamped_hosts.md)."""
from __future__ import annotations

from ..jgm import effective_modulus
from .clamped import tsuji_drop, tsuji_parameters

__all__ = ["NAME", "FORCE_LAW", "SCHEME", "CR_MIN", "parameters", "snippet", "simulate_drop"]

NAME = "liggghts"
FORCE_LAW = (
    "LIGGGHTS (CFDEMproject LIGGGHTS-PUBLIC), normal model hertz, as read in its source (the normal model in "
    "src/normal_model_hertz.h; Yeff and betaeff in src/global_properties.cpp): S_n = 2 Y_eff sqrt(r_eff "
    "delta_n), k_n = (4/3) Y_eff sqrt(r_eff delta_n), beta = ln(e_r) / sqrt(ln(e_r)^2 + pi^2), "
    "gamma_n = -2 sqrt(5/6) beta sqrt(S_n m_eff), F_n = k_n delta_n - gamma_n v_n, 1/Y_eff = (1 - nu1^2)/Y1 + "
    "(1 - nu2^2)/Y2, e_r the coefficientRestitution of the type pair, r_eff the particle's radius on a wall "
    "and m_eff its mass. With limitForce on (off by default) a negative F_n is set to 0: it clamps. The beta "
    "formula gives back e_r only without the clamp, so the exported coefficientRestitution is the exact "
    "inverse of the clamped law. Mapped: coefficientRestitution of the sphere-plate pair; youngsModulus and "
    "poissonsRatio of both types as they are. LIGGGHTS refuses coefficientRestitution <= 0.05, which bounds "
    "the clamped law's e from below at 0.214, and youngsModulus > 1e9 Pa in SI without 'hard_particles yes'.")
#: LIGGGHTS's step: velocity Verlet (fix nve/sphere), the pair force from the half-step velocity.
SCHEME = "velocity_verlet"
#: LIGGGHTS accepts 0.05 < coefficientRestitution <= 1 (its sanity check); a hair above 0.05.
CR_MIN = 0.05 * (1.0 + 1e-9)


def parameters(case) -> dict:
    """The JSON of ``restitution export liggghts`` for ``case`` (an ExportCase): "e",
    "coefficientRestitution" (of the sphere-plate type pair), "youngsModulus" [Pa] and "poissonsRatio" per
    type (1 the sphere, 2 the plate), "E_eff" [Pa] (LIGGGHTS's Y_eff), "t_contact" [s] (LIGGGHTS's Hertz
    contact), "cr_naive_gives" (the e LIGGGHTS returns for coefficientRestitution = e), "R" [m], "m" [kg],
    "v" [m/s], "scheme". UnreachableRestitution where e < 0.214."""
    params = tsuji_parameters(case, CR_MIN, "LIGGGHTS", "coefficientRestitution")
    cr = params.pop("cr")
    return {"e": params.pop("e"), "coefficientRestitution": cr,
            "youngsModulus": [case.E1, case.E2], "poissonsRatio": [case.nu1, case.nu2], **params,
            "scheme": SCHEME}


def snippet(params: dict) -> str:
    """The LIGGGHTS input lines: the pair style, the wall's model and the fix property/global block (atom
    type 1 the sphere, 2 the plate's wall type)."""
    cr = params["coefficientRestitution"]
    return "\n".join([
        f"# restitution export liggghts: e = {params['e']:.6g} at v = {params['v']:.6g} m/s "
        f"(contact {params['t_contact']:.3g} s: keep the timestep below a fiftieth of it)",
        "hard_particles yes",
        "pair_style gran model hertz tangential history limitForce on",
        "pair_coeff * *",
        "fix m1 all property/global youngsModulus peratomtype "
        + " ".join(f"{value:.9g}" for value in params["youngsModulus"]),
        "fix m2 all property/global poissonsRatio peratomtype "
        + " ".join(f"{value:.9g}" for value in params["poissonsRatio"]),
        f"fix m3 all property/global coefficientRestitution peratomtypepair 2 {cr:.9g} {cr:.9g} {cr:.9g} {cr:.9g}",
        "# the plate: fix wall/gran model hertz tangential history limitForce on ... with the plate's atom type 2",
    ])


def simulate_drop(params: dict, case, dt: float | None) -> dict:
    """The drop of ``case``'s sphere at ``case.v`` on LIGGGHTS's published Hertz law with ``params``'s
    coefficientRestitution and moduli (LIGGGHTS is not installed here): dt None finely, else LIGGGHTS's velocity
    Verlet step [s]."""
    (young1, young2), (nu1, nu2) = params["youngsModulus"], params["poissonsRatio"]
    e_eff = effective_modulus(young1, nu1, young2, nu2)  # LIGGGHTS's Y_eff
    result = tsuji_drop(params["coefficientRestitution"], e_eff, params["R"], case.m_sphere, case.v, dt, SCHEME)
    return {"e": result.e, "t_contact": result.t_contact, "law": "published force law, integrated here"}
