"""BouncingBall: a ball in free flight above a plate, as an FMI 2.0 co-simulation slave.

The ball's side of a two-FMU co-simulation with ``SpherePlateImpact.fmu``: this FMU holds
the free flight under gravity and finds each contact with the plate *inside* ``do_step``
(the root of the flight parabola h(t) = 0, in closed form); the impact FMU supplies the
coefficient of restitution. Connections:

    BouncingBall.v_approach  ->  SpherePlateImpact.v_approach
    SpherePlateImpact.e      ->  BouncingBall.e

A co-simulation master exchanges values only at communication points, so the ball cannot
ask for the COR of an impact that happens inside a step. ``contact_mode`` says what it does:

* 1 = ``wait`` (default): at contact the ball stops at the plate (h = 0), keeps its
  approach velocity and reports it as ``v_approach``; at the start of the next step it
  rebounds with the COR then on its input ``e``, which a master that resolves the direct
  feedthrough of the impact FMU has computed for exactly that approach speed. The COR is
  right; the rebound is late by the rest of the step (< one communication step).
* 2 = ``immediate``: the ball rebounds at the contact instant with the COR held on its
  input since the last communication point, i.e. the COR for the speed the ball had then,
  not its impact speed. The timing is right; the COR is off by O(step).

The flight is kept as a parabola from its start (``flight.*``), so the position at any
time is closed-form and independent of the step size: every error in a co-simulation of
this FMU comes from the coupling, none from integrating the flight.

The ball rests when the rebound speed would fall below ``v_min`` or e <= 0 (as the
event-exact master ``restitution.cosim.bounce``). Impacts are instantaneous (the contact
duration, tens of microseconds, is not spent), as in that master.

Every ``do_step`` takes a bounded time, whatever the step and the parameters: in ``immediate``
mode the bounces after the first rebound of a step all start at the plate with the same COR, so
their impact times and speeds form a geometric series, and the step jumps to the last impact
inside it in closed form (:func:`constant_e_bounces`) instead of visiting each one (with e = 1 and a
flight shorter than the clock's resolution there would be no end to them). ``impacts`` saturates
at ``MAX_IMPACTS``.

State: every quantity the ball evolves is a registered variable (outputs and the local
``flight.*``); the FMU state is every registered variable, tagged with the model, the state
format and the variable list, and validated (parameters and input as the setters would, the
rest numbers) before anything is restored. Bad input never raises: a value outside its range is
refused, the previous value kept, and the refusal logged with fmi2Error (in the built FMU the C
guard refuses it first and returns fmi2Error). The module has a unique name (two pythonfmu FMUs
whose scripts share a module name clash in one process). Which ``restitution`` it runs, and which
class pythonfmu instantiates, is decided at start-up (restitution_slave_support.py): the FMU's own
code, or a copy verified to be the same, whatever the host and other FMUs loaded before and whether
their folders still exist.
"""
from __future__ import annotations

import hashlib
import importlib.util
import math
import os
import sys

from pythonfmu import Boolean, Fmi2Causality, Fmi2Slave, Fmi2Variability, Integer, Real
from pythonfmu.enums import Fmi2Initial

# Start-up: which code this instance runs (restitution_slave_support.py says what and why). pythonfmu
# executes this script twice at each fmi2Instantiate: as an import (only the first time in a process),
# then with the cached module's globals, whose __file__ may be another FMU's, and this FMU's resources/
# first on sys.path. Up to settle() at the end, straight-line code only (a function defined here would
# read the cached module's globals) that cannot raise at the second execution (pythonfmu would crash).
_here = os.path.dirname(os.path.abspath(__file__)) if globals() is locals() else sys.path[0]
_resources = _here if os.path.isfile(os.path.join(_here, "slavemodule.txt")) else None  # None: not in an FMU
if _resources is not None:  # the support module this FMU ships, unless the one loaded has the same source
    _path = os.path.join(_resources, "restitution_slave_support.py")
    with open(_path, "rb") as _file:
        _source = hashlib.sha256(_file.read()).hexdigest()
    if getattr(sys.modules.get("restitution_slave_support"), "SOURCE_SHA256", None) != _source:
        _spec = importlib.util.spec_from_file_location("restitution_slave_support", _path)
        _support = importlib.util.module_from_spec(_spec)
        _spec.loader.exec_module(_support)
        sys.modules[_spec.name] = _support
import restitution_slave_support as _support  # noqa: E402 (the one just loaded, or the importable one)
from restitution_slave_support import (checked_setter, restore_state, state_check,  # noqa: E402
                                       state_from_bytes, state_schema, state_to_bytes)

# the package this instance runs: the one the FMU ships, or a copy of the same code
_restitution = _support.start(globals(), locals(), "BouncingBall", _resources)
TABLE = _support.submodule(_restitution, "fmu.models.bouncing_ball.variables").TABLE
#: the package's free flight under gravity (restitution.flight), shared with the host tools
flight_to_plate = _support.submodule(_restitution, "flight").flight_to_plate

#: A contact found within this time [s] after the end of a step still belongs to the step:
#: a master that steps exactly to a reported contact time (t_impact) must see the contact
#: although (t + (t_impact - t)) may differ from t_impact by an ulp.
TIME_TOLERANCE = 1e-12

#: The count of impacts saturates here: the largest fmi2Integer (a ball whose flights are shorter
#: than the clock's resolution can bounce more often in one step than an Integer counts).
MAX_IMPACTS = 2**31 - 1
#: The largest number of bounces one step jumps over (a float; where flights are too short for the
#: clock to tell apart, the count is only a bound anyway).
MAX_TRAIN = 1e18

def constant_e_bounces(t0, u, e, g, v_min, limit):
    """The bounces of a ball that leaves the plate at t0 [s] with upward speed u > 0 [m/s] and
    rebounds every time with the same COR 0 < e <= 1 under gravity g [m/s2], until it would rebound
    slower than v_min [m/s]: (n, T_n [s], w_n [m/s]), the number of its impacts at or before `limit`
    [s] and the time and approach speed of the last of them (n = 0: none).

    Flight j = 1, 2, ... starts at the plate with speed u e^(j-1) and lasts 2 u e^(j-1)/g, so impact j
    is at T_j = t0 + (2u/g) S_j, S_j = (1 - e^j)/(1 - e) (j for e = 1; -expm1(j ln e)/(1 - e), no
    cancellation for e near 1), with speed w_j = u e^(j-1); the ball comes to rest at the first impact
    with e w_j < v_min. n comes from inverting T_j and is then checked against T_j and w_j as written,
    a few steps either way, so it counts the impacts a one-by-one loop would count wherever the clock
    resolves them, in bounded time where it does not. n <= MAX_TRAIN."""
    c = 2.0 * u / g

    def time(j):
        return t0 + c * (j if e == 1.0 else -math.expm1(j * math.log(e)) / (1.0 - e))

    def speed(j):
        return u * e ** (j - 1.0)

    rest = MAX_TRAIN  # the impact at which the ball comes to rest (at most)
    if e < 1.0:
        rest = min(max(math.floor((math.log(v_min) - math.log(u)) / math.log(e)) + 1.0, 1.0), MAX_TRAIN)
        for _ in range(4):
            if rest > 1.0 and e * speed(rest - 1.0) < v_min:
                rest -= 1.0
        for _ in range(4):
            if rest < MAX_TRAIN and not e * speed(rest) < v_min:
                rest += 1.0
    x = (limit - t0) / c if c > 0.0 else math.inf  # the time to `limit` in flights of the first
    if e == 1.0:
        n = x
    else:
        y = x * (1.0 - e)
        n = math.log1p(-y) / math.log(e) if y < 1.0 else math.inf
    n = float(math.floor(min(max(n, 0.0), rest)))
    for _ in range(4):
        if n > 0.0 and time(n) > limit:
            n -= 1.0
    for _ in range(4):
        if n < rest and time(n + 1.0) <= limit:
            n += 1.0
    return n, time(n), speed(n)


def contact_indicator(h, v, g):
    """The model-exchange event indicator in flight [m]: the height h + max(v, 0)^2/(2 g) the ball
    reaches before it falls (h [m], v [m/s] upward, g [m/s2]). It equals h while the ball falls, so
    its crossing to <= 0 is the contact; while the ball rises it stays at the apex height, which right
    after a rebound is v^2/(2 g) > 0: the ball is then strictly in flight, never at the indicator's
    zero (a host that compares each indicator with its value after the last event sees every contact).

    Evaluated as written wherever that is finite. Departure, for states a host may set (any finite h
    and v): where v * v or the sum overflows, the apex term is v'^2 with v' = v / sqrt(2 g) (no overflow
    for the speeds whose term is finite: sqrt(2 g) >= 1.4e-3), and a sum that still overflows, whose
    exact value is above the largest float, is held at sys.float_info.max: the indicator stays finite,
    with its sign right. A NaN stays NaN (as rst_native_ball.c's contact_indicator)."""
    if not v > 0.0:
        return h
    apex = h + v * v / (2.0 * g)
    if not math.isinf(apex):
        return apex
    scaled = v / math.sqrt(2.0 * g)
    apex = h + scaled * scaled
    return sys.float_info.max if math.isinf(apex) else apex


_INITIAL_STATE = {
    "h": 0.0, "v": 0.0, "v_approach": 0.0, "impacts": 0, "t_impact": -1.0, "v_impact": 0.0,
    "t_rebound": -1.0, "v_rebound": 0.0, "e_applied": 0.0, "in_contact": False, "at_rest": False,
    "t_start": 0.0, "h_start": 0.0, "v_start": 0.0, "der_h": 0.0, "der_v": 0.0, "contact_indicator": 0.0,
}


class BouncingBall(Fmi2Slave):
    """A ball dropped onto a plate; the coefficient of restitution is an input (from SpherePlateImpact)."""

    author = "restitution developers"
    description = TABLE.description

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self._values = {}  # parameters and the input, by FMI name
        self._s = dict(_INITIAL_STATE)  # evolving state, by table key
        self._setters = {}  # every registered variable's setter, by FMI name (FMU state restore)
        self._start_time = 0.0
        for var in TABLE:
            kind = {"Real": Real, "Integer": Integer, "Boolean": Boolean}[var.type]
            variability = getattr(Fmi2Variability, var.variability)
            if var.causality in ("parameter", "input"):
                self._values[var.name] = var.start
                self._setters[var.name] = checked_setter(self, var, self._values, lambda _name: None)
                self.register_variable(kind(
                    var.name, causality=getattr(Fmi2Causality, var.causality), variability=variability,
                    start=var.start, description=var.description, getter=self._value_getter(var.name),
                    setter=self._setters[var.name]), nested=False)
                continue
            self._setters[var.name] = self._state_setter(var.key)
            self.register_variable(kind(
                var.name, causality=getattr(Fmi2Causality, var.causality), variability=variability,
                initial=Fmi2Initial.calculated, description=var.description,
                getter=self._state_getter(var.key), setter=self._setters[var.name]), nested=False)
        self._schema = state_schema("BouncingBall", [var.name for var in TABLE])

    # --- variable access ---------------------------------------------------------------
    def _value_getter(self, name):
        return lambda: self._values[name]

    def _state_getter(self, key):
        return lambda: self._s[key]

    def _state_setter(self, key):  # used by fmi2SetFMUstate (and the guard's state restore)
        def set_value(value):
            self._s[key] = value
        return set_value

    def _get_fmu_state(self):
        return {"schema": self._schema, "values": {var.name: var.getter() for var in self.vars.values()}}

    def _set_fmu_state(self, state):
        checks = {var.name: state_check(var) for var in TABLE.settable}
        restore_state(self, state, self._schema, checks, self._setters)

    _fmu_state_to_bytes = staticmethod(state_to_bytes)
    _fmu_state_from_bytes = staticmethod(state_from_bytes)

    # --- the ball ------------------------------------------------------------------------
    def _start_flight(self, t, h, v):
        s = self._s
        s["t_start"], s["h_start"], s["v_start"] = float(t), float(h), float(v)

    def _rebound(self, t):
        """Leave the plate at time t with the COR on the input (or come to rest)."""
        s = self._s
        e = float(self._values["e"])
        v_out = e * s["v_impact"]
        s["in_contact"] = False
        s["t_rebound"] = float(t)
        s["e_applied"] = e
        if e <= 0.0 or v_out < float(self._values["v_min"]):
            s["at_rest"] = True
            s["v_rebound"] = 0.0
            self._start_flight(t, 0.0, 0.0)
        else:
            s["v_rebound"] = v_out
            self._start_flight(t, 0.0, v_out)

    def _update_outputs(self, t):
        s = self._s
        if s["at_rest"]:
            s["h"], s["v"], s["v_approach"] = 0.0, 0.0, 0.0
        elif s["in_contact"]:
            s["h"], s["v"], s["v_approach"] = 0.0, -s["v_impact"], s["v_impact"]
        else:
            g = float(self._values["g"])
            # within the flight: a flight shorter than the clock's resolution must not extrapolate past its end
            dt = min(max(t - s["t_start"], 0.0), flight_to_plate(s["h_start"], s["v_start"], g)[0])
            s["h"] = max(s["h_start"] + s["v_start"] * dt - 0.5 * g * dt * dt, 0.0)
            s["v"] = s["v_start"] - g * dt
            s["v_approach"] = -s["v"] if -s["v"] > 0.0 else 0.0  # +0.0 at the apex, never -0.0
        self._update_derivatives()

    def _update_derivatives(self):
        """der(h), der(v) and the contact indicator from the state (the native model exchange's
        equations: flight under gravity; nothing moves at the plate)."""
        s = self._s
        if s["at_rest"] or s["in_contact"]:
            s["der_h"], s["der_v"] = 0.0, 0.0
        else:
            s["der_h"], s["der_v"] = s["v"], -float(self._values["g"])
        s["contact_indicator"] = 1.0 if s["at_rest"] else contact_indicator(s["h"], s["v"], float(self._values["g"]))

    def _impact(self, t, v, count):
        """The last of `count` contacts: at time t [s] with approach speed v [m/s]."""
        s = self._s
        s["impacts"] = int(min(s["impacts"] + count, MAX_IMPACTS))
        s["t_impact"], s["v_impact"] = t, v
        s["in_contact"] = True

    # --- FMI calls -------------------------------------------------------------------------
    def setup_experiment(self, start_time, stop_time=None, tolerance=None):
        self._start_time = float(start_time)

    def exit_initialization_mode(self):
        self._s = dict(_INITIAL_STATE)
        self._start_flight(self._start_time, self._values["h0"], 0.0)
        if self._values["h0"] == 0.0:  # released on the plate: at rest from the start, no contact
            self._s["at_rest"] = True
        self._update_outputs(self._start_time)

    def do_step(self, current_time: float, step_size: float) -> bool:
        s = self._s
        g, e, v_min = float(self._values["g"]), float(self._values["e"]), float(self._values["v_min"])
        wait = TABLE["contact_mode"].word(self._values["contact_mode"]) == "wait"
        now = float(current_time)
        end = now + float(step_size)
        limit = end + TIME_TOLERANCE
        if s["in_contact"]:  # the COR for the pending contact arrived at this communication point
            self._rebound(now)
        if not s["at_rest"]:
            duration, v_hit = flight_to_plate(s["h_start"], s["v_start"], g)
            t_hit = s["t_start"] + duration
            if t_hit <= limit:  # (a NaN is no contact)
                self._impact(t_hit, v_hit, 1)
                if not wait:
                    self._rebound(t_hit)
                    if not s["at_rest"]:  # the rest of the step: flights from the plate, all with this e
                        n, t_last, v_last = constant_e_bounces(s["t_start"], s["v_start"], e, g, v_min, limit)
                        if n > 0:
                            self._impact(t_last, v_last, n)
                            self._rebound(t_last)
        self._update_outputs(end)
        return True

    def reset(self):
        for var in TABLE.settable:
            self._values[var.name] = var.start
        self._s = dict(_INITIAL_STATE)
        self._start_time = 0.0


_support.settle(globals(), locals(), "BouncingBall")
