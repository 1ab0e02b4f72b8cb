"""A refused value, in one line: the error every reader of a user's value raises (:class:`OptionError`)
and the user's text as a refusal echoes it, shortened to :data:`ECHO_CHARS` characters (:func:`echo`):
a 100 000-character value is refused in one short line."""
from __future__ import annotations

import re

__all__ = ["OptionError", "echo", "shorten_quoted", "short_enough", "ECHO_CHARS", "MAX_VALUE_CHARS"]

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
