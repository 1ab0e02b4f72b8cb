"""Run an FMI scenario in a child process, so that a crash fails one test and not the run.

:func:`run_child` executes Python code in a fresh interpreter with :data:`PRELUDE` (raw fmpy calls on
an unzipped FMU, every status collected instead of raised, every log message collected) and returns
the exit code, the JSON the code printed last with ``report(...)``, and stderr.
"""
from __future__ import annotations

import json
import subprocess
import sys
import textwrap
from dataclasses import dataclass

#: Prepended to every child script. ``FMU`` is the .fmu path, ``UNZIP`` its extraction.
PRELUDE = r'''
import ctypes, json, math, sys
from ctypes import byref, c_char_p, c_double, c_int, c_size_t, c_uint, c_void_p, POINTER
from fmpy import read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import (FMU2Slave, calloc, fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE,
                       fmi2CallbackFunctions, fmi2CallbackLoggerTYPE, free, fmi2FMUstate)

FMU, UNZIP, ARGS = sys.argv[1], sys.argv[2], sys.argv[3:]
MD = read_model_description(FMU)
VR = {v.name: v.valueReference for v in MD.modelVariables}
# the FMI type a variable is got and set with (an Enumeration with the Integer functions)
TYPE = {v.name: "Integer" if v.type == "Enumeration" else v.type for v in MD.modelVariables}
LOG = []  # (instance name, status, message) of every logger call


def _log(env, name, status, category, message):
    LOG.append((name.decode("utf-8", "replace") if name else None, int(status),
                message.decode("utf-8", "replace") if message else ""))


CALLBACKS = fmi2CallbackFunctions()
CALLBACKS.logger = fmi2CallbackLoggerTYPE(_log)
CALLBACKS.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
CALLBACKS.freeMemory = fmi2CallbackFreeMemoryTYPE(free)


def status(function, *args):
    """The fmi2Status of an fmpy call (fmpy raises on a status above fmi2Warning)."""
    try:
        function(*args)
        return 0
    except FMICallException as exc:
        return exc.status


def slave(name="child"):
    """An FMU2Slave of the FMU, loaded (not instantiated)."""
    return FMU2Slave(guid=MD.guid, unzipDirectory=UNZIP, modelIdentifier=MD.coSimulation.modelIdentifier,
                     instanceName=name)


def instance(name="child", parameters=None):
    """An instantiated, initialised FMU2Slave at t = 0 (parameters set in initialization mode)."""
    s = slave(name)
    s.instantiate(callbacks=CALLBACKS, loggingOn=True)
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    for key, value in (parameters or {}).items():
        if TYPE[key] == "Real":
            s.setReal([VR[key]], [value])
        else:
            s.setInteger([VR[key]], [value])
    s.exitInitializationMode()
    return s


def reals(s, names):
    return list(s.getReal([VR[n] for n in names]))


def report(**values):
    print("REPORT " + json.dumps(values, allow_nan=True), flush=True)


LOG3 = []  # (status, message) of every FMI 3.0 logger call (log3: an FMU3Slave's logMessage)


def log3(env, status, category, message):
    LOG3.append((int(status), message.decode("utf-8", "replace")))


def report_with_log3(**values):
    """report(), with the statuses the FMI 3.0 logger saw and its messages in order."""
    report(**values, statuses_logged=sorted({st for st, _m in LOG3}), messages=[m for _st, m in LOG3])
'''


@dataclass
class ChildResult:
    returncode: int
    report: dict | None
    stdout: str
    stderr: str

    def explain(self) -> str:
        return f"exit {self.returncode}\nstdout: {self.stdout[-2000:]}\nstderr: {self.stderr[-3000:]}"


def run_child(code: str, fmu, unzip, *args, timeout: float = 300, env=None) -> ChildResult:
    """Run PRELUDE + ``code`` with argv = [fmu, unzip, *args] (``ARGS``) in a new interpreter."""
    script = PRELUDE + "\n" + textwrap.dedent(code)
    proc = subprocess.run([sys.executable, "-c", script, str(fmu), str(unzip), *map(str, args)],
                          capture_output=True, text=True, timeout=timeout, env=env)
    found = None
    for line in proc.stdout.splitlines():
        if line.startswith("REPORT "):
            found = json.loads(line[len("REPORT "):])
    return ChildResult(proc.returncode, found, proc.stdout, proc.stderr)
