"""Text with a unit to SI, by kind of quantity: ``"3.18 mm"``, ``"69 GPa"``, ``"2700 kg/m3"``, the one
reader of every front end (the command lines' options, sweeps, scene files, the package's objects).

A dimensional value is a string "<number> <unit>", or a bare number in SI units
(``thickness = 0.00318`` is 3.18 mm), as everywhere in the package. Dimensionless values (Poisson's
ratio, tolerances) are plain numbers. Units are read by pint, so any unit of the right kind works
(``"0.125 in"``, ``"1 ft"``, ``"2.7 g/cm3"``, ``"9.81 m/s2"``; the common ones, :data:`_SI_FACTOR`, are
converted with pint's factors without loading pint);
a digit right after a unit's letters is its exponent (``m3`` is m**3). Everything is converted to SI
on load. The command lines and the sweep read with the same parser (:func:`split_quantity`,
:func:`convert_quantity`, :func:`read_quantity`), where a fraction (``"1/4 in"``) is a number too;
:mod:`restitution.inputs` reads an FMU input's value by its name.

A refused value is one line (:class:`OptionError`, what every reader of a user's value raises), the
user's text echoed shortened to :data:`ECHO_CHARS` characters (:func:`echo`): a 100 000-character value
is refused in one short line.
"""
from __future__ import annotations

import math
import re
from functools import lru_cache

__all__ = ["QUANTITIES", "EXAMPLES", "parse_quantity", "split_quantity", "convert_quantity", "UnitError",
           "format_quantity", "read_quantity", "python_quantity", "OptionError", "echo", "shorten_quoted",
           "short_enough", "ECHO_CHARS", "MAX_VALUE_CHARS"]


# --- a refused value, in one line ------------------------------------------------------------
#: The most characters of a user's text a refusal echoes; longer text is cut, "..." and its length added.
ECHO_CHARS = 60
#: The longest value a quantity option takes ("6.35 mm" is 7): longer text is refused unparsed (the unit
#: parser's time grows with the square of the length: 100 000 characters took minutes).
MAX_VALUE_CHARS = 200
#: A quoted run in a message: what the parsers echo of the user's text.
_QUOTED = re.compile(r"'[^'\n]*'|\"[^\"\n]*\"")
#: The end of a text :func:`echo` shortened.
_ECHOED = re.compile(r"\.\.\. \(\d+ characters\)$")


class OptionError(ValueError):
    """A refused option value: the message is one line naming the option."""


def echo(text) -> str:
    """``text`` as a refusal shows it: whole up to :data:`ECHO_CHARS` characters, else its first
    ECHO_CHARS characters, an ellipsis and its length (``'xxx...' (100000 characters)``), line breaks
    and other control characters shown escaped so that the message stays one line."""
    text = str(text)
    shown = text if len(text) <= ECHO_CHARS else text[:ECHO_CHARS]
    shown = repr(shown)[1:-1] if not shown.isprintable() else shown
    return shown if len(text) <= ECHO_CHARS else f"{shown}... ({len(text)} characters)"


def shorten_quoted(message: str, *texts) -> str:
    """``message`` with every occurrence of each of ``texts`` (the user's values) and every quoted run
    longer than :data:`ECHO_CHARS` shortened by :func:`echo`, on one line."""
    for text in texts:
        text = str(text)
        if len(text) > ECHO_CHARS or not text.isprintable():
            message = message.replace(repr(text), f"'{echo(text)}'").replace(text, echo(text))

    def cut(match):
        inner = match.group(0)[1:-1]
        if len(inner) <= ECHO_CHARS or _ECHOED.search(inner):
            return match.group(0)
        return f"'{echo(inner)}'"

    return " ".join(_QUOTED.sub(cut, message).split())


def short_enough(option: str, text, label: str | None = None) -> str:
    """``text`` as a string, OptionError if it is longer than :data:`MAX_VALUE_CHARS`."""
    text = str(text)
    if len(text) > MAX_VALUE_CHARS:
        raise OptionError(f"{label or '--' + option} '{echo(text)}': too long for a value "
                          f"(at most {MAX_VALUE_CHARS} characters)")
    return text


class UnitError(ValueError):
    """A value whose unit is missing, unknown or of the wrong kind (the message says which)."""


#: SI unit of each kind of quantity (what the loader converts to; shown in messages).
QUANTITIES = {"length": "m", "pressure": "Pa", "density": "kg/m3", "speed": "m/s", "acceleration": "m/s2",
              "time": "s"}
#: Units named in the messages as examples of each kind (any unit pint knows of that kind works).
EXAMPLES = {"length": "m, cm, mm, um, in", "pressure": "Pa, kPa, MPa, GPa", "density": "kg/m3, g/cm3",
            "speed": "m/s, cm/s, mm/s, km/h", "acceleration": "m/s2", "time": "s, ms, us, ns"}
_EXAMPLE_VALUE = {"length": "3.18 mm", "pressure": "69 GPa", "density": "2700 kg/m3", "speed": "0.1 m/s",
                  "acceleration": "9.81 m/s2", "time": "1 us"}

# ASCII digits only: float() would take "٣.١٨" (Arabic-Indic digits) as 3.18. The unit is what follows,
# from its first to its last non-blank character: written greedily, since a lazy ".*?" before "\s*$" made
# the match take time growing with the square of the text's length (5.8 s for 20,000 characters).
_NUMBER = re.compile(r"^\s*([-+]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][-+]?[0-9]+)?)\s*(\S(?:.*\S)?)?\s*$", re.ASCII)
# "1/4 in": a fraction of two integers, then a unit (or nothing) that does not start a number
_FRACTION = re.compile(r"^\s*([-+]?[0-9]+)\s*/\s*([0-9]+)(?![0-9.eE])\s*(\S(?:.*\S)?)?\s*$", re.ASCII)
# "kg/m3", "m/s2": an exponent written as digits right after a unit's letters
_EXPONENT = re.compile(r"(?<=[A-Za-zµμ])([0-9]+)\b")


#: Each kind's common units, as written, and pint's factor to SI for each, to the last bit: read without pint,
#: whose registry takes over a second to build (``restitution cor`` with "6.35 mm" took 1.5 s, 0.3 s without).
#: pint converts by one multiplication, ``number * factor``, and so does :func:`convert_quantity` with these
#: factors, which makes the result the same float. Some of pint's factors are not the decimal one: its chain of
#: definitions (foot = 12 inch, inch = yard / 36, ...) rounds, hence ft and g/cm3 below;
#: tests/cli/test_units_fast_path.py checks every entry against pint. Any other unit or spelling is read by pint.
_SI_FACTOR = {
    "length": {"m": 1, "mm": 0.001, "cm": 0.01, "nm": 1e-09, "km": 1000.0, "in": 0.0254, "ft": 0.30479999999999996,
               "um": 1e-06, "\u00b5m": 1e-06, "\u03bcm": 1e-06},  # micro: u, the micro sign, the Greek mu
    "pressure": {"Pa": 1, "kPa": 1000.0, "MPa": 1000000.0, "GPa": 1000000000.0},
    "density": {"kg/m3": 1, "g/cm3": 999.9999999999999},
    "speed": {"m/s": 1, "mm/s": 0.001, "cm/s": 0.01, "km/h": 0.2777777777777778},
    "acceleration": {"m/s2": 1},
    "time": {"s": 1, "ms": 0.001, "us": 1e-06, "ns": 1e-09},
}


@lru_cache(maxsize=1)
def _registry():
    import pint

    return pint.UnitRegistry()


def _pint_units(unit: str) -> str:
    return _EXPONENT.sub(r"**\1", unit)


def split_quantity(text: str, fractions: bool = False) -> tuple[float, str | None] | None:
    """``(number, unit)`` of "<number> <unit>" text (``unit`` None where there is none), or None when the
    text is not a number in ASCII digits followed by a unit. With ``fractions``, a fraction of two
    integers is a number too (``"1/4 in"``)."""
    if fractions:
        match = _FRACTION.match(text)
        if match is not None:
            if int(match.group(2)) == 0:
                return None
            return int(match.group(1)) / int(match.group(2)), match.group(3)
    match = _NUMBER.match(text)
    if match is None:
        return None
    return float(match.group(1)), match.group(2)


def convert_quantity(name: str, text: str, number: float, unit: str, kind: str) -> float:
    """SI value of ``number`` in ``unit`` for a quantity of ``kind``; ``text`` is the value as written and
    ``name`` what the messages call the quantity. Raises :class:`UnitError` for an unknown unit or a
    unit of another kind."""
    factor = _SI_FACTOR[kind].get(unit)
    if factor is not None:
        return _finite(text, number * factor)
    ureg = _registry()
    try:
        given = ureg.parse_units(_pint_units(unit))
    except Exception:  # noqa: BLE001 - pint raises several kinds for a unit it cannot read
        raise UnitError(f"{text!r}: unknown unit {unit!r} for a {kind} (units: {EXAMPLES[kind]})") from None
    target = ureg.parse_units(_pint_units(QUANTITIES[kind]))
    if given.dimensionality != target.dimensionality:
        other = next((k for k, si in QUANTITIES.items()
                      if ureg.parse_units(_pint_units(si)).dimensionality == given.dimensionality),
                     f"{given.dimensionality}" if given.dimensionality else "a dimensionless number")
        raise UnitError(f"{text!r}: {unit} is a unit of {other}, but {name} is a {kind} "
                        f"(units: {EXAMPLES[kind]})")
    return _finite(text, ureg.Quantity(number, given).to(target).magnitude)


def _finite(text: str, si) -> float:
    """``si`` as a float, UnitError if it is not finite (``"1e308 km"``)."""
    si = float(si)
    if not math.isfinite(si):
        raise UnitError(f"{text!r} is not finite")
    return si


def parse_quantity(key: str, value, kind: str) -> float:
    """SI value of ``value`` (a "<number> <unit>" string, or a number or numeric string: SI) for a
    quantity of ``kind``.

    ``key`` is the value's key (its last part is used in the examples of error messages; the
    caller prefixes the full key). Raises :class:`UnitError` for a value that is not a number,
    an unknown unit or a unit of another kind.
    """
    short = key.rsplit(".", 1)[-1]
    example = f'{short} = "{_EXAMPLE_VALUE[kind]}"'
    if isinstance(value, bool) or not isinstance(value, (str, int, float)):
        raise UnitError(f"{value!r}: expected a {kind}, a string with its unit or a number in "
                        f"{QUANTITIES[kind]}, e.g. {example}")
    if not isinstance(value, str):  # a bare number is SI
        if not math.isfinite(value):
            raise UnitError(f"{value!r} is not finite")
        return float(value)
    parsed = split_quantity(value)
    if parsed is None:
        raise UnitError(f"{value!r} is not '<number> <unit>' (a number in ASCII digits), e.g. {example}")
    number, unit = parsed
    if unit is None:  # "0.00318": a number in SI, as a bare one
        if not math.isfinite(number):
            raise UnitError(f"{value!r} is not finite")
        return float(number)
    return convert_quantity(short, value, number, unit, kind)


def format_quantity(value: float, kind: str) -> str:
    """Short human-readable form (mm for lengths below 1 m, GPa/MPa for pressures)."""
    if kind == "length":
        return f"{value * 1e3:g} mm" if value < 1.0 else f"{value:g} m"
    if kind == "pressure":
        return f"{value / 1e9:g} GPa" if value >= 1e9 else f"{value / 1e6:g} MPa"
    return f"{value:g} {QUANTITIES[kind]}"


def read_quantity(label: str, text, unit: str, kind: str | None) -> float:
    """The SI value of ``text``: a number (SI, ``unit``) or a number with any unit of ``kind`` ("length",
    "pressure", "density", "speed", "acceleration"; None: a plain number, no unit). OptionError, one
    line starting with ``label``, for anything else."""
    text = short_enough("", text, label)
    parsed = split_quantity(text, fractions=True)
    if parsed is None:
        raise OptionError(f"{label} = '{echo(text)}' is not a number with an optional unit (a bare number is "
                          f"in {unit})" if kind else f"{label} = '{echo(text)}' is not a number")
    number, given = parsed
    if given is not None and kind is None:
        raise OptionError(f"{label} = '{echo(text)}': a plain number (dimensionless), no unit")
    try:
        return number if given is None else convert_quantity(label.lstrip("-"), text.strip(), number, given, kind)
    except UnitError as exc:
        raise OptionError(shorten_quoted(f"{label} = {exc}", text, text.strip())) from None


#: The kind of quantity of each SI unit the package's objects take (:mod:`restitution.quantities` spelling).
_KIND_OF_UNIT = {"m": "length", "Pa": "pressure", "kg/m**3": "density", "kg/m3": "density", "m/s": "speed",
                 "m/s**2": "acceleration", "dimensionless": None}


def python_quantity(name: str, value, unit: str):
    """``value`` unchanged unless it is a string; a string's SI value, read as the command lines read
    a value (``"2 mm"``, ``"1/4 in"``, ``"115 GPa"``, ``"0.003"`` in SI; a plain number for a
    dimensionless ``unit``): what :class:`~restitution.Sphere`, :class:`~restitution.Plate`,
    :class:`~restitution.Material` and :func:`restitution.impact_between` take. OptionError (a
    ValueError, one line naming ``name``) for text that is not one."""
    if not isinstance(value, str):
        return value
    return read_quantity(name, value, unit.replace("**", ""), _KIND_OF_UNIT[unit])
