"""The values of the command lines' options (``restitution cor``, ``restitution fit``), read one way:
a material by name, a quantity of an FMU input with any unit (a bare number is SI) checked against the
model's domain, a positive quantity of a kind. Each refusal is an :class:`OptionError`, one line naming
the option and, where it helps, the likely slip or the close names."""
from __future__ import annotations

__all__ = ["OptionError", "material", "input_quantity", "positive_quantity"]


class OptionError(ValueError):
    """A refused option value: the message is one line naming the option."""


def material(option: str, key: str):
    """The preset material ``key`` (:data:`restitution.MATERIALS`)."""
    from .materials import MATERIALS, suggest_material

    if key not in MATERIALS:
        raise OptionError(f"--{option} {key!r}: unknown material{suggest_material(key, MATERIALS)}; "
                          "`restitution materials` lists them")
    return MATERIALS[key]


def input_quantity(option: str, name: str, text: str) -> float:
    """The SI value of ``text`` for the FMU input ``name`` (``sphere.d``, ``plate.t``, ``v_approach``):
    a number (SI) or text with a unit of its kind, inside the input's declared range (the refusal names
    the range and an SI-prefix slip that explains the value)."""
    from .sweep.values import QuantityError, outside, quantity

    try:
        value = quantity(name, text)
    except QuantityError as exc:
        raise OptionError(f"--{option}: {exc}") from None
    refusal = outside(name, value)
    if refusal is not None:
        raise OptionError(f"--{option}: {refusal}")
    return value


def positive_quantity(option: str, text: str, unit: str, kind: str) -> float:
    """A positive quantity of ``kind`` ("length", "acceleration", ...) [``unit``]: a number (SI) or text
    with any unit of that kind."""
    from .scene.units import UnitError, convert_quantity, split_quantity

    parsed = split_quantity(text, fractions=True)
    if parsed is None:
        raise OptionError(f"--{option} = {text!r} is not a number with an optional unit (a bare number is in {unit})")
    number, given = parsed
    try:
        value = number if given is None else convert_quantity(option, text.strip(), number, given, kind)
    except UnitError as exc:
        raise OptionError(f"--{option} = {exc}") from None
    if not value > 0:
        raise OptionError(f"--{option} = {text}: must be > 0 {unit}")
    return value
