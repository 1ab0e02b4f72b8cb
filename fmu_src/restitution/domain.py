"""The values each input of the model may take, in one place: the checks every value passes (finite, of
the right sign, nu in [0, 0.5], one of an option's words: :func:`check_positive` and its siblings, the
words in :data:`RESTITUTION_MODELS`, :data:`ZENER_METHODS`, :data:`EFFECT_MODES`), and the model's domain:
the values of each physical input that every front end accepts (the package's
objects and :func:`restitution.impact`, the FMUs, scenes, sweeps, ``restitution cor`` and ``fit``),
and the one-line refusal of a value outside it, with the unit the value was likely meant in:

    plate.E = 114 Pa is outside 1e+05 <= value <= 1e+13 Pa: did you mean 114 GPa?

A bare number is SI everywhere, so the usual slip is a number meant in a prefixed unit (GPa, MPa, mm).
The domain is wide (foams to osmium, rubber to diamond, spheres of 1 um to 10 m, plates of 0.1 um to
100 m, speeds to 10 km/s): a value outside it is a slip, never a material.
"""
from __future__ import annotations

import math
import warnings

import numpy as np

from ._num import is_scalar

__all__ = ["DOMAIN", "PREFIXED", "TYPICAL", "DomainWarning", "slipped_prefix", "outside_text", "outside_domain",
           "check_in_domain", "warn_outside_domain", "number_text", "RESTITUTION_MODELS", "ZENER_METHODS",
           "EFFECT_MODES", "check_positive", "check_nonnegative", "check_nonnegative_or_infinite", "check_poisson",
           "check_choice"]

# The words of restitution.impact()'s named options, in order (an option's integer code in the FMUs is its
# word's position): the interface tables and the command lines list them, model and zener act on them.
#: ``restitution_model``: the elastoplastic COR by Eq. (45) or Eq. (44) of JGM.
RESTITUTION_MODELS = ("e45", "e44")
#: ``zener_method``: how Zener's (e_ze, tau0) is found (:mod:`restitution.zener`).
ZENER_METHODS = ("exact", "paper_fit", "linear", "ode")
#: ``plasticity`` and ``plate_waves``: each effect off, on, or on where it matters.
EFFECT_MODES = ("off", "on", "auto")

#: The domain the FMUs declare (min/max in modelDescription.xml) and the property tests cover, per
#: argument of :func:`restitution.impact`: (low, high) [SI], both included; nu has its own [0, 0.5].
#: Inside it every output is finite except the documented infinities (m_eff for e_ze = 1, T at v = 0,
#: the linear method's tau0 and t_contact for lambda >= 2): wide enough for any solid (BRITTLE_SY =
#: 1e12 Pa included), spheres from 1 um to 10 m, plates from 0.1 um to 100 m, speeds up to 10 km/s.
DOMAIN = {
    "v": (0.0, 1e4),
    "sphere_E": (1e5, 1e13), "sphere_Sy": (1e3, 1e13), "sphere_rho": (1.0, 1e5), "sphere_d": (1e-6, 10.0),
    "plate_E": (1e5, 1e13), "plate_Sy": (1e3, 1e13), "plate_rho": (1.0, 1e5), "plate_t": (1e-7, 100.0),
}

#: A typical value of each quantity of :data:`DOMAIN` (by the part after ``sphere_`` / ``plate_``) [SI]:
#: of the prefixed units that would bring a refused value into the domain, the hint names the one
#: that brings it nearest (in decades) to this.
TYPICAL = {"v": 2.0, "E": 1e11, "Sy": 5e8, "rho": 5e3, "d": 1e-2, "t": 5e-3}

#: The prefixed units a slip of an SI prefix suggests: SI unit -> {factor to SI: unit}. A value
#: outside the range that lands in it times a factor (1e3, 1e6, 1e9 or 1e-3) was likely meant in
#: that unit (``plate.E = 114`` -> 114 GPa; ``plate.t = 3000`` -> 3000 mm).
PREFIXED = {"m": {1e-3: "mm"}, "Pa": {1e3: "kPa", 1e6: "MPa", 1e9: "GPa"},
            "m/s": {1e-3: "mm/s", 1e3: "km/s"}, "kg/m3": {1e3: "g/cm3"}}


def number_text(value: float) -> str:
    return f"{value:.15g}"


def slipped_prefix(value: float, unit: str, accepts, typical: float) -> str | None:
    """``"114 GPa"`` where ``value`` (SI, refused) is accepted (``accepts(SI value) -> bool``) once read
    in a prefixed unit of :data:`PREFIXED` ``[unit]``: of those that bring it in, the one nearest (in
    decades) to ``typical``; None where none does."""
    best = None
    for factor, prefixed in PREFIXED.get(unit, {}).items():
        meant = value * factor
        if meant > 0 < typical and accepts(meant):
            distance = abs(math.log10(meant / typical))
            if best is None or distance < best[0]:
                best = (distance, prefixed)
    return None if best is None else f"{number_text(value)} {best[1]}"


def outside_text(label: str, value: float, unit: str | None, allowed: str, hint: str | None = None) -> str:
    """The one wording of a value refused for lying outside its range, whatever front end read it (the
    objects, :func:`restitution.impact`, the command lines, sweeps, scenes): ``plate.E = 114 Pa is outside
    100000 <= value <= 1e+13 Pa: did you mean 114 GPa?``. ``value`` [SI], ``unit`` its SI unit (None or
    "": dimensionless), ``allowed`` the range as text, ``hint`` the value as it was likely meant
    (:func:`slipped_prefix`)."""
    suffix = f" {unit}" if unit else ""
    message = f"{label} = {number_text(value)}{suffix} is outside {allowed}{suffix}"
    return f"{message}: did you mean {hint}?" if hint else message


class DomainWarning(UserWarning):
    """A value outside the model's domain given to :func:`restitution.impact`, which computes it anyway."""


def outside_domain(label: str, key: str, value, unit: str) -> str | None:
    """The one-line refusal of ``value`` (a number or an array, SI, already checked finite) for
    :data:`DOMAIN` ``[key]``, naming ``label``, the first value outside and the prefixed unit it was
    likely meant in; None where every value lies inside."""
    low, high = DOMAIN[key]
    if value.__class__ is float and low <= value <= high:  # the usual call: one comparison
        return None
    if is_scalar(value):
        bad = float(value)
        if low <= bad <= high:
            return None
    else:
        arr = np.asarray(value, dtype=float)
        if arr.size == 0 or (low <= arr.min() and arr.max() <= high):
            return None
        bad = float(arr[(arr < low) | (arr > high)].flat[0])
    hint = slipped_prefix(bad, unit, lambda x: low <= x <= high, TYPICAL[key.split("_", 1)[-1]])
    return outside_text(label, bad, unit, f"{low:g} <= value <= {high:g}", hint)


def check_in_domain(label: str, key: str, value, unit: str):
    """``value`` if it lies in :data:`DOMAIN` ``[key]``, else ValueError (:func:`outside_domain`'s line)."""
    message = outside_domain(label, key, value, unit)
    if message:
        raise ValueError(message)
    return value


def warn_outside_domain(label: str, key: str, value, unit: str, stacklevel: int = 2):
    """``value``, after a :class:`DomainWarning` (:func:`outside_domain`'s line) if it leaves
    :data:`DOMAIN` ``[key]``: for :func:`restitution.impact`, the equations, which are defined beyond
    the domain and computed there (the model's limits, its tests, a study of the asymptotes)."""
    message = outside_domain(label, key, value, unit)
    if message:
        warnings.warn(f"{message} (outside the domain the FMUs, the objects and the command lines accept; "
                      f"impact() computes it anyway)", DomainWarning, stacklevel=stacklevel + 1)
    return value


# --- the checks every value passes: a ValueError naming the parameter, its value and the allowed range
def _check(name, value, unit, ok_scalar, ok_array, allowed):
    if is_scalar(value):
        v = float(value)
        if not ok_scalar(v):
            raise ValueError(f"{name} = {v!r}{unit} is outside the allowed range: {allowed}")
        return v
    arr = np.asarray(value, dtype=float)
    if arr.size and ok_scalar(float(arr.min())) and ok_scalar(float(arr.max())):
        # every range allowed here is an interval, so its two ends decide for the whole array: two
        # reductions instead of an elementwise mask (NaN propagates through min and max: refused, and
        # the mask below finds it)
        return arr
    with np.errstate(invalid="ignore"):
        good = ok_array(arr)
    if not np.all(good):
        bad_value = float(arr[~good].flat[0]) if arr.ndim else float(arr)
        raise ValueError(f"{name} = {bad_value!r}{unit} is outside the allowed range: {allowed}")
    return arr


def check_positive(name: str, value, unit: str = ""):
    """Require finite values > 0."""
    if value.__class__ is float and 0.0 < value < math.inf:  # fast path, same result
        return value
    u = f" {unit}" if unit else ""
    return _check(name, value, u, lambda v: math.isfinite(v) and v > 0.0,
                  lambda a: np.isfinite(a) & (a > 0.0), "finite and > 0")


def check_nonnegative(name: str, value, unit: str = ""):
    """Require finite values >= 0."""
    if value.__class__ is float and 0.0 <= value < math.inf:  # fast path, same result
        return value
    u = f" {unit}" if unit else ""
    return _check(name, value, u, lambda v: math.isfinite(v) and v >= 0.0,
                  lambda a: np.isfinite(a) & (a >= 0.0), "finite and >= 0")


def check_nonnegative_or_infinite(name: str, value, unit: str = "", allowed: str = ">= 0"):
    """Require values >= 0, +inf included (NaN refused); ``allowed`` says what the range means."""
    if value.__class__ is float and value >= 0.0:  # fast path, same result
        return value
    u = f" {unit}" if unit else ""
    return _check(name, value, u, lambda v: v >= 0.0, lambda a: a >= 0.0, allowed)


def check_poisson(name: str, value):
    """Require a Poisson's ratio in [0, 0.5] (0.5: incompressible; the model uses nu only through
    E' = E/(1 - nu^2), Eq. 1, and C(nu), Eq. 2, both finite there)."""
    if value.__class__ is float and 0.0 <= value <= 0.5:  # fast path, same result
        return value
    return _check(name, value, "", lambda v: 0.0 <= v <= 0.5,
                  lambda a: (a >= 0.0) & (a <= 0.5), "0 <= nu <= 0.5")


def check_choice(name: str, value, choices):
    if value not in choices:
        raise ValueError(f"{name} = {value!r} is not one of {sorted(choices)}")
    return value
