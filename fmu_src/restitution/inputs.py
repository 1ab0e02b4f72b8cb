"""An input's value from the text a user gave, by the input's name: the one reader behind ``restitution
cor``, ``fit``, ``sweep`` and ``scene`` and the examples' command lines.

* a quantity of an FMU input (``sphere.d``, ``plate.t``, ``v_approach``, ``plate.E``, ...): a number (SI)
  or text with a unit of its kind (:mod:`restitution.units`), inside the input's declared range (the
  interface table's interval, the FMUs' ``min``/``max``, :data:`restitution.domain.DOMAIN`), refused
  otherwise in the one wording of :func:`restitution.domain.outside_text`, with a hint where a slipped
  SI prefix explains the value (``plate.E = 114 Pa ... did you mean 114 GPa?``);
* a material by name, from a TOML file or from its four properties;
* the lengths a person likely slipped on (a bare "10" for a sphere's diameter).

Each refusal is one line naming the option or the input (:class:`~restitution.units.OptionError`,
:class:`QuantityError`), the user's text shortened (:func:`~restitution.units.echo`).
"""
from __future__ import annotations

import math

from ._num import decimal_like
from .domain import number_text, outside_text, slipped_prefix
from .fmu.models.sphere_plate_impact.variables import TABLE
from .options import MATERIAL_PROPERTIES, MAX_BARE_LENGTH, PLAUSIBLE_T_OVER_D
from .units import (ECHO_CHARS, EXAMPLES, QUANTITIES, OptionError, UnitError, convert_quantity, echo, read_quantity,
                    short_enough, shorten_quoted, split_quantity)

__all__ = ["QuantityError", "ROWS", "unit_of", "quantity", "quantities", "outside", "material", "input_quantity",
           "input_reading", "positive_quantity", "MATERIAL_PROPERTIES", "read_material_file", "custom_material",
           "material_from_args", "check_plausible_lengths", "MAX_BARE_LENGTH", "PLAUSIBLE_T_OVER_D", "IMPACT_QUANTITIES",
           "impact_inputs"]

#: FMU name -> row of the interface table, for every input and parameter.
ROWS = {v.name: v for v in TABLE.settable}
#: SI unit (as the interface table writes it) -> the kind of quantity the scene's parser converts to.
KINDS = {si: kind for kind, si in QUANTITIES.items()}


class QuantityError(ValueError):
    """A value the sweep refuses: not a number, a unit it cannot take, or outside the input's declared
    range. ``name`` is the input, ``section`` where the value was given ("grid", "random", "fixed";
    set by :class:`~restitution.sweep.SweepSpec`), for the command line to name the option."""

    def __init__(self, message: str, name: str, section: str | None = None):
        super().__init__(message)
        self.name, self.section = name, section


def unit_of(name: str) -> str | None:
    """The SI unit of input ``name`` (``"m"``, ``"Pa"``, ``"kg/m3"``, ``"m/s"``); None where it is
    dimensionless or a code (no unit is taken)."""
    row = ROWS.get(name)
    return row.unit if row is not None and row.unit in KINDS else None


def _read(name: str, value) -> tuple[float, bool]:
    """(SI value, whether a unit was given) of one value."""
    if not isinstance(value, str):
        try:
            return float(value), False
        except (TypeError, ValueError):
            raise QuantityError(f"{name} = {value!r} is not a number", name) from None
    si = unit_of(name)
    parsed = split_quantity(value, fractions=True)
    if parsed is None:
        example = f" with an optional unit ({EXAMPLES[KINDS[si]]}; a bare number is in {si})" if si else ""
        raise QuantityError(f"{name} = {value!r} is not a number{example}", name)
    number, unit = parsed
    if unit is None:
        return number, False
    if si is None:
        raise QuantityError(f"{name} = {value!r}: {name} is dimensionless: give a plain number, no unit", name)
    try:  # the unit's factor may leave the product an ulp off the decimal it is (4.5 x 0.001)
        return float(decimal_like(convert_quantity(name, value.strip(), number, unit, KINDS[si]))), True
    except UnitError as exc:
        raise QuantityError(f"{name} = {exc}", name) from None


def quantity(name: str, value) -> float:
    """SI value of ``value`` for input ``name``: a number (SI), or text ``"<number>[ <unit>]"``
    (see the module docstring). :class:`QuantityError` (a ValueError) naming ``name`` otherwise."""
    return _read(name, value)[0]


def quantities(name: str, values, text=None) -> list[float]:
    """SI values of ``values`` given together (a list, the ends of a range, a distribution's
    parameters): either all with units or none (``"1,2,3mm"`` is refused, not read as 1 m, 2 m and
    3 mm); a bare 0 goes with either. ``text`` is the whole value, for the message."""
    read = [_read(name, v) for v in values]
    with_unit = [v for v, (_, unit) in zip(values, read) if unit]
    bare = [v for v, (si, unit) in zip(values, read) if not unit and si != 0]
    if with_unit and bare:
        shown = text if text is not None else list(values)
        raise QuantityError(f"{name} = {shown!r}: give every value its unit or none ({bare[0]!r} has none and "
                            f"would be {bare[0]} {unit_of(name)}, {with_unit[0]!r} has one)", name)
    return [si for si, _ in read]


def _hint(name: str, value: float) -> str | None:
    """``"114 GPa"`` where ``value`` (SI, outside the range) lands in it with a slipped SI prefix
    (:func:`restitution.domain.slipped_prefix`, nearest the input's start value); None where none does."""
    row = ROWS[name]
    return slipped_prefix(value, unit_of(name), row.accepts, float(row.start))


def outside(name: str, value: float) -> str | None:
    """The message refusing ``value`` (SI) for input ``name`` when it lies outside the input's declared
    range (``v_approach = -1 m/s is outside 0 <= value <= 10000 m/s``, with ``: did you mean 114 GPa?``
    where a slipped prefix explains it); None when it lies inside, or ``name`` is a code (checked when
    read) or not an input."""
    row = ROWS.get(name)
    if row is None or row.interval is None or row.choices is not None:
        return None
    try:
        if row.accepts(value):
            return None
    except (ValueError, OverflowError):
        pass
    unit = unit_of(name)
    hint = _hint(name, value) if unit and math.isfinite(value) else None
    return outside_text(name, value, unit, row.allowed_text(), hint)


# --- options and materials ---------------------------------------------------------------
def material(option: str, key: str):
    """The preset material ``key`` (:data:`restitution.MATERIALS`)."""
    from .materials import MATERIALS, suggest_material

    if key not in MATERIALS:
        close = suggest_material(key, MATERIALS) if len(key) <= 4 * ECHO_CHARS else ""
        raise OptionError(f"--{option} '{echo(key)}': unknown material{close}; `restitution materials` lists them")
    return MATERIALS[key]


def input_quantity(option: str, name: str, text: str) -> float:
    """The SI value of ``text`` for the FMU input ``name`` (``sphere.d``, ``plate.t``, ``v_approach``,
    ``plate.E``, ``plate.nu``, ...): a number (SI) or text with a unit of its kind, inside the input's
    declared range (the refusal names the range and an SI-prefix slip that explains the value)."""
    return input_reading(option, name, text)[0]


def input_reading(option: str, name: str, text: str) -> tuple[float, bool]:
    """(SI value, whether ``text`` was a bare number) of :func:`input_quantity`."""
    text = short_enough(option, text)
    try:
        value = quantity(name, text)
    except QuantityError as exc:
        raise OptionError(shorten_quoted(f"--{option}: {exc}", text)) from None
    refusal = outside(name, value)
    if refusal is not None:
        raise OptionError(shorten_quoted(f"--{option}: {refusal}", text))
    parsed = split_quantity(text, fractions=True)
    return value, parsed is not None and parsed[1] is None


def positive_quantity(option: str, text: str, unit: str, kind: str) -> float:
    """A positive quantity of ``kind`` ("length", "acceleration", ...) [``unit``]: a number (SI) or text
    with any unit of that kind."""
    value = read_quantity(f"--{option}", text, unit, kind)
    if not value > 0:
        raise OptionError(f"--{option} = {echo(text)}: must be > 0 {unit}")
    return value


# --- materials given by their properties (MATERIAL_PROPERTIES: restitution.options) -------------
#: The keys a material file may hold besides the properties.
_FILE_TEXT_KEYS = ("name", "source")


def read_material_file(role: str, path) -> dict:
    """The properties (SI, checked against the model's domain), ``name`` and ``source`` of a material
    file (TOML): unknown keys, a value of the wrong kind or outside the domain refused in one line."""
    import tomllib

    label = f"--{role}-material {echo(path)}"
    try:
        with open(path, "rb") as handle:
            data = tomllib.load(handle)
    except OSError as exc:
        raise OptionError(f"{label}: {exc.strerror or exc}") from None
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise OptionError(f"{label}: not a TOML file: {' '.join(str(exc).split())}") from None
    unknown = [key for key in data if key not in MATERIAL_PROPERTIES and key not in _FILE_TEXT_KEYS]
    if unknown:
        raise OptionError(f"{label}: unknown key(s) {', '.join(repr(echo(k)) for k in unknown)}: a material file "
                          f"has {', '.join(MATERIAL_PROPERTIES)} and optionally {', '.join(_FILE_TEXT_KEYS)}")
    out = {}
    for key, value in data.items():
        if key in _FILE_TEXT_KEYS:
            if not isinstance(value, str):
                raise OptionError(f"{label}: {key} = {echo(repr(value))}: expected a string")
            out[key] = value
        elif isinstance(value, bool) or not isinstance(value, (int, float, str)):
            raise OptionError(f"{label}: {key} = {echo(repr(value))}: expected a number (SI) or a string with "
                              f"its unit")
        else:
            out[key] = input_quantity(f"{role}-material {echo(path)}", f"{role}.{key}", str(value))
    return out


def custom_material(role: str, key: str | None = None, path=None, given: dict | None = None):
    """(:class:`~restitution.Material`, label) of the preset ``key``, then the file ``path``, then the
    properties ``given`` (option text by key of :data:`MATERIAL_PROPERTIES`), each overriding the one
    before; every property must come from one of them. The label is the preset's key, the file's
    ``name`` (else its stem) or "custom"; a preset whose values were overridden is "KEY (custom E, Sy)"."""
    from pathlib import Path

    from .materials import Material

    given = given or {}
    base = material(role, key) if key is not None else None
    if base is not None and path is None and not given:
        return base, key
    values = {k: getattr(base, k) for k in MATERIAL_PROPERTIES} if base is not None else {}
    from_file = read_material_file(role, path) if path is not None else {}
    values.update({k: v for k, v in from_file.items() if k in MATERIAL_PROPERTIES})
    values.update({k: input_quantity(f"{role}-{k}", f"{role}.{k}", text) for k, text in given.items()})
    missing = [k for k in MATERIAL_PROPERTIES if k not in values]
    if missing:
        raise OptionError(f"--{role}: give a preset (--{role} KEY), a file (--{role}-material FILE.toml) or all of "
                          f"{', '.join(f'--{role}-{k}' for k in MATERIAL_PROPERTIES)} (missing: {', '.join(missing)})")
    changed = [k for k in MATERIAL_PROPERTIES if k in given or k in from_file]
    if "name" in from_file:
        label = from_file["name"]
    elif path is not None and base is None:
        label = Path(path).stem
    elif base is not None:
        label = f"{key} (custom {', '.join(changed)})"
    else:
        label = "custom"
    source = from_file.get("source") or (f"{path}" if path is not None else "given on the command line")
    try:
        return Material(label, **values, source=source), label
    except ValueError as exc:
        raise OptionError(f"--{role}: {exc}") from None


def material_from_args(args, role: str):
    """(the :class:`~restitution.Material`, its label in reports) of the options of
    :func:`restitution.options.add_material_options`."""
    given = {key: getattr(args, f"{role}_{key}") for key in MATERIAL_PROPERTIES}
    return custom_material(role, getattr(args, role), getattr(args, f"{role}_material"),
                           {k: v for k, v in given.items() if v is not None})


# --- lengths a person slipped on (the rule's numbers: restitution.options) --------------------
def check_plausible_lengths(d, t, allow: bool = False) -> None:
    """OptionError for a likely slip of a bare length: ``d`` and ``t`` are (as shown, e.g. "--d 10";
    SI value; whether it was a bare number), or None where not given. A bare diameter or thickness
    over :data:`MAX_BARE_LENGTH`, or t/d outside :data:`PLAUSIBLE_T_OVER_D` with either bare, is
    refused naming the unit it was likely meant in, unless ``allow``."""
    if allow:
        return
    for reading, what in ((d, "sphere"), (t, "plate")):
        if reading is not None and reading[2] and reading[1] > MAX_BARE_LENGTH:
            number = number_text(reading[1])
            raise OptionError(f"{echo(reading[0])}: a bare number is metres: a {number} m {what} is implausible; "
                              f"did you mean {number} mm? (--allow-implausible accepts it)")
    if d is None or t is None or not (d[2] or t[2]) or not d[1] > 0:
        return
    ratio = t[1] / d[1]
    low, high = PLAUSIBLE_T_OVER_D
    if low <= ratio <= high:
        return
    culprit = d if ratio < low else t  # read in mm, it brings t/d up (d) or down (t)
    meant = ratio * 1e3 if culprit is d else ratio / 1e3
    hint = f"; did you mean {number_text(culprit[1])} mm?" if culprit[2] and low <= meant <= high else ""
    shown = culprit if culprit[2] else (t if t[2] else d)
    raise OptionError(f"{echo(shown[0])}: a bare number is metres: t/d = {ratio:.3g} (d = {number_text(d[1])} m, "
                      f"t = {number_text(t[1])} m) is implausible, outside {low:g} to {high:g}{hint} "
                      f"(--allow-implausible accepts it)")


# --- one impact's bodies, sizes and speed (restitution cor, restitution export) -------------------
#: The options with a unit: option -> (FMU input name whose unit and range apply, impact keyword).
IMPACT_QUANTITIES = {"d": ("sphere.d", "sphere_d"), "t": ("plate.t", "plate_t"), "v": ("v_approach", "v"),
                     "edge": ("plate.edge_distance", "plate_edge_distance")}


def impact_inputs(sphere, d, plate, t, v=None, edge=None, allow_implausible: bool = True) -> tuple[dict, dict]:
    """(the approach speed ``v`` [m/s] (None where not given) and the keyword arguments of
    :func:`restitution.impact` but the speed, SI) for the materials ``sphere`` and ``plate`` (a preset's name or
    a :class:`~restitution.Material`), the diameter ``d``, the thickness ``t``, the speed ``v`` and the edge
    distance ``edge`` (each a number in SI or a text with its unit; ``edge`` None or 0: an unbounded plate).
    Without ``allow_implausible`` a bare-number length that is a likely slip is refused
    (:func:`check_plausible_lengths`). OptionError (one line) for an unknown material or a value outside the
    domain."""
    bodies = {role: (material(role, body) if isinstance(body, str) else body)
              for role, body in (("sphere", sphere), ("plate", plate))}
    readings = {option: input_reading(option, IMPACT_QUANTITIES[option][0], str(text))
                for option, text in (("d", d), ("t", t), ("v", v), ("edge", edge)) if text is not None}
    check_plausible_lengths(*((f"--{option} {text}", *readings[option]) for option, text in (("d", d), ("t", t))),
                            allow=allow_implausible)
    values = {option: value for option, (value, _) in readings.items()}
    params = {**bodies["sphere"].params("sphere"), **bodies["plate"].params("plate"),
              "sphere_d": values["d"], "plate_t": values["t"], "plate_edge_distance": values.get("edge", 0.0)}
    return values.get("v"), params
