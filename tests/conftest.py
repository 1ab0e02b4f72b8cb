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
