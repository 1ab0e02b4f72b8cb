"""The picture of a ``--sobol`` sweep: for each analysed output, the first-order and total Sobol' indices
of every random input as bars, with their bootstrap intervals (matplotlib)."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from .plot import fit_title, save_figure
from .sobol import SOBOL_OUTPUTS, refusals

__all__ = ["plot_sobol", "sobol_figure"]

#: Bars of each index: the key in the section, its colour, its legend.
_BARS = (("S1", "tab:blue", "first order S1"), ("ST", "tab:orange", "total ST"))


def sobol_figure(section: dict, title: str | None = None):
    """The figure of ``section`` (:meth:`~restitution.sweep.sobol.SobolCollector.analyze`'s result): one
    panel per output with indices, in the sweep's usual order; the outputs refused are named below."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    shown = list(section["sobol"])
    keys = [k for k in SOBOL_OUTPUTS if k in shown] + [k for k in shown if k not in SOBOL_OUTPUTS]
    if not keys:
        raise ValueError("no output has Sobol' indices to draw")
    names = list(section["inputs"])
    ncols = min(2, len(keys))
    nrows = math.ceil(len(keys) / ncols)
    fig, grid = plt.subplots(nrows, ncols, figsize=(max(4.6, 1.2 * len(names) + 2.6) * ncols, 3.6 * nrows + 0.6),
                             squeeze=False, constrained_layout=True)
    x, width = np.arange(len(names)), 0.38
    for k, key in enumerate(keys):
        ax = grid[k // ncols][k % ncols]
        indices = section["sobol"][key]
        low, high = 0.0, 1.0
        for j, (index, colour, label) in enumerate(_BARS):
            value = np.array([indices[n][index] for n in names])
            conf = np.array([indices[n][f"{index}_conf"] for n in names])
            ax.bar(x + (j - 0.5) * width, value, width, yerr=conf, capsize=3, color=colour, label=label)
            low, high = min(low, float(np.min(value - conf))), max(high, float(np.max(value + conf)))
        ax.axhline(0.0, color="k", lw=0.6)
        ax.set_xticks(x, names, rotation=20 if len(names) > 3 else 0)
        ax.set_ylim(low - 0.05, high + 0.05)
        column = SOBOL_OUTPUTS.get(key, key)
        ax.set_title(column if column == key else f"{column} ({key})", fontsize=10)
        ax.set_ylabel("Sobol' index [1]")
        ax.legend(fontsize=7)
    for k in range(len(keys), nrows * ncols):
        grid[k // ncols][k % ncols].set_axis_off()
    level = f"{section['conf_level']:.0%}"
    note = "; ".join(refusals(section))
    fit_title(fig, title or (f"Sobol' indices, {section['N']:,} base samples ({section['evaluations']:,} "
                             f"evaluations), {level} bootstrap intervals" + (f" ({note})" if note else "")))
    return fig


def plot_sobol(section: dict, path, title: str | None = None, dpi: int = 120) -> Path:
    """Draw :func:`sobol_figure` into ``path`` (written under a temporary name, renamed when whole)."""
    return save_figure(sobol_figure(section, title), path, dpi, "Sobol' chart")
