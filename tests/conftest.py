"""Shared fixtures: the FMU is built once per test session from the working tree.

The tests mirror the package: physics/ (the equations and the model), fmu/ (the FMUs: both
implementations, the C front, the guard, the builders), hosts/ (FMI hosts and co-simulation masters),
fit/, sweep/, scene/ (one folder per tool wing), cli/ (the restitution command: options, materials, output
files), docs/ (the pages, the site and the examples they show), benchmarks/ (the benchmarks' quick runs). What several of them share lives here, in tests/:
cases.py (case sets), agree.py (comparing within conditioning), independent.py (the references from
outside the code), fmi_child.py (hostile FMI calls in a child process), toy_fmu.py and toys/, c_host/
(C hosts and drivers), data/."""
import os
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "build_scripts"))
sys.path.insert(0, str(ROOT / "benchmarks"))
sys.path.insert(0, str(ROOT / "tests"))  # the shared helpers, from every folder
# the slave modules (sphere_plate_impact_slave, ...) and what they share import by name, as in the FMUs
MODELS = ROOT / "fmu_src" / "restitution" / "fmu" / "models"
for _folder in (MODELS / "sphere_plate_impact", MODELS / "bouncing_ball", MODELS):
    sys.path.insert(0, str(_folder))


@pytest.fixture(scope="session")
def release(tmp_path_factory):
    """(sdist, wheel) of ``python -m build`` (the sdist, then the wheel from it, carrying every FMU built),
    made once per session (by one pytest-xdist worker, the others waiting for it) with this environment's
    build tools (--no-isolation: nothing downloaded). With
    RESTITUTION_RELEASE_DIR=DIR: those of DIR where it holds both, else built into DIR (.ci/run keeps the
    release for its smoke test so)."""
    import fcntl
    import subprocess

    given = os.environ.get("RESTITUTION_RELEASE_DIR", "").strip()
    if given:
        dist = Path(given)
    elif os.environ.get("PYTEST_XDIST_WORKER"):  # the folder every worker of this session shares
        dist = tmp_path_factory.getbasetemp().parent / "release"
    else:
        dist = tmp_path_factory.mktemp("release")
    dist.mkdir(parents=True, exist_ok=True)
    patterns = ("restitution-*.tar.gz", "restitution-*-py3-none-any.whl")
    with open(dist / ".lock", "w") as lock:  # pytest-xdist workers (test_wheel, test_package) build it once
        fcntl.flock(lock, fcntl.LOCK_EX)
        found = [sorted(dist.glob(pattern)) for pattern in patterns]
        if not all(len(f) == 1 for f in found):
            proc = subprocess.run([sys.executable, "-m", "build", "--no-isolation", "--outdir", str(dist), str(ROOT)],
                                  capture_output=True, text=True, cwd=dist)
            assert proc.returncode == 0, proc.stderr[-3000:]
            found = [sorted(dist.glob(pattern)) for pattern in patterns]
    (sdist,), (wheel,) = found
    return sdist, wheel


@pytest.fixture(scope="session")
def built_fmus(tmp_path_factory) -> Path:
    """Every FMU of the project built from the current sources (and validated) into one temp dir:
    SpherePlateImpact.fmu and BouncingBall.fmu (pythonfmu, behind the C guard), and their native
    twins, FMI 2.0 in fmi2/ and FMI 3.0 in fmi3/, where a C compiler is available."""
    from restitution.fmu.builders import build_all

    out = tmp_path_factory.mktemp("fmu")
    build_all(out)
    return out


@pytest.fixture(scope="session")
def impact_fmu(built_fmus) -> Path:
    """The pythonfmu SpherePlateImpact.fmu."""
    return built_fmus / "SpherePlateImpact.fmu"


@pytest.fixture(scope="session")
def ball_fmu(built_fmus) -> Path:
    """The pythonfmu BouncingBall.fmu."""
    return built_fmus / "BouncingBall.fmu"


@pytest.fixture(scope="session")
def host_fmi3(tmp_path_factory):
    """The native FMI 3.0 BouncingBall.fmu and SpherePlateImpact.fmu of the current sources, built for this
    machine's platform only (seconds; the session's built_fmus builds every platform)."""
    from fmpy import platform_tuple

    from restitution.fmu.builders.toolchains import NativeBuildSkipped
    from restitution.fmu.builders.native import build_native_one

    out = tmp_path_factory.mktemp("fmi3_host")
    try:
        return {model: build_native_one(model, out, fmi_version="3.0", folders=(platform_tuple,), log=lambda _l: None)
                for model in ("BouncingBall", "SpherePlateImpact")}
    except NativeBuildSkipped as exc:
        pytest.skip(f"native FMI 3.0 FMUs not built here: {exc}")


#: The folder of each native FMU of the build: FMI 2.0 and FMI 3.0.
NATIVE_FOLDERS = {"fmi2": "FMI 2.0", "fmi3": "FMI 3.0"}


def _built_native(built_fmus, folder, model):
    path = built_fmus / folder / f"{model}.fmu"
    if not path.is_file():
        pytest.skip(f"{NATIVE_FOLDERS[folder]} {model}.fmu not built here (needs gcc)")
    return path


@pytest.fixture(scope="session")
def native_impact_fmu(built_fmus) -> Path:
    """The native SpherePlateImpact.fmu (C front and C physics, no Python)."""
    return _built_native(built_fmus, "fmi2", "SpherePlateImpact")


@pytest.fixture(scope="session")
def native_ball_fmu(built_fmus) -> Path:
    """The native BouncingBall.fmu."""
    return _built_native(built_fmus, "fmi2", "BouncingBall")


@pytest.fixture(scope="session")
def fmi3_impact_fmu(built_fmus) -> Path:
    """The native FMI 3.0 SpherePlateImpact.fmu (the same C core and physics as the native FMI 2.0 one)."""
    return _built_native(built_fmus, "fmi3", "SpherePlateImpact")


@pytest.fixture(scope="session")
def fmi3_ball_fmu(built_fmus) -> Path:
    """The native FMI 3.0 BouncingBall.fmu."""
    return _built_native(built_fmus, "fmi3", "BouncingBall")


@pytest.fixture(scope="session")
def host_native_fmus(tmp_path_factory) -> Path:
    """A folder with the native FMUs for this machine's platform only (gcc, seconds: no zig): fmi2/ (linux64)
    and fmi3/ (x86_64-linux) BouncingBall.fmu and SpherePlateImpact.fmu. Skips where they cannot be built."""
    from restitution.fmu.builders.toolchains import NativeBuildSkipped
    from restitution.fmu.builders.native import build_native_one

    out = tmp_path_factory.mktemp("host_native")
    try:
        for version, folder in (("2.0", "linux64"), ("3.0", "x86_64-linux")):
            for model in ("BouncingBall", "SpherePlateImpact"):
                build_native_one(model, out, fmi_version=version, folders=(folder,))
    except NativeBuildSkipped as exc:
        pytest.skip(f"native FMUs not built here: {exc}")
    return out


def _implementation(built_fmus, model, which) -> Path:
    """``model``.fmu as ``which``: "python" (pythonfmu), "fmi2" (FMI 2.0 C) or "fmi3" (FMI 3.0 C)."""
    return built_fmus / f"{model}.fmu" if which == "python" else _built_native(built_fmus, which, model)


#: The two FMI 2.0 implementations of each FMU: tests that hold for both take these fixtures
#: (any_impact_fmu, any_ball_fmu), the tests that make raw fmi2 calls among them.
IMPLEMENTATIONS = ("python", "fmi2")
#: Every FMU an fmpy host runs through restitution.cosim.FmuInstance: the two FMI 2.0 implementations
#: and the FMI 3.0 one (any_version_impact_fmu, any_version_ball_fmu).
VERSIONS = ("python", "fmi2", "fmi3")


@pytest.fixture(scope="session", params=IMPLEMENTATIONS)
def any_impact_fmu(request, built_fmus) -> Path:
    """SpherePlateImpact.fmu, once as the pythonfmu FMU and once as the native one (FMI 2.0)."""
    return _implementation(built_fmus, "SpherePlateImpact", request.param)


@pytest.fixture(scope="session", params=IMPLEMENTATIONS)
def any_ball_fmu(request, built_fmus) -> Path:
    """BouncingBall.fmu, once as the pythonfmu FMU and once as the native one (FMI 2.0)."""
    return _implementation(built_fmus, "BouncingBall", request.param)


@pytest.fixture(scope="session", params=VERSIONS)
def any_version_impact_fmu(request, built_fmus) -> Path:
    """SpherePlateImpact.fmu as the pythonfmu FMU, the native FMI 2.0 one and the native FMI 3.0 one."""
    return _implementation(built_fmus, "SpherePlateImpact", request.param)


@pytest.fixture(scope="session", params=VERSIONS)
def any_version_ball_fmu(request, built_fmus) -> Path:
    """BouncingBall.fmu as the pythonfmu FMU, the native FMI 2.0 one and the native FMI 3.0 one."""
    return _implementation(built_fmus, "BouncingBall", request.param)


@pytest.fixture(scope="session", params=VERSIONS)
def any_version_fmu_dir(request, built_fmus) -> Path:
    """The folder with both FMUs: the pythonfmu ones, the native FMI 2.0 ones (fmi2/), the FMI 3.0
    ones (fmi3/)."""
    return _implementation(built_fmus, "SpherePlateImpact", request.param).parent


#: Test files whose results depend on floating-point kernels: .ci/run runs them (``-m numerics``)
#: a second time with numpy's SIMD dispatch switched off (build_scripts/cpu_dispatch.py).
NUMERICAL_TEST_FILES = {"test_physics.py", "test_hard_cases.py", "test_fast_path.py", "test_zener_exact.py",
                        "test_conditioning.py", "test_references.py", "test_sweep_agreement.py",
                        "test_paper_references.py", "test_paper_tables.py"}


def pytest_configure(config):
    config.addinivalue_line("markers", "numerics: floating-point results (rerun by .ci/run on numpy's baseline kernels)")


def pytest_collection_modifyitems(config, items):
    for item in items:
        if item.path.name in NUMERICAL_TEST_FILES:
            item.add_marker(pytest.mark.numerics)
