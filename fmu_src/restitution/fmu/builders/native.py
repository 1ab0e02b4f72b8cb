"""Build the native FMUs, ``DIR/fmi2/<model>.fmu`` (FMI 2.0) and ``DIR/fmi3/<model>.fmu`` (FMI 3.0), for every
model: the same interface as the pythonfmu ``DIR/<model>.fmu``, no Python at run time, and nothing read
from another build (no pythonfmu needed).

Each native FMU is the project's C FMI front (``cfront/``: the state machine, checks, logging and
value store, driven by the table :func:`restitution.fmu.describe.c_header.c_header` generates from the
model's interface table) with the model's C backend and glue (``models/<model>/rst_native_*.c``) and,
for SpherePlateImpact, the C physics (``physics_c/``). Its descriptions are written from the same table
(:mod:`restitution.fmu.describe`): modelDescription.xml with model exchange and co-simulation and the C
sources declared, so a host on another platform can compile ``sources/`` (FMI 3.0: also
``sources/buildDescription.xml``); its identity is the table's instantiation token, which the
pythonfmu FMU of the same interface carries too.

Binaries: every platform of :mod:`restitution.fmu.builders.toolchains` (FMI 2.0: linux64, win64, darwin64;
FMI 3.0: x86_64-linux, aarch64-linux, x86_64-windows, x86_64-darwin, aarch64-darwin), Linux x86-64 with
gcc, Windows with mingw-w64 where installed, the others with zig (the ``ziglang`` package from PyPI). A
missing compiler skips that binary with a message; with none, no native FMU is written (and the build
says why). ``resources/build_info.json`` lists the platforms built and the compiler of each.
"""
from __future__ import annotations

import json
import shutil
import sys
import tempfile
from pathlib import Path

from ...about import VERSION
from ..describe import fmi2, fmi3
from ..describe.c_header import c_header, model_info_header
from ..models import native_sources, table
from . import sources
from . import toolchains
from .compile import PHYSICS_SOURCES, prepare_sources
from .toolchains import NativeBuildSkipped, fmi_include_dir
from .files import place, zip_dir
from .licenses import documentation_files
from .sources import BACKENDS, BUILD_INFO, FRONT, PHYSICS_C, VERSION_DIRS, native_source_hash

#: Models whose backend calls the impact physics (rst_physics.c and the generated Zener table).
PHYSICS_MODELS = {"SpherePlateImpact"}
INTERFACE_HEADER = "rst_{model}_interface.h"
MODEL_INFO_HEADER = "rst_model_info.h"


def front_files(fmi_version: str = "2.0") -> list[Path]:
    """The C FMI front's sources for one FMI version (cfront/: the core and that version's layer);
    NativeBuildSkipped where they are missing (an installed package without its package data)."""
    if not (FRONT / "rst_front.h").is_file():
        raise NativeBuildSkipped(f"the C FMI front is missing ({FRONT / 'rst_front.h'})")
    return sources.front_files(fmi_version)


def write_sources(model: str, directory: Path, fmi_version: str = "2.0") -> list[str]:
    """Every C file of ``model``'s native FMU of ``fmi_version`` into ``directory``; returns the .c files
    to compile."""
    front = front_files(fmi_version)
    needed = [PHYSICS_C / name for name in PHYSICS_SOURCES] if model in PHYSICS_MODELS else []
    missing = [str(path) for path in needed if not path.is_file()]
    if missing or not native_sources(model):  # an installed package without its C files (package-data)
        raise NativeBuildSkipped(f"C sources of native {model} missing: {', '.join(missing) or 'its backend'}")
    if model in PHYSICS_MODELS:
        prepare_sources(directory)
    else:
        directory.mkdir(parents=True, exist_ok=True)
    for path in front:
        shutil.copyfile(path, directory / path.name)
    write_backend(model, directory)
    return sorted(p.name for p in directory.glob("*.c"))


def write_backend(model: str, directory: Path) -> None:
    """The backend's C files and the interface header they include (generated from the model's
    interface table, with the row type it needs, cfront/rst_variable.h, and the prefixing of external
    names, cfront/rst_prefix.h)."""
    directory.mkdir(parents=True, exist_ok=True)
    for path in native_sources(model):
        shutil.copyfile(path, directory / path.name)
    for header in ("rst_variable.h", "rst_prefix.h"):
        shutil.copyfile(FRONT / header, directory / header)
    (directory / INTERFACE_HEADER.format(model=model)).write_text(c_header(model), encoding="utf-8")


def compile_binary(model: str, sources: Path, c_files: list[str], folder: str, out: Path,
                   extra_flags=(), fmi_version: str = "2.0", step=None) -> tuple[Path, str]:
    """Compile ``out/binaries/<folder>/<model>.<so|dll|dylib>`` (``folder``: a binaries/ folder of
    ``fmi_version``, see toolchains.folders) with the compiler toolchains picks; returns (the binary, the
    compiler, e.g. "gcc" or "zig cc"); NativeBuildSkipped when there is none here. ``step``: see
    :func:`toolchains.build_binary`."""
    try:
        binary, compilers = toolchains.build_binary(model, folder, fmi_version, sources, c_files, out / "binaries",
                                                    system_include_dirs=[fmi_include_dir(fmi_version)],
                                                    extra_flags=extra_flags, step=step)
    except toolchains.ToolchainMissing as exc:
        raise NativeBuildSkipped(str(exc)) from None
    return binary, ", ".join(dict.fromkeys(compilers))


def build_native_one(model: str, out_dir: Path, log=None, fmi_version: str = "2.0", folders=None,
                     progress=None) -> Path:
    """Build and validate ``out_dir/fmi2/<model>.fmu`` (FMI 2.0) or ``out_dir/fmi3/<model>.fmu`` (FMI 3.0)
    from the package alone; its GUID (FMI 3.0: instantiation token) is the model's
    :meth:`~restitution.fmu.table.Table.instantiation_token`. ``folders``: the binaries/ folders to build
    (default every one of :func:`toolchains.folders`); ``log``: warnings (default stderr); ``progress``: a
    :class:`~restitution.fmu.builders.progress.Progress` told each platform's compilation (default: none)."""
    from fmpy.validation import validate_fmu

    from .progress import quiet

    log = log or (lambda message: print(message, file=sys.stderr, flush=True))
    step = (progress or quiet()).compile_step(f"{VERSION_DIRS[fmi_version]}/{model}.fmu")
    front_files(fmi_version)  # before anything is written: no empty folder where the front is missing
    fmi_include_dir(fmi_version)
    target_dir = Path(out_dir) / VERSION_DIRS[fmi_version]
    target_dir.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix=f".{model}-native-", dir=target_dir) as tmp:
        stage = Path(tmp) / "fmu"
        sources = stage / "sources"
        c_files = write_sources(model, sources, fmi_version)
        if fmi_version == "2.0":
            description = fmi2.model_description(model, native=True, c_files=c_files)
        else:
            description = fmi3.model_description(model)
            (sources / "buildDescription.xml").write_text(fmi3.build_description(model, c_files), encoding="utf-8")
        (stage / "modelDescription.xml").write_text(description, encoding="utf-8")
        token = table(model).instantiation_token(VERSION)
        (sources / MODEL_INFO_HEADER).write_text(model_info_header(model, token), encoding="ascii")
        built = {}
        for folder in toolchains.folders(fmi_version):
            if folders is not None and folder not in folders:
                continue
            try:
                binary, compilers = compile_binary(model, sources, c_files, folder, stage, fmi_version=fmi_version,
                                                   step=step)
                built[binary.parent.name] = compilers
            except NativeBuildSkipped as exc:
                log(f"warning: native FMI {fmi_version} {model}.fmu: {exc}")
        if not built:
            raise NativeBuildSkipped(f"no C compiler for any platform: native FMI {fmi_version} {model}.fmu not built")
        info = {"model": model, "native": True, "fmi_version": fmi_version, "source_hash": native_source_hash(model),
                "platforms": sorted(built), "compilers": dict(sorted(built.items()))}
        (stage / BUILD_INFO).parent.mkdir(parents=True, exist_ok=True)
        (stage / BUILD_INFO).write_text(json.dumps(info, indent=1), encoding="utf-8")
        for name, data in documentation_files(model, fmi_version, native=True).items():
            (stage / name).parent.mkdir(parents=True, exist_ok=True)
            (stage / name).write_bytes(data)
        fmu = Path(tmp) / f"{model}.fmu"
        zip_dir(stage, fmu)
        problems = validate_fmu(str(fmu))
        if problems:
            raise RuntimeError(f"native FMI {fmi_version} {model}.fmu failed fmpy validation: " + "; ".join(problems))
        return place(fmu, target_dir / f"{model}.fmu")


def build_native(out_dir: Path, log=None, progress=None) -> list[Path]:
    """Every native FMU there is a backend for, FMI 2.0 (``fmi2/``) and FMI 3.0 (``fmi3/``), into
    ``out_dir``; a model that cannot be built here is skipped with a message (the Python FMUs stay
    usable)."""
    log = log or (lambda message: print(message, file=sys.stderr, flush=True))
    built = []
    for fmi_version in VERSION_DIRS:
        for model in BACKENDS:
            try:
                built.append(build_native_one(model, out_dir, log=log, fmi_version=fmi_version, progress=progress))
            except NativeBuildSkipped as exc:
                log(f"warning: native FMI {fmi_version} {model}.fmu not built: {exc}")
    return built
