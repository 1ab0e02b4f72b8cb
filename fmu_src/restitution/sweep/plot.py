"""The plot of a sweep (matplotlib). A grid sweep's COR map: e against approach speed and t/d, one panel per
material pair; with ``--columns`` that leave one of them out, e against the inputs the table keeps that the
sweep varies (a curve for one, a map for two). A sweep with random draws: the distribution of e (a histogram
of e around one point, or its median and 95 % band along a grid axis)."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ..output_files import atomic_write
from .columns import INPUT_NAMES, T_OVER_D, pair_label
from ..inputs import unit_of

__all__ = ["plot_cor_map", "plot_random", "NoPlot", "plot_kind", "map_axes"]

LAMBDA_MAX = 1.5  #: Zener's studied range, lambda <= 1.5
VSTAR_MAX = 1000.0  #: range of the JGM fits, V* <= 1000


class NoPlot(ValueError):
    """Why the table's kept columns allow no plot (one line, said instead of the plot)."""


def plot_kind(spec) -> tuple[str, str]:
    """(file name suffix, what it is called) of the plot a sweep draws: ``("_hist.png", "histogram of e")``
    for random draws around one point (no grid axis besides the pairs), else ``("_cor_map.png", "COR map")``
    (a grid's map or curves; with random draws, the median and band of e along the grid)."""
    if spec is not None and spec.random and not spec.grid:
        return "_hist.png", "histogram of e"
    return "_cor_map.png", "COR map"


def _log_axis(values) -> bool:
    v = values[np.isfinite(values)]
    return v.size > 1 and v.min() > 0 and v.max() / v.min() > 20


def _edges(centres, log):
    c = np.log10(centres) if log else centres
    if c.size == 1:
        e = np.array([c[0] - 0.5, c[0] + 0.5])
    else:
        mid = 0.5 * (c[1:] + c[:-1])
        e = np.concatenate([[c[0] - (mid[0] - c[0])], mid, [c[-1] + (c[-1] - mid[-1])]])
    return 10 ** e if log else e


#: Up to this many values of one input over more of the other, a grid is drawn as curves.
MAX_CURVES = 6


def _curves(ax, x, key, e, valid, xname: str, label: str) -> None:
    """e against ``x``, one line per value of ``key`` (labelled ``label.format(value)``); cases outside
    the validated range marked."""
    for value in np.unique(key):
        sel = key == value
        order = np.argsort(x[sel], kind="stable")
        ax.plot(x[sel][order], e[sel][order], "-", lw=1.2, label=label.format(value))
        bad = sel & ~valid
        if bad.any():
            ax.plot(x[bad], e[bad], "rx", ms=4)
    if not valid.all():
        ax.plot([], [], "rx", ms=4, label="outside validated range")
    ax.set_xscale("log" if _log_axis(x) else "linear")
    ax.set(xlabel=xname, ylabel="apparent COR e")
    ax.axhline(0.0, color="0.6", lw=0.5)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)


def fit_title(fig, title: str, fontsize: float = 10):
    """``fig``'s suptitle, wrapped at word boundaries so that every line fits the figure's width
    (measured as drawn; a single pair's map is narrower than the default title)."""
    import textwrap

    text = fig.suptitle(title, fontsize=fontsize)
    renderer = fig.canvas.get_renderer()
    limit = 0.96 * fig.bbox.width
    width = len(title)
    while width > 10 and text.get_window_extent(renderer).width > limit:
        width = int(width * 0.85)
        text.set_text(textwrap.fill(title, width=width, break_long_words=False))
    return text


def plot_cor_map(result, path, title: str | None = None, dpi: int = 120, statistics=None) -> Path:
    """Draw e over (v_approach, t/d) for each material pair of a :class:`SweepResult` into ``path``
    (over the inputs :func:`map_axes` finds when the table leaves one of the two out: a curve of e for one
    input, a map for two; :class:`NoPlot`, saying why, when it keeps neither e nor an input the sweep varies).

    A grid sweep gives a colour map (each cell the mean e of its cases, with e contours and
    a dashed line where the validity range ends: lambda <= 1.5 and V* <= 1000), or curves when one
    of the two takes at most :data:`MAX_CURVES` values (one curve per value); cases off a grid
    are drawn as coloured points; a sweep over only one of the two is drawn as a curve.
    A sweep with random draws is drawn by :func:`plot_random` (from ``statistics``, a
    :class:`~restitution.sweep.statistics.SweepStatistics` of it, gathered here if not given).
    """
    spec = getattr(result, "spec", None)
    if spec is not None and spec.random:
        if statistics is None:
            from .statistics import SweepStatistics

            statistics = SweepStatistics(spec, keep=set(result.columns))
            statistics.add(result.columns)
        return plot_random(statistics, path, title=title, dpi=dpi)
    cols = result.columns if hasattr(result, "columns") else result
    if "e" not in cols:
        raise NoPlot("--columns leaves out e, which the COR map draws")
    xname, yname = (map_axes(cols, spec) + [None])[:2]
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt
    from matplotlib.colors import Normalize

    pairs = list(dict.fromkeys(cols["pair"].tolist()))
    n_all = np.size(cols["e"])
    ok = np.asarray(cols["ok"], dtype=bool) if "ok" in cols else np.isfinite(cols["e"])
    valid_all = np.asarray(cols["valid"], dtype=bool) if "valid" in cols else np.ones(n_all, dtype=bool)
    e_all = np.asarray(cols["e"], dtype=float)[ok]
    lo = min(0.0, float(np.nanmin(e_all))) if e_all.size else 0.0
    hi = max(1.0, float(np.nanmax(e_all))) if e_all.size else 1.0
    norm = Normalize(vmin=lo, vmax=hi)
    spec_fixed = _fixed_text(spec) if spec is not None else ""
    axis = _shared_axis(cols, pairs, ok, [a for a in (xname, yname) if a is not None])
    if axis is not None:  # several pairs over one input: one panel, a curve per pair
        return _pairs_on_one_panel(cols, ok, valid_all, axis, path, title, spec_fixed, dpi)
    n = max(1, len(pairs))
    ncols = min(3, n)
    nrows = math.ceil(n / ncols)
    fig, axes = plt.subplots(nrows, ncols, figsize=(4.6 * ncols + 0.8, 3.9 * nrows), squeeze=False,
                             constrained_layout=True)
    mappable = None
    boundary = False
    for k, pair in enumerate(pairs):
        ax = axes[k // ncols][k % ncols]
        sel = (cols["pair"] == pair) & ok
        v = np.asarray(cols[xname], dtype=float)[sel]  # v_approach, or the first input kept that varies
        td = np.asarray(cols[yname], dtype=float)[sel] if yname else np.zeros(v.size)  # t_over_d, or the second
        e = np.asarray(cols["e"], dtype=float)[sel]
        valid = valid_all[sel]
        ax.set_title(pair_label(pair), fontsize=10)
        if e.size == 0:
            ax.text(0.5, 0.5, "no case with inputs in range", ha="center", va="center", transform=ax.transAxes)
            continue
        uv, iv = np.unique(v, return_inverse=True)
        ut, it = np.unique(td, return_inverse=True)
        if uv.size > 1 and ut.size > 1:
            logv, logt = _log_axis(uv), _log_axis(ut)
            cells = uv.size * ut.size
            gridded = cells <= 4 * e.size and np.unique(iv * ut.size + it).size == cells
            if gridded and min(uv.size, ut.size) <= MAX_CURVES and uv.size != ut.size:
                # a few values of one input over many of the other (COR against thickness at 1, 3 and
                # 5 m/s): one curve per value, not a colour map of a few wide blocks
                if uv.size < ut.size:
                    _curves(ax, td, v, e, valid, _map_label(yname), _value_label(xname))
                else:
                    _curves(ax, v, td, e, valid, _map_label(xname), _value_label(yname))
                continue
            if gridded:
                flat = iv.ravel() * ut.size + it.ravel()
                count = np.bincount(flat, minlength=cells)
                emap = (np.bincount(flat, weights=e, minlength=cells) / count).reshape(uv.size, ut.size).T
                nan = np.full(n_all, np.nan)
                lam = np.asarray(cols.get("zener.lambda", nan), dtype=float)[sel]
                vstar = np.asarray(cols.get("jgm.V_star", nan), dtype=float)[sel]
                lmap = (np.bincount(flat, weights=lam, minlength=cells) / count).reshape(uv.size, ut.size).T
                smap = (np.bincount(flat, weights=vstar, minlength=cells) / count).reshape(uv.size, ut.size).T
                mappable = ax.pcolormesh(_edges(uv, logv), _edges(ut, logt), emap, cmap="viridis", norm=norm,
                                         shading="flat")
                if uv.size > 2 and ut.size > 2:
                    levels = [x for x in np.round(np.arange(-1.0, 1.0001, 0.1), 1) if emap.min() < x < emap.max()]
                    if levels:
                        cs = ax.contour(uv, ut, emap, levels=levels, colors="white", linewidths=0.6, alpha=0.8)
                        ax.clabel(cs, fmt=lambda x: f"{round(x, 1) + 0.0:.1f}", fontsize=7)
                    for m, limit in ((lmap, LAMBDA_MAX), (smap, VSTAR_MAX)):
                        if np.isfinite(m).all() and m.min() < limit < m.max():
                            ax.contour(uv, ut, m, levels=[limit], colors="red", linewidths=1.0, linestyles="--")
                            boundary = True
                if count.max() > 1:
                    ax.text(0.02, 0.02, f"mean of {count.max()} cases per cell", transform=ax.transAxes,
                            fontsize=7, color="white")
            else:
                mappable = ax.scatter(v, td, c=e, s=6, cmap="viridis", norm=norm, linewidths=0)
                if not valid.all():
                    ax.scatter(v[~valid], td[~valid], s=10, facecolors="none", edgecolors="red", linewidths=0.3,
                               alpha=0.6)
            ax.set_xscale("log" if logv else "linear")
            ax.set_yscale("log" if logt else "linear")
            ax.set_xlabel(_map_label(xname))
            ax.set_ylabel(_map_label(yname))
        else:
            x, name = (v, _map_label(xname)) if uv.size > 1 or not yname else (td, _map_label(yname, short=True))
            order = np.argsort(x, kind="stable")
            if np.unique(x).size == x.size:
                ax.plot(x[order], e[order], "-", lw=1.2)
            else:
                ax.plot(x, e, ".", ms=2, alpha=0.5)
            if not valid.all():
                ax.plot(x[~valid], e[~valid], "rx", ms=4, label="outside validated range")
                ax.legend(fontsize=7)
            ax.set_xscale("log" if _log_axis(x) else "linear")
            ax.set_xlabel(name)
            ax.set_ylabel("apparent COR e")
            ax.grid(alpha=0.3)
    for k in range(len(pairs), nrows * ncols):
        axes[k // ncols][k % ncols].set_visible(False)
    if mappable is not None:
        fig.colorbar(mappable, ax=axes, label="apparent COR e", shrink=0.9)
    if title is None:
        title = _grid_title(len(ok), spec_fixed)
        if boundary:
            title += "; red dashes: edge of the validated range (lambda <= 1.5, V* <= 1000)"
        elif not valid_all.all():
            title += "; red marks: outside the validated range"
        hidden = _hidden_axes(spec, cols, (xname, yname))
        if hidden:
            title += f"; {', '.join(hidden)} not kept by --columns: the points of its values are not told apart"
    fit_title(fig, title, fontsize=10)
    return save_figure(fig, path, dpi)


#: The inputs a COR map draws along, with their axis labels.
_MAP_AXES = {"v_approach": "approach speed v [m/s]", "t_over_d": "plate thickness / sphere diameter t/d"}
#: Their labels of one curve's value.
_VALUE_LABELS = {"v_approach": "v = {:g} m/s", "t_over_d": "t/d = {:g}"}


def _map_label(name: str, short: bool = False) -> str:
    """An axis label: the COR map's own for speed and t/d, else the input's name with its SI unit."""
    if short and name == T_OVER_D:
        return "t/d"
    return _MAP_AXES.get(name) or _axis_label(name)


def _value_label(name: str) -> str:
    """A curve's label for one value of input ``name``, a format with one field."""
    unit = unit_of(name)
    return _VALUE_LABELS.get(name) or f"{name} = {{:g}}{' ' + unit if unit else ''}"


def _varies(cols, name: str, pairs, ok) -> bool:
    """Whether input ``name`` takes more than one value within some material pair."""
    values = np.asarray(cols[name], dtype=float)
    return any(np.unique(values[(cols["pair"] == pair) & ok]).size > 1 for pair in pairs)


def _hidden_axes(spec, cols, drawn) -> list:
    """The sweep's grid axes that the plot does not draw and the table does not keep (nor their twin,
    plate.t for t_over_d and back): their values are drawn on top of each other."""
    twins = {"plate.t": T_OVER_D, T_OVER_D: "plate.t"}
    grid = [name for name in (spec.grid if spec is not None else ()) if name != "pair"]
    seen = {*drawn, *cols} - {None}
    return [name for name in grid if name not in seen and twins.get(name, name) not in seen]


def map_axes(cols, spec=None) -> list:
    """The inputs a grid sweep's plot draws e along: ``v_approach`` and ``t_over_d`` when the table keeps
    both (the COR map); else those of the kept inputs that vary within a pair, up to two, the sweep's grid
    axes first (a curve of e for one, a map for two). :class:`NoPlot` when the table keeps none."""
    if "v_approach" in cols and T_OVER_D in cols:
        return ["v_approach", T_OVER_D]

    n = np.size(cols["e"])
    ok = np.asarray(cols["ok"], dtype=bool) if "ok" in cols else np.isfinite(np.asarray(cols["e"], dtype=float))
    pairs = list(dict.fromkeys(np.asarray(cols["pair"]).tolist())) if "pair" in cols else [None]
    cols = cols if "pair" in cols else {**cols, "pair": np.full(n, None, dtype=object)}
    grid = [name for name in (spec.grid if spec is not None else ()) if name != "pair"]
    twins = {"plate.t": T_OVER_D, T_OVER_D: "plate.t"}  # one derived from the other: the same axis
    order = [*grid, *(twins[name] for name in grid if name in twins), "v_approach", T_OVER_D, *INPUT_NAMES]
    axes = []
    for name in dict.fromkeys(order):
        if len(axes) < 2 and name in cols and twins.get(name) not in axes and _varies(cols, name, pairs, ok):
            axes.append(name)
    if not axes:
        varied = ", ".join(grid) if grid else "v_approach, t_over_d"
        raise NoPlot(f"--columns keeps none of the inputs the sweep varies ({varied}); keep one to draw e "
                     f"against it")
    return sorted(axes, key=lambda a: a != "v_approach")  # speed along x, as in the COR map


def _grid_title(n_cases: int, fixed: str) -> str:
    """A grid sweep's map title: its cases and the values it held fixed."""
    return f"Apparent COR e (Green 2022), {n_cases} cases" + (f"; {fixed}" if fixed else "")


def _shared_axis(cols, pairs, ok, axes) -> str | None:
    """The one input of ``axes`` (``v_approach`` or ``t_over_d``, or the kept inputs a plot draws along)
    that varies within every pair when there are several pairs and the other input holds one value within
    each: their curves share one panel."""
    if len(pairs) < 2:
        return None
    shared = set()
    for pair in pairs:
        sel = (cols["pair"] == pair) & ok
        varying = {name for name in axes if np.unique(np.asarray(cols[name], dtype=float)[sel]).size > 1}
        if len(varying) != 1:
            return None
        shared |= varying
    return shared.pop() if len(shared) == 1 else None


def _pairs_on_one_panel(cols, ok, valid_all, axis, path, title, fixed, dpi) -> Path:
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.8, 4.4), constrained_layout=True)
    labels = np.array([pair_label(p) for p in np.asarray(cols["pair"])[ok]], dtype=object)
    _curves(ax, np.asarray(cols[axis], dtype=float)[ok], labels, np.asarray(cols["e"], dtype=float)[ok],
            valid_all[ok], _map_label(axis), "{}")
    if title is None:
        title = _grid_title(len(ok), fixed)
    fit_title(fig, title, fontsize=10)
    return save_figure(fig, path, dpi)


def save_figure(fig, path, dpi, what: str = "COR map") -> Path:
    """Write ``fig`` to ``path`` under a temporary name, renamed when whole (restitution.output_files;
    ``what`` names it in an error), and close it."""
    import matplotlib.pyplot as plt

    path = Path(path)
    try:
        atomic_write(path, lambda tmp: fig.savefig(tmp, dpi=dpi), what)
    finally:
        plt.close(fig)
    return path


def _axis_label(name: str) -> str:
    """An input's axis label with its SI unit: ``v_approach [m/s]``, ``t/d [1]``."""
    if name == T_OVER_D:
        return "plate thickness / sphere diameter t/d [1]"
    return f"{name} [{unit_of(name) or '1'}]"


def _draws_text(spec) -> str:
    """What a random sweep drew and held: ``plate.Sy ~ uniform_rel:0.15; fixed plate.t = 3mm``."""
    text = "; ".join(f"{name} ~ {given}" for name, given in spec.random.items())
    return text + ("; " + _fixed_text(spec) if spec.fixed else "")


def _fixed_text(spec) -> str:
    """The values a sweep holds fixed, with their units: ``plate.t = 3mm, sphere.d = 0.01 m``."""
    return ", ".join(f"{name} = {value}{' ' + unit_of(name) if unit_of(name) and _bare(value) else ''}"
                     for name, value in spec.fixed.items())


def _bare(value) -> bool:
    """Whether a fixed value is a bare number (SI: its unit is then shown), not a text with its own unit."""
    try:
        float(value)
    except (TypeError, ValueError):
        return False
    return True


def plot_random(statistics, path, title: str | None = None, dpi: int = 120) -> Path:
    """The distribution of e in a sweep with random draws, one panel per material pair, from its
    :class:`~restitution.sweep.statistics.SweepStatistics`: with no grid axis besides the pairs, a
    histogram of e with its mean and its 2.5 and 97.5 % percentiles marked; with grid axes, e against
    the longest one, its median per grid point and the band between the 2.5 and 97.5 % percentiles
    (one band per value of the other axes, up to :data:`MAX_CURVES`; medians only beyond)."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    if "e" not in statistics.names:
        raise NoPlot("--columns leaves out e, which the plot of a random sweep draws")
    spec = statistics.spec
    stats, coords = statistics.by_point(["e"])
    e = stats["e"]
    axes = sorted((a for a in coords if a != "pair"), key=lambda a: -np.unique(coords[a]).size)
    pair_of = coords["pair"].astype(int) if "pair" in coords else np.zeros(spec.n_grid, dtype=int)
    labels = spec.pairs or [""]
    ncols = min(3, len(labels))
    nrows = math.ceil(len(labels) / ncols)
    fig, grid = plt.subplots(nrows, ncols, figsize=(4.6 * ncols + 0.8, 3.9 * nrows), squeeze=False,
                             constrained_layout=True)
    values, points = statistics.values("e") if not axes else (None, None)
    for k, pair in enumerate(labels):
        ax = grid[k // ncols][k % ncols]
        ax.set_title(pair_label(pair), fontsize=10)
        here = np.flatnonzero(pair_of == k)
        if not axes:  # random draws around one point: their histogram
            v = values if points is None else values[points == k]
            v = v[np.isfinite(v)]
            if v.size == 0:
                ax.text(0.5, 0.5, "no case with inputs in range", ha="center", va="center", transform=ax.transAxes)
                continue
            ax.hist(v, bins=min(60, max(10, int(np.sqrt(v.size)))), color="tab:blue", alpha=0.75)
            ax.axvline(e["mean"][k], color="k", lw=1.4, label=f"mean {e['mean'][k]:.4g}")
            for p, style in (("p2.5", "--"), ("p97.5", "--")):
                ax.axvline(e[p][k], color="tab:red", lw=1.1, ls=style)
            ax.plot([], [], "--", color="tab:red", label=f"2.5-97.5 %: {e['p2.5'][k]:.4g} ... {e['p97.5'][k]:.4g}")
            ax.set(xlabel="apparent COR e [1]", ylabel="cases per bin")
            ax.legend(fontsize=7)
            continue
        x_axis, others = axes[0], axes[1:]
        x = coords[x_axis]
        key = np.zeros(spec.n_grid, dtype=np.int64)  # one group per combination of the other axes' values
        for other in others:
            key = key * spec.n_grid + np.unique(coords[other], return_inverse=True)[1]
        groups = np.unique(key[here])
        banded = groups.size <= MAX_CURVES
        for group in groups:
            sel = here[key[here] == group]
            sel = sel[np.argsort(x[sel], kind="stable")]
            label = statistics.point_label(coords, sel[0], skip=("pair", x_axis)) or "median"
            (line,) = ax.plot(x[sel], e["p50"][sel], "-", lw=1.3 if banded else 0.8, label=label if banded else None)
            if banded:
                ax.fill_between(x[sel], e["p2.5"][sel], e["p97.5"][sel], color=line.get_color(), alpha=0.25, lw=0)
        ax.fill_between([], [], [], color="0.5", alpha=0.25, label="2.5-97.5 % of the draws")
        if _log_axis(x[here]):
            from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

            ax.set_xscale("log")  # plain numbers at 1, 2, 5 per decade: an axis of less than two decades reads
            ax.xaxis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
            ax.xaxis.set_major_formatter(FuncFormatter(lambda value, _pos: f"{value:g}"))
            ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set(xlabel=_axis_label(x_axis), ylabel="apparent COR e [1], median")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    for k in range(len(labels), nrows * ncols):
        grid[k // ncols][k % ncols].set_visible(False)
    if title is None:
        counts = statistics.counts()
        title = f"Apparent COR e (Green 2022), {counts['ok']:,} random cases"
        if counts["cases"] > counts["ok"]:
            title += f" ({counts['cases'] - counts['ok']:,} with inputs out of range left out)"
        title += f": {_draws_text(spec)}"
    fit_title(fig, title, fontsize=10)
    return save_figure(fig, path, dpi, plot_kind(spec)[1])
