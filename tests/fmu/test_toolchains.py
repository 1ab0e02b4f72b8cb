"""restitution.fmu.builders.toolchains: the platforms of the native FMUs and the compiler of each.

* The table: FMI 3.0 gives each of the five platforms its folder; FMI 2.0 names linux64, win64 and
  darwin64 (both macOS architectures in one file) and no aarch64 Linux folder.
* Which compiler: gcc for x86_64-linux, mingw-w64 for Windows where it is on PATH, zig otherwise; with
  neither, one line naming what to install.
* zig's cache: where ZIG_GLOBAL_CACHE_DIR / ZIG_LOCAL_CACHE_DIR say, else ~/.cache/zig (or
  $XDG_CACHE_HOME/zig), else, where that cannot be written, a folder in the temporary directory.
* A universal Mach-O file of two slices reads back as both (tests/binary_formats.py).
* Reproducible: the same sources compiled twice, from two folders, give the same bytes on every platform,
  with each compiler there is here.
"""
from __future__ import annotations

import shutil
import struct
import time
import zipfile

import pytest

from restitution.fmu.builders import toolchains

from binary_formats import read_images


def test_every_platform_has_its_folders():
    assert {p.name for p in toolchains.PLATFORMS} == {"x86_64-linux", "aarch64-linux", "x86_64-windows",
                                                       "x86_64-darwin", "aarch64-darwin"}
    assert {f: [p.name for p in ps] for f, ps in toolchains.folders("3.0").items()} == {
        p.name: [p.name] for p in toolchains.PLATFORMS}
    assert {f: sorted(p.name for p in ps) for f, ps in toolchains.folders("2.0").items()} == {
        "linux64": ["x86_64-linux"], "win64": ["x86_64-windows"], "darwin64": ["aarch64-darwin", "x86_64-darwin"]}
    assert toolchains.platform("win64").name == "x86_64-windows"
    with pytest.raises(KeyError):
        toolchains.platform("darwin64")  # two platforms


def test_which_compiler(monkeypatch):
    real_which = shutil.which
    monkeypatch.delenv(toolchains.COMPILER_CHOICE, raising=False)
    monkeypatch.setattr(toolchains, "zig_command", lambda: ("python", "-m", "ziglang"))
    # x86_64-linux: zig first (the glibc 2.17 baseline), gcc where zig is missing
    linux = toolchains.compiler("x86_64-linux")
    assert linux.name == "zig cc" and linux.command[-2:] == ("-target", "x86_64-linux-gnu.2.17")
    if shutil.which("gcc"):
        assert toolchains.compiler("x86_64-linux", use="native").name == "gcc"
        with monkeypatch.context() as without_zig:
            without_zig.setattr(toolchains, "zig_command", lambda: None)
            assert toolchains.compiler("x86_64-linux").name == "gcc"
    if shutil.which(toolchains.MINGW):  # RESTITUTION_COMPILER=zig (the wheel's build): zig though mingw is here
        assert toolchains.compiler("x86_64-windows").name == toolchains.MINGW
        monkeypatch.setenv(toolchains.COMPILER_CHOICE, "zig")
        assert toolchains.compiler("x86_64-windows").name == "zig cc"
        monkeypatch.delenv(toolchains.COMPILER_CHOICE)
    monkeypatch.setenv(toolchains.COMPILER_CHOICE, "gcc")
    with pytest.raises(ValueError, match="RESTITUTION_COMPILER"):
        toolchains.compiler("x86_64-linux")
    monkeypatch.delenv(toolchains.COMPILER_CHOICE)
    hidden = {toolchains.MINGW, "gcc"}
    monkeypatch.setattr(toolchains.shutil, "which", lambda cmd, *a, **k: None if cmd in hidden else real_which(cmd, *a, **k))
    windows = toolchains.compiler("x86_64-windows")
    assert windows.name == "zig cc" and windows.command[-2:] == ("-target", "x86_64-windows-gnu")
    assert toolchains.compiler("x86_64-linux").name == "zig cc"  # without gcc
    with pytest.raises(toolchains.ToolchainMissing, match="gcc-mingw-w64-x86-64"):
        toolchains.compiler("x86_64-windows", use="native")
    monkeypatch.setattr(toolchains, "zig_command", lambda: None)
    with pytest.raises(toolchains.ToolchainMissing) as missing:
        toolchains.compiler("x86_64-windows")
    assert str(missing.value) == ("neither x86_64-w64-mingw32-gcc (apt-get install gcc-mingw-w64-x86-64) nor zig "
                                  "(pip install ziglang) found")
    with pytest.raises(toolchains.ToolchainMissing, match=r"^zig not found \(pip install ziglang\)$"):
        toolchains.compiler("aarch64-darwin")
    with pytest.raises(toolchains.ToolchainMissing, match=r"^no binaries/darwin64: zig not found"):
        toolchains.build_binary("M", "darwin64", "2.0", ".", [], "unused")


def test_zig_cache_directory(tmp_path):
    base = {"HOME": str(tmp_path / "home"), "PATH": "/usr/bin"}
    env = toolchains.zig_environment(base)
    assert env["ZIG_GLOBAL_CACHE_DIR"] == env["ZIG_LOCAL_CACHE_DIR"] == str(tmp_path / "home" / ".cache" / "zig")
    env = toolchains.zig_environment(dict(base, XDG_CACHE_HOME=str(tmp_path / "xdg")))
    assert env["ZIG_GLOBAL_CACHE_DIR"] == str(tmp_path / "xdg" / "zig")
    env = toolchains.zig_environment(dict(base, ZIG_GLOBAL_CACHE_DIR="/somewhere", ZIG_LOCAL_CACHE_DIR="/else"))
    assert (env["ZIG_GLOBAL_CACHE_DIR"], env["ZIG_LOCAL_CACHE_DIR"]) == ("/somewhere", "/else")
    env = toolchains.zig_environment(dict(base, ZIG_GLOBAL_CACHE_DIR="/somewhere"))
    assert env["ZIG_LOCAL_CACHE_DIR"] == "/somewhere"
    blocked = tmp_path / "file"
    blocked.write_text("not a directory")
    env = toolchains.zig_environment(dict(base, XDG_CACHE_HOME=str(blocked)))  # cannot be written
    assert env["ZIG_GLOBAL_CACHE_DIR"].startswith(toolchains.tempfile.gettempdir())


def _thin_macho(cputype: int, size: int) -> bytes:
    """A minimal thin 64-bit Mach-O dylib header without load commands, padded to ``size``."""
    return struct.pack("<IiiIIIII", 0xFEEDFACF, cputype, 3, 6, 0, 0, 0, 0).ljust(size, b"\x01")


def test_universal_binary(tmp_path):
    slices = []
    for name, cputype, size in (("x86_64", 0x01000007, 5000), ("aarch64", 0x0100000C, 20000)):
        slices.append(tmp_path / name)
        slices[-1].write_bytes(_thin_macho(cputype, size))
    out = toolchains.universal_binary(slices, tmp_path / "fat.dylib")
    images = read_images(out.read_bytes())
    assert [i.arch for i in images] == ["x86_64", "aarch64"]
    assert [i.details["fat_offset"] for i in images] == [16384, 32768]
    data = out.read_bytes()
    assert data[16384:16384 + 5000] == slices[0].read_bytes() and data[32768:] == slices[1].read_bytes()


def test_builds_are_reproducible(fmi3_ball_fmu, tmp_path):
    """BouncingBall's FMI 3.0 sources compiled twice, from two folders, seconds apart, by every compiler of
    every platform there is here (gcc, mingw-w64, zig): the same bytes (a PE link time stamp from the clock
    would differ)."""
    from restitution.fmu.builders.native import fmi_include_dir

    compared = []
    for target in toolchains.PLATFORMS:
        for use in ("native", "zig"):
            try:
                cc = toolchains.compiler(target, use=use)
            except toolchains.ToolchainMissing:
                continue
            builds = []
            for k in (1, 2):
                folder = tmp_path / f"{target.name}-{use}-{k}"
                with zipfile.ZipFile(fmi3_ball_fmu) as z:
                    z.extractall(folder, [n for n in z.namelist() if n.startswith("sources/")])
                sources = folder / "sources"
                library = toolchains.compile_library(target, cc, sources, sorted(p.name for p in sources.glob("*.c")),
                                                     folder / f"BouncingBall{target.suffix}",
                                                     system_include_dirs=[fmi_include_dir("3.0")])
                builds.append(library.read_bytes())
                time.sleep(1.1 if k == 1 else 0)  # PE time stamps count seconds
            assert builds[0] == builds[1], f"{target.name} with {cc.name}: two builds differ"
            compared.append(f"{target.name}/{cc.name}")
    if not compared:
        pytest.skip("no compiler here")
    print("reproducible:", ", ".join(compared))
