"""Fixed-step co-simulation masters for connected FMUs, on fmpy (``FmuInstance``: FMI 2.0 and FMI 3.0
FMUs alike, mixed as they come).

:class:`FixedStepMaster` couples several FMU instances through named connections
``("ball.v_approach", "impact.v_approach")``: every FMU steps over the same communication
step with the inputs of the last communication point (Jacobi stepping); at each
communication point the connections are transferred *in the order given*, so a chain
through a direct-feedthrough FMU (ball -> impact -> ball: the impact FMU's COR is valid
right after its input is set) is resolved at that point, with no extra step of delay.

Two ways to run it:

* ``run(step, stop)``: plain fixed communication step. An event inside a step (the ball
  touching the plate) is seen by the master only at the end of the step.
* ``run(step, stop, event=("ball.impacts", "ball.t_impact"))``: step with state restore.
  Before each step the master saves every FMU's state (fmi2GetFMUstate / fmi3GetFMUState); when the event
  counter output changes during the step, it restores all states, steps exactly to the
  event time the FMU reported, transfers the connections there (so the impact FMU sees the
  true impact speed and the ball gets its COR), and finishes the step. This needs
  ``canGetAndSetFMUstate`` (true for both of this project's FMUs).

:func:`ball_bounces` turns a recorded BouncingBall run into the impacts and rebounds to
compare with the event-exact master (:func:`restitution.cosim.bounce`).
"""
from __future__ import annotations

import time as _time
from dataclasses import dataclass, field

import numpy as np

__all__ = ["CosimResult", "FixedStepMaster", "ball_bounces", "BALL_RECORD", "BALL_IMPACT_CONNECTIONS"]

#: The two connections of the ball + impact co-simulation (source -> target).
BALL_IMPACT_CONNECTIONS = (("ball.v_approach", "impact.v_approach"), ("impact.e", "ball.e"))

#: BouncingBall outputs :func:`ball_bounces` needs, recorded at every communication point.
BALL_RECORD = ("ball.h", "ball.impacts", "ball.t_impact", "ball.v_impact", "ball.t_rebound",
               "ball.v_rebound", "ball.e_applied")


@dataclass
class CosimResult:
    """Values recorded at the communication points of one co-simulation run."""

    time: np.ndarray  #: communication points [s] (including the start and any event points)
    values: dict  #: "instance.variable" -> samples at ``time``
    step_size: float  #: communication step [s]
    wall_time: float  #: seconds spent stepping and exchanging (not loading the FMUs)
    steps: int  #: communication steps accepted (including the partial steps to events)
    rollbacks: int = 0  #: trial steps rejected (state restored) because an event fell inside
    master: str = ""
    extra: dict = field(default_factory=dict)

    def __getitem__(self, name):
        return self.values[name]


def _split(name):
    instance, _, variable = name.partition(".")
    if not variable:
        raise ValueError(f"{name!r} is not of the form 'instance.variable'")
    return instance, variable


class FixedStepMaster:
    """Couple FMU instances (``{name: FmuInstance}``) through ``connections`` (see module doc)."""

    def __init__(self, fmus: dict, connections=BALL_IMPACT_CONNECTIONS):
        self.fmus = dict(fmus)
        self._links = []
        for source, target in connections:
            src_i, src_v = _split(source)
            dst_i, dst_v = _split(target)
            src, dst = self.fmus[src_i], self.fmus[dst_i]
            if src.kind(src_v) != "Real" or dst.kind(dst_v) != "Real":
                raise ValueError(f"connection {source} -> {target}: only Real connections are supported")
            self._links.append((src.reader(src_v), dst.writer(dst_v)))

    # --- helpers --------------------------------------------------------------------------
    def exchange(self):
        """Transfer every connection once, in order."""
        for read, write in self._links:
            write(read())

    def _recorder(self, names):
        """[(reader, names)]: one reader per instance (one FMI call per variable type)."""
        groups = {}  # instance -> (variables, names)
        for name in names:
            inst_name, var = _split(name)
            variables, keys = groups.setdefault(inst_name, ([], []))
            variables.append(var)
            keys.append(name)
        return [(self.fmus[inst_name].reader(*variables), keys) for inst_name, (variables, keys) in groups.items()]

    def _step_all(self, t, dt):
        for inst in self.fmus.values():
            inst.do_step(t, dt)

    # --- the masters ------------------------------------------------------------------------
    def run(self, step_size: float, stop_time: float, record=(), event=None, start_time: float = 0.0,
            stateful=None, max_events_per_step: int = 1000) -> CosimResult:
        """Co-simulate from ``start_time`` to ``stop_time`` with communication step ``step_size`` [s].

        ``record``: "instance.variable" names sampled at every communication point.
        ``event``: ("instance.counter", "instance.event_time"): locate each event by state
        restore (module doc); None: plain fixed step.
        ``stateful``: names of the FMUs whose state is saved and restored (default: all).
        An FMU whose outputs depend only on its current inputs and parameters (such as
        SpherePlateImpact) may be left out to save the cost of its state: it is then
        stepped only once a step is accepted, so it never has to go back in time.
        """
        if not (step_size > 0.0 and stop_time > start_time):
            raise ValueError(f"step_size = {step_size!r} s and stop_time = {stop_time!r} s: need step > 0, stop > start")
        n = int(round((stop_time - start_time) / step_size))
        readers = self._recorder(record)
        rows_t, rows = [], []

        def sample(t):
            rows_t.append(t)
            row = []
            for read, _keys in readers:
                row.extend(read())
            rows.append(row)

        if event is not None:
            cnt_inst, cnt_var = _split(event[0])
            time_inst, time_var = _split(event[1])
            counter = self.fmus[cnt_inst].reader(cnt_var)
            event_time = self.fmus[time_inst].reader(time_var)
            saved = list(self.fmus if stateful is None else stateful)
            if cnt_inst not in saved or time_inst not in saved:
                raise ValueError(f"the event FMU {cnt_inst!r} must be among the stateful FMUs {saved}")
            trial = [self.fmus[name] for name in saved]
            others = [inst for name, inst in self.fmus.items() if name not in saved]
        steps = rollbacks = 0
        self.exchange()
        sample(start_time)
        if event is not None:
            count = counter()[0]
        wall = _time.perf_counter()
        for k in range(n):
            t = start_time + k * step_size
            t_next = start_time + (k + 1) * step_size
            if event is None:
                self._step_all(t, t_next - t)
                steps += 1
            else:
                for _ in range(max_events_per_step):
                    states = [inst.get_state() for inst in trial]
                    for inst in trial:
                        inst.do_step(t, t_next - t)
                    new_count = counter()[0]
                    moved = new_count != count
                    t_event = event_time()[0] if moved else t_next
                    if moved and t < t_event < t_next:
                        for inst, state in zip(trial, states):
                            inst.set_state(state)
                        self._step_all(t, t_event - t)
                        count = counter()[0]
                        steps += 1
                        rollbacks += 1
                        for inst, state in zip(trial, states):
                            inst.free_state(state)
                        self.exchange()
                        sample(t_event)
                        t = t_event
                        continue
                    count = new_count
                    for inst, state in zip(trial, states):
                        inst.free_state(state)
                    for inst in others:  # stepped only once the step is accepted
                        inst.do_step(t, t_next - t)
                    steps += 1
                    break
                else:
                    raise RuntimeError(f"more than {max_events_per_step} events in the step at t = {t} s")
            self.exchange()
            sample(t_next)
        wall = _time.perf_counter() - wall
        data = np.array(rows, dtype=float).reshape(len(rows_t), -1)
        keys = [key for _read, ks in readers for key in ks]
        values = {key: data[:, i] for i, key in enumerate(keys)}
        return CosimResult(time=np.array(rows_t), values=values, step_size=step_size, wall_time=wall,
                           steps=steps, rollbacks=rollbacks,
                           master="fmpy fixed step" if event is None else "fmpy state restore")


def ball_bounces(result: CosimResult, gravity: float, prefix: str = "ball") -> dict:
    """Impacts and rebounds of a recorded BouncingBall run (needs :data:`BALL_RECORD`).

    Returns arrays ``t_impact``, ``v_impact`` (one per contact seen at a communication
    point), ``t_rebound``, ``v_rebound``, ``e_applied``, ``apex`` = v_rebound^2 / 2g (one per
    rebound, at rest included). A contact and its rebound within one step are both seen
    (the outputs hold the last ones); two contacts within one step show as one.
    """
    v = result.values
    impacts = v[f"{prefix}.impacts"]
    new_impact = np.flatnonzero(np.diff(impacts) != 0) + 1
    t_reb = v[f"{prefix}.t_rebound"]
    new_rebound = np.flatnonzero(np.diff(t_reb) != 0) + 1
    v_reb = v[f"{prefix}.v_rebound"][new_rebound]
    return {
        "t_impact": v[f"{prefix}.t_impact"][new_impact],
        "v_impact": v[f"{prefix}.v_impact"][new_impact],
        "t_rebound": t_reb[new_rebound],
        "v_rebound": v_reb,
        "e_applied": v[f"{prefix}.e_applied"][new_rebound],
        "apex": v_reb * v_reb / (2.0 * gravity),
    }
