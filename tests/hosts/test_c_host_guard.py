"""A pythonfmu FMU post-processed by restitution/fmu/builders/guard.py
must run in a plain C FMI host (no LD_PRELOAD, no PYTHONPATH/PYTHONHOME, no
venv, PATH=/usr/bin:/bin), must keep running in Python hosts (fmpy), and must
fail cleanly (log message + NULL instance) when its interpreter is missing.
"""
from __future__ import annotations

import math
import shutil
import subprocess
import sys
import textwrap
import zipfile
from pathlib import Path
from xml.etree import ElementTree

import pytest

from script_host import build_host
from toy_fmu import build_plain_toy

ROOT = Path(__file__).resolve().parents[2]

pytestmark = [
    pytest.mark.skipif(not sys.platform.startswith("linux"), reason="Linux-only (linux64 guard)"),
    pytest.mark.skipif(shutil.which("gcc") is None, reason="gcc not available"),
]

MODULE = "toy_gain_slave"  # tests/toys/: y = gain * sqrt(x), gain 1; imports numpy
MODEL = "ToyGain"
VR_X, VR_Y = 0, 2  # x, gain, y, steps
CLEAN_ENV = {"PATH": "/usr/bin:/bin"}


def _load_add_guard():
    from restitution.fmu.builders import guard

    return guard


def _unpack(fmu: Path, dest: Path) -> Path:
    with zipfile.ZipFile(fmu) as zf:
        zf.extractall(dest)
    return dest


def _guid(fmu: Path) -> str:
    with zipfile.ZipFile(fmu) as zf:
        return ElementTree.fromstring(zf.read("modelDescription.xml")).attrib["guid"]


def _scenario(x: float, steps: int = 1, h: float = 1e-3) -> list[str]:
    """The host's script: instantiate, set up at t = 0, initialise with x = `x`, then `steps` times
    set x and step by h; read y after the last step; terminate and free."""
    script = ["instantiate instance1", "setup 0 0.0", "enter_init 0", f"set_real 0 {VR_X} {x!r}", "exit_init 0"]
    t = 0.0
    for _ in range(steps):
        script += [f"set_real 0 {VR_X} {x!r}", f"step 0 {t!r} {h!r}"]
        t += h
    return script + [f"get_real 0 {VR_Y}", "terminate 0", "free 0"]


def _run_host(host: Path, unpacked: Path, guid: str, script: list[str]) -> subprocess.CompletedProcess:
    # env -i: nothing inherited (no VIRTUAL_ENV, PYTHONPATH, PYTHONHOME, LD_*)
    return subprocess.run(
        ["env", "-i", "PATH=/usr/bin:/bin", str(host), str(unpacked), MODEL, guid],
        input="\n".join(script) + "\n",
        capture_output=True,
        text=True,
        timeout=120,
        env=CLEAN_ENV,
    )


def _values(proc: subprocess.CompletedProcess) -> dict[int, float]:
    """The values read ({vr: value}) of a run in which every fmi2 call succeeded (OK or Warning)
    and the script ran to its end."""
    statuses = [line.split() for line in proc.stdout.splitlines() if line.startswith("STATUS ")]
    failed = [s for s in statuses if s[3] not in ("OK", "Warning")]
    assert statuses and not failed, proc.stdout + proc.stderr
    assert proc.stdout.rstrip().endswith("DONE"), proc.stdout + proc.stderr
    out = {}
    for line in proc.stdout.splitlines():
        if line.startswith("REAL "):
            _, _slot, vr, value = line.split()
            out[int(vr)] = float(value)
    return out


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    work = tmp_path_factory.mktemp("chost")
    plain = build_plain_toy(work / "plain", MODULE)
    guarded = work / f"{MODEL}.fmu"
    shutil.copy(plain, guarded)
    _load_add_guard().add_guard(guarded)

    host = build_host(work / "fmi2_script_host", 2)
    return {"work": work, "plain": plain, "fmu": guarded, "host": host, "guid": _guid(guarded)}


def test_fmu_layout(built):
    with zipfile.ZipFile(built["fmu"]) as zf:
        names = set(zf.namelist())
        config = zf.read("resources/python_env.txt").decode()
    assert f"binaries/linux64/{MODEL}.so" in names
    assert f"binaries/linux64/{MODEL}_pythonfmu.so" in names
    assert f"binaries/win64/{MODEL}.dll" in names  # untouched
    assert "libpython=" in config and "executable=" in config
    assert "require=numpy" in config


def test_plain_pythonfmu_binary_fails_in_c_host(built, tmp_path):
    """The problem being solved: without the guard, dlopen fails."""
    unpacked = _unpack(built["plain"], tmp_path / "plain")
    proc = _run_host(built["host"], unpacked, built["guid"], _scenario(2.0))
    assert proc.returncode == 2
    assert "undefined symbol" in proc.stderr


@pytest.mark.parametrize("x", [2.0, 9.0, 1e-3])
def test_runs_in_plain_c_host(built, tmp_path, x):
    unpacked = _unpack(built["fmu"], tmp_path / "fmu")
    proc = _run_host(built["host"], unpacked, built["guid"], _scenario(x, steps=3))
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert _values(proc) == {VR_Y: math.sqrt(x)}


def test_runs_in_fmpy(built, tmp_path):
    """Same guarded FMU in a Python host: the guard uses the running interpreter."""
    code = textwrap.dedent(
        f"""
        import sys
        from fmpy import simulate_fmu, read_model_description, extract
        from fmpy.fmi2 import FMU2Slave
        fmu = sys.argv[1]
        res = simulate_fmu(fmu, stop_time=0.01, output_interval=0.001, start_values={{"x": 16.0}})
        assert res["y"][-1] == 4.0, res["y"]
        md = read_model_description(fmu)
        s = FMU2Slave(guid=md.guid, unzipDirectory=extract(fmu), modelIdentifier="{MODEL}")
        s.instantiate()
        s.setupExperiment(startTime=0.0)
        s.enterInitializationMode()
        s.exitInitializationMode()
        s.setReal([{VR_X}], [6.25])
        s.doStep(0.0, 0.1)
        print("y", repr(s.getReal([{VR_Y}])[0]))
        s.terminate()
        s.freeInstance()
        """
    )
    proc = subprocess.run([sys.executable, "-c", code, str(built["fmu"])], capture_output=True, text=True,
                          timeout=120)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "y 2.5" in proc.stdout


def _with_config(built, tmp_path, edit) -> Path:
    unpacked = _unpack(built["fmu"], tmp_path / "broken")
    cfg = unpacked / "resources" / "python_env.txt"
    cfg.write_text(edit(cfg.read_text()))
    return unpacked


def test_missing_libpython_gives_log_message_and_null(built, tmp_path):
    bogus = "/nonexistent/python/lib/libpython3.11.so.1.0"
    unpacked = _with_config(
        built, tmp_path,
        lambda text: "\n".join(f"libpython={bogus}" if line.startswith("libpython=") else line
                               for line in text.splitlines()) + "\n",
    )
    proc = _run_host(built["host"], unpacked, built["guid"], _scenario(4.0))
    assert proc.returncode == 3, proc.stdout + proc.stderr  # NULL instance, no crash
    assert "INSTANTIATE_FAILED" in proc.stdout
    log = [line for line in proc.stdout.splitlines() if line.startswith("LOG ")]
    assert any("cannot load the Python shared library" in line and bogus in line
               and "python_env.txt" in line for line in log), proc.stdout


def test_missing_module_gives_log_message_and_null(built, tmp_path):
    unpacked = _with_config(
        built, tmp_path,
        lambda text: text + "require=no_such_module_for_chost_test\n",
    )
    proc = _run_host(built["host"], unpacked, built["guid"], _scenario(4.0))
    assert proc.returncode == 3, proc.stdout + proc.stderr
    assert any("no_such_module_for_chost_test" in line and "ModuleNotFoundError" in line
               for line in proc.stdout.splitlines() if line.startswith("LOG ")), proc.stdout


def test_missing_config_gives_log_message_and_null(built, tmp_path):
    unpacked = _unpack(built["fmu"], tmp_path / "nocfg")
    (unpacked / "resources" / "python_env.txt").unlink()
    proc = _run_host(built["host"], unpacked, built["guid"], _scenario(4.0))
    assert proc.returncode == 3, proc.stdout + proc.stderr
    assert "python_env.txt" in proc.stdout and "needs a Python interpreter" in proc.stdout


def test_add_guard_is_idempotent(built, tmp_path):
    again = tmp_path / f"{MODEL}.fmu"
    shutil.copy(built["fmu"], again)
    _load_add_guard().add_guard(again)
    with zipfile.ZipFile(again) as zf:
        names = zf.namelist()
        assert zf.read(f"binaries/linux64/{MODEL}_pythonfmu.so") == \
            zipfile.ZipFile(built["plain"]).read(f"binaries/linux64/{MODEL}.so")
    assert len(names) == len(set(names))
    proc = _run_host(built["host"], _unpack(again, tmp_path / "again"), built["guid"], _scenario(2.0))
    assert proc.returncode == 0 and _values(proc) == {VR_Y: math.sqrt(2.0)}
