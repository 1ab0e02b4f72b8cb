"""Sweep rough edges: a small sweep given no scheduler runs serially (a LocalCluster would
not win back its start), a Ctrl-C of a Dask sweep prints the one interrupt line and nothing else
whenever it comes, and --resume says what it reused and rates only the cases it evaluated."""
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

from restitution.sweep import SweepSpec, read_table, run_sweep
from restitution.sweep.__main__ import main as sweep_cli
from restitution.sweep.cluster import CASE_SECONDS, CLUSTER_SECONDS, serial_reason
from restitution.sweep.run import SweepInterrupted

from interrupting_backend import InterruptingBackend
from terminal import takes_ctrl_c

PYTHON = sys.executable
ENV = {**os.environ, "PYTHONUNBUFFERED": "1"}
ENV.pop("DASK_SCHEDULER_ADDRESS", None)


# --- small sweeps run serially --------------------------------------------------------------
def _cases_a_cluster_pays_for(backend, workers, column=0):
    """The smallest sweep whose serial time, less what ``workers`` workers could do of it, exceeds the start."""
    return int(CLUSTER_SECONDS / (CASE_SECONDS[backend][column] * (1 - 1 / workers))) + 1


@pytest.mark.parametrize("backend", ["package", "fmu"])
def test_the_threshold_is_where_a_cluster_can_win_back_its_start(backend, monkeypatch):
    monkeypatch.delenv("DASK_SCHEDULER_ADDRESS", raising=False)
    n = _cases_a_cluster_pays_for(backend, 2)
    below, above = SweepSpec(random={"v": "uniform:1:2"}, samples=n // 2), SweepSpec(random={"v": "uniform:1:2"}, samples=n)
    assert serial_reason(below, [backend], 2).startswith("serial:")
    assert serial_reason(above, [backend], 2) is None
    if backend == "package":  # --backend both: the two costs add, the FMU's dominates
        assert serial_reason(below, ["package", "fmu"], 2) is None
    # slow options count: the integrated Zener model makes a few thousand cases worth a cluster
    ode = SweepSpec(random={"v": "uniform:1:2"}, samples=_cases_a_cluster_pays_for(backend, 2, 2),
                    grid={"zener_method": "exact,ode"})
    assert serial_reason(ode, [backend], 2) is None
    assert serial_reason(SweepSpec(grid={"zener_method": "exact,ode"}), [backend], 2) is not None
    import dask

    with dask.config.set({"scheduler-address": "tcp://127.0.0.1:1"}):  # as $DASK_SCHEDULER_ADDRESS sets it
        assert serial_reason(below, [backend], 2) is None


def test_cli_small_sweep_without_scheduler_runs_serially_and_says_so(tmp_path, capsys, monkeypatch):
    monkeypatch.delenv("DASK_SCHEDULER_ADDRESS", raising=False)
    args = ["--pair", "s2_tool_steel/al_6061", "--grid", "v=geomspace:0.1:10:16", "--grid", "t/d=geomspace:0.1:10:10",
            "--no-plot", "--out", str(tmp_path / "s.csv")]
    assert sweep_cli(args) == 0
    out = capsys.readouterr().out
    line = next(l for l in out.splitlines() if l.startswith("160 cases with the package back end"))
    assert "on this process (serial: about" in line and "--scheduler local starts one" in line, line
    assert sweep_cli([*args, "--scheduler", "serial"]) == 0  # asked for: no reason given
    assert "on this process (serial) (" in capsys.readouterr().out


# --- --resume says what it reused -------------------------------------------------------------

def test_resume_reports_reused_chunks_and_rates_only_the_evaluated_cases(tmp_path):
    spec = SweepSpec(pairs=["s2_tool_steel/al_6061"], grid={"v": "geomspace:0.1:10:30", "t/d": "0.2,1,5"},
                     random={"sphere.E": {"normal_rel": 0.05}}, samples=5, seed=2)
    with pytest.raises(SweepInterrupted):
        run_sweep(spec, InterruptingBackend(4), scheduler="serial", chunk_size=100, parts=tmp_path / "p")
    counting = InterruptingBackend(0)
    res = run_sweep(spec, counting, scheduler="serial", parts=tmp_path / "p", resume=True)
    n_chunks = -(-spec.n_cases // 100)
    assert counting.calls == n_chunks - 3
    assert res.info["reused"] == {"chunks": 3, "cases": 300, "from": str(tmp_path / "p")}
    evaluated = spec.n_cases - 300
    assert res.cases_per_second == pytest.approx(evaluated / res.elapsed)
    summary = res.summary()
    assert f"over the {evaluated:,} cases evaluated (3 chunk(s) of 300 cases reused from {tmp_path / 'p'})" in summary
    fresh = run_sweep(spec, scheduler="serial", chunk_size=100)  # no resume: no such words, every case rated
    assert "reused" not in fresh.info and "reused" not in fresh.summary()
    assert fresh.cases_per_second == pytest.approx(spec.n_cases / fresh.elapsed)


def test_cli_resume_prints_the_reused_and_evaluated_counts(tmp_path, capsys):
    out = tmp_path / "s.csv"
    args = ["--grid", "v=linspace:0.5:3:50", "--grid", "t/d=0.2,1,5,8", "--scheduler", "serial", "--no-plot",
            "--out", str(out), "--chunk-size", "40"]
    spec = SweepSpec(grid={"v": "linspace:0.5:3:50", "t/d": "0.2,1,5,8"})
    with pytest.raises(SweepInterrupted):
        run_sweep(spec, InterruptingBackend(3), scheduler="serial", chunk_size=40, parts=out.with_name("s.csv.parts") / "package")
    assert sweep_cli([*args, "--resume"]) == 0
    text = capsys.readouterr().out
    assert f"over the {200 - 80} cases evaluated (2 chunk(s) of 80 cases reused from" in text, text
    assert np.array_equal(read_table(out)["case"], np.arange(200))


# --- Ctrl-C of a Dask sweep: one line, whenever it comes ----------------------------------------
#: zener_method = ode: about 5 ms a case, 40 chunks of 30 cases on 2 workers: a few seconds of chunks
SLOW = ["--pair", "s2_tool_steel/al_6061", "--grid", "v=geomspace:0.1:10:40", "--grid", "t/d=geomspace:0.1:10:30",
        "--set", "zener_method=ode", "--chunk-size", "30"]
#: Many fast chunks of 20,000 cases (about 6 MB each to take from the workers): a Ctrl-C meets a transfer
FAST = ["--pair", "s2_tool_steel/al_6061", "--random", "v=uniform:0.1:10", "--samples", "2000000", "--chunk-size", "20000"]
LINES = {"start": "interrupted before the sweep started", "chunks": "interrupted: wrote the "}


def _ctrl_c(tmp_path, sweep, when):
    """The CLI on a 2-worker LocalCluster in a process group of its own; SIGINT to the group (what a
    terminal's Ctrl-C does) ``when``: "start" just after it printed what the sweep covers (the cluster
    starting), "first" once the run has begun (its manifest written: the first chunks starting, with
    the FMU back end the workers instantiating it), else once ``when`` chunks are on disk."""
    tmp_path.mkdir()
    out = tmp_path / "s.csv"
    proc = subprocess.Popen([PYTHON, "-m", "restitution.sweep", *sweep, "--scheduler", "local", "--workers", "2",
                             "--no-plot", "--out", str(out)], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, cwd=tmp_path, env=ENV, start_new_session=True, preexec_fn=takes_ctrl_c)
    parts = tmp_path / "s.csv.parts" / ("fmu" if "fmu" in sweep else "package")
    if when == "start":
        assert proc.stdout.readline().startswith("sweep:")
        time.sleep(0.2)
    elif when == "first":
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and not (parts / "manifest.json").exists():
            time.sleep(0.01)
    else:
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and len(list(parts.glob("chunk-*.parquet"))) < when:
            time.sleep(0.02)
    assert proc.poll() is None, "the sweep ended before it could be interrupted"
    import psutil

    children = psutil.Process(proc.pid).children(recursive=True)
    os.killpg(proc.pid, signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    _, alive = psutil.wait_procs(children, timeout=30)
    assert not alive, f"processes left after the interrupt: {alive}"
    assert proc.returncode == 130, err
    for word in ("Traceback", "ERROR", "CommClosedError", "KeyboardInterrupt"):
        assert word not in err, err
    lines = [l for l in err.splitlines() if any(line in l for line in LINES.values())]
    assert len(lines) == 1 and (when == "first" or LINES["start" if when == "start" else "chunks"] in lines[0]), err
    if when not in ("start", "first"):  # the finished chunks are kept, and written
        kept = len(list(parts.glob("chunk-*.parquet")))
        assert kept >= when
        assert read_table(out)["case"].size >= when * int(sweep[sweep.index("--chunk-size") + 1])
    return err


@pytest.mark.slow
def test_ctrl_c_of_a_dask_sweep_is_one_line_whenever_it_comes(tmp_path, impact_fmu):
    _ctrl_c(tmp_path / "start", SLOW, "start")  # during the cluster's start: held, raised once it can close
    # as the FMU is instantiated on the workers: the end-of-sweep release_fmus() met it (No module named ...)
    _ctrl_c(tmp_path / "fmu", [*SLOW, "--backend", "fmu", "--fmu", str(impact_fmu)], "first")
    _ctrl_c(tmp_path / "chunks", SLOW, 3)  # while chunks compute
    for i in range(3):  # while chunks are taken from the workers: the race that printed CommClosedError, repeated
        _ctrl_c(tmp_path / f"gather{i}", FAST, 5 + 7 * i)


@pytest.mark.skipif(sys.version_info[:2] != (3, 11) or sys.implementation.name != "cpython",
                    reason="only CPython 3.11 exports its note of an unhandled KeyboardInterrupt "
                           "(_Py_UnhandledKeyboardInterrupt) for a test to read")
def test_a_handled_ctrl_c_leaves_no_note_of_an_unhandled_one(tmp_path):
    """A KeyboardInterrupt inside code that ``exec`` runs from a string (a dataclass being made while a
    module imports) leaves CPython's note of an unhandled interrupt set although the command line caught
    it, and ``python -m restitution.sweep`` then died by SIGINT (-2) after saying it was interrupted:
    the test above did, 4 times in 12 when Ctrl-C met distributed's import. The command lines clear the
    note (``forget_unhandled_interrupt``) before returning 130. In a child process: the note is the
    interpreter's own state, read here with ctypes."""
    script = (
        "import ctypes, os, signal\n"
        "from restitution.cosim.interrupt import forget_unhandled_interrupt\n"
        "note = ctypes.c_int.in_dll(ctypes.pythonapi, '_Py_UnhandledKeyboardInterrupt')\n"
        "try:\n"
        "    exec('import os, signal\\nos.kill(os.getpid(), signal.SIGINT)\\nx = 1', {}, {})\n"
        "except KeyboardInterrupt:\n"
        "    pass\n"
        "set_by_exec = note.value\n"
        "forget_unhandled_interrupt()\n"
        "print(set_by_exec, note.value)\n")
    done = subprocess.run([PYTHON, "-c", script], capture_output=True, text=True, env=ENV, timeout=60)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["1", "0"]
