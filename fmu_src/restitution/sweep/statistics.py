"""Statistics of a sweep's outputs: mean, standard deviation, 2.5/50/97.5 % percentiles and the 95 %
interval of the mean of every Real output the table keeps, over the cases the model evaluated
(``ok``); the cases whose inputs left the model's domain (``ok`` false, NaN outputs) are counted
and the first of them listed.

The statistics are gathered chunk by chunk as the sweep runs (:meth:`SweepStatistics.add` is the
``on_chunk`` hook of :func:`~restitution.sweep.run.run_sweep`: every finished chunk, and on
``--resume`` every chunk kept in the parts, as the part store checks it), never from the written
table. Of a chunk only the evaluated values of the Real outputs are kept (8 bytes a value), with the
grid point of each row when the sweep has a grid; the numbers are reduced once the sweep is whole,
the chunks taken in case order so that the result does not depend on the scheduler or the chunking.

With grid axes and random draws the statistics are of the whole sweep (every grid point pooled),
and per grid point under ``by_point`` (up to :data:`MAX_POINTS` points).
"""
from __future__ import annotations

import math

import numpy as np

from .._blocks import has_own_bytes
from ..assumptions import E_NEGATIVE_MEANING, meaning_lines
from ..fmu.models.sphere_plate_impact.variables import TABLE
from ..output_files import write_json
from .order_statistics import Scratch, distinct, moments_and_order_statistics, order_statistics
from .student_t import t975
from .columns import OUTPUTS, T_OVER_D, VALIDITY, pair_label, table_counts
from ..inputs import unit_of

__all__ = ["SweepStatistics", "UNITS", "MAIN_OUTPUTS", "PERCENTILES", "describe", "write_summary"]

#: Real output columns of a sweep's table -> SI unit ("1": dimensionless).
UNITS = {v.name: v.unit for v in TABLE.outputs if v.type == "Real"}
#: Column name -> the keyword of restitution.impact()'s result (jgm.e -> e_ep), where they differ.
KEYWORDS = {name: key for name, key, vtype in OUTPUTS if vtype == "Real" and key != name}
#: The outputs printed on screen, in this order (those the table keeps).
MAIN_OUTPUTS = ("e", "jgm.e", "zener.e", "v_rebound", "zener.t_contact")
#: The percentiles reported [%]: the median and the central 95 % of the draws.
PERCENTILES = (2.5, 50.0, 97.5)
#: Out-of-range case numbers listed in the summary (the count is always whole).
LISTED_CASES = 20
#: Grid points up to which the summary gives the statistics of each one (``by_point``).
MAX_POINTS = 10_000


def _student_t975(dof: np.ndarray) -> np.ndarray:
    """The 97.5 % quantile of Student's t with ``dof`` degrees of freedom (NaN where dof < 1), once per
    distinct dof (:func:`~.student_t.t975`: plain Python, where scipy.special's import took 0.3 s)."""
    dof = np.asarray(dof, dtype=float)
    values, inverse = distinct(dof, return_inverse=True)
    return np.array([t975(d) for d in values])[inverse.ravel()].reshape(dof.shape)


def describe(values: np.ndarray, groups: np.ndarray | None = None, n_groups: int = 1,
             scratch: Scratch | None = None) -> dict:
    """Statistics of ``values`` in each of ``n_groups`` groups (``groups``: the group of each value,
    None: one group), as arrays of ``n_groups``: ``n`` (finite values), ``n_not_finite``, ``mean``,
    ``std`` (sample, n - 1), ``p2.5``, ``p50``, ``p97.5`` (linear interpolation between order
    statistics, numpy's default, Hyndman & Fan type 7) and ``ci_half`` (half-width of the 95 %
    interval of the mean, t(0.975, n - 1) std / sqrt(n)). NaN where a group has too few values.
    ``scratch``: work arrays for one group's order statistics, reused from call to call."""
    values = np.asarray(values, dtype=float)
    if groups is None and n_groups == 1:
        return _describe_one(values, scratch)
    groups = np.zeros(values.size, dtype=np.int64) if groups is None else np.asarray(groups, dtype=np.int64)
    finite = np.isfinite(values)
    n_all = np.bincount(groups, minlength=n_groups)
    v, g = values[finite], groups[finite]
    n = np.bincount(g, minlength=n_groups)
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = np.bincount(g, weights=v, minlength=n_groups) / n
        # one refinement pass: the residuals' sum corrects the rounding of the first (a sequential sum)
        mean = mean + np.bincount(g, weights=v - mean[g], minlength=n_groups) / n
        std = np.sqrt(np.bincount(g, weights=(v - mean[g]) ** 2, minlength=n_groups) / (n - 1))
    std[n < 2] = np.nan
    # percentiles: the values sorted within their group, then numpy's linear rule on each group's slice
    ordered = np.sort(v) if n_groups == 1 else v[np.lexsort((v, g))]
    first = np.concatenate([[0], np.cumsum(n)[:-1]])
    out = {"n": n, "n_not_finite": n_all - n, "mean": mean, "std": std}
    for p in PERCENTILES:
        position = (n - 1) * (p / 100.0)
        below = np.floor(position).astype(np.int64)
        above = np.minimum(below + 1, n - 1)
        fraction = position - below
        pick = n > 0
        lo = np.full(n_groups, np.nan)
        hi = np.full(n_groups, np.nan)
        lo[pick] = ordered[first[pick] + below[pick]]
        hi[pick] = ordered[first[pick] + above[pick]]
        out[f"p{p:g}"] = lo + fraction * (hi - lo)
    out["ci_half"] = _student_t975(n - 1) * std / np.sqrt(np.maximum(n, 1))
    return out


def _describe_one(values: np.ndarray, scratch: Scratch | None = None) -> dict:
    """:func:`describe` of one group, in a few passes over the values
    (:func:`~.order_statistics.moments_and_order_statistics`): the mean and the sum of squared
    deviations in the passes that count the values into bins for the percentiles' order statistics
    (exact, where a full sort of 10^6 values costs thirty times more). ``scratch``: work arrays to
    reuse (one :class:`~.order_statistics.Scratch` for all outputs)."""
    scratch = scratch or Scratch()
    # the values whole (no mask) unless some are not finite, which the fused pass finds
    got = moments_and_order_statistics(values, _ranks(values.size), scratch) if values.size else None
    v = values
    if got is None and values.size:
        v = values[np.isfinite(values)]
        got = moments_and_order_statistics(v, _ranks(v.size), scratch) if v.size else None
        if got is None and v.size:  # finite values whose sums overflow: the order statistics still hold
            got = (float(v.mean()), math.nan, order_statistics(v, _ranks(v.size), scratch))
    n = v.size if got is not None else 0
    out = {"n": np.array([n]), "n_not_finite": np.array([values.size - n])}
    if got is None:
        nan = np.array([np.nan])
        return {**out, "mean": nan, "std": nan.copy(), **{f"p{p:g}": nan.copy() for p in PERCENTILES},
                "ci_half": nan.copy()}
    mean, squares, order = got
    std = math.sqrt(squares / (n - 1)) if n > 1 else math.nan
    picked = dict(zip(_ranks(n), order))
    out.update(mean=np.array([mean]), std=np.array([std]))
    for p in PERCENTILES:
        below, above = _bracket(n, p)
        position = (n - 1) * (p / 100.0)
        lo, hi = picked[below], picked[above]
        out[f"p{p:g}"] = np.array([lo + (position - below) * (hi - lo)])
    out["ci_half"] = _student_t975(np.array([n - 1])) * std / math.sqrt(n)
    return out


def _ranks(n: int) -> list[int]:
    """The ranks of every order statistic the percentiles of n values need, ascending."""
    return sorted({r for p in PERCENTILES for r in _bracket(n, p)})


def _bracket(n: int, p: float) -> tuple[int, int]:
    """The ranks (0-based) of the two order statistics numpy's linear rule interpolates for percentile p."""
    below = math.floor((n - 1) * (p / 100.0))
    return below, min(below + 1, n - 1)


def _kept(column) -> np.ndarray:
    """A chunk's column as the statistics keep it: a read-only view where the column owns its memory or
    is a whole row of a block of outputs (holding it costs what a copy would: the statistics keep every
    output the block holds), else a copy (a view into a chunk's packed buffer or an Arrow batch would
    keep every other column of the chunk alive with it)."""
    column = np.asarray(column, dtype=float)
    if not has_own_bytes(column):
        return column.copy()
    view = column.view()
    view.flags.writeable = False
    return view


def _end_to_end(parts: list, dtype) -> np.ndarray:
    """The parts end to end: the one part itself, without a copy, when there is one."""
    if len(parts) == 1:
        return parts[0]
    return np.concatenate(parts) if parts else np.empty(0, dtype=dtype)


def _number(x) -> float | None:
    """A JSON number: a Python float, None where it is not finite."""
    x = float(x)
    return x if math.isfinite(x) else None


def _entry(stats: dict, k: int, n_out_of_range: int, unit: str) -> dict:
    """The summary's record of one output (group ``k`` of :func:`describe`'s arrays)."""
    mean, half = stats["mean"][k], stats["ci_half"][k]
    entry = {"mean": _number(mean), "std": _number(stats["std"][k]),
             **{f"p{p:g}": _number(stats[f"p{p:g}"][k]) for p in PERCENTILES},
             "n": int(stats["n"][k]), "n_out_of_range": int(n_out_of_range),
             "mean_ci95": [_number(mean - half), _number(mean + half)], "unit": unit}
    if stats["n_not_finite"][k]:  # evaluated, but not a finite number: left out of the statistics, counted
        entry["n_not_finite"] = int(stats["n_not_finite"][k])
    return entry


class SweepStatistics:
    """The statistics of one sweep's outputs, gathered from its chunks (see the module docstring).

    ``keep``: the columns the table keeps (:func:`~restitution.sweep.table.keep_columns`; None: all).
    Feed it every chunk with :meth:`add` (or call it: the ``on_chunk`` hook of ``run_sweep``); then :meth:`summary`
    (the JSON record), :meth:`text` (the table printed on screen), :meth:`by_point` (per grid point)."""

    def __init__(self, spec, keep=None):
        self.spec = spec
        self.names = [name for name in UNITS if keep is None or name in keep]
        #: first case of a chunk -> (its evaluated values per output, their grid points or None,
        #: its table_counts, its first out-of-range case numbers, its evaluated cases with e < 0 or None
        #: where it keeps neither e nor e_negative)
        self._chunks = {}
        self._whole = None  # whole()'s result until the next chunk comes

    # --- gathering ---
    def add(self, columns: dict) -> None:
        """Take one chunk (a dict of columns, consecutive cases): keeps the evaluated values of the
        Real outputs, their grid points when the sweep has a grid, its counts and its first
        out-of-range cases. A chunk given again (the same first case) replaces the one before."""
        case = np.asarray(columns["case"])
        if case.size == 0:
            return
        ok = np.asarray(columns["ok"], dtype=bool)
        if ok.all():  # every case evaluated: no mask; a column that owns its memory is kept without a copy
            values, evaluated = {name: _kept(columns[name]) for name in self.names}, case
        else:
            values, evaluated = {name: np.asarray(columns[name], dtype=float)[ok] for name in self.names}, case[ok]
        points = evaluated // self.spec.samples if self.spec.n_grid > 1 else None
        self._chunks[int(case[0])] = (values, points, table_counts(columns), case[~ok][:LISTED_CASES].tolist(),
                                      _negative(columns, ok))
        self._whole = None

    def __call__(self, start: int, stop: int, columns: dict) -> None:
        """:meth:`add`, as ``run_sweep``'s ``on_chunk`` hook calls it (the chunk's cases start ... stop - 1)."""
        self.add(columns)

    def __len__(self):
        """Cases taken so far."""
        return sum(chunk[2]["cases"] for chunk in self._chunks.values())

    def _joined(self, names=None):
        """(values per output of ``names``, default all kept; grid points or None) of every chunk, in case order."""
        chunks = [self._chunks[k] for k in sorted(self._chunks)]
        values = {name: _end_to_end([c[0][name] for c in chunks], float)
                  for name in (self.names if names is None else names)}
        points = _end_to_end([c[1] for c in chunks], np.int64) if self.spec.n_grid > 1 else None
        return values, points

    def values(self, name: str) -> tuple[np.ndarray, np.ndarray | None]:
        """(the evaluated values of output ``name`` in case order, the grid point of each, None
        without a grid)."""
        values, points = self._joined([name])
        return values[name], points

    def counts(self) -> dict:
        """:func:`~restitution.sweep.table.table_counts` of the whole sweep."""
        total = {}
        for chunk in self._chunks.values():
            for key, value in chunk[2].items():
                total[key] = total.get(key, 0) + value
        return total or {"cases": 0, "ok": 0, "inside": 0, **{flag: 0 for flag in VALIDITY}}

    def e_negative(self) -> int | None:
        """Evaluated cases with e < 0 (``e_negative``); None when the table keeps neither e nor e_negative."""
        counts = [chunk[4] for chunk in self._chunks.values()]
        return None if any(n is None for n in counts) else sum(counts)

    def out_of_range_cases(self) -> list:
        """The first :data:`LISTED_CASES` case numbers whose inputs left the model's domain."""
        cases = [c for k in sorted(self._chunks) for c in self._chunks[k][3]]
        return cases[:LISTED_CASES]

    # --- results ---
    def whole(self) -> dict:
        """Output name -> :func:`describe`'s arrays (one group: the whole sweep); computed once for the
        printed table and the summary alike."""
        if self._whole is None:
            values, _points = self._joined()
            scratch = Scratch()
            self._whole = {name: describe(values[name], scratch=scratch) for name in self.names}
        return self._whole

    def by_point(self, names=None) -> tuple[dict, dict]:
        """(output name -> :func:`describe`'s arrays over the grid points, grid coordinates: axis name
        -> the value at each point, ``pair`` as indices into ``spec.pairs``), for ``names`` (default:
        every output kept). A sweep without a grid is one point."""
        names = self.names if names is None else [n for n in names if n in self.names]
        values, points = self._joined(names)
        n_points = self.spec.n_grid
        stats = {name: describe(values[name], points, n_points) for name in names}
        index = np.unravel_index(np.arange(n_points), self.spec.shape) if self.spec.shape else ()
        coords = {axis: np.asarray(axis_values)[i] for (axis, axis_values), i in zip(self.spec.axes.items(), index)}
        return stats, coords

    def summary(self, **about) -> dict:
        """The JSON record: the sweep (random inputs and their distributions, grid, fixed values,
        samples, seed; ``about``: what else to record, e.g. the back end), the counts, the
        statistics of every output over the evaluated cases, and per grid point (``by_point``)."""
        counts = self.counts()
        n_out = counts["cases"] - counts["ok"]
        whole = self.whole()
        record = {"sweep": {**self._describe_spec(), **about},
                  "n_cases": counts["cases"], "n_evaluated": counts["ok"],
                  "out_of_range": {"n": n_out, "cases": self.out_of_range_cases(),
                                   "meaning": "inputs outside the model's domain (ok = False, outputs NaN); "
                                              f"the first {LISTED_CASES} case numbers are listed"},
                  "outside_validated_ranges": {flag: counts[flag] for flag in VALIDITY},
                  **({"e_negative": {"n": self.e_negative(), "meaning": f"e < 0: {E_NEGATIVE_MEANING}"}}
                     if self.e_negative() is not None else {}),
                  "method": {"over": "the evaluated cases (ok = True) with a finite value",
                             "std": "sample standard deviation (n - 1)",
                             "percentiles": "linear interpolation between order statistics (numpy's default, "
                                            "Hyndman & Fan type 7)",
                             "mean_ci95": "mean -+ t(0.975, n - 1) std / sqrt(n)"},
                  "outputs": {name: {**_entry(whole[name], 0, n_out, UNITS[name]),
                                     **({"keyword": KEYWORDS[name]} if name in KEYWORDS else {})}
                              for name in self.names}}
        if self.spec.n_grid > 1 and self.spec.random:
            if self.spec.n_grid <= MAX_POINTS:
                record["by_point"] = self._points_record()
            else:
                record["by_point_omitted"] = f"{self.spec.n_grid:,} grid points, over {MAX_POINTS:,}"
        return record

    def _points_record(self) -> list:
        stats, coords = self.by_point()
        out = []
        for k in range(self.spec.n_grid):
            where = {axis: (self.spec.pairs[int(v[k])] if axis == "pair" else float(v[k])) for axis, v in coords.items()}
            n_evaluated = int(stats[self.names[0]]["n"][k] + stats[self.names[0]]["n_not_finite"][k]) if self.names else 0
            n_out = self.spec.samples - n_evaluated
            out.append({**where, "outputs": {name: _entry(stats[name], k, n_out, UNITS[name]) for name in self.names}})
        return out

    def _describe_spec(self) -> dict:
        spec = self.spec
        random = {}
        for name, (kind, args) in spec.distributions.items():
            unit = "1" if kind.endswith("_rel") or name == T_OVER_D else (unit_of(name) or "1")
            random[name] = {"given": spec.random[name], "distribution": kind, "parameters": list(args),
                            "unit": unit, **({"relative_to": "the value the case has without the draw"}
                                             if kind.endswith("_rel") else {})}
        return {"random": random, "samples": spec.samples, "seed": spec.seed,
                "grid": {name: int(size) for name, size in zip(spec.grid, spec.shape[1 if spec.pairs else 0:])},
                "n_grid_points": spec.n_grid, "spec": spec.as_dict()}

    def text(self, names=MAIN_OUTPUTS) -> str:
        """The statistics of ``names`` (those kept) as a compact aligned table, with units."""
        counts = self.counts()
        n_out = counts["cases"] - counts["ok"]
        names = [name for name in names if name in self.names]
        if not names:
            return f"statistics: none of {', '.join(KEYWORDS.get(n, n) for n in MAIN_OUTPUTS)} is kept by --columns"
        whole = self.whole()
        head = (f"statistics of {counts['cases']:,} cases ({counts['ok']:,} evaluated, {n_out:,} with inputs "
                f"out of range{', left out' if n_out else ''}):")
        rows = [("output", "unit", "mean", "std", "p2.5", "p50", "p97.5", "mean 95% CI")]
        for name in names:
            s = whole[name]
            mean, half = s["mean"][0], s["ci_half"][0]
            label = KEYWORDS.get(name, name)
            rows.append((label, UNITS[name], *(f"{s[k][0]:.6g}" for k in ("mean", "std", "p2.5", "p50", "p97.5")),
                         f"[{mean - half:.6g}, {mean + half:.6g}]"))
        widths = [max(len(row[j]) for row in rows) for j in range(len(rows[0]))]
        lines = [head]
        for row in rows:
            cells = [row[0].ljust(widths[0]), row[1].ljust(widths[1])]
            cells += [cell.rjust(w) for cell, w in zip(row[2:-1], widths[2:-1])] + [row[-1]]
            lines.append("  " + "  ".join(cells).rstrip())
        lines += meaning_lines(self.e_negative(), counts["valid"], counts["ok"], "evaluated cases")
        return "\n".join(lines)

    def point_label(self, coords: dict, k: int, skip=()) -> str:
        """Where grid point ``k`` is: ``t/d = 0.3, v_approach = 2 m/s`` (``skip``: axes left out)."""
        bits = []
        for axis, values in coords.items():
            if axis in skip:
                continue
            if axis == "pair":
                bits.append(pair_label(self.spec.pairs[int(values[k])]))
            else:
                unit = unit_of(axis)
                bits.append(f"{axis} = {values[k]:g}{' ' + unit if unit else ''}")
        return ", ".join(bits)


def _negative(columns: dict, ok: np.ndarray) -> int | None:
    """A chunk's evaluated cases with e < 0: its ``e_negative`` flags, else its e; None with neither."""
    if "e_negative" in columns:
        return int(np.count_nonzero(ok & np.asarray(columns["e_negative"], dtype=bool)))
    if "e" in columns:
        return int(np.count_nonzero(ok & (np.asarray(columns["e"], dtype=float) < 0.0)))
    return None


def write_summary(path, statistics: dict, extra_sections: dict | None = None):
    """The summary JSON: ``statistics`` (:meth:`SweepStatistics.summary`) and ``extra_sections``
    (e.g. ``{"sobol": ...}``) as top-level keys, written atomically (non-finite numbers as null). A
    section that would replace one of the statistics' keys is a ValueError."""
    extra = dict(extra_sections or {})
    clash = sorted(set(extra) & set(statistics))
    if clash:
        raise ValueError(f"summary sections {clash} are already taken by the statistics")
    return write_json(path, {**statistics, **extra}, "--summary")
