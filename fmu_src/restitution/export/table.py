"""``restitution export table``: the model's e, contact time and flags over a speed range, as CSV, JSON or
Solfec's restitution list (``[vel0, res0, vel1, res1, ...]``, Solfec issue 76: a COR given per impact speed).

The rows are :func:`restitution.model.impact` over the speeds (one array call), nothing recomputed.
"""
from __future__ import annotations

import json

import numpy as np

from .hosts import FLAGS

__all__ = ["FORMATS", "speeds", "table", "render"]

#: The formats of the table: csv (a header and one row a speed), json (one list a column), solfec.
FORMATS = ("csv", "json", "solfec")
#: The columns with a number, in order, then :data:`~restitution.export.hosts.FLAGS`.
NUMBERS = ("v", "e", "t_contact")


def speeds(low: float, high: float, points: int) -> np.ndarray:
    """``points`` speeds from ``low`` to ``high`` [m/s], evenly spaced (ValueError for high <= low or points < 2)."""
    if not high > low:
        raise ValueError(f"--v-range {low:g} {high:g} m/s: the second speed must be above the first")
    if points < 2:
        raise ValueError(f"--points {points}: at least 2")
    return np.linspace(low, high, points)


def table(v: np.ndarray, params: dict, **impact_options) -> dict:
    """{column: list} of :data:`NUMBERS` and :data:`~restitution.export.hosts.FLAGS` at the speeds ``v`` [m/s]
    for the keyword arguments ``params`` of :func:`~restitution.model.impact` (SI)."""
    from ..model import impact

    result = impact(np.asarray(v, dtype=float), **params, **impact_options)
    columns = {"v": [float(x) for x in v], "e": [float(x) for x in np.atleast_1d(result.e)],
               "t_contact": [float(x) for x in np.atleast_1d(result.t_contact)]}
    columns.update({flag: [bool(x) for x in np.atleast_1d(getattr(result, flag))] for flag in FLAGS})
    return columns


def render(columns: dict, form: str) -> str:
    """The table as text in ``form`` (:data:`FORMATS`)."""
    if form == "json":
        return json.dumps(columns, indent=1, allow_nan=False)
    if form == "solfec":
        return "[" + ", ".join(f"{v:.10g}, {e:.10g}" for v, e in zip(columns["v"], columns["e"])) + "]"
    names = [*NUMBERS, *FLAGS]
    lines = [",".join(names)]
    for i in range(len(columns["v"])):
        lines.append(",".join(f"{columns[n][i]:.10g}" if n in NUMBERS else str(int(columns[n][i])) for n in names))
    return "\n".join(lines)
