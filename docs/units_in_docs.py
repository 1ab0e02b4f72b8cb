"""A local Sphinx extension: the API reference shows the SI unit of each argument of a function that
takes physical quantities.

Those functions are wrapped by :func:`restitution.quantities.with_units`, which records the unit of
each argument it converts (``si_units``); their docstrings name the result's unit in brackets but not
always each argument's. This appends one line to such a function's documentation, e.g.
"Arguments (SI units, or pint Quantities of any compatible unit): E_a [Pa], nu_a [1]".
"""
from __future__ import annotations

#: pint's spelling of a unit -> how the pages write it
_WRITTEN = {"dimensionless": "1", "kg/m**3": "kg/m^3", "m/s**2": "m/s^2", "N/m**1.5": "N/m^1.5"}


def argument_units_line(si_units: dict) -> str:
    """The line appended to a documented function whose arguments have the SI units ``si_units``
    (argument name -> pint unit)."""
    listed = ", ".join(f"``{name}`` [{_WRITTEN.get(unit, unit)}]" for name, unit in si_units.items())
    return f"Arguments (SI units, or pint Quantities of any compatible unit): {listed}."


def _append_argument_units(app, what, name, obj, options, lines):
    si_units = getattr(obj, "si_units", None)
    if what in ("function", "method") and isinstance(si_units, dict) and si_units:
        lines.extend(["", argument_units_line(si_units)])


def setup(app):
    # after numpydoc (priority 500) has turned its sections into reStructuredText: a paragraph at the end
    app.connect("autodoc-process-docstring", _append_argument_units, priority=600)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
