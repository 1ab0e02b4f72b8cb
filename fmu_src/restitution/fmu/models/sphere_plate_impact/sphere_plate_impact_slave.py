"""SpherePlateImpact: the FMI 2.0 co-simulation adapter around the ``restitution`` package.

A thin layer: it keeps the inputs and parameters, checks each value as it is set,
evaluates :func:`restitution.impact` lazily (only when an output is read or a step is
taken after something changed) and exposes the results. Nothing here is physics.

Bad input never raises (pythonfmu would turn an exception into fmi2Fatal for every
instance): a value outside its range is refused, the previous value kept, and a message
naming the variable, its value and the allowed range is logged with fmi2Error (in the built
FMU the C guard refuses it first and returns fmi2Error). An evaluation that fails, or gives a
non-finite output (every published output is finite), is logged with the inputs; the outputs then
read NaN (Booleans false) and ``fmi2DoStep`` returns fmi2Discard. An impact outside the validated
domain (lambda > 1.5, V* > 1000, e < 0, an edge echo during the contact) is computed as usual and
logged once per instance and condition with fmi2Warning (restitution.assumptions); the calls return
fmi2OK.

The FMU state is exactly the inputs and parameters, tagged with the model, the state format
and the variable list; a state is validated as the setters would before anything is restored.

The module has a name of its own (not ``model``): two pythonfmu FMUs whose scripts share
a module name clash in one process. Which ``restitution`` it runs, and which class pythonfmu
instantiates, is decided at start-up (restitution_slave_support.py): the FMU's own code, or a copy
verified to be the same, whatever the host and other FMUs loaded before and whether their folders
still exist.
"""
from __future__ import annotations

import hashlib
import importlib.util
import math
import operator
import os
import sys

from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Boolean, Integer, Real
from pythonfmu.enums import Fmi2Initial, Fmi2Status

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
_restitution = _support.start(globals(), locals(), "SpherePlateImpact", _resources)
_variables = _support.submodule(_restitution, "fmu.models.sphere_plate_impact.variables")
MATERIAL_SELECTORS, TABLE = _variables.MATERIAL_SELECTORS, _variables.TABLE
resolve_materials = _variables.resolve_materials
_model = _support.submodule(_restitution, "model")
PARAMETERS, RECORD, published = _model.PARAMETERS, _model.RECORD, _model.published
impact_terms, impact_record_at = _model.impact_terms, _model.impact_record_at
si_only = _support.submodule(_restitution, "quantities").si_only
departures = _support.submodule(_restitution, "assumptions").departures

#: The outputs of each FMI type, in value-reference order (every output is a Real or a Boolean).
_OUTPUTS = {vtype: tuple(v for v in TABLE.outputs if v.type == vtype) for vtype in ("Real", "Boolean")}
#: What the outputs of each type read while they are invalid (the last evaluation failed).
_INVALID = {"Real": (math.nan,) * len(_OUTPUTS["Real"]), "Boolean": (False,) * len(_OUTPUTS["Boolean"])}
# a published record (restitution.model.RECORD) -> the Real outputs in order, the Boolean outputs in order:
# one C call each
_real_values = operator.itemgetter(*(RECORD.index(v.key) for v in _OUTPUTS["Real"]))
_flag_values = operator.itemgetter(*(RECORD.index(v.key) for v in _OUTPUTS["Boolean"]))
_VALID, _EDGE_CLEAR, _E_NEGATIVE = (RECORD.index(key) for key in ("valid", "edge_clear", "e_negative"))
#: impact_terms() and impact_record_at() without their unit layer: the FMU's values are SI floats
_terms_si = si_only(impact_terms)
_impact_si = si_only(impact_record_at)

#: impact()'s keyword arguments that are Integer choices, and the words their codes stand for
_CHOICES = {v.name: v for v in TABLE.settable if v.choices is not None and v.name not in MATERIAL_SELECTORS}
#: impact()'s positional arguments after v: the material and geometry parameters, by FMU name
_PHYSICAL = tuple(TABLE.by_key()[key].name for key, _unit, _check in PARAMETERS)
_FMI_CAUSALITY = {"input": Fmi2Causality.input, "parameter": Fmi2Causality.parameter, "output": Fmi2Causality.output}


def nonfinite_outputs(reals: tuple) -> list[str]:
    """The Real outputs that are NaN or infinite (``name = value`` texts), ``reals`` being their values in
    value-reference order. Every output is finite (:func:`restitution.model.published`): anything else
    is an evaluation failure."""
    if math.isfinite(sum(reals)):  # the usual case, one C loop (a NaN or inf, or an overflow, falls through)
        return []
    return [f"{var.name} = {value!r}" for var, value in zip(_OUTPUTS["Real"], reals) if not math.isfinite(value)]


def output_reader(positions: list, count: int):
    """values (the ``count`` outputs of one type, in order) -> the list of those at ``positions``: what a
    get request of these outputs returns."""
    if positions == list(range(count)):  # every output of the type, in order: what hosts ask for
        return list
    if len(positions) == 1:  # itemgetter of one key gives the value itself, of none is an error
        (at,) = positions
        return lambda values: [values[at]]
    if not positions:
        return lambda values: []
    pick = operator.itemgetter(*positions)
    return lambda values: list(pick(values))


class SpherePlateImpact(Fmi2Slave):
    """Apparent COR of a sphere hitting a plate of finite thickness (I. Green, Nonlinear Dyn 2022)."""

    author = "restitution developers"
    description = TABLE.description

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self._values = {}  # name -> current value of every input and parameter
        self._stale = True  # an input or parameter changed since the last evaluation
        self._terms = None  # impact_terms() of the parameters, made when a parameter changed
        self._used = None  # the parameters with each body's material preset applied, when a parameter changed
        self._failure = None  # message of the last evaluation that raised
        self._warned = set()  # the conditions of restitution.assumptions logged (pythonfmu's reset makes a new slave)
        # the outputs of each type, in order, as of the last evaluation (invalid until the first)
        self._current = dict(_INVALID)
        # per type: value reference -> position among the outputs of that type
        self._positions = {vtype: {} for vtype in _OUTPUTS}
        # per type: (value references, reader) of the last get request; reader None: not only outputs
        self._request = {vtype: (None, None) for vtype in _OUTPUTS}
        self._real_setters = {}  # value reference -> checked setter of each Real input and parameter
        for var in TABLE:
            kind = {"Real": Real, "Integer": Integer, "Boolean": Boolean}[var.type]
            variability = getattr(Fmi2Variability, var.variability)
            if var.causality == "calculatedParameter":
                self.register_variable(kind(
                    var.name, causality=Fmi2Causality.calculatedParameter, variability=variability,
                    initial=Fmi2Initial.calculated, description=var.description,
                    getter=self._used_getter(var.name)), nested=False)
                continue
            if var.causality == "output":
                positions = self._positions[var.type]
                fmi_var = kind(var.name, causality=Fmi2Causality.output, variability=variability,
                               initial=Fmi2Initial.calculated, description=var.description,
                               getter=self._output_getter(var.type, len(positions)))
                self.register_variable(fmi_var, nested=False)
                positions[fmi_var.value_reference] = len(positions)
                continue
            self._values[var.name] = var.start
            setter = checked_setter(self, var, self._values, self._changed)
            fmi_var = kind(var.name, causality=_FMI_CAUSALITY[var.causality], variability=variability,
                           start=var.start, description=var.description, getter=self._input_getter(var.name),
                           setter=setter)
            self.register_variable(fmi_var, nested=False)
            if var.type == "Real":
                self._real_setters[fmi_var.value_reference] = setter
        self._schema = state_schema("SpherePlateImpact", list(self._values))

    # --- variable access -------------------------------------------------------------
    def _input_getter(self, name):
        return lambda: self._values[name]

    def _used_getter(self, name):
        """A calculated parameter: the material property the model uses (``sphere.used.E`` is the
        preset's E, or sphere.E for a custom material)."""
        parameter = name.replace(".used.", ".")
        return lambda: self._used_values()[parameter]

    def _used_values(self):
        if self._used is None:
            self._used = resolve_materials(self._values)
        return self._used

    def _changed(self, name):
        self._stale = True
        if name != "v_approach":
            self._terms = None
            self._used = None

    def _output_getter(self, vtype, position):
        """One output, for pythonfmu's per-variable path (requests mixing outputs with other variables):
        NaN (Real) or False (Boolean) while the outputs are invalid."""
        def get_value():
            if self._stale:
                self._evaluate()
            return self._current[vtype][position]
        return get_value

    # fmi2SetReal: pythonfmu's version looks each variable up and checks its type; the setters of the
    # Real inputs and parameters are kept by value reference instead. Anything else takes pythonfmu's
    # path, with its checks.
    def set_real(self, vrs, values):
        setters = self._real_setters
        for vr, value in zip(vrs, values):
            setter = setters.get(vr)
            if setter is None:
                super().set_real([vr], [value])
            else:
                setter(value)

    # fmi2GetReal/fmi2GetBoolean: pythonfmu's versions call one getter per variable; for outputs only,
    # evaluate once (if anything changed) and read them in one pass from the values kept per type. A
    # host asks for the same list step after step: the reader of the last list is kept, so a repeated
    # request costs one list comparison. Requests that include inputs or parameters take pythonfmu's
    # path, with its checks.
    def get_real(self, vrs):
        return self._get_outputs("Real", vrs, super().get_real)

    def get_boolean(self, vrs):
        return self._get_outputs("Boolean", vrs, super().get_boolean)

    def _get_outputs(self, vtype, vrs, general_get):
        last_vrs, read = self._request[vtype]
        if vrs != last_vrs:
            read = self._remember_reader(vtype, vrs)
        if read is None:
            return general_get(vrs)
        if self._stale:
            self._evaluate()
        return read(self._current[vtype])

    def _remember_reader(self, vtype, vrs):
        """The reader (:func:`output_reader`) of the request ``vrs``, or None when it names anything but
        outputs of type ``vtype``; kept as the reader of ``vtype``'s last request."""
        positions = self._positions[vtype]
        try:
            read = output_reader([positions[vr] for vr in vrs], len(positions))
        except (KeyError, TypeError):
            read = None
        self._request[vtype] = (list(vrs), read)
        return read

    # --- evaluation --------------------------------------------------------------------
    def _evaluate(self):
        """The outputs for the current inputs (called when an input or parameter changed): kept in
        ``_current``, invalid (NaN, False) when the evaluation fails."""
        self._stale = False
        v = self._values
        try:
            if self._terms is None:
                used = self._used_values()
                self._terms = _terms_si(
                    *(float(used[name]) for name in _PHYSICAL),
                    **{TABLE.key_of(name): var.word(int(v[name])) for name, var in _CHOICES.items()},
                    effect_tolerance=float(v["effect_tolerance"]), ode_rtol=float(v["zener.ode_tolerance"]),
                    plate_edge_distance=float(v["plate.edge_distance"]), validate=False)
            outputs = published(_impact_si(float(v["v_approach"]), self._terms, False))
            reals = _real_values(outputs)
            flags = _flag_values(outputs)
        except Exception as exc:  # a numerical failure must not become fmi2Fatal
            self._fail(f"{type(exc).__name__}: {exc}")
            return
        if not math.isfinite(sum(reals)):  # rare (a NaN or inf, or an overflow of the sum): which ones
            bad = nonfinite_outputs(reals)
            if bad:
                self._fail("non-finite output " + ", ".join(bad))
                return
        self._failure = None
        self._current = {"Real": reals, "Boolean": flags}
        if not (outputs[_VALID] and outputs[_EDGE_CLEAR] and not outputs[_E_NEGATIVE]):  # rare: say it once
            self._log_departures(dict(zip(RECORD, outputs)))

    def _log_departures(self, outputs):
        for name, message in departures(outputs):
            if name not in self._warned:
                self._warned.add(name)
                self.log(message, Fmi2Status.warning)

    def _fail(self, reason):
        self._failure = f"evaluation failed for {self._describe_inputs()}: {reason}"
        self._current = dict(_INVALID)
        self.log(self._failure, Fmi2Status.error)

    def _describe_inputs(self):
        return ", ".join(f"{k} = {val!r}" for k, val in self._values.items())

    # --- FMI calls -------------------------------------------------------------------------
    def exit_initialization_mode(self):
        if self._stale:
            self._evaluate()

    def do_step(self, current_time: float, step_size: float) -> bool:
        if self._stale:
            self._evaluate()
        if self._failure is not None:
            self.log("fmi2DoStep discarded: the model could not be evaluated for the current inputs "
                     "(see the error above)", Fmi2Status.discard)
            return False
        return True

    def reset(self):
        for var in TABLE.settable:
            self._values[var.name] = var.start
        self._stale = True
        self._terms = None
        self._used = None
        self._failure = None
        self._current = dict(_INVALID)

    # --- FMU state: the inputs and parameters, with a schema tag, validated before restoring ---
    def _get_fmu_state(self):
        return {"schema": self._schema, "values": dict(self._values)}

    def _set_fmu_state(self, state):
        checks = {name: state_check(TABLE[name]) for name in self._values}
        setters = {name: self._state_setter(name) for name in self._values}
        restore_state(self, state, self._schema, checks, setters)

    def _state_setter(self, name):
        def set_value(value):
            if value != self._values[name]:
                self._values[name] = value
                self._changed(name)
        return set_value

    _fmu_state_to_bytes = staticmethod(state_to_bytes)
    _fmu_state_from_bytes = staticmethod(state_from_bytes)


_support.settle(globals(), locals(), "SpherePlateImpact")
