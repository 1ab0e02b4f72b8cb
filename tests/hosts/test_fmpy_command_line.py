"""The `fmpy simulate` command lines of docs/hosts.md ("fmpy's command line") run as printed against the
FMUs built from the working tree (the page's ``dist/`` replaced by the session's build), in a temporary
folder, and write what the page says: chrome steel (code 9), d = 4.76 mm, on brass (code 1), t = 3.18 mm,
at 2.3 m/s gives the package's e, in co-simulation and in model exchange; a ramp of speeds read from a
CSV gives the package's e at each row's speed; BouncingBall alone in model exchange with e = 0.5 rebounds
at half its impact speed. The limits the page states are checked too: model exchange is refused by the
pythonfmu FMU, an Enumeration given by its item's name is refused, the material codes are the FMUs'.
"""
import csv
import re
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

import restitution as r

ROOT = Path(__file__).resolve().parents[2]
FMPY = Path(sys.executable).parent / "fmpy"
G = 9.80665

pytestmark = pytest.mark.skipif(not FMPY.is_file(), reason=f"fmpy's command line ({FMPY}) is not installed: "
                                                           "the fmu extra (pip install -e '.[fmu]')")


def _page_block() -> str:
    """The shell block of docs/hosts.md's section on fmpy's command line."""
    text = (ROOT / "docs" / "hosts.md").read_text(encoding="utf-8")
    section = text[text.index("## fmpy's command line"):]
    section = section[:section.index("\n## ", 1)]
    (block,) = re.findall(r"(?ms)^```sh\n(.*?)^```", section)
    return block


def _rows(path: Path) -> list[dict]:
    with open(path, newline="") as f:
        return [{key: (value if value in ("True", "False") else float(value)) for key, value in row.items()}
                for row in csv.DictReader(f)]


def _package(v: float):
    return r.impact_between(r.Sphere(r.MATERIALS["chrome_steel"], 4.76e-3), r.Plate(r.MATERIALS["brass_260"], 3.18e-3),
                            v=v)


@pytest.fixture(scope="module")
def ran(built_fmus, tmp_path_factory) -> Path:
    """The folder the page's block ran in (its CSV files)."""
    for native in ("fmi2", "fmi3"):
        if not (built_fmus / native / "SpherePlateImpact.fmu").is_file():
            pytest.skip(f"the native {native} FMUs are not built here (needs gcc): the page's model-exchange lines "
                        "need them")
    work = tmp_path_factory.mktemp("fmpy_cli")
    script = _page_block().replace("dist/", f"{built_fmus}/")
    env = {"PATH": f"{FMPY.parent}:/usr/bin:/bin", "HOME": str(work)}
    proc = subprocess.run(["bash", "-e", "-c", script], cwd=work, capture_output=True, text=True, env=env, timeout=300)
    assert proc.returncode == 0, f"docs/hosts.md's fmpy lines failed:\n{proc.stdout[-3000:]}\n{proc.stderr[-3000:]}"
    return work


def test_block_uses_only_options_fmpy_has():
    block = _page_block()
    help_text = subprocess.run([str(FMPY), "--help"], capture_output=True, text=True, timeout=60).stdout
    for option in set(re.findall(r"(--[a-z][a-z-]+)", block)):
        assert option in help_text, f"fmpy has no {option}"
    assert "--interface-type ModelExchange" in block


def test_cor_in_co_simulation_and_model_exchange(ran):
    expected = _package(2.3)
    for name in ("impact.csv", "impact_me.csv"):
        rows = _rows(ran / name)
        assert rows, name
        for row in rows:
            assert row["e"] == pytest.approx(expected.e, rel=1e-9), name
            assert row["v_rebound"] == pytest.approx(expected.v_rebound, rel=1e-9), name
    assert f"e = {expected.e:.4f}" in (ROOT / "docs" / "hosts.md").read_text(encoding="utf-8")  # as the page says
    assert all(row["plate.used.E"] == 103e9 for row in _rows(ran / "impact.csv"))  # brass's modulus: code 1
    assert all(row["valid"] == "True" for row in _rows(ran / "impact_me.csv"))


def test_speeds_from_a_csv_in_model_exchange(ran):
    rows = _rows(ran / "ramp.csv")
    assert [row["time"] for row in rows] == [0.0, 0.25, 0.5, 0.75, 1.0]
    for row in rows:
        assert row["v_approach"] == pytest.approx(0.5 + 4.5 * row["time"], rel=1e-12)  # linear between the rows
        assert row["e"] == pytest.approx(_package(row["v_approach"]).e, rel=1e-9)


def test_ball_alone_in_model_exchange(ran):
    rows = _rows(ran / "ball.csv")
    assert rows[0]["h"] == 0.3 and rows[-1]["time"] == 1.0
    first = min(row["time"] for row in rows if row["impacts"] >= 1)
    assert first == pytest.approx((2 * 0.3 / G) ** 0.5, abs=1e-6)  # the contact is an event fmpy located
    after = [row for row in rows if row["impacts"] == 1 and row["v"] > 0]
    assert after and after[0]["v"] == pytest.approx(0.5 * (2 * G * 0.3) ** 0.5, rel=1e-3)  # e = 0.5
    assert rows[-1]["impacts"] >= 4


def test_stated_limits(built_fmus, tmp_path):
    python_fmu = built_fmus / "SpherePlateImpact.fmu"
    run = lambda *args: subprocess.run([str(FMPY), "simulate", str(python_fmu), "--stop-time", "0.001",
                                        "--output-interval", "0.001", *args], capture_output=True, text=True,
                                       cwd=tmp_path, timeout=120)
    refused = run("--interface-type", "ModelExchange")
    assert refused.returncode != 0 and 'FMI type "ModelExchange" is not supported by the FMU' in refused.stderr
    by_name = run("--start-values", "sphere.material", "chrome_steel")
    assert by_name.returncode != 0 and "invalid literal for int()" in by_name.stderr
    too_big = run("--start-values", "sphere.d", "100")
    assert too_big.returncode != 0 and "fmi2SetReal failed with status 3 (error)" in too_big.stderr
    # the material codes the page lists are the FMUs' (every FMU numbers its Material items alike)
    text = (ROOT / "docs" / "hosts.md").read_text(encoding="utf-8")
    codes = text[text.index("0 custom"):text.index("([materials](materials.md))")]
    listed = {name: int(code) for code, name in re.findall(r"(\d+)\s+([a-z][a-z0-9_]+)", codes)}
    fmus = [python_fmu] + [p for p in (built_fmus / "fmi2" / "SpherePlateImpact.fmu",
                                       built_fmus / "fmi3" / "SpherePlateImpact.fmu") if p.is_file()]
    for fmu in fmus:
        xml = zipfile.ZipFile(fmu).read("modelDescription.xml").decode()
        material = xml[xml.index('name="Material"'):]
        material = material[:material.index("</")]
        items = {name: int(code) for name, code in re.findall(r'<Item name="(\w+)" value="(\d+)"', material)}
        assert listed == items, fmu
