"""Every FMU says which version of the package it is and under which license, and carries the license
texts its contents require: the MIT notice of this project (its terms ask that the notice travel with
every copy) and, in the pythonfmu FMUs, which bundle pythonfmu, pythonfmu's. One version number for
pyproject.toml's metadata, ``restitution.__version__``, every modelDescription.xml and CITATION.cff.

And every FMU has a stable identity: its GUID (FMI 3.0: instantiation token) is the model's
``Table.instantiation_token(VERSION)``, the same for the pythonfmu, native FMI 2.0 and FMI 3.0 FMUs of
a model and in every build, different for another interface; two builds of the same sources write
byte-identical modelDescription.xml files (``generationDateAndTime`` from SOURCE_DATE_EPOCH or absent);
the guard and the native fronts instantiate with that token and refuse another, and pythonfmu's own
binary, which the guard forwards to, does not compare GUIDs at all."""
import json
import math
import os
import re
import subprocess
import sys
import uuid
import zipfile
from dataclasses import replace
from importlib import metadata
from pathlib import Path
from xml.etree import ElementTree as ET

import pytest

import restitution
from restitution.about import VERSION
from restitution.fmu.describe.common import generation_date_and_time
from restitution.fmu.models import FOLDERS, table
from restitution.fmu.table import Table

ROOT = Path(__file__).resolve().parents[2]
FMUS = ["SpherePlateImpact.fmu", "BouncingBall.fmu", "fmi2/SpherePlateImpact.fmu", "fmi2/BouncingBall.fmu"]
MODELS = list(FOLDERS)
#: Where each implementation of a model is in a build directory.
PLACES = {"python": "{model}.fmu", "fmi2": "fmi2/{model}.fmu", "fmi3": "fmi3/{model}.fmu"}
ALL_FMUS = [place.format(model=model) for model in MODELS for place in PLACES.values()]
#: 2025-11-25T10:00:00Z, as SOURCE_DATE_EPOCH writes it.
EPOCH, EPOCH_DATE = "1764064800", "2025-11-25T10:00:00Z"
GUID = re.compile(r"\{[0-9a-f]{8}-[0-9a-f]{4}-[0-9a-f]{4}-[0-9a-f]{4}-[0-9a-f]{12}\}")


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


# --- the instantiation token: one function of the interface table and the version ---

def _token(model_table, version=VERSION):
    return model_table.instantiation_token(version)


def _changed(model_table, name, **fields):
    """A copy of ``model_table`` with the fields of row ``name`` replaced."""
    rows = [replace(row, **fields) if row.name == name else row for row in model_table.rows]
    return Table(model_table.model, model_table.description, rows, model_table.constants)


@pytest.mark.parametrize("model", MODELS)
def test_the_token_is_a_guid_fixed_by_the_table_and_the_version(model):
    model_table = table(model)
    token = _token(model_table)
    assert GUID.fullmatch(token), token
    assert uuid.UUID(token).variant == uuid.RFC_4122
    assert _token(model_table) == token
    assert _token(_changed(model_table, model_table.rows[0].name)) == token  # an equal copy: the same token
    assert _token(model_table, "0.0.0") != token


def test_the_two_models_have_different_tokens():
    assert len({_token(table(model)) for model in MODELS}) == len(MODELS)


def _real_input_or_parameter(model_table):
    return next(row for row in model_table.settable if row.type == "Real" and row.choices is None)


@pytest.mark.parametrize("model", MODELS)
def test_the_token_changes_with_anything_hosts_see_of_a_row(model):
    model_table = table(model)
    row = _real_input_or_parameter(model_table)
    low, high, low_open, high_open = row.interval
    output = model_table.outputs[0]
    changed = {
        "description": _changed(model_table, row.name, description=row.description + " (edited)"),
        "range": _changed(model_table, row.name, interval=(low, high / 2 if math.isfinite(high) else 1e3, low_open, False)),
        "start": _changed(model_table, row.name, start=row.start * 1.5 if row.start else 1.0),
        "unit": _changed(model_table, row.name, unit="1" if row.unit != "1" else "m"),
        "variability": _changed(model_table, output.name, variability="discrete"),
        "dependencies": _changed(model_table, output.name, feedthrough=not output.feedthrough),
        "model description": Table(model, model_table.description + ".", model_table.rows, model_table.constants),
        "order": Table(model, model_table.description, model_table.rows[::-1], model_table.constants),
    }
    tokens = {what: _token(changed_table) for what, changed_table in changed.items()}
    assert _token(model_table) not in tokens.values(), tokens
    assert len(set(tokens.values())) == len(tokens), tokens


def test_the_token_does_not_depend_on_the_process():
    """The same in another interpreter, whatever its string hashing (no set or dict order leaks in)."""
    code = ("import json; from restitution.about import VERSION; from restitution.fmu.models import FOLDERS, table; "
            "print(json.dumps({m: table(m).instantiation_token(VERSION) for m in FOLDERS}))")
    for seed in ("1", "2"):
        done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                              env={**os.environ, "PYTHONHASHSEED": seed})
        assert json.loads(done.stdout) == {model: _token(table(model)) for model in MODELS}


# --- generationDateAndTime ---

def test_the_generation_date_is_source_date_epoch_or_none():
    assert generation_date_and_time({}) is None
    assert generation_date_and_time({"SOURCE_DATE_EPOCH": ""}) is None
    assert generation_date_and_time({"SOURCE_DATE_EPOCH": "0"}) == "1970-01-01T00:00:00Z"
    assert generation_date_and_time({"SOURCE_DATE_EPOCH": EPOCH}) == EPOCH_DATE
    for bad in ("-1", "12.5", "yesterday", "1e9", "99999999999999999999"):
        with pytest.raises(ValueError, match="SOURCE_DATE_EPOCH"):
            generation_date_and_time({"SOURCE_DATE_EPOCH": bad})


def test_a_malformed_source_date_epoch_stops_the_build_before_it_starts(tmp_path, monkeypatch):
    from restitution.fmu.builders import BuildError, build_one

    monkeypatch.setenv("SOURCE_DATE_EPOCH", "tomorrow")
    with pytest.raises(BuildError, match="SOURCE_DATE_EPOCH"):
        build_one("BouncingBall", tmp_path / "out")
    assert not (tmp_path / "out" / "BouncingBall.fmu").exists()


# --- the built FMUs ---

def _root(fmu: Path) -> ET.Element:
    with zipfile.ZipFile(fmu) as z:
        return ET.fromstring(z.read("modelDescription.xml"))


def _identity(fmu: Path) -> str:
    root = _root(fmu)
    return root.get("instantiationToken") if root.get("fmiVersion") == "3.0" else root.get("guid")


def _built(directory: Path, place: str, model: str) -> Path:
    fmu = directory / place.format(model=model)
    if not fmu.is_file():
        pytest.skip(f"{fmu.relative_to(directory)} not built here (needs gcc)")
    return fmu


@pytest.mark.parametrize("model", MODELS)
def test_every_implementation_of_a_model_carries_its_token(built_fmus, model):
    token = _token(table(model))
    for place in PLACES.values():
        assert _identity(_built(built_fmus, place, model)) == token, place
    for place in ("fmi2/{model}.fmu", "fmi3/{model}.fmu"):  # the header the native front is compiled with
        with zipfile.ZipFile(_built(built_fmus, place, model)) as z:
            header = z.read("sources/rst_model_info.h").decode("ascii")
        assert f'#define RST_MODEL_GUID "{token}"' in header, place


@pytest.fixture(scope="module")
def builds(built_fmus, tmp_path_factory):
    """Two builds of every FMU without SOURCE_DATE_EPOCH and two with it (``EPOCH``), in separate
    directories and at different times; the session's build is one of them where its environment is."""
    out = {"unset": [], "set": []}
    session = os.environ.get("SOURCE_DATE_EPOCH", "").strip()
    if session in ("", EPOCH):
        out["set" if session else "unset"].append(built_fmus)
    from restitution.fmu.builders import build_all

    with pytest.MonkeyPatch.context() as patch:
        for which, value in (("unset", None), ("set", EPOCH)):
            if value is None:
                patch.delenv("SOURCE_DATE_EPOCH", raising=False)
            else:
                patch.setenv("SOURCE_DATE_EPOCH", value)
            while len(out[which]) < 2:
                directory = tmp_path_factory.mktemp(f"build_{which}_")
                build_all(directory, log=lambda message: None)
                out[which].append(directory)
    return out


def _description_bytes(directory: Path, name: str) -> bytes | None:
    if not (directory / name).is_file():
        return None
    with zipfile.ZipFile(directory / name) as z:
        return z.read("modelDescription.xml")


@pytest.mark.slow
@pytest.mark.parametrize("which", ["unset", "set"])
def test_two_builds_write_byte_identical_model_descriptions(builds, which):
    first, second = builds[which]
    built = 0
    for name in ALL_FMUS:
        one, two = _description_bytes(first, name), _description_bytes(second, name)
        assert (one is None) == (two is None), f"{name} built only once"
        assert one == two, f"{name}: the two builds' modelDescription.xml differ"
        built += one is not None
    assert built >= 2  # the pythonfmu FMUs at least


def _sha256(path: Path) -> str:
    import hashlib

    return hashlib.sha256(path.read_bytes()).hexdigest()


@pytest.mark.slow
@pytest.mark.parametrize("which", ["unset", "set"])
def test_two_builds_write_byte_identical_fmus(builds, which):
    """Every FMU, every platform's binaries in it (Windows DLLs included), built twice at different times
    into different directories: the same SHA-256 (the archives' entry times are SOURCE_DATE_EPOCH's or
    fixed, their order and permissions fixed: restitution.reproducible.write_zip)."""
    first, second = builds[which]
    compared = []
    for name in ALL_FMUS:
        if (first / name).is_file() or (second / name).is_file():
            assert _sha256(first / name) == _sha256(second / name), f"{name}: the two builds differ"
            compared.append(name)
    print(which, "identical:", ", ".join(compared))
    assert len(compared) >= 2  # the pythonfmu FMUs at least


@pytest.mark.slow
def test_the_generation_date_is_source_date_epochs_and_absent_without_it(builds):
    for name in ALL_FMUS:
        unset, dated = _description_bytes(builds["unset"][0], name), _description_bytes(builds["set"][0], name)
        if unset is None:
            continue
        assert b"generationDateAndTime" not in unset, name
        assert ET.fromstring(dated).get("generationDateAndTime") == EPOCH_DATE, name
        # and nothing else differs
        assert dated.replace(f' generationDateAndTime="{EPOCH_DATE}"'.encode(), b"") == unset, name


# --- instantiation: the token is accepted, another refused ---

OTHER_TOKENS = ("{00000000-0000-0000-0000-000000000000}",)

FMI2_CODE = """
token, others = ARGS[0], ARGS[1:]
s = FMU2Slave(guid=token, unzipDirectory=UNZIP, modelIdentifier=MD.coSimulation.modelIdentifier,
              instanceName="identity")
loc = ("file://" + UNZIP + "/resources").encode()
refused = [s.fmi2Instantiate(b"other", 1, other.encode(), loc, byref(CALLBACKS), 0, 0) is None for other in others]
s.instantiate(callbacks=CALLBACKS, loggingOn=True)  # fmpy raises where the FMU returns NULL
s.setupExperiment(startTime=0.0)
s.enterInitializationMode()
s.exitInitializationMode()
s.doStep(0.0, 1e-3)
s.terminate()
s.freeInstance()
report(refused=refused, log=[m for _name, _status, m in LOG])
"""

FMI3_CODE = """
import ctypes
from fmpy.fmi3 import FMU3Slave, fmi3IntermediateUpdateCallback, fmi3LogMessageCallback
token, others = ARGS[0], ARGS[1:]
CB = fmi3LogMessageCallback(log3)
s = FMU3Slave(guid=token, unzipDirectory=UNZIP, modelIdentifier=MD.coSimulation.modelIdentifier, instanceName="identity")
s.instantiate(loggingOn=True, logMessage=lambda env, status, category, message: None)
lib = s.dll
lib.fmi3InstantiateCoSimulation.restype = ctypes.c_void_p
refused = [lib.fmi3InstantiateCoSimulation(b"other", other.encode(), None, False, True, False, False, None,
                                           ctypes.c_size_t(0), None, CB, fmi3IntermediateUpdateCallback()) is None
           for other in others]
s.enterInitializationMode(startTime=0.0)
s.exitInitializationMode()
s.doStep(0.0, 1e-3)
s.terminate()
s.freeInstance()
report(refused=refused, log=[m for _status, m in LOG3])
"""


def _other_tokens(model):
    """Tokens a host could hold by mistake: the other model's, this model's at another version, a zero GUID."""
    return [*(_token(table(m)) for m in MODELS if m != model), _token(table(model), "0.0.0"), *OTHER_TOKENS]


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the built binaries are run on Linux")
@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("implementation", list(PLACES))
def test_instantiation_takes_the_token_and_refuses_another(built_fmus, implementation, model, tmp_path):
    """The guard in front of pythonfmu (python), the native FMI 2.0 front and the FMI 3.0 front each
    instantiate with the token computed from the table (and step), and return NULL, logging why, for
    the other tokens."""
    from fmpy import extract
    from fmi_child import run_child

    fmu = _built(built_fmus, PLACES[implementation], model)
    if implementation == "python" and not _has_guard(fmu):
        pytest.skip("the pythonfmu FMU was built without the guard (no gcc)")
    unzip = extract(str(fmu), str(tmp_path / "unzip"))
    others = _other_tokens(model)
    run = run_child(FMI3_CODE if implementation == "fmi3" else FMI2_CODE, fmu, unzip, _token(table(model)), *others)
    assert run.returncode == 0 and run.report is not None, run.explain()
    assert run.report["refused"] == [True] * len(others)
    text = "\n".join(run.report["log"])
    for other in others:
        assert other in text and "does not match" in text, text


def _has_guard(fmu: Path) -> bool:
    with zipfile.ZipFile(fmu) as z:
        return any(name.endswith("_pythonfmu.so") for name in z.namelist())


RAW_PYTHONFMU_CODE = """
s = FMU2Slave(guid=ARGS[0], unzipDirectory=UNZIP, modelIdentifier=MD.coSimulation.modelIdentifier + "_pythonfmu",
              instanceName="raw")
loc = ("file://" + UNZIP + "/resources").encode()
accepted = []
for guid in ARGS:
    component = s.fmi2Instantiate(b"raw", 1, guid.encode(), loc, byref(CALLBACKS), 0, 0)
    accepted.append(component is not None)
    if component is not None:
        s.fmi2FreeInstance(component)
report(accepted=accepted)
"""


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the guard is the Linux binary")
@pytest.mark.parametrize("model", MODELS)
def test_pythonfmus_binary_does_not_compare_the_guid(built_fmus, model, tmp_path):
    """pythonfmu 0.7.0's binary (kept in the FMU behind the guard as ``<id>_pythonfmu.so``) instantiates
    with any GUID, the one pythonfmu wrote into the file included (it has no GUID check of its own):
    the build may replace that GUID by the token, and the guard, which forwards the token
    to it, is what checks a host's GUID."""
    from fmpy import extract
    from fmi_child import run_child

    fmu = _built(built_fmus, PLACES["python"], model)
    if not _has_guard(fmu):
        pytest.skip("the pythonfmu FMU was built without the guard (no gcc)")
    unzip = extract(str(fmu), str(tmp_path / "unzip"))
    guids = [_token(table(model)), *_other_tokens(model), str(uuid.uuid1()), "not a GUID at all"]
    run = run_child(RAW_PYTHONFMU_CODE, fmu, unzip, *guids)
    assert run.returncode == 0 and run.report is not None, run.explain()
    assert run.report["accepted"] == [True] * len(guids)
