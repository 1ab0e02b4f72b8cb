"""Do two sweep tables (the package and the FMU back end) agree? :func:`compare_results` gives the
largest difference per output; :func:`agreement_report` checks them within each output's conditioning.

The FMU evaluates one case at a time (the package's scalar mode, the C library's exp/log), the
package whole arrays (numpy's SIMD kernels): they may differ in the last bits, amplified by each
output's condition number. :func:`agreement_report` allows, case by case, what
:func:`restitution.agreement.tolerances` derives, and reports every case beyond it.
"""
from __future__ import annotations

import math

import numpy as np

from ..agreement import disagreements, tolerances
from .backends import impact_groups
from .spec import OUTPUT_NAMES, OUTPUTS
from .result import SweepResult

__all__ = ["agreement_report", "compare_results"]

_NAME_OF_FIELD = {field: name for name, field, _type in OUTPUTS}  # ImpactResult field -> column


class _Columns:
    """Sweep columns (by FMU name) seen as an ImpactResult (by field name), rows ``sel``."""

    def __init__(self, columns, sel):
        self._columns, self._sel = columns, sel

    def __getattr__(self, field):
        if field not in _NAME_OF_FIELD:
            raise AttributeError(field)
        return np.asarray(self._columns[_NAME_OF_FIELD[field]])[self._sel]


def agreement_report(a: dict, b: dict) -> tuple[int, dict]:
    """(cases compared, {output: description of a case beyond tolerance}) for two sweep tables
    (column dicts) of the same cases; only cases both back ends evaluated (``ok``) are compared."""
    if not np.array_equal(np.asarray(a["case"]), np.asarray(b["case"])):
        raise ValueError("the two results cover different cases")
    ok = np.asarray(a["ok"], dtype=bool) & np.asarray(b["ok"], dtype=bool)
    problems: dict = {}
    rows = np.flatnonzero(ok)
    for sel, inputs, options in impact_groups(a, rows):
        tol, flips = tolerances(inputs.pop("v"), inputs, **options)
        for line in disagreements(_Columns(a, sel), _Columns(b, sel), tol, flips):
            problems.setdefault(_NAME_OF_FIELD[line.split(":", 1)[0]], line)
    return int(rows.size), problems


def compare_results(a, b, names=None) -> dict:
    """Largest difference per output between two results (or column dicts) of the same spec.

    Reals: max |a - b| / max(1, |b|) over cases where both are finite (NaN and inf must match
    exactly, else the difference is inf); Booleans: number of cases that differ. ``names``:
    default, every output both have.
    """
    ca = a.columns if isinstance(a, SweepResult) else a
    cb = b.columns if isinstance(b, SweepResult) else b
    if not np.array_equal(ca["case"], cb["case"]):
        raise ValueError("the two results cover different cases")
    out = {}
    if names is None:
        names = [n for n in (*OUTPUT_NAMES, "ok") if n in ca and n in cb]
    for name in names:
        x, y = np.asarray(ca[name]), np.asarray(cb[name])
        if x.dtype == bool or y.dtype == bool:
            out[name] = int(np.count_nonzero(x.astype(bool) != y.astype(bool)))
            continue
        finite = np.isfinite(x) & np.isfinite(y)
        same_special = (np.isnan(x) & np.isnan(y)) | (x == y)
        if not np.all(finite | same_special):
            out[name] = math.inf
            continue
        diff = np.abs(x[finite] - y[finite]) / np.maximum(1.0, np.abs(y[finite]))
        out[name] = float(diff.max()) if diff.size else 0.0
    return out
