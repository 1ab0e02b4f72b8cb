"""``restitution export`` as a user runs it (child processes): the table against impact() called here, the
JSON contract of the MuJoCo export, --verify and --dt, and bad input refused in one line with exit 2."""
from __future__ import annotations

import csv
import io
import json
import subprocess
import sys

import numpy as np
import pytest

import restitution as r
from restitution.export.hosts import ExportCase

#: A pair of no preset: a bearing-steel-like sphere given by its properties on a bronze-like plate.
SPHERE = ["--sphere-E", "203 GPa", "--sphere-nu", "0.29", "--sphere-Sy", "1.65 GPa", "--sphere-rho", "7810 kg/m3"]
PLATE = ["--plate-E", "112 GPa", "--plate-nu", "0.34", "--plate-Sy", "310 MPa", "--plate-rho", "8800 kg/m3"]
PAIR = [*SPHERE, *PLATE, "--d", "7.9 mm", "--t", "4.2 mm"]
PARAMS = dict(sphere_E=203e9, sphere_nu=0.29, sphere_Sy=1.65e9, sphere_rho=7810.0, sphere_d=7.9e-3,
              plate_E=112e9, plate_nu=0.34, plate_Sy=310e6, plate_rho=8800.0, plate_t=4.2e-3)


def _run(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "restitution", "export", *args], capture_output=True, text=True,
                          cwd=cwd, timeout=300)


def test_table_is_impact_at_each_speed(tmp_path):
    """JSON keeps every digit (repr of a float): the same numbers as impact() at the same speeds, to 1e-12
    (the same code path; the margin covers an array call against one-speed calls). CSV has 10 digits."""
    out = tmp_path / "t.json"
    done = _run("table", *PAIR, "--v-range", "30 cm/s", "4.5 m/s", "--points", "7", "--format", "json", "--out",
                str(out))
    assert done.returncode == 0, done.stderr
    table = json.loads(out.read_text())
    assert table["v"] == pytest.approx(np.linspace(0.3, 4.5, 7), rel=1e-15)
    for i, v in enumerate(table["v"]):
        want = r.impact(v, **PARAMS, plate_edge_distance=0.0)
        assert table["e"][i] == pytest.approx(want.e, rel=1e-12)
        assert table["t_contact"][i] == pytest.approx(want.t_contact, rel=1e-12)
        assert table["valid"][i] is bool(want.valid) and table["e_negative"][i] is bool(want.e_negative)
    csv_done = _run("table", *PAIR, "--v-range", "0.3", "4.5", "--points", "7")
    rows = list(csv.DictReader(io.StringIO(csv_done.stdout)))
    assert [float(row["e"]) for row in rows] == pytest.approx(table["e"], rel=1e-9)
    solfec = _run("table", *PAIR, "--v-range", "0.3", "4.5", "--points", "7", "--format", "solfec")
    flat = json.loads(solfec.stdout)
    assert flat[0::2] == pytest.approx(table["v"], rel=1e-9) and flat[1::2] == pytest.approx(table["e"], rel=1e-9)


def test_mujoco_json_contract(tmp_path):
    out = tmp_path / "m.json"
    done = _run("mujoco", *PAIR, "--v", "1.3 m/s", "--json", str(out))
    assert done.returncode == 0, done.stderr
    data = json.loads(out.read_text())
    want = r.impact(1.3, **PARAMS, plate_edge_distance=0.0)
    assert data["e"] == pytest.approx(want.e, rel=1e-12) and data["t_contact"] == pytest.approx(want.t_contact,
                                                                                                rel=1e-12)
    assert len(data["solref"]) == 2 and all(x > 0 for x in data["solref"]) and len(data["solimp"]) == 5
    assert 0 < data["timestep"] <= data["t_contact"] / 5
    # tuned for the default step, t_contact/50, and holding there and at every finer step
    assert data["tuned_dt"] == pytest.approx(data["t_contact"] / 50, rel=1e-12) and data["holds_at_finer_steps"]
    assert data["timestep"] >= data["tuned_dt"] * (1 - 1e-12) and len(data["solref_continuous"]) == 2
    assert "<geom" in done.stdout and f"{data['solref'][1]:.8g}" in done.stdout and 'solimp="' in done.stdout


def test_a_speed_range_gives_the_parameters_per_speed(tmp_path):
    out = tmp_path / "r.json"
    done = _run("mujoco", *PAIR, "--v-range", "0.2 m/s", "2 m/s", "--points", "3", "--json", str(out))
    assert done.returncode == 0 and done.stdout.count("<geom") == 3, done.stderr
    speeds = json.loads(out.read_text())["speeds"]
    for entry, v in zip(speeds, (0.2, 1.1, 2.0)):
        assert entry["v"] == pytest.approx(v, rel=1e-12)
        assert entry["e"] == pytest.approx(r.impact(v, **PARAMS, plate_edge_distance=0.0).e, rel=1e-12)
    assert speeds[0]["e"] > speeds[2]["e"] and speeds[0]["solref"][1] < speeds[2]["solref"][1]


def test_verify_and_dt(tmp_path):
    """--verify passes at a fine contact; a coarse --dt is reported with a warning, and --verify at it exits 1
    (at t_contact/5 the damped contact's first step alone misses e by far more than 1 %); at t_contact/25 the
    parameters are tuned for the step and the drop at it holds."""
    fine = _run("mujoco", *PAIR, "--v", "1.3 m/s", "--verify", "--json", str(tmp_path / "m.json"))
    assert fine.returncode == 0 and "error" in fine.stdout, fine.stdout + fine.stderr
    data = json.loads((tmp_path / "m.json").read_text())
    assert abs(data["verify"][0]["error"]) < 0.01 and data["verify"][0]["dt"] is None
    coarse = _run("mujoco", *PAIR, "--v", "1.3 m/s", "--verify", "--dt", f"{data['t_contact'] / 5} s")
    assert coarse.returncode == 1 and "warning: dt" in coarse.stdout, coarse.stdout + coarse.stderr
    # a step of t_contact/25: the export tunes solref and solimp for it, and the drop at it holds 1 %
    middle = _run("mujoco", *PAIR, "--v", "1.3 m/s", "--verify", "--dt", f"{data['t_contact'] / 25} s", "--json",
                  str(tmp_path / "m25.json"))
    assert middle.returncode == 0, middle.stdout + middle.stderr
    tuned = json.loads((tmp_path / "m25.json").read_text())
    assert tuned["tuned_dt"] == pytest.approx(data["t_contact"] / 25, rel=1e-9)
    assert abs(tuned["verify"][1]["error"]) < 0.01 and tuned["verify"][1]["dt"] == tuned["tuned_dt"]


@pytest.mark.parametrize("args, words", [
    (["nohost", *PAIR, "--v", "2"], ["unknown host", "mujoco"]),
    (["table", *PAIR, "--v-range", "3 m/s", "1 m/s"], ["--v-range", "above"]),
    (["mujoco", *PAIR, "--v-range", "3 m/s", "1 m/s"], ["--v-range", "above"]),
    (["mujoco", *PAIR], ["--v"]),
    (["mujoco", "--sphere", "chrome_steel", "--d", "12.7 mm", "--plate", "al_6061", "--t", "1 mm", "--v", "2"],
     ["e = ", "< 0", "--allow-invalid"]),
    (["table", "--sphere", "chrome_steel", "--d", "12.7 mm", "--plate", "al_6061", "--t", "1 mm", "--v-range", "1",
      "2"], ["< 0", "--allow-invalid"]),
    (["mujoco", *PAIR, "--v", "2", "--dt", "-1 us"], ["--dt"]),
    (["mujoco", *PAIR, "--v", "2", "--dt", "3 mm"], ["--dt"]),
])
def test_bad_input_is_one_line_and_exit_2(tmp_path, args, words):
    done = _run(*args, cwd=tmp_path)
    lines = done.stderr.strip().splitlines()
    assert done.returncode == 2 and done.stdout == "" and len(lines) == 1, done.stderr
    assert all(word in lines[0] for word in words), lines[0]


def test_allow_invalid_exports_and_says_so():
    done = _run("table", "--sphere", "chrome_steel", "--d", "12.7 mm", "--plate", "al_6061", "--t", "1 mm",
                "--v-range", "1", "2", "--points", "2", "--allow-invalid")
    assert done.returncode == 0 and "--allow-invalid" in done.stderr and done.stdout.count("\n") == 3
    host = _run("mujoco", "--sphere", "chrome_steel", "--d", "12.7 mm", "--plate", "al_6061", "--t", "1 mm", "--v",
                "1", "--allow-invalid")  # no contact of MuJoCo's gives e < 0: still one line, exit 2
    assert host.returncode == 2 and len(host.stderr.strip().splitlines()) == 1 and "e = " in host.stderr


def test_a_flag_outside_validity_is_a_refusal():
    """valid = no with e > 0 is refused as well (the command turns the phrase into its one line)."""
    case = ExportCase(e=0.4, t_contact=1e-5, v=1.0, m_sphere=1e-3, R_sphere=3e-3, E_eff=1e11, m_eff=1e-3, E1=2e11,
                      nu1=0.3, E2=7e10, nu2=0.33, d=6e-3, t=1e-3, valid=False, lambda_in_range=False,
                      vstar_in_range=True, e_negative=False, contact_ends=True, concurrent=False, edge_clear=True,
                      plasticity_used=True, plate_waves_used=True)
    assert "lambda_in_range = no" in case.refusal()


def test_verify_without_mujoco_integrates_its_documented_step(tmp_path):
    """Where MuJoCo cannot be imported (made unimportable in the child, as for a package not installed),
    --verify steps the contact as MuJoCo's documentation describes it and says so; the e it gets is the same
    mapping's, within 1 %."""
    code = ("import sys; sys.modules['mujoco'] = None\n"
            "from restitution.command import main\n"
            f"sys.exit(main({['export', 'mujoco', *PAIR, '--v', '1.3 m/s', '--verify', '--json', 'v.json']!r}))")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path, timeout=300)
    assert done.returncode == 0 and "published force law, integrated here" in done.stdout, done.stdout + done.stderr
    check = json.loads((tmp_path / "v.json").read_text())["verify"][0]
    assert check["law"] == "published force law, integrated here" and abs(check["error"]) < 0.01
