"""What hosts see of the FMUs' interface does not change by accident: each built modelDescription.xml
(both models; the pythonfmu FMU, the native FMI 2.0 and the native FMI 3.0 FMU) equals its checked-in
copy in tests/data/model_descriptions/, byte for byte, the GUID or instantiation token included (a
host passes it back at instantiation: it is fixed per model interface and version,
``Table.instantiation_token``). The copies are what a build without SOURCE_DATE_EPOCH writes (no
``generationDateAndTime``); where the tests run with it set, the one attribute it adds is checked and
taken out before the comparison.

A deliberate change of the interface (or of the version) updates the copies in the same commit:

    RESTITUTION_UPDATE_SNAPSHOTS=1 bash build_scripts/quickstart.sh test tests/fmu/test_interface_snapshot.py

and the diff of the copies is what a reviewer reads to see what hosts will see."""
import difflib
import os
import zipfile
from pathlib import Path

import pytest

from restitution.fmu.describe.common import generation_date_and_time

SNAPSHOTS = Path(__file__).resolve().parents[1] / "data" / "model_descriptions"


def _as_built_without_date(fmu: Path) -> str:
    with zipfile.ZipFile(fmu) as z:
        text = z.read("modelDescription.xml").decode("utf-8")
    date = generation_date_and_time()
    if date is None:
        return text
    stamp = f' generationDateAndTime="{date}"'
    assert text.count(stamp) == 1, f"{fmu}: SOURCE_DATE_EPOCH is set but the file does not state {stamp.strip()}"
    return text.replace(stamp, "")


@pytest.mark.parametrize("model", ["SpherePlateImpact", "BouncingBall"])
@pytest.mark.parametrize("implementation", ["python", "fmi2", "fmi3"])
def test_model_description_equals_its_checked_in_copy(built_fmus, implementation, model):
    fmu = built_fmus / (f"{model}.fmu" if implementation == "python" else f"{implementation}/{model}.fmu")
    if not fmu.is_file():
        pytest.skip(f"{implementation} {model}.fmu not built here (needs gcc)")
    text = _as_built_without_date(fmu)
    copy = SNAPSHOTS / implementation / f"{model}.xml"
    if os.environ.get("RESTITUTION_UPDATE_SNAPSHOTS") == "1":
        copy.parent.mkdir(parents=True, exist_ok=True)
        copy.write_text(text, encoding="utf-8")
    expected = copy.read_text(encoding="utf-8")
    diff = "".join(difflib.unified_diff(expected.splitlines(True), text.splitlines(True),
                                        f"checked-in {copy.name}", f"built {fmu.name}", n=1))
    assert text == expected, f"{implementation} {model}: the modelDescription changed:\n{diff}"
