"""The whole model: apparent COR of a sphere hitting a plate of finite thickness,
I. Green, Nonlinear Dyn (2022), JGM (Eqs. 1-8) and Zener (Eqs. 9-13a) fused by Eq. (20).

:func:`impact` takes Python floats (one impact) or numpy arrays (broadcast together, one
result per element); one pipeline, :func:`_pipeline`, serves both, after :func:`_terms` has computed what
depends on the parameters only. Both steps are public too: :func:`impact_terms` once per parameter set,
:func:`impact_at` per speed (a co-simulation's steps).
"""
from __future__ import annotations

import math
from dataclasses import fields
from functools import lru_cache
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from . import fusion, jgm, zener
from ._array_steps import _moving, _own_array, _skip_small_loss, _waves_needed
from ._num import fifth_root, is_scalar, where
from .fusion import apparent_restitution, mass_ratio, plate_mass_from_ratio, plate_velocity_after_impact
from .jgm import restitution_e44, restitution_e45, vstar_in_fit_range
from .domain import (DOMAIN, EFFECT_MODES, RESTITUTION_MODELS, check_choice, check_nonnegative,
                     check_nonnegative_or_infinite, check_poisson, check_positive, warn_outside_domain)
from .quantities import si_only, with_units
from .record import (_LAMBDA_OK_AT, _VSTAR_OK_AT, EDGE_ECHO_PUBLISHED_MAX, ENDLESS, RECORD, RECORD_FLAGS,  # noqa: F401
                     RECORD_REALS, ImpactResult, _both, published)  # (EDGE_ECHO_PUBLISHED_MAX, ENDLESS: public here too)
from .zener import (TAU0_HERTZ, ZENER_METHODS, edge_clear, edge_echo_ratio_from_time, lambda_from_root,
                    lambda_in_studied_range, lambda_material_factor, lambda_speed_factor, time_scale_factor,
                    time_scale_from_root, wave_delay, waves_concurrent, zener_linear, zener_paper_fit, zener_restitution_only,
                    zener_restitution_where, zener_solution, zener_solution_where)

if TYPE_CHECKING:  # loaded by impact(outputs=...) when a caller chooses its outputs
    from ._output_steps import Wanted

# The pipeline passes SI numbers it has checked: it calls the equations without their unit layer
# (restitution.quantities), which would cost more than the equations on the scalar path.
(critical_interference, critical_load, critical_pressure, critical_velocity, effective_modulus, sphere_mass,
 yield_strain) = map(si_only, (jgm.critical_interference, jgm.critical_load, jgm.critical_pressure,
                               jgm.critical_velocity, jgm.effective_modulus, jgm.sphere_mass, jgm.yield_strain))
(contact_duration, hertz_stiffness, dilatational_slowness, edge_echo_time) = map(
    si_only, (zener.contact_duration, zener.hertz_stiffness, zener.dilatational_slowness, zener.edge_echo_time))

__all__ = ["ImpactResult", "impact", "ImpactTerms", "impact_terms", "impact_at", "impact_record_at", "RECORD",
           "published", "RESTITUTION_MODELS", "EFFECT_MODES", "ZENER_SLOPE_BOUND",
           "PARAMETERS", "DOMAIN", "validate_parameters", "RECORD_REALS", "RECORD_FLAGS", "EDGE_ECHO_PUBLISHED_MAX",
           "check_edge_distance", "output_dependencies"]

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


def check_edge_distance(value):
    """The distance [m] from the impact point to the plate's nearest edge: >= 0, where 0 and +inf
    both mean an unbounded plate (Zener's assumption; 0 is how the FMUs say it, their values being
    finite); ValueError otherwise (negative, NaN)."""
    return check_nonnegative_or_infinite("plate.edge_distance", value, "m", ">= 0 (0 or inf: an unbounded plate)")


_PARAMETER_NAMES = tuple(name for name, _unit, _kind in PARAMETERS)
_PARAMETER_CHECKS = tuple((name, name.replace("_", ".", 1), unit, kind) for name, unit, kind in PARAMETERS)


def validate_parameters(**params) -> dict:
    """Check each parameter named in :data:`PARAMETERS`: ValueError naming the first that is not finite
    and positive (nu: in [0, 0.5]); a :class:`~restitution.domain.DomainWarning` for one outside the
    model's :data:`~restitution.domain.DOMAIN`, with the unit it was likely meant in."""
    checked = {}
    for name, label, unit, kind in _PARAMETER_CHECKS:
        if kind == "poisson":
            checked[name] = check_poisson(label, params[name])
        else:
            checked[name] = warn_outside_domain(label, name, check_positive(label, params[name], unit), unit,
                                                stacklevel=_CALLER)
    return checked


#: warnings.warn's stacklevel from validate_parameters / check_speed to the code that called impact(),
#: impact_terms() or impact_at() (through the units wrapper where there is one): the line a warning names
_CALLER = 4


def check_speed(v):
    """The approach speed [m/s]: ValueError unless finite and >= 0; a DomainWarning above 10 km/s."""
    return warn_outside_domain("v_approach", "v", check_nonnegative("v_approach", v, "m/s"), "m/s", stacklevel=_CALLER)


def _mode(name, value):
    if value.__class__ is str and value in EFFECT_MODES:  # a word, the usual case: nothing to convert
        return value
    if isinstance(value, (int, np.integer)) and not isinstance(value, bool):
        if not 0 <= value < len(EFFECT_MODES):
            raise ValueError(f"{name} = {value!r} is not one of 0 = off, 1 = on, 2 = auto")
        return EFFECT_MODES[value]
    return check_choice(name, value, EFFECT_MODES)


_UNITS = dict(sphere_E="Pa", sphere_nu="dimensionless", sphere_Sy="Pa", sphere_rho="kg/m**3", sphere_d="m",
              plate_E="Pa", plate_nu="dimensionless", plate_Sy="Pa", plate_rho="kg/m**3", plate_t="m",
              plate_edge_distance="m")


@with_units(v="m/s", **_UNITS)
def impact(v, sphere_E, sphere_nu, sphere_Sy, sphere_rho, sphere_d,
           plate_E, plate_nu, plate_Sy, plate_rho, plate_t, *, plate_edge_distance=math.inf,
           restitution_model: str = "e45", zener_method: str = "exact",
           plasticity="auto", plate_waves="auto", effect_tolerance: float = 1e-6,
           ode_rtol: float = 1e-10, validate: bool = True, outputs=None):
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

    ``outputs``: None (default) gives the whole :class:`ImpactResult`. A sequence of names from
    :data:`RECORD` (its fields and ``valid``) gives a dict of those values only, in the order asked, and
    limits the work to them and what they depend on (:func:`output_dependencies`): ``outputs=("e",
    "v_rebound")`` computes neither the contact time nor the monitors nor Zener's contact time where it
    can skip them. Each value is the one the full result holds (the same operations). An unknown name
    raises ValueError naming it, whatever ``validate``.

    The equations are computed for any finite positive input. One outside the model's domain (the
    ranges the FMUs declare and :class:`Material`, :class:`Sphere`, :class:`Plate` and
    :func:`impact_between` refuse: :data:`restitution.domain.DOMAIN`) gives a
    :class:`~restitution.domain.DomainWarning` naming the unit it was likely meant in (``sphere_E =
    114``: did you mean 114 GPa?). Validity is reported, never clipped: ``lambda_in_range`` (<= 1.5), ``vstar_in_range``
    (<= 1000), ``e_negative``, and the monitors of the assumptions: ``wave_delay`` with ``concurrent``
    (<= 1.8136), ``edge_echo`` with ``edge_clear`` (>= 1); docs/assumptions.md. Bad input raises
    ValueError naming the parameter.

    ``impact(v, *p, **o)`` is ``impact_at(v, impact_terms(*p, **o))``: many speeds for one parameter set
    (a co-simulation's steps) make the terms once (:func:`impact_terms`, :func:`impact_at`).

    Over many cases (at least 131,072) the model runs a block of cases at a time (:mod:`restitution._blocks`),
    and the result's arrays of one kind (float, bool) are the rows of one allocation: each is contiguous,
    writable and shares no memory with another or with an input, but a row kept alone keeps its whole
    block alive (``res.e.copy()`` keeps e alone). Once a result is gone its blocks serve the next call (up
    to 256 MB of them are kept), so a run of large calls writes into memory the process already has.
    """
    want = None if outputs is None else _wanted(outputs)
    plasticity = _mode("plasticity", plasticity)
    plate_waves = _mode("plate_waves", plate_waves)
    if validate:
        _check_options(restitution_model, zener_method, effect_tolerance, ode_rtol)
        v = check_speed(v)
        (sphere_E, sphere_nu, sphere_Sy, sphere_rho, sphere_d, plate_E, plate_nu, plate_Sy, plate_rho,
         plate_t) = validate_parameters(
            sphere_E=sphere_E, sphere_nu=sphere_nu, sphere_Sy=sphere_Sy, sphere_rho=sphere_rho,
            sphere_d=sphere_d, plate_E=plate_E, plate_nu=plate_nu, plate_Sy=plate_Sy,
            plate_rho=plate_rho, plate_t=plate_t).values()
        plate_edge_distance = check_edge_distance(plate_edge_distance)
    terms = _terms((sphere_E, sphere_nu, sphere_Sy, sphere_rho, sphere_d, plate_E, plate_nu, plate_Sy, plate_rho,
                    plate_t), plate_edge_distance, restitution_model, zener_method, plasticity, plate_waves,
                   effect_tolerance, ode_rtol)
    if want is None:
        return _result(_pipeline(v, terms))
    return _pipeline(v, terms, want)


class ImpactTerms(NamedTuple):
    """What :func:`impact` computes before it needs the speed: the terms of every equation that depend on the
    parameters only (Python floats, or arrays where a parameter is one) and the options, as words. Made by
    :func:`impact_terms`, used by :func:`impact_at`. Units in brackets."""

    floats: bool  #: every parameter is a Python float (one impact per float speed)
    shape: tuple  #: the parameters' broadcast shape (() for floats)
    V_c: object  #: critical velocity, Eq. (6) [m/s]
    eps_y: object  #: yield strain, Eq. (3) [1]
    m_a: object  #: sphere mass [kg]
    time_factor: object  #: Zener's time unit without the speed, Eq. (9) [s^(4/5) m^(1/5)]
    lambda_factor: object  #: lambda / v^(1/5), Eq. (12) [(s/m)^(1/5)]
    echo_time: object  #: the edge echo's travel time 2a/c_L [s] (+inf: an unbounded plate)
    restitution_model: str
    zener_method: str
    plasticity: str  #: "off", "on" or "auto"
    plate_waves: str  #: "off", "on" or "auto"
    effect_tolerance: float
    ode_rtol: float
    skipped_tau0: float  #: tau0 [1] where Zener is not computed (off, or skipped by "auto")
    tau0_half_space: float  #: the method's tau0 at lambda = 0 [1], the reference of ``wave_delay``


@with_units(**_UNITS)
def impact_terms(sphere_E, sphere_nu, sphere_Sy, sphere_rho, sphere_d, plate_E, plate_nu, plate_Sy, plate_rho,
                 plate_t, *, plate_edge_distance=math.inf, restitution_model: str = "e45",
                 zener_method: str = "exact", plasticity="auto", plate_waves="auto", effect_tolerance: float = 1e-6,
                 ode_rtol: float = 1e-10, validate: bool = True) -> ImpactTerms:
    """Everything :func:`impact` computes from its arguments but the speed, for :func:`impact_at`: the same
    arguments as :func:`impact` without ``v``, checked the same way (``validate=False`` skips the checks)."""
    plasticity = _mode("plasticity", plasticity)
    plate_waves = _mode("plate_waves", plate_waves)
    params = (sphere_E, sphere_nu, sphere_Sy, sphere_rho, sphere_d, plate_E, plate_nu, plate_Sy, plate_rho, plate_t)
    if validate:
        _check_options(restitution_model, zener_method, effect_tolerance, ode_rtol)
        params = tuple(validate_parameters(**dict(zip(_PARAMETER_NAMES, params))).values())
        plate_edge_distance = check_edge_distance(plate_edge_distance)
    return _terms(params, plate_edge_distance, restitution_model, zener_method, plasticity, plate_waves,
                  effect_tolerance, ode_rtol)


@with_units(v="m/s")
def impact_at(v, terms: ImpactTerms, validate: bool = True) -> ImpactResult:
    """:func:`impact` at the approach speed ``v`` [m/s] (a float or an array), the rest of its arguments made
    into ``terms`` by :func:`impact_terms`: what a co-simulation evaluates per step. ``validate=False``
    skips the check of ``v`` (>= 0, finite)."""
    if validate:
        if not isinstance(terms, ImpactTerms):
            raise TypeError(f"terms must be an ImpactTerms (made by impact_terms), got {type(terms).__name__}")
        v = check_speed(v)
    return _result(_pipeline(v, terms))


@with_units(v="m/s")
def impact_record_at(v, terms: ImpactTerms, validate: bool = True) -> tuple:
    """The values of :func:`impact_at`'s result in the order of :data:`RECORD` (its fields, then ``valid``),
    without the :class:`ImpactResult` around them: a co-simulation's step at the least cost. ``validate=False``
    skips the check of ``v``."""
    if validate:
        if not isinstance(terms, ImpactTerms):
            raise TypeError(f"terms must be an ImpactTerms (made by impact_terms), got {type(terms).__name__}")
        v = check_speed(v)
    return _pipeline(v, terms)


def _result(values) -> ImpactResult:
    """The :class:`ImpactResult` of :func:`_pipeline`'s record (its fields: all but ``valid``, a property)."""
    out = object.__new__(ImpactResult)  # frozen dataclass: its __dict__ set directly, ~5x faster
    object.__setattr__(out, "__dict__", dict(zip(_FIELD_NAMES, values)))
    return out


def _check_options(restitution_model, zener_method, effect_tolerance, ode_rtol):
    check_choice("restitution_model", restitution_model, RESTITUTION_MODELS)
    check_choice("zener_method", zener_method, ZENER_METHODS)
    check_nonnegative("effect_tolerance", effect_tolerance)
    check_positive("ode_rtol", ode_rtol)


def _terms(params, edge_distance, restitution_model, zener_method, plasticity, plate_waves, effect_tolerance,
           ode_rtol) -> ImpactTerms:
    """:class:`ImpactTerms` of checked parameters (any real scalars or arrays): JGM's Eqs. (1)-(6), the
    speed-free parts of Eqs. (9) and (12), the edge echo's travel time.

    Scalars become Python floats. No up-front broadcast: what depends on the parameters only is computed
    once per distinct parameter value, and a scalar parameter stays a Python float, so one sphere on one
    pair of materials (a sweep in v and t) computes its material terms in floats, once (memoised)."""
    floats = edge_distance.__class__ is float and all(x.__class__ is float for x in params)
    if not floats:
        if is_scalar(edge_distance) and all(is_scalar(x) for x in params):
            params, edge_distance, floats = tuple(map(float, params)), float(edge_distance), True
        else:
            params = tuple(_float_or_array(x) for x in params)
            edge_distance = _float_or_array(edge_distance)
    sphere_E, sphere_nu, sphere_Sy, sphere_rho, sphere_d, plate_E, plate_nu, plate_Sy, plate_rho, plate_t = params
    material_terms = (_material_terms_cached if floats or all(x.__class__ is float for x in params)
                      else _material_terms)
    E_prime, eps_y, m_a, V_c, time_factor, lambda_material, slowness = material_terms(
        sphere_E, sphere_nu, sphere_Sy, sphere_rho, sphere_d, plate_E, plate_nu, plate_Sy, plate_rho)
    tau0_half_space = _TAU0_AT_LAMBDA0[zener_method]
    return ImpactTerms(
        floats, () if floats else np.broadcast_shapes(np.shape(edge_distance), *(np.shape(x) for x in params)),
        V_c, eps_y, m_a, time_factor, lambda_speed_factor(lambda_material, sphere_d, plate_t),
        edge_echo_time(edge_distance, slowness), restitution_model, zener_method, plasticity, plate_waves,
        effect_tolerance, ode_rtol, tau0_half_space if plate_waves == "auto" else TAU0_HERTZ, tau0_half_space)


def _pipeline(v, terms, want=None, raw=False):
    """The record (:data:`RECORD`: :class:`ImpactResult`'s fields in order, then ``valid``) at the speed ``v``,
    from the parameter-only ``terms``; written once for Python floats
    (``v`` a float and ``terms.floats``, the scalar mode) and numpy arrays alike.

    ``want`` (:func:`_wanted`): None for the whole record; else the dict of the asked outputs only, each
    step computed only where an asked output depends on it (:data:`_DEPENDS`). A step that runs runs the
    same operations in both modes, so an asked value is the record's.

    Every step goes through the float-or-array helpers of :mod:`restitution._num` and the equations'
    own float-or-array forms; the differences are where results are stored and how many whole-array
    passes a step takes. Floats: a direct fill of the result. Arrays: scalar parameters keep their terms
    in floats; each equation's array form works in place on its own temporaries; the masks of speed 0, of
    the auto skip of Zener and of the half-space are built only where one reduction (a minimum) shows a
    case needs them; owned output arrays. ``raw`` (the blocks of :func:`restitution._blocks.in_blocks`, which
    write each value into a row of their own): the array mode's values as computed, a value shared by every
    case a scalar, none copied.
    """
    (floats, shape, V_c, eps_y, m_a, time_factor, lambda_factor, echo_time, restitution_model, zener_method,
     plasticity, plate_waves, effect_tolerance, ode_rtol, skipped_tau0, tau0_half_space) = terms
    if v.__class__ is float and floats:
        scalar = True
    elif floats and is_scalar(v):
        v, scalar = float(v), True
    else:
        v, scalar = np.asarray(v, dtype=float), False
        from ._blocks import blockable, in_blocks  # the array mode's alone (`restitution cor` loads it not)

        if blockable(v, terms):  # many cases: the same steps a cache-sized block at a time
            return in_blocks(_pipeline, v, terms, want, _dtype_of)
    every = want is None
    need = None if every else want.steps  # the outputs and every step they depend on
    e_ep = e_ze = d_ze = tau0 = T = t_contact = e = ratio = delay = echo = None  # the steps not needed

    # --- JGM, Eqs. (1)-(8)
    V_star = v / V_c
    if every or "e_ep" in need:
        if plasticity == "off":
            e_ep = 1.0
        else:
            e_ep = (restitution_e45(V_star, eps_y) if restitution_model == "e45"
                    else restitution_e44(V_star))
            if plasticity == "auto":
                e_ep = ((1.0 if 1.0 - e_ep < effect_tolerance else e_ep) if scalar
                        else _skip_small_loss(e_ep, effect_tolerance))

    # --- Zener, Eqs. (9)-(13a)
    v_root = v ** 0.2 if scalar else fifth_root(v)  # v^(1/5), in Eq. (12) and Eq. (9)
    lam = lambda_from_root(v_root, lambda_factor)  # Eq. (12)
    # Eq. (9), +inf at v = 0; for arrays into v_root's own memory where the shapes allow (one array
    # fewer alive while Zener's table is read)
    if every or "T" in need:
        T = time_scale_from_root(time_factor, v_root, None if scalar or np.shape(time_factor) not in (
            (), np.shape(v_root)) else v_root)
    del v_root
    if plate_waves == "auto":
        needed = ZENER_SLOPE_BOUND * lam >= effect_tolerance if scalar else _waves_needed(lam, effect_tolerance, ZENER_SLOPE_BOUND)
    else:
        needed = plate_waves == "on"
    if every or "zener" in need:
        if scalar:
            e_ze, d_ze, tau0 = zener_solution(lam, zener_method, ode_rtol) if needed else (1.0, 0.0, skipped_tau0)
        else:
            e_ze, d_ze, tau0 = zener_solution_where(lam, needed, zener_method, ode_rtol, skipped_tau0)
    elif "e_ze" in need:  # e_ze alone: no deficit, no contact time where the method can skip them
        e_ze = ((zener_restitution_only(lam, zener_method, ode_rtol) if needed else 1.0) if scalar
                else zener_restitution_where(lam, needed, zener_method, ode_rtol))

    # T tau0 = inf where not moving (v = 0): replaced by 0
    if every or "t_contact" in need:
        t_contact = ((contact_duration(T, tau0) if v > 0.0 else 0.0) if scalar
                     else where(_moving(v), contact_duration(T, tau0), 0.0))

    # --- Fusion, Eqs. (17)-(20)
    if every or "e" in need:
        e = apparent_restitution(e_ep, e_ze)
    if every or "mass_ratio" in need:
        ratio = mass_ratio(e_ze, d_ze)

    # --- The monitors of the assumptions (sections 3 and 4): where Zener was skipped or off, the half-space
    # contact is its own reference
    if every or "wave_delay" in need:
        delay = ((wave_delay(tau0, tau0_half_space) if needed else 1.0) if scalar
                 else where(needed, wave_delay(tau0, tau0_half_space), 1.0))
    if every or "edge_echo" in need:
        echo = edge_echo_ratio_from_time(echo_time, t_contact)

    lambda_ok = lambda_in_studied_range(lam) if every or "lambda_in_range" in need else None
    vstar_ok = vstar_in_fit_range(V_star) if every or "vstar_in_range" in need else None
    if every:
        values = (e, e * v, e_ep, V_c, V_star, eps_y, e_ze, lam, tau0, T, t_contact, m_a,
                  plate_mass_from_ratio(m_a, ratio), ratio, plate_velocity_after_impact(v, e_ep, d_ze), delay, echo,
                  e_ep < 1.0, needed, lambda_ok, vstar_ok, e < 0.0, tau0 < math.inf, waves_concurrent(delay),
                  edge_clear(echo))
        if scalar:  # every value is already a Python float or bool (math-module paths; the tests check it)
            return values + (lambda_ok and vstar_ok,)
        if raw:
            return values + (_both(lambda_ok, vstar_ok),)
        shape = np.broadcast_shapes(v.shape, shape)
        values = tuple(_own_array(value, shape, bool if name in _FLAGS else float)
                       for name, value in zip(_FIELD_NAMES, values))
        return values + (_both(values[_LAMBDA_OK_AT], values[_VSTAR_OK_AT]),)
    steps = dict(v=v, e=e, e_ep=e_ep, V_c=V_c, V_star=V_star, eps_y=eps_y, e_ze=e_ze, d_ze=d_ze, lam=lam, tau0=tau0, T=T,
                 t_contact=t_contact, m_a=m_a, mass_ratio=ratio, wave_delay=delay, edge_echo=echo,
                 plate_waves_used=needed, lambda_in_range=lambda_ok, vstar_in_range=vstar_ok)
    out = {name: _DERIVED[name](steps) if name in _DERIVED else steps[name] for name in want.names}
    if scalar or raw:
        return out
    shape = np.broadcast_shapes(v.shape, shape)
    return {name: _own_array(value, shape, float if name in _REALS else bool) for name, value in out.items()}


#: The record's values that are not a step of :func:`_pipeline` of their own, from its steps (by name), for
#: ``impact(outputs=...)``: the expressions of the whole record's, evaluated only where asked.
_DERIVED = {
    "v_rebound": lambda s: s["e"] * s["v"], "m_eff": lambda s: plate_mass_from_ratio(s["m_a"], s["mass_ratio"]),
    "v_plate": lambda s: plate_velocity_after_impact(s["v"], s["e_ep"], s["d_ze"]),
    "plasticity_used": lambda s: s["e_ep"] < 1.0, "e_negative": lambda s: s["e"] < 0.0,
    "contact_ends": lambda s: s["tau0"] < math.inf, "concurrent": lambda s: waves_concurrent(s["wave_delay"]),
    "edge_clear": lambda s: edge_clear(s["edge_echo"]), "valid": lambda s: _both(s["lambda_in_range"], s["vstar_in_range"]),
}


def output_dependencies(name: str) -> frozenset:
    """The outputs of :data:`RECORD` that :func:`impact` computes to give ``name`` (itself included);
    ValueError for a name not in :data:`RECORD`."""
    from ._output_steps import dependencies  # loaded by the callers that choose their outputs

    return dependencies(name, RECORD)


def _wanted(outputs) -> Wanted:
    """``impact(outputs=...)`` checked: one name, or a sequence of names (each kept once, in order)."""
    try:
        names = (outputs,) if isinstance(outputs, str) else tuple(dict.fromkeys(outputs))
    except TypeError:  # not a sequence of names
        raise ValueError(f"outputs = {outputs!r:.60} is not a name or a sequence of names of {RECORD}") from None
    from ._output_steps import wanted

    return wanted(names, RECORD)


#: tau0 [1] of each Zener method at lambda = 0: what ``plate_waves="auto"`` reports where it skips
#: the effect (the half-space Hertz value would jump by 2.4 % from the linear method's pi, 0.1 %
#: from the paper fit's 3.215, at the skip threshold).
_TAU0_AT_LAMBDA0 = {"exact": TAU0_HERTZ, "ode": TAU0_HERTZ, "paper_fit": zener_paper_fit(0.0)[1],
                    "linear": zener_linear(0.0)[1]}

_FLAGS = frozenset(f.name for f in fields(ImpactResult) if f.type == "Flag")
_FIELD_NAMES = tuple(f.name for f in fields(ImpactResult))
_REALS = frozenset(RECORD_REALS)


def _dtype_of(key) -> type:
    """float or bool: the dtype of a record's value, by its position in :data:`RECORD` or its name."""
    return float if (RECORD[key] if key.__class__ is int else key) in _REALS else bool


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
