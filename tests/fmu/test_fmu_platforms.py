"""The platforms every built FMU declares are the platforms it has binaries for, with or without a cross
compiler on the machine.

* Every FMU of the build (pythonfmu, native FMI 2.0, native FMI 3.0; both models): each binaries/ folder
  is one the FMI standard of its version names and holds ``<modelIdentifier>.<so|dll|dylib>``; each
  platform the build records in ``resources/build_info.json`` has its folder and each folder is recorded;
  an FMI 3.0 ``sources/buildDescription.xml`` names only platform tuples and sources it ships; fmpy's
  ``supported_platforms`` (what a host reads) agrees with the folders (tests/fmu_platforms.py).
* The checker finds each of those faults in an FMU doctored to have it.
* The native FMUs have binaries for every platform (FMI 3.0: x86_64 and aarch64 Linux, x86_64 Windows,
  x86_64 and aarch64 macOS; FMI 2.0: linux64, win64, darwin64) where the build has gcc and zig; a platform
  whose compiler is missing skips, naming it.
* A native build with mingw-w64 missing (whatever this machine has) builds the Windows binaries with zig;
  with zig missing too it writes no Windows, macOS or Linux aarch64 folder, declares none, and says which
  compiler was missing and how to install it.
* Where the build produced the Windows binaries they are PE32+ x86-64 DLLs; where it did not, that test
  skips naming the compiler. (Every binary's format, architecture and exports:
  tests/fmu/test_cross_binaries.py.)

``.ci/run`` runs this file (and the other platform tests) a second time with every cross compiler hidden
from PATH.
"""
from __future__ import annotations

import json
import shutil
import struct
import zipfile
from pathlib import Path

import pytest

from conftest import VERSIONS, _implementation
from fmu_platforms import (INSTALL, NATIVE_FOLDERS, binary_folders, declared_platforms, fmi_version, model_identifiers,
                           platform_problems, skip_unless_built)

MODELS = ("SpherePlateImpact", "BouncingBall")
#: fmpy.supported_platforms' name of each binaries/ folder the builds here can write (fmpy 0.3.32 lists no
#: aarch64 Linux platform).
FMPY_NAMES = {"linux64": "linux64", "x86_64-linux": "linux64", "win64": "win64", "x86_64-windows": "win64",
              "darwin64": "darwin64", "x86_64-darwin": "darwin64", "aarch64-darwin": "darwin64", "aarch64-linux": None}


@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("which", VERSIONS)
def test_every_declared_platform_has_its_binary_and_every_binary_platform_is_declared(built_fmus, which, model):
    from fmpy import supported_platforms

    fmu = _implementation(built_fmus, model, which)
    folders = binary_folders(fmu)
    assert platform_problems(fmu) == []
    assert ("linux64" if fmi_version(fmu) == "2.0" else "x86_64-linux") in folders
    if which != "python":  # the native builds record their platforms
        assert sorted(declared_platforms(fmu)) == sorted(folders)
    with zipfile.ZipFile(fmu) as z:
        has_sources = any(n.startswith("sources/") and n.endswith(".c") for n in z.namelist())
    assert has_sources == (which != "python")
    assert sorted(supported_platforms(str(fmu))) == sorted({FMPY_NAMES[f] for f in folders if FMPY_NAMES[f]}
                                                           | ({"c-code"} if has_sources else set()))


@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("which", ["fmi2", "fmi3"])
def test_native_fmus_have_every_platform(built_fmus, which, model):
    """Every platform of the issue, FMI 3.0: x86_64-linux, aarch64-linux, x86_64-windows, x86_64-darwin,
    aarch64-darwin; FMI 2.0: linux64, win64, darwin64 (skipped, naming the compiler and how to install it,
    where one is missing here), and nothing else."""
    fmu = _implementation(built_fmus, model, which)
    version = fmi_version(fmu)
    for folder in NATIVE_FOLDERS[version]:
        skip_unless_built(fmu, folder)
    assert sorted(binary_folders(fmu)) == sorted(NATIVE_FOLDERS[version])
    assert sorted(declared_platforms(fmu)) == sorted(NATIVE_FOLDERS[version])


def _doctored(fmu: Path, out: Path, drop=(), add=None, build_info=None, build_description=None) -> Path:
    """A copy of ``fmu`` without the members whose name starts with one of ``drop``, with ``add`` (name ->
    bytes), its build_info.json updated by ``build_info`` and its buildDescription.xml passed through
    ``build_description``."""
    with zipfile.ZipFile(fmu) as src, zipfile.ZipFile(out, "w") as dst:
        for item in src.infolist():
            if any(item.filename.startswith(prefix) for prefix in drop):
                continue
            data = src.read(item.filename)
            if item.filename == "resources/build_info.json" and build_info:
                data = json.dumps({**json.loads(data), **build_info}).encode()
            if item.filename == "sources/buildDescription.xml" and build_description:
                data = build_description(data.decode()).encode()
            dst.writestr(item, data)
        for name, data in (add or {}).items():
            dst.writestr(name, data)
    return out


def test_platform_checker_finds_each_fault(fmi3_ball_fmu, tmp_path):
    """What test_every_declared_platform... asserts empty is not empty for an FMU with each fault."""
    fmu = fmi3_ball_fmu
    assert platform_problems(fmu) == []
    cases = {
        "declares x86_64-windows (build_info.json) without binaries/x86_64-windows/":
            dict(drop=("binaries/x86_64-windows/",), build_info={"platforms": ["x86_64-linux", "x86_64-windows"]}),
        "binaries/x86_64-windows/ not declared in build_info.json":
            dict(drop=("binaries/x86_64-windows/",), add={"binaries/x86_64-windows/BouncingBall.dll": b"MZ"},
                 build_info={"platforms": ["x86_64-linux"]}),
        "binaries/win64: not a platform folder of FMI 3.0": dict(add={"binaries/win64/BouncingBall.dll": b"MZ"}),
        "binaries/x86_64-windows: no BouncingBall.dll":
            dict(drop=("binaries/x86_64-windows/",), add={"binaries/x86_64-windows/BouncingBall.so": b""},
                 build_info={"platforms": ["x86_64-linux", "x86_64-windows"]}),
        "buildDescription.xml: platform 'x86_64-windoze' is not an FMI 3.0 platform tuple":
            dict(build_description=lambda xml: xml.replace("<BuildConfiguration ",
                                                           '<BuildConfiguration platform="x86_64-windoze" ')),
        "buildDescription.xml: sources/rst_lifecycle.c missing": dict(drop=("sources/rst_lifecycle.c",)),
    }
    for i, (expected, change) in enumerate(cases.items()):
        doctored = _doctored(fmu, tmp_path / f"{i}.fmu", **change)
        assert expected in platform_problems(doctored), (expected, platform_problems(doctored))


@pytest.mark.parametrize("zig", ["zig", "no zig"])
@pytest.mark.parametrize("fmi_version_", ["2.0", "3.0"])
def test_native_platforms_without_mingw_are_the_built_ones(ball_fmu, fmi_version_, zig, tmp_path, monkeypatch):
    """build_native_one with x86_64-w64-mingw32-gcc missing (hidden from the build, whatever this machine
    has): with zig, the FMU has every platform, the Windows one built by zig; without zig too (hidden), it
    has the Linux x86-64 binary only. build_info.json declares what was built, and the build says which
    compiler was missing for each platform it skipped and how to install it."""
    from restitution.fmu.builders import native as build_native, toolchains

    if shutil.which("gcc") is None:
        pytest.skip("gcc not found: no native FMU is built here")
    if zig == "zig" and toolchains.zig_command() is None:
        pytest.skip(f"zig not found ({toolchains.ZIG_INSTALL})")
    if zig == "no zig":
        monkeypatch.setattr(toolchains, "zig_command", lambda: None)
    real_which = shutil.which
    monkeypatch.setattr(toolchains.shutil, "which",
                        lambda cmd, *a, **k: None if cmd == toolchains.MINGW else real_which(cmd, *a, **k))
    messages = []
    fmu = build_native.build_native_one("BouncingBall", tmp_path, log=messages.append, fmi_version=fmi_version_)
    linux = toolchains.platform("x86_64-linux").folder(fmi_version_)
    windows = toolchains.platform("x86_64-windows").folder(fmi_version_)
    expected = list(NATIVE_FOLDERS[fmi_version_]) if zig == "zig" else [linux]
    assert sorted(binary_folders(fmu)) == expected
    assert declared_platforms(fmu) == expected
    assert platform_problems(fmu) == []
    with zipfile.ZipFile(fmu) as z:
        compilers = json.loads(z.read("resources/build_info.json"))["compilers"]
    assert compilers[linux] == ("zig cc" if zig == "zig" else "gcc")  # zig first: the glibc 2.17 baseline
    if zig == "zig":
        assert compilers[windows] == "zig cc" and messages == [], messages
    else:
        assert len(messages) == len(NATIVE_FOLDERS[fmi_version_]) - 1, messages
        assert any(toolchains.MINGW in m and toolchains.ZIG_INSTALL in m and f"binaries/{windows}:" in m
                   for m in messages), messages
        for folder in set(NATIVE_FOLDERS[fmi_version_]) - {linux}:
            message = next(m for m in messages if f"binaries/{folder}:" in m)
            assert message.startswith(f"warning: native FMI {fmi_version_} BouncingBall.fmu: no binaries/{folder}: ")
            platforms = toolchains.folders(fmi_version_)[folder]
            assert all(INSTALL[p.name].split(", or ")[-1] in message for p in platforms), message


def _pe_machine(dll: bytes) -> int:
    """The COFF machine field of a PE image (0x8664: x86-64)."""
    assert dll[:2] == b"MZ", dll[:2]
    pe = struct.unpack_from("<I", dll, 0x3C)[0]
    assert dll[pe:pe + 4] == b"PE\0\0"
    return struct.unpack_from("<H", dll, pe + 4)[0]


@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("which", ["fmi2", "fmi3"])
def test_windows_binary_platform_is_a_x86_64_dll(built_fmus, which, model):
    """The native FMUs' Windows x64 binaries, where the build produced them (mingw-w64 installed; skipped,
    naming the compiler, where not): PE images for x86-64, one per modelIdentifier."""
    fmu = _implementation(built_fmus, model, which)
    folder = skip_unless_built(fmu, "win64")
    with zipfile.ZipFile(fmu) as z:
        for identifier in model_identifiers(fmu):
            assert _pe_machine(z.read(f"binaries/{folder}/{identifier}.dll")) == 0x8664
