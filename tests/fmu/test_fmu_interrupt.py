"""Ctrl-C and SIGTERM at random moments never turn into fmi2Fatal in a Python host (pythonfmu FMU behind
the guard).

A signal that reaches Python just before an FMI call used to stay pending: Python's C handler had set
its flag, and the next check of the interpreter's eval loop was inside the slave's code, where the
Python handler raised KeyboardInterrupt; pythonfmu answered fmi2Fatal ("[getBoolean]
PyObject_CallMethod"), the instance was latched for good and fmpy raised FMICallException instead of
KeyboardInterrupt: 5-10 % of the SIGINTs here, and 55 % of SIGTERMs with a Python handler (not held back
during calls at all). See "Ctrl-C and SIGTERM in a Python host" in
fmu_src/restitution/fmu/pythonfmu_guard/README.md for what the guard does about it.

Each scenario runs in a child process (tests/fmi_child.py) under a timeout. A sender thread in the child
fires the signal at the process at random moments, through a POSIX timer (on time whoever holds the
GIL) or os.kill (when the thread gets the GIL, often just as the loop released it for a call), while
the main thread loops set/get/doStep over Real, Integer and Boolean variables; the loop catches the
host-level exception and goes on. The sender fires the next signal only after the loop has counted the
previous one, so one is outstanding at a time and each must come back as one exception in the host's
code: none may give fmi2Fatal or be lost, none may escape the loop, and the values stay right.

* SIGINT with Python's default handler (KeyboardInterrupt), SIGINT and SIGTERM with Python handlers that
  raise, and SIGTERM with a handler the host installed after the guard's first call (in the place of the
  guard's relay): 250 signals each, 1,250 in all, about 0.3 s of signals per scenario;
* SIGINT and SIGTERM with the default action, from the start or set back after a handler: the process
  dies of the signal at once, even inside a call (the guard holds back only signals the host handles).
"""
from __future__ import annotations

import signal
import subprocess
import sys
import textwrap
import time

import pytest
from fmpy import extract

from fmi_child import PRELUDE, run_child
from toy_fmu import build_toy_fmu

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the guard is the Linux binary")

TOY_MODULE = "toy_interrupt_slave"  # tests/toys/

#: The child: PRELUDE + this, argv = [fmu, unzip, signal name, handler ("default" or "raise"), signals, seed].
LOOP_CODE = r"""
import os, random, signal, threading, time

SIGNUM = getattr(signal, ARGS[0])
HANDLER, N_SIGNALS, SEED = ARGS[1], int(ARGS[2]), int(ARGS[3])
H = 1e-3


class Terminated(Exception):
    pass


class Stale(Exception):
    pass


if HANDLER in ("raise", "changed"):
    def on_signal(signum, frame):
        raise Terminated(signum)
    if HANDLER == "changed":
        # the guard's relay takes the place of a first handler at the first call; the host then installs
        # its own between calls: that one must be the one signals reach (a Stale escapes the loop)
        def stale(signum, frame):
            raise Stale(signum)
        signal.signal(SIGNUM, stale)
        first = instance("first")
        first.setReal([VR["x"]], [2.0])
        first.doStep(0.0, H)
        first.terminate()
        first.freeInstance()
    signal.signal(SIGNUM, on_signal)
EXPECTED = KeyboardInterrupt if HANDLER == "default" else Terminated

# shared with the sender; plain attributes (the sender only reads what the loop publishes)
shared = {"sent": 0, "seen": -1, "lost": 0, "done": False}


class Timer:
    # a POSIX one-shot timer that sends SIGNUM to the process: it fires on time, whoever holds the GIL

    class sigevent(ctypes.Structure):  # struct sigevent of Linux x86_64: value, signo, notify, 48 bytes of union
        _fields_ = [("value", c_void_p), ("signo", c_int), ("notify", c_int), ("pad", ctypes.c_byte * 48)]

    class itimerspec(ctypes.Structure):
        _fields_ = [("interval_s", ctypes.c_long), ("interval_ns", ctypes.c_long),
                    ("value_s", ctypes.c_long), ("value_ns", ctypes.c_long)]

    def __init__(self):
        self.libc = ctypes.CDLL(None, use_errno=True)
        self.id = c_void_p()
        event = self.sigevent(None, SIGNUM, 0)  # SIGEV_SIGNAL
        if self.libc.timer_create(1, byref(event), byref(self.id)) != 0:  # CLOCK_MONOTONIC
            raise OSError(ctypes.get_errno(), "timer_create")

    def fire_in(self, seconds):
        ns = max(1, int(seconds * 1e9))
        spec = self.itimerspec(0, 0, ns // 1000000000, ns % 1000000000)
        if self.libc.timer_settime(self.id, 0, byref(spec), None) != 0:
            raise OSError(ctypes.get_errno(), "timer_settime")


def sender():
    rng = random.Random(SEED)
    timer = Timer()
    while shared["seen"] < 0:  # until the loop runs
        time.sleep(1e-3)
    for _ in range(N_SIGNALS):
        mode = rng.random()
        shared["sent"] += 1
        if mode < 0.6:  # a kernel timer: any moment of the loop, in C or in Python, inside or between calls
            timer.fire_in(rng.random() * 400e-6)
        else:  # from this thread, when it gets the GIL (often just after the loop released it for a call)
            if mode < 0.75:
                time.sleep(rng.random() * 2e-3)
            else:  # below sleep's resolution: spin a random number of microseconds
                end = time.perf_counter() + rng.random() * 300e-6
                while time.perf_counter() < end:
                    pass
            os.kill(os.getpid(), SIGNUM)
        deadline = time.monotonic() + 5.0
        while shared["seen"] < shared["sent"] and time.monotonic() < deadline:
            time.sleep(50e-6)
        if shared["seen"] < shared["sent"]:
            shared["lost"] += 1
            shared["seen"] = shared["sent"]
    shared["done"] = True


def expected_y(x):
    total = 0.0
    for k in range(1, 40):
        total += x / k
    return total


s = instance("interrupted")
t, k, caught, resync = 0.0, 0, 0, False
fatal, errors, wrong, where = [], [], 0, {}
thread = threading.Thread(target=sender, daemon=True)
started = time.monotonic()
thread.start()
finished = False
while not finished:  # its back jump comes only after an except clause, when no signal is outstanding
    try:
        while True:  # inside the try: a signal may come at any moment of it
            shared["seen"] = caught  # the next signal is sent only after this
            if shared["done"] or time.monotonic() - started > 60:
                finished = True
                break
            if resync:  # an exception may have come between doStep and t += H
                t = reals(s, ["time"])[0]
                resync = False
            x = 1.0 + k % 7
            s.setReal([VR["x"]], [x])
            s.setInteger([VR["n"]], [k % 5])
            s.setBoolean([VR["flag"]], [k % 2 == 0])
            s.doStep(t, H)
            t += H
            y, = reals(s, ["y"])
            positive, = s.getBoolean([VR["positive"]])
            count, = s.getInteger([VR["count"]])
            if y != expected_y(x) or bool(positive) != ((k % 2 == 0) != (y > 3.0)):
                wrong += 1
            k += 1
    except EXPECTED as exc:
        caught += 1
        resync = True
        frame = exc.__traceback__
        while frame.tb_next is not None:
            frame = frame.tb_next
        name = frame.tb_frame.f_code.co_name
        where[name] = where.get(name, 0) + 1
    except FMICallException as exc:
        caught += 1
        (fatal if exc.status == 4 else errors).append(exc.status)
        if exc.status == 4:  # latched for good: carry on with a new instance
            s = instance(f"fresh{len(fatal)}")
            t, resync = 0.0, False
        else:
            resync = True
thread.join(10)
# the instance still works: a few clean steps with checked values
for j in range(5):
    s.setReal([VR["x"]], [2.5 + j])
    s.doStep(t, H)
    t += H
    if reals(s, ["y"])[0] != expected_y(2.5 + j):
        wrong += 1
s.terminate()
s.freeInstance()
report(sent=shared["sent"], caught=caught, lost=shared["lost"], fatal=fatal, errors=errors, wrong=wrong,
       steps=k, where=where, seconds=time.monotonic() - started,
       fatal_log=[m for _, st, m in LOG if st == 4][:3])
"""


@pytest.fixture(scope="module")
def interrupt_fmu(tmp_path_factory):
    work = tmp_path_factory.mktemp("toy_interrupt")
    fmu = build_toy_fmu(work, TOY_MODULE)
    return fmu, extract(str(fmu), str(work / "unzipped"))


#: (signal, the host's handler, seed): 250 random moments each, 1,250 in all (about 0.3 s per scenario).
#: "changed": the host replaces a handler by its own after the guard's first call (what the guard holds
#: back is then the new one's).
SCENARIOS = [("SIGINT", "default", 1), ("SIGINT", "default", 2), ("SIGINT", "raise", 3), ("SIGTERM", "raise", 4),
             ("SIGTERM", "changed", 5)]
N_SIGNALS = 250


@pytest.mark.parametrize("signame, handler, seed", SCENARIOS)
def test_random_signals_never_give_fatal(interrupt_fmu, signame, handler, seed):
    fmu, unzip = interrupt_fmu
    run = run_child(LOOP_CODE, fmu, unzip, signame, handler, N_SIGNALS, seed, timeout=120)
    assert run.returncode == 0 and run.report is not None, run.explain()
    rep = run.report
    assert rep["sent"] == N_SIGNALS, rep
    assert rep["fatal"] == [] and rep["fatal_log"] == [], rep  # before the fix: 5-10 % of SIGINTs, 55 % of SIGTERMs
    assert rep["lost"] == 0 and rep["caught"] == rep["sent"], rep  # each signal: one exception in the host
    assert rep["errors"] == [] and rep["wrong"] == 0, rep


DEFAULT_ACTION_CODE = r"""
import signal
SIGNUM = getattr(signal, ARGS[0])
s = instance("defaulted")
t = 0.0
if ARGS[1] == "after_a_handler":  # the guard's relay in the place of a handler first, then the default action
    signal.signal(SIGNUM, lambda signum, frame: None)
    s.setReal([VR["x"]], [2.0])
    s.doStep(t, 1e-3)
    t += 1e-3
signal.signal(SIGNUM, signal.SIG_DFL)
print("RUNNING", flush=True)
while True:
    s.setReal([VR["x"]], [2.0])
    s.doStep(t, 1e-3)
    t += 1e-3
    s.getBoolean([VR["positive"]])
"""


@pytest.mark.parametrize("signame, delay, before", [("SIGTERM", 0.013, "none"), ("SIGTERM", 0.171, "none"),
                                                    ("SIGINT", 0.089, "none"), ("SIGTERM", 0.052, "after_a_handler"),
                                                    ("SIGINT", 0.127, "after_a_handler")])
def test_a_signal_with_the_default_action_ends_the_process(interrupt_fmu, signame, delay, before):
    """Nothing is held back then (no Python code would run for it): the process ends at once, also when
    the host had a handler at the guard's first calls and set the default action back since."""
    fmu, unzip = interrupt_fmu
    script = PRELUDE + "\n" + textwrap.dedent(DEFAULT_ACTION_CODE)
    proc = subprocess.Popen([sys.executable, "-c", script, str(fmu), str(unzip), signame, before],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert proc.stdout.readline().startswith("RUNNING")
        time.sleep(delay)
        proc.send_signal(getattr(signal, signame))
        out, err = proc.communicate(timeout=30)
    finally:
        proc.kill()
    assert proc.returncode == -getattr(signal, signame), f"exit {proc.returncode}: {err[-3000:]}"
    assert "Fatal" not in err and "Fatal" not in out
