"""MuJoCo: the COR as a contact's ``solref`` and ``solimp``.

MuJoCo's contacts are soft constraints (MuJoCo documentation, Computation, "Soft constraints"): along the
normal the constraint's acceleration obeys a1 + d (b v + k r) = (1 - d) a0, r the signed distance (below
zero in penetration), v its rate, a0 the acceleration without the contact, d the impedance of ``solimp``
and the reference acceleration -b v - k r set by ``solref``: (timeconst, dampratio) gives
b = 2 / (dmax timeconst), k = d(r) / (dmax^2 timeconst^2 dampratio^2); the negative form (-stiffness,
-damping) gives b = damping / dmax, k = stiffness d(r) / dmax^2. The normal force is unilateral: the
solver never lets it pull (a contact whose reference acceleration would pull gets zero force).

With a constant impedance (dmin = dmax = d, :data:`SOLIMP`) and d near 1 the contact is the linear
oscillator r'' + 2 zeta omega r' + omega^2 r = 0 with omega = 1 / (timeconst dampratio) and
zeta = dampratio (the same with the negative form, omega^2 = stiffness, 2 zeta omega = damping), whatever the
masses, and clamped at zero force: :mod:`restitution.export.linear_contact` inverts it exactly. The export
takes zeta from the model's e and omega so that the contact lasts the model's t_contact, both exact in
the host's continuous law; MuJoCo's semi-implicit Euler step then decides how close a run gets
(:func:`largest_timestep`).
"""
from __future__ import annotations

import math

from .linear_contact import clamped_damping_ratio, clamped_release, unclamped_damping_ratio

__all__ = ["NAME", "FORCE_LAW", "SOLIMP", "parameters", "snippet", "simulate_drop", "emulate_drop",
           "largest_timestep", "solref_for", "drop_mjcf", "mujoco_drop", "sphere_geom", "STEP_TOLERANCE"]

NAME = "mujoco"
FORCE_LAW = (
    "MuJoCo (documentation, Computation > Soft constraints; solref/solimp in the XML reference): the contact "
    "is a soft constraint whose normal acceleration is a1 = (1 - d) a0 + d (-b v - k r), r the signed distance "
    "(negative in penetration), d the impedance from solimp and b, k from solref: (timeconst, dampratio) gives "
    "b = 2/(dmax timeconst), k = d(r)/(dmax^2 timeconst^2 dampratio^2). The normal force is unilateral: it is "
    "clamped at zero, so the sphere leaves when the force, not the penetration, returns to zero. Mapped: with "
    "solimp dmin = dmax = 0.9999 (constant impedance, MuJoCo's largest) the contact is a linear spring-damper on "
    "the penetration, omega = 1/(timeconst dampratio), damping ratio = dampratio; dampratio is the exact inverse "
    "of the clamped oscillator for the model's e and timeconst makes the contact last the model's t_contact.")

#: solimp (dmin, dmax, width [m], midpoint, power): a constant impedance d = 0.9999, MuJoCo's largest (it
#: clamps d to [0.0001, 0.9999]); the width then plays no part. The contact leaks (1 - d) = 1e-4 of the
#: free acceleration (gravity), 1e-4 g against the contact's thousands of g.
SOLIMP = (0.9999, 0.9999, 0.001, 0.5, 2.0)
#: The relative error of e within which :func:`largest_timestep` holds the step [1].
STEP_TOLERANCE = 0.01
#: Steps per contact at which the host's contact counts as resolved (``dt`` None in :func:`simulate_drop`).
FINE_STEPS = 1000
#: The steps per contact :func:`largest_timestep` tries, coarse to fine.
_STEPS_TRIED = (5, 6, 8, 10, 12, 15, 20, 25, 30, 40, 50, 60, 80, 100, 120, 150, 200, 300, 400, 600, 1000)
#: Where in a step the sphere first touches, as fractions of a step (the worst one decides).
_PHASES = tuple(i / 16 for i in range(16))
#: The share of STEP_TOLERANCE the sampled onset phases may use: the worst phase may lie between two samples.
_PHASE_MARGIN = 0.9


def solref_for(e: float, t_contact: float) -> tuple[float, float, float]:
    """(timeconst [s], dampratio [1], omega [1/s]) of the clamped linear contact that gives the COR ``e``
    and lasts ``t_contact`` [s]: dampratio = zeta of :func:`~.linear_contact.clamped_damping_ratio`,
    omega = omega t* / t_contact with omega t* the release time (:func:`~.linear_contact.clamped_release`),
    timeconst = 1 / (zeta omega)."""
    zeta = clamped_damping_ratio(e)
    omega = clamped_release(zeta) / t_contact
    return 1.0 / (zeta * omega), zeta, omega


def parameters(case) -> dict:
    """The MJCF contract for ``case`` (an :class:`~restitution.export.hosts.ExportCase`): e, t_contact [s],
    solref [timeconst s, dampratio], solimp (:data:`SOLIMP`), timestep [s] (:func:`largest_timestep`), the
    same solref in MuJoCo's negative form (solref_direct: -stiffness [1/s^2], -damping [1/s]), the damping
    ratio the usual unclamped formula would give (dampratio_unclamped, for comparison), and the sphere's
    radius [m] and mass [kg] for the geom."""
    timeconst, zeta, omega = solref_for(case.e, case.t_contact)
    params = {"e": case.e, "t_contact": case.t_contact, "solref": [timeconst, zeta], "solimp": list(SOLIMP),
              "solref_direct": [-omega * omega, -2.0 * zeta * omega],
              "dampratio_unclamped": unclamped_damping_ratio(case.e), "v": case.v,
              "sphere_radius": case.R_sphere, "sphere_mass": case.m_sphere}
    params["timestep"] = largest_timestep(params)
    return params


def snippet(params: dict) -> str:
    """The MJCF lines: the sphere's geom with the contact's solref and solimp (priority 1, so that they win
    over the plate's whatever its solmix), and the option's timestep."""
    return (f"<!-- e = {params['e']:.6g} at {params['v']:.6g} m/s, contact {params['t_contact']:.4g} s; "
            f"holds to {STEP_TOLERANCE:.0%} at timestep <= {params['timestep']:.3g} s -->\n"
            f"<option timestep=\"{params['timestep']:.3g}\"/>\n" + sphere_geom(params, 8))


def sphere_geom(params: dict, digits: int, extra: str = "") -> str:
    """The sphere's ``<geom>`` with params' radius, mass, solref and solimp to ``digits`` digits, priority 1 (its
    solref and solimp win over the plate's whatever its solmix); ``extra``: more attributes."""
    def numbers(values):
        return " ".join(f"{x:.{digits}g}" for x in values)

    return (f"<geom {extra}type=\"sphere\" size=\"{params['sphere_radius']:.{digits}g}\" "
            f"mass=\"{params['sphere_mass']:.{digits}g}\" priority=\"1\" solref=\"{numbers(params['solref'])}\" "
            f"solimp=\"{numbers(params['solimp'])}\"/>")


def _law(params: dict) -> tuple[float, float]:
    """(stiffness [1/s^2], damping [1/s]) of the contact's reference acceleration, per unit penetration and speed."""
    timeconst, zeta = params["solref"]
    omega = 1.0 / (timeconst * zeta)
    return omega * omega, 2.0 * zeta * omega


def emulate_drop(params: dict, v: float, dt: float, phase: float = 0.5) -> tuple[float, float]:
    """(e, contact time [s]) of MuJoCo's step as its documentation describes it, written here: semi-implicit
    Euler (the speed from the acceleration at the step's start, then the position from the new speed) of a
    sphere reaching the plate at ``v`` [m/s] with gravity off, the contact's acceleration -k r - b r' while
    that pushes, zero otherwise. ``phase``: where in a step the sphere first touches (0 to 1)."""
    stiffness, damping = _law(params)
    gap, speed = v * dt * (1.0 - phase), -v  # above the plate by that much of a step: as drop_mjcf starts
    touched, pushing_steps = False, 0
    for _ in range(100_000):
        accel = 0.0
        if gap < 0.0:
            touched = True
            accel = max(-stiffness * gap - damping * speed, 0.0)  # unilateral: never pulls
            pushing_steps += accel > 0.0
        elif touched:
            return speed / v, pushing_steps * dt
        speed += dt * accel
        gap += dt * speed
    return math.nan, math.inf


def largest_timestep(params: dict) -> float:
    """The largest step [s] at which :func:`emulate_drop` gives e within :data:`STEP_TOLERANCE` (relative)
    of params' e wherever in a step the contact begins (16 onset phases held to 90 % of the tolerance, for
    the phases between them), at that step and every finer one tried
    (t_contact / n, n from :data:`_STEPS_TRIED`)."""
    def holds(n):
        return all(abs(emulate_drop(params, params["v"], params["t_contact"] / n, phase)[0] - params["e"])
                   <= _PHASE_MARGIN * STEP_TOLERANCE * params["e"] for phase in _PHASES)

    finest_failing = max((n for n in _STEPS_TRIED if not holds(n)), default=0)
    passing = [n for n in _STEPS_TRIED if n > finest_failing]
    return params["t_contact"] / passing[0] if passing else math.nan


def drop_mjcf(params: dict, dt: float, phase: float = 0.5) -> str:
    """The MJCF of the verification: the sphere (the snippet's geom) on a vertical slide joint, gravity off,
    starting ``phase`` of a step above the plane (a plane geom), approaching it at the case's speed."""
    z0 = params["sphere_radius"] + params["v"] * dt * (1.0 - phase)
    return (f"<mujoco><option timestep=\"{dt:.17g}\" gravity=\"0 0 0\" integrator=\"Euler\"/>"
            f"<worldbody><geom name=\"plate\" type=\"plane\" size=\"1 1 0.1\" condim=\"1\"/>"
            f"<body name=\"ball\" pos=\"0 0 {z0:.17g}\"><joint name=\"drop\" type=\"slide\" axis=\"0 0 1\"/>"
            + sphere_geom(params, 17, "name=\"ball\" condim=\"1\" ") + "</body></worldbody></mujoco>")


def mujoco_drop(params: dict, dt: float, phase: float = 0.5) -> tuple[float, float]:
    """(e, contact time [s]) of the drop of :func:`drop_mjcf` stepped by MuJoCo itself (mj_step): the speed
    after the sphere has left the plate over the speed it came with; the contact time counts the steps with a
    pushing normal force. ImportError where MuJoCo is not installed (the ``export`` extra)."""
    import mujoco

    model = mujoco.MjModel.from_xml_string(drop_mjcf(params, dt, phase))
    data = mujoco.MjData(model)
    data.qvel[0] = -params["v"]
    touched, pushing_steps = False, 0
    for _ in range(int(50 * params["t_contact"] / dt) + 1000):
        mujoco.mj_step(model, data)
        if data.ncon:
            touched = True
            pushing_steps += int(data.nefc > 0 and data.efc_force[0] > 0.0)
        elif touched and data.qvel[0] > 0.0:
            return data.qvel[0] / params["v"], pushing_steps * dt
    return math.nan, math.inf


def simulate_drop(params: dict, case, dt: float | None) -> dict:
    """The drop in MuJoCo itself where it is installed (the ``export`` extra), else MuJoCo's step as its
    documentation describes it (:func:`emulate_drop`). ``dt`` None: :data:`FINE_STEPS` steps a contact. At a
    given ``dt``, also ``e_range``: the least and the largest e wherever in a step the contact begins."""
    step = params["t_contact"] / FINE_STEPS if dt is None else dt
    try:
        import mujoco  # noqa: F401 - only whether it is there
        drop, law = mujoco_drop, "host itself"
    except ImportError:
        drop, law = (lambda p, h, phase: emulate_drop(p, p["v"], h, phase)), "published force law, integrated here"
    e, t_contact = drop(params, step, 0.5)
    result = {"e": e, "t_contact": t_contact, "law": law}
    if dt is not None:
        spread = [drop(params, step, phase)[0] for phase in _PHASES[::2]] + [e]
        result["e_range"] = [min(spread), max(spread)]
    return result
