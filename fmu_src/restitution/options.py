"""The values of the command lines' options (``restitution cor``, ``restitution fit``), read one way:
a material by name, a quantity of an FMU input with any unit (a bare number is SI) checked against the
model's domain, a positive quantity of a kind. Each refusal is an :class:`OptionError`, one line naming
the option and, where it helps, the likely slip or the close names. Text the user gave is echoed in a
refusal shortened to :data:`ECHO_CHARS` characters (:func:`echo`): a 100 000-character value is
refused in one short line. :class:`ArgumentParser` does the same for argparse's own refusals."""
from __future__ import annotations

import argparse
import re

__all__ = ["OptionError", "ArgumentParser", "material", "input_quantity", "positive_quantity", "echo",
           "shorten_quoted", "ECHO_CHARS", "MAX_VALUE_CHARS"]

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


def _short_enough(option: str, text) -> str:
    """``text`` as a string, OptionError if it is longer than :data:`MAX_VALUE_CHARS`."""
    text = str(text)
    if len(text) > MAX_VALUE_CHARS:
        raise OptionError(f"--{option} '{echo(text)}': too long for a value (at most {MAX_VALUE_CHARS} characters)")
    return text


def material(option: str, key: str):
    """The preset material ``key`` (:data:`restitution.MATERIALS`)."""
    from .materials import MATERIALS, suggest_material

    if key not in MATERIALS:
        close = suggest_material(key, MATERIALS) if len(key) <= 4 * ECHO_CHARS else ""
        raise OptionError(f"--{option} '{echo(key)}': unknown material{close}; `restitution materials` lists them")
    return MATERIALS[key]


def input_quantity(option: str, name: str, text: str) -> float:
    """The SI value of ``text`` for the FMU input ``name`` (``sphere.d``, ``plate.t``, ``v_approach``):
    a number (SI) or text with a unit of its kind, inside the input's declared range (the refusal names
    the range and an SI-prefix slip that explains the value)."""
    from .sweep.values import QuantityError, outside, quantity

    text = _short_enough(option, text)
    try:
        value = quantity(name, text)
    except QuantityError as exc:
        raise OptionError(shorten_quoted(f"--{option}: {exc}", text)) from None
    refusal = outside(name, value)
    if refusal is not None:
        raise OptionError(shorten_quoted(f"--{option}: {refusal}", text))
    return value


def positive_quantity(option: str, text: str, unit: str, kind: str) -> float:
    """A positive quantity of ``kind`` ("length", "acceleration", ...) [``unit``]: a number (SI) or text
    with any unit of that kind."""
    from .scene.units import UnitError, convert_quantity, split_quantity

    text = _short_enough(option, text)
    parsed = split_quantity(text, fractions=True)
    if parsed is None:
        raise OptionError(f"--{option} = '{echo(text)}' is not a number with an optional unit (a bare number is "
                          f"in {unit})")
    number, given = parsed
    try:
        value = number if given is None else convert_quantity(option, text.strip(), number, given, kind)
    except UnitError as exc:
        raise OptionError(shorten_quoted(f"--{option} = {exc}", text, text.strip())) from None
    if not value > 0:
        raise OptionError(f"--{option} = {echo(text)}: must be > 0 {unit}")
    return value
