"""Every FMU says which version of the package it is and under which license, and carries the license
texts its contents require: the MIT notice of this project (its terms ask that the notice travel with
every copy) and, in the pythonfmu FMUs, which bundle pythonfmu, pythonfmu's. One version number for
pyproject.toml's metadata, ``restitution.__version__``, every modelDescription.xml and CITATION.cff."""
import re
import zipfile
from importlib import metadata
from pathlib import Path
from xml.etree import ElementTree as ET

import pytest

import restitution

ROOT = Path(__file__).resolve().parents[2]
FMUS = ["SpherePlateImpact.fmu", "BouncingBall.fmu", "native/SpherePlateImpact.fmu", "native/BouncingBall.fmu"]


def test_one_version_number_in_the_metadata_the_package_and_the_citation():
    assert re.fullmatch(r"\d+\.\d+\.\d+", restitution.__version__)
    assert metadata.version("restitution") == restitution.__version__
    citation = (ROOT / "CITATION.cff").read_text(encoding="utf-8")
    assert re.search(rf'^version: "?{re.escape(restitution.__version__)}"?$', citation, re.MULTILINE)
    changelog = (ROOT / "CHANGELOG.md").read_text(encoding="utf-8")
    assert f"## [{restitution.__version__}]" in changelog, "CHANGELOG.md has no section for this version"


def test_the_package_ships_the_repository_license():
    """The package's copy (package data, so an installed package can put it into the FMUs it builds)
    is the repository's LICENSE, byte for byte."""
    from restitution.about import LICENSE_FILE

    assert LICENSE_FILE.read_bytes() == (ROOT / "LICENSE").read_bytes()
    assert metadata.metadata("restitution")["License-Expression"] == "MIT"


@pytest.mark.parametrize("name", FMUS)
def test_every_fmu_declares_version_and_license_and_carries_the_texts(built_fmus, name):
    fmu = built_fmus / name
    if not fmu.is_file():
        pytest.skip(f"{name} not built here (needs gcc)")
    with zipfile.ZipFile(fmu) as z:
        root = ET.fromstring(z.read("modelDescription.xml"))
        files = set(z.namelist())
        entry = z.read("documentation/licenses/license.txt").decode("utf-8")
        third_party = (z.read("documentation/licenses/pythonfmu.txt").decode("utf-8")
                       if "documentation/licenses/pythonfmu.txt" in files else None)
        bundles_pythonfmu = any(f.startswith("resources/pythonfmu/") for f in files)
    assert root.get("version") == restitution.__version__
    assert root.get("license") == "MIT"
    assert "restitution developers" in root.get("copyright")
    assert (ROOT / "LICENSE").read_text(encoding="utf-8") in entry
    if bundles_pythonfmu:
        assert third_party is not None and "MIT License" in third_party and "NTNU" in third_party
        assert "pythonfmu.txt" in entry
    else:
        assert third_party is None and "pythonfmu" not in entry
