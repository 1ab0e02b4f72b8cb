"""Which optional extra of the package each tool needs, checked before any work: a command whose extra
is not installed stops with one line naming the ``pip install`` that brings it (exit 2), instead of
writing half its outputs and then failing on an import.

    restitution[fmu]       pythonfmu, fmpy: build and run the FMUs
    restitution[examples]  matplotlib: plots
    restitution[scene]     the scene runner (fmu, examples, tqdm)
    restitution[sweep]     dask.distributed and pandas: sweeps and their tables as DataFrames
    restitution[parquet]   pyarrow: Parquet tables
    restitution[fit]       emcee (and matplotlib): calibration posteriors and plots
"""
from __future__ import annotations

import importlib.util

__all__ = ["MissingExtra", "missing", "require"]


class MissingExtra(RuntimeError):
    """An optional package a command needs is not installed: the message is one line."""


def _installed(module: str) -> bool:
    try:
        return importlib.util.find_spec(module) is not None
    except (ImportError, ValueError):  # a parent package missing, or a module set to None
        return False


def missing(needs: dict[str, str]) -> list[tuple[str, str]]:
    """The (module, extra) pairs of ``needs`` (module -> the extra that installs it) not importable here."""
    return [(module, extra) for module, extra in needs.items() if not _installed(module)]


def require(what: str, needs: dict[str, str]) -> None:
    """:class:`MissingExtra` naming ``what`` (the command or option), the first missing module and the
    ``pip install`` of its extra, unless every module of ``needs`` is installed."""
    absent = missing(needs)
    if absent:
        module, extra = absent[0]
        others = f" (also missing: {', '.join(m for m, _ in absent[1:])})" if len(absent) > 1 else ""
        raise MissingExtra(f"{what} needs {module}, which is not installed{others}: "
                           f"pip install \"restitution[{extra}]\"")
