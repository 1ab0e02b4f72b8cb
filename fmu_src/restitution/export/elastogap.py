"""The Modelica Standard Library's ``Modelica.Mechanics.Translational.Components.ElastoGap``: a Hertz
spring (n = 1.5) and the damping d that makes ElastoGap's own bounded-damper law return the model's e at the
case's mass and speed (docs/exports_clamped_hosts.md)."""
from __future__ import annotations

from .clamped import UnreachableRestitution, bounce, hertz_constant, hertz_time_unit, solve_decreasing

__all__ = ["NAME", "FORCE_LAW", "SCHEME", "EXPONENT", "parameters", "snippet", "simulate_drop", "elastogap_force"]

NAME = "elastogap"
FORCE_LAW = (
    "Modelica Standard Library, Modelica.Mechanics.Translational.Components.ElastoGap, as read in its source "
    "and documentation (Modelica/Mechanics/Translational/Components/ElastoGap.mo): in contact (s_rel < s_rel0) "
    "f_c = -f_ref |(s_rel - s_rel0)/s_ref|^n with f_ref = c s_ref (s_ref = 1 m by default), f_d2 = d v_rel, "
    "f_d = min(max(f_d2, f_c), -f_c), f = f_c + f_d; no force out of contact. It clamps, and on both sides: the "
    "damper force never exceeds the spring force, so the contact never pulls on the way out and pushes at most "
    "twice the spring force on the way in. Mapped: n = 1.5 and c = (4/3) E' sqrt(R) (Hertz, sphere on a flat "
    "plate), and d by brentq so that this bounded law returns e for the sphere's mass at the case's speed. A "
    "linear damper on a Hertz spring gives a speed-dependent COR (the damping counts less at higher speed): d "
    "holds at the exported speed only; export it per speed over a range.")
#: The fixed-step Euler of Modelica tools (their default, DASSL, is variable-step: dt None).
SCHEME = "explicit_euler"
#: The spring exponent of Hertz's sphere on a flat (ElastoGap's n) [1].
EXPONENT = 1.5


def elastogap_force(x: float, xdot: float, c: float, d: float, n: float) -> float:
    """ElastoGap's contact force [N] pushing the bodies apart at compression ``x`` = s_rel0 - s_rel [m] > 0 and
    its rate ``xdot`` [m/s] (> 0 closing): the spring c x^n (s_ref = 1 m, c in N/m^n) plus the damper d x',
    bounded by the spring force on both sides. ``c`` [N/m^n], ``d`` [N s/m], ``n`` [1]."""
    if x <= 0.0:
        return 0.0
    spring = c * x ** n
    return spring + min(max(d * xdot, -spring), spring)


def _restitution(damping: float) -> float:
    """The COR [1] of ElastoGap with n = 1.5 for unit mass, unit spring and unit speed at damping ``damping``
    [1]: d T / m in the units of any case (T Zener's time unit, :func:`~.clamped.hertz_time_unit`)."""
    return bounce(lambda x, xdot: elastogap_force(x, xdot, 1.0, damping, EXPONENT), 1.0, 1.0, 1.0).e


def parameters(case) -> dict:
    """The JSON of ``restitution export elastogap`` for ``case`` (an ExportCase): "e", "c" [N/m^1.5] (with
    ElastoGap's default s_ref = 1 m), "d" [N s/m], "n" = 1.5, "t_contact" [s] (ElastoGap's contact at that
    speed), "m" [kg] (the sliding mass), "v" [m/s] (d holds at this speed only), "E_eff" [Pa], "R" [m],
    "scheme". Every e in (0, 1] is reachable; UnreachableRestitution for e <= 0."""
    if not case.e > 0.0:
        raise UnreachableRestitution(f"e = {case.e:.4g}: ElastoGap's bounded damper gives an e above 0 only")
    c = hertz_constant(case.E_eff, case.R_sphere)
    time_unit = hertz_time_unit(case.m_sphere, c, case.v)
    scale = case.m_sphere / time_unit  # d = (d T / m) m / T
    damping = solve_decreasing(_restitution, case.e, 0.0, 1.0, "ElastoGap's bounded damper", grow=True)
    d = damping * scale
    drop = bounce(lambda x, xdot: elastogap_force(x, xdot, c, d, EXPONENT), case.m_sphere, case.v, time_unit)
    return {"e": case.e, "c": c, "d": d, "n": EXPONENT, "t_contact": drop.t_contact, "m": case.m_sphere,
            "v": case.v, "E_eff": case.E_eff, "R": case.R_sphere, "scheme": SCHEME}


def snippet(params: dict) -> str:
    """A Modelica modifier for ElastoGap between the sphere's Mass and a Fixed plate (ready to paste)."""
    return "\n".join([
        f"// restitution export elastogap: e = {params['e']:.6g} for a {params['m']:.6g} kg mass at "
        f"{params['v']:.6g} m/s (d holds at this speed only; contact {params['t_contact']:.3g} s)",
        f"Modelica.Mechanics.Translational.Components.ElastoGap elastoGap(c={params['c']:.9g}, "
        f"d={params['d']:.9g}, n={params['n']:g}, s_rel0=0);",
        "// c in N/m^1.5 with the default s_ref = 1 m (f_ref = c*s_ref); connect flange_a to a Fixed plate, "
        "flange_b to the sphere's Mass",
    ])


def simulate_drop(params: dict, case, dt: float | None) -> dict:
    """The drop of ``case``'s sphere at ``case.v`` on ElastoGap's published law with ``params``'s c, d, n (no
    Modelica tool is installed here): dt None finely (a variable-step solver, as DASSL), else the explicit
    Euler step [s] of a fixed-step tool."""
    c, d, n = params["c"], params["d"], params["n"]
    time_unit = hertz_time_unit(case.m_sphere, c, case.v)
    result = bounce(lambda x, xdot: elastogap_force(x, xdot, c, d, n), case.m_sphere, case.v, time_unit, dt, SCHEME)
    return {"e": result.e, "t_contact": result.t_contact, "law": "published force law, integrated here"}
