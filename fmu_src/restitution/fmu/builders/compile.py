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
from .toolchains import CFLAGS

#: The hand-written C sources of the physics (the table header is generated, see :func:`prepare_sources`).
PHYSICS_SOURCES = ("rst_physics.h", "rst_physics.c")
TABLE_HEADER = "rst_zener_table.h"
#: The front's header that prefixes every external name when FMI2_FUNCTION_PREFIX or FMI3_FUNCTION_PREFIX is defined.
PREFIX_HEADER = "rst_prefix.h"


class CompilerMissing(RuntimeError):
    """The C compiler asked for is not installed."""


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
