"""What a model's prose is made of (``models/<model>/documentation.py``: ``DOCUMENTATION``, a tuple of
:class:`Section`): plain data, which :mod:`restitution.fmu.describe.documentation` writes into every
FMU's ``documentation/index.html``."""
from __future__ import annotations

from dataclasses import dataclass

__all__ = ["Rows", "Section"]


@dataclass(frozen=True)
class Rows:
    """A small table in a model's prose (its equations, say): a header and rows of cells, plain text."""

    header: tuple[str, ...]
    rows: tuple[tuple[str, ...], ...]


@dataclass(frozen=True)
class Section:
    """One part of a model's documentation beyond its interface table.

    ``blocks``: each a paragraph (``str``), a bullet list (``tuple`` of ``str``) or a :class:`Rows`. All
    text is plain (escaped when written); a variable name or a piece of code between backticks is set as
    code. ``model_exchange``: True to show the section only in the FMUs that offer model exchange (the
    native ones), False only in those that do not, None in every FMU."""

    title: str
    blocks: tuple
    model_exchange: bool | None = None
