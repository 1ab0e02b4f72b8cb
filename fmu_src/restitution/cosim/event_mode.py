"""FMI 3.0 co-simulation with event mode and early return: the native BouncingBall.fmu (FMI 3.0) coupled
to SpherePlateImpact.fmu through fmpy's ``FMU3Slave``, each contact at its exact instant with the COR
for its exact speed.

BouncingBall declares ``hasEventMode`` and ``mightReturnEarlyFromDoStep``. Instantiated with
``eventModeUsed`` and ``earlyReturnAllowed``, its ``fmi3DoStep`` ends at the first contact inside the
step (found in closed form): ``earlyReturn``, ``lastSuccessfulTime`` = the contact instant,
``eventHandlingNeeded``. The ball waits at the plate; the master (:func:`event_mode_bounce`) then

1. calls ``fmi3EnterEventMode``, reads ``v_approach`` (the contact's speed),
2. asks the impact model for the rebound at that speed (``rebound(v)``: SpherePlateImpact's ``e``),
3. sets the ball's ``e`` and calls ``fmi3UpdateDiscreteStates``, which rebounds the ball (or brings it
   to rest) at the contact instant,
4. calls ``fmi3EnterStepMode`` and steps on from the contact instant to the next communication point.

Initialization ends in event mode too (``eventModeUsed``): ``fmi3UpdateDiscreteStates`` until no
further update is needed, then ``fmi3EnterStepMode``. Neither the contact times nor the COR depend on
the communication step: no contact is late and none uses the COR of an earlier one (the ``wait`` and
``immediate`` contact modes of a master without events do one or the other). docs/hosts.md describes
the calling sequence for other hosts.

:class:`EventModeInstance` is :class:`~restitution.cosim.fmu.FmuInstance` instantiated with the two
flags, whose :meth:`~EventModeInstance.step` returns where the step ended.
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

import numpy as np

from .fmu import FmiStatusError, FmuInstance, _Fmi3

__all__ = ["EventModeInstance", "StepEnd", "EventModeBounces", "event_mode_bounce", "drop_contacts",
           "check_event_ball_fmu", "BALL_AT_CONTACT"]

#: What the master reads from the ball after each event update (its record of the contact).
BALL_AT_CONTACT = ("t_impact", "v_impact", "t_rebound", "v_rebound", "e_applied", "at_rest")


@dataclass(frozen=True)
class StepEnd:
    """Where an ``fmi3DoStep`` ended: ``reached`` [s] (``lastSuccessfulTime``), whether it returned early
    and whether an event waits for the host's event mode (``eventHandlingNeeded``)."""

    reached: float
    early_return: bool
    event_pending: bool


class _Fmi3Events(_Fmi3):
    """FMI 3.0 co-simulation instantiated with ``eventModeUsed`` and ``earlyReturnAllowed`` as asked."""

    def __init__(self, event_mode: bool, early_return: bool):
        self.event_mode = event_mode
        self.early_return = early_return

    def instantiate(self, slave, logging_on: bool, instance):
        plain = slave.instantiate  # fmpy's, which takes the two flags as keywords
        slave.instantiate = functools.partial(plain, eventModeUsed=self.event_mode,
                                              earlyReturnAllowed=self.early_return)
        try:
            _Fmi3.instantiate(slave, logging_on, instance)
        finally:
            del slave.instantiate  # the method of fmpy's class again

    @staticmethod
    def stepper(slave):
        call, (event, terminate, early, last) = _Fmi3.step_call(slave)

        def step(t, h, no_state_before):
            call(t, h, no_state_before)
            if terminate.value:
                raise FmiStatusError(f"fmi3DoStep({t!r}, {h!r}) asked to terminate at {last.value!r} s", 2)
            return StepEnd(last.value, early.value, event.value)
        return step


class EventModeInstance(FmuInstance):
    """An FMI 3.0 co-simulation instance instantiated with ``eventModeUsed = event_mode`` and
    ``earlyReturnAllowed = early_return`` (the FMU must declare ``hasEventMode`` for event mode).

    With event mode, initialization (and every :meth:`reset`) ends in event mode: the instance updates
    its discrete states and enters step mode itself, so that it is in step mode after construction, as
    every FmuInstance is. :meth:`step` returns a :class:`StepEnd`; :meth:`handle_event` runs one event
    (``fmi3EnterEventMode``, what the caller sets there, ``fmi3UpdateDiscreteStates`` until done,
    ``fmi3EnterStepMode``)."""

    def __init__(self, fmu_path, instance_name: str = "instance", event_mode: bool = True,
                 early_return: bool = True, **options):
        self._events = _Fmi3Events(event_mode, early_return)
        super().__init__(fmu_path, instance_name, **options)
        if self.fmi_version != "3.0":
            self.close()
            raise ValueError(f"{fmu_path}: an FMI {self.fmi_version} FMU; event mode and early return are FMI 3.0's")

    def _interface(self):
        if not self.model_description.fmiVersion.startswith("3"):
            return super()._interface()
        cs = self.model_description.coSimulation
        if self._events.event_mode and not cs.hasEventMode:
            raise ValueError(f"{self.path}: {self.model_description.modelName} declares hasEventMode = false")
        return self._events

    def _initialize(self, start_time: float, parameters: dict | None):
        super()._initialize(start_time, parameters)
        if self._events.event_mode:  # initialization ends in event mode
            self._update_discrete_states()
            self._call(self._slave.enterStepMode)

    def _update_discrete_states(self):
        for _ in range(100):  # a model whose update asks for another one (BouncingBall never does)
            need_update, terminate, *_rest = self._call(self._slave.updateDiscreteStates)
            if terminate:
                raise FmiStatusError(f"fmi3UpdateDiscreteStates asked to terminate at t = {self.time!r} s", 2)
            if not need_update:
                return
        raise FmiStatusError("fmi3UpdateDiscreteStates still asks for an update after 100 iterations", 2)

    def step(self, current_time: float, step_size: float) -> StepEnd:
        """One ``fmi3DoStep``; the next step starts where it ended (``StepEnd.reached``)."""
        try:
            end = self._step(current_time, step_size, self._held_states == 0)
        except Exception as exc:  # noqa: BLE001 - fmpy's status exception, with the FMU's last message
            if getattr(exc, "status", None) is None or isinstance(exc, FmiStatusError):
                raise
            raise self._error(exc) from exc
        self.time = end.reached
        return end

    def do_step(self, current_time: float | None = None, step_size: float = 0.0):
        """One step (FmuInstance's interface): where it ended is :attr:`time`."""
        self.step(self.time if current_time is None else current_time, step_size)

    def handle_event(self, during=None):
        """Event mode at :attr:`time`: ``fmi3EnterEventMode``, ``during()`` (get and set values there),
        ``fmi3UpdateDiscreteStates`` until no further update is needed, ``fmi3EnterStepMode``. Returns
        what ``during`` returned."""
        self._call(self._slave.enterEventMode)
        result = during() if during is not None else None
        self._update_discrete_states()
        self._call(self._slave.enterStepMode)
        return result


@dataclass
class EventModeBounces:
    """Every contact of one event-mode co-simulation, as the ball recorded it; arrays by contact."""

    t_impact: np.ndarray  #: contact instants [s] (lastSuccessfulTime of each early return)
    v_impact: np.ndarray  #: approach speeds [m/s] (the ball's v_approach in event mode)
    e_set: np.ndarray  #: the COR the master set for each contact (the impact model's, at that speed) [1]
    e_applied: np.ndarray  #: the COR the ball applied [1]
    v_rebound: np.ndarray  #: rebound speeds [m/s] (0: at rest)
    outputs: list  #: what ``rebound(v)`` returned at each contact
    stop_reason: str  #: "v_min", "e<=0", "max_bounces" or "stop_time"
    steps: int  #: fmi3DoStep calls
    early_returns: int  #: of them, the steps that ended at a contact before the communication point
    step_size: float  #: communication step [s]
    extra: dict = field(default_factory=dict)


def event_mode_bounce(ball: EventModeInstance, rebound, step_size: float, stop_time: float = math.inf,
                      max_bounces: int = 100_000, interrupt=None) -> EventModeBounces:
    """Co-simulate ``ball`` (an :class:`EventModeInstance` of BouncingBall with event mode and early return,
    initialised with its parameters) with the impact model ``rebound(v) -> dict`` (with at least ``"e"``:
    the COR for approach speed ``v`` [m/s], e.g. SpherePlateImpact.fmu's, see
    :func:`~restitution.cosim.bouncing.fmu_rebound`) on a communication grid of ``step_size`` [s] from the
    ball's time until it comes to rest, ``stop_time`` [s] or ``max_bounces`` contacts.

    At each contact (a step that returned early, or ended on the contact, with ``eventHandlingNeeded``)
    the event is handled as the module doc says. ``interrupt``, if given, is checked between FMU calls
    (:class:`~restitution.cosim.interrupt.DeferredInterrupt`)."""
    if not (math.isfinite(step_size) and step_size > 0.0):
        raise ValueError(f"step_size = {step_size!r} s is outside the allowed range: finite and > 0")
    if not stop_time > ball.time:
        raise ValueError(f"stop_time = {stop_time!r} s: must be after the start, {ball.time!r} s")
    speed = ball.reader("v_approach")
    set_e = ball.writer("e")
    record = ball.reader(*BALL_AT_CONTACT)
    start, k = ball.time, 1
    rows, outputs, e_set = [], [], []
    steps = early = 0
    stop = "max_bounces"
    if record()[-1]:  # released on the plate (h0 = 0): at rest from the start, no contact
        stop, max_bounces = "v_min", 0
    while len(rows) < max_bounces:
        t_next = min(start + k * step_size, stop_time)
        if ball.time >= t_next:  # a contact on the grid point itself: on to the next point
            k += 1
            continue
        end = ball.step(ball.time, t_next - ball.time)
        steps += 1
        early += end.early_return
        if not end.early_return:
            k += 1
        if end.event_pending:
            def at_contact():
                (v,) = speed()
                out = rebound(v)
                set_e([out["e"]])
                return out
            outputs.append(ball.handle_event(at_contact))
            e_set.append(outputs[-1]["e"])
            row = record()
            rows.append(row)
            if row[-1]:  # at rest: the ball stays on the plate
                stop = "e<=0" if row[4] <= 0.0 else "v_min"
                break
        elif end.reached >= stop_time:
            stop = "stop_time"
            break
        if interrupt is not None:
            interrupt.check()
    data = np.array([row[:5] for row in rows], dtype=float).reshape(len(rows), 5)
    return EventModeBounces(t_impact=data[:, 0], v_impact=data[:, 1], e_set=np.array(e_set, dtype=float),
                            e_applied=data[:, 4], v_rebound=data[:, 3], outputs=outputs, stop_reason=stop,
                            steps=steps, early_returns=early, step_size=step_size)


def drop_contacts(ball: EventModeInstance, rebound, drop_height: float, gravity: float, v_min: float,
                  step_size: float, max_bounces: int = 100_000, advance=None, interrupt=None):
    """One drop through ``ball`` in event mode, in the form of
    :func:`~restitution.cosim.bouncing.impact_sequence`: ``([(t, v_approach, out), ...], stop_reason)``,
    ``out = rebound(v_approach)`` at each contact (its ``"e"`` is set on the ball there). The ball is reset
    and released from rest at ``drop_height`` [m] at t = 0 under ``gravity`` [m/s2], at rest once it
    would rebound slower than ``v_min`` [m/s]. ``advance(t, dt)``, if given, is called before each contact
    for the flight that ends there (to step the impact FMU across it, as impact_sequence does)."""
    ball.reset(parameters={"h0": drop_height, "g": gravity, "v_min": v_min})
    last = [0.0]

    def at_contact(v):
        if advance is not None:
            advance(last[0], ball.time - last[0])
        last[0] = ball.time
        out = rebound(v)
        if any(math.isnan(x) for x in out.values() if x.__class__ is float):
            values = ", ".join(f"{k} = {x!r}" for k, x in out.items() if x.__class__ is float)
            raise ValueError(f"rebound at v_approach = {v!r} m/s gave {values} (t = {ball.time!r} s): "
                             "the impact model rejected its inputs (see its log)")
        return out

    run = event_mode_bounce(ball, at_contact, step_size, max_bounces=max_bounces, interrupt=interrupt)
    events = list(zip(run.t_impact.tolist(), run.v_impact.tolist(), run.outputs))
    return events, run.stop_reason


def check_event_ball_fmu(path, option: str = "--ball-fmu"):
    """``path`` if it is an FMI 3.0 BouncingBall FMU that offers event mode and early return; else ValueError,
    one line naming ``option`` and the path."""
    from .fmu import read_fmu_description

    path, md = read_fmu_description(path, option)
    cs = md.coSimulation
    if md.modelName != "BouncingBall" or not md.fmiVersion.startswith("3") or cs is None or not cs.hasEventMode \
            or not cs.mightReturnEarlyFromDoStep:
        raise ValueError(f"{option} {path}: not an FMI 3.0 BouncingBall FMU with event mode and early return "
                         f"({md.modelName}, FMI {md.fmiVersion})")
    return path
