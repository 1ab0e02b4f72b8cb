"""Every file a sweep writes, resolved and checked before any work: the table (``--out``), the finished
chunks' folder beside it (``<out>.parts/``), the plot, the Sobol' chart and the summary.

Each is checked as :func:`restitution.output_files.check_output` checks an output (a writable regular
file, never a directory or a device), and together they must not land on an input (the FMU, the spec
file) or on one another, links and hard links included: a refusal is one line
(:class:`~restitution.output_files.OutputPathError`) before the cluster starts, never after the run.
"""
from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

from ..extras import require
from ..output_files import OutputPathError, check_output, check_outputs

__all__ = ["SweepOutputs", "resolve_outputs", "check_sweep_outputs"]


@dataclass(frozen=True)
class SweepOutputs:
    """The paths a sweep writes (None: not written)."""
    out: Path  #: the table, .csv or .parquet
    parts: Path  #: the finished chunks, one folder per back end, removed once the table is whole
    plot: Path | None  #: the plot's image
    plot_name: str  #: what the plot is called ("COR map", "histogram of e")
    sobol_chart: Path | None  #: the Sobol' indices' chart
    summary: str | None  #: the JSON summary


def default_table() -> str:
    """sweep.parquet where pyarrow can write it, else sweep.csv."""
    try:
        import pyarrow  # noqa: F401
    except ModuleNotFoundError:
        return "sweep.csv"
    return "sweep.parquet"


def resolve_outputs(spec, out, plot, summary, no_plot: bool, sobol: bool, backend: str) -> SweepOutputs:
    """The paths of a sweep of ``spec`` from the options (or the spec file's [run] table): ``out`` the
    table (None: :func:`default_table`), ``plot`` the plot (None: derived from ``out``; False or
    ``no_plot``: none), ``summary`` the JSON summary or None. :class:`~restitution.extras.MissingExtra`
    for a package the run or a file needs (``distributed``, ``fmpy`` for the FMU back end, ``matplotlib``
    for a plot, ``pyarrow`` for Parquet), OutputPathError for an ``out`` that names no file."""
    from .plot import plot_kind

    out = Path(out if out is not None else default_table())
    plot_wanted = not (no_plot or plot is False)
    require("restitution sweep", {"distributed": "sweep", **({"fmpy": "fmu"} if backend != "package" else {}),
                                  **({"matplotlib": "examples"} if plot_wanted else {}),
                                  **({"pyarrow": "parquet"} if out.suffix.lower() == ".parquet" else {})})
    if out.name in ("", ".."):  # ".", "/", "..": no file name to write (nor to derive the map's from)
        raise OutputPathError(f"--out {out}: is a directory, not a regular file; give the name of a file to write "
                              f"(.csv or .parquet)")
    plot_suffix, plot_name = plot_kind(spec)  # a histogram of e, or a COR map
    plot = Path(plot or out.with_name(out.stem + plot_suffix)) if plot_wanted else None
    sobol_chart = out.with_name(out.stem + "_sobol.png") if sobol and plot is not None else None
    return SweepOutputs(out, out.with_name(out.name + ".parts"), plot, plot_name, sobol_chart, summary)


def check_sweep_outputs(outputs: SweepOutputs, streamed: bool, inputs: dict) -> None:
    """OutputPathError (one line) for an output that cannot be written or would land on one of ``inputs``
    (label -> path or None: the FMU, the spec file) or on another output; the plot is not checked where
    the table is ``streamed`` (too big for memory: no plot is drawn)."""
    out, parts = outputs.out, outputs.parts
    plot = outputs.plot if not streamed else None
    check_output(out)
    for where in (parts, *(parts / name for name in ("package", "fmu"))):
        if os.path.lexists(where) and not where.is_dir():
            raise OutputPathError(f"--out {out}: {where} (where finished chunks go) exists and is not a directory")
    if plot is not None:
        check_output(plot, "--plot")
    if outputs.sobol_chart is not None:
        check_output(outputs.sobol_chart, "the Sobol' chart")
    if outputs.summary is not None:
        check_output(outputs.summary, "--summary")
    # no output over an input (the FMU, the spec file) or over another output, links and hard links included
    check_outputs({"--out": out, "--plot": plot, "the Sobol' chart": outputs.sobol_chart,
                   "--summary": outputs.summary}, inputs)
