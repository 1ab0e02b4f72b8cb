"""Do two sweep tables (the package and the FMU back end) agree? Within each output's conditioning.

The FMU evaluates one case at a time (the package's scalar mode, the C library's exp/log), the
package whole arrays (numpy's SIMD kernels): they may differ in the last bits, amplified by each
output's condition number. :func:`agreement_report` allows, case by case, what
:func:`restitution.agreement.tolerances` derives, and reports every case beyond it.
"""
from __future__ import annotations

import numpy as np

from ..agreement import disagreements, tolerances
from ..model import EFFECT_MODES, RESTITUTION_MODELS, ZENER_METHODS
from .spec import INPUTS, OUTPUTS

__all__ = ["agreement_report"]

_OPTIONS = ("restitution_model", "zener_method", "plasticity", "plate_waves", "effect_tolerance",
            "zener.ode_tolerance")
_FIELD = {name: field for name, field, _type in OUTPUTS}


class _Columns:
    """Sweep columns (by FMU name) seen as an ImpactResult (by field name), rows ``sel``."""

    def __init__(self, columns, sel):
        self._columns, self._sel = columns, sel

    def __getattr__(self, field):
        for name, f in _FIELD.items():
            if f == field:
                return np.asarray(self._columns[name])[self._sel]
        raise AttributeError(field)


def agreement_report(a: dict, b: dict) -> tuple[int, dict]:
    """(cases compared, {output: description of a case beyond tolerance}) for two sweep tables
    (column dicts) of the same cases; only cases both back ends evaluated (``ok``) are compared."""
    if not np.array_equal(np.asarray(a["case"]), np.asarray(b["case"])):
        raise ValueError("the two results cover different cases")
    ok = np.asarray(a["ok"], dtype=bool) & np.asarray(b["ok"], dtype=bool)
    problems: dict = {}
    rows = np.flatnonzero(ok)
    if rows.size == 0:
        return 0, problems
    options = np.stack([np.asarray(a[name], dtype=float)[rows] for name in _OPTIONS], axis=1)
    groups, inverse = np.unique(options, axis=0, return_inverse=True)
    for g, opt in enumerate(groups):
        sel = rows[inverse.ravel() == g]
        kwargs = dict(restitution_model=RESTITUTION_MODELS[int(opt[0]) - 1],
                      zener_method=ZENER_METHODS[int(opt[1]) - 1], plasticity=EFFECT_MODES[int(opt[2])],
                      plate_waves=EFFECT_MODES[int(opt[3])], effect_tolerance=float(opt[4]),
                      ode_rtol=float(opt[5]))
        inputs = {kw: np.asarray(a[name], dtype=float)[sel] for name, kw, _t, _s in INPUTS if name not in _OPTIONS}
        v = inputs.pop("v")
        tol, flips = tolerances(v, inputs, **kwargs)
        for line in disagreements(_Columns(a, sel), _Columns(b, sel), tol, flips):
            field = line.split(":", 1)[0]
            name = next(n for n, f in _FIELD.items() if f == field)
            problems.setdefault(name, line)
    return int(rows.size), problems
