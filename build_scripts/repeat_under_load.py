#!/usr/bin/env python3
"""Run one pytest node N times while K busy-loop processes load the cores, and report each run.

A test that passes alone may fail when the machine is busy (a timing window that a loaded scheduler
widens: an interrupt landing during a transfer, a worker that starts late). This runs the node N times
in ONE pytest process (the session fixtures, such as the FMUs ``built_fmus`` builds, are made once), with
K processes spinning ``while True: pass`` beside it, and prints per run: passed / failed / skipped, its
time, and every line a child process wrote to stderr after a line starting with "interrupted" (what a
sweep says after Ctrl-C: anything after it, a worker's traceback or a distributed log line, is a symptom).

    .venv/bin/python build_scripts/repeat_under_load.py NODE [-n 20] [-k 2] [--max-minutes 15] [--show-stderr]

NODE is a pytest node id, e.g.
``"tests/sweep/test_sweep_streaming.py::test_cli_ctrl_c_writes_what_is_done_and_resume_completes[localcluster2-fmu]"``
(quote it: the brackets). K defaults to the number of cores. The runs stop at the first one that starts
after ``--max-minutes`` (the runs done are reported; the busy loops are always ended). Exit status 0 when
every run that ran passed and none was left out, 1 otherwise.

How: this file is also the pytest plugin (``-p repeat_under_load``, found through PYTHONPATH): with
REPEAT_UNDER_LOAD_COUNT = N it repeats the collected items N times, records each run's outcome and
duration, and keeps the stderr of every child process the test reads through ``Popen.communicate``
(``subprocess.run`` included) in the JSON file REPEAT_UNDER_LOAD_LOG names.
"""
from __future__ import annotations

import argparse
import json
import os
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
COUNT_ENV, LOG_ENV, DEADLINE_ENV = "REPEAT_UNDER_LOAD_COUNT", "REPEAT_UNDER_LOAD_LOG", "REPEAT_UNDER_LOAD_DEADLINE"
#: The line after which a child's stderr is reported: what the sweep prints when Ctrl-C stops it.
MARK = "interrupted"

# ---------------------------------------------------------------------------------------------------
# the pytest plugin (active only when REPEAT_UNDER_LOAD_COUNT is set)

_RUNS: list[dict] = []
_CURRENT: dict | None = None


def _patch_communicate() -> None:
    """Keep the stderr every child process returns through Popen.communicate in the current run."""
    original = subprocess.Popen.communicate
    if getattr(original, "_repeat_under_load", False):
        return

    def communicate(self, *args, **kwargs):
        out, err = original(self, *args, **kwargs)
        if err and _CURRENT is not None:
            _CURRENT["stderr"].append(err if isinstance(err, str) else err.decode("utf-8", "replace"))
        return out, err

    communicate._repeat_under_load = True
    subprocess.Popen.communicate = communicate


def pytest_configure(config):
    if os.environ.get(COUNT_ENV):
        _patch_communicate()


def pytest_collection_modifyitems(session, config, items):
    count = int(os.environ.get(COUNT_ENV) or 0)
    if count > 1:  # a new item per run (an item runs once: its fixtures' values stay on it)
        items[:] = [item if k == 0 else _copy(item) for k in range(count) for item in items]


def _copy(item):
    """A new test item of the same function and parameters as ``item``."""
    return type(item).from_parent(item.parent, name=item.name, callspec=getattr(item, "callspec", None),
                                  callobj=item.obj, fixtureinfo=item._fixtureinfo, keywords=item.keywords,
                                  originalname=item.originalname)


def pytest_runtest_protocol(item, nextitem):
    global _CURRENT
    if not os.environ.get(COUNT_ENV):
        return None
    deadline = float(os.environ.get(DEADLINE_ENV) or "inf")
    if time.time() > deadline:  # past --max-minutes: this run is left out
        _RUNS.append({"nodeid": item.nodeid, "outcome": "not run (time limit)", "seconds": 0.0, "stderr": []})
        return True
    _CURRENT = {"nodeid": item.nodeid, "outcome": "passed", "seconds": 0.0, "stderr": [], "longrepr": ""}
    _RUNS.append(_CURRENT)
    start = time.monotonic()
    try:
        from _pytest.runner import runtestprotocol

        item.ihook.pytest_runtest_logstart(nodeid=item.nodeid, location=item.location)
        runtestprotocol(item, nextitem=nextitem)
        item.ihook.pytest_runtest_logfinish(nodeid=item.nodeid, location=item.location)
    finally:
        _CURRENT["seconds"] = time.monotonic() - start
        _CURRENT = None
    return True


def pytest_runtest_logreport(report):
    if _CURRENT is None:
        return
    if report.failed:
        _CURRENT["outcome"] = "failed"
        _CURRENT["longrepr"] += f"[{report.when}] {report.longreprtext[-4000:]}\n"
    elif report.skipped and _CURRENT["outcome"] == "passed":
        _CURRENT["outcome"] = "skipped"


def pytest_sessionfinish(session, exitstatus):
    log = os.environ.get(LOG_ENV)
    if log and os.environ.get(COUNT_ENV):
        Path(log).write_text(json.dumps(_RUNS, indent=1), encoding="utf-8")


# ---------------------------------------------------------------------------------------------------
# the command


def after_mark(stderr_texts: list[str]) -> list[str]:
    """The lines after the first line starting with "interrupted" in each child's stderr."""
    lines = []
    for text in stderr_texts:
        rows = text.splitlines()
        marks = [k for k, row in enumerate(rows) if row.lstrip().startswith(MARK)]
        if marks:
            lines += [row for row in rows[marks[0] + 1:] if row.strip()]
    return lines


def start_load(k: int) -> list[subprocess.Popen]:
    """K busy-loop processes, each in a session of its own."""
    return [subprocess.Popen([sys.executable, "-c", "while True: pass"], start_new_session=True,
                             stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            for _ in range(k)]


def stop_load(procs: list[subprocess.Popen]) -> None:
    for proc in procs:  # by pid, each one started here
        if proc.poll() is None:
            proc.kill()
    for proc in procs:
        proc.wait(timeout=30)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("node", nargs="+", help="pytest node id (quote it); several: each is repeated")
    parser.add_argument("-n", "--runs", type=int, default=20, help="how many runs (default 20)")
    parser.add_argument("-k", "--load", type=int, default=os.cpu_count() or 1,
                        help="busy-loop processes beside the runs (default: the number of cores)")
    parser.add_argument("--max-minutes", type=float, default=15.0,
                        help="start no run after this many minutes (default 15)")
    parser.add_argument("--show-stderr", action="store_true", help="print the children's whole stderr of a failed run")
    args = parser.parse_args(argv)
    if args.runs < 1 or args.load < 0:
        parser.error("--runs must be >= 1 and --load >= 0")
    if signal.getsignal(signal.SIGINT) == signal.SIG_IGN:
        # started in the background by a non-interactive shell (`cmd &`, nohup): SIGINT is ignored here and,
        # inherited, in every child, so a test's Ctrl-C (os.killpg(..., SIGINT)) would never reach its sweep
        signal.signal(signal.SIGINT, signal.default_int_handler)
        print("SIGINT was ignored in this process (started in the background?): restored for the runs", flush=True)
    with tempfile.TemporaryDirectory(prefix="repeat_under_load_") as tmp:
        log = Path(tmp) / "runs.json"
        env = {**os.environ, COUNT_ENV: str(args.runs), LOG_ENV: str(log),
               DEADLINE_ENV: str(time.time() + 60 * args.max_minutes),
               "PYTHONPATH": os.pathsep.join([str(ROOT / "build_scripts")] + [p for p in [os.environ.get("PYTHONPATH")] if p])}
        load = start_load(args.load)
        start = time.monotonic()
        try:
            print(f"{args.runs} runs of {' '.join(args.node)} beside {args.load} busy loops on {os.cpu_count()} cores", flush=True)
            proc = subprocess.run([sys.executable, "-m", "pytest", "-p", "no:cacheprovider", "-n", "0", "-q",
                                   "-p", "repeat_under_load", *args.node], cwd=ROOT, env=env, capture_output=True,
                                  text=True)
            load_avg = os.getloadavg()[0]
        finally:
            stop_load(load)
        runs = json.loads(log.read_text(encoding="utf-8")) if log.is_file() else []
    if not runs:
        print(f"no run recorded (pytest exit {proc.returncode}):\n{proc.stdout[-3000:]}\n{proc.stderr[-3000:]}")
        return 1
    for k, run in enumerate(runs, 1):
        print(f"run {k:>3}: {run['outcome']:<8} {run['seconds']:7.1f} s")
        for line in after_mark(run["stderr"]):
            print(f"         stderr after '{MARK}': {line}")
        if run["outcome"] == "failed":
            print("         " + run["longrepr"].strip().replace("\n", "\n         ")[-3000:])
            if args.show_stderr:
                print("         children's stderr:\n" + "\n".join(run["stderr"]))
    counts = {outcome: sum(run["outcome"] == outcome for run in runs) for outcome in dict.fromkeys(r["outcome"] for r in runs)}
    print(f"{counts.get('passed', 0)} of {len(runs)} runs passed ({', '.join(f'{n} {o}' for o, n in counts.items())}); "
          f"{time.monotonic() - start:.0f} s; load average (1 min) at the end {load_avg:.1f}")
    return 0 if counts.get("passed", 0) == len(runs) and len(runs) == args.runs * len(args.node) else 1


if __name__ == "__main__":
    sys.exit(main())
