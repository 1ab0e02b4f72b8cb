"""Put the pythonfmu guard (``pythonfmu_guard/``) in front of a pythonfmu FMU's Linux binary: every FMI
call checked, and the FMU loadable by plain C/C++ FMI 2.0 hosts (Linux x86_64).

pythonfmu's Linux binary does not link libpython, so outside a Python process
``dlopen`` fails with ``undefined symbol: _Py_NoneStruct``. This module
post-processes a built FMU, in place:

* ``binaries/linux64/<id>.so`` (pythonfmu) is renamed ``<id>_pythonfmu.so``;
* the guard takes its place: the project's C FMI front (``cfront/``: state machine, argument and
  range checks from the interface table, FMU states, logging) with ``pythonfmu_backend.c``, which
  forwards the checked calls to the pythonfmu binary, and the loader (``python_loader.c`` and its ``pyloader_*.c`` parts). In a process without
  Python the latter loads the libpython recorded below (RTLD_GLOBAL), starts the interpreter on the
  build environment (venv) and checks the required modules; in a Python host (fmpy, libcosimpy) it
  uses the running interpreter;
* ``resources/python_env.txt`` records the interpreter: libpython, executable,
  home (base prefix), site-packages directories and required modules.

Windows binaries are left unchanged. Running it again on an already processed
FMU rebuilds the guard and the configuration file.

Usage::

    from restitution.fmu.builders.guard import add_guard
    add_guard(Path("build/Model.fmu"))                  # this interpreter / venv

    python -m restitution.fmu.builders.guard build/Model.fmu \
        [--python /path/to/venv/bin/python] [--require numpy --require scipy]
"""
from __future__ import annotations

import argparse
import ast
import json
import os
import shutil
import subprocess
import sys
import tempfile
import warnings
import zipfile
from pathlib import Path
from typing import Iterable, Optional, Sequence
from xml.etree import ElementTree

from ...reproducible import write_zip
from . import toolchains
from .toolchains import Compiler, NativeBuildSkipped, fmi_include_dir
from .sources import FRONT, GUARD, front_files

#: The guard's C sources: the front, then the guard's backend (forwarding to pythonfmu) and Python loader.
GUARD_SOURCES = (*(p for p in front_files("2.0") if p.suffix == ".c"), GUARD / "pythonfmu_backend.c",
                 GUARD / "python_loader.c", GUARD / "pyloader_api.c", GUARD / "pyloader_config.c",
                 GUARD / "pyloader_start.c", GUARD / "pyloader_preflight.c", GUARD / "pyloader_threads.c",
                 GUARD / "pyloader_lifetime.c", GUARD / "pyloader_signals.c")
CONFIG_NAME = "python_env.txt"  # must match PYLOADER_CONFIG_NAME in python_loader.c
REAL_SUFFIX = "_pythonfmu"

__all__ = ["add_guard", "GuardError", "describe_interpreter"]


class GuardError(RuntimeError):
    """The FMU cannot be given its guard (missing compiler, static Python, ...)."""


# Runs inside the target interpreter: everything the guard needs to know about it.
_PROBE = r"""
import importlib.util, json, os, platform, site, sys, sysconfig
cv = sysconfig.get_config_var
libdir = cv('LIBDIR') or ''
dirs = [libdir, os.path.join(libdir, cv('MULTIARCH') or ''), cv('LIBPL') or '',
        os.path.join(sys.base_prefix, 'lib')]
names = [n for n in (cv('INSTSONAME'), cv('LDLIBRARY')) if n and '.so' in n]
names.append('libpython%d.%d.so.1.0' % sys.version_info[:2])
libpython = ''
for n in names:
    for d in dirs:
        p = os.path.join(d, n)
        if d and os.path.isfile(p):
            libpython = p
            break
    if libpython:
        break
candidates = json.loads(sys.argv[1])
found = {}
for m in candidates:
    try:
        found[m] = importlib.util.find_spec(m) is not None
    except Exception:
        found[m] = False
try:
    sites = site.getsitepackages()
except AttributeError:
    sites = []
if site.ENABLE_USER_SITE and os.path.isdir(site.getusersitepackages()):
    sites.append(site.getusersitepackages())
print(json.dumps(dict(
    version=platform.python_version(),
    executable=sys.executable,
    prefix=sys.prefix,
    base_prefix=sys.base_prefix,
    libpython=libpython,
    shared=bool(cv('Py_ENABLE_SHARED')),
    include=sysconfig.get_paths().get('include', ''),
    site=[s for s in sites if os.path.isdir(s)],
    stdlib=sorted(getattr(sys, 'stdlib_module_names', ())),
    importable=found,
)))
"""


def describe_interpreter(python_executable: str, candidate_modules: Iterable[str] = ()) -> dict:
    """Ask ``python_executable`` for its libpython, prefixes, site-packages, ..."""
    out = subprocess.run(
        [python_executable, "-c", _PROBE, json.dumps(sorted(set(candidate_modules)))],
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    return json.loads(out)


def _model_identifier(model_description: bytes) -> str:
    root = ElementTree.fromstring(model_description)
    cs = root.find("CoSimulation")
    if cs is None:
        raise GuardError("modelDescription.xml has no <CoSimulation> element")
    return cs.attrib["modelIdentifier"]


def _imported_top_level_modules(sources: Iterable[bytes]) -> set[str]:
    names: set[str] = set()
    for src in sources:
        try:
            tree = ast.parse(src)
        except SyntaxError:
            continue
        for node in ast.walk(tree):
            if isinstance(node, ast.Import):
                names.update(alias.name.split(".")[0] for alias in node.names)
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                names.add(node.module.split(".")[0])
    return names


def _detect_requirements(entries: dict[str, bytes]) -> set[str]:
    """Top-level modules imported by the Python files in resources/ that the
    FMU does not ship itself (stdlib filtering happens in the interpreter)."""
    sources = [
        data
        for name, data in entries.items()
        if name.startswith("resources/") and name.endswith(".py") and not name.startswith("resources/pythonfmu/")
    ]
    shipped = set()
    for name in entries:
        if name.startswith("resources/"):
            first = name[len("resources/"):].split("/")[0]
            shipped.add(first[:-3] if first.endswith(".py") else first)
    return _imported_top_level_modules(sources) - shipped - {"pythonfmu", "__future__"}


def _config_text(info: dict, requires: Sequence[str]) -> str:
    lines = [
        "# Written by restitution.fmu.builders.guard.",
        "# Read by the FMU's binaries/linux64 guard when the host process has no Python",
        "# (plain C/C++ FMI hosts). Edit the paths to move the FMU to another Python",
        f"# {'.'.join(info['version'].split('.')[:2])} installation; ignored inside Python hosts (fmpy, libcosimpy).",
        f"python_version={info['version']}",
        f"libpython={info['libpython']}",
        f"executable={info['executable']}",
        f"home={info['base_prefix']}",
        "use_environment=0",
    ]
    lines += [f"site={s}" for s in info["site"]]
    if requires:
        lines.append("require=" + ",".join(requires))
    return "\n".join(lines) + "\n"


#: pythonfmu's ``(anonymous namespace)::pyState`` (a std::shared_ptr, two words): see
#: pyloader_arm_pystate_exit_fix in pyloader_lifetime.c, which empties it before pythonfmu's exit-time double release.
PYSTATE_SYMBOL = b"_ZN12_GLOBAL__N_17pyStateE"


def _pystate_offset(binary: bytes) -> Optional[int]:
    """st_value of PYSTATE_SYMBOL in the ELF64 (little-endian) binary's .symtab, if it has one of 16 bytes."""
    import struct

    if binary[:4] != b"\x7fELF" or binary[4] != 2 or binary[5] != 1:
        return None
    shoff, = struct.unpack_from("<Q", binary, 0x28)
    shentsize, shnum = struct.unpack_from("<HH", binary, 0x3A)
    sections = [struct.unpack_from("<IIQQQQIIQQ", binary, shoff + i * shentsize) for i in range(shnum)]
    for _name, sh_type, _flags, _addr, offset, size, link, _info, _align, entsize in sections:
        if sh_type != 2 or not entsize:  # SHT_SYMTAB
            continue
        str_offset, str_size = sections[link][4], sections[link][5]
        strtab = binary[str_offset:str_offset + str_size]
        for k in range(size // entsize):
            st_name, _st_info, _st_other, st_shndx, st_value, st_size = struct.unpack_from(
                "<IBBHQQ", binary, offset + k * entsize)
            end = strtab.find(b"\0", st_name)
            if strtab[st_name:end] == PYSTATE_SYMBOL and st_size == 16 and st_shndx != 0:
                return st_value
    return None


#: The guard is C99 with the GNU extensions its Linux-only loader needs (dladdr, dlinfo, __thread).
GUARD_CFLAGS = ("-std=gnu99", "-O2", "-Wall", "-Wextra", "-Werror", "-shared", "-fPIC", "-fvisibility=hidden",
                "-pthread")


def guard_compiler() -> Compiler:
    """The compiler of the guard: x86_64-linux's (:func:`restitution.fmu.builders.toolchains.compiler`: zig for
    the glibc 2.17 baseline, else gcc); GuardError where there is none."""
    try:
        return toolchains.compiler("x86_64-linux")
    except toolchains.ToolchainMissing as exc:
        raise GuardError(f"the FMU guard cannot be compiled: {exc}") from None


def _fmi2_headers() -> Path:
    try:
        return fmi_include_dir("2.0")
    except NativeBuildSkipped as exc:
        raise GuardError(f"the FMU guard cannot be compiled: {exc}") from None


def guard_command(output: Path, generated: Path, real_name: str, compiler="gcc", include_dir: str = "",
                  real_binary: Optional[bytes] = None, extra_flags: Sequence[str] = ()) -> list[str]:
    """The compiler command for the guard; ``generated`` holds rst_interface.h and rst_model_info.h.
    ``compiler``: a command name ("gcc") or a :class:`~restitution.fmu.builders.toolchains.Compiler`."""
    prefix = [compiler] if isinstance(compiler, str) else [*compiler.command, *compiler.flags]
    cmd = [*prefix, *GUARD_CFLAGS, *extra_flags, f'-DPYLOADER_REAL_BINARY="{real_name}"',
           f'-DPYLOADER_CONFIG_NAME="{CONFIG_NAME}"', f"-I{generated}", f"-I{FRONT}", f"-I{GUARD}", f"-I{_fmi2_headers()}"]
    offset = _pystate_offset(real_binary) if real_binary else None
    if offset is not None:
        cmd += [f"-DPYLOADER_PYSTATE_OFFSET={offset:#x}", f"-DPYLOADER_REAL_SIZE={len(real_binary)}"]
    if include_dir and (Path(include_dir) / "Python.h").is_file():
        cmd += ["-DPYLOADER_HAVE_PYTHON_H", f"-I{include_dir}"]
    return cmd + [str(p) for p in GUARD_SOURCES] + ["-o", str(output), "-ldl", "-lpthread"]


def write_guard_headers(directory: Path, model_description: str, interface_header: Optional[str] = None) -> None:
    """rst_interface.h (``interface_header``, or one made from the modelDescription for an FMU without an
    interface table of its own) and rst_model_info.h into ``directory``."""
    from ..describe.c_header import c_header, model_info, model_info_header, variables_from_model_description

    if interface_header is None:
        identifier = model_info(model_description)[0]
        interface_header = c_header(identifier, variables_from_model_description(model_description))
    (directory / "rst_interface.h").write_text(interface_header, encoding="utf-8")
    (directory / "rst_model_info.h").write_text(model_info_header(*model_info(model_description)), encoding="ascii")


def _compile_guard(output: Path, real_name: str, include_dir: str, compiler: Compiler, real_binary: bytes,
                   model_description: str, interface_header: Optional[str]) -> None:
    with tempfile.TemporaryDirectory(prefix="fmi2guard_") as tmp:
        write_guard_headers(Path(tmp), model_description, interface_header)
        cmd = guard_command(output, Path(tmp), real_name, compiler, include_dir, real_binary)
        proc = subprocess.run(cmd, capture_output=True, text=True, env=compiler.env)
    if proc.returncode != 0:
        raise GuardError(f"compiling the FMU guard failed:\n{' '.join(cmd)}\n{proc.stderr}")


def add_guard(
    fmu_path: Path,
    python_executable: str = sys.executable,
    *,
    required_modules: Optional[Sequence[str]] = None,
    compiler: "Compiler | str | None" = None,
    interface_header: Optional[str] = None,
) -> None:
    """Rewrite the FMU zip at ``fmu_path`` in place so that its Linux binary
    also runs in hosts without Python (see the module docstring).

    ``python_executable`` is the interpreter (typically the venv's python) the
    FMU will use in such hosts; its libpython, prefixes and site-packages are
    recorded. ``required_modules`` are checked at instantiation for a clear
    error message; by default they are the non-stdlib top-level modules
    imported by the FMU's Python files that are importable at build time.
    ``compiler``: None (default) for :func:`guard_compiler`, or a command name ("gcc").
    ``interface_header`` is the guard's variable table (:func:`restitution.fmu.describe.c_header.c_header`
    of the model's interface table); without it the table is made from the FMU's modelDescription.xml.
    """
    fmu_path = Path(fmu_path)
    if not sys.platform.startswith("linux"):
        raise GuardError("add_guard builds a Linux x86_64 guard and must run on Linux")
    if isinstance(compiler, str):
        if shutil.which(compiler) is None:
            raise GuardError(f"C compiler '{compiler}' not found (install gcc)")
        compiler = Compiler(compiler, (compiler,), ())
    elif compiler is None:
        compiler = guard_compiler()
    missing = [str(p) for p in GUARD_SOURCES if not p.is_file()]
    if missing:
        raise GuardError(f"guard sources missing: {', '.join(missing)}")

    with zipfile.ZipFile(fmu_path) as zin:
        entries = {i.filename: zin.read(i.filename) for i in zin.infolist()}

    model_id = _model_identifier(entries["modelDescription.xml"])
    guard_name = f"binaries/linux64/{model_id}.so"
    real_name = f"binaries/linux64/{model_id}{REAL_SUFFIX}.so"
    if real_name in entries:  # already processed: rebuild guard and config
        real_binary = entries[real_name]
    elif guard_name in entries:
        real_binary = entries[guard_name]
    else:
        raise GuardError(f"{fmu_path} has no {guard_name}")
    if b"Py_IsInitialized" not in real_binary:
        raise GuardError(f"{guard_name} does not look like a pythonfmu binary")

    candidates = _detect_requirements(entries) if required_modules is None else set()
    info = describe_interpreter(python_executable, candidates)
    if not info["libpython"]:
        raise GuardError(
            f"{python_executable} (Python {info['version']}) has no shared libpython "
            f"(Py_ENABLE_SHARED={info['shared']}); a guarded FMU needs an interpreter built with "
            "--enable-shared (pyenv: PYTHON_CONFIGURE_OPTS=--enable-shared, Debian: libpython3.X package)"
        )
    if required_modules is None:
        stdlib = set(info["stdlib"])
        requires = sorted(m for m in candidates if m not in stdlib and info["importable"].get(m))
        unresolved = sorted(m for m in candidates if m not in stdlib and not info["importable"].get(m))
        if unresolved:
            warnings.warn(
                f"{fmu_path.name}: modules imported by the FMU's Python code are not importable by "
                f"{info['executable']}: {', '.join(unresolved)} (ignored if optional imports; otherwise the "
                "FMU will fail to instantiate in hosts without Python)",
                stacklevel=2,
            )
    else:
        requires = list(dict.fromkeys(required_modules))

    with tempfile.TemporaryDirectory(prefix="fmi2guard_") as tmp:
        guard_so = Path(tmp) / f"{model_id}.so"
        _compile_guard(guard_so, f"{model_id}{REAL_SUFFIX}.so", info["include"], compiler, real_binary,
                       entries["modelDescription.xml"].decode("utf-8"), interface_header)
        guard_binary = guard_so.read_bytes()

    entries = {name: data for name, data in entries.items()
               if name not in (guard_name, real_name, f"resources/{CONFIG_NAME}") and not name.endswith("/")}
    entries[guard_name] = guard_binary
    entries[real_name] = real_binary
    entries[f"resources/{CONFIG_NAME}"] = _config_text(info, requires).encode("utf-8")

    fd, tmp_name = tempfile.mkstemp(prefix=fmu_path.name, suffix=".tmp", dir=fmu_path.parent)
    os.close(fd)
    try:
        write_zip(tmp_name, entries)
        os.replace(tmp_name, fmu_path)
    except BaseException:
        Path(tmp_name).unlink(missing_ok=True)
        raise


def main(argv: Optional[Sequence[str]] = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("fmu", type=Path, nargs="+", help="FMU file(s) built by pythonfmu, rewritten in place")
    parser.add_argument("--python", default=sys.executable, help="interpreter (venv python) to record")
    parser.add_argument(
        "--require",
        action="append",
        default=None,
        help="module that must import at instantiation (repeatable; default: detected from the FMU's imports)",
    )
    parser.add_argument("--cc", default=None, help="C compiler command (default: zig for glibc 2.17, else gcc)")
    args = parser.parse_args(argv)
    for fmu in args.fmu:
        add_guard(fmu, args.python, required_modules=args.require, compiler=args.cc)
        print(f"{fmu}: guard added ({CONFIG_NAME} records {args.python})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
