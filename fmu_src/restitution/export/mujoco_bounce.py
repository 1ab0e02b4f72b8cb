"""A ball bouncing on a plate in MuJoCo with a COR that depends on the impact speed.

MuJoCo has one ``solref`` per geom, not a COR per impact speed. Between contacts the ball flies freely,
so its approach speed is known before it touches: this loop steps MuJoCo with a coarse step in flight,
switches to the step the contact's parameters are tuned for once the ball is within a few coarse steps of
the plate, sets the geom's solref and solimp for the predicted approach speed (``solref_at(v)``, e.g. the
model's e(v) through :func:`restitution.export.mujoco.parameters`) and measures
each contact's approach and rebound speeds. Needs MuJoCo (the ``export`` extra).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

from .mujoco import SOLIMP, sphere_geom

__all__ = ["Bounces", "bounce_in_mujoco", "solref_from_model", "G"]

#: Standard gravity [m/s^2].
G = 9.80665


@dataclass
class Bounces:
    """Each contact of a run: approach speed [m/s], rebound speed [m/s], the solref used, the step [s]."""

    v_in: list = field(default_factory=list)
    v_out: list = field(default_factory=list)
    solref: list = field(default_factory=list)
    dt: list = field(default_factory=list)

    @property
    def e(self) -> list:
        """The achieved COR of each contact [1]."""
        return [out / v for v, out in zip(self.v_in, self.v_out)]


def _mjcf(radius: float, mass: float, height: float, flight_dt: float) -> str:
    """A plane and the ball on a vertical slide joint, its bottom ``height`` [m] above the plane; the ball's
    solref is MuJoCo's default until :func:`bounce_in_mujoco` sets it before the first contact."""
    ball = {"sphere_radius": radius, "sphere_mass": mass, "solref": (0.02, 1.0), "solimp": SOLIMP}
    return (f"<mujoco><option timestep=\"{flight_dt!r}\" gravity=\"0 0 {-G!r}\" integrator=\"Euler\"/><worldbody>"
            f"<geom name=\"plate\" type=\"plane\" size=\"1 1 0.1\" condim=\"1\"/>"
            f"<body name=\"ball\" pos=\"0 0 {radius + height!r}\"><joint type=\"slide\" axis=\"0 0 1\"/>"
            + sphere_geom(ball, 17, "name=\"ball\" condim=\"1\" ") + "</body></worldbody></mujoco>")


def bounce_in_mujoco(solref_at, radius: float, mass: float, height: float, v_min: float = 0.05,
                     flight_dt: float = 1e-4, max_bounces: int = 30) -> Bounces:
    """The contacts of a ball of ``radius`` [m] and ``mass`` [kg] dropped from ``height`` [m] above a plane in
    MuJoCo until it rebounds slower than ``v_min`` [m/s]. ``solref_at(v)`` -> (solref [timeconst s,
    dampratio], solimp [5 numbers], step [s]): the contact's parameters for an approach speed v [m/s] and the
    step they are tuned for. Flight steps are ``flight_dt`` [s]; within three of them from the plate the step
    becomes the contact's, and solref and solimp are set from
    the approach speed predicted there, sqrt(v^2 + 2 g gap)."""
    import mujoco

    model = mujoco.MjModel.from_xml_string(_mjcf(radius, mass, height, flight_dt))
    data = mujoco.MjData(model)
    ball = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, "ball")
    out, armed, in_contact = Bounces(), False, False
    for _ in range(10_000_000):
        gap, speed = height + data.qpos[0], data.qvel[0]  # the slide joint moves from the start, height above
        if not armed and speed < 0.0 and gap < 3.0 * flight_dt * (abs(speed) + G * flight_dt):
            predicted = math.sqrt(speed * speed + 2.0 * G * max(gap, 0.0))
            solref, solimp, step = solref_at(predicted)
            model.geom_solref[ball] = solref
            model.geom_solimp[ball] = solimp
            model.opt.timestep = step
            armed = True
        mujoco.mj_step(model, data)
        touching = data.ncon > 0
        if touching and not in_contact:
            out.v_in.append(-speed)  # the speed of the step before the contact began
            out.solref.append(tuple(model.geom_solref[ball]))
            out.dt.append(model.opt.timestep)
        if in_contact and not touching:
            out.v_out.append(float(data.qvel[0]))
            armed = False
            model.opt.timestep = flight_dt
            if out.v_out[-1] < v_min or len(out.v_out) >= max_bounces:
                return out
        in_contact = touching
    return out


def solref_from_model(sphere, plate, d: float, t: float, **impact_options):
    """``solref_at(v)`` for :func:`bounce_in_mujoco`: (solref, solimp, the step [s] they are tuned for) of
    ``restitution export mujoco`` (tuned for t_contact/50) for ``sphere`` (a :class:`~restitution.Material`) of
    diameter ``d`` [m] on ``plate`` of thickness ``t`` [m] at the approach speed v [m/s]."""
    from .hosts import export_case
    from .mujoco import parameters

    def solref_at(v: float):
        params = parameters(export_case(v, sphere, plate, d, t, **impact_options))
        return tuple(params["solref"]), tuple(params["solimp"]), params["tuned_dt"]

    return solref_at
