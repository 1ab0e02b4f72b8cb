"""The release as a user gets it: ``python -m build`` makes the sdist and, from it, the wheel, which carries
every FMU built (build_scripts/wheel_backend.py, zig from PyPI for every platform); both pass ``twine check``.
The wheel installs into a fresh venv and, with every C compiler hidden (PATH: the venv's bin/ and a folder
of links to the few tools the test needs; no ziglang importable), gives the installed FMUs' paths, copies
them out, runs a scene through the installed FMU without building anything, and fmpy simulates each FMU:
SpherePlateImpact's e against restitution.impact (the package's Python physics), BouncingBall's height in
free fall against h0 - g t^2 / 2.

Slow (the wheel builds every FMU for every platform: minutes): built once per session (the ``release``
fixture of tests/conftest.py; RESTITUTION_RELEASE_DIR=DIR keeps it in DIR, or reuses what DIR holds);
.ci/run smoke-tests that release again in a venv with none of the test environment
(build_scripts/release_check.sh)."""
from __future__ import annotations

import json
import os
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

import restitution as r

ROOT = Path(__file__).resolve().parents[2]
MODELS = ("SpherePlateImpact", "BouncingBall")
#: Every FMU the wheel carries, as installed: (path below installed_fmus/, --fmi, --implementation).
FMUS = [(f"{m}.fmu", "2", "pythonfmu") for m in MODELS] + [
    (f"fmi{v}/{m}.fmu", v, "native") for v in ("2", "3") for m in MODELS]
#: binaries/ folders each FMU must carry (the FMI standards' names for the five platforms).
FOLDERS = {"2": {"linux64", "win64", "darwin64"},
           "3": {"x86_64-linux", "aarch64-linux", "x86_64-windows", "x86_64-darwin", "aarch64-darwin"}}
COMPILERS = ("gcc", "cc", "clang", "x86_64-w64-mingw32-gcc", "zig", "tcc")


@pytest.mark.slow
def test_both_artefacts_pass_twine_check(release):
    proc = subprocess.run([sys.executable, "-m", "twine", "check", "--strict", *map(str, release)],
                          capture_output=True, text=True)
    assert proc.returncode == 0 and proc.stdout.count("PASSED") == 2, proc.stdout + proc.stderr


@pytest.mark.slow
def test_the_wheel_carries_every_fmu_for_every_platform_and_the_sdist_none(release):
    sdist, wheel = release
    with zipfile.ZipFile(wheel) as z:
        names = z.namelist()
        for place, fmi, implementation in FMUS:
            member = f"restitution/fmu/installed_fmus/{place}"
            assert member in names, member
            with zipfile.ZipFile(z.open(member)) as fmu:
                inside = fmu.namelist()
                folders = {n.split("/")[1] for n in inside if n.startswith("binaries/") and n.count("/") >= 2}
                if implementation == "native":
                    assert folders == FOLDERS[fmi], (place, folders)
                    assert any(n.startswith("sources/") for n in inside), place
                else:
                    assert {"linux64", "win64"} <= folders, (place, folders)  # pythonfmu's platforms
                assert "documentation/licenses/license.txt" in inside, place
                info = json.loads(fmu.read("resources/build_info.json"))
                if implementation == "native":  # zig from PyPI built every platform: no gcc, no mingw
                    assert set(info["compilers"].values()) == {"zig cc"}, info
    import tarfile
    with tarfile.open(sdist) as t:
        members = t.getnames()
    assert not any("installed_fmus" in m for m in members)
    assert any(m.endswith("build_scripts/wheel_backend.py") for m in members)


def _bare_environment(tmp_path: Path, wheel: Path) -> tuple[Path, dict]:
    """A fresh venv with the wheel installed, the test environment's packages but ziglang (and this
    checkout) importable, and a PATH of the venv's bin/ and links to a few tools, no compiler."""
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
    py = venv / "bin" / "python"
    site = Path(subprocess.run([str(py), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                               capture_output=True, text=True, check=True).stdout.strip())
    deps_site = next(p for p in map(Path, sys.path) if (p / "numpy").is_dir() and p.name == "site-packages")
    deps = tmp_path / "deps"  # every package of the test environment but zig and restitution itself
    deps.mkdir()
    for entry in deps_site.iterdir():
        lower = entry.name.lower()
        if not (lower.startswith(("ziglang", "restitution", "__editable__", "_restitution")) or lower.endswith(".pth")):
            (deps / entry.name).symlink_to(entry)
    (site / "test_env_deps.pth").write_text(str(deps) + "\n")
    subprocess.run([str(py), "-m", "pip", "install", "--quiet", "--no-deps", "--no-index", str(wheel)],
                   check=True, capture_output=True)
    tools = tmp_path / "tools"
    tools.mkdir()
    for tool in ("sh", "env", "uname", "ldconfig"):  # what Python's subprocess/platform may call
        found = next((Path(d) / tool for d in ("/usr/bin", "/bin", "/usr/sbin", "/sbin") if (Path(d) / tool).exists()),
                     None)
        if found is not None:
            (tools / tool).symlink_to(found)
    env = {"PATH": f"{venv / 'bin'}:{tools}", "HOME": str(tmp_path / "home"), "LANG": "C.UTF-8",
           "XDG_CACHE_HOME": str(tmp_path / "cache"), "TMPDIR": str(tmp_path)}
    return venv, env


@pytest.fixture(scope="module")
def bare(release, tmp_path_factory):
    tmp = tmp_path_factory.mktemp("bare")
    venv, env = _bare_environment(tmp, release[1])
    work = tmp / "elsewhere"
    work.mkdir()

    def run(*args, **kw):
        return subprocess.run(list(args), cwd=work, env=env, capture_output=True, text=True, **kw)

    return venv, env, work, run


@pytest.mark.slow
def test_no_compiler_is_reachable_in_the_bare_environment(bare):
    venv, env, work, run = bare
    proc = run(str(venv / "bin" / "python"), "-c",
               "import importlib.util, shutil, sys; print([c for c in sys.argv[1:] if shutil.which(c)], "
               "importlib.util.find_spec('ziglang'))", *COMPILERS)
    assert proc.stdout.split() == ["[]", "None"], proc.stdout + proc.stderr


@pytest.mark.slow
def test_path_names_each_installed_fmu_and_copy_copies_them(bare, tmp_path):
    venv, env, work, run = bare
    restitution = str(venv / "bin" / "restitution")
    for place, fmi, implementation in FMUS:
        model = Path(place).stem
        proc = run(restitution, "fmu", "path", model, "--fmi", fmi, "--implementation", implementation)
        assert proc.returncode == 0, proc.stderr
        printed = Path(proc.stdout.strip())
        assert printed.is_file() and printed.as_posix().endswith(f"restitution/fmu/installed_fmus/{place}")
        assert str(venv) in str(printed)  # the wheel's copy, not this checkout's
        code = f"import restitution.fmu as f; print(f.path({model!r}, fmi={fmi!r}, implementation={implementation!r}))"
        assert run(str(venv / "bin" / "python"), "-c", code).stdout.strip() == str(printed)
    proc = run(restitution, "fmu", "path", "SpherePlateImpact", "--fmi", "3", "--implementation", "pythonfmu")
    assert proc.returncode == 2 and proc.stderr.count("\n") == 1 and "Traceback" not in proc.stderr
    out = tmp_path / "copied"
    proc = run(restitution, "fmu", "copy", "--out", str(out))
    assert proc.returncode == 0, proc.stderr
    assert {p.relative_to(out).as_posix() for p in out.rglob("*.fmu")} == {place for place, _, _ in FMUS}
    installed = Path(run(restitution, "fmu", "path", "BouncingBall").stdout.strip())
    assert (out / "BouncingBall.fmu").read_bytes() == installed.read_bytes()
    proc = run(restitution, "fmu", "copy", "--out", str(installed.parent))  # onto the installed files
    assert proc.returncode == 2 and "Traceback" not in proc.stderr and proc.stderr.count("\n") == 1, proc.stderr


#: SpherePlateImpact's case: Green (2022)'s checkpoint, a 1/4 in S2 tool steel ball on a 6.35 mm 6061 plate.
SPHERE, PLATE, SPEED = ("s2_tool_steel", 6.35e-3), ("al_6061", 6.35e-3), 2.3  # [m], [m], [m/s]

SIMULATE = r"""
import json, sys
import fmpy
import restitution as r
from restitution.cosim import impact_fmu_parameters
from restitution.fmu import path
(sphere, d), (plate, t), speed = json.loads(sys.argv[2])
parameters = impact_fmu_parameters(r.Sphere(r.MATERIALS[sphere], d=d), r.Plate(r.MATERIALS[plate], t=t))
out = {}
for place, fmi, implementation in json.loads(sys.argv[1]):
    model = place.rsplit("/", 1)[-1][:-4]
    fmu = str(path(model, fmi, implementation))
    if model == "SpherePlateImpact":
        res = fmpy.simulate_fmu(fmu, stop_time=1e-3, output_interval=1e-3,
                                start_values={**parameters, "v_approach": speed}, output=["e"])
        out[place] = {"e": float(res["e"][-1])}
    else:
        res = fmpy.simulate_fmu(fmu, stop_time=0.2, output_interval=0.01, output=["h"])
        md = fmpy.read_model_description(fmu)
        start = {v.name: float(v.start) for v in md.modelVariables if v.name in ("h0", "g")}
        out[place] = {"h": float(res["h"][-1]), "t": float(res["time"][-1]), **start}
print(json.dumps(out))
"""


@pytest.mark.slow
def test_fmpy_simulates_every_installed_fmu(bare):
    from restitution.agreement import tolerances

    venv, env, work, run = bare
    proc = run(str(venv / "bin" / "python"), "-c", SIMULATE, json.dumps(FMUS), json.dumps([SPHERE, PLATE, SPEED]))
    assert proc.returncode == 0, proc.stderr[-3000:]
    results = json.loads(proc.stdout.strip().splitlines()[-1])
    assert set(results) == {place for place, _, _ in FMUS}
    sphere, plate = r.Sphere(r.MATERIALS[SPHERE[0]], d=SPHERE[1]), r.Plate(r.MATERIALS[PLATE[0]], t=PLATE[1])
    expected = r.impact_between(sphere, plate, v=SPEED).e
    # the C physics (native) or the Python one (pythonfmu) against this checkout's package: the per-case
    # tolerance restitution.agreement derives from the case's conditioning
    tol = float(tolerances(SPEED, {**sphere.params(), **plate.params()})[0]["e"])
    for place, values in results.items():
        if place.endswith("SpherePlateImpact.fmu"):
            assert abs(values["e"] - expected) <= tol, (place, values, expected, tol)
        else:
            # free fall before the first impact (from the default h0 = 0.3 m the ball lands after 0.25 s):
            # h0 - g t^2 / 2; 1e-9 m covers the rounding of a flight the FMUs solve in closed form
            free_fall = values["h0"] - values["g"] * values["t"] ** 2 / 2
            assert abs(values["h"] - free_fall) <= 1e-9, (place, values)


@pytest.mark.slow
def test_a_scene_runs_through_the_installed_fmu_without_building(bare, tmp_path):
    venv, env, work, run = bare
    scene = ROOT / "examples" / "scenes" / "steel_ball_thin_aluminium.toml"
    proc = run(str(venv / "bin" / "restitution-scene"), "run", str(scene), "--out", str(tmp_path / "scene"),
               "--no-plot", "--no-progress")
    assert proc.returncode == 0, proc.stderr
    assert "building" not in proc.stderr and "fmu build" not in proc.stderr, proc.stderr
    assert not (Path(env["XDG_CACHE_HOME"]) / "restitution").exists()  # nothing built into the cache
    assert any(p.suffix == ".csv" for p in (tmp_path / "scene").iterdir())


# --- without a wheel: the checkout has no installed FMUs; default_fmu prefers installed ones that fit -----
def test_a_checkout_has_no_installed_fmus_and_says_how_to_build_them():
    proc = subprocess.run([sys.executable, "-m", "restitution.fmu", "path", "SpherePlateImpact"],
                          capture_output=True, text=True)
    assert proc.returncode == 2 and proc.stderr.count("\n") == 1 and "Traceback" not in proc.stderr
    assert "restitution fmu build" in proc.stderr, proc.stderr


def test_default_fmu_uses_the_installed_fmus_and_builds_elsewhere_when_they_do_not_fit(built_fmus, tmp_path,
                                                                                     monkeypatch):
    import shutil

    from restitution.fmu.builders import plan, products

    installed = tmp_path / "installed_fmus"
    shutil.copytree(built_fmus, installed)
    builds = []
    monkeypatch.setattr(products, "installed_dir", lambda: installed)
    monkeypatch.setattr(products, "default_fmu_dir", lambda: tmp_path / "cache")
    monkeypatch.setattr(products, "run", lambda todo, out, **k: builds.append((out, [p.name for p in todo])))
    assert products.default_fmu() == installed / "SpherePlateImpact.fmu" and builds == []
    assert products.default_fmu(model="BouncingBall", scope="model") == installed / "BouncingBall.fmu"
    assert builds == []
    assert products.default_fmu(rebuild=True, scope="model") == tmp_path / "cache" / "SpherePlateImpact.fmu"
    assert builds == [(tmp_path / "cache", ["SpherePlateImpact.fmu"])]  # asked: built, never into the package
    builds.clear()
    monkeypatch.setattr(plan, "source_hash", lambda model: "0" * 64)  # the installed FMUs no longer fit
    assert products.default_fmu(scope="model") == tmp_path / "cache" / "SpherePlateImpact.fmu"
    assert builds == [(tmp_path / "cache", ["SpherePlateImpact.fmu"])]
