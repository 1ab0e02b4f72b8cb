"""Every FMU the build makes, and the FMUs the host tools use by default.

    python -m restitution.fmu build [--out DIR]      (or: restitution-fmu build, build_scripts/build_fmu.py)

writes ``DIR/<model>.fmu`` (pythonfmu, :mod:`.python_fmu`), ``DIR/fmi2/<model>.fmu`` and
``DIR/fmi3/<model>.fmu`` (native C, :mod:`.native`) for every model. Each builder reads the package
only, never another builder's output.
"""
from __future__ import annotations

import os
from pathlib import Path

from .files import BuildError
from .python_fmu import FMUS, build_one
from .sources import PACKAGE, recorded_source_hash, source_hash

__all__ = ["FMUS", "BuildError", "build_all", "build_one", "default_fmu", "default_fmu_dir"]


def build_all(out_dir: Path, standalone: bool = True, log=None) -> list[Path]:
    """Build every FMU of the project into ``out_dir``: the pythonfmu ones, then the native ones into
    ``out_dir/fmi2`` and ``out_dir/fmi3``."""
    built = [build_one(model, out_dir, standalone=standalone, log=log) for model in FMUS]
    from .native import build_native  # skipped with a message where they cannot be built
    return built + build_native(out_dir, log=log)


def _checkout_dist() -> Path | None:
    """dist/ of the source checkout this package runs from (editable install), else None."""
    root = PACKAGE.parent.parent
    if (root / "pyproject.toml").is_file() and (root / "fmu_src" / "restitution").resolve() == PACKAGE:
        return root / "dist"
    return None


def default_fmu_dir() -> Path:
    """Where :func:`default_fmu` keeps the FMUs: dist/ in a source checkout, else a per-user cache."""
    dist = _checkout_dist()
    if dist is not None:
        return dist
    cache = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")
    return cache / "restitution" / "fmus"


def default_fmu(out_dir: str | Path | None = None, model: str = "SpherePlateImpact",
                rebuild: bool = False, log=None) -> Path:
    """Path of ``<model>.fmu`` (default SpherePlateImpact) in ``out_dir`` (default :func:`default_fmu_dir`).

    The FMUs are (re)built when missing, built from other sources than the installed package's
    (the source hash recorded in the FMU differs; a stale build would run old code), or when
    ``rebuild``. ``log(message)`` is told when a build starts. Raises :class:`BuildError` with a
    one-line reason naming ``--fmu PATH`` when no FMU can be built here.
    """
    out = Path(out_dir) if out_dir is not None else default_fmu_dir()
    fmu = out / f"{model}.fmu"
    if rebuild or recorded_source_hash(fmu) != source_hash(model):
        if log is not None:
            log(f"building {fmu} ...")
        try:
            build_all(out, log=log)
        except BuildError as exc:
            raise BuildError(f"no usable {fmu.name} at {out} and it cannot be built here ({exc}); "
                             f"pass --fmu PATH to use an existing one") from None
    return fmu
