"""Sweeps lose nothing: finished chunks on disk as they complete, Ctrl-C (SIGINT to the
process group, as a terminal sends it) writes what is done and exits 130, --resume completes only
the missing chunks and gives the table of an uninterrupted run, for both back ends, serially and
on a 2-worker LocalCluster; guards before any work (case counts, axis sizes, memory budget or
streaming to disk, CLI integers, output paths, the FMU file); validity on every row, counted and
warned about; progress output in a terminal and redirected."""
import os
import resource
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from restitution.sweep import SweepSpec, compare_results, read_table, run_sweep
from restitution.sweep.__main__ import main as sweep_cli
from restitution.sweep.result import DiskSweepResult
from restitution.sweep.run import SweepInterrupted
from restitution.sweep.size import check_memory, plan_size, table_bytes
from restitution.sweep.spec import SizeError

from terminal import takes_ctrl_c, with_terminal_stderr

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


def _cli(*args, cwd=None, env=None, **kwargs):
    return subprocess.run([PYTHON, "-m", "restitution.sweep", *args], capture_output=True, text=True,
                          cwd=cwd, env=env or ENV, timeout=300, **kwargs)


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


def test_memory_budget_refuses_with_numbers_or_streams_to_disk(tmp_path):
    spec = SweepSpec(grid={"v": "linspace:0.1:1:1000"}, random={"sphere.E": {"normal_rel": 0.01}}, samples=10 ** 6)
    with pytest.raises(SizeError, match=r"1,000,000,000 cases would take .*GiB.*memory budget of 1 MiB"):
        check_memory(spec, budget=2 ** 20)
    small = SweepSpec(grid={"v": "1,2,3"})
    assert check_memory(small, budget=2 ** 20) == table_bytes(3) > 0
    assert table_bytes(10, ["e"]) < table_bytes(10)
    # over the budget but small enough for the disk: streamed, with the numbers
    mid = SweepSpec(random={"v": "uniform:1:2"}, samples=10 ** 4)
    plan = plan_size(mid, budget=2 ** 10, out=tmp_path / "s.csv")
    assert plan.stream and plan.memory == table_bytes(10 ** 4) and 0 < plan.disk <= plan.disk_free
    assert "streamed to disk chunk by chunk" in plan.describe()
    assert not plan_size(mid, out=tmp_path / "s.csv").stream  # within the default budget: in memory
    # too big for the disk as well (255 TB): refused, with both numbers
    huge = SweepSpec(random={"v": "uniform:1:2"}, samples=10 ** 12)
    with pytest.raises(SizeError, match=r"memory budget .* streamed to disk it would need .* free"):
        plan_size(huge, out=tmp_path / "s.csv")
    with pytest.raises(SizeError, match="--backend both compares the two tables in memory"):
        plan_size(mid, budget=2 ** 10, backends=2, out=tmp_path / "s.csv")
    with pytest.raises(SizeError, match="at most 100,000,000 per axis"):
        SweepSpec(grid={"v": {"linspace": [0.1, 1, 10 ** 9]}}).check_axes()
    with pytest.raises(SizeError, match="case numbers are 64-bit"):
        plan_size(SweepSpec(random={"v": "uniform:1:2"}, samples=10 ** 12,
                            grid={"t/d": {"linspace": [1, 2, 10 ** 7]}}), budget=2 ** 80, out=tmp_path / "s.csv")


@pytest.mark.parametrize("kwargs", [dict(chunk_size=-1), dict(chunk_size=0), dict(n_workers=0), dict(chunk_size=2.5)])
def test_run_sweep_refuses_sizes_that_silently_gave_nothing(kwargs):
    """The API as well as the CLI: chunk_size = -1 gave a table of 0 rows, 0 became the default."""
    with pytest.raises(ValueError, match="expected an integer >= 1"):
        run_sweep(SweepSpec(grid={"v": "1,2"}), scheduler="serial", **kwargs)


def _address_space(limit):
    return lambda: resource.setrlimit(resource.RLIMIT_AS, (limit, limit))


def test_cli_refuses_absurd_sizes_before_any_work(tmp_path):
    # 1e9 cases: 237 GiB in memory, about 1 TB streamed to disk (skip on a machine with that much free)
    if shutil.disk_usage(tmp_path).free > 10 ** 12:
        pytest.skip("this machine could stream a 1e9-case table to disk")
    proc = _cli("--random", "v=uniform:1:2", "--samples", "1000000000", "--out", str(tmp_path / "s.csv"))
    _one_line_error(proc, "1,000,000,000 cases", "memory budget", "streamed to disk it would need")
    grid = ["--grid", "v=linspace:0.1:1:65536", "--grid", "t/d=linspace:0.1:1:65536",
            "--grid", "sphere.E=linspace:1e9:2e9:65536", "--grid", "plate.E=linspace:1e9:2e9:65536"]
    proc = _cli(*grid, "--out", str(tmp_path / "s.csv"))
    _one_line_error(proc, "18,446,744,073,709,551,616 cases")  # was "0 cases"
    assert not (tmp_path / "s.csv").exists()
    # --dry-run answers from the sizes: with 2 GiB of address space, the 7.45 GiB of a built
    # 1e9-point axis (or the 80 GB of 1e10) cannot be allocated
    small_memory = _address_space(2 * 2 ** 30)
    proc = _cli("--grid", "v=linspace:0.1:1:1000000000", "--dry-run", preexec_fn=small_memory)
    assert proc.returncode == 0, proc.stderr
    assert "1,000,000,000 cases" in proc.stdout and "at most 100,000,000 per axis" in proc.stdout
    proc = _cli("--grid", "v=linspace:0.1:1:10000000000", "--grid", "t/d=linspace:1:2:10000000000", "--dry-run",
                preexec_fn=small_memory)
    assert proc.returncode == 0, proc.stderr
    assert "100,000,000,000,000,000,000 cases" in proc.stdout  # was 7,766,279,631,452,241,920
    proc = _cli("--random", "v=uniform:1:2", "--samples", "1000000", "--dry-run", preexec_fn=small_memory)
    assert proc.returncode == 0 and "1,000,000 cases" in proc.stdout, proc.stdout
    # 290 bytes a case: 35 eight-byte numbers (inputs, outputs, the pair label) and 10 one-byte Booleans
    assert "277 MiB (290,000,000 bytes) in memory, within the memory budget" in proc.stdout, proc.stdout
    proc = _cli("--grid", "v=1,2,3", "--dry-run", "--memory-budget", "500", "--out", str(tmp_path / "s.csv"))
    assert proc.returncode == 0 and "3 cases" in proc.stdout and "streamed to disk" in proc.stdout, proc.stdout


@pytest.mark.parametrize("args, words", [
    (["--chunk-size", "-1"], ["--chunk-size", "-1", "1 <= value"]),
    (["--chunk-size", "0"], ["--chunk-size", "0"]),
    (["--workers", "0"], ["--workers", "0"]),
    (["--seed", "-1"], ["--seed", "-1", "0 <= value"]),
    (["--samples", "0"], ["--samples"]),
    (["--memory-budget", "lots"], ["--memory-budget"]),
    (["--set", "zener_method=4294967297", "--backend", "fmu"], ["zener_method = 4294967297", "out of range"]),
    (["--grid", "v=arange:0:1:0"], ["arange step = 0"]),
    (["--grid", "v=geomspace:0:1:5"], ["geomspace needs first and last non-zero"]),
    (["--grid", "v"], ["expected NAME=VALUE", "'v'"]),
    (["no_such_spec.toml"], ["no_such_spec.toml", "No such file"]),
    (["list.json"], ["list.json", "expected a table", "list"]),
    (["pairs.toml"], ["pairs = 5", "expected a list"]),
    (["grid.toml"], ["grid = [1]", "expected a table"]),
    (["run.toml"], ["run = 3", "[run]"]),
    (["--backend", "both", "--columns", "e"], ["--columns must keep ok"]),
    (["--columns", "e,E"], ["--columns", "unknown column(s) ['E']"]),
    (["--backend", "fmu", "--fmu", "missing.fmu"], ["--fmu missing.fmu", "no such file"]),
    (["--backend", "fmu", "--fmu", "list.json"], ["--fmu list.json", "not an FMU"]),
    (["--backend", "fmu", "--fmu", "BouncingBall.fmu"], ["--fmu BouncingBall.fmu", "not a SpherePlateImpact FMU"]),
])
def test_cli_user_mistakes_are_one_line_errors(tmp_path, args, words, bouncing_ball_fmu):
    (tmp_path / "list.json").write_text("[1, 2]")
    (tmp_path / "pairs.toml").write_text("pairs = 5")
    (tmp_path / "grid.toml").write_text("grid = [1]")
    (tmp_path / "run.toml").write_text("run = 3")
    shutil.copy(bouncing_ball_fmu, tmp_path / "BouncingBall.fmu")
    grid = [] if "--grid" in args or args[0].endswith((".toml", ".json")) else ["--grid", "v=1,2"]
    proc = _cli(*args, *grid, "--no-plot", "--scheduler", "serial", "--out", str(tmp_path / "s.csv"), cwd=tmp_path)
    _one_line_error(proc, *words)
    assert not (tmp_path / "s.csv").exists() and not (tmp_path / "s.csv.parts").exists()


@pytest.fixture(scope="module")
def bouncing_ball_fmu(tmp_path_factory):
    """An FMU that is not a SpherePlateImpact FMU."""
    from restitution.fmu.builders import build_one

    return build_one("BouncingBall", tmp_path_factory.mktemp("ball"), guard=False)


def test_cli_unreachable_scheduler_is_one_line_error(tmp_path):
    env = {**ENV, "DASK_DISTRIBUTED__COMM__TIMEOUTS__CONNECT": "2s"}
    proc = _cli("--grid", "v=1,2", "--scheduler", "tcp://127.0.0.1:9", "--no-plot", "--out", str(tmp_path / "s.csv"),
                env=env)
    _one_line_error(proc, "--scheduler tcp://127.0.0.1:9", "cannot connect")


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
    for out, words in ((tmp_path, ["is a directory"]), (a_file / "s.csv", ["is not a directory"]),
                       ("/proc/no/such.csv", ["cannot write"])):
        proc = _cli(*SLOW_ARGS, "--scheduler", "serial", "--out", str(out))
        _one_line_error(proc, "--out", *words)  # at once: the slow sweep never started
    proc = _cli("--grid", "v=1,2", "--out", str(tmp_path / "s.csv"), "--plot", str(tmp_path))
    _one_line_error(proc, "--plot")


# --- streaming, interruption, resuming (in process) ----------------------------------------
from interrupting_backend import InterruptingBackend



def test_serial_interrupt_keeps_finished_chunks_and_resume_completes(tmp_path):
    spec = SweepSpec(pairs=["s2_tool_steel/al_6061", "table4:A2"], grid={"v": "geomspace:0.1:10:30", "t/d": "0.2,1,5"},
                     random={"sphere.E": {"normal_rel": 0.05}}, samples=5, seed=2)
    whole = run_sweep(spec, scheduler="serial", chunk_size=100)
    backend = InterruptingBackend(4)
    with pytest.raises(SweepInterrupted) as info:
        run_sweep(spec, backend, scheduler="serial", chunk_size=100, parts=tmp_path / "p")
    partial = info.value.result
    assert len(partial) == 300 and info.value.missing == spec.n_cases - 300
    assert len(list((tmp_path / "p").glob("chunk-*.parquet"))) == 3
    assert np.array_equal(partial["case"], np.arange(300))
    counting = InterruptingBackend(0)  # never interrupts; counts the chunks it evaluates
    resumed = run_sweep(spec, counting, scheduler="serial", chunk_size=7, parts=tmp_path / "p", resume=True)
    assert resumed.info["processes"] == 1 and resumed.n_chunks == 9  # the parts' chunk size is kept
    assert counting.calls == 9 - 3  # only the missing chunks are evaluated
    assert np.array_equal(resumed["pair"], whole["pair"])
    assert all(v <= TOL for v in compare_results(resumed, whole).values())
    # parts of another sweep are refused, not mixed in
    other = SweepSpec(**{**spec.as_dict(), "seed": 3})
    with pytest.raises(ValueError, match="another sweep"):
        run_sweep(other, scheduler="serial", parts=tmp_path / "p", resume=True)


@pytest.mark.parametrize("backend", ["package", "fmu"])
def test_ctrl_c_just_after_a_part_is_written_keeps_that_chunk_in_the_table(tmp_path, monkeypatch, backend,
                                                                            impact_fmu):
    """A real SIGINT sent the moment the third part file is on disk, before the run records the chunk as
    done (the window where a CI run's interrupted table had 11 chunks and its parts directory 12): the
    interrupted table has every chunk whose part exists, and the statistics saw the same chunks."""
    from restitution.sweep.parts import PartStore

    write = PartStore.write

    def write_then_ctrl_c(self, a, b, part):
        write(self, a, b, part)
        if a == 200:
            os.kill(os.getpid(), signal.SIGINT)

    monkeypatch.setattr(PartStore, "write", write_then_ctrl_c)
    spec = SweepSpec(pairs=["s2_tool_steel/al_6061"], grid={"v": "geomspace:0.1:10:10", "t/d": "0.2,1,5"},
                     random={"sphere.E": {"normal_rel": 0.05}}, samples=20, seed=4)
    seen = []
    with pytest.raises(SweepInterrupted) as info:
        run_sweep(spec, backend, fmu=impact_fmu if backend == "fmu" else None, scheduler="serial",
                  chunk_size=100, parts=tmp_path / "p", on_chunk=lambda a, b, columns: seen.append(a))
    on_disk = sorted(int(f.name.split("-")[1]) for f in (tmp_path / "p").glob("chunk-*.parquet"))
    assert on_disk == [0, 100, 200] and seen == on_disk
    assert np.array_equal(info.value.result["case"], np.arange(300))


def test_cli_resume_on_another_sweeps_chunks_is_one_line_error(tmp_path):
    run_sweep(SweepSpec(grid={"v": "1,2,3"}), scheduler="serial", parts=tmp_path / "s.csv.parts" / "package")
    proc = _cli("--grid", "v=1,2,4", "--resume", "--scheduler", "serial", "--no-plot", "--out", str(tmp_path / "s.csv"))
    _one_line_error(proc, "--resume", "belong to another sweep")
    assert not (tmp_path / "s.csv").exists()


def test_table_on_disk_when_over_the_memory_budget(tmp_path):
    """in_memory=False: only counts in memory; the table is streamed from the finished chunks, the
    same as the in-memory one (CSV and Parquet), also after an interrupt and a resume."""
    spec = SweepSpec(pairs=["s2_tool_steel/al_6061", "table4:A2"], grid={"v": "geomspace:0.1:3000:30", "t/d": "0.05,1,5"},
                     random={"sphere.E": {"normal_rel": 0.05}}, samples=5, seed=2)
    whole = run_sweep(spec, scheduler="serial", chunk_size=100)
    with pytest.raises(SweepInterrupted) as info:
        run_sweep(spec, InterruptingBackend(4), scheduler="serial", chunk_size=100, parts=tmp_path / "p", in_memory=False)
    partial = info.value.result
    assert isinstance(partial, DiskSweepResult) and partial.columns == {}
    assert len(partial) == 300 and info.value.missing == spec.n_cases - 300
    table = read_table(partial.write(tmp_path / "partial.csv"))
    assert np.array_equal(table["case"], np.arange(300))
    res = run_sweep(spec, scheduler="serial", chunk_size=7, parts=tmp_path / "p", resume=True, in_memory=False)
    assert isinstance(res, DiskSweepResult) and len(res) == spec.n_cases == len(whole)
    assert res.out_of_range() == whole.out_of_range() and res.out_of_range()["valid"] > 0
    assert res.summary().split(": ", 1)[1].split("; ", 1)[1] == whole.summary().split(": ", 1)[1].split("; ", 1)[1]
    assert res.warning() == whole.warning()
    whole.write(tmp_path / "whole.csv")
    assert (tmp_path / "whole.csv").read_bytes() == res.write(tmp_path / "disk.csv").read_bytes()
    for name, col in read_table(res.write(tmp_path / "disk.parquet")).items():
        ref = whole[name]
        assert np.array_equal(col, ref, equal_nan=ref.dtype.kind == "f"), name
    with pytest.raises(RuntimeError, match="no COR map"):
        res.plot(tmp_path / "map.png")


def test_cli_streams_a_table_over_the_budget_to_disk(tmp_path):
    args = ["--pair", "s2_tool_steel/al_6061", "--random", "v=uniform:0.1:3000", "--samples", "3000",
            "--chunk-size", "700", "--scheduler", "serial", "--columns", "e"]
    ref = _cli(*args, "--no-plot", "--out", str(tmp_path / "ref.csv"))
    assert ref.returncode == 0, ref.stderr
    proc = _cli(*args, "--memory-budget", "10K", "--out", str(tmp_path / "s.csv"))
    assert proc.returncode == 0, proc.stderr
    assert "over the memory budget" in proc.stderr and "streamed to disk chunk by chunk" in proc.stderr
    # random draws around one point: its plot would be the histogram of e, not written for a streamed table
    assert "no histogram of e" in proc.stderr and not (tmp_path / "s_hist.png").exists()
    assert not (tmp_path / "s_cor_map.png").exists()
    assert "warning:" in proc.stderr  # v up to 3 km/s: V* beyond 1000, counted from the chunks
    assert (tmp_path / "s.csv").read_bytes() == (tmp_path / "ref.csv").read_bytes()
    table = read_table(tmp_path / "s.csv")
    assert list(table) == ["case", "pair", "e", "valid", "zener.in_range", "jgm.in_range", "ok"]  # validity kept
    assert not (tmp_path / "s.csv.parts").exists()


# --- the CLI interrupted by Ctrl-C in a child process -------------------------------------
@pytest.fixture(scope="module")
def slow_reference(impact_fmu):
    """The slow sweep, uninterrupted, per back end (the resumed tables must equal these)."""
    spec = SweepSpec(**SLOW_SPEC)
    return {"package": run_sweep(spec, scheduler="serial", chunk_size=30),
            "fmu": run_sweep(spec, "fmu", fmu=impact_fmu, scheduler="serial", chunk_size=30)}


def _interrupt_after_chunks(args, parts: Path, n_chunks: int, cwd):
    """Run the CLI in a process group of its own and send SIGINT to the whole group once ``n_chunks``
    chunks are on disk: what Ctrl-C in a terminal does (the Dask workers get it too)."""
    proc = subprocess.Popen([PYTHON, "-m", "restitution.sweep", *args], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, cwd=cwd, env=ENV, start_new_session=True,
                            preexec_fn=takes_ctrl_c)
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and proc.poll() is None:
        if len(list(parts.glob("chunk-*.parquet"))) >= n_chunks:
            break
        time.sleep(0.05)
    assert proc.poll() is None, "the sweep ended before it could be interrupted"
    import psutil

    children = psutil.Process(proc.pid).children(recursive=True)  # Dask's workers, if any
    os.killpg(proc.pid, signal.SIGINT)
    out, err = proc.communicate(timeout=120)
    gone, alive = psutil.wait_procs(children, timeout=30)
    assert not alive, f"orphan processes after the interrupt: {alive}"
    return proc.returncode, out, err


@pytest.mark.slow
@pytest.mark.parametrize("backend", ["package", "fmu"])
@pytest.mark.parametrize("scheduler", [["--scheduler", "serial"], ["--scheduler", "local", "--workers", "2"]],
                         ids=["serial", "localcluster2"])
def test_cli_ctrl_c_writes_what_is_done_and_resume_completes(tmp_path, slow_reference, scheduler, backend,
                                                            impact_fmu):
    out = tmp_path / "s.csv"
    args = [*SLOW_ARGS, *scheduler, "--backend", backend, "--fmu", str(impact_fmu), "--out", str(out)]
    rc, stdout, stderr = _interrupt_after_chunks(args, tmp_path / "s.csv.parts" / backend, 4, tmp_path)
    assert rc == 130, stderr
    # no worker's KeyboardInterrupt, no FMU instance freed under a running chunk (a worker lost)
    assert "Traceback" not in stderr and "ERROR" not in stderr and "fmi2Fatal" not in stderr, stderr
    partial = read_table(out)
    n_done = partial["case"].size
    assert 4 * 30 <= n_done < 1200
    assert f"{1200 - n_done:,} of 1,200 cases are missing" in stderr and "--resume" in stderr
    ref = slow_reference[backend].columns
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


def test_serial_fmu_takes_ctrl_c_between_cases_not_at_the_chunks_end(impact_fmu):
    """The FMU back end checks for a held Ctrl-C between cases: a long chunk ends after the case
    in progress, not after its thousands of FMU calls."""
    from restitution.sweep import backends

    calls = []

    def check():
        calls.append(1)
        if len(calls) == 5:
            raise KeyboardInterrupt

    cases = SweepSpec(grid={"v": "linspace:0.1:2:5000"}).cases()
    backend = backends.get_backend("fmu", impact_fmu)
    backends._INTERRUPT_CHECK = check
    try:
        with pytest.raises(KeyboardInterrupt):
            backend.evaluate(cases, backend.local_payload())
    finally:
        backends._INTERRUPT_CHECK = None
        backends.release_fmus()
    assert len(calls) == 5


def test_fmu_instance_released_while_a_chunk_runs_is_freed_after_it(impact_fmu, tmp_path):
    """What a cancelled task meets on a worker: release_fmus() (client.run) while another thread still
    evaluates a chunk with the instance. Freeing it under the running chunk killed the worker; now the
    chunk stops at the next case and the instance is freed then. In a child process: it may crash."""
    script = tmp_path / "release.py"
    script.write_text(f"""
import threading, time
from restitution.sweep import SweepSpec, backends
cases = SweepSpec(grid={{"v": "linspace:0.1:2:200"}}, fixed={{"zener_method": "ode", "plate_waves": "on"}}).cases()
backend = backends.get_backend("fmu", {str(impact_fmu)!r})
payload = backend.local_payload()
errors = []
def work():
    try:
        backend.evaluate(cases, payload)
    except Exception as exc:
        errors.append(exc)
t = threading.Thread(target=work)
t.start()
while not any(i.busy for i in list(backends._INSTANCES.values())):  # inside the chunk (about 5 ms a case)
    time.sleep(0.01)
assert backends.release_fmus() == 1
t.join(60)
assert not t.is_alive()
print("stopped:", [str(e) for e in errors])
print("instances left:", len(backends._INSTANCES))
""")
    proc = subprocess.run([PYTHON, str(script)], capture_output=True, text=True, env=ENV, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert "FMU instance released" in proc.stdout and "instances left: 0" in proc.stdout, proc.stdout


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


def test_progress_in_a_terminal_ends_with_the_final_state_on_its_own_line(tmp_path):
    # long enough (about 40 ode chunks) that a terminal may show the redrawn line; not asserted
    rc, out, err = with_terminal_stderr([PYTHON, "-m", "restitution.sweep", *SLOW_ARGS, "--scheduler", "serial",
                                         "--out", str(tmp_path / "s.csv")], ENV)
    assert rc == 0, err
    lines = err.replace("\r\n", "\n").split("\n")
    final = [line.rsplit("\r", 1)[-1] for line in lines if "chunks done" in line]
    assert len(final) == 1 and final[0].startswith("[serial] 40/40 chunks done in "), err
    assert out.splitlines()[1].startswith("1200 cases with the package back end"), out  # not glued to the bar


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
    # the map itself: one pair crossing the validated range's edge (the long title), drawn as saved
    spec = SweepSpec(pairs=["s2_tool_steel/al_6061"], grid={"v": "geomspace:0.1:3000:8", "t/d": "geomspace:0.05:5:6"})
    titles = []
    close = plt.close

    def measure_then_close(fig=None):  # the saved figure's title, as drawn
        titles.append((fig._suptitle.get_text(), fig._suptitle.get_window_extent(fig.canvas.get_renderer()),
                       fig.bbox.width))
        close(fig)

    plt.close = measure_then_close
    try:
        assert run_sweep(spec, scheduler="serial").plot(tmp_path / "map.png").stat().st_size > 10_000
    finally:
        plt.close = close
    (text, box, width), = titles
    assert "validated range" in text
    assert 0 <= box.x0 and box.x1 <= width, (text, box, width)


@pytest.fixture(scope="module")
def cli_built_fmus(tmp_path_factory):
    """What `python -m restitution.fmu build --out DIR` makes (the pythonfmu FMUs, and the native ones
    where they can be built)."""
    out = tmp_path_factory.mktemp("built")
    proc = subprocess.run([PYTHON, "-m", "restitution.fmu", "build", "--out", str(out)], capture_output=True,
                          text=True, env=ENV, timeout=600)
    assert proc.returncode == 0, proc.stderr
    return out


@pytest.mark.parametrize("native_dir", ["fmi2", "fmi3"])
def test_cli_fmu_back_end_on_the_built_fmus_python_and_native(tmp_path, cli_built_fmus, native_dir):
    """--fmu DIR/SpherePlateImpact.fmu and DIR/fmi2/SpherePlateImpact.fmu (C only: the sweep refused it
    with a traceback, looking for the bundled Python package), or DIR/fmi3/SpherePlateImpact.fmu (FMI 3.0,
    the same C), give the same table, refused cases too."""
    native = cli_built_fmus / native_dir / "SpherePlateImpact.fmu"
    if not native.is_file():
        pytest.skip(f"no {native_dir} FMU built here")
    args = ["--pair", "s2_tool_steel/al_6061", "--grid", "v=geomspace:0.1:100:10", "--grid", "t/d=0.05,1",
            "--random", "sphere.E=normal_rel:0.6", "--samples", "3", "--seed", "4", "--backend", "fmu",
            "--scheduler", "serial", "--no-plot"]
    tables = {}
    for name, fmu in (("python", cli_built_fmus / "SpherePlateImpact.fmu"), ("fmi2", native)):
        proc = _cli(*args, "--fmu", str(fmu), "--out", str(tmp_path / f"{name}.csv"))
        assert proc.returncode == 0 and "Traceback" not in proc.stderr, proc.stderr
        tables[name] = read_table(tmp_path / f"{name}.csv")
    assert np.count_nonzero(~tables["python"]["ok"]) > 0  # sphere.E drawn negative: refused by both
    assert np.array_equal(tables["python"]["ok"], tables["fmi2"]["ok"])
    assert all(v <= 1e-12 for v in compare_results(tables["fmi2"], tables["python"]).values())


def test_fmu_back_end_refuses_codes_that_would_wrap(impact_fmu):
    """A case table built elsewhere, with zener_method = 2**32 + 1: ctypes' int32 made it 1."""
    from restitution.sweep.backends import get_backend

    cases = SweepSpec(grid={"v": "1,2"}).cases()
    cases["zener_method"] = np.array([1.0, 2.0 ** 32 + 1])
    backend = get_backend("fmu", impact_fmu)
    with pytest.raises(ValueError, match=r"zener_method = 4294967297.0 is out of range"):
        backend.evaluate(cases, backend.local_payload())
