"""The whole model: apparent COR of a sphere hitting a plate of finite thickness,
I. Green, Nonlinear Dyn (2022), JGM (Eqs. 1-8) and Zener (Eqs. 9-13a) fused by Eq. (20).

:func:`impact` takes Python floats (one impact) or numpy arrays (broadcast together, one
result per element); one pipeline, :func:`_pipeline`, serves both.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, fields
from fractions import Fraction
from functools import lru_cache

import numpy as np

from . import fusion, jgm, zener
from ._num import fifth_root, is_scalar, minimum, where
from .fusion import apparent_restitution, mass_ratio, plate_mass_from_ratio, plate_velocity_after_impact
from .jgm import restitution_e44, restitution_e45, vstar_in_fit_range
from .quantities import si_only, with_units
from .validation import (check_choice, check_nonnegative, check_nonnegative_or_infinite, check_poisson,
                         check_positive)
from .zener import (TAU0_HERTZ, ZENER_METHODS, edge_clear, lambda_from_root, lambda_in_studied_range,
                    lambda_material_factor, time_scale_factor, time_scale_from_root, wave_delay, waves_concurrent,
                    zener_linear, zener_paper_fit, zener_solution)

# The pipeline passes SI numbers it has checked: it calls the equations without their unit layer
# (restitution.quantities), which would cost more than the equations on the scalar path.
(critical_interference, critical_load, critical_pressure, critical_velocity, effective_modulus, sphere_mass,
 yield_strain) = map(si_only, (jgm.critical_interference, jgm.critical_load, jgm.critical_pressure,
                               jgm.critical_velocity, jgm.effective_modulus, jgm.sphere_mass, jgm.yield_strain))
(contact_duration, hertz_stiffness, dilatational_slowness, edge_echo_ratio) = map(
    si_only, (zener.contact_duration, zener.hertz_stiffness, zener.dilatational_slowness, zener.edge_echo_ratio))

__all__ = ["ImpactResult", "impact", "published", "RESTITUTION_MODELS", "EFFECT_MODES", "ZENER_SLOPE_BOUND",
           "PARAMETERS", "DOMAIN", "validate_parameters", "RECORD_REALS", "RECORD_FLAGS", "EDGE_ECHO_PUBLISHED_MAX",
           "check_edge_distance"]

RESTITUTION_MODELS = ("e45", "e44")
EFFECT_MODES = ("off", "on", "auto")
#: Upper bound of (1 - e_ze(lambda)) / lambda over lambda > 0 for the nonlinear ODE [1]
#: (the slope at lambda = 0, 1.73015, is the supremum; checked against the exact solution in the tests).
#: ``plate_waves='auto'`` skips Zener where this bound times lambda is below the tolerance.
ZENER_SLOPE_BOUND = 1.731

#: (name, unit, check) of every model parameter, in the order of :func:`impact`.
PARAMETERS = (
    ("sphere_E", "Pa", "positive"), ("sphere_nu", "1", "poisson"), ("sphere_Sy", "Pa", "positive"),
    ("sphere_rho", "kg/m3", "positive"), ("sphere_d", "m", "positive"),
    ("plate_E", "Pa", "positive"), ("plate_nu", "1", "poisson"), ("plate_Sy", "Pa", "positive"),
    ("plate_rho", "kg/m3", "positive"), ("plate_t", "m", "positive"),
)


#: The domain the FMUs declare (min/max in modelDescription.xml) and the property tests cover, per
#: argument of :func:`impact`: (low, high) [SI units of :data:`PARAMETERS`], both included; nu has
#: its own [0, 0.5). Inside it every output is finite except the documented infinities (m_eff for
#: e_ze = 1, T at v = 0, the linear method's tau0 and t_contact for lambda >= 2): wide enough for
#: any solid (foams to osmium, rubber to diamond; BRITTLE_SY = 1e12 Pa included), spheres from
#: 1 um to 10 m, plates from 0.1 um to 100 m, speeds up to 10 km/s. :func:`impact` itself accepts
#: any positive value, where intermediate results may leave double range (over- or underflow).
DOMAIN = {
    "v": (0.0, 1e4),
    "sphere_E": (1e5, 1e13), "sphere_Sy": (1e3, 1e13), "sphere_rho": (1.0, 1e5), "sphere_d": (1e-6, 10.0),
    "plate_E": (1e5, 1e13), "plate_Sy": (1e3, 1e13), "plate_rho": (1.0, 1e5), "plate_t": (1e-7, 100.0),
}

#: The largest ``edge_echo`` the FMUs and the sweep tables publish [1] (:func:`published`): an unbounded
#: plate (or no contact) has an infinite echo ratio, and every published output must be finite.
#: 1e9 contact times is far beyond any echo that matters (the monitor's threshold is 1).
EDGE_ECHO_PUBLISHED_MAX = 1e9


def check_edge_distance(value):
    """The distance [m] from the impact point to the plate's nearest edge: >= 0, where 0 and +inf
    both mean an unbounded plate (Zener's assumption; 0 is how the FMUs say it, their values being
    finite); ValueError otherwise (negative, NaN)."""
    return check_nonnegative_or_infinite("plate.edge_distance", value, "m", ">= 0 (0 or inf: an unbounded plate)")


_PARAMETER_CHECKS = tuple((name, name.replace("_", ".", 1), unit, kind) for name, unit, kind in PARAMETERS)


def validate_parameters(**params) -> dict:
    """Check each parameter named in :data:`PARAMETERS`; ValueError naming the first bad one."""
    checked = {}
    for name, label, unit, kind in _PARAMETER_CHECKS:
        if kind == "poisson":
            checked[name] = check_poisson(label, params[name])
        else:
            checked[name] = check_positive(label, params[name], unit)
    return checked


#: The annotations of :class:`ImpactResult`'s fields: a real (a float, or an array of floats) or a flag
#: (a bool, or an array of bools). The C record of one impact and the equivalence tests read them
#: (:data:`RECORD_REALS`, :data:`RECORD_FLAGS`): a field's annotation is its C type (double or int).
Real = object
Flag = object


@dataclass(frozen=True)
class ImpactResult:
    """Everything one impact (or one array of impacts) produces. Units in brackets."""

    e: Real  #: apparent COR, Eq. (20) [1]
    v_rebound: Real  #: sphere speed away from the plate after impact, e * v [m/s]
    e_ep: Real  #: elastoplastic COR, Eq. (7) or (8) [1]
    V_c: Real  #: critical (yield onset) velocity, Eq. (6) [m/s]
    V_star: Real  #: normalised impact speed v / V_c [1]
    eps_y: Real  #: yield strain, Eq. (3) [1]
    e_ze: Real  #: Zener's COR [1]
    lam: Real  #: Zener's parameter lambda, Eq. (12) [1]
    tau0: Real  #: dimensionless contact time [1]
    T: Real  #: Zener's time unit, Eq. (9) [s]
    t_contact: Real  #: contact duration T tau0 [s] (0 when v = 0: no impact)
    m_a: Real  #: sphere mass [kg]
    m_eff: Real  #: equivalent plate mass, Eq. (19) [kg] (+inf for e_ze = 1)
    mass_ratio: Real  #: m_a / m_eff = (1 - e_ze)/(1 + e_ze), Eq. (19) [1], in [0, 1] (0 for e_ze = 1)
    v_plate: Real  #: plate velocity after impact, Eq. (17) [m/s]
    wave_delay: Real  #: Zener's ejection time over its half-space value, tau0(lambda)/tau0(0) [1] (section 4)
    edge_echo: Real  #: first dilatational edge echo 2a/c_L over the contact time [1] (+inf: unbounded plate)
    plasticity_used: Flag  #: JGM contributed (e_ep < 1 was applied)
    plate_waves_used: Flag  #: Zener contributed (e_ze was computed)
    lambda_in_range: Flag  #: lambda <= 1.5, Zener's studied range
    vstar_in_range: Flag  #: V* <= 1000, JGM's fit range
    e_negative: Flag  #: e < 0: the sphere keeps moving with the plate
    contact_ends: Flag  #: tau0 is finite (False: the linear method at lambda >= 2 never releases)
    concurrent: Flag  #: wave_delay <= 1.8136 (its value at lambda = 1.5): plastic and wave processes overlap
    edge_clear: Flag  #: edge_echo >= 1: no edge echo returns during the contact

    @property
    def valid(self):
        """Inside both models' validated ranges."""
        if is_scalar(self.lam):
            return self.lambda_in_range and self.vstar_in_range
        return np.logical_and(self.lambda_in_range, self.vstar_in_range)

    def as_dict(self) -> dict:
        d = dict(self.__dict__)  # the fields, in order: a frozen dataclass has no other instance attributes
        d["valid"] = self.valid
        return d

    def __repr__(self) -> str:
        """The answer and what qualifies it: e and its two parts, the rebound speed, where the impact
        sits in each model's range, and every flag (for arrays: the range of e and how many impacts
        raise each flag). Every field is also an attribute; :meth:`as_dict` gives them all."""
        if is_scalar(self.lam):
            return (f"ImpactResult: e = {self.e:.4g} (e_ep = {self.e_ep:.4g} elastoplastic, "
                    f"e_ze = {self.e_ze:.4g} plate waves), v_rebound = {self.v_rebound:.4g} m/s\n"
                    f"  V* = {self.V_star:.4g} (V_c = {self.V_c:.4g} m/s), lambda = {self.lam:.4g}, "
                    f"t_contact = {self.t_contact:.4g} s\n"
                    f"  valid = {self.valid}: lambda <= 1.5 (lambda_in_range) {self.lambda_in_range}, "
                    f"V* <= 1000 (vstar_in_range) {self.vstar_in_range}\n"
                    + "  " + ", ".join(f"{name} = {getattr(self, name)}" for name in _REPR_FLAGS) + "\n"
                    + "  monitors: " + ", ".join(f"{value} = {getattr(self, value):.4g} ({flag} {getattr(self, flag)})"
                                                 for value, flag in _REPR_MONITORS))
        e = np.asarray(self.e)
        n = e.size
        counts = ", ".join(f"{name} {int(np.count_nonzero(getattr(self, name)))}"
                           for name in ("lambda_in_range", "vstar_in_range") + _REPR_FLAGS
                           + tuple(flag for _value, flag in _REPR_MONITORS))
        finite = e[np.isfinite(e)]
        span = f"e in [{finite.min():.4g}, {finite.max():.4g}]" if finite.size else "no finite e"
        return (f"ImpactResult of {n} impacts, shape {e.shape}: {span}; valid at "
                f"{int(np.count_nonzero(self.valid))} of {n}\n  impacts with each flag true: {counts}")


#: The result record of one impact, in order: :class:`ImpactResult`'s real fields, then its flags and
#: ``valid`` (a property: both models inside their validated ranges). The C physics' ``rst_impact_result``
#: (generated by restitution.fmu.physics_c.result_header), the agreement of the package and the C
#: (:mod:`restitution.agreement`) and the tests' ctypes view are written from these two lists, so a new
#: field is one edit here (docs/adding_an_output.md).
RECORD_REALS = tuple(f.name for f in fields(ImpactResult) if f.type == "Real")
RECORD_FLAGS = tuple(f.name for f in fields(ImpactResult) if f.type == "Flag") + ("valid",)


#: The flags shown by ``repr`` beside ``valid`` and its two parts.
_REPR_FLAGS = ("plasticity_used", "plate_waves_used", "e_negative", "contact_ends")
#: The monitors of the assumptions, with their flags, shown by ``repr`` on a line of their own.
_REPR_MONITORS = (("wave_delay", "concurrent"), ("edge_echo", "edge_clear"))


#: Outputs that are +inf where the contact never ends (``contact_ends`` False: the linear method at
#: lambda >= 2, whose oscillator never returns to zero force).
ENDLESS = ("tau0", "t_contact", "wave_delay")


def published(values: dict) -> dict:
    """``values`` (:meth:`ImpactResult.as_dict`) as the FMUs and the sweep tables publish them: every
    value finite. Result writers (OMSimulator's, for one) drop a whole time point for one inf, so where
    the contact never ends tau0 and t_contact read 0 beside ``contact_ends`` = False, and the
    equivalent plate mass is published as ``mass_ratio`` (0 for a half-space) instead of m_eff = +inf;
    ``edge_echo`` is capped at :data:`EDGE_ECHO_PUBLISHED_MAX` (+inf for an unbounded plate) and
    ``wave_delay`` reads 0 with tau0 where the contact never ends.
    Nothing else changes; the package's own results keep the infinities."""
    ends, echo = values["contact_ends"], values["edge_echo"]
    if ends is True and echo.__class__ is float and echo <= EDGE_ECHO_PUBLISHED_MAX:  # one impact, a bounded plate
        return values
    out = dict(values)
    out["edge_echo"] = minimum(echo, EDGE_ECHO_PUBLISHED_MAX)
    if ends is True:
        return out
    for key in ENDLESS:
        out[key] = where(ends, values[key], 0.0)
    return out


def _mode(name, value):
    if value.__class__ is str and value in EFFECT_MODES:  # a word, the usual case: nothing to convert
        return value
    if isinstance(value, (int, np.integer)) and not isinstance(value, bool):
        if not 0 <= value < len(EFFECT_MODES):
            raise ValueError(f"{name} = {value!r} is not one of 0 = off, 1 = on, 2 = auto")
        return EFFECT_MODES[value]
    return check_choice(name, value, EFFECT_MODES)


@with_units(v="m/s", sphere_E="Pa", sphere_nu="dimensionless", sphere_Sy="Pa", sphere_rho="kg/m**3", sphere_d="m", plate_E="Pa", plate_nu="dimensionless", plate_Sy="Pa", plate_rho="kg/m**3", plate_t="m", plate_edge_distance="m")
def impact(v, sphere_E, sphere_nu, sphere_Sy, sphere_rho, sphere_d,
           plate_E, plate_nu, plate_Sy, plate_rho, plate_t, *, plate_edge_distance=math.inf,
           restitution_model: str = "e45", zener_method: str = "exact",
           plasticity="auto", plate_waves="auto", effect_tolerance: float = 1e-6,
           ode_rtol: float = 1e-10, validate: bool = True) -> ImpactResult:
    """Apparent COR and everything behind it for a sphere hitting a plate at normal speed ``v``.

    Parameters (units in brackets): ``v`` approach speed [m/s] >= 0; sphere E [Pa],
    nu [1], Sy [Pa], rho [kg/m^3], d [m]; plate E, nu, Sy, rho, t [m].
    ``plate_edge_distance`` [m]: from the impact point to the plate's nearest edge, for the edge-echo
    monitor only (``edge_echo``, ``edge_clear``); +inf (default) or 0: an unbounded plate, Zener's assumption.
    ``restitution_model``: "e45" (Eq. 8, default) or "e44" (Eq. 7, second branch reconstructed).
    ``zener_method``: "exact" (default), "paper_fit", "linear" or "ode" (see :mod:`restitution.zener`).
    ``plasticity`` / ``plate_waves``: "on", "off" (e_ep = 1, resp. e_ze = 1) or "auto":
    skip the effect where its contribution to e is below ``effect_tolerance``
    (plasticity: V* <= 1 or 1 - e_ep < tol; plate waves: ZENER_SLOPE_BOUND * lambda < tol,
    which bounds 1 - e_ze). ``plate_waves="off"`` treats the plate as a half-space:
    e_ze = 1, tau0 = 3.2180655 (Hertz). Where "auto" skips the effect, e_ze = 1 and tau0 is
    the method's own value at lambda = 0 (Hertz for exact and ode, 3.215 for paper_fit, pi for
    linear), so tau0 and t_contact stay continuous at the skip threshold. ``ode_rtol`` is the tolerance of ``zener_method="ode"``.
    ``validate=False`` skips the input checks (for callers that already checked).

    Validity is reported, never clipped: ``lambda_in_range`` (<= 1.5), ``vstar_in_range``
    (<= 1000), ``e_negative``, and the monitors of the assumptions: ``wave_delay`` with ``concurrent``
    (<= 1.8136), ``edge_echo`` with ``edge_clear`` (>= 1); docs/assumptions.md. Bad input raises
    ValueError naming the parameter.
    """
    plasticity = _mode("plasticity", plasticity)
    plate_waves = _mode("plate_waves", plate_waves)
    if validate:
        check_choice("restitution_model", restitution_model, RESTITUTION_MODELS)
        check_choice("zener_method", zener_method, ZENER_METHODS)
        check_nonnegative("effect_tolerance", effect_tolerance)
        check_positive("ode_rtol", ode_rtol)
        v = check_nonnegative("v_approach", v, "m/s")
        (sphere_E, sphere_nu, sphere_Sy, sphere_rho, sphere_d, plate_E, plate_nu, plate_Sy, plate_rho,
         plate_t) = validate_parameters(
            sphere_E=sphere_E, sphere_nu=sphere_nu, sphere_Sy=sphere_Sy, sphere_rho=sphere_rho,
            sphere_d=sphere_d, plate_E=plate_E, plate_nu=plate_nu, plate_Sy=plate_Sy,
            plate_rho=plate_rho, plate_t=plate_t).values()
        plate_edge_distance = check_edge_distance(plate_edge_distance)
    params = (sphere_E, sphere_nu, sphere_Sy, sphere_rho, sphere_d, plate_E, plate_nu, plate_Sy, plate_rho, plate_t)
    if (v.__class__ is float and sphere_E.__class__ is float and sphere_nu.__class__ is float
            and sphere_Sy.__class__ is float and sphere_rho.__class__ is float and sphere_d.__class__ is float
            and plate_E.__class__ is float and plate_nu.__class__ is float and plate_Sy.__class__ is float
            and plate_rho.__class__ is float and plate_t.__class__ is float
            and plate_edge_distance.__class__ is float):
        # one impact in Python floats (the FMU's case; spelt out: a generator costs 10 % of the call)
        scalar = True
    else:
        scalar = is_scalar(v) and is_scalar(plate_edge_distance) and all(is_scalar(x) for x in params)
        if scalar:
            v, params, plate_edge_distance = float(v), tuple(map(float, params)), float(plate_edge_distance)
        else:
            # No up-front broadcast: what depends on the parameters only is computed once per
            # distinct parameter value, and a scalar parameter stays a Python float, so one sphere on
            # one pair of materials (a sweep in v and t) computes its material terms in floats, once.
            v = np.asarray(v, dtype=float)
            params = tuple(_float_or_array(x) for x in params)
            plate_edge_distance = _float_or_array(plate_edge_distance)
    return _pipeline(v, params, plate_edge_distance, scalar, restitution_model, zener_method, plasticity, plate_waves,
                     effect_tolerance, ode_rtol)


def _pipeline(v, params, edge_distance, scalar, restitution_model, zener_method, plasticity, plate_waves,
              effect_tolerance, ode_rtol) -> ImpactResult:
    """The model, written once for Python floats (``scalar``) and numpy arrays alike.

    Every step goes through the float-or-array helpers of :mod:`restitution._num` and the equations'
    own float-or-array forms; the differences are where results are stored and how many whole-array
    passes a step takes. Floats: a memoised material step and a direct fill of the result. Arrays:
    scalar parameters keep the material step in floats, computed once; each equation's array form
    works in place on its own temporaries; the masks of speed 0, of the auto skip of Zener and of the
    half-space are built only where one reduction (a minimum) shows a case needs them; owned output arrays.
    """
    sphere_E, sphere_nu, sphere_Sy, sphere_rho, sphere_d, plate_E, plate_nu, plate_Sy, plate_rho, plate_t = params

    # --- JGM, Eqs. (1)-(8)
    material_terms = (_material_terms_cached if scalar or all(x.__class__ is float for x in params)
                      else _material_terms)
    E_prime, eps_y, m_a, V_c, time_factor, lambda_factor, slowness = material_terms(
        sphere_E, sphere_nu, sphere_Sy, sphere_rho, sphere_d, plate_E, plate_nu, plate_Sy, plate_rho)
    V_star = v / V_c
    if plasticity == "off":
        e_ep = 1.0
    else:
        e_ep = (restitution_e45(V_star, eps_y) if restitution_model == "e45"
                else restitution_e44(V_star))
        if plasticity == "auto":
            e_ep = (where(1.0 - e_ep < effect_tolerance, 1.0, e_ep) if scalar
                    else _skip_small_loss(e_ep, effect_tolerance))

    # --- Zener, Eqs. (9)-(13a)
    v_root = v ** 0.2 if scalar else fifth_root(v)  # v^(1/5), in Eq. (12) and Eq. (9)
    lam = lambda_from_root(v_root, sphere_d, plate_t, lambda_factor)  # Eq. (12)
    # Eq. (9), +inf at v = 0; for arrays into v_root's own memory where the shapes allow (one array
    # fewer alive while Zener's table is read)
    T = time_scale_from_root(time_factor, v_root, None if scalar or np.shape(time_factor) not in (
        (), np.shape(v_root)) else v_root)
    del v_root
    if plate_waves == "auto":
        needed = ZENER_SLOPE_BOUND * lam >= effect_tolerance if scalar else _waves_needed(lam, effect_tolerance)
        skipped_tau0 = _TAU0_AT_LAMBDA0[zener_method]
    else:
        needed = plate_waves == "on"
        skipped_tau0 = TAU0_HERTZ
    e_ze, d_ze, tau0 = _zener_where_needed(lam, needed, zener_method, ode_rtol, skipped_tau0, scalar)

    moving = v > 0.0 if scalar else _moving(v)
    t_contact = where(moving, contact_duration(T, tau0), 0.0)  # T tau0 = inf where not moving: replaced

    # --- Fusion, Eqs. (17)-(20)
    e = apparent_restitution(e_ep, e_ze)
    ratio = mass_ratio(e_ze, d_ze)
    m_eff = plate_mass_from_ratio(m_a, ratio)
    v_plate = plate_velocity_after_impact(v, e_ep, d_ze)

    # --- Monitors of the assumptions (sections 3 and 4): where Zener was skipped or off, the
    # half-space contact is the reference itself
    delay = where(needed, wave_delay(tau0, _TAU0_AT_LAMBDA0[zener_method]), 1.0)
    echo = edge_echo_ratio(edge_distance, slowness, t_contact)

    values = (e, e * v, e_ep, V_c, V_star, eps_y, e_ze, lam, tau0, T, t_contact, m_a, m_eff, ratio, v_plate,
              delay, echo,
              e_ep < 1.0, needed, lambda_in_studied_range(lam), vstar_in_fit_range(V_star), e < 0.0,
              tau0 < math.inf, waves_concurrent(delay), edge_clear(echo))
    out = object.__new__(ImpactResult)  # frozen dataclass: fill __dict__ directly, ~5x faster
    if scalar:  # every value is already a Python float or bool (math-module paths; the tests check it)
        out.__dict__.update(zip(_FIELD_NAMES, values))
        return out
    shape = np.broadcast_shapes(v.shape, np.shape(edge_distance), *(np.shape(x) for x in params))
    out.__dict__.update((name, _own_array(value, shape, bool if name in _FLAGS else float))
                        for name, value in zip(_FIELD_NAMES, values))
    return out


#: tau0 [1] of each Zener method at lambda = 0: what ``plate_waves="auto"`` reports where it skips
#: the effect (the half-space Hertz value would jump by 2.4 % from the linear method's pi, 0.1 %
#: from the paper fit's 3.215, at the skip threshold).
_TAU0_AT_LAMBDA0 = {"exact": TAU0_HERTZ, "ode": TAU0_HERTZ, "paper_fit": zener_paper_fit(0.0)[1],
                    "linear": zener_linear(0.0)[1]}

_FLAGS = frozenset(f.name for f in fields(ImpactResult) if f.type == "Flag")
_FIELD_NAMES = tuple(f.name for f in fields(ImpactResult))


def _own_array(x, shape, dtype):
    """``x`` as an array of ``shape`` and ``dtype`` that no other field or input shares.

    A temporary that already is one is used as is (copying 1e5-element results cost as
    much as computing them); anything else (scalars, views) is broadcast and copied. Every value
    the pipeline hands over is a fresh temporary or a scalar, never an input and never the same
    object twice (tests/physics/test_model_contract.py checks that no field shares memory with an input
    or another field, in every effect mode), so an owned array of the right kind is safe to keep.
    """
    if x.__class__ is np.ndarray and x.shape == shape and x.dtype == dtype and x.flags.owndata:
        return x
    if np.ndim(x) == 0:  # a value shared by every case (a material term, a flag): one fill
        return np.full(shape, x, dtype=dtype)
    return np.broadcast_to(x, shape).astype(dtype)


def _material_terms(sphere_E, sphere_nu, sphere_Sy, sphere_rho, sphere_d, plate_E, plate_nu, plate_Sy,
                    plate_rho):
    """What depends on the materials and the sphere only: (E' [Pa], eps_y [1], m_a [kg], V_c [m/s],
    :func:`restitution.zener.time_scale_factor` of the Hertz stiffness, :func:`restitution.zener.lambda_material_factor`
    and the plate's dilatational slowness 1/c_L [s/m]), Eqs. (1)-(6), the speed-free parts of Eqs. (9)
    and (12), and the edge monitor's wave speed."""
    E_prime = effective_modulus(sphere_E, sphere_nu, plate_E, plate_nu)
    CSy = critical_pressure(sphere_nu, sphere_Sy, plate_nu, plate_Sy)
    eps_y = yield_strain(E_prime, sphere_nu, sphere_Sy, plate_nu, plate_Sy)
    R = 0.5 * sphere_d
    m_a = sphere_mass(sphere_rho, sphere_d)
    V_c = critical_velocity(critical_interference(CSy, E_prime, R), critical_load(CSy, E_prime, R), m_a)
    return (E_prime, eps_y, m_a, V_c, time_scale_factor(m_a, hertz_stiffness(E_prime, sphere_d)),
            lambda_material_factor(sphere_E, sphere_nu, sphere_rho, plate_E, plate_nu, plate_rho),
            dilatational_slowness(plate_E, plate_nu, plate_rho))


#: :func:`_material_terms` memoised for Python floats (a pure function): a co-simulation or a
#: sweep in v pays for it once.
_material_terms_cached = lru_cache(maxsize=64)(_material_terms)


def _float_or_array(x):
    """A scalar input as a Python float, anything else as a float array."""
    return float(x) if is_scalar(x) else np.asarray(x, dtype=float)


def _skip_small_loss(e_ep, tolerance):
    """``plasticity="auto"`` on arrays: e_ep = 1 where the plastic loss 1 - e_ep is below ``tolerance``, in
    place (e_ep is a fresh result of Eq. 7 or 8, no one else's), by one comparison with
    :func:`_loss_threshold`: the same cases as 1 - e_ep < tolerance, without the array of 1 - e_ep."""
    if np.ndim(e_ep) == 0:
        return where(1.0 - e_ep < tolerance, 1.0, e_ep)
    threshold = _loss_threshold(tolerance)
    np.copyto(e_ep, 1.0, where=(e_ep > threshold) if threshold is not None else np.subtract(1.0, e_ep) < tolerance)
    return e_ep


@lru_cache(maxsize=8)
def _loss_threshold(tolerance):
    """The largest float below or at 1 - ``tolerance`` (exactly, not rounded to nearest), or None for a
    tolerance above 1/2. For e_ep in [1/2, 1], 1 - e_ep is exact (Sterbenz), so the floating-point
    1 - e_ep < tolerance holds exactly where e_ep > 1 - tolerance, i.e. where e_ep exceeds this float;
    below 1/2 neither holds (1 - e_ep > 1/2 >= tolerance, and the threshold is >= 1/2); e_ep never exceeds 1."""
    if not 0.0 <= tolerance <= 0.5:
        return None
    exact = Fraction(1) - Fraction(tolerance)
    threshold = float(exact)  # rounded to nearest: one step down if that went up
    return threshold if Fraction(threshold) <= exact else math.nextafter(threshold, -math.inf)


def _moving(v):
    """v > 0 [m/s], an impact at all, of an array: one True when every speed is positive (the masks it
    selects by then cost nothing), else the mask."""
    if v.size and v.min() > 0.0:  # min propagates NaN: not > 0, and the mask decides
        return True
    return v > 0.0


def _waves_needed(lam, tolerance):
    """Where ``plate_waves="auto"`` computes Zener on arrays: ZENER_SLOPE_BOUND * lambda >= ``tolerance``;
    one True when the smallest lambda passes (the product is non-decreasing in lambda, so then every case
    does), else the mask."""
    lam = np.asarray(lam)
    if lam.size and ZENER_SLOPE_BOUND * lam.min() >= tolerance:
        return True
    return ZENER_SLOPE_BOUND * lam >= tolerance


def _zener_where_needed(lam, needed, method, rtol, skipped_tau0, scalar):
    """(e_ze, 1 - e_ze, tau0), computed only where the plate-wave effect is needed;
    (1, 0, ``skipped_tau0``) elsewhere."""
    if scalar:
        return zener_solution(lam, method, rtol) if needed else (1.0, 0.0, skipped_tau0)
    lam = np.asarray(lam)  # float already: Eq. (12) of float arrays
    needed = np.broadcast_to(needed, lam.shape)
    if needed.all():  # elementwise methods: same values as the masked evaluation, no gather/scatter
        return zener_solution(lam, method, rtol)
    e_ze, d_ze, tau0 = np.ones(lam.shape), np.zeros(lam.shape), np.full(lam.shape, skipped_tau0)
    if needed.any():
        e_ze[needed], d_ze[needed], tau0[needed] = zener_solution(lam[needed], method, rtol)
    return e_ze, d_ze, tau0
