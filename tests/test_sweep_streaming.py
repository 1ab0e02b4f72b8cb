"""Sweeps lose nothing (issue 13): finished chunks on disk as they complete, Ctrl-C writes what
is done and exits 130, --resume completes only the missing chunks and gives the table of an
uninterrupted run; guards before any work (case counts, memory budget, CLI integers, output
paths); validity counted and warned about."""
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from restitution.sweep import SweepSpec, compare_results, read_table, run_sweep
from restitution.sweep.__main__ import main as sweep_cli
from restitution.sweep.run import SweepInterrupted, check_memory, table_bytes

PYTHON = sys.executable
ENV = {**os.environ, "PYTHONUNBUFFERED": "1"}
ENV.pop("DASK_SCHEDULER_ADDRESS", None)

#: Slow enough to interrupt (zener_method = ode: about 5 ms a case here), 1200 cases in 40 chunks.
SLOW_ARGS = ["--pair", "s2_tool_steel/al_6061", "--grid", "v=geomspace:0.1:10:40", "--grid", "t/d=geomspace:0.1:10:30",
             "--set", "zener_method=ode", "--set", "plate_waves=on", "--chunk-size", "30", "--no-plot"]
SLOW_SPEC = dict(pairs=["s2_tool_steel/al_6061"], grid={"v": "geomspace:0.1:10:40", "t/d": "geomspace:0.1:10:30"},
                 fixed={"zener_method": "ode", "plate_waves": "on"})
#: Same code path, same machine, same inputs: the resumed table equals the uninterrupted one;
#: 1e-13 relative leaves room for nothing but the last bits of the ODE's stepping.
TOL = 1e-13


def _cli(*args, cwd=None):
    return subprocess.run([PYTHON, "-m", "restitution.sweep", *args], capture_output=True, text=True,
                          cwd=cwd, env=ENV, timeout=300)


def _one_line_error(proc, *words):
    assert proc.returncode == 2, (proc.returncode, proc.stderr)
    assert "Traceback" not in proc.stderr, proc.stderr
    last = proc.stderr.strip().splitlines()[-1]
    for w in words:
        assert w in last, (w, last)


# --- guards: counts, sizes, integers, paths ------------------------------------------------
def test_case_counts_are_python_ints_and_axes_are_not_built():
    axis = "linspace:0.1:1:65536"
    spec = SweepSpec(grid={"v": axis, "t/d": axis, "sphere.E": "linspace:1e9:2e9:65536",
                           "plate.E": "linspace:1e9:2e9:65536"})
    assert spec.n_cases == 65536 ** 4 == 2 ** 64  # np.prod(dtype=int64) made this 0
    assert SweepSpec(grid={"v": "linspace:0.1:1:100000", "t/d": {"linspace": [1, 2, 10 ** 15]}}).n_cases == 10 ** 20
    big = SweepSpec(grid={"v": {"linspace": [0.1, 1, 10 ** 9]}})  # 7.45 GiB if built
    assert big.n_cases == 10 ** 9 and big._axes_built is None
    assert "1,000,000,000 cases" in big.describe()


def test_memory_budget_refuses_with_numbers():
    spec = SweepSpec(grid={"v": "linspace:0.1:1:1000"}, random={"sphere.E": {"normal_rel": 0.01}}, samples=10 ** 6)
    with pytest.raises(ValueError, match=r"1,000,000,000 cases would take .*GiB.*memory budget of 1 MiB"):
        check_memory(spec, budget=2 ** 20)
    small = SweepSpec(grid={"v": "1,2,3"})
    assert check_memory(small, budget=2 ** 20) == table_bytes(3) > 0
    assert table_bytes(10, ["e"]) < table_bytes(10)


def test_cli_refuses_absurd_sizes_before_any_work(tmp_path):
    proc = _cli("--random", "v=uniform:1:2", "--samples", "1000000000", "--out", str(tmp_path / "s.csv"))
    _one_line_error(proc, "1,000,000,000 cases", "memory budget")
    grid = ["--grid", "v=linspace:0.1:1:65536", "--grid", "t/d=linspace:0.1:1:65536",
            "--grid", "sphere.E=linspace:1e9:2e9:65536", "--grid", "plate.E=linspace:1e9:2e9:65536"]
    proc = _cli(*grid, "--out", str(tmp_path / "s.csv"))
    _one_line_error(proc, "18,446,744,073,709,551,616 cases")
    assert not (tmp_path / "s.csv").exists()
    # --dry-run answers from the sizes (a 1e9-point axis is not built) and says it would be refused
    proc = _cli("--grid", "v=linspace:0.1:1:1000000000", "--dry-run")
    assert proc.returncode == 0 and "1,000,000,000 cases" in proc.stdout and "memory budget" in proc.stdout
    proc = _cli("--grid", "v=1,2,3", "--dry-run", "--memory-budget", "1K")
    assert proc.returncode == 0 and "3 cases" in proc.stdout, proc.stdout


@pytest.mark.parametrize("args, words", [
    (["--chunk-size", "-1"], ["--chunk-size", "-1", "1 <= value"]),
    (["--chunk-size", "0"], ["--chunk-size", "0"]),
    (["--workers", "0"], ["--workers", "0"]),
    (["--seed", "-1"], ["--seed", "-1", "0 <= value"]),
    (["--samples", "0"], ["--samples"]),
    (["--memory-budget", "lots"], ["--memory-budget"]),
    (["--set", "zener_method=4294967297", "--backend", "fmu"], ["zener_method = 4294967297", "out of range"]),
    (["--grid", "v=arange:0:1:0"], ["arange step = 0"]),
    (["no_such_spec.toml"], ["no_such_spec.toml", "No such file"]),
    (["--backend", "both", "--columns", "e"], ["--columns must keep ok"]),
])
def test_cli_user_mistakes_are_one_line_errors(tmp_path, args, words):
    proc = _cli(*args, "--grid" if "--grid" not in args else "--no-plot",
                *(["v=1,2"] if "--grid" not in args else []), "--out", str(tmp_path / "s.csv"), cwd=tmp_path)
    _one_line_error(proc, *words)


def test_codes_are_range_checked_in_the_spec():
    with pytest.raises(ValueError, match="out of range"):
        SweepSpec(fixed={"zener_method": 2 ** 32 + 1})
    with pytest.raises(ValueError, match="out of range"):
        SweepSpec(grid={"plasticity": [0, 1, 3]})
    with pytest.raises(ValueError, match="seed = -1"):
        SweepSpec(seed=-1)


def test_output_paths_are_checked_before_the_run(tmp_path):
    a_file = tmp_path / "file"
    a_file.write_text("x")
    for out, words in ((tmp_path, ["is a directory"]), (a_file / "s.csv", ["cannot write"]),
                       ("/proc/no/such.csv", ["cannot write"])):
        proc = _cli(*SLOW_ARGS, "--scheduler", "serial", "--out", str(out))
        _one_line_error(proc, "--out", *words)  # at once: the slow sweep never started
    proc = _cli("--grid", "v=1,2", "--out", str(tmp_path / "s.csv"), "--plot", str(tmp_path))
    _one_line_error(proc, "--plot")


# --- streaming, interruption, resuming (in process) ----------------------------------------
from restitution.sweep.backends import PackageBackend


class _Interrupting(PackageBackend):
    """The package back end raising KeyboardInterrupt (as Ctrl-C would) on its n-th chunk."""

    def __init__(self, n):
        super().__init__()
        self.n, self.calls = n, 0

    def evaluate(self, *args):
        self.calls += 1
        if self.calls == self.n:
            raise KeyboardInterrupt
        return super().evaluate(*args)


def test_serial_interrupt_keeps_finished_chunks_and_resume_completes(tmp_path):
    spec = SweepSpec(pairs=["s2_tool_steel/al_6061", "table4:A2"], grid={"v": "geomspace:0.1:10:30", "t/d": "0.2,1,5"},
                     random={"sphere.E": {"normal_rel": 0.05}}, samples=5, seed=2)
    whole = run_sweep(spec, scheduler="serial", chunk_size=100)
    backend = _Interrupting(4)
    with pytest.raises(SweepInterrupted) as info:
        run_sweep(spec, backend, scheduler="serial", chunk_size=100, parts=tmp_path / "p")
    partial = info.value.result
    assert len(partial) == 300 and info.value.missing == spec.n_cases - 300
    assert len(list((tmp_path / "p").glob("chunk-*.npz"))) == 3
    assert np.array_equal(partial["case"], np.arange(300))
    resumed = run_sweep(spec, "package", scheduler="serial", chunk_size=7, parts=tmp_path / "p", resume=True)
    assert resumed.info["processes"] == 1 and resumed.n_chunks == 9  # the parts' chunk size is kept
    assert np.array_equal(resumed["pair"], whole["pair"])
    assert all(v <= TOL for v in compare_results(resumed, whole).values())
    # parts of another sweep are refused, not mixed in
    other = SweepSpec(**{**spec.as_dict(), "seed": 3})
    with pytest.raises(ValueError, match="another sweep"):
        run_sweep(other, scheduler="serial", parts=tmp_path / "p", resume=True)


# --- the CLI interrupted by SIGINT in a child process -------------------------------------
@pytest.fixture(scope="module")
def slow_reference():
    return run_sweep(SweepSpec(**SLOW_SPEC), scheduler="serial", chunk_size=30)


def _interrupt_after_chunks(args, parts: Path, n_chunks: int, cwd):
    proc = subprocess.Popen([PYTHON, "-m", "restitution.sweep", *args], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, cwd=cwd, env=ENV)
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and proc.poll() is None:
        if len(list(parts.glob("chunk-*.npz"))) >= n_chunks:
            break
        time.sleep(0.05)
    assert proc.poll() is None, "the sweep ended before it could be interrupted"
    import psutil

    children = psutil.Process(proc.pid).children(recursive=True)  # Dask's workers, if any
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=120)
    gone, alive = psutil.wait_procs(children, timeout=30)
    assert not alive, f"orphan processes after the interrupt: {alive}"
    return proc.returncode, out, err


@pytest.mark.slow
@pytest.mark.parametrize("scheduler", [["--scheduler", "serial"], ["--scheduler", "local", "--workers", "2"]],
                         ids=["serial", "localcluster2"])
def test_cli_sigint_writes_what_is_done_and_resume_completes(tmp_path, slow_reference, scheduler):
    out = tmp_path / "s.csv"
    args = [*SLOW_ARGS, *scheduler, "--out", str(out)]
    rc, stdout, stderr = _interrupt_after_chunks(args, tmp_path / "s.csv.parts" / "package", 4, tmp_path)
    assert rc == 130, stderr
    assert "Traceback" not in stderr, stderr
    partial = read_table(out)
    n_done = partial["case"].size
    assert 4 * 30 <= n_done < 1200
    assert f"{1200 - n_done:,} of 1,200 cases are missing" in stderr and "--resume" in stderr
    ref = slow_reference.columns
    for name in ("e", "zener.tau0"):  # the finished cases are right
        sel = partial["case"]
        assert np.allclose(partial[name], ref[name][sel], rtol=TOL, atol=0), name
    rc2 = subprocess.run([PYTHON, "-m", "restitution.sweep", *args, "--resume"], capture_output=True, text=True,
                         cwd=tmp_path, env=ENV, timeout=300)
    assert rc2.returncode == 0, rc2.stderr
    table = read_table(out)
    assert np.array_equal(table["case"], np.arange(1200))
    assert all(v <= TOL for v in compare_results(table, ref).values())
    assert not (tmp_path / "s.csv.parts").exists()  # whole table written: parts removed


# --- validity ---------------------------------------------------------------------------
def test_summary_counts_and_cli_warns_about_out_of_range_cases(tmp_path):
    spec = SweepSpec(pairs=["s2_tool_steel/al_6061"], grid={"v": "0.5,1,2000", "t/d": "0.05,1"})
    res = run_sweep(spec, scheduler="serial")
    counts = res.out_of_range()
    # v = 2000 m/s: V* far beyond 1000 (V_c of this pair is ~0.1 m/s); t/d = 0.05: lambda > 1.5
    assert counts["jgm.in_range"] == 2
    assert counts["zener.in_range"] >= 2
    assert counts["valid"] == int(np.count_nonzero(~res["valid"]))
    assert f"({counts['valid']} outside" in res.summary()
    assert res.warning().startswith(f"warning: {counts['valid']} of 6 cases")
    proc = _cli("--pair", "s2_tool_steel/al_6061", "--grid", "v=0.5,1,2000", "--grid", "t/d=0.05,1",
                "--scheduler", "serial", "--no-plot", "--out", str(tmp_path / "s.csv"))
    assert proc.returncode == 0, proc.stderr
    assert "warning:" in proc.stderr and "outside the models' validated ranges" in proc.stderr
    table = read_table(tmp_path / "s.csv")
    assert {"valid", "jgm.in_range", "zener.in_range"} <= set(table)
    clean = _cli("--pair", "s2_tool_steel/al_6061", "--grid", "v=1,2", "--scheduler", "serial", "--no-plot",
                 "--out", str(tmp_path / "c.csv"))
    assert clean.returncode == 0 and "warning" not in clean.stderr


def test_progress_when_redirected_is_one_final_line(tmp_path):
    proc = _cli("--grid", "v=1,2,3", "--scheduler", "serial", "--no-plot", "--out", str(tmp_path / "s.csv"))
    assert proc.returncode == 0
    lines = proc.stderr.strip().splitlines()
    assert lines == ["[serial] 1/1 chunks done in " + lines[0].split(" in ")[1]], proc.stderr
    assert "\r" not in proc.stderr
    assert any(line.startswith("3 cases with the package back end") for line in proc.stdout.splitlines())


def test_cor_map_title_fits_a_single_pair(tmp_path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from restitution.sweep.plot import fit_title

    title = ("Apparent COR e (Green 2022), 2000 cases; red dashes: edge of the validated range "
             "(lambda <= 1.5, V* <= 1000)")
    fig = plt.figure(figsize=(5.4, 3.9))  # the width plot_cor_map gives one pair
    text = fit_title(fig, title)
    box = text.get_window_extent(fig.canvas.get_renderer())
    assert 0 <= box.x0 and box.x1 <= fig.bbox.width  # was clipped on both sides
    assert "\n" in text.get_text() and text.get_text().replace("\n", " ") == title
    plt.close(fig)
    spec = SweepSpec(pairs=["s2_tool_steel/al_6061"], grid={"v": "geomspace:0.1:100:8", "t/d": "geomspace:0.05:5:6"})
    assert run_sweep(spec, scheduler="serial").plot(tmp_path / "map.png").stat().st_size > 10_000


def test_fmu_back_end_refuses_codes_that_would_wrap(impact_fmu):
    """A case table built elsewhere, with zener_method = 2**32 + 1: ctypes' int32 made it 1."""
    from restitution.sweep.backends import get_backend

    cases = SweepSpec(grid={"v": "1,2"}).cases()
    cases["zener_method"] = np.array([1.0, 2.0 ** 32 + 1])
    backend = get_backend("fmu", impact_fmu)
    with pytest.raises(ValueError, match=r"zener_method = 4294967297.0 is out of range"):
        backend.evaluate(cases, backend.local_payload())
