"""The package as a user installs it: locked versions, FMUs built from the installed package
(outside the checkout), builds that cannot leave a broken FMU, clear errors."""
from __future__ import annotations

import os
import re
import stat
import subprocess
import sys
import zipfile
from importlib import metadata
from pathlib import Path

import pytest

import restitution as r
from restitution.fmu.builders import products as fmu_build, sources

ROOT = Path(__file__).resolve().parents[2]
LOCK = ROOT / "requirements" / "dev.lock"


def _locked_versions() -> dict[str, str]:
    pins = re.findall(r"^([A-Za-z0-9_.\-]+)==([^\s;\\]+)", LOCK.read_text(), flags=re.MULTILINE)
    return {name.lower().replace("_", "-"): version for name, version in pins}


def test_installed_versions_equal_the_lock():
    locked = _locked_versions()
    assert {"numpy", "scipy", "pythonfmu", "fmpy", "pytest", "hypothesis"} <= set(locked)
    wrong = {name: (version, metadata.version(name)) for name, version in locked.items()
             if metadata.version(name) != version}
    assert not wrong, f"installed versions differ from requirements/dev.lock (rerun quickstart.sh): {wrong}"


def test_lock_holds_hashes_and_no_machine_specific_locations():
    text = LOCK.read_text()
    assert "--hash=sha256:" in text
    for marker in ("file:", "/opt/", "/work/", "/home/", "--index-url", "--extra-index-url", "--find-links"):
        assert marker not in text, marker
    for block in re.split(r"\n(?=[A-Za-z0-9])", text.split("\n", 2)[2]):
        if "==" in block:
            assert "--hash=sha256:" in block, block.splitlines()[0]


def test_unknown_material_lists_the_names_and_suggests_the_closest():
    with pytest.raises(KeyError) as info:
        r.MATERIALS["aluminum"]
    message = info.value.args[0]
    assert "did you mean" in message and "'al_6061'" in message.split("known:")[0]
    assert all(name in message.split("known:")[1] for name in r.MATERIALS)


# --- builds ---------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def built(tmp_path_factory):
    out = tmp_path_factory.mktemp("dist")
    return out, fmu_build.build_one("SpherePlateImpact", out, guard=False)


def test_built_fmu_is_readable_by_others_and_records_its_sources(built):
    _out, fmu = built
    mode = stat.S_IMODE(fmu.stat().st_mode)
    umask = os.umask(0o022)
    os.umask(umask)
    assert mode == 0o666 & ~umask
    assert sources.recorded_source_hash(fmu) == sources.source_hash("SpherePlateImpact")
    with zipfile.ZipFile(fmu) as z:
        assert "resources/restitution/model.py" in z.namelist()
        assert not any(n.startswith(("resources/restitution/scene/", "resources/restitution/sweep/",
                                     "resources/restitution/cosim/")) for n in z.namelist())
        # of the FMU tooling, only the interface tables (pure data the slaves read), never the build
        bundled = sorted(n for n in z.namelist() if n.startswith("resources/restitution/fmu/"))
        assert bundled and all(re.fullmatch(r"resources/restitution/fmu/(__init__|table|models/__init__|"
                                            r"models/\w+/(__init__|variables))\.py", n) for n in bundled), bundled


def test_a_failed_build_leaves_the_previous_fmu_untouched(built, monkeypatch):
    out, fmu = built
    before = fmu.read_bytes()
    monkeypatch.setattr("fmpy.validation.validate_fmu", lambda path: ["injected validation problem"])
    with pytest.raises(fmu_build.BuildError, match="injected validation problem"):
        fmu_build.build_one("SpherePlateImpact", out, guard=False)
    assert fmu.read_bytes() == before
    assert sorted(p.name for p in out.iterdir()) == ["SpherePlateImpact.fmu"]  # no temporary left


def test_staleness_is_decided_by_the_recorded_source_hash(built, monkeypatch):
    from restitution.fmu.builders import plan

    out, fmu = built
    builds = []
    monkeypatch.setattr(fmu_build, "run", lambda todo, out_dir, **k: builds.append([p.name for p in todo]))
    assert fmu_build.default_fmu(out, scope="model") == fmu and builds == []  # fresh: even if older than a source
    os.utime(fmu, (0, 0))
    assert fmu_build.default_fmu(out, scope="model") == fmu and builds == []
    monkeypatch.setattr(plan, "source_hash", lambda model: "0" * 64)
    fmu_build.default_fmu(out, scope="model")
    assert builds == [["SpherePlateImpact.fmu"]]  # sources changed: rebuilt, that one alone


def test_unwritable_output_is_one_line_exit_2(tmp_path):
    target = tmp_path / "a_file"
    target.write_text("x")
    proc = subprocess.run([sys.executable, "-m", "restitution.fmu", "build", "--out", str(target)],
                          capture_output=True, text=True)
    assert proc.returncode == 2 and "Traceback" not in proc.stderr
    assert proc.stderr.strip().count("\n") == 0 and "not a directory" in proc.stderr


def test_no_fmu_and_none_buildable_is_one_line_naming_fmu_path(tmp_path):
    """Without pythonfmu the scene runner cannot build an FMU: one line that names --fmu PATH."""
    blocker = tmp_path / "blocker"
    blocker.mkdir()
    (blocker / "pythonfmu.py").write_text("raise ImportError('pythonfmu hidden by the test')\n")
    scene = ROOT / "examples" / "scenes" / "steel_ball_thin_aluminium.toml"
    env = dict(os.environ, PYTHONPATH=str(blocker), XDG_CACHE_HOME=str(tmp_path / "cache"))
    code = ("import sys, restitution.fmu.builders.products as b; b._checkout_dist = lambda: None; "
            "from restitution.scene.__main__ import main; sys.exit(main(sys.argv[1:]))")
    proc = subprocess.run([sys.executable, "-c", code, "run", str(scene), "--out", str(tmp_path / "o")],
                          capture_output=True, text=True, env=env)
    assert proc.returncode == 2, proc.stderr
    assert "Traceback" not in proc.stderr and "--fmu PATH" in proc.stderr, proc.stderr


@pytest.mark.slow
def test_the_release_installs_builds_the_fmus_and_runs_a_scene_outside_the_checkout(release, tmp_path):
    """What an index would get (the ``release`` fixture: ``python -m build`` makes the sdist and, from it, the
    wheel, so the sdist holds everything the wheel needs; twine check: tests/fmu/test_wheel.py): the wheel
    installs into a fresh venv whose dependencies come from the test environment; then, from another
    directory: restitution-fmu build (asked: it builds, whatever the wheel carries), and a scene through it."""
    sdist, wheel = release
    assert sdist.name == f"restitution-{r.__version__}.tar.gz"
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
    py = venv / "bin" / "python"
    site = subprocess.run([str(py), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                          capture_output=True, text=True, check=True).stdout.strip()
    deps = next(p for p in map(Path, sys.path) if (p / "numpy").is_dir() and p.name == "site-packages")
    # the test environment's packages as plain path entries: its .pth files (the editable install of
    # this checkout) are not processed, so only the copy installed below can provide restitution
    (Path(site) / "test_env_deps.pth").write_text(str(deps) + "\n")
    subprocess.run([str(py), "-m", "pip", "install", "--quiet", "--no-deps", str(wheel)],
                   check=True, capture_output=True)
    work = tmp_path / "elsewhere"
    work.mkdir()
    where = subprocess.run([str(py), "-c", "import restitution; print(restitution.__file__)"], cwd=work,
                           capture_output=True, text=True, check=True).stdout
    assert where.startswith(site), where
    installed = subprocess.run([str(py), "-c", "from importlib import metadata; m = metadata.metadata('restitution'); "
                                "print(m['Version'], m['License-Expression']); print(m['Summary'])"],
                               cwd=work, capture_output=True, text=True, check=True).stdout.splitlines()
    assert installed[0].split() == [r.__version__, "MIT"]
    assert "FMI 2.0 and 3.0" in installed[1] and "model exchange" in installed[1]  # what the FMUs now offer
    out = work / "fmus"
    proc = subprocess.run([str(venv / "bin" / "restitution-fmu"), "build", "--out", str(out)], cwd=work,
                          capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    assert (out / "SpherePlateImpact.fmu").is_file() and (out / "BouncingBall.fmu").is_file()
    with zipfile.ZipFile(out / "SpherePlateImpact.fmu") as z:  # the license travels with an installed package
        assert "Permission is hereby granted" in z.read("documentation/licenses/license.txt").decode()
    scene = ROOT / "examples" / "scenes" / "steel_ball_thin_aluminium.toml"
    proc = subprocess.run([str(venv / "bin" / "restitution-scene"), "run", str(scene), "--fmu",
                           str(out / "SpherePlateImpact.fmu"), "--out", str(work / "scene"), "--no-plot",
                           "--no-progress"], cwd=work, capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    assert any(p.suffix == ".csv" for p in (work / "scene").iterdir())


def test_the_build_refuses_a_slave_that_registers_unlike_the_table(built):
    """pythonfmu's binary numbers variables in the order the slave registers them, and the build replaces
    pythonfmu's modelDescription with the table's: a slave registering two variables the other way round
    (as pythonfmu would then describe them) stops the build, naming the first difference."""
    from restitution.fmu.builders import python_fmu

    _out, fmu = built
    with zipfile.ZipFile(fmu) as z:
        xml = z.read("modelDescription.xml").decode("utf-8")
    python_fmu._check_registration("SpherePlateImpact", xml)  # the table's own order passes
    first, second = 'name="sphere.E" valueReference="1"', 'name="sphere.nu" valueReference="2"'
    assert first in xml and second in xml
    swapped = xml.replace(first, "\0").replace(second, 'name="sphere.E" valueReference="2"').replace(
        "\0", 'name="sphere.nu" valueReference="1"')
    with pytest.raises(fmu_build.BuildError, match=r"first difference at position 1.*sphere\.nu"):
        python_fmu._check_registration("SpherePlateImpact", swapped)


def test_the_bundled_package_imports_neither_the_host_side_readers_nor_pint():
    """The pythonfmu FMUs bundle the package's top-level modules but the host-side readers
    (HOST_ONLY_MODULES). A copy loaded from resources/ is imported whole, so no bundled module may import a
    reader at its top; and none may import pint anywhere, lazily included, or the guard's loader requires
    it in a plain C host (it reads every import of the bundled files)."""
    import ast

    from restitution.fmu.builders.sources import HOST_ONLY_MODULES, PACKAGE

    readers = {name[:-3] for name in HOST_ONLY_MODULES}
    bundled = sorted(p for p in PACKAGE.glob("*.py") if p.name not in HOST_ONLY_MODULES)
    assert len(bundled) > 10 and readers <= {p.stem for p in PACKAGE.glob("*.py")}
    for path in bundled:
        tree = ast.parse(path.read_text(encoding="utf-8"))
        top = {n.module.split(".")[0] for n in tree.body if isinstance(n, ast.ImportFrom) and n.level == 1 and n.module}
        assert not top & readers, (path.name, top & readers)
        everywhere = {a.name.split(".")[0] for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names}
        everywhere |= {n.module.split(".")[0] for n in ast.walk(tree)
                       if isinstance(n, ast.ImportFrom) and n.level == 0 and n.module}
        assert "pint" not in everywhere, path.name
