"""A model-exchange master for the native BouncingBall FMU with e(v) from SpherePlateImpact at each contact.

In model exchange (FMI 2.0 and 3.0, through fmpy's ``FMU2Model`` / ``FMU3Model``) the ball FMU gives the
derivatives of its continuous states (h, v) and one event indicator (``contact_indicator``, the height the
ball reaches before it falls); the master integrates the states, locates each zero crossing of the indicator
(a contact), and at that event does what :func:`restitution.cosim.bounce` does in co-simulation: it reads the
ball's impact speed, asks the impact model for the coefficient of restitution at that speed, and sets the
ball's input ``e`` before the ball's event update (fmi2NewDiscreteStates / fmi3UpdateDiscreteStates), which
rebounds the ball with it (or brings it to rest when e <= 0 or the rebound would be slower than ``v_min``).
The impact model is SpherePlateImpact as an FMU, co-simulation (:func:`restitution.cosim.fmu_rebound`) or
model exchange (:func:`model_exchange_rebound`), or the package (:func:`restitution.cosim.package_rebound`).

The integrator: scipy's explicit Runge-Kutta steppers (``RK45`` by default, ``DOP853`` or ``RK23``) driven
step by step, with the FMU's derivatives as the right-hand side. In free flight der(h) = v, der(v) = -g: a
linear system whose matrix is nilpotent (A^2 = 0), so the exact flow is the quadratic
x + dt f(x) + dt^2/2 A f(x), and every Runge-Kutta step *and* continuous extension of order >= 2 reproduces
it up to rounding. The master stays a general model-exchange master (it knows nothing of the ball's
equations, only its derivatives and indicators) and is exact for this model without an "own exact stepping"
that would have to assume them; the error control then only sets how fast the steps grow.
solve_ivp was not used: it gives no hook to call fmi2CompletedIntegratorStep after each accepted step, and
its event location (brentq on the interpolant) returns a root estimate on either side of the crossing,
whereas the ball's event update takes a contact only when the indicator is <= 0.

Event location: after each accepted step the indicators are evaluated at the step's end; when one changed
sign ((z > 0) differs from the step's start), the crossing is bracketed [a, b] on the step's dense output and
bisected (the indicators evaluated by the FMU at the interpolated states) until b - a <= ``event_tol`` (or
a and b are adjacent doubles, ``event_tol = 0``). The event is placed at b, the first point known to be
past the crossing: the located instant is late by 0 <= t_event - t_true <= event_tol, so the approach speed
read there is high by at most g * event_tol (the ball is falling). Each such error carries into the later
flights: after k contacts the instants are off by at most about k (k + 2) event_tol (the test derives it).

Time events (nextEventTime) and step events (completedIntegratorStep's enterEventMode) are honoured as the
FMI state machine asks; BouncingBall has neither.
"""
from __future__ import annotations

import math
import time as _time

import numpy as np

from .bouncing import _JUDGED, STANDARD_GRAVITY, Bounces, fmu_rebound
from .fmu import FmiStatusError, FmuInstance, _Fmi2, _Fmi3

__all__ = ["ModelExchangeInstance", "model_exchange_rebound", "bounce_model_exchange", "BALL_OUTPUTS", "METHODS"]

#: BouncingBall outputs read after every contact event (the ball's own record of the contact).
BALL_OUTPUTS = ("impacts", "t_impact", "v_impact", "t_rebound", "v_rebound", "e_applied", "at_rest")
#: The ball's variables this master needs (besides BALL_OUTPUTS).
_BALL_NEEDS = ("h0", "g", "v_min", "e", "h", "v") + BALL_OUTPUTS
#: The Runge-Kutta steppers of scipy.integrate the master can drive (all of order >= 2: exact in free flight).
METHODS = ("RK45", "DOP853", "RK23")
#: The largest drop height and gravity the ball accepts (its declared maximum) and the least v_min.
_MAX_HEIGHT_OR_GRAVITY, _MIN_GRAVITY, _MIN_REST_SPEED = 1e6, 1e-6, 1e-6


def _no_step(slave):
    def step(t, h, no_state_before):
        raise FmiStatusError("a model-exchange instance has no doStep: the master integrates its states", 3)
    return step


class _MeFmi2(_Fmi2):
    """FMI 2.0 model exchange through ``fmpy.fmi2.FMU2Model``."""

    interface = "ModelExchange"
    derivatives = "getDerivatives"
    stepper = staticmethod(_no_step)

    @staticmethod
    def slave(md, unzip_dir, name):
        from fmpy.fmi2 import FMU2Model
        return FMU2Model(guid=md.guid, unzipDirectory=unzip_dir, modelIdentifier=md.modelExchange.modelIdentifier,
                         instanceName=name)

    @staticmethod
    def update_discrete_states(slave):
        """(newDiscreteStatesNeeded, terminateSimulation, nominalsChanged, valuesChanged, nextEventTimeDefined,
        nextEventTime), as fmpy returns them for both versions."""
        return slave.newDiscreteStates()


class _MeFmi3(_Fmi3):
    """FMI 3.0 model exchange through ``fmpy.fmi3.FMU3Model``."""

    interface = "ModelExchange"
    derivatives = "getContinuousStateDerivatives"
    stepper = staticmethod(_no_step)

    @staticmethod
    def slave(md, unzip_dir, name):
        from fmpy.fmi3 import FMU3Model
        return FMU3Model(guid=md.instantiationToken, unzipDirectory=unzip_dir,
                         modelIdentifier=md.modelExchange.modelIdentifier, instanceName=name)

    @staticmethod
    def update_discrete_states(slave):
        return slave.updateDiscreteStates()


class ModelExchangeInstance(FmuInstance):
    """One model-exchange instance of an FMI 2.0 or FMI 3.0 FMU, variables by name (as :class:`FmuInstance`:
    :meth:`get`, :meth:`set`, :meth:`reader`, :meth:`writer`, FMU states), plus the model-exchange calls.

    After construction (and after :meth:`reset`) the instance has done its initial event iteration and is
    in continuous-time mode; :attr:`next_event_time` is the FMU's next time event (None: none).
    ValueError (one line) when the FMU has no model-exchange interface (the pythonfmu FMUs).
    """

    def _interface(self):
        md = self.model_description
        if md.modelExchange is None:
            raise ValueError(f"{self.path}: {md.modelName} has no model-exchange interface (the pythonfmu FMUs are "
                             "co-simulation only; use a native one: DIR/fmi2 or DIR/fmi3)")
        return _MeFmi3 if md.fmiVersion.startswith("3") else _MeFmi2

    def _initialize(self, start_time: float, parameters: dict | None):
        md = self.model_description
        self.n_states = len(md.derivatives)
        self.n_indicators = int(md.numberOfEventIndicators or 0)
        self._x, self._dx = np.zeros(self.n_states), np.zeros(self.n_states)
        self._z = np.zeros(self.n_indicators)
        self._px, self._pdx, self._pz = (np.ctypeslib.as_ctypes(a) if a.size else None
                                         for a in (self._x, self._dx, self._z))
        slave = self._slave
        self._set_time, self._set_states = slave.setTime, slave.setContinuousStates
        self._get_states, self._get_derivatives = slave.getContinuousStates, getattr(slave, self._fmi.derivatives)
        self._get_indicators = slave.getEventIndicators
        self.next_event_time = None
        super()._initialize(start_time, parameters)  # ends in event mode (exitInitializationMode)
        self.update_discrete_states()
        self.enter_continuous_time_mode()

    # --- continuous-time mode ---------------------------------------------------------------
    def set_time(self, t: float):
        self._call(self._set_time, t)
        self.time = t

    def set_states(self, x):
        if self.n_states:
            self._x[:] = x
            self._call(self._set_states, self._px, self.n_states)

    def get_states(self) -> np.ndarray:
        if self.n_states:
            self._call(self._get_states, self._px, self.n_states)
        return self._x.copy()

    def derivatives(self) -> np.ndarray:
        if self.n_states:
            self._call(self._get_derivatives, self._pdx, self.n_states)
        return self._dx.copy()

    def indicators(self) -> np.ndarray:
        if self.n_indicators:
            self._call(self._get_indicators, self._pz, self.n_indicators)
        return self._z.copy()

    def completed_integrator_step(self) -> tuple[bool, bool]:
        """(enterEventMode, terminateSimulation) after an accepted integrator step."""
        enter, terminate = self._call(self._slave.completedIntegratorStep, True)
        return bool(enter), bool(terminate)

    # --- event mode ---------------------------------------------------------------------------
    def enter_event_mode(self):
        self._call(self._slave.enterEventMode)

    def update_discrete_states(self, max_iterations: int = 100) -> dict:
        """The event iteration: the FMU's discrete update until it needs no more. Returns
        ``{"states_changed", "terminate", "next_event_time"}`` (the latter also in :attr:`next_event_time`)."""
        changed = terminate = False
        for _ in range(max_iterations):
            needed, stop, _nominals, values, defined, t_next = self._call(self._fmi.update_discrete_states, self._slave)
            changed |= bool(values)
            terminate |= bool(stop)
            self.next_event_time = float(t_next) if defined else None
            if not needed or stop:
                return {"states_changed": changed, "terminate": terminate, "next_event_time": self.next_event_time}
        raise RuntimeError(f"{self.model_description.modelName}: the event iteration at t = {self.time!r} s did not "
                           f"settle in {max_iterations} updates")

    def enter_continuous_time_mode(self):
        self._call(self._slave.enterContinuousTimeMode)


def model_exchange_rebound(instance: ModelExchangeInstance):
    """Rebound function backed by SpherePlateImpact in model exchange (a :class:`ModelExchangeInstance`).

    The FMU has no continuous states and no event indicators, and its outputs are direct feedthrough: at
    each impact the master sets ``v_approach`` and reads the outputs (the fields of
    :func:`restitution.cosim.fmu_rebound`); ``advance(t, dt)`` moves the FMU's time to ``t + dt``.
    """
    if instance.n_states or instance.n_indicators:
        raise ValueError(f"{instance.path}: {instance.model_description.modelName} has {instance.n_states} "
                         f"continuous states and {instance.n_indicators} event indicators; the impact model "
                         "at a contact must be a function of its inputs (SpherePlateImpact)")
    rebound = fmu_rebound(instance)

    def advance(t, dt):
        if t + dt > instance.time:
            instance.set_time(t + dt)

    rebound.advance = advance
    return rebound


def _check(name, value, unit, ok, allowed):
    if not (isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value) and ok(value)):
        raise ValueError(f"{name} = {value!r}{unit} is outside the allowed range: {allowed}")


def _check_inputs(drop_height, gravity, v_min, stop_time, max_bounces, event_tol, method, rtol, atol):
    _check("drop_height", drop_height, " m", lambda x: 0.0 < x <= _MAX_HEIGHT_OR_GRAVITY, "finite, 0 < h <= 1e6")
    _check("gravity", gravity, " m/s2", lambda x: _MIN_GRAVITY <= x <= _MAX_HEIGHT_OR_GRAVITY,
           "finite, 1e-6 <= g <= 1e6")
    _check("v_min", v_min, " m/s", lambda x: x >= _MIN_REST_SPEED, "finite, >= 1e-6")
    if stop_time is not None:
        _check("stop_time", stop_time, " s", lambda x: x > 0.0, "finite and > 0 (or None: until the ball rests)")
    if isinstance(max_bounces, bool) or not isinstance(max_bounces, int) or max_bounces < 1:
        raise ValueError(f"max_bounces = {max_bounces!r} is outside the allowed range: an integer >= 1")
    _check("event_tol", event_tol, " s", lambda x: x >= 0.0, "finite and >= 0 (0: to adjacent doubles)")
    _check("rtol", rtol, "", lambda x: x > 0.0, "finite and > 0")
    _check("atol", atol, "", lambda x: x > 0.0, "finite and > 0")
    if method not in METHODS:
        raise ValueError(f"method = {method!r} is not one of {', '.join(METHODS)}")


def bounce_model_exchange(ball, rebound, drop_height: float, gravity: float = STANDARD_GRAVITY,
                          v_min: float = 0.1, stop_time: float | None = None, max_bounces: int = 100_000,
                          event_tol: float = 1e-12, method: str = "RK45", rtol: float = 1e-10,
                          atol: float = 1e-12) -> Bounces:
    """Drop the BouncingBall FMU from ``drop_height`` [m] in model exchange, with ``e`` from ``rebound`` at each
    contact (see the module doc), until it rests (or ``stop_time`` [s], or ``max_bounces`` contacts).

    ``ball``: the path of a native BouncingBall FMU (FMI 2.0 or 3.0; it is instantiated and freed here) or a
    :class:`ModelExchangeInstance` of one (reset here with h0, g, v_min). ``rebound(v_approach) -> dict``
    as for :func:`restitution.cosim.bounce` (:func:`model_exchange_rebound`,
    :func:`restitution.cosim.fmu_rebound`, :func:`restitution.cosim.package_rebound`).
    ``event_tol`` [s]: the bracket width to which each contact is located (0: adjacent doubles);
    ``method``, ``rtol``, ``atol``: the scipy Runge-Kutta stepper and its tolerances.

    Returns :class:`restitution.cosim.Bounces`, as the co-simulation master does: one row per contact with
    the located instant, the impact speed given to the impact model, its outputs, and ``v_rebound`` = e v
    (as the impact model gives it; the ball's own record, 0 where it came to rest, is in ``extra["ball"]``).
    ``stop_reason``: "v_min", "e<=0", "max_bounces" or "stop_time" (then ``rest_time`` is inf).
    ``extra``: "ball" (BALL_OUTPUTS after each contact), "points" (t, h, v at every accepted point), the
    counts "steps", "rhs_calls", "indicator_calls", "events", "fmi_version", "method", "event_tol",
    "wall_time" [s]. Bad input: ValueError, one line.
    """
    from scipy import integrate

    _check_inputs(drop_height, gravity, v_min, stop_time, max_bounces, event_tol, method, rtol, atol)
    parameters = {"h0": float(drop_height), "g": float(gravity), "v_min": float(v_min)}
    own = not isinstance(ball, ModelExchangeInstance)
    inst = ModelExchangeInstance(ball, instance_name="ball") if own else ball
    try:
        missing = [name for name in _BALL_NEEDS if name not in inst.variables]
        if missing or inst.n_states < 1 or inst.n_indicators < 1:
            raise ValueError(f"{inst.path}: not a BouncingBall FMU ({inst.model_description.modelName}: "
                             f"{'no variable(s) ' + ', '.join(missing) if missing else 'no states or indicators'})")
        inst.reset(parameters)  # (checked first: the parameters of another FMU are no variables of it)
        return _run(inst, rebound, getattr(integrate, method), stop_time, max_bounces, event_tol, rtol, atol,
                    drop_height, gravity, method, float(v_min))
    finally:
        if own:
            inst.close()


def _run(inst, rebound, stepper, stop_time, max_bounces, event_tol, rtol, atol, drop_height, gravity, method,
         v_min):
    counts = {"steps": 0, "rhs_calls": 0, "indicator_calls": 0, "events": 0}
    set_e = inst.writer("e")
    read_v = inst.reader("v")
    read_ball = inst.reader(*BALL_OUTPUTS)
    advance = getattr(rebound, "advance", None)

    def rhs(t, x):
        counts["rhs_calls"] += 1
        inst.set_time(t)
        inst.set_states(x)
        return inst.derivatives()

    def indicators_at(t, x):
        counts["indicator_calls"] += 1
        inst.set_time(t)
        inst.set_states(x)
        return inst.indicators()

    def crossed(z0, z1):
        return bool(np.any((z1 > 0.0) != (z0 > 0.0)))

    def locate(dense, a, b, x_b, z_a):
        """The first point known past the crossing in (a, b], to within event_tol: (t, x)."""
        while b - a > event_tol:
            m = a + 0.5 * (b - a)
            if not a < m < b:
                break
            x_m = dense(m)
            if crossed(z_a, indicators_at(m, x_m)):
                b, x_b = m, x_m
            else:
                a = m
        return b, x_b

    wall = _time.perf_counter()
    horizon = math.inf if stop_time is None else float(stop_time)
    t, x = inst.time, inst.get_states()
    z = inst.indicators()
    rows, ball_rows = [], []
    points = [(t, *x[:2])]
    last_contact = t
    stop = "stop_time"
    while t < horizon:
        t_end = min(horizon, inst.next_event_time if inst.next_event_time is not None else math.inf)
        solver = stepper(rhs, t, x, t_end, rtol=rtol, atol=atol)
        event = contact = False
        while solver.status == "running":
            solver.step()
            if solver.status == "failed":
                raise RuntimeError(f"{method} failed at t = {solver.t!r} s")
            counts["steps"] += 1
            t_new, x_new = solver.t, solver.y.copy()
            z_new = indicators_at(t_new, x_new)
            if crossed(z, z_new):
                t_new, x_new = locate(solver.dense_output(), solver.t_old, t_new, x_new, z)
                inst.set_time(t_new)
                inst.set_states(x_new)
                event = contact = True
            z = z_new
            enter, terminate = inst.completed_integrator_step()
            t, x = t_new, x_new
            points.append((t, *x[:2]))
            if terminate:
                horizon = t
                break
            event |= enter or (inst.next_event_time is not None and t >= inst.next_event_time)
            if event:
                break
        else:
            event = inst.next_event_time is not None and t >= inst.next_event_time
        if not event:
            continue  # the horizon is reached (the loop ends) or the FMU asked to terminate
        counts["events"] += 1
        inst.enter_event_mode()
        if contact:  # the coupling: e at this impact speed, on the ball's input before its event update
            v_impact = abs(read_v()[0])  # the speed the ball's event update takes (|v| at the plate)
            if advance is not None:
                advance(last_contact, t - last_contact)
            out = rebound(v_impact)
            bad = {k: x_ for k, x_ in out.items() if x_.__class__ is float and math.isnan(x_)}
            if bad:
                values = ", ".join(f"{k} = {x_!r}" for k, x_ in out.items() if x_.__class__ is float)
                raise ValueError(f"rebound at v_approach = {v_impact!r} m/s gave {values} (impact {len(rows) + 1}, "
                                 f"t = {t!r} s): the impact model rejected its inputs (see its log)")
            set_e([min(max(out["e"], -1.0), 1.0)])  # the ball's declared range; e <= 0 brings it to rest anyway
            count_before = read_ball()[0]
        update = inst.update_discrete_states()
        inst.enter_continuous_time_mode()
        x, z = inst.get_states(), inst.indicators()
        points.append((t, *x[:2]))
        if update["terminate"]:
            break
        if contact:
            ball_row = read_ball()
            if ball_row[0] == count_before:
                continue  # the ball took no contact here (a crossing it did not count as one)
            rows.append((t, v_impact, out))
            ball_rows.append(ball_row)
            last_contact = t
            if ball_row[-1]:  # at rest
                stop = "e<=0" if ball_row[5] <= 0.0 else "v_min"
                if stop_time is None:
                    break
            elif len(rows) >= max_bounces:
                stop = "max_bounces"
                break
    if rows and all(key in rows[0][2] for key in _JUDGED):
        from ..assumptions import warn_departures
        warn_departures((out for _t, _v, out in rows), stacklevel=3)
    table = np.array([(t_, v_, o["e"], o.get("e_ep", np.nan), o.get("e_ze", np.nan), o.get("lam", np.nan),
                       o.get("tau0", np.nan), o.get("t_contact", np.nan), o["v_rebound"]) for t_, v_, o in rows],
                     dtype=float).reshape(len(rows), 9).T
    v_reb = table[8]
    apex = np.where(v_reb > 0.0, v_reb * v_reb / (2.0 * gravity), 0.0)
    ball = np.array(ball_rows, dtype=float).reshape(len(ball_rows), len(BALL_OUTPUTS)).T
    pts = np.array(points, dtype=float).T
    extra = {"ball": {name: ball[i] for i, name in enumerate(BALL_OUTPUTS)},
             "points": {"t": pts[0], "h": pts[1], "v": pts[2]}, **counts, "fmi_version": inst.fmi_version,
             "method": method, "event_tol": event_tol, "wall_time": _time.perf_counter() - wall}
    rest = float(table[0][-1]) if rows and stop != "stop_time" else math.inf
    return Bounces(time=table[0], v_approach=table[1], e=table[2], e_ep=table[3], e_ze=table[4], lam=table[5],
                   tau0=table[6], t_contact=table[7], v_rebound=v_reb, apex=apex, rest_time=rest, stop_reason=stop,
                   drop_height=drop_height, gravity=gravity, extra=extra, v_min=v_min)
