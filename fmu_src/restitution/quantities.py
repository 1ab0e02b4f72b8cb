"""Physical quantities with units as inputs: every public function of the package that takes a
physical quantity also takes a pint Quantity of any compatible unit, converted to SI on entry; a
plain number is SI, as before. A Quantity of the wrong dimension is a ValueError naming the argument.

    import pint, restitution as r
    u = pint.UnitRegistry()
    r.Plate(r.MATERIALS["al_6061"], t=3 * u.mm)                     # t = 0.003 m
    r.impact(2.3 * u.m / u.s, ..., plate_t=0.125 * u.inch)

pint is never imported here (the FMUs bundle this package without pint): until the caller has
imported pint no argument can be a Quantity, and a call costs one dictionary lookup more; after,
one class check per argument. Results are plain SI numbers.
"""
from __future__ import annotations

import functools
import inspect
import sys

import numpy as np

__all__ = ["KINDS", "with_units", "to_si", "is_quantity", "si_only"]

#: SI unit (pint spelling) -> the kind of quantity it measures, for messages.
KINDS = {
    "m": "length", "kg": "mass", "s": "time", "m/s": "speed", "Pa": "pressure", "N": "force",
    "kg/m**3": "density", "m/s**2": "acceleration", "N/m**1.5": "Hertz contact stiffness",
    "dimensionless": "dimensionless number",
}

_MODULES = sys.modules
# Classes that are never Quantities: the common case costs one set lookup per argument.
_PLAIN = frozenset({float, int, bool, str, type(None), np.ndarray, np.float64, np.float32, np.int64, np.bool_})


def is_quantity(value) -> bool:
    """True for a pint Quantity (of any registry), without importing pint."""
    cls = value.__class__
    return cls not in _PLAIN and cls.__module__.split(".", 1)[0] == "pint"


def to_si(name: str, value, unit: str):
    """``value`` in the SI ``unit`` (a key of :data:`KINDS`) when it is a pint Quantity, else ``value``
    unchanged (a plain number is already SI). ValueError naming ``name`` for a wrong dimension."""
    if not is_quantity(value):
        return value
    # A Quantity exists, so pint is loaded: taken from sys.modules, with no import statement that the
    # FMU build would list among the modules the bundled package needs.
    pint = _MODULES["pint"]
    try:
        return value.to(unit).magnitude
    except pint.DimensionalityError:
        raise ValueError(f"{name} = {value:~}: a {KINDS[unit]} is expected (SI unit {unit}), but its unit "
                         f"measures {value.dimensionality}") from None


def with_units(**units):
    """Decorator: the keyword/positional arguments named in ``units`` (name -> SI unit) accept pint
    Quantities, converted by :func:`to_si` before the function runs."""
    def decorate(function):
        names = list(inspect.signature(function).parameters)
        position = {name: names.index(name) for name in units}

        @functools.wraps(function)
        def wrapper(*args, **kwargs):
            # no Quantity can exist before pint is imported: then the check is one dict lookup
            if "pint" in _MODULES and (any(map(is_quantity, args)) or any(map(is_quantity, kwargs.values()))):
                args = list(args)
                for name, unit in units.items():
                    i = position[name]
                    if i < len(args):
                        args[i] = to_si(name, args[i], unit)
                    elif name in kwargs:
                        kwargs[name] = to_si(name, kwargs[name], unit)
            return function(*args, **kwargs)

        wrapper.si_units = dict(units)  # each argument's SI unit, which the documentation site shows
        return wrapper
    return decorate


def si_only(function):
    """``function`` without its unit layer: for the package's own calls, which pass SI numbers
    (on the scalar path the layer would cost more than the equations)."""
    return getattr(function, "__wrapped__", function)
