"""Every FMU the build makes, and the FMUs the host tools use by default.

    python -m restitution.fmu build [--out DIR]      (or: restitution-fmu build, build_scripts/build_fmu.py)

writes ``DIR/<model>.fmu`` (pythonfmu, :mod:`.python_fmu`), ``DIR/fmi2/<model>.fmu`` and
``DIR/fmi3/<model>.fmu`` (native C, :mod:`.native`, for every platform) for every model, a line per
product and platform as it goes (:func:`run`: what :mod:`.plan` chose, told by :mod:`.progress`). Each builder reads the package only,
never another builder's output.
"""
from __future__ import annotations

import os
from pathlib import Path

from ..installed import installed_dir
from . import toolchains
from .toolchains import NativeBuildSkipped
from .files import BuildError, writable_dir
from .plan import build_info, full_plan, model_plan, steps, to_build, zig_targets
from .progress import PREFIX, Progress, stderr_line
from .python_fmu import build_one
from .sources import FMUS, PACKAGE

__all__ = ["FMUS", "SCOPES", "BuildError", "build_all", "build_one", "default_fmu", "default_fmu_dir", "run"]

#: What :func:`default_fmu` keeps up to date: "all", every FMU for every platform buildable here (what the
#: tools that use the directory's other FMUs, fmi2/ and fmi3/, need); "model", ``<model>.fmu`` alone.
SCOPES = ("all", "model")


def build_all(out_dir: Path, guard: bool = True, log=None) -> list[Path]:
    """Build every FMU of the project into ``out_dir``: the pythonfmu ones, then the native ones into
    ``out_dir/fmi2`` and ``out_dir/fmi3``, every platform (:func:`~restitution.fmu.builders.plan.full_plan`),
    then the SSPs of the native ones into ``out_dir/ssp`` (:func:`restitution.fmu.ssp.write_ssps`).
    ``log``: the build's lines and warnings (default stderr). Returns the FMUs, then the SSPs."""
    from ..ssp import write_ssps

    fmus = run(full_plan(), out_dir, guard=guard, log=log)
    return fmus + write_ssps(out_dir, log=log if log is not None else stderr_line)


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
                rebuild: bool = False, log=None, scope: str = "all") -> Path:
    """The default FMU: path of ``<model>.fmu`` (default SpherePlateImpact), built when missing or stale. The
    one function for that job (scenes, sweeps, examples, the Quickstart demo).

    Without ``out_dir`` and ``rebuild``, the FMU a wheel installed (:mod:`restitution.fmu.installed`) where
    what ``scope`` names is there and up to date: nothing is built. Otherwise ``<model>.fmu`` in ``out_dir``
    (default :func:`default_fmu_dir`).

    What ``scope`` names (:data:`SCOPES`) is built first where it is missing, was built from other
    sources than the installed package's (the source hash recorded in the FMU differs; a stale build
    would run old code), lacks a platform a compiler here builds, or when ``rebuild``; the rest is left
    as it is. "all" (the default): every FMU of the project, each native one for every platform this
    machine can build (a directory the demo filled with ``<model>.fmu`` alone is completed); "model":
    ``<model>.fmu`` alone, the pythonfmu FMU (seconds, no zig: the Quickstart demo). ``log(message)`` is
    told what is built and why, and gets the build's lines (default: stderr). Raises :class:`BuildError`
    with a one-line reason naming ``--fmu PATH`` when no FMU can be built here.
    """
    if scope not in SCOPES:
        raise ValueError(f"scope={scope!r}: one of {', '.join(SCOPES)}")
    plan = full_plan() if scope == "all" else model_plan(model)
    if out_dir is None and not rebuild:
        installed = installed_dir()
        if installed is not None and (installed / f"{model}.fmu").is_file() and not to_build(plan, installed):
            return installed / f"{model}.fmu"
    out = Path(out_dir) if out_dir is not None else default_fmu_dir()
    fmu = out / f"{model}.fmu"
    todo = [(p, "rebuild asked") for p in plan] if rebuild else to_build(plan, out)
    if todo:
        say = log if log is not None else stderr_line
        reasons = {}
        for product, why in todo:
            reasons.setdefault(why, []).append(product.name)
        say(f"{PREFIX}in {out}, " + "; ".join(f"{', '.join(names)} {why}" for why, names in reasons.items())
            + ("" if scope == "all" else f": building {model}.fmu alone, what this uses (`restitution fmu build` "
                                        "builds every FMU for every platform)"))
        try:
            run([p for p, _ in todo], out, log=log)
        except BuildError as exc:
            raise BuildError(f"no usable {fmu.name} at {out} and it cannot be built here ({exc}); "
                             f"pass --fmu PATH to use an existing one") from None
    return fmu


def _headline(plan, out_dir) -> str:
    count = f"{len(plan)} FMU{'s' if len(plan) != 1 else ''}"
    parts = []
    python = [p.name for p in plan if not p.native]
    if python:
        parts.append(f"{', '.join(python)} (pythonfmu)")
    native = [p for p in plan if p.native]
    if native:
        found = {s.platform for s in steps(native) if s.compiler is not None}
        platforms = [t.name for t in toolchains.PLATFORMS if t.name in found]
        parts.append(f"{', '.join(p.name for p in native)} (native C for {', '.join(platforms) or 'no platform'})")
    return f"{count} into {out_dir}: {'; '.join(parts)}"


def run(plan, out_dir, guard: bool = True, log=None, progress: Progress | None = None) -> list[Path]:
    """Build every product of ``plan`` into ``out_dir``, in order; returns the FMUs built. ``log``: every
    line (the progress and the warnings; default stderr, flushed). A native FMU that cannot be built here
    is skipped with a warning (the pythonfmu ones stay usable); a pythonfmu one that cannot be built
    raises :class:`~restitution.fmu.builders.files.BuildError`."""
    from .native import build_native_one  # it loads the describers: only when building

    say = log if log is not None else stderr_line
    out_dir = writable_dir(out_dir)  # an unusable --out is one line, before any other
    progress = progress or Progress(say)
    progress.expect_zig(zig_targets(plan))
    start = progress.clock()
    progress.line(_headline(plan, out_dir))
    built = []
    for product in plan:
        if not product.native:
            built.append(build_one(product.model, out_dir, guard=guard, log=say, progress=progress))
            continue
        begun = progress.clock()
        try:
            fmu = build_native_one(product.model, out_dir, log=say, fmi_version=product.fmi_version,
                                   folders=product.folders, progress=progress)
        except NativeBuildSkipped as exc:
            say(f"warning: native FMI {product.fmi_version} {product.model}.fmu not built: {exc}")
            continue
        platforms = (build_info(fmu) or {}).get("platforms", [])
        progress.line(f"{product.name:<30} validated, binaries/ {', '.join(platforms)}: "
                      f"{progress.clock() - begun:.1f} s")
        built.append(fmu)
    progress.line(f"{len(built)} FMU{'s' if len(built) != 1 else ''} built in {progress.clock() - start:.1f} s")
    return built
