"""Compile the C physics (``physics_c/``): the generated table header, the C sources, the FMI headers
and the compiler flags every C build of the project uses.

:func:`prepare_sources` writes every C file the native build needs into a directory (the physics
sources shipped in this package and ``rst_zener_table.h`` generated from the package's table);
:func:`compile_shared` turns them into a shared library (the equivalence tests call it via ctypes).
"""
from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

from ..physics_c.result_header import RESULT_HEADER, result_header
from ..physics_c.zener_table_header import zener_table_header
from .sources import FRONT, PHYSICS_C

#: The FMI headers fmpy ships, by FMI version (used at build time only; not copied into the FMU: hosts
#: bring them).
FMI_HEADERS = {"2.0": ("fmi2Functions.h", "fmi2FunctionTypes.h", "fmi2TypesPlatform.h"),
               "3.0": ("fmi3Functions.h", "fmi3FunctionTypes.h", "fmi3PlatformTypes.h")}
#: The hand-written C sources of the physics (the table header is generated, see :func:`prepare_sources`).
PHYSICS_SOURCES = ("rst_physics.h", "rst_physics.c")
TABLE_HEADER = "rst_zener_table.h"
#: The front's header that prefixes every external name when FMI2_FUNCTION_PREFIX or FMI3_FUNCTION_PREFIX is defined.
PREFIX_HEADER = "rst_prefix.h"
#: C99, every warning an error; no contraction of a*b+c into an FMA, so the C rounds as the Python does.
CFLAGS = ("-std=c99", "-O2", "-Wall", "-Wextra", "-Werror", "-pedantic", "-ffp-contract=off")


class CompilerMissing(RuntimeError):
    """The C compiler asked for is not installed."""


class NativeBuildSkipped(RuntimeError):
    """A native FMU (or one of its binaries) cannot be built here; the message says why."""


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


def prepare_sources(directory: Path) -> Path:
    """Copy the physics sources into ``directory`` and generate the Zener table and result record headers
    there; returns it."""
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    for name in PHYSICS_SOURCES:
        shutil.copyfile(PHYSICS_C / name, directory / name)
    shutil.copyfile(FRONT / PREFIX_HEADER, directory / PREFIX_HEADER)
    (directory / TABLE_HEADER).write_text(zener_table_header(), encoding="ascii")
    (directory / RESULT_HEADER).write_text(result_header(), encoding="ascii")
    return directory


def compile_shared(out_dir: Path, name: str = "rst_physics", cc: str = "gcc", extra_flags=()) -> Path:
    """Build ``out_dir/lib<name>.so`` from the physics (sources prepared in ``out_dir/src``)."""
    if shutil.which(cc) is None:
        raise CompilerMissing(f"{cc} not found: the native physics cannot be compiled here")
    out_dir = Path(out_dir)
    src = prepare_sources(out_dir / "src")
    lib = out_dir / f"lib{name}.so"
    cmd = [cc, *CFLAGS, *extra_flags, "-fPIC", "-shared", "-o", str(lib), str(src / "rst_physics.c"), "-lm"]
    subprocess.run(cmd, check=True, capture_output=True, text=True)
    return lib
