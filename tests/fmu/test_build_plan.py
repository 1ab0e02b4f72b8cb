"""restitution.fmu.builders.plan and .progress: what a build makes and what it says as it goes.

* The plans: the Quickstart demo's is its one FMU (pythonfmu, the host's guard, no zig); ``restitution fmu
  build`` and the default FMUs' are every FMU, the native ones for every platform.
* Completeness: a directory the demo filled is not the full set (a full plan builds the rest, and only
  that), a native FMU lacking a platform a compiler here builds is rebuilt, and the demo reuses a full set.
* The lines: a start and an end line per product and platform, in build order, naming the compiler; zig's
  cache told once, before zig's first use (warm or cold as its cache says).
"""
from __future__ import annotations

import json
import shutil
import struct
import zipfile
from pathlib import Path

import pytest

from restitution.fmu.builders import plan, products, toolchains
from restitution.fmu.builders.progress import Progress

ROOT = Path(__file__).resolve().parents[2]


def _fmu_lines(lines):
    return [line for line in lines if line.startswith("fmu build: ")]


# --- the plans ---------------------------------------------------------------------------------------------
def test_the_demo_plan_is_its_one_fmu_for_the_host_only():
    demo = plan.model_plan("SpherePlateImpact")
    assert [p.name for p in demo] == ["SpherePlateImpact.fmu"] and not demo[0].native
    (step,) = plan.steps(demo)
    assert step.platform == "x86_64-linux" and step.compiler.startswith("pythonfmu ")
    assert plan.zig_targets(demo) == []  # zig is never started by the demo
    with pytest.raises(KeyError):
        plan.model_plan("NoSuchModel")


def test_the_full_plan_is_every_fmu_for_every_platform():
    full = plan.full_plan()
    assert [p.name for p in full] == ["SpherePlateImpact.fmu", "BouncingBall.fmu",
                                      "fmi2/SpherePlateImpact.fmu", "fmi2/BouncingBall.fmu",
                                      "fmi3/SpherePlateImpact.fmu", "fmi3/BouncingBall.fmu"]
    native = [p for p in full if p.native]
    assert all(p.planned_folders() == tuple(toolchains.folders(p.fmi_version)) for p in native)
    platforms = {name: [s.platform for s in plan.steps([p])] for p in native for name in [p.name]}
    every = {t.name for t in toolchains.PLATFORMS}
    assert all(set(found) == every - ({"aarch64-linux"} if name.startswith("fmi2/") else set())
               for name, found in platforms.items()), platforms  # FMI 2.0 has no aarch64 Linux folder


def test_restitution_fmu_build_builds_the_full_plan(tmp_path, monkeypatch, capsys):
    from restitution.fmu.__main__ import main

    asked = []
    monkeypatch.setattr(products, "run", lambda todo, out, **kw: asked.append((todo, out)) or [])
    assert main(["build", "--out", str(tmp_path)]) == 0
    assert asked == [(plan.full_plan(), tmp_path)]


# --- completeness ------------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def demo_dist(tmp_path_factory):
    """dist/ as the Quickstart demo leaves it on a fresh clone (examples/quickstart_bounce.py, its own build),
    and what the demo printed on stderr."""
    import importlib.util
    import io
    from contextlib import redirect_stderr, redirect_stdout

    dist = tmp_path_factory.mktemp("demo") / "dist"
    spec = importlib.util.spec_from_file_location("quickstart_bounce_demo", ROOT / "examples" / "quickstart_bounce.py")
    demo = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(demo)
    err, out = io.StringIO(), io.StringIO()
    with pytest.MonkeyPatch.context() as patch, redirect_stderr(err), redirect_stdout(out):
        patch.setattr(products, "default_fmu_dir", lambda: dist)
        bounces = demo.run()
    assert bounces.n_impacts > 3
    return dist, err.getvalue().splitlines()


def test_the_demo_builds_its_fmu_alone_and_says_so_as_it_goes(demo_dist):
    dist, lines = demo_dist
    assert sorted(p.relative_to(dist).as_posix() for p in dist.rglob("*")) == ["SpherePlateImpact.fmu"]
    assert all(line.startswith("fmu build: ") for line in lines), lines
    why, head, start, end, total = lines
    assert why.startswith(f"fmu build: in {dist}, SpherePlateImpact.fmu missing: building SpherePlateImpact.fmu "
                          "alone") and "`restitution fmu build` builds every FMU for every platform" in why
    assert head == f"fmu build: 1 FMU into {dist}: SpherePlateImpact.fmu (pythonfmu)"
    words = start.split()
    assert words[2:4] == ["SpherePlateImpact.fmu", "linux64,"] and "pythonfmu" in start and start.endswith(" ...")
    assert end.startswith(start[:-len(" ...")] + ": ") and end.endswith(" s")
    assert total.startswith("fmu build: 1 FMU built in ")
    # no cross compilation: at most this machine's guard, by zig for glibc 2.17 (else gcc)
    assert not any(t.zig_target in "".join(lines) for t in toolchains.PLATFORMS if t.name != "x86_64-linux")


def test_a_dist_the_demo_filled_is_not_the_full_set(demo_dist, monkeypatch):
    """The full plan (``restitution fmu build``'s, and the default FMUs' for the tools that use fmi2/ and
    fmi3/) finds the five other FMUs missing and builds those, not the demo's again."""
    dist, _ = demo_dist
    assert plan.to_build(plan.model_plan(), dist) == []  # the demo reuses its own
    missing = plan.to_build(plan.full_plan(), dist)
    assert [(p.name, why) for p, why in missing] == [(p.name, "missing") for p in plan.full_plan()[1:]
                                                     if not p.native or p.buildable_folders()]
    asked = []
    monkeypatch.setattr(products, "run", lambda todo, out, **kw: asked.append(todo) or [])
    lines = []
    assert products.default_fmu(dist, log=lines.append) == dist / "SpherePlateImpact.fmu"
    assert asked == [[p for p, _ in missing]]
    assert lines[0].startswith(f"fmu build: in {dist}, BouncingBall.fmu, fmi2/SpherePlateImpact.fmu")
    asked.clear()
    products.default_fmu(dist, scope="model")
    assert asked == []


def test_a_native_fmu_lacking_a_platform_is_not_the_full_set(tmp_path):
    """fmi3/BouncingBall.fmu built for x86_64-linux alone (zig, else gcc: cheap) is up to date for a plan of
    that platform; for the full plan it lacks every platform zig builds here (none without zig)."""
    from restitution.fmu.builders.native import build_native_one

    if shutil.which("gcc") is None:
        pytest.skip("gcc not found: no native FMU is built here")
    lines = []
    fmu = build_native_one("BouncingBall", tmp_path, fmi_version="3.0", folders=("x86_64-linux",),
                           progress=Progress(lines.append))
    with zipfile.ZipFile(fmu) as z:
        assert json.loads(z.read("resources/build_info.json"))["platforms"] == ["x86_64-linux"]
    assert plan.stale(plan.Product("BouncingBall", "fmi3", ("x86_64-linux",)), tmp_path) is None
    others = [f for f in plan.Product("BouncingBall", "fmi3").buildable_folders() if f != "x86_64-linux"]
    expected = f"lacks binaries/{', binaries/'.join(others)}" if others else None
    assert plan.stale(plan.Product("BouncingBall", "fmi3"), tmp_path) == expected
    start, end = [line for line in lines if "fmi3/BouncingBall.fmu" in line]  # beside zig's cache line
    label = toolchains.compiler_label("x86_64-linux", toolchains.compiler("x86_64-linux")).split()
    assert start.split() == ["fmu", "build:", "fmi3/BouncingBall.fmu", "x86_64-linux", *label, "..."]
    assert end.split()[:4 + len(label)] == ["fmu", "build:", "fmi3/BouncingBall.fmu", "x86_64-linux", *label[:-1],
                                            label[-1] + ":"]
    assert end.endswith(" s")


def test_staleness_follows_each_fmus_own_sources(demo_dist, tmp_path, monkeypatch):
    """A pythonfmu FMU is stale when the hash of its sources changes, a native one when its own (the C
    files too) does; the time stamps do not count."""
    dist, _ = demo_dist
    copy = tmp_path / "dist"
    shutil.copytree(dist, copy)
    import os
    os.utime(copy / "SpherePlateImpact.fmu", (0, 0))
    assert plan.to_build(plan.model_plan(), copy) == []
    monkeypatch.setattr(plan, "source_hash", lambda model: "another")
    assert [(p.name, why) for p, why in plan.to_build(plan.model_plan(), copy)] == [
        ("SpherePlateImpact.fmu", "built from other sources")]


# --- the lines ---------------------------------------------------------------------------------------------
class _Clock:
    """A clock that advances 1.5 s each time it is read (the lines' seconds, without waiting)."""

    def __init__(self):
        self.now = 0.0

    def __call__(self):
        self.now += 1.5
        return self.now


def test_each_platform_gets_a_start_and_an_end_line_in_order_and_zig_is_told_once(tmp_path, monkeypatch):
    """The lines of a native FMU's platforms, compiled as build_binary does (gcc, then three zig targets):
    start and end per platform, in order, each naming the compiler (zig's with its target); zig's cache line
    once, just before zig's first use, saying which targets' C runtime it lacks."""
    monkeypatch.setenv("ZIG_GLOBAL_CACHE_DIR", str(tmp_path / "zig"))  # an empty cache: cold
    lines = []
    progress = Progress(lines.append, clock=_Clock())
    zig_targets = [toolchains.platform(n) for n in ("x86_64-windows", "x86_64-darwin", "aarch64-darwin")]
    progress.expect_zig(zig_targets)
    step = progress.compile_step("fmi2/M.fmu")
    gcc = toolchains.Compiler("gcc", ("gcc",), ())
    zig = toolchains.Compiler("zig cc", ("zig", "cc"), ())
    for target, cc in [(toolchains.platform("x86_64-linux"), gcc)] + [(t, zig) for t in zig_targets]:
        with step(target, cc):
            pass
    assert len(lines) == 9
    assert [line.split()[3] for line in lines[:2] + lines[3:]] == [
        "x86_64-linux", "x86_64-linux", "x86_64-windows", "x86_64-windows", "x86_64-darwin", "x86_64-darwin",
        "aarch64-darwin", "aarch64-darwin"]
    assert lines[1].endswith("x86_64-linux    gcc: 1.5 s")
    notice = lines[2]
    assert notice.startswith("fmu build: zig's first use fills its cache (") and str(tmp_path / "zig") in notice
    assert "x86_64-windows, x86_64-darwin, aarch64-darwin" in notice and "a few minutes" in notice
    assert lines[3].endswith("zig cc -target x86_64-windows-gnu ... (zig's first build for this target: may take minutes)")
    assert lines[4].endswith("zig cc -target x86_64-windows-gnu: 1.5 s")
    assert lines[6].endswith("zig cc -target x86_64-macos.11.0: 1.5 s")
    assert lines[8].endswith("zig cc -target aarch64-macos.11.0: 1.5 s")
    with pytest.raises(RuntimeError):  # a failed step says so, with its seconds
        with step(zig_targets[0], zig):
            raise RuntimeError("compiler failed")
    assert lines[-1].endswith("zig cc -target x86_64-windows-gnu: failed after 1.5 s")
    assert lines[-2].endswith("x86_64-windows-gnu ...")  # its runtime is no longer new to zig's cache


def _cache_with(root: Path, files: dict[str, bytes]) -> Path:
    for i, (name, data) in enumerate(files.items()):
        folder = root / "o" / f"{i:032x}"
        folder.mkdir(parents=True)
        (folder / name).write_bytes(data)
    return root


def test_zig_cache_warmth_is_read_from_what_it_holds(tmp_path):
    """Windows: mingw-w64's runtime; Linux: the target's libc.so.6 stub (its ELF machine); macOS: compiler_rt
    with a Mach-O object of the architecture. An empty or missing cache is cold for every target."""
    every = [t for t in toolchains.PLATFORMS]
    assert toolchains.zig_cache_cold(every, tmp_path / "none") == every
    elf = lambda machine: b"\x7fELF\x02\x01\x01" + bytes(11) + struct.pack("<H", machine) + bytes(40)  # noqa: E731
    macho = lambda cpu: b"!<arch>\n" + bytes(100) + struct.pack("<Ii", 0xFEEDFACF, cpu) + bytes(20)  # noqa: E731
    cache = _cache_with(tmp_path / "zig", {"libmingw32.lib": b"!<arch>\n", "libc.so.6": elf(183),
                                           "libcompiler_rt.a": macho(0x0100000C)})
    cold = toolchains.zig_cache_cold(every, cache)
    assert [t.name for t in cold] == ["x86_64-linux", "x86_64-darwin"]
    lines = []
    progress = Progress(lines.append)
    progress.expect_zig([toolchains.platform("x86_64-windows"), toolchains.platform("aarch64-darwin")])
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("ZIG_GLOBAL_CACHE_DIR", str(cache))
        progress.zig_notice(toolchains.platform("x86_64-windows"))
        progress.zig_notice(toolchains.platform("aarch64-darwin"))  # said once
    assert lines == [f"fmu build: zig's cache ({cache}) is warm: it holds the C runtime of x86_64-windows, "
                     "aarch64-darwin"]


def test_a_zig_cache_that_cannot_be_read_may_be_cold(monkeypatch):
    """Where zig's cache cannot be read, the line says zig's first use *may* fill it, and each zig step
    may take minutes."""
    monkeypatch.setattr(toolchains, "zig_cache_cold", lambda targets, cache=None: None)
    lines = []
    progress = Progress(lines.append, clock=_Clock())
    windows = toolchains.platform("x86_64-windows")
    with progress.compile_step("fmi3/M.fmu")(windows, toolchains.Compiler("zig cc", ("zig", "cc"), ())):
        pass
    notice, start, _end = lines
    assert notice.startswith("fmu build: zig's first use may fill its cache (") and "Windows C runtime" in notice
    assert start.endswith("(zig's first build for this target: may take minutes)")
