"""SpherePlateImpact: the FMI 2.0 co-simulation adapter around the ``restitution`` package.

A thin layer: it keeps the inputs and parameters, checks each value as it is set,
evaluates :func:`restitution.impact` lazily (only when an output is read or a step is
taken after something changed) and exposes the results. Nothing here is physics.

Bad input never raises (pythonfmu would turn an exception into fmi2Fatal for every
instance): a value outside its range is refused, the previous value kept, and a message
naming the variable, its value and the allowed range is logged with fmi2Error (in the built
FMU the C guard refuses it first and returns fmi2Error). An evaluation that fails, or gives a
non-finite output (every published output is finite), is logged with the inputs; the outputs then
read NaN (Booleans false) and ``fmi2DoStep`` returns fmi2Discard.

The FMU state is exactly the inputs and parameters, tagged with the model, the state format
and the variable list; a state is validated as the setters would before anything is restored.

The module has a name of its own (not ``model``): two pythonfmu FMUs whose scripts share
a module name clash in one process.
"""
from __future__ import annotations

import math
import os
import sys

from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Boolean, Integer, Real
from pythonfmu.enums import Fmi2Initial, Fmi2Status

# Inside the FMU the bundled package sits next to this script in resources/; put it first
# so the FMU runs the code it was built with, not whatever the host happens to have.
_HERE = os.path.dirname(os.path.abspath(__file__))
if os.path.isdir(os.path.join(_HERE, "restitution")) and sys.path[0] != _HERE:
    sys.path.insert(0, _HERE)

from restitution.model import DOMAIN, EFFECT_MODES, RESTITUTION_MODELS, ZENER_METHODS, impact, published  # noqa: E402
from restitution.validation import interval_check  # noqa: E402
from restitution_slave_support import (checked_setter, restore_state, state_check,  # noqa: E402
                                       state_from_bytes, state_schema, state_to_bytes)

P, IN, OUT = "parameter", "input", "output"

# (name, type, causality, unit, start, description, key); key is the impact() keyword for
# inputs/parameters and the ImpactResult field for outputs. build_fmu.py reads this table
# to write units, ranges and descriptions into modelDescription.xml.
VARIABLES = (
    ("v_approach", "Real", IN, "m/s", 1.0, "Normal approach speed of the sphere toward the plate, 0 to 1e4 m/s", "v"),
    ("sphere.E", "Real", P, "Pa", 207e9, "Sphere elastic modulus, 1e5 to 1e13 Pa (default: S2 tool steel, Table 3)", "sphere_E"),
    ("sphere.nu", "Real", P, "1", 0.30, "Sphere Poisson's ratio, 0 <= nu < 0.5", "sphere_nu"),
    ("sphere.Sy", "Real", P, "Pa", 2.0e9, "Sphere yield strength, 1e3 to 1e13 Pa (1e12 for brittle materials)", "sphere_Sy"),
    ("sphere.rho", "Real", P, "kg/m3", 7861.0, "Sphere density, 1 to 1e5 kg/m3", "sphere_rho"),
    ("sphere.d", "Real", P, "m", 6.35e-3, "Sphere diameter, 1e-6 to 10 m", "sphere_d"),
    ("plate.E", "Real", P, "Pa", 69e9, "Plate elastic modulus, 1e5 to 1e13 Pa (default: Al 6061, Table 3)", "plate_E"),
    ("plate.nu", "Real", P, "1", 0.33, "Plate Poisson's ratio, 0 <= nu < 0.5", "plate_nu"),
    ("plate.Sy", "Real", P, "Pa", 0.290e9, "Plate yield strength, 1e3 to 1e13 Pa (1e12 for brittle materials)", "plate_Sy"),
    ("plate.rho", "Real", P, "kg/m3", 2700.0, "Plate density, 1 to 1e5 kg/m3", "plate_rho"),
    ("plate.t", "Real", P, "m", 6.35e-3, "Plate thickness, 1e-7 to 100 m", "plate_t"),
    ("restitution_model", "Integer", P, None, 1,
     "Elastoplastic COR: 1 = e45 (Eq. 8, default), 2 = e44 (Eq. 7, second branch reconstructed)",
     "restitution_model"),
    ("zener_method", "Integer", P, None, 1,
     "Zener COR and contact time: 1 = exact (tabulated ODE solution), 2 = paper_fit (Eqs. 13, 13a), "
     "3 = linear (Eq. 22), 4 = ode (Eq. 10 integrated at every evaluation)", "zener_method"),
    ("plasticity", "Integer", P, None, 2,
     "Elastoplastic effect: 0 = off (e_ep = 1), 1 = on, 2 = auto (skipped where 1 - e_ep < effect_tolerance)",
     "plasticity"),
    ("plate_waves", "Integer", P, None, 2,
     "Plate-wave effect: 0 = off (e_ze = 1, half-space), 1 = on, "
     "2 = auto (skipped where 1 - e_ze < effect_tolerance is guaranteed)", "plate_waves"),
    ("effect_tolerance", "Real", P, "1", 1e-6, "Largest change in e that auto may neglect, >= 0", "effect_tolerance"),
    ("zener.ode_tolerance", "Real", P, "1", 1e-10,
     "Relative tolerance of zener_method = 4 (ode), 1e-14 <= tol <= 1e-2 (below what the integrator honours "
     "it is raised to 2.2e-14 for lambda <= 10, 1e-13 above)", "ode_rtol"),
    ("e", "Real", OUT, "1", None, "Apparent coefficient of restitution, Eq. (20); < 0: sphere moves on with the plate", "e"),
    ("v_rebound", "Real", OUT, "m/s", None, "Sphere speed away from the plate after impact, e * v_approach", "v_rebound"),
    ("jgm.e", "Real", OUT, "1", None, "Elastoplastic COR e_ep, Eq. (7) or (8)", "e_ep"),
    ("jgm.V_c", "Real", OUT, "m/s", None, "Critical velocity at the onset of yielding, Eq. (6)", "V_c"),
    ("jgm.V_star", "Real", OUT, "1", None, "Normalised impact speed V* = v_approach / V_c", "V_star"),
    ("zener.e", "Real", OUT, "1", None, "Zener's COR e_ze (1 where plate waves are off or skipped)", "e_ze"),
    ("zener.lambda", "Real", OUT, "1", None, "Zener's inelasticity parameter lambda, Eq. (12)", "lam"),
    ("zener.tau0", "Real", OUT, "1", None, "Dimensionless contact time tau0 (plate_waves off: 3.2180655, Hertz; "
     "skipped by auto: the method's value at lambda = 0; 0 where zener.contact_ends is false)", "tau0"),
    ("zener.t_contact", "Real", OUT, "s", None, "Contact duration T * tau0 (0 when v_approach = 0 "
     "or where zener.contact_ends is false)", "t_contact"),
    ("plate.mass_ratio", "Real", OUT, "1", None, "Sphere mass over the equivalent plate mass of Eq. (19), "
     "m_a/m_b = (1 - e_ze)/(1 + e_ze): 0 for a half-space (plate waves off or negligible), 1 when e_ze = 0",
     "mass_ratio"),
    ("plate.v_after", "Real", OUT, "m/s", None, "Plate velocity after impact, Eq. (17), positive along the approach", "v_plate"),
    ("sphere.m", "Real", OUT, "kg", None, "Sphere mass m_a = rho pi d^3/6 (equivalent plate mass m_b = "
     "sphere.m / plate.mass_ratio)", "m_a"),
    ("valid", "Boolean", OUT, None, None, "Inside both models' validated ranges: lambda <= 1.5 and V* <= 1000", "valid"),
    ("zener.in_range", "Boolean", OUT, None, None, "lambda <= 1.5, Zener's studied range", "lambda_in_range"),
    ("jgm.in_range", "Boolean", OUT, None, None, "V* <= 1000, the range of the JGM fits", "vstar_in_range"),
    ("e_negative", "Boolean", OUT, None, None, "e < 0: the sphere keeps moving with the plate after impact", "e_negative"),
    ("effects.plasticity", "Boolean", OUT, None, None, "The elastoplastic effect was applied (e_ep < 1)", "plasticity_used"),
    ("effects.plate_waves", "Boolean", OUT, None, None, "The plate-wave effect was computed", "plate_waves_used"),
    ("zener.contact_ends", "Boolean", OUT, None, None, "The sphere leaves the plate after a finite contact time "
     "(false only for the linear method at lambda >= 2: e_ze = 0, tau0 and t_contact read 0)", "contact_ends"),
)

_CHOICES = {
    "restitution_model": (RESTITUTION_MODELS, "1 = e45 or 2 = e44"),
    "zener_method": (ZENER_METHODS, "1 = exact, 2 = paper_fit, 3 = linear or 4 = ode"),
    "plasticity": (EFFECT_MODES, "0 = off, 1 = on or 2 = auto"),
    "plate_waves": (EFFECT_MODES, "0 = off, 1 = on or 2 = auto"),
}
_CODE_OFFSET = {"restitution_model": 1, "zener_method": 1, "plasticity": 0, "plate_waves": 0}
_PACKAGE_KEY = {row[0]: row[6] for row in VARIABLES}
_TYPES = {row[0]: row[1] for row in VARIABLES}
#: FMU name of each Real output, by ImpactResult key
_REAL_OUTPUTS = {row[6]: row[0] for row in VARIABLES if row[2] == OUT and row[1] == "Real"}


def nonfinite_outputs(outputs: dict) -> list[str]:
    """The Real outputs that are NaN or infinite (``name = value`` texts). Every output is finite
    (``outputs`` as :func:`restitution.model.published` gives them): anything else is an evaluation
    failure."""
    values = [outputs[key] for key in _REAL_OUTPUTS]
    if math.isfinite(sum(values)):  # the usual case, one C loop (a NaN or inf, or an overflow, falls through)
        return []
    return [f"{name} = {outputs[key]!r}" for key, name in _REAL_OUTPUTS.items() if not math.isfinite(outputs[key])]


def allowed_interval(name):
    """(low, high, low_open, high_open) of an input or parameter: the one place the interface's
    ranges live. The setters check values with it (:func:`allowed_range`), the build writes the
    min/max attributes and the C guard's range table from it. An infinite bound is always open:
    non-finite values are rejected."""
    if name in _CHOICES:
        low = _CODE_OFFSET[name]
        return low, low + len(_CHOICES[name][0]) - 1, False, False
    if name.endswith(".nu"):
        return 0.0, 0.5, False, True
    if _PACKAGE_KEY.get(name) in DOMAIN:  # the package's declared domain: every output finite inside it
        low, high = DOMAIN[_PACKAGE_KEY[name]]
        return low, high, False, False
    if name == "effect_tolerance":
        return 0.0, math.inf, False, True
    if name == "zener.ode_tolerance":
        return 1e-14, 1e-2, False, False
    return 0.0, math.inf, True, True


def allowed_range(name):
    """(predicate, allowed-range text, xml min, xml max) of an input or parameter, from :func:`allowed_interval`."""
    if name in _CHOICES:
        low, high, _, _ = allowed_interval(name)
        return (lambda v: low <= int(v) <= high), _CHOICES[name][1], str(low), str(high)
    text = "1e-14 <= value <= 1e-2" if name == "zener.ode_tolerance" else None
    return interval_check(*allowed_interval(name), text=text)


class SpherePlateImpact(Fmi2Slave):
    """Apparent COR of a sphere hitting a plate of finite thickness (I. Green, Nonlinear Dyn 2022)."""

    author = "restitution developers"
    description = ("Apparent coefficient of restitution of a sphere hitting a plate of finite thickness: "
                   "JGM elastoplastic model fused with Zener's plate-wave model, I. Green, Nonlinear Dyn (2022)")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self._values = {}  # name -> current value of every input and parameter
        self._outputs = {}
        self._stale = True  # an input or parameter changed since the last evaluation
        self._call = None  # impact()'s arguments but v, built when a parameter changed
        self._failure = None  # message of the last evaluation that raised
        self._output_keys = {}  # (Real|Boolean, value reference) -> ImpactResult key, for get_real/get_boolean
        for name, vtype, causality, _unit, start, description, key in VARIABLES:
            if causality == OUT:
                var_cls = Real if vtype == "Real" else Boolean
                var = var_cls(
                    name, causality=Fmi2Causality.output, variability=Fmi2Variability.continuous
                    if vtype == "Real" else Fmi2Variability.discrete, initial=Fmi2Initial.calculated,
                    description=description, getter=self._output_getter(key, vtype))
                self.register_variable(var, nested=False)
                self._output_keys.setdefault(vtype, {})[var.value_reference] = key
                continue
            self._values[name] = start
            var_cls = Real if vtype == "Real" else Integer
            if causality == IN:
                fmi_causality, variability = Fmi2Causality.input, Fmi2Variability.continuous
            else:
                fmi_causality, variability = Fmi2Causality.parameter, Fmi2Variability.tunable
            self.register_variable(var_cls(
                name, causality=fmi_causality, variability=variability, start=start,
                description=description, getter=self._input_getter(name),
                setter=checked_setter(self, name, allowed_range, self._values, self._changed)), nested=False)
        self._schema = state_schema("SpherePlateImpact", list(self._values))

    # --- variable access -------------------------------------------------------------
    def _input_getter(self, name):
        return lambda: self._values[name]

    def _changed(self, name):
        self._stale = True
        if name != "v_approach":
            self._call = None

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
    def get_real(self, vrs):
        return self._get_outputs("Real", vrs, math.nan, super().get_real)

    def get_boolean(self, vrs):
        return self._get_outputs("Boolean", vrs, False, super().get_boolean)

    def _get_outputs(self, vtype, vrs, invalid_value, general_get):
        keys = self._output_keys[vtype]
        try:
            names = [keys[vr] for vr in vrs]
        except KeyError:
            return general_get(vrs)
        outputs = self._evaluate()
        return [outputs[k] for k in names] if outputs is not None else [invalid_value] * len(names)

    # --- evaluation --------------------------------------------------------------------
    def _evaluate(self):
        """Outputs for the current inputs, recomputed only when an input or parameter changed."""
        if not self._stale:
            return self._outputs if self._failure is None else None
        self._stale = False
        v = self._values
        try:
            if self._call is None:
                self._call = (
                    (float(v["sphere.E"]), float(v["sphere.nu"]), float(v["sphere.Sy"]), float(v["sphere.rho"]),
                     float(v["sphere.d"]), float(v["plate.E"]), float(v["plate.nu"]), float(v["plate.Sy"]),
                     float(v["plate.rho"]), float(v["plate.t"])),
                    dict(restitution_model=RESTITUTION_MODELS[int(v["restitution_model"]) - 1],
                         zener_method=ZENER_METHODS[int(v["zener_method"]) - 1],
                         plasticity=EFFECT_MODES[int(v["plasticity"])],
                         plate_waves=EFFECT_MODES[int(v["plate_waves"])],
                         effect_tolerance=float(v["effect_tolerance"]), ode_rtol=float(v["zener.ode_tolerance"]),
                         validate=False))
            args, kwargs = self._call
            result = impact(float(v["v_approach"]), *args, **kwargs)
        except Exception as exc:  # a numerical failure must not become fmi2Fatal
            return self._fail(f"{type(exc).__name__}: {exc}")
        outputs = published(result.as_dict())
        bad = nonfinite_outputs(outputs)
        if bad:
            return self._fail("non-finite output " + ", ".join(bad))
        self._failure = None
        self._outputs = outputs
        return self._outputs

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
        for name, _vtype, causality, _unit, start, _description, _key in VARIABLES:
            if causality != OUT:
                self._values[name] = start
        self._stale = True
        self._call = None
        self._failure = None
        self._outputs = {}

    # --- FMU state: the inputs and parameters, with a schema tag, validated before restoring ---
    def _get_fmu_state(self):
        return {"schema": self._schema, "values": dict(self._values)}

    def _set_fmu_state(self, state):
        checks = {name: state_check(name, allowed_range, _TYPES[name]) for name in self._values}
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
