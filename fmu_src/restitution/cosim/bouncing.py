"""An event-exact bouncing-ball master: a sphere dropped onto a plate, bouncing again and again.

Free flight under gravity is integrated in closed form, each impact instant is located
exactly (the root of h(t) = 0), the impact model is asked for the rebound at that instant,
and flight resumes. Impacts are instantaneous (the contact duration, tens of microseconds,
is reported but not spent): the classic rigid-impact bouncing ball.

Stop rule: the ball is at rest when the rebound speed falls below ``v_min`` (default
0.1 m/s, as the ``v_min`` of the Modelica Reference FMU BouncingBall) or when e <= 0 (the
sphere stays with the plate). With this model e -> 1 as the speed -> 0 (no plasticity
below V_c, lambda ~ v^(1/5)), so the ideal bounce sequence is Zeno-like: the stop rule,
not the physics, ends it. ``max_bounces`` is a last guard (e = 1 exactly, e.g. both effects
off or skipped by ``auto``, bounces forever). ``rest_time`` is the instant of the last impact.

Impact instants are accumulated with compensated (Neumaier) summation, so after thousands
of bounces they are still the correctly rounded sums of the flight times. A rebound
function that returns a non-finite e or v_rebound (e.g. an FMU whose inputs are invalid
reads NaN) stops the drop with ValueError instead of bouncing on NaN.

fmpy's ``simulate_fmu`` has no events in co-simulation (docs/fmi_tools.md), hence this master
on fmpy (through :class:`~restitution.cosim.fmu.FmuInstance`: FMI 2.0 and FMI 3.0 FMUs alike).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..assumptions import warn_departures
from ..flight import flight_to_plate
from ..fmu.models.sphere_plate_impact.variables import TABLE

__all__ = ["Bounces", "Trajectory", "bounce", "impact_sequence", "fmu_rebound", "package_rebound", "RECORDED", "STANDARD_GRAVITY"]

STANDARD_GRAVITY = 9.80665  # [m/s^2]

#: FMU output name -> record field (the output's ImpactResult field), read at every impact: what
#: :class:`Bounces` keeps, and what :func:`restitution.assumptions.departures` reads.
RECORDED = {name: TABLE[name].key
            for name in ("e", "jgm.e", "zener.e", "zener.lambda", "zener.tau0", "zener.t_contact", "v_rebound",
                         "jgm.V_star", "monitor.edge_echo", "zener.in_range", "jgm.in_range", "e_negative",
                         "monitor.edge_clear")}


class Trajectory:
    """The ball's path over one drop, from its impacts: released from rest at ``drop_height`` [m], a
    parabola under ``gravity`` [m/s2] from each impact (``time`` [s]) at the upward speed
    ``v_rebound`` [m/s], at rest on the plate from ``rest_time`` [s] on. The one implementation behind
    both drop results (:class:`Bounces`, and the scene's ``DropResult``)."""

    @property
    def n_impacts(self) -> int:
        return int(self.time.size)

    def _segments(self, t):
        """(t, time since the flight's start, its upward start speed, its start height) at times ``t``."""
        t = np.asarray(t, dtype=float)
        starts = np.concatenate([[0.0], self.time])
        v0 = np.concatenate([[0.0], np.maximum(self.v_rebound, 0.0)])
        h0 = np.concatenate([[self.drop_height], np.zeros(self.time.size)])
        k = np.clip(np.searchsorted(starts, t, side="right") - 1, 0, starts.size - 1)
        return t, t - starts[k], v0[k], h0[k]

    def height(self, t):
        """Height of the ball [m] at times ``t`` [s] (piecewise parabolas between impacts, 0 once at rest)."""
        t, dt, v0, h0 = self._segments(t)
        h = np.where(t >= self.rest_time, 0.0, h0 + v0 * dt - 0.5 * self.gravity * dt * dt)
        return np.maximum(h, 0.0)

    def velocity(self, t):
        """Upward velocity of the ball [m/s] at times ``t`` [s] (0 once at rest)."""
        t, dt, v0, _h0 = self._segments(t)
        return np.where(t >= self.rest_time, 0.0, v0 - self.gravity * dt)

    def energy(self, t):
        """Mechanical energy per unit mass g h + v^2/2 [J/kg] at times ``t`` [s]."""
        v = self.velocity(t)
        return self.gravity * self.height(t) + 0.5 * v * v


@dataclass
class Bounces(Trajectory):
    """Every impact of one drop; arrays are indexed by impact number. Units in brackets."""

    time: np.ndarray  #: impact instants [s]
    v_approach: np.ndarray  #: approach speeds [m/s]
    e: np.ndarray  #: apparent COR [1]
    e_ep: np.ndarray  #: elastoplastic COR [1]
    e_ze: np.ndarray  #: Zener COR [1]
    lam: np.ndarray  #: Zener's lambda [1]
    tau0: np.ndarray  #: dimensionless contact time [1]
    t_contact: np.ndarray  #: contact duration [s]
    v_rebound: np.ndarray  #: rebound speeds [m/s]
    apex: np.ndarray  #: apex height after each impact [m] (0 when the ball stays down)
    rest_time: float  #: when the ball came to rest [s]
    stop_reason: str  #: "v_min", "e<=0", "max_bounces" (or the model-exchange master's "stop_time")
    drop_height: float  #: [m]
    gravity: float  #: [m/s^2]
    extra: dict = field(default_factory=dict)
    v_min: float = math.nan  #: the rebound speed below which the ball was taken to rest [m/s]

    @property
    def why_stopped(self) -> str:
        """Why the drop ended, in words: ``stop_reason`` explained."""
        return {"v_min": f"the rebound speed fell below v_min = {self.v_min:g} m/s",
                "e<=0": "e <= 0: the ball stays on the plate",
                "max_bounces": f"{self.n_impacts} impacts, the most asked for (max_bounces)",
                "stop_time": "the stop time came first"}.get(self.stop_reason, self.stop_reason)


#: The fields :func:`restitution.assumptions.departures` judges an impact by.
_JUDGED = ("e", "lam", "V_star", "edge_echo", "lambda_in_range", "vstar_in_range", "e_negative", "edge_clear")


def package_rebound(**options):
    """Rebound function backed by :func:`restitution.impact` (options as for impact, incl. materials)."""
    from ..model import impact

    keys = tuple(RECORDED.values())

    def rebound(v):
        res = impact(v, **options).__dict__  # the fields (a frozen dataclass has no other attributes)
        return {key: res[key] for key in keys}
    return rebound


def fmu_rebound(instance):
    """Rebound function backed by a SpherePlateImpact :class:`FmuInstance`.

    At each impact: set ``v_approach``, read the outputs (direct feedthrough: valid right
    after the set call, no step needed). The master steps the FMU across each flight, on the FMU's
    own clock (FMI 2.0 steps must follow each other), so a second drop through the same instance
    continues that clock where the first ended; the impact model does not depend on time.
    """
    names = list(RECORDED)
    fields_ = [RECORDED[n] for n in names]
    set_speed = instance.writer("v_approach")
    read = instance.reader(*names)

    def rebound(v):
        set_speed([v])
        return dict(zip(fields_, read()))

    def advance(_t, dt):
        if dt > 0.0:
            instance.do_step(instance.time, dt)

    rebound.advance = advance
    return rebound


def impact_sequence(rebound, drop_height: float, gravity: float = STANDARD_GRAVITY, v_min: float = 0.1,
                    max_bounces: int = 100_000, advance=None):
    """The impacts of one drop: ``([(t, v_approach, out), ...], stop_reason)``.

    Flight is integrated in closed form and each impact located exactly; at each one
    ``out = rebound(v_approach)`` (a mapping with at least ``v_rebound`` [m/s]; its other
    float entries are checked for NaN too, the FMU's sign of rejected input). ``advance(t, dt)``, if given, is called for each
    flight (to step an FMU across it). Stops on e <= 0 (``v_rebound <= 0``), on
    ``v_rebound < v_min`` or after ``max_bounces`` impacts (see the module doc).
    Impact times are summed with Neumaier compensation (10^4 bounces lose no digits).
    """
    if not (math.isfinite(drop_height) and drop_height > 0.0):
        raise ValueError(f"drop_height = {drop_height!r} m is outside the allowed range: finite and > 0")
    if not (math.isfinite(gravity) and gravity > 0.0):
        raise ValueError(f"gravity = {gravity!r} m/s2 is outside the allowed range: finite and > 0")
    if not (math.isfinite(v_min) and v_min > 0.0):
        raise ValueError(f"v_min = {v_min!r} m/s is outside the allowed range: finite and > 0")
    events = []
    t = 0.0
    t_err = 0.0  # Neumaier compensation term of the running sum t
    v_up = 0.0  # upward speed at the last impact (0: released from rest)
    h = drop_height
    for _ in range(max_bounces):
        flight, v_impact = flight_to_plate(h, v_up, gravity)
        if advance is not None:
            advance(t + t_err, flight)
        total = t + flight
        t_err += (t - total) + flight if abs(t) >= abs(flight) else (flight - total) + t
        t = total
        out = rebound(v_impact)
        v_reb = out["v_rebound"]
        if any(math.isnan(x) for x in out.values() if x.__class__ is float):
            values = ", ".join(f"{k} = {x!r}" for k, x in out.items() if x.__class__ is float)
            raise ValueError(f"rebound at v_approach = {v_impact!r} m/s gave {values} "
                             f"(impact {len(events) + 1}, t = {t + t_err!r} s): "
                             "the impact model rejected its inputs (see its log)")
        events.append((t + t_err, v_impact, out))
        if v_reb <= 0.0:
            return events, "e<=0"
        if v_reb < v_min:
            return events, "v_min"
        v_up, h = v_reb, 0.0
    return events, "max_bounces"


def bounce(rebound, drop_height: float, gravity: float = STANDARD_GRAVITY, v_min: float = 0.1,
           max_bounces: int = 100_000) -> Bounces:
    """Drop a ball from ``drop_height`` [m] and bounce it until it rests (see module doc).

    ``rebound(v_approach) -> dict`` gives e, e_ep, e_ze, lam, tau0, t_contact, v_rebound
    for an impact at speed v [m/s]; :func:`fmu_rebound` and :func:`package_rebound` make one.
    Impacts outside the validated domain (lambda > 1.5, V* > 1000, e < 0, an edge echo during the
    contact) raise one :class:`restitution.assumptions.AssumptionWarning` per condition, as the FMUs
    log them, where the rebound function gives the fields to judge by (both of those do).
    """
    events, stop = impact_sequence(rebound, drop_height, gravity, v_min, max_bounces,
                                   getattr(rebound, "advance", None))
    if events and all(key in events[0][2] for key in _JUDGED):
        warn_departures((out for _t, _v, out in events), stacklevel=3)
    rows = []
    for t, v_impact, out in events:
        v_reb = out["v_rebound"]
        apex = v_reb * v_reb / (2.0 * gravity) if v_reb > 0.0 else 0.0
        rows.append((t, v_impact, out["e"], out["e_ep"], out["e_ze"], out["lam"], out["tau0"],
                     out["t_contact"], v_reb, apex))
    cols = np.array(rows, dtype=float).T
    return Bounces(time=cols[0], v_approach=cols[1], e=cols[2], e_ep=cols[3], e_ze=cols[4], lam=cols[5],
                   tau0=cols[6], t_contact=cols[7], v_rebound=cols[8], apex=cols[9], rest_time=float(cols[0][-1]),
                   stop_reason=stop, drop_height=drop_height, gravity=gravity, v_min=v_min)
