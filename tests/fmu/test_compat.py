"""``restitution fmu compat`` (restitution.fmu.compat): the compatibility information of each native FMU
(model x FMI version x interface), built here from this platform's native FMUs:

1. the Cross-Check's format: every file present; fmpy's own checker of a vendor's test FMU
   (fmpy.cross_check.validate_vendor_repo.validate_test_fmu) finds no problem; the CSVs comma separated,
   numeric cells only, time first and increasing, names the modelDescription's, at most 10 variables,
   under 1 MB;
2. each ``_ref.csv`` (computed by the package, not the FMU) reproduced by an independent fmpy run of the
   FMU from its ``_ref.opt`` and ``_in.csv``, within the ``.opt``'s RelTol of each signal's range; the FMI
   2.0 co-simulation BouncingBall also by libcosim (constant e as its initial value);
3. the command: an output that is an input FMU is refused, a missing FMU is one line and exit 2.
"""
from __future__ import annotations

import csv
import importlib.util
import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest


@pytest.fixture(scope="module")
def compat(host_native_fmus, tmp_path_factory):
    from restitution.fmu.compat import write_compat

    out = tmp_path_factory.mktemp("compat")
    return write_compat(out, host_native_fmus)


def _folders(compat):
    return {(f.parts[-6], f.parts[-5], f.name): f for f in compat}  # (FMI version, interface, model)


def test_every_model_version_and_interface_is_written(compat):
    assert set(_folders(compat)) == {(v, i, m) for v in ("2.0", "3.0") for i in ("cs", "me")
                                     for m in ("BouncingBall", "SpherePlateImpact")}
    for folder in compat:
        model = folder.name
        assert {p.name for p in folder.iterdir()} == {f"{model}.fmu", f"{model}_in.csv", f"{model}_ref.csv",
                                                      f"{model}_ref.opt", "ReadMe.txt"}


def test_fmpys_cross_check_validator_finds_no_problem(compat):
    from fmpy.cross_check.validate_vendor_repo import validate_test_fmu

    for folder in compat:  # (it reads the FMI version and interface from the folder names, as the layout says)
        assert validate_test_fmu(str(folder)) == [], folder


def _variable_names(fmu: Path) -> set:
    from fmpy import read_model_description

    return {v.name for v in read_model_description(str(fmu)).modelVariables}


def test_csvs_follow_the_cross_check_rules(compat):
    for folder in compat:
        names = _variable_names(folder / f"{folder.name}.fmu")
        for suffix in ("_in.csv", "_ref.csv"):
            path = folder / f"{folder.name}{suffix}"
            assert path.stat().st_size < 1_000_000
            rows = list(csv.reader(path.read_text().splitlines(), delimiter=","))
            header, body = rows[0], rows[1:]
            assert header[0] == "time" and 2 <= len(header) <= 11, header  # time + at most 10 variables
            assert set(header[1:]) <= names, header
            values = np.array([[float(cell) for cell in row] for row in body])  # numeric cells only
            assert values.shape[1] == len(header) and np.isfinite(values).all()
            assert np.all(np.diff(values[:, 0]) > 0), path


def _read(path: Path) -> dict:
    rows = list(csv.reader(path.read_text().splitlines()))
    data = np.array([[float(c) for c in row] for row in rows[1:]])
    return {name: data[:, i] for i, name in enumerate(rows[0])}


def _options(path: Path) -> dict:
    from fmpy.util import read_ref_opt_file

    return read_ref_opt_file(str(path))


def _fmpy_run(folder: Path) -> dict:
    """The FMU simulated by fmpy from its .opt and _in.csv alone, sampled at the reference's times."""
    from fmpy import simulate_fmu

    model, opt = folder.name, _options(folder / f"{folder.name}_ref.opt")
    inputs = _read(folder / f"{model}_in.csv")
    names = list(inputs)
    signals = np.array(list(zip(*[inputs[n] for n in names])), dtype=[(n, float) for n in names])
    reference = _read(folder / f"{model}_ref.csv")
    cs = folder.parts[-5] == "cs"
    result = simulate_fmu(str(folder / f"{model}.fmu"), fmi_type="CoSimulation" if cs else "ModelExchange",
                          start_time=opt["StartTime"], stop_time=opt["StopTime"], output_interval=opt["StepSize"],
                          step_size=opt["StepSize"] if cs else None, relative_tolerance=1e-10 if not cs else None,
                          input=signals, output=[n for n in reference if n != "time"])
    out = {}
    for name in reference:
        if name == "time":
            continue
        # model exchange records the event instants too: take each reference time's last sample
        index = np.searchsorted(result["time"], reference["time"] + 1e-12, side="right") - 1
        assert np.allclose(result["time"][index], reference["time"], rtol=0, atol=1e-9)
        out[name] = result[name][index]
    return out


def _assert_within_opt(folder: Path, run: dict):
    reference, opt = _read(folder / f"{folder.name}_ref.csv"), _options(folder / f"{folder.name}_ref.opt")
    for name, values in run.items():
        span = np.ptp(reference[name]) or abs(reference[name]).max() or 1.0
        error = np.abs(values - reference[name]).max()
        assert error <= opt["RelTol"] * span, (folder, name, error, opt["RelTol"] * span)


def test_each_reference_is_reproduced_by_fmpy(compat):
    for folder in compat:
        _assert_within_opt(folder, _fmpy_run(folder))


LIBCOSIM_CHILD = textwrap.dedent('''
    import json, sys
    from pathlib import Path
    from restitution.cosim.libcosim_run import run_system_structure, write_system_structure

    cfg = json.loads(sys.argv[1])
    path = write_system_structure(Path(cfg["dir"]), {"ball": (cfg["fmu"], {"e": cfg["e"]})}, cfg["step"],
                                  connections=())
    result = run_system_structure(path, cfg["stop"], record=("ball.h", "ball.v"))
    print("RESULT " + json.dumps({"time": result.time.tolist(), "h": result.values["ball.h"].tolist(),
                                  "v": result.values["ball.v"].tolist()}))
''')


def test_libcosim_reproduces_the_fmi2_cosimulation_ball(compat, tmp_path):
    if importlib.util.find_spec("libcosimpy") is None:
        pytest.skip("libcosimpy (OSP libcosim) not installed")
    folder = _folders(compat)[("2.0", "cs", "BouncingBall")]
    opt, inputs = _options(folder / "BouncingBall_ref.opt"), _read(folder / "BouncingBall_in.csv")
    assert np.ptp(inputs["e"]) == 0  # a constant input: libcosim gets it as the initial value
    cfg = {"dir": str(tmp_path), "fmu": str(folder / "BouncingBall.fmu"), "e": float(inputs["e"][0]),
           "step": opt["StepSize"], "stop": opt["StopTime"]}
    proc = subprocess.run([sys.executable, "-c", LIBCOSIM_CHILD, json.dumps(cfg)], capture_output=True, text=True,
                          timeout=300)
    assert proc.returncode == 0, proc.stderr[-3000:]
    run = json.loads(next(x for x in proc.stdout.splitlines() if x.startswith("RESULT "))[len("RESULT "):])
    reference = _read(folder / "BouncingBall_ref.csv")
    assert np.allclose(run["time"], reference["time"], rtol=0, atol=1e-9)
    _assert_within_opt(folder, {"h": np.array(run["h"]), "v": np.array(run["v"])})


def test_an_output_that_is_an_input_fmu_is_refused(host_native_fmus, tmp_path):
    from restitution.about import VERSION
    from restitution.fmu.compat import platform_folder, write_compat
    from restitution.output_files import OutputPathError

    out = tmp_path / "out"
    target = (out / "fmus" / "2.0" / "cs" / platform_folder("2.0") / "restitution" / VERSION / "BouncingBall"
              / "BouncingBall.fmu")
    target.parent.mkdir(parents=True)
    fmus = tmp_path / "fmus"
    (fmus / "fmi2").mkdir(parents=True)
    os.link(host_native_fmus / "fmi2" / "BouncingBall.fmu", target)
    os.link(target, fmus / "fmi2" / "BouncingBall.fmu")  # the output file is the input FMU (a hard link)
    before = target.read_bytes()
    with pytest.raises(OutputPathError, match="is the input"):
        write_compat(out, fmus, models=("BouncingBall",))
    assert target.read_bytes() == before


def test_command_line(host_native_fmus, tmp_path):
    exe = [sys.executable, "-m", "restitution", "fmu", "compat"]
    ok = subprocess.run(exe + ["--out", str(tmp_path / "c"), "--fmus", str(host_native_fmus)], capture_output=True,
                        text=True, timeout=300)
    assert ok.returncode == 0 and len(ok.stdout.splitlines()) == 8, ok.stderr
    bad = subprocess.run(exe + ["--out", str(tmp_path / "d"), "--fmus", str(tmp_path / "none")], capture_output=True,
                         text=True, timeout=300)
    assert bad.returncode == 2 and len(bad.stderr.splitlines()) == 1 and "restitution fmu build" in bad.stderr
