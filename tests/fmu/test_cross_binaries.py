"""Every binary of every native FMU, for every platform, read from its bytes; and those this machine can
run, run.

* Format and architecture: each binaries/ folder holds a shared library of its platform's format (ELF,
  PE, Mach-O) for its architecture (FMI 2.0 darwin64: one universal file with an x86_64 and an arm64
  slice), read by tests/binary_formats.py (pure Python; no tool of this machine reads Mach-O).
* Exports: every FMI function of the FMU's version (the list from the FMI headers fmpy ships) and nothing
  else: no internal name of the C front or the model (the only extras are the two symbols zig's Mach-O
  linker defines in every dylib, the image header and ``__dso_handle``).
* Loads with the system's libraries only (C library, libm; Windows' own DLLs; libSystem), names itself as
  ``<model>.dll`` / ``@rpath/<model>.dylib``, needs macOS 11 at most, and on Apple silicon carries the code
  signature macOS requires there.
* The reader itself: it finds exactly the one exported function of tests/c_host/export_probe.c built for
  every platform, and agrees with binutils' objdump on the FMUs' ELF and PE binaries.
* Runs: tests/c_host/fmi_probe_host.c (load the binary, instantiate, set in initialization mode, one doStep,
  get) built for each platform this machine can run: x86_64 Linux natively (gcc), aarch64 Linux under
  qemu-user (host built with zig), Windows under Wine (host built with mingw-w64 or zig). SpherePlateImpact's
  outputs against restitution.impact within restitution.agreement's per-case tolerances (another C
  library's maths, another architecture: never bit identity); BouncingBall's height and speed against the
  free fall. On Windows both the FMU's own DLL (mingw-w64 where installed) and one zig builds from the FMU's
  sources/, so the zig path is run here whatever built the FMU.

Each test skips with one line naming what is missing: the binary (the build had no compiler for it; see
tests/fmu_platforms.py), qemu-user and the aarch64 C library (Debian: qemu-user, libc6-arm64-cross), Wine
(wine64, wine), zig (pip install ziglang).
"""
from __future__ import annotations

import math
import os
import platform as host_platform
import re
import shutil
import subprocess
import zipfile
from pathlib import Path
from types import SimpleNamespace

import pytest

import restitution as r
from restitution.agreement import disagreements, tolerances
from restitution.fmu.builders.compile import CFLAGS

from binary_formats import read_images
from cases import FMU_REALS, params_for
from conftest import _implementation
from fmu_platforms import binary_folders, fmi_version, model_identifiers, skip_unless_built
from script_host import interface

MODELS = ("SpherePlateImpact", "BouncingBall")
C_HOST = Path(__file__).resolve().parents[1] / "c_host"
PROBE_HOST = C_HOST / "fmi_probe_host.c"
EXPORT_PROBE = C_HOST / "export_probe.c"
#: Each binaries/ folder: the format and the architectures (slices) of its library, written out here from
#: the FMI standards' names (not read from the build's table).
FOLDERS = {"linux64": ("ELF", ("x86_64",)), "x86_64-linux": ("ELF", ("x86_64",)),
           "aarch64-linux": ("ELF", ("aarch64",)),
           "win64": ("PE", ("x86_64",)), "x86_64-windows": ("PE", ("x86_64",)),
           "darwin64": ("Mach-O", ("aarch64", "x86_64")), "x86_64-darwin": ("Mach-O", ("x86_64",)),
           "aarch64-darwin": ("Mach-O", ("aarch64",))}
SUFFIXES = {"ELF": ".so", "PE": ".dll", "Mach-O": ".dylib"}
#: What a linker exports in every library of a format beside the code's own exports (zig's Mach-O linker:
#: __mh_dylib_header and ___dso_handle, named here without Mach-O's leading underscore).
LINKER_EXPORTS = {"ELF": frozenset(), "PE": frozenset(), "Mach-O": frozenset({"_mh_dylib_header", "__dso_handle"})}
MACOS_MINIMUM = (11, 0)  # the first macOS on Apple silicon
QEMU = shutil.which("qemu-aarch64") or shutil.which("qemu-aarch64-static")
AARCH64_ROOT = Path("/usr/aarch64-linux-gnu")  # Debian's libc6-arm64-cross
WINE = shutil.which("wine64") or shutil.which("wine") or (
    "/usr/lib/wine/wine64" if os.access("/usr/lib/wine/wine64", os.X_OK) else None)


def fmi_functions(version: str) -> frozenset:
    """The FMI functions of ``version`` ("2.0" or "3.0"): every ``FMIn_Export fmiNxTYPE fmiNx;`` of the
    fmiNFunctions.h fmpy ships."""
    from restitution.fmu.builders.native import NativeBuildSkipped, fmi_include_dir

    n = version[0]
    try:
        header = fmi_include_dir(version) / f"fmi{n}Functions.h"
    except NativeBuildSkipped as exc:
        pytest.skip(str(exc))
    names = re.findall(rf"FMI{n}_Export\s+fmi{n}\w+TYPE\s+(fmi{n}\w+)\s*;", header.read_text(encoding="utf-8"))
    assert len(names) > 30 and len(set(names)) == len(names), names
    return frozenset(names)


def _system_library(fmt: str, name: str) -> bool:
    """A library every machine of that system has (nothing of the build machine, no Python, no mingw or
    compiler runtime DLL)."""
    if fmt == "ELF":
        return name in {"libc.so.6", "libm.so.6", "libpthread.so.0", "libdl.so.2"}
    if fmt == "PE":
        return name.lower() in {"kernel32.dll", "msvcrt.dll"} or name.lower().startswith("api-ms-win-crt-")
    return name == "/usr/lib/libSystem.B.dylib"


def _binaries(fmu: Path) -> dict[str, dict[str, bytes]]:
    """binaries/ folder -> {file name: bytes}."""
    with zipfile.ZipFile(fmu) as z:
        return {folder: {name: z.read(f"binaries/{folder}/{name}") for name in names}
                for folder, names in binary_folders(fmu).items()}


@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("which", ["fmi2", "fmi3"])
def test_every_binary_is_its_platforms_library_and_exports_the_fmi_functions_only(built_fmus, which, model):
    fmu = _implementation(built_fmus, model, which)
    version = fmi_version(fmu)
    functions = fmi_functions(version)
    identifiers = model_identifiers(fmu)
    binaries = _binaries(fmu)
    assert ("linux64" if version == "2.0" else "x86_64-linux") in binaries
    for folder, files in sorted(binaries.items()):
        fmt, archs = FOLDERS[folder]
        assert sorted(files) == sorted(f"{i}{SUFFIXES[fmt]}" for i in identifiers), (folder, sorted(files))
        for name, data in files.items():
            where = f"{which}/{model}.fmu binaries/{folder}/{name}"
            images = read_images(data)
            assert sorted(image.arch for image in images) == sorted(archs), where
            for image in images:
                at = f"{where} ({image.arch})"
                assert image.format == fmt and image.shared, at
                assert functions <= image.exports, f"{at}: missing {sorted(functions - image.exports)}"
                assert image.exports - functions <= LINKER_EXPORTS[fmt], \
                    f"{at}: exports {sorted(image.exports - functions - LINKER_EXPORTS[fmt])}"
                assert all(_system_library(fmt, lib) for lib in image.needed), f"{at}: needs {image.needed}"
                if fmt == "PE":
                    assert image.details["dll_name"] == name, at
                if fmt == "Mach-O":
                    assert image.details["install_name"] == f"@rpath/{name}", at
                    assert image.details["symtab_exports"] == image.exports, at  # the trie and the symbol table agree
                    minimum = tuple(int(x) for x in image.details["min_os"].split(".")[:2])
                    assert image.details["platform"] == 1 and minimum <= MACOS_MINIMUM, at  # 1: macOS
                    assert image.arch != "aarch64" or image.details["signed"], f"{at}: no code signature"
                    if len(images) > 1:
                        assert image.details["fat_offset"] % (1 << image.details["fat_align"]) == 0, at


def test_the_reader_finds_exactly_what_the_compiler_was_told_to_export(tmp_path):
    """tests/c_host/export_probe.c (one exported, one internal function, as the FMUs build them) built for
    every platform of the native FMUs with zig, read back: its platform's format and architecture, and the
    exported function only (beside the Mach-O linker's own)."""
    from restitution.fmu.builders import toolchains

    if toolchains.zig_command() is None:
        pytest.skip(f"zig not found ({toolchains.ZIG_INSTALL})")
    for target in toolchains.PLATFORMS:
        cc = toolchains.compiler(target, use="zig")
        library = toolchains.compile_library(target, cc, C_HOST, [EXPORT_PROBE.name], tmp_path / target.name / f"probe{target.suffix}",
                                             libraries=())
        fmt, archs = FOLDERS[target.name]
        images = read_images(library.read_bytes())
        assert [(i.format, i.arch) for i in images] == [(fmt, archs[0])], target.name
        assert images[0].exports == {"probe_exported"} | LINKER_EXPORTS[fmt], (target.name, images[0].exports)


def _objdump_exports(path: Path, fmt: str) -> set[str] | None:
    """The exports binutils' objdump lists (ELF: defined global symbols of -T; PE: the export table of -p)."""
    objdump = shutil.which("objdump")
    if objdump is None:
        return None
    out = subprocess.run([objdump, "-T" if fmt == "ELF" else "-p", str(path)], capture_output=True, text=True).stdout
    if fmt == "ELF":
        return {f[-1] for f in (line.split() for line in out.splitlines())
                if len(f) >= 6 and f[1] in ("g", "w") and f[3] != "*UND*"}
    table = out.split("[Ordinal/Name Pointer] Table", 1)[-1].split("\n\n", 1)[0]
    return set(re.findall(r"\]\s+(\S+)", table))


@pytest.mark.parametrize("which", ["fmi2", "fmi3"])
def test_the_reader_agrees_with_objdump(built_fmus, which, tmp_path):
    if shutil.which("objdump") is None:
        pytest.skip("objdump not found (Debian: apt-get install binutils)")
    fmu = _implementation(built_fmus, "SpherePlateImpact", which)
    compared = 0
    for folder, files in sorted(_binaries(fmu).items()):
        fmt = FOLDERS[folder][0]
        if fmt == "Mach-O":
            continue  # binutils reads no Mach-O
        for name, data in files.items():
            path = tmp_path / folder / name
            path.parent.mkdir()
            path.write_bytes(data)
            assert read_images(data)[0].exports == _objdump_exports(path, fmt), f"{folder}/{name}"
            compared += 1
    assert compared >= 1  # the Linux x86-64 binary at least


# --- the C library baseline of the Linux binaries ------------------------------------------------------
#: The newest glibc symbol version a Linux binary of the project may need (toolchains.GLIBC_BASELINE, written
#: out here: the manylinux2014 baseline, the first glibc with aarch64).
GLIBC_BASELINE = (2, 17)
#: Every FMU of the build: (place in the build directory, whether its binaries/ holds pythonfmu's own).
ALL_FMUS = [(f"{model}.fmu", "python") for model in MODELS] + [
    (f"{which}/{model}.fmu", which) for which in ("fmi2", "fmi3") for model in MODELS]


def _project_elf_binaries(built_fmus):
    """(where, bytes) of every ELF binary the project builds, in every FMU of the build: the native FMUs'
    and the pythonfmu FMUs' guard (not pythonfmu's own ``<id>_pythonfmu.so``, which pythonfmu ships
    prebuilt)."""
    for place, which in ALL_FMUS:
        fmu = built_fmus / place if which == "python" else _implementation(built_fmus, place.split("/")[1][:-4], which)
        for folder, files in sorted(_binaries(fmu).items()):
            for name, data in sorted(files.items()):
                if FOLDERS[folder][0] == "ELF" and not name.endswith("_pythonfmu.so"):
                    yield f"{place} binaries/{folder}/{name}", data


def _glibc_text(version) -> str:
    return "none" if version is None else "GLIBC_" + ".".join(map(str, version))


def test_every_linux_binary_needs_at_most_glibc_2_17(built_fmus):
    """The highest GLIBC_x.y each Linux binary needs (its .gnu.version_r, read in Python): at most 2.17, so
    it loads on CentOS 7 and every later distribution, whatever glibc the build machine has."""
    from binary_formats import glibc_version

    found = {}
    for where, data in _project_elf_binaries(built_fmus):
        image, = read_images(data)
        found[where] = glibc_version(image.details.get("version_needs", {}))
    print("\n".join(f"{where}: {_glibc_text(v)}" for where, v in found.items()))
    assert len(found) >= 2 + 2 * 2 * 1  # the two guards, each native FMU's x86_64 binary (and aarch64 in FMI 3.0)
    above = {where: _glibc_text(v) for where, v in found.items() if v is not None and v > GLIBC_BASELINE}
    assert not above, f"needs a glibc newer than {_glibc_text(GLIBC_BASELINE)}: {above}"


@pytest.mark.parametrize("glibc, expected", [("2.17", (2, 2, 5)), ("2.34", (2, 29))])
def test_the_version_reader_finds_the_glibc_the_target_names(tmp_path, glibc, expected):
    """A library calling exp() linked by zig against glibc 2.17 and 2.34: glibc 2.29 gave exp a new symbol
    version (GLIBC_2.29, glibc's NEWS for 2.29); before it, x86-64's exp is GLIBC_2.2.5, its first version."""
    from restitution.fmu.builders import toolchains
    from binary_formats import glibc_version

    if toolchains.zig_command() is None:
        pytest.skip(f"zig not found ({toolchains.ZIG_INSTALL})")
    source = tmp_path / "uses_exp.c"
    # exported as the FMI functions are (the build compiles with -fvisibility=hidden)
    source.write_text("#include <math.h>\n__attribute__((visibility(\"default\"))) double uses_exp(double x) "
                      "{ return exp(x); }\n")
    target = toolchains.Platform("x86_64-linux", None, ".so", f"x86_64-linux-gnu.{glibc}")
    library = toolchains.compile_library(target, toolchains.zig_compiler(target), tmp_path, [source.name],
                                         tmp_path / "out" / "libuses_exp.so")
    image, = read_images(library.read_bytes())
    assert glibc_version(image.details["version_needs"]) == expected
    assert any(lib.startswith("libm.so") for lib in image.details["version_needs"])


@pytest.mark.parametrize("model", MODELS)
def test_the_guard_exports_the_fmi2_functions_only(built_fmus, model):
    """The pythonfmu FMU's binaries/linux64/<id>.so, the project's guard: every FMI 2.0 function and nothing
    else (its FMI 2.0 layer is the native FMUs'; the model-exchange functions are there and a model-exchange
    instantiation is refused, docs/installing.md)."""
    with zipfile.ZipFile(built_fmus / f"{model}.fmu") as z:
        names = z.namelist()
        if not any(n.endswith("_pythonfmu.so") for n in names):
            pytest.skip("the pythonfmu FMU was built without the guard (no zig or gcc)")
        image, = read_images(z.read(f"binaries/linux64/{model}.so"))
    assert image.exports == fmi_functions("2.0"), sorted(image.exports ^ fmi_functions("2.0"))


# --- the binaries run: a plain C host on each platform this machine can run ---------------------------
PROBE_STEP = {"SpherePlateImpact": 1e-3, "BouncingBall": 0.1}  # [s] the one communication step
PROBE_SPEED = 2.3  # [m/s] Green (2022)'s checkpoint
PROBE_THICKNESS = 3.1e-3  # [m] plate.t, set: about half the start value


def _runner(target: str) -> list[str]:
    """The command prefix that runs a program of ``target`` here; skips naming what is missing."""
    if target == "x86_64-linux":
        if not (host_platform.system() == "Linux" and host_platform.machine() in ("x86_64", "AMD64")):
            pytest.skip("not an x86_64 Linux machine")
        return []
    if target == "aarch64-linux":
        if QEMU is None:
            pytest.skip("qemu-aarch64 not found (Debian: apt-get install qemu-user): aarch64-linux binaries not run")
        if not (AARCH64_ROOT / "lib" / "ld-linux-aarch64.so.1").exists():
            pytest.skip(f"no aarch64 C library in {AARCH64_ROOT} (Debian: apt-get install libc6-arm64-cross)")
        return [QEMU, "-L", str(AARCH64_ROOT)]
    if WINE is None:
        pytest.skip("wine not found (Debian: apt-get install wine64 wine): x86_64-windows binaries not run")
    return [WINE]


@pytest.fixture(scope="module")
def probe_hosts(tmp_path_factory):
    """build(target, version) -> tests/c_host/fmi_probe_host.c built for ``target`` (x86_64-linux with gcc,
    aarch64-linux with zig, x86_64-windows with mingw-w64 or zig: toolchains' choice) and FMI ``version``,
    once per module; skips naming the missing compiler."""
    from restitution.fmu.builders import toolchains
    from restitution.fmu.builders.native import fmi_include_dir

    out, built = tmp_path_factory.mktemp("probe_hosts"), {}

    def build(target: str, version: str) -> Path:
        if (target, version) not in built:
            try:
                cc = toolchains.compiler(target)
            except toolchains.ToolchainMissing as exc:
                pytest.skip(f"no C compiler for the {target} host: {exc}")
            windows = target.endswith("windows")
            exe = out / f"fmi{version[0]}_probe_{target}{'.exe' if windows else ''}"
            extra = ["-D__USE_MINGW_ANSI_STDIO=1"] + (["-static", "-static-libgcc"] if cc.name == toolchains.MINGW else []) \
                if windows else ["-ldl"]
            cmd = [*cc.command, *CFLAGS, f"-DFMI_VERSION={version[0]}", "-isystem", str(fmi_include_dir(version)),
                   "-o", str(exe), str(PROBE_HOST), *extra]
            done = subprocess.run(cmd, capture_output=True, text=True, env=cc.env, timeout=600)
            assert done.returncode == 0, f"{' '.join(cmd)}\n{done.stderr}"
            built[target, version] = exe
        return built[target, version]

    return build


@pytest.fixture(scope="module")
def wine_env(tmp_path_factory):
    """One Wine prefix for the Wine runs of this file; its wineserver (this prefix's only) stopped at the end."""
    prefix = tmp_path_factory.mktemp("wineprefix")
    env = dict(os.environ, WINEPREFIX=str(prefix), WINEDEBUG="-all", WINEDLLOVERRIDES="mscoree,mshtml=")
    yield env
    server = shutil.which("wineserver")
    if server and WINE is not None:
        subprocess.run([server, "-k"], env=env, capture_output=True, timeout=60)


def _windows_path(path: Path) -> str:
    """A Linux path as Wine's Z: drive sees it."""
    return "Z:" + str(path.resolve()).replace("/", "\\")


def _probe_arguments(fmu, model: str) -> tuple[list[str], list[str]]:
    """(sets, gets) of the probe for ``model`` (fmi_probe_host.c's sVR=VALUE and gVR arguments)."""
    if model == "SpherePlateImpact":
        sets = [f"s{fmu.vr['v_approach']}={PROBE_SPEED!r}", f"s{fmu.vr['plate.t']}={PROBE_THICKNESS!r}"]
        return sets, [f"g{fmu.vr[name]}" for name in FMU_REALS]
    return [], [f"g{fmu.vr['h']}", f"g{fmu.vr['v']}"]


def _check_values(fmu, model: str, values: dict[int, float], label: str) -> None:
    """The probe's outputs against the package (SpherePlateImpact) or the free fall (BouncingBall)."""
    if model == "SpherePlateImpact":
        params = dict(params_for("s2/al6061"), plate_t=PROBE_THICKNESS)
        got = SimpleNamespace(**{field: values[fmu.vr[name]] for name, field in FMU_REALS.items()})
        tol, flips = tolerances(PROBE_SPEED, params)
        problems = disagreements(got, r.impact(PROBE_SPEED, **params), tol, flips)
        assert not problems, f"{label}: {problems}"
        return
    h0, g, t = 0.3, 9.80665, PROBE_STEP[model]  # the start values; the first contact is at 0.247 s
    assert math.isclose(values[fmu.vr["h"]], h0 - 0.5 * g * t * t, rel_tol=1e-12), (label, values)
    assert math.isclose(values[fmu.vr["v"]], -g * t, rel_tol=1e-12), (label, values)


def _probe(host: Path, runner: list[str], library: Path, fmu, resources: Path, model: str, env=None) -> dict[int, float]:
    """Run the probe host on ``library``; the values it read, by value reference."""
    windows = library.suffix == ".dll"
    lib = _windows_path(library) if windows else str(library)
    if fmu.version == 2:
        res = "file:///" + _windows_path(resources).replace("\\", "/") if windows else resources.resolve().as_uri()
    else:
        res = _windows_path(resources) + "\\" if windows else str(resources.resolve()) + os.sep
    sets, gets = _probe_arguments(fmu, model)
    cmd = [*runner, str(host), lib, fmu.token, res, repr(PROBE_STEP[model]), *sets, *gets]
    run = subprocess.run(cmd, capture_output=True, text=True, timeout=300, env=env)
    assert run.returncode == 0 and run.stdout.rstrip().endswith("DONE"), \
        f"{' '.join(cmd)}: exit {run.returncode}\n{run.stdout[-2000:]}\n{run.stderr[-2000:]}"
    values = {}
    for line in run.stdout.splitlines():
        if line.startswith("REAL "):
            _, vr, text = line.split()
            values[int(vr)] = float.fromhex(text)
    assert len(values) == len(gets), run.stdout
    return values


RUNS = [("x86_64-linux", "fmi2"), ("x86_64-linux", "fmi3"), ("aarch64-linux", "fmi3"),
        ("x86_64-windows", "fmi2"), ("x86_64-windows", "fmi3")]


@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("target, which", RUNS, ids=[f"{t}-{w}" for t, w in RUNS])
def test_binary_runs_and_computes_what_the_package_does(built_fmus, target, which, model, probe_hosts, request,
                                                        tmp_path):
    """The FMU's binary of ``target`` in the probe host run on this machine (natively, under qemu-user or
    under Wine): every call OK, the outputs those of the package (SpherePlateImpact, within tolerance)
    or of the free fall (BouncingBall)."""
    fmu_path = _implementation(built_fmus, model, which)
    runner = _runner(target)
    folder = skip_unless_built(fmu_path, target)
    fmu = interface(fmu_path)
    unpacked = tmp_path / "fmu"
    with zipfile.ZipFile(fmu_path) as z:
        z.extractall(unpacked)
    library = unpacked / "binaries" / folder / f"{model}{SUFFIXES[FOLDERS[folder][0]]}"
    env = request.getfixturevalue("wine_env") if target == "x86_64-windows" else None
    values = _probe(probe_hosts(target, fmi_version(fmu_path)), runner, library, fmu, unpacked / "resources", model, env)
    _check_values(fmu, model, values, f"{which}/{model}.fmu binaries/{folder}")


@pytest.mark.slow
@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("which", ["fmi2", "fmi3"])
def test_zig_windows_dll_from_the_fmus_sources_runs_under_wine(built_fmus, which, model, probe_hosts, wine_env,
                                                               tmp_path):
    """The Windows DLL zig builds from the FMU's sources/ (what the build writes where mingw-w64 is missing;
    built here whatever built the FMU's own) in the probe host under Wine: the package's values, as above."""
    from restitution.fmu.builders import toolchains
    from restitution.fmu.builders.native import fmi_include_dir

    fmu_path = _implementation(built_fmus, model, which)
    runner = _runner("x86_64-windows")
    try:
        cc = toolchains.compiler("x86_64-windows", use="zig")
    except toolchains.ToolchainMissing as exc:
        pytest.skip(str(exc))
    fmu = interface(fmu_path)
    version = fmi_version(fmu_path)
    unpacked = tmp_path / "fmu"
    with zipfile.ZipFile(fmu_path) as z:
        z.extractall(unpacked)
    sources = unpacked / "sources"
    library = toolchains.compile_library("x86_64-windows", cc, sources, sorted(p.name for p in sources.glob("*.c")),
                                         tmp_path / "zig" / f"{model}.dll", system_include_dirs=[fmi_include_dir(version)])
    image, = read_images(library.read_bytes())
    assert image.format == "PE" and image.arch == "x86_64" and image.exports == fmi_functions(version)
    values = _probe(probe_hosts("x86_64-windows", version), runner, library, fmu, unpacked / "resources", model, wine_env)
    _check_values(fmu, model, values, f"zig's DLL from {which}/{model}.fmu sources/")
