"""Build ``DIR/native/<model>.fmu`` for every model: the same interface as ``DIR/<model>.fmu``, no
Python at run time.

Each native FMU is the project's C FMI front (``cfront/``: the state machine, checks, logging and
value store, driven by the table :func:`restitution.fmu.interface.c_header` generates from the model's
interface table) with the model's C backend and glue (``models/<model>/rst_native_*.c``) and, for
SpherePlateImpact, the C physics (``physics_c/``). Its modelDescription.xml is the pythonfmu FMU's
(which the build completed from the same interface table:
names, value references, types, causalities, variabilities, units, starts, min/max, descriptions,
ModelStructure), with what belongs to pythonfmu replaced (generation tool, needsExecutionTool) and
the C sources declared in ``<SourceFiles>`` so a host on another platform can compile ``sources/``.

Binaries: every platform of :mod:`restitution.fmu.toolchains` (FMI 2.0: linux64, win64, darwin64; FMI
3.0: x86_64-linux, aarch64-linux, x86_64-windows, x86_64-darwin, aarch64-darwin), Linux x86-64 with gcc,
Windows with mingw-w64 where installed, the others with zig (the ``ziglang`` package from PyPI). A
missing compiler skips that binary with a message; with none, no native FMU is written (and the build
says why). ``resources/build_info.json`` lists the platforms built and the compiler of each.
"""
from __future__ import annotations

import json
import os
import shutil
import sys
import tempfile
import zipfile
from pathlib import Path
from xml.etree import ElementTree as ET

from ..about import VERSION
from .compile import PHYSICS_SOURCES, prepare_sources
from .documentation import documentation_files
from . import model_description3, toolchains
from .interface import c_header, model_info, model_info_header
from .models import FOLDERS, native_sources, table
from . import sources
from .sources import BUILD_INFO, FRONT, PHYSICS_C, native_source_hash

#: The models with a native backend (every one).
BACKENDS = tuple(FOLDERS)
#: Models whose backend calls the impact physics (rst_physics.c and the generated Zener table).
PHYSICS_MODELS = {"SpherePlateImpact"}
#: The FMI headers fmpy ships, by FMI version (used at build time only; not copied into the FMU: hosts
#: bring them).
FMI_HEADERS = {"2.0": ("fmi2Functions.h", "fmi2FunctionTypes.h", "fmi2TypesPlatform.h"),
               "3.0": ("fmi3Functions.h", "fmi3FunctionTypes.h", "fmi3PlatformTypes.h")}
INTERFACE_HEADER = "rst_{model}_interface.h"
MODEL_INFO_HEADER = "rst_model_info.h"
#: Where the FMUs of each FMI version go, below the build's output directory.
VERSION_DIRS = {"2.0": "native", "3.0": "fmi3"}
GENERATION_TOOL = "restitution native build (C99 front + native physics)"


class NativeBuildSkipped(RuntimeError):
    """The native FMU cannot be built here; the message says why."""


def fmi_include_dir(fmi_version: str = "2.0") -> Path:
    """fmpy's copy of the FMI C headers of ``fmi_version``."""
    try:
        import fmpy
    except ImportError:
        raise NativeBuildSkipped(f"fmpy is not installed (its FMI {fmi_version} headers are needed)") from None
    path = Path(fmpy.__file__).resolve().parent / "c-code"
    if not all((path / h).is_file() for h in FMI_HEADERS[fmi_version]):
        raise NativeBuildSkipped(f"FMI {fmi_version} headers not found in {path}")
    return path



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


#: What the native FMI 2.0 FMU offers for model exchange (the same binary and front as co-simulation).
MODEL_EXCHANGE = {"needsExecutionTool": "false", "completedIntegratorStepNotNeeded": "true",
                  "canBeInstantiatedOnlyOncePerProcess": "false", "canNotUseMemoryManagementFunctions": "false",
                  "canGetAndSetFMUstate": "true", "canSerializeFMUstate": "true"}


def _declare_native_limits(root: ET.Element, model_table) -> None:
    """min and max of the variables whose native range is narrower (what the C does not offer)."""
    for sv in root.find("ModelVariables"):
        name = sv.get("name")
        if name in model_table and model_table[name].native_interval is not None:
            low, high = model_table[name].xml_limits(native=True)
            node = next(iter(sv))
            for attribute, text in (("min", low), ("max", high)):
                if text is not None:
                    node.set(attribute, str(int(float(text))) if model_table[name].type == "Integer" else text)


def native_model_description(xml_text: str, c_files: list[str], model_table=None) -> str:
    """The pythonfmu FMU's modelDescription.xml for the native FMU: same interface, C sources declared,
    and, given the model's interface table, model exchange offered beside co-simulation (its number
    of event indicators from the table)."""
    root = ET.fromstring(xml_text)
    root.set("generationTool", GENERATION_TOOL)
    cosim = root.find("CoSimulation")
    cosim.set("needsExecutionTool", "false")
    cosim.set("canBeInstantiatedOnlyOncePerProcess", "false")
    cosim.set("canNotUseMemoryManagementFunctions", "false")  # the front allocates through the host's callbacks
    for old in cosim.findall("SourceFiles"):
        cosim.remove(old)
    parts = [cosim]
    if model_table is not None:
        _declare_native_limits(root, model_table)
        root.set("numberOfEventIndicators", str(len(model_table.event_indicators)))
        exchange = ET.Element("ModelExchange", {"modelIdentifier": cosim.get("modelIdentifier"), **MODEL_EXCHANGE})
        root.insert(list(root).index(cosim), exchange)  # FMI 2.0 order: ModelExchange, then CoSimulation
        parts.insert(0, exchange)
    for part in parts:
        files = ET.SubElement(part, "SourceFiles")
        for name in c_files:
            ET.SubElement(files, "File", name=name)
    ET.indent(root, "  ")
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n"


def compile_binary(model: str, sources: Path, c_files: list[str], folder: str, out: Path,
                   extra_flags=(), fmi_version: str = "2.0") -> tuple[Path, str]:
    """Compile ``out/binaries/<folder>/<model>.<so|dll|dylib>`` (``folder``: a binaries/ folder of
    ``fmi_version``, see toolchains.folders) with the compiler toolchains picks; returns (the binary, the
    compiler, e.g. "gcc" or "zig cc"); NativeBuildSkipped when there is none here."""
    try:
        binary, compilers = toolchains.build_binary(model, folder, fmi_version, sources, c_files, out / "binaries",
                                                    system_include_dirs=[fmi_include_dir(fmi_version)],
                                                    extra_flags=extra_flags)
    except toolchains.ToolchainMissing as exc:
        raise NativeBuildSkipped(str(exc)) from None
    return binary, ", ".join(dict.fromkeys(compilers))


def _zip_dir(directory: Path, fmu: Path) -> None:
    with zipfile.ZipFile(fmu, "w", zipfile.ZIP_DEFLATED) as z:
        for path in sorted(directory.rglob("*")):
            if path.is_file():
                z.write(path, path.relative_to(directory).as_posix())


def build_native_one(model: str, out_dir: Path, python_fmu: Path, log=None, fmi_version: str = "2.0") -> Path:
    """Build and validate ``out_dir/native/<model>.fmu`` (FMI 2.0) or ``out_dir/fmi3/<model>.fmu``
    (FMI 3.0) beside the pythonfmu ``python_fmu``, whose GUID both carry (FMI 3.0: as the instantiation
    token), the model's :meth:`~restitution.fmu.table.Table.instantiation_token` (a ``python_fmu`` of
    another interface or version is refused), and whose modelDescription the FMI 2.0 one reuses."""
    from fmpy.validation import validate_fmu

    log = log or (lambda message: print(message, file=sys.stderr))
    front_files(fmi_version)  # before anything is written: no empty folder where the front is missing
    target_dir = Path(out_dir) / VERSION_DIRS[fmi_version]
    target_dir.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix=f".{model}-native-", dir=target_dir) as tmp:
        stage = Path(tmp) / "fmu"
        sources = stage / "sources"
        c_files = write_sources(model, sources, fmi_version)
        if not Path(python_fmu).is_file():
            raise NativeBuildSkipped(f"{python_fmu} missing: the native FMU takes its GUID from it")
        with zipfile.ZipFile(python_fmu) as z:
            xml = z.read("modelDescription.xml").decode("utf-8")
        token = table(model).instantiation_token(VERSION)
        if model_info(xml)[1] != token:
            raise NativeBuildSkipped(f"{python_fmu} is of another interface or version (its GUID is not {token}): rebuild it")
        if fmi_version == "2.0":
            description = native_model_description(xml, c_files, table(model))
        else:
            description = model_description3.model_description(model, token)
            (sources / "buildDescription.xml").write_text(model_description3.build_description(model, c_files),
                                                          encoding="utf-8")
        (stage / "modelDescription.xml").write_text(description, encoding="utf-8")
        (sources / MODEL_INFO_HEADER).write_text(model_info_header(xml), encoding="ascii")
        built = {}
        for folder in toolchains.folders(fmi_version):
            try:
                binary, compilers = compile_binary(model, sources, c_files, folder, stage, fmi_version=fmi_version)
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
        _zip_dir(stage, fmu)
        problems = validate_fmu(str(fmu))
        if problems:
            raise RuntimeError(f"native FMI {fmi_version} {model}.fmu failed fmpy validation: " + "; ".join(problems))
        mask = os.umask(0o022)
        os.umask(mask)
        os.chmod(fmu, 0o666 & ~mask)
        target = target_dir / f"{model}.fmu"
        os.replace(fmu, target)
    return target


def build_native(out_dir: Path, log=None) -> list[Path]:
    """Every native FMU there is a backend for, FMI 2.0 (``native/``) and FMI 3.0 (``fmi3/``), beside the
    pythonfmu ones already in ``out_dir``; a model that cannot be built here is skipped with a message
    (the Python FMUs stay usable)."""
    log = log or (lambda message: print(message, file=sys.stderr))
    built = []
    for fmi_version in VERSION_DIRS:
        for model in BACKENDS:
            try:
                built.append(build_native_one(model, out_dir, Path(out_dir) / f"{model}.fmu", log=log,
                                              fmi_version=fmi_version))
            except NativeBuildSkipped as exc:
                log(f"warning: native FMI {fmi_version} {model}.fmu not built: {exc}")
    return built
