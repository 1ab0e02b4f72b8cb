"""The values of the command lines' options (``restitution cor``, ``restitution fit``), read one way:
a material by name, a quantity of an FMU input with any unit (a bare number is SI) checked against the
model's domain, a positive quantity of a kind. Each refusal is an :class:`OptionError`, one line naming
the option and, where it helps, the likely slip or the close names. Text the user gave is echoed in a
refusal shortened to :data:`ECHO_CHARS` characters (:func:`echo`): a 100 000-character value is
refused in one short line. :class:`ArgumentParser` does the same for argparse's own refusals."""
from __future__ import annotations

import argparse
import re

__all__ = ["OptionError", "ArgumentParser", "material", "input_quantity", "input_reading", "positive_quantity",
           "read_quantity", "python_quantity", "add_material_options", "material_from_args", "custom_material",
           "read_material_file", "check_plausible_lengths", "echo", "shorten_quoted", "ECHO_CHARS", "MAX_VALUE_CHARS",
           "MATERIAL_PROPERTIES", "MAX_BARE_LENGTH", "PLAUSIBLE_T_OVER_D", "BARE_NUMBER_RULE", "IMPACT_QUANTITIES",
           "add_impact_options", "impact_inputs"]

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


class ArgumentParser(argparse.ArgumentParser):
    """argparse's parser whose refusals (an invalid choice, a value that is not an integer) echo the
    user's text shortened (:func:`shorten_quoted`): one short line and exit 2."""

    def error(self, message):
        super().error(shorten_quoted(message))

    def print_help(self, file=None):
        """The help on ``file``; on standard output flushed at once, so that a full disk or a closed pipe
        is one line and exit 74 (or a quiet 141), not an exception at the interpreter's exit."""
        if file is not None:
            return super().print_help(file)
        from .output_files import finish_stdout

        status = finish_stdout(self.prog, self.format_help().rstrip("\n"))
        if status:
            self.exit(status)
        return None


def _short_enough(option: str, text, label: str | None = None) -> str:
    """``text`` as a string, OptionError if it is longer than :data:`MAX_VALUE_CHARS`."""
    text = str(text)
    if len(text) > MAX_VALUE_CHARS:
        raise OptionError(f"{label or '--' + option} '{echo(text)}': too long for a value "
                          f"(at most {MAX_VALUE_CHARS} characters)")
    return text


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
    from .scene.units import split_quantity
    from .sweep.values import QuantityError, outside, quantity

    text = _short_enough(option, text)
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


def read_quantity(label: str, text, unit: str, kind: str | None) -> float:
    """The SI value of ``text``: a number (SI, ``unit``) or a number with any unit of ``kind`` ("length",
    "pressure", "density", "speed", "acceleration"; None: a plain number, no unit). OptionError, one
    line starting with ``label``, for anything else."""
    from .scene.units import UnitError, convert_quantity, split_quantity

    text = _short_enough("", text, label)
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


# --- materials given by their properties ------------------------------------------------------
#: A material's properties as options and file keys (``--plate-E``, ``E = "69 GPa"``): key -> help.
MATERIAL_PROPERTIES = {"E": "elastic modulus, e.g. \"115 GPa\"", "nu": "Poisson's ratio, e.g. 0.31",
                       "Sy": "yield strength, e.g. \"69 MPa\"", "rho": "density, e.g. \"8960 kg/m3\""}
#: The keys a material file may hold besides the properties.
_FILE_TEXT_KEYS = ("name", "source")


def add_material_options(parser, role: str, required_help: str = "") -> None:
    """``--ROLE KEY``, ``--ROLE-material FILE.toml`` and ``--ROLE-E/-nu/-Sy/-rho`` on ``parser``."""
    group = parser.add_argument_group(f"{role} material", f"a preset (--{role}), a TOML file (--{role}-material) "
                                      f"or the four properties; each property given overrides the preset's or "
                                      f"the file's{required_help}")
    group.add_argument(f"--{role}", metavar="KEY", help=f"{role} material preset (restitution materials)")
    group.add_argument(f"--{role}-material", metavar="FILE", help="TOML file: E, nu, Sy, rho (a number in SI or "
                       "a string with its unit) and optionally name, source")
    for key, what in MATERIAL_PROPERTIES.items():
        group.add_argument(f"--{role}-{key}", metavar="VALUE", dest=f"{role}_{key}", help=f"{role} {what}")


def material_from_args(args, role: str):
    """(the :class:`~restitution.Material`, its label in reports) of the options of
    :func:`add_material_options`."""
    given = {key: getattr(args, f"{role}_{key}") for key in MATERIAL_PROPERTIES}
    return custom_material(role, getattr(args, role), getattr(args, f"{role}_material"),
                           {k: v for k, v in given.items() if v is not None})


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


# --- lengths a person slipped on -------------------------------------------------------------
#: The largest sphere diameter and plate thickness taken as a bare number [m] without --allow-implausible.
MAX_BARE_LENGTH = 0.5
#: The plate's thickness over the sphere's diameter taken without --allow-implausible when either was a bare number.
PLAUSIBLE_T_OVER_D = (0.01, 100.0)
#: The rule, for --help epilogs.
BARE_NUMBER_RULE = ("A bare number is SI (metres, Pa, kg/m3, m/s): a bare sphere diameter or plate thickness over "
                    f"{MAX_BARE_LENGTH:g} m, or t/d outside {PLAUSIBLE_T_OVER_D[0]:g} to {PLAUSIBLE_T_OVER_D[1]:g} "
                    "with a bare length, is refused as a likely slip (\"--d 10\" meant 10 mm); write the unit "
                    "(\"10 m\") or give --allow-implausible to accept it.")


def check_plausible_lengths(d, t, allow: bool = False) -> None:
    """OptionError for a likely slip of a bare length: ``d`` and ``t`` are (as shown, e.g. "--d 10";
    SI value; whether it was a bare number), or None where not given. A bare diameter or thickness
    over :data:`MAX_BARE_LENGTH`, or t/d outside :data:`PLAUSIBLE_T_OVER_D` with either bare, is
    refused naming the unit it was likely meant in, unless ``allow``."""
    from .domain import number_text

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


def add_impact_options(parser, speed_required: bool = True) -> None:
    """``--d``, ``--t``, ``--v`` (required unless not ``speed_required``), ``--edge``, ``--allow-implausible``
    and the sphere's and the plate's material options (:func:`add_material_options`) on ``parser``."""
    parser.add_argument("--d", required=True, metavar="LEN", help="sphere diameter, e.g. \"6.35 mm\" (a bare "
                                                                  "number is metres)")
    parser.add_argument("--t", required=True, metavar="LEN", help="plate thickness, e.g. \"3 mm\" (a bare number "
                                                                  "is metres)")
    parser.add_argument("--v", required=speed_required, metavar="SPEED", help="approach speed, e.g. \"2 m/s\"")
    parser.add_argument("--edge", metavar="LEN", help="distance from the impact point to the plate's nearest "
                                                      "edge, e.g. \"76 mm\" (default: an unbounded plate)")
    parser.add_argument("--allow-implausible", action="store_true",
                        help="accept a bare-number length that looks like a slip (a 10 m sphere)")
    add_material_options(parser, "sphere")
    add_material_options(parser, "plate")


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
