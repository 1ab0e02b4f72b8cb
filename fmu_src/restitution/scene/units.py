"""Quantities with explicit units for scene files: ``"3.18 mm"``, ``"69 GPa"``, ``"2700 kg/m3"``.

A dimensional value in a scene is a string "<number> <unit>"; a bare number is refused
(``thickness = 3.18`` could mean metres or millimetres). Dimensionless values (Poisson's
ratio, tolerances) are plain numbers. Everything is converted to SI on load.
"""
from __future__ import annotations

import math
import re

__all__ = ["UNITS", "QUANTITIES", "parse_quantity", "UnitError", "format_quantity"]


class UnitError(ValueError):
    """A value whose unit is missing, unknown or of the wrong kind (the message says which)."""


#: quantity kind -> {unit spelling: factor to SI}
UNITS: dict[str, dict[str, float]] = {
    "length": {"m": 1.0, "cm": 1e-2, "mm": 1e-3, "um": 1e-6, "µm": 1e-6, "in": 0.0254},
    "pressure": {"Pa": 1.0, "kPa": 1e3, "MPa": 1e6, "GPa": 1e9},
    "density": {"kg/m3": 1.0, "kg/m^3": 1.0, "g/cm3": 1e3, "g/cm^3": 1e3},
    "speed": {"m/s": 1.0, "cm/s": 1e-2, "mm/s": 1e-3},
    "acceleration": {"m/s2": 1.0, "m/s^2": 1.0},
}
#: SI unit of each kind (what the loader converts to).
QUANTITIES = {"length": "m", "pressure": "Pa", "density": "kg/m3", "speed": "m/s", "acceleration": "m/s2"}

_KIND_OF = {unit: kind for kind, units in UNITS.items() for unit in units}
# ASCII digits only: float() would take "٣.١٨" (Arabic-Indic digits) as 3.18.
_NUMBER = re.compile(r"^\s*([-+]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][-+]?[0-9]+)?)\s*(\S.*?)?\s*$", re.ASCII)


def _examples(kind: str) -> str:
    return ", ".join(u for u in UNITS[kind] if "^" not in u and u != "µm")


def parse_quantity(key: str, value, kind: str) -> float:
    """SI value of ``value`` (a "<number> <unit>" string) for a quantity of ``kind``.

    ``key`` is the value's key (its last part is used in the examples of error messages; the
    caller prefixes the full key). Raises :class:`UnitError` for a bare number,
    an unknown unit or a unit of another kind.
    """
    units = UNITS[kind]
    short = key.rsplit(".", 1)[-1]
    example = f'{short} = "{_example_value(kind)}"'
    if isinstance(value, bool) or not isinstance(value, (str, int, float)):
        raise UnitError(f"{value!r}: expected a {kind} with its unit, as a string, e.g. {example}")
    if not isinstance(value, str):
        raise UnitError(f"{value!r} has no unit: write the {kind} with its unit, e.g. {example} "
                        f"(units: {_examples(kind)})")
    match = _NUMBER.match(value)
    if match is None:
        raise UnitError(f"{value!r} is not '<number> <unit>' (a number in ASCII digits), e.g. {example}")
    number, unit = float(match.group(1)), match.group(2)
    if unit is None:
        raise UnitError(f"{value!r} has no unit: write the {kind} with its unit, e.g. {example} "
                        f"(units: {_examples(kind)})")
    if unit not in units:
        other = _KIND_OF.get(unit)
        if other is not None:
            raise UnitError(f"{value!r}: {unit} is a unit of {other}, but {short} is a {kind} "
                            f"(units: {_examples(kind)})")
        raise UnitError(f"{value!r}: unknown unit {unit!r} for a {kind} (units: {_examples(kind)})")
    si = number * units[unit]
    if not math.isfinite(si):
        raise UnitError(f"{value!r} is not finite")
    return si


def _example_value(kind: str) -> str:
    return {"length": "3.18 mm", "pressure": "69 GPa", "density": "2700 kg/m3", "speed": "0.1 m/s",
            "acceleration": "9.81 m/s2"}[kind]


def format_quantity(value: float, kind: str) -> str:
    """Short human-readable form (mm for lengths below 1 m, GPa/MPa for pressures)."""
    if kind == "length":
        return f"{value * 1e3:g} mm" if value < 1.0 else f"{value:g} m"
    if kind == "pressure":
        return f"{value / 1e9:g} GPa" if value >= 1e9 else f"{value / 1e6:g} MPa"
    return f"{value:g} {QUANTITIES[kind]}"
