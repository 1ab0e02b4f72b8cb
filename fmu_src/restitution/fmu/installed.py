"""The FMUs a wheel carries: ``restitution/fmu/installed_fmus/``, laid out as a build directory
(``<model>.fmu``: pythonfmu; ``fmi2/<model>.fmu``, ``fmi3/<model>.fmu``: native C, every platform's binaries;
``ssp/``: the SSP files where the release has them). The wheel's build writes them
(build_scripts/wheel_backend.py); a source checkout has none (``restitution fmu build`` writes dist/).

:func:`path` names one of them, :func:`copy` copies them out; :func:`restitution.fmu.default_fmu` uses them
before building anything.
"""
from __future__ import annotations

import shutil
from pathlib import Path

__all__ = ["INSTALLED", "IMPLEMENTATIONS", "FMI_VERSIONS", "NotInstalled", "installed_dir", "relative_path", "path",
           "installed_files", "copy"]

#: Where the wheel puts the FMUs, inside the package.
INSTALLED = Path(__file__).resolve().parent / "installed_fmus"
#: The implementations of each model: pythonfmu (the Python physics behind the C guard; FMI 2.0 only) and
#: native (the C front and physics; FMI 2.0 and 3.0).
IMPLEMENTATIONS = ("pythonfmu", "native")
FMI_VERSIONS = ("2", "3")


class NotInstalled(LookupError):
    """No installed FMU of that name (a source checkout, or a model, version or implementation that does not
    exist); the message is one line saying what to do."""


def installed_dir() -> Path | None:
    """The folder of the installed FMUs, or None where the package carries none (a source checkout)."""
    return INSTALLED if INSTALLED.is_dir() and any(INSTALLED.rglob("*.fmu")) else None


def relative_path(model: str = "SpherePlateImpact", fmi: str | int = "2", implementation: str | None = None) -> str:
    """Where ``model``'s FMU of FMI ``fmi`` ("2" or "3") and ``implementation`` ("pythonfmu" or "native";
    None: pythonfmu for FMI 2, native for FMI 3, the only one there) is in a build directory. ValueError
    for a version or implementation that does not exist."""
    fmi = str(fmi).split(".")[0]
    if fmi not in FMI_VERSIONS:
        raise ValueError(f"FMI {fmi}: one of {', '.join(FMI_VERSIONS)}")
    implementation = implementation or ("pythonfmu" if fmi == "2" else "native")
    if implementation not in IMPLEMENTATIONS:
        raise ValueError(f"implementation {implementation!r}: one of {', '.join(IMPLEMENTATIONS)}")
    if implementation == "pythonfmu":
        if fmi != "2":
            raise ValueError("the pythonfmu FMUs are FMI 2.0 only; FMI 3: --implementation native")
        return f"{model}.fmu"
    return f"fmi{fmi}/{model}.fmu"


def path(model: str = "SpherePlateImpact", fmi: str | int = "2", implementation: str | None = None) -> Path:
    """The installed FMU of ``model`` (see :func:`relative_path` for ``fmi`` and ``implementation``).
    :class:`NotInstalled` where the package carries none (one line saying how to build one), ValueError for
    a version or implementation that does not exist."""
    name = relative_path(model, fmi, implementation)
    folder = installed_dir()
    if folder is None:
        raise NotInstalled("this restitution carries no built FMUs (a source checkout or an sdist install): "
                           "`restitution fmu build` builds them")
    fmu = folder / name
    if not fmu.is_file():
        known = sorted(p.relative_to(folder).as_posix() for p in folder.rglob("*.fmu"))
        raise NotInstalled(f"no installed {name}; installed: {', '.join(known)}")
    return fmu


def installed_files() -> list[Path]:
    """Every installed file (FMUs, SSP files), relative to :data:`INSTALLED`; empty without any."""
    folder = installed_dir()
    if folder is None:
        return []
    return sorted(p.relative_to(folder) for p in folder.rglob("*") if p.is_file())


def copy(out_dir: str | Path) -> list[Path]:
    """Copy every installed file into ``out_dir`` (created where missing), laid out as installed; returns
    the copies. NotInstalled without any; OutputPathError (:mod:`restitution.output_files`) for an
    ``out_dir`` that cannot be written or a copy that would land on its own source."""
    from ..output_files import atomic_write, check_output, check_output_dir, check_outputs

    files = installed_files()
    if not files:
        path()  # raises NotInstalled, saying why
    out = check_output_dir(Path(out_dir), "--out")
    targets = {f"--out {out / rel}": out / rel for rel in files}
    check_outputs(targets, {f"installed {rel}": INSTALLED / rel for rel in files})
    for rel, target in zip(files, targets.values()):
        check_output(target, "--out")
        atomic_write(target, lambda tmp, source=INSTALLED / rel: shutil.copyfile(source, tmp), what="--out")
    return list(targets.values())
