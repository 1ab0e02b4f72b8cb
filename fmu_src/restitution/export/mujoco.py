"""MuJoCo: the COR as a contact's ``solref`` and ``solimp``, tuned for the time step the user runs.

MuJoCo's contacts are soft constraints (MuJoCo documentation, Computation, "Soft constraints"): along the
normal the constraint's acceleration obeys a1 + d (b v + k r) = (1 - d) a0, r the signed distance (below
zero in penetration), v its rate, a0 the acceleration without the contact, d = d(abs(r)) the impedance of
``solimp`` and the reference acceleration -b v - k r set by ``solref``: (timeconst, dampratio) gives
b = 2 / (dmax timeconst), k = d(r) / (dmax^2 timeconst^2 dampratio^2). With s = d / dmax and gravity off the
contact is r'' = -s (2 zeta omega) r' - s^2 omega^2 r, omega = 1 / (timeconst dampratio), zeta = dampratio,
whatever the masses. The normal force is unilateral: a contact whose reference acceleration would pull gets
zero force.

Two things decide the e a run gets. The continuous law: with a constant impedance (s = 1) it is the
linear oscillator clamped at zero force, inverted exactly by :mod:`restitution.export.linear_contact`
(:func:`solref_for`, the answer as the step goes to zero). MuJoCo's step: semi-implicit Euler, whose
dashpot switches on at the first step in contact, wherever inside that step the sphere touched (at
t_contact/50 that alone moves e = 0.2 by -4.7 % to +1.4 %), and whose damping is first-order in the step.
The export therefore (i) ramps the impedance in linearly over the penetration the sphere covers in one step
(solimp dmin = 0.0001, dmax = 0.9999, width = v dt, power 1), which interpolates the onset within the step
(the spread over onset phases falls below 0.1 %), and (ii) solves for the damping ratio on MuJoCo's discrete
step (:func:`emulate_drop`, equal to mj_step to 1e-12): the one that centres the errors of every step from
the tuned ``dt`` down to dt/20 on zero (:func:`tuned_solref`), so that the parameters hold at ``dt`` and at
every finer step. omega keeps the contact as long as the model's t_contact.
"""
from __future__ import annotations

import math

from .linear_contact import clamped_damping_ratio, clamped_release, unclamped_damping_ratio

__all__ = ["NAME", "FORCE_LAW", "SOLIMP", "parameters", "snippet", "simulate_drop", "emulate_drop",
           "largest_timestep", "solref_for", "drop_mjcf", "mujoco_drop", "sphere_geom", "STEP_TOLERANCE",
           "impedance", "ramp_solimp", "tuned_solref", "DEFAULT_STEPS", "TUNES_TO_STEP"]

NAME = "mujoco"
FORCE_LAW = (
    "MuJoCo (documentation, Computation > Soft constraints; solref/solimp in the XML reference): the contact "
    "is a soft constraint whose normal acceleration is a1 = (1 - d) a0 + d (-b v - k r), r the signed distance "
    "(negative in penetration), d the impedance from solimp and b, k from solref: (timeconst, dampratio) gives "
    "b = 2/(dmax timeconst), k = d(r)/(dmax^2 timeconst^2 dampratio^2). The normal force is unilateral: it is "
    "clamped at zero, so the sphere leaves when the force, not the penetration, returns to zero. Mapped: solimp "
    "ramps the impedance linearly from 0.0001 to 0.9999 over the penetration of one time step (width = v dt), "
    "past which the contact is a linear spring-damper, omega = 1/(timeconst dampratio), damping ratio = "
    "dampratio; dampratio is solved on MuJoCo's own semi-implicit Euler step so that e holds at the tuned step "
    "and every finer one, and timeconst makes the contact last the model's t_contact. As the step goes to zero "
    "dampratio tends to the exact inverse of the clamped oscillator (solref_continuous).")

#: solimp (dmin, dmax, width [m], midpoint, power) of a constant impedance d = 0.9999, MuJoCo's largest (it
#: clamps d to [0.0001, 0.9999]); the width then plays no part. The continuous law's solimp (solref_for).
SOLIMP = (0.9999, 0.9999, 0.001, 0.5, 2.0)
#: The relative error of e within which :func:`largest_timestep` holds the step [1].
STEP_TOLERANCE = 0.01
#: The step the export is tuned for when the user names none: t_contact / DEFAULT_STEPS.
DEFAULT_STEPS = 50
#: parameters() takes the user's step (the command passes --dt to hosts that set this).
TUNES_TO_STEP = True
#: Steps per contact at which the host's contact counts as resolved (``dt`` None in :func:`simulate_drop`).
FINE_STEPS = 1000
#: The steps per contact :func:`largest_timestep` tries, coarse to fine.
_STEPS_TRIED = (5, 6, 8, 10, 12, 15, 20, 25, 30, 40, 50, 60, 80, 100, 120, 150, 200, 300, 400, 600, 1000)
#: Where in a step the sphere first touches, as fractions of a step (the worst one decides).
_PHASES = tuple(i / 16 for i in range(16))
#: The share of STEP_TOLERANCE the sampled onset phases may use: the worst phase may lie between two samples,
#: but with the ramped impedance e varies by under 0.1 % of e over all phases, so 3 % of the tolerance covers it.
_PHASE_MARGIN = 0.97
#: The tuned step over these: the steps tuned_solref centres the errors of; dt -> 0 joins them, extrapolated
#: from dt/20 and dt/40 (the step's error is first order: e(0) = 2 e(dt/40) - e(dt/20)).
_TUNED_DIVISORS = (1.0, 1.2, 1.4, 1.7, 2.0, 3.0, 4.0, 8.0, 20.0)
#: Onset phases tuned_solref samples at each of those steps (mid-points of eight equal parts).
_TUNING_PHASES = tuple((i + 0.5) / 8 for i in range(8))


def impedance(solimp, penetration: float) -> float:
    """MuJoCo's impedance d [1] at ``penetration`` [m] (MuJoCo documentation, Computation > Soft constraints,
    "solimp"): x = penetration / width clipped to [0, 1], y = x^p / m^(p-1) for x <= m else
    1 - (1 - x)^p / (1 - m)^(p-1) (m the midpoint, p the power), d = dmin + y (dmax - dmin), with dmin and dmax
    clamped to [0.0001, 0.9999] as MuJoCo does."""
    dmin, dmax, width, midpoint, power = solimp
    dmin, dmax = (min(max(x, 1e-4), 0.9999) for x in (dmin, dmax))
    x = penetration / width
    if x >= 1.0:
        return dmax
    if x <= 0.0:
        return dmin
    if x <= midpoint:
        y = x ** power / midpoint ** (power - 1.0)
    else:
        y = 1.0 - (1.0 - x) ** power / (1.0 - midpoint) ** (power - 1.0)
    return dmin + y * (dmax - dmin)


def ramp_solimp(v: float, dt: float) -> tuple[float, float, float, float, float]:
    """solimp [1, 1, m, 1, 1] ramping the impedance linearly from MuJoCo's least (0.0001) to its largest (0.9999)
    over the penetration v dt a sphere approaching at ``v`` [m/s] covers in one step ``dt`` [s]: the first
    step in contact then pushes in proportion to how deep it went, not with the full dashpot."""
    return (0.0001, 0.9999, v * dt, 0.5, 1.0)


def solref_for(e: float, t_contact: float) -> tuple[float, float, float]:
    """(timeconst [s], dampratio [1], omega [1/s]) of the clamped linear contact (constant impedance, the
    continuous law) that gives the COR ``e`` and lasts ``t_contact`` [s]: dampratio = zeta of
    :func:`~.linear_contact.clamped_damping_ratio`, omega = omega t* / t_contact with omega t* the release time
    (:func:`~.linear_contact.clamped_release`), timeconst = 1 / (zeta omega)."""
    zeta = clamped_damping_ratio(e)
    omega = clamped_release(zeta) / t_contact
    return 1.0 / (zeta * omega), zeta, omega


def _solref_of_zeta(zeta: float, t_contact: float) -> list:
    """[timeconst [s], dampratio [1]] of damping ratio ``zeta`` with omega lasting ``t_contact`` [s] as the
    clamped linear contact would."""
    omega = clamped_release(zeta) / t_contact
    return [1.0 / (zeta * omega), zeta]


def _errors(zeta: float, e: float, t_contact: float, v: float, dt: float, finer: bool) -> list:
    """The relative errors of e [1] of :func:`emulate_drop` with damping ratio ``zeta`` and the ramp of ``dt``
    at the step ``dt`` and every onset phase; ``finer``: also at the steps dt / :data:`_TUNED_DIVISORS` and as
    the step goes to zero."""
    trial = {"solref": _solref_of_zeta(zeta, t_contact), "solimp": ramp_solimp(v, dt)}
    divisors = _TUNED_DIVISORS if finer else (1.0,)
    errors = [emulate_drop(trial, v, dt / divisor, phase)[0] / e - 1.0
              for divisor in divisors for phase in (_TUNING_PHASES if divisor < 3.0 else (0.25, 0.75))]
    if finer:
        limit = 2.0 * emulate_drop(trial, v, dt / 40.0)[0] - emulate_drop(trial, v, dt / 20.0)[0]
        errors.append(limit / e - 1.0)
    return errors


def _centred_zeta(e: float, t_contact: float, v: float, dt: float, finer: bool) -> float:
    """The damping ratio [1] whose errors (:func:`_errors`) are centred on zero, by brentq. ValueError where no
    damping ratio within a factor of 8 of the continuous one centres them (a step far too coarse)."""
    from scipy.optimize import brentq

    zeta0 = clamped_damping_ratio(e)
    def midrange(zeta):
        errors = _errors(zeta, e, t_contact, v, dt, finer)
        return 0.5 * (min(errors) + max(errors))

    low, high = 0.5 * zeta0, 2.0 * zeta0
    while midrange(low) < 0.0 and low > zeta0 / 8.0:
        low *= 0.5
    while midrange(high) > 0.0 and high < zeta0 * 8.0:
        high *= 2.0
    if not midrange(low) >= 0.0 >= midrange(high):
        raise ValueError(f"e = {e:.4g} cannot be tuned at dt = {dt:.4g} s ({t_contact / dt:.3g} steps a contact)")
    return brentq(midrange, low, high, xtol=1e-9 * zeta0)


def tuned_solref(e: float, t_contact: float, v: float, dt: float, finer: bool = True) -> list:
    """[timeconst [s], dampratio [1]] for the ramp of :func:`ramp_solimp` at the step ``dt`` [s], on MuJoCo's
    step (:func:`emulate_drop`); omega as in :func:`solref_for`. The damping ratio centres on zero the errors
    of every onset phase at the step dt and, with ``finer``, at the steps down to dt/20 and as the step goes to
    zero (:func:`_errors`)."""
    return _solref_of_zeta(_centred_zeta(e, t_contact, v, dt, finer), t_contact)


def parameters(case, dt: float | None = None) -> dict:
    """The MJCF contract for ``case`` (an :class:`~restitution.export.hosts.ExportCase`) run at the step ``dt``
    [s] (None: t_contact / :data:`DEFAULT_STEPS`): e, t_contact [s], solref [timeconst s, dampratio] and solimp
    (:func:`tuned_solref`, :func:`ramp_solimp`), tuned_dt [s], holds_at_finer_steps, timestep [s] (the largest
    step at which e holds to :data:`STEP_TOLERANCE` wherever the contact begins, at it and every finer step:
    :func:`largest_timestep`; tuned_dt itself where the tuning holds at that step only; NaN where even that
    fails), the continuous law's exact inverse (solref_continuous with solimp_continuous, right as the step
    goes to zero), the same solref in MuJoCo's negative form (solref_direct: -stiffness [1/s^2],
    -damping [1/s], with the ramped solimp), the damping ratio the usual unclamped formula would give
    (dampratio_unclamped), and the sphere's radius [m] and mass [kg] for the geom."""
    step = case.t_contact / DEFAULT_STEPS if dt is None else dt
    params = {"e": case.e, "t_contact": case.t_contact, "solimp": list(ramp_solimp(case.v, step)), "tuned_dt": step,
              "solref_continuous": list(solref_for(case.e, case.t_contact)[:2]), "solimp_continuous": list(SOLIMP),
              "dampratio_unclamped": unclamped_damping_ratio(case.e), "v": case.v,
              "sphere_radius": case.R_sphere, "sphere_mass": case.m_sphere}
    # tuned for the step and every finer one where that holds there (a step too coarse for the contact: the
    # step's first-order error alone exceeds twice the tolerance), else for the step alone
    params.update(solref=tuned_solref(case.e, case.t_contact, case.v, step), holds_at_finer_steps=True)
    params["timestep"] = largest_timestep(params)
    if not params["timestep"] >= step * (1.0 - 1e-12):
        params.update(solref=tuned_solref(case.e, case.t_contact, case.v, step, finer=False),
                      holds_at_finer_steps=False)
        params["timestep"] = step if _holds(params, step) else math.nan
    omega = 1.0 / (params["solref"][0] * params["solref"][1])
    params["solref_direct"] = [-omega * omega, -2.0 * params["solref"][1] * omega]
    return params


def snippet(params: dict) -> str:
    """The MJCF lines: the sphere's geom with the contact's solref and solimp (priority 1, so that they win
    over the plate's whatever its solmix), and the option's timestep: the step the parameters are tuned for."""
    return (f"<!-- e = {params['e']:.6g} at {params['v']:.6g} m/s, contact {params['t_contact']:.4g} s; "
            + _step_note(params) + " -->\n"
            f"<option timestep=\"{params['tuned_dt']:.4g}\"/>\n" + sphere_geom(params, 8))


def _step_note(params: dict) -> str:
    """What the snippet's comment says of the step: the one tuned for, and where e holds."""
    tuned = f"tuned for timestep {params['tuned_dt']:.4g} s"
    if params["holds_at_finer_steps"]:
        return f"{tuned}: holds to {STEP_TOLERANCE:.0%} at every step <= {params['timestep']:.4g} s"
    if params["timestep"] == params["timestep"]:
        return f"{tuned}: holds to {STEP_TOLERANCE:.0%} at that step only (finer steps give a higher e)"
    return f"{tuned}: does NOT hold to {STEP_TOLERANCE:.0%} at that step (too coarse for the contact)"


def sphere_geom(params: dict, digits: int, extra: str = "") -> str:
    """The sphere's ``<geom>`` with params' radius, mass, solref and solimp to ``digits`` digits, priority 1 (its
    solref and solimp win over the plate's whatever its solmix); ``extra``: more attributes."""
    def numbers(values):
        return " ".join(f"{x:.{digits}g}" for x in values)

    return (f"<geom {extra}type=\"sphere\" size=\"{params['sphere_radius']:.{digits}g}\" "
            f"mass=\"{params['sphere_mass']:.{digits}g}\" priority=\"1\" solref=\"{numbers(params['solref'])}\" "
            f"solimp=\"{numbers(params['solimp'])}\"/>")


def _law(params: dict, dt: float) -> tuple[float, float]:
    """(stiffness [1/s^2], damping [1/s]) of the contact's reference acceleration at full impedance (d = dmax),
    per unit penetration and speed, at the step ``dt`` [s]: MuJoCo raises a positive solref's timeconst to
    2 dt (its "refsafe" rule, XML reference, solref), keeping dampratio."""
    timeconst, zeta = params["solref"]
    timeconst = max(timeconst, 2.0 * dt)
    omega = 1.0 / (timeconst * zeta)
    return omega * omega, 2.0 * zeta * omega


def emulate_drop(params: dict, v: float, dt: float, phase: float = 0.5) -> tuple[float, float]:
    """(e, contact time [s]) of MuJoCo's step as its documentation describes it, written here: semi-implicit
    Euler (the speed from the acceleration at the step's start, then the position from the new speed) of a
    sphere reaching the plate at ``v`` [m/s] with gravity off, the contact's acceleration
    -s^2 k r - s b r' (s = d(r)/dmax, :func:`impedance`) while that pushes, zero otherwise. ``phase``: where
    in a step the sphere first touches (0 to 1)."""
    stiffness, damping = _law(params, dt)
    solimp = params["solimp"]
    dmax = impedance(solimp, math.inf)
    gap, speed = v * dt * (1.0 - phase), -v  # above the plate by that much of a step: as drop_mjcf starts
    touched, pushing_steps = False, 0
    for _ in range(1_000_000):
        accel = 0.0
        if gap < 0.0:
            touched = True
            scale = impedance(solimp, -gap) / dmax
            accel = max(-scale * (scale * stiffness * gap + damping * speed), 0.0)  # unilateral: never pulls
            pushing_steps += accel > 0.0
        elif touched:
            return speed / v, pushing_steps * dt
        speed += dt * accel
        gap += dt * speed
    return math.nan, math.inf


def _holds(params: dict, dt: float) -> bool:
    """Whether :func:`emulate_drop` at the step ``dt`` [s] gives e within :data:`STEP_TOLERANCE` (relative) of
    params' e wherever in a step the contact begins (16 onset phases held to 97 % of the tolerance, for the
    phases between them)."""
    return all(abs(emulate_drop(params, params["v"], dt, phase)[0] - params["e"])
               <= _PHASE_MARGIN * STEP_TOLERANCE * params["e"] for phase in _PHASES)


def largest_timestep(params: dict) -> float:
    """The largest step [s] at which :func:`_holds`, at that step and every finer one tried (t_contact / n, n
    from :data:`_STEPS_TRIED`, and params' tuned_dt); NaN where the finest fails."""
    steps = sorted({params["t_contact"] / n for n in _STEPS_TRIED} | ({params["tuned_dt"]} if "tuned_dt" in params
                                                                      else set()), reverse=True)
    finest_failing = min((dt for dt in steps if not _holds(params, dt)), default=math.inf)
    passing = [dt for dt in steps if dt < finest_failing]
    return passing[0] if passing else math.nan


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
