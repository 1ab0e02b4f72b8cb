"""The platforms the native FMUs carry binaries for, and the C compiler that builds each.

Five platforms (:data:`PLATFORMS`), named by their FMI 3.0 platform tuple: x86_64-linux, aarch64-linux,
x86_64-windows, x86_64-darwin and aarch64-darwin. FMI 3.0 gives each its own ``binaries/`` folder; FMI
2.0 names only linux64, win64 and darwin64 of them, its darwin64 being one universal Mach-O file with
both macOS architectures (what a host on an Intel or an Apple silicon Mac loads from darwin64), and has
no folder for aarch64-linux (:func:`folders`).

The compilers:

* x86_64-linux: zig (glibc 2.17 baseline), else gcc, the machine's own compiler (``-fPIC -fvisibility=hidden
  -pthread``; its binaries need this machine's glibc).
* x86_64-windows: mingw-w64's ``x86_64-w64-mingw32-gcc`` where it is on PATH (runtime linked statically:
  the DLL needs only Windows' own DLLs), else zig.
* aarch64-linux, x86_64-darwin, aarch64-darwin: zig.

zig is the C compiler (clang, with the C libraries and linkers of every target) the ``ziglang`` package
brings from PyPI; it runs as ``python -m ziglang cc -target <triple>``, so it needs nothing on PATH and
every platform builds on a machine with only Python and gcc. Where a platform's compiler is missing,
:func:`compiler` raises :class:`ToolchainMissing` with a one-line reason naming what to install, and the
build skips that platform.

Every build compiles with the project's flags (:data:`CFLAGS`: C99, ``-Wall
-Wextra -Werror -pedantic``, no FMA contraction) and includes the FMI headers as system headers
(``-isystem``: they are the standard's, and clang warns about two unprototyped callback types in the
FMI 3.0 ones). Only the FMI functions are exported (hidden visibility on ELF and Mach-O; on Windows the
headers' ``__declspec(dllexport)``). The binaries are reproducible: the same sources give the same bytes,
wherever they are compiled from (no debug information or symbol table with paths; Windows: no link time
stamp and a fixed image base; macOS: the install name is ``@rpath/<name>.dylib``, not the build path).

zig keeps what it compiled for each target (its C runtime libraries the first time, ~1 min for Windows;
then each object) in its cache: ``ZIG_GLOBAL_CACHE_DIR`` and ``ZIG_LOCAL_CACHE_DIR`` where set, else
``$XDG_CACHE_HOME/zig`` or ``~/.cache/zig``, else a folder in the temporary directory where that is not
writable (:func:`zig_environment`). :func:`zig_cache_cold` tells, from what that cache holds, which targets'
C runtimes zig has yet to build (what makes a first build slow), so a build can say so before it starts.
"""
from __future__ import annotations

import contextlib
import importlib.util
import os
import shutil
import struct
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

#: C99, every warning an error; no contraction of a*b+c into an FMA, so the C rounds as the Python does.
CFLAGS = ("-std=c99", "-O2", "-Wall", "-Wextra", "-Werror", "-pedantic", "-ffp-contract=off")
#: The FMI headers fmpy ships, by FMI version (used at build time only; not copied into the FMU: hosts
#: bring them).
FMI_HEADERS = {"2.0": ("fmi2Functions.h", "fmi2FunctionTypes.h", "fmi2TypesPlatform.h"),
               "3.0": ("fmi3Functions.h", "fmi3FunctionTypes.h", "fmi3PlatformTypes.h")}
#: The PyPI package that brings zig, and how to install it.
ZIG_PACKAGE = "ziglang"
ZIG_INSTALL = f"pip install {ZIG_PACKAGE}"
MINGW = "x86_64-w64-mingw32-gcc"
#: The environment variable that, set to "zig" or "native", makes every build use that compiler only (the
#: wheel's build sets "zig": the same compiler for every platform, no gcc or mingw-w64).
COMPILER_CHOICE = "RESTITUTION_COMPILER"


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


@dataclass(frozen=True)
class Platform:
    """One platform of the native FMUs' binaries."""

    name: str  #: the FMI 3.0 platform tuple, also its binaries/ folder in an FMI 3.0 FMU
    fmi2: str | None  #: its FMI 2.0 binaries/ folder (darwin64: one universal file of both macOS slices), or None
    suffix: str  #: the shared library's suffix
    zig_target: str  #: zig's target (architecture-os[.minimum version]-abi[.glibc version])
    native: str | None = None  #: the platform's own compiler where it is on PATH; None: zig only
    zig_first: bool = False  #: zig tried before ``native`` (which is then the fallback without the ziglang package)
    native_flags: tuple = ()  #: that compiler's flags
    install: str = ""  #: how to get that compiler (Debian)

    def folder(self, fmi_version: str) -> str | None:
        """The binaries/ folder of this platform in an FMU of ``fmi_version`` (None: FMI 2.0 names none)."""
        return self.name if fmi_version.startswith("3.") else self.fmi2


#: The Linux binaries need at most :data:`GLIBC_BASELINE`.
GLIBC_BASELINE = (2, 17)
#: The platforms, in build order. zig targets: glibc 2.17 for both Linux platforms (the manylinux2014
#: baseline, the oldest glibc with aarch64; zig links against stubs of that version's symbols, so the
#: binaries load on every Linux with glibc >= 2.17, e.g. CentOS 7, whatever this machine's glibc is),
#: macOS 11.0 (the first with Apple silicon); Windows through zig links the Universal C Runtime
#: (api-ms-win-crt-*, part of Windows 10 and later). x86_64-linux: zig first for that baseline; gcc, the
#: fallback without the ziglang package, links against this machine's glibc (e.g. exp/log/pow need 2.29).
PLATFORMS = (
    # the front locks each instance (pthreads here; -pthread for glibc < 2.34)
    Platform("x86_64-linux", "linux64", ".so", "x86_64-linux-gnu.2.17", zig_first=True,
             native="gcc", native_flags=("-fPIC", "-fvisibility=hidden", "-pthread"), install="apt-get install gcc"),
    Platform("aarch64-linux", None, ".so", "aarch64-linux-gnu.2.17"),
    # mingw: the runtime linked statically; no symbol table, time stamp or image base chosen from the path
    Platform("x86_64-windows", "win64", ".dll", "x86_64-windows-gnu",
             native=MINGW, install="apt-get install gcc-mingw-w64-x86-64",
             native_flags=("-static", "-static-libgcc", "-s", "-Wl,--no-insert-timestamp",
                           "-Wl,--disable-auto-image-base")),
    Platform("x86_64-darwin", "darwin64", ".dylib", "x86_64-macos.11.0"),
    Platform("aarch64-darwin", "darwin64", ".dylib", "aarch64-macos.11.0"),
)
#: zig's flags by operating system (the target's C library and compiler runtime come with zig; -s: no
#: debug information and no symbol table, whose paths would make the bytes depend on the build folder;
#: Windows: /Brepro, lld's reproducible mode, puts a hash of the image where the link time would be in the
#: COFF header's TimeDateStamp, which zig's linker otherwise fills with the clock).
ZIG_FLAGS = {"linux": ("-fPIC", "-fvisibility=hidden", "-pthread", "-s"),
             "windows": ("-s", "-Wl,/Brepro"),
             "darwin": ("-fvisibility=hidden", "-s")}


class ToolchainMissing(RuntimeError):
    """No compiler for a platform here; the message (one line) says what to install."""


class CompileError(RuntimeError):
    """The compiler failed; the message has its command and its messages."""


@dataclass(frozen=True)
class Compiler:
    """A C compiler for one platform."""

    name: str  #: what messages call it: "gcc", "x86_64-w64-mingw32-gcc", "zig cc"
    command: tuple  #: the command line before the flags
    flags: tuple  #: the platform's flags
    env: dict | None = None  #: the environment it runs in (None: this process's)


def platform(name: str) -> Platform:
    """The platform of an FMI 3.0 platform tuple, or of an FMI 2.0 folder naming one platform (linux64,
    win64)."""
    matches = [p for p in PLATFORMS if p.name == name] or [p for p in PLATFORMS if p.fmi2 == name]
    if len(matches) != 1:
        raise KeyError(f"{name}: not one platform of {', '.join(p.name for p in PLATFORMS)}")
    return matches[0]


def folders(fmi_version: str) -> dict[str, tuple[Platform, ...]]:
    """binaries/ folder -> the platforms whose code it holds, for an FMU of ``fmi_version`` (FMI 2.0:
    darwin64 holds both macOS slices in one file; aarch64-linux has no folder)."""
    out: dict[str, tuple[Platform, ...]] = {}
    for p in PLATFORMS:
        folder = p.folder(fmi_version)
        if folder is not None:
            out[folder] = out.get(folder, ()) + (p,)
    return out


def zig_command() -> tuple[str, ...] | None:
    """The command that runs zig (``python -m ziglang``, this Python's), or None without the ziglang
    package."""
    try:
        found = importlib.util.find_spec(ZIG_PACKAGE)
    except (ImportError, ValueError):  # a broken or blocked installation counts as none
        found = None
    return None if found is None else (sys.executable, "-m", ZIG_PACKAGE)


def _writable(directory: Path) -> bool:
    try:
        directory.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=directory):
            return True
    except OSError:
        return False


def zig_cache_dir(environ=None) -> Path:
    """Where zig's cache goes when ZIG_GLOBAL_CACHE_DIR / ZIG_LOCAL_CACHE_DIR are not set:
    ``$XDG_CACHE_HOME/zig`` or ``~/.cache/zig``, or, where that cannot be written, a per-user folder in
    the temporary directory."""
    environ = os.environ if environ is None else environ
    base = environ.get("XDG_CACHE_HOME") or os.path.join(environ.get("HOME") or os.path.expanduser("~"), ".cache")
    preferred = Path(base) / "zig"
    if _writable(preferred):
        return preferred
    user = os.getuid() if hasattr(os, "getuid") else os.environ.get("USERNAME", "user")
    return Path(tempfile.gettempdir()) / f"zig-cache-{user}"


def zig_environment(environ=None) -> dict:
    """The environment zig runs in: ``environ`` (default this process's) with ZIG_GLOBAL_CACHE_DIR, where
    it is not set, :func:`zig_cache_dir`, and ZIG_LOCAL_CACHE_DIR, where it is not set, the global one (as
    zig cc does by default)."""
    env = dict(os.environ if environ is None else environ)
    if not env.get("ZIG_GLOBAL_CACHE_DIR"):
        env["ZIG_GLOBAL_CACHE_DIR"] = str(zig_cache_dir(env))
    if not env.get("ZIG_LOCAL_CACHE_DIR"):
        env["ZIG_LOCAL_CACHE_DIR"] = env["ZIG_GLOBAL_CACHE_DIR"]
    return env


#: What zig's cache holds once zig has built a target's C runtime (its first use for that target, the slow
#: part: about a minute and a half for Windows' on two cores): a file of that name in one of its o/<hash>/
#: folders, whose first bytes name the target where several targets have one (ELF machine at byte 18, or a
#: thin 64-bit Mach-O header of the architecture in a static archive).
_ELF_MACHINE = {"x86_64": 62, "aarch64": 183}
_MACHO_CPU = {"x86_64": 0x01000007, "aarch64": 0x0100000C}


def _zig_runtime_marker(target: Platform) -> tuple[str, object]:
    """(file name, test of its first 64 KiB) of what zig's cache holds once ``target``'s C runtime is built."""
    arch, _, system = target.name.partition("-")
    if system == "windows":
        return "libmingw32.lib", None  # mingw-w64's C runtime, built for the one Windows target
    if system == "linux":
        machine = _ELF_MACHINE[arch].to_bytes(2, "little")
        return "libc.so.6", lambda head: head[:4] == b"\x7fELF" and head[18:20] == machine
    header = struct.pack("<Ii", MACHO_MAGIC_64, _MACHO_CPU[arch])
    return "libcompiler_rt.a", lambda head: header in head


def zig_cache_cold(targets, cache: Path | None = None) -> list[Platform] | None:
    """Of ``targets``, those whose C runtime zig's cache (``cache``, default the one :func:`zig_environment`
    gives zig) does not hold yet: zig builds it on its first use for that target. None where the cache
    cannot be read (then nobody can tell)."""
    targets = [platform(t) if isinstance(t, str) else t for t in targets]
    cache = Path(cache if cache is not None else zig_environment()["ZIG_GLOBAL_CACHE_DIR"])
    markers = {t.name: _zig_runtime_marker(t) for t in targets}
    wanted = {name for name, _ in markers.values()}
    found: dict[str, list[Path]] = {}
    try:
        if not (cache / "o").is_dir():
            return targets
        with os.scandir(cache / "o") as entries:
            for entry in entries:
                if entry.is_dir():
                    for name in wanted:
                        candidate = Path(entry.path) / name
                        if candidate.is_file():
                            found.setdefault(name, []).append(candidate)

        def holds(name, test) -> bool:
            for path in found.get(name, ()):
                with contextlib.suppress(OSError), open(path, "rb") as f:
                    if test is None or test(f.read(1 << 16)):
                        return True
            return False

        return [t for t in targets if not holds(*markers[t.name])]
    except OSError:
        return None


def zig_compiler(target: Platform) -> Compiler:
    """zig for ``target``; ToolchainMissing without the ziglang package."""
    zig = zig_command()
    if zig is None:
        raise ToolchainMissing(f"zig not found ({ZIG_INSTALL})")
    system = target.name.partition("-")[2]
    return Compiler("zig cc", (*zig, "cc", "-target", target.zig_target), ZIG_FLAGS[system], zig_environment())


def compiler(target: Platform | str, use: str | None = None) -> Compiler:
    """The compiler that builds ``target``'s binaries here: its native compiler where it has one and that
    is on PATH, else zig (x86_64-linux: zig first, for the glibc baseline, else gcc). ``use``: "native" or "zig" to ask for that one only. ToolchainMissing (a one-line
    reason naming what to install) where there is none. Without ``use``, the environment variable
    :data:`COMPILER_CHOICE` where set ("zig": the wheel's build, zig from PyPI for every platform)."""
    target = platform(target) if isinstance(target, str) else target
    if use is None:
        use = os.environ.get(COMPILER_CHOICE, "").strip() or None
    if use not in (None, "native", "zig"):
        raise ValueError(f"use={use!r} ({COMPILER_CHOICE}): 'native' or 'zig'")
    if target.zig_first and use is None:
        with contextlib.suppress(ToolchainMissing):
            return zig_compiler(target)
    if use != "zig" and target.native is not None:
        found = shutil.which(target.native)
        if found is not None:
            return Compiler(target.native, (target.native,), target.native_flags)
        if use == "native":
            raise ToolchainMissing(f"{target.native} not found ({target.install})")
    elif use == "native":
        raise ToolchainMissing(f"{target.name} has no compiler but zig")
    try:
        return zig_compiler(target)
    except ToolchainMissing:
        if target.native is None:
            raise
        raise ToolchainMissing(f"neither {target.native} ({target.install}) nor zig ({ZIG_INSTALL}) found") from None


def compile_library(target: Platform | str, cc: Compiler, sources: Path, c_files, out: Path, include_dirs=(),
                    system_include_dirs=(), extra_flags=(), cflags=CFLAGS, libraries=("-lm",)) -> Path:
    """Compile ``c_files`` (names in ``sources``) with ``cc`` into the shared library ``out`` for
    ``target``; CompileError with the compiler's messages where it fails. The compiler writes into a
    scratch folder (zig puts an import library beside a DLL), of which only the library is kept; on
    macOS its install name is ``@rpath/<out's name>``."""
    target = platform(target) if isinstance(target, str) else target
    sources, out = Path(sources), Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    flags = list(cc.flags)
    if target.suffix == ".dylib":
        flags.append(f"-Wl,-install_name,@rpath/{out.name}")
    with tempfile.TemporaryDirectory(prefix=".cc-", dir=out.parent) as scratch:
        library = Path(scratch) / out.name
        cmd = [*cc.command, *cflags, *flags, *extra_flags, "-shared", f"-I{sources}",
               *(f"-I{d}" for d in include_dirs), *(arg for d in system_include_dirs for arg in ("-isystem", str(d))),
               "-o", str(library), *(str(sources / f) for f in c_files), *libraries]
        done = subprocess.run(cmd, capture_output=True, text=True, env=cc.env)
        if done.returncode != 0 or not library.is_file():
            raise CompileError(f"{cc.name} failed for {out.name} ({target.name}):\n{' '.join(cmd)}\n{done.stderr}")
        os.replace(library, out)
    return out


#: Mach-O: the CPU type of a thin 64-bit image (little-endian) is at offset 4, its subtype at 8.
MACHO_MAGIC_64 = 0xFEEDFACF
FAT_MAGIC = 0xCAFEBABE
FAT_ALIGN = 14  # 2^14: the page size of arm64 macOS (and a multiple of x86_64's)


def universal_binary(slices, out: Path) -> Path:
    """One universal ("fat") Mach-O file ``out`` of the thin 64-bit Mach-O images ``slices`` (one per
    architecture), each at a 16 KiB aligned offset, as macOS's loader reads it."""
    images = [Path(s).read_bytes() for s in slices]
    header = struct.pack(">II", FAT_MAGIC, len(images))
    offset, entries, body = 1 << FAT_ALIGN, [], b""
    for image in images:
        magic, cputype, subtype = struct.unpack_from("<Iii", image, 0)
        if magic != MACHO_MAGIC_64:
            raise ValueError("universal_binary takes thin 64-bit Mach-O images")
        entries.append(struct.pack(">iiIII", cputype, subtype, offset, len(image), FAT_ALIGN))
        pad = -(len(image)) % (1 << FAT_ALIGN)
        body += image + b"\0" * pad
        offset += len(image) + pad
    head = header + b"".join(entries)
    Path(out).write_bytes(head + b"\0" * ((1 << FAT_ALIGN) - len(head)) + body[:len(body) - pad])  # no tail padding
    return Path(out)


def compiler_label(target: Platform | str, cc: Compiler) -> str:
    """What build lines call ``cc`` compiling for ``target``: "gcc", "x86_64-w64-mingw32-gcc", "zig cc
    -target x86_64-windows-gnu"."""
    target = platform(target) if isinstance(target, str) else target
    return f"{cc.name} -target {target.zig_target}" if cc.name == "zig cc" else cc.name


def build_binary(name: str, folder: str, fmi_version: str, sources: Path, c_files, binaries: Path, include_dirs=(),
                 system_include_dirs=(), extra_flags=(), use: str | None = None,
                 step=None) -> tuple[Path, list[str]]:
    """``binaries/<folder>/<name><suffix>`` of an FMU of ``fmi_version``: each platform of that folder
    compiled (:func:`compiler`, :func:`compile_library`), several merged into one universal file. Returns
    (the library, the name of each platform's compiler, in the order of ``folders(fmi_version)[folder]``).
    ToolchainMissing where a platform of the folder has no compiler here (nothing is written).
    ``step(platform, compiler)``: a context manager around each platform's compilation (the build's
    progress lines)."""
    step = step or (lambda target, cc: contextlib.nullcontext())
    platforms = folders(fmi_version)[folder]
    try:
        compilers = [compiler(p, use) for p in platforms]  # every one found before anything is compiled
    except ToolchainMissing as exc:
        raise ToolchainMissing(f"no binaries/{folder}: {exc}") from None
    target = Path(binaries) / folder / f"{name}{platforms[0].suffix}"
    if len(platforms) == 1:
        with step(platforms[0], compilers[0]):
            compile_library(platforms[0], compilers[0], sources, c_files, target, include_dirs, system_include_dirs,
                            extra_flags)
    else:
        Path(binaries).mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryDirectory(prefix=".slices-", dir=Path(binaries)) as scratch:
            slices = []
            for p, cc in zip(platforms, compilers):
                with step(p, cc):
                    slices.append(compile_library(p, cc, sources, c_files, Path(scratch) / p.name / target.name,
                                                  include_dirs, system_include_dirs, extra_flags))
            target.parent.mkdir(parents=True, exist_ok=True)
            universal_binary(slices, target)
    return target, [cc.name for cc in compilers]


def pythonfmu_label(guard: bool = True) -> str:
    """What builds a pythonfmu FMU here, as the build's lines say it: pythonfmu and its version, and the
    compiler of the guard (zig for glibc 2.17, else gcc) or why there is none."""
    from importlib import metadata

    try:
        label = f"pythonfmu {metadata.version('pythonfmu')}"
    except metadata.PackageNotFoundError:
        label = "pythonfmu (not installed)"
    if not guard:
        return f"{label}, no guard"
    try:
        return f"{label}, guard {compiler_label('x86_64-linux', compiler('x86_64-linux'))}"
    except ToolchainMissing:
        return f"{label}, no guard (no gcc or zig)"
