"""Shared fixtures: the FMU is built once per test session from the working tree."""
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "build_scripts"))
# the slave modules (sphere_plate_impact_slave, ...) import by name, as the FMUs do
sys.path.insert(0, str(ROOT / "fmu_src" / "restitution" / "fmu" / "slaves"))


@pytest.fixture(scope="session")
def impact_fmu(tmp_path_factory) -> Path:
    """SpherePlateImpact.fmu built from the current sources (and validated) into a temp dir."""
    from restitution.fmu.build import build_one

    return build_one("SpherePlateImpact", tmp_path_factory.mktemp("fmu"))


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
