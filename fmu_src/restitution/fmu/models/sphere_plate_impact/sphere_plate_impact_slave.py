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
PARAMETERS, impact, published = _model.PARAMETERS, _model.impact, _model.published
si_only = _support.submodule(_restitution, "quantities").si_only
departures = _support.submodule(_restitution, "assumptions").departures

#: FMU name of each Real output, by ImpactResult key
_REAL_OUTPUTS = {v.key: v.name for v in TABLE.outputs if v.type == "Real"}
# one C call for the step's finiteness check instead of a Python loop over the outputs
_real_output_values = operator.itemgetter(*_REAL_OUTPUTS)
#: impact() without its unit layer: the FMU's values are SI floats
_impact_si = si_only(impact)

#: impact()'s keyword arguments that are Integer choices, and the words their codes stand for
_CHOICES = {v.name: v for v in TABLE.settable if v.choices is not None and v.name not in MATERIAL_SELECTORS}
#: impact()'s positional arguments after v: the material and geometry parameters, by FMU name
_PHYSICAL = tuple(TABLE.by_key()[key].name for key, _unit, _check in PARAMETERS)
_FMI_CAUSALITY = {"input": Fmi2Causality.input, "parameter": Fmi2Causality.parameter, "output": Fmi2Causality.output}


def nonfinite_outputs(outputs: dict) -> list[str]:
    """The Real outputs that are NaN or infinite (``name = value`` texts). Every output is finite
    (``outputs`` as :func:`restitution.model.published` gives them): anything else is an evaluation
    failure."""
    if math.isfinite(sum(_real_output_values(outputs))):  # the usual case, one C loop (a NaN or inf, or an overflow, falls through)
        return []
    return [f"{name} = {outputs[key]!r}" for key, name in _REAL_OUTPUTS.items() if not math.isfinite(outputs[key])]


class SpherePlateImpact(Fmi2Slave):
    """Apparent COR of a sphere hitting a plate of finite thickness (I. Green, Nonlinear Dyn 2022)."""

    author = "restitution developers"
    description = TABLE.description

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self._values = {}  # name -> current value of every input and parameter
        self._outputs = {}
        self._stale = True  # an input or parameter changed since the last evaluation
        self._call = None  # impact()'s arguments but v, built when a parameter changed
        self._used = None  # the parameters with each body's material preset applied, when a parameter changed
        self._failure = None  # message of the last evaluation that raised
        self._warned = set()  # the conditions of restitution.assumptions logged (pythonfmu's reset makes a new slave)
        self._output_keys = {}  # (Real|Boolean, value reference) -> ImpactResult key, for get_real/get_boolean
        self._last_read = {"Real": (None, None), "Boolean": (None, None)}  # type -> (vrs, reader) of the last get
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
                fmi_var = kind(var.name, causality=Fmi2Causality.output, variability=variability,
                               initial=Fmi2Initial.calculated, description=var.description,
                               getter=self._output_getter(var.key, var.type))
                self.register_variable(fmi_var, nested=False)
                self._output_keys.setdefault(var.type, {})[fmi_var.value_reference] = var.key
                continue
            self._values[var.name] = var.start
            self.register_variable(kind(
                var.name, causality=_FMI_CAUSALITY[var.causality], variability=variability, start=var.start,
                description=var.description, getter=self._input_getter(var.name),
                setter=checked_setter(self, var, self._values, self._changed)), nested=False)
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
            self._call = None
            self._used = None

    def _output_getter(self, key, vtype):
        nan = math.nan if vtype == "Real" else False

        def get_value():
            if self._stale or self._failure is not None:
                outputs = self._evaluate()
                return outputs.get(key, nan) if outputs is not None else nan
            return self._outputs[key]  # the common case: cached, valid
        return get_value

    # fmi2GetReal/fmi2GetBoolean: pythonfmu's versions call one getter per variable (and each
    # getter checks the cache); for outputs only, evaluate once and read them in one pass. The
    # values are those of the getters: NaN (Real) or False (Boolean) while the outputs are invalid.
    # Requests that include inputs or parameters take pythonfmu's path, with its checks.
    # A host asks for the same list step after step: the reader of the last list is kept, so a
    # repeated request costs one list comparison instead of a lookup per value reference.
    def get_real(self, vrs):
        return self._get_outputs("Real", vrs, math.nan, super().get_real)

    def get_boolean(self, vrs):
        return self._get_outputs("Boolean", vrs, False, super().get_boolean)

    def _get_outputs(self, vtype, vrs, invalid_value, general_get):
        last_vrs, read = self._last_read[vtype]
        if vrs != last_vrs:
            read = self._remember_reader(vtype, vrs)
        if read is None:
            return general_get(vrs)
        outputs = self._evaluate()
        return read(outputs) if outputs is not None else [invalid_value] * len(vrs)

    def _remember_reader(self, vtype, vrs):
        """outputs -> the list of values of ``vrs``, or None when ``vrs`` names anything but outputs
        of type ``vtype``; kept as the reader of ``vtype``'s last request."""
        keys = self._output_keys[vtype]
        try:
            names = [keys[vr] for vr in vrs]
        except KeyError:
            names = None
        if names is None:
            read = None
        elif len(names) < 2:  # itemgetter of one key gives the value itself, of none is an error
            def read(outputs):
                return [outputs[name] for name in names]
        else:
            values = operator.itemgetter(*names)

            def read(outputs):
                return list(values(outputs))
        self._last_read[vtype] = (list(vrs), read)
        return read

    # --- evaluation --------------------------------------------------------------------
    def _evaluate(self):
        """Outputs for the current inputs, recomputed only when an input or parameter changed."""
        if not self._stale:
            return self._outputs if self._failure is None else None
        self._stale = False
        v = self._values
        try:
            if self._call is None:
                used = self._used_values()
                self._call = (
                    tuple(float(used[name]) for name in _PHYSICAL),
                    dict({TABLE.key_of(name): var.word(int(v[name])) for name, var in _CHOICES.items()},
                         effect_tolerance=float(v["effect_tolerance"]), ode_rtol=float(v["zener.ode_tolerance"]),
                         plate_edge_distance=float(v["plate.edge_distance"]), validate=False))
            args, kwargs = self._call
            result = _impact_si(float(v["v_approach"]), *args, **kwargs)
        except Exception as exc:  # a numerical failure must not become fmi2Fatal
            return self._fail(f"{type(exc).__name__}: {exc}")
        outputs = published(result.as_dict())
        bad = nonfinite_outputs(outputs)
        if bad:
            return self._fail("non-finite output " + ", ".join(bad))
        self._failure = None
        self._outputs = outputs
        if not (outputs["valid"] and outputs["edge_clear"] and not outputs["e_negative"]):  # rare: say it once
            self._log_departures(outputs)
        return self._outputs

    def _log_departures(self, outputs):
        for name, message in departures(outputs):
            if name not in self._warned:
                self._warned.add(name)
                self.log(message, Fmi2Status.warning)

    def _fail(self, reason):
        self._failure = f"evaluation failed for {self._describe_inputs()}: {reason}"
        self.log(self._failure, Fmi2Status.error)
        return None

    def _describe_inputs(self):
        return ", ".join(f"{k} = {val!r}" for k, val in self._values.items())

    # --- FMI calls -------------------------------------------------------------------------
    def exit_initialization_mode(self):
        self._evaluate()

    def do_step(self, current_time: float, step_size: float) -> bool:
        if self._evaluate() is None:
            self.log("fmi2DoStep discarded: the model could not be evaluated for the current inputs "
                     "(see the error above)", Fmi2Status.discard)
            return False
        return True

    def reset(self):
        for var in TABLE.settable:
            self._values[var.name] = var.start
        self._stale = True
        self._call = None
        self._used = None
        self._failure = None
        self._outputs = {}

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
