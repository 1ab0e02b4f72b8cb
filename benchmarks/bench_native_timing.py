"""The timings of benchmarks/bench_native.py: interleaved batches, medians, ratios.

Every comparison runs its variants in turn, batch by batch (the first variant rotating from one
repeat to the next), so that a ratio compares batches run close together in time; a ratio is the
median over the repeats of the ratio within a repeat, a time the median of its batches. A batch runs
for a fixed CPU time of the timing thread (``time.thread_time``, ``CLOCK_THREAD_CPUTIME_ID`` in C),
after an untimed tenth of that to warm caches: other processes on a shared machine slow a batch
down (they share caches and cores) but their own run time is not counted.
"""
from __future__ import annotations

import statistics
import subprocess
import time
from dataclasses import dataclass, field

from bench_native_build import Built, Unzipped

#: Zener methods the C implements, with their FMU / C codes.
METHODS = {"exact": 1, "paper_fit": 2, "linear": 3}
STEP = 1e-3  # communication step of every round trip [s]


@dataclass
class Series:
    """Per-repeat seconds per operation of several variants, in the order they were measured."""

    batches: dict = field(default_factory=dict)  # label -> [seconds per operation, one per repeat]

    def add(self, label: str, seconds: float) -> None:
        self.batches.setdefault(label, []).append(seconds)

    def median(self, label: str) -> float:
        return statistics.median(self.batches[label])

    def ratios(self, num: str, den: str) -> list[float]:
        return [a / b for a, b in zip(self.batches[num], self.batches[den])]

    def ratio(self, num: str, den: str) -> float:
        """Median over the repeats of num / den within each repeat."""
        return statistics.median(self.ratios(num, den))

    def spread(self, num: str, den: str) -> tuple[float, float]:
        """Smallest and largest per-repeat ratio."""
        r = self.ratios(num, den)
        return min(r), max(r)


#: The outputs of the impact the goal against the precomputed C floor is about: e and v_rebound.
IMPACT_OUTPUTS = ("e", "v_rebound")


def _interfaces(model_description: str, only=None):
    """(value reference of v_approach, Real output vrs, Boolean output vrs), from the modelDescription;
    ``only``: just the outputs of these names."""
    from xml.etree import ElementTree as ET

    root = ET.fromstring(model_description)
    v, reals, bools = None, [], []
    for sv in root.find("ModelVariables"):
        vr, kind = int(sv.get("valueReference")), sv[0].tag
        if sv.get("name") == "v_approach":
            v = vr
        elif sv.get("causality") == "output" and (only is None or sv.get("name") in only):
            (reals if kind == "Real" else bools).append(vr)
    return v, reals, bools


# ------------------------------------------------------------------------------------------------
# Round trips through fmpy's FMU2Slave (raw calls, preallocated ctypes arrays)
# ------------------------------------------------------------------------------------------------
class _FmpyRoundTrip:
    """One initialised instance and its raw FMI functions: set v_approach, doStep, get every Real and
    every Boolean output, as tests/fmu/test_fmu_robustness.py's million-step test calls them."""

    def __init__(self, fmu: Unzipped, v_vr, real_vrs, bool_vrs):
        from fmpy.fmi2 import FMU2Slave, fmi2Boolean, fmi2Real, fmi2ValueReference

        self.slave = FMU2Slave(guid=fmu.guid, unzipDirectory=str(fmu.directory), modelIdentifier="SpherePlateImpact",
                               instanceName=f"bench_{fmu.label}")
        self.slave.instantiate()
        self.slave.setupExperiment(startTime=0.0)
        self.slave.enterInitializationMode()
        self.slave.exitInitializationMode()
        self.vr_v = (fmi2ValueReference * 1)(v_vr)
        self.vr_r = (fmi2ValueReference * len(real_vrs))(*real_vrs)
        self.vr_b = (fmi2ValueReference * len(bool_vrs))(*bool_vrs)
        self.value = (fmi2Real * 1)()
        self.reals, self.bools = (fmi2Real * len(real_vrs))(), (fmi2Boolean * len(bool_vrs))()
        self.t, self.k = 0.0, 0

    def run(self, n: int) -> None:
        s = self.slave
        set_real, do_step, get_real, get_boolean = s.fmi2SetReal, s.fmi2DoStep, s.fmi2GetReal, s.fmi2GetBoolean
        c = s.component
        vr_v, vr_r, vr_b, value, reals, bools = self.vr_v, self.vr_r, self.vr_b, self.value, self.reals, self.bools
        n_r, n_b = len(vr_r), len(vr_b)
        t, k = self.t, self.k
        bad = 0
        for _ in range(n):
            value[0] = 0.1 + 1e-6 * (k % 1000000)
            k += 1
            bad |= set_real(c, vr_v, 1, value) | do_step(c, t, STEP, 1) | get_real(c, vr_r, n_r, reals) \
                | get_boolean(c, vr_b, n_b, bools)
            t += STEP
        self.t, self.k = t, k
        if bad:
            raise RuntimeError("an FMI call did not return fmi2OK in the fmpy round trips")

    def close(self) -> None:
        self.slave.terminate()
        self.slave.freeInstance()


def _timed(run, seconds: float, chunk: int) -> float:
    """``run(chunk)`` repeatedly for ``seconds`` of thread CPU time (after a tenth of that untimed);
    seconds per operation."""
    for phase in (0.1 * seconds, seconds):
        t0, count = time.thread_time(), 0
        while True:
            run(chunk)
            count += chunk
            elapsed = time.thread_time() - t0
            if elapsed >= phase:
                break
    return elapsed / count


def fmpy_round_trips(built: Built, labels: tuple, reps: int, seconds: float) -> Series:
    """Seconds per round trip through fmpy for the FMUs ``labels`` (of native, floor, pythonfmu)."""
    fmus = {"native": built.native, "floor": built.floor, "pythonfmu": built.python}
    v, reals, bools = _interfaces(built.model_description)
    trips = {label: _FmpyRoundTrip(fmus[label], v, reals, bools) for label in labels}
    out = Series()
    try:
        for r in range(reps):
            for i in range(len(labels)):
                label = labels[(i + r) % len(labels)]
                out.add(label, _timed(trips[label].run, seconds, 32))
    finally:
        for trip in trips.values():
            trip.close()
    return out


# ------------------------------------------------------------------------------------------------
# Round trips in the plain C host (one process, every FMU instantiated once, batches interleaved)
# ------------------------------------------------------------------------------------------------
def c_host_round_trips(built: Built, labels: tuple, reps: int, seconds: float, each_call: bool = False,
                       outputs=None) -> Series:
    """Seconds per round trip in the C timing host, run as tests/hosts/test_c_host_impact.py runs its host:
    ``env -i PATH=/usr/bin:/bin`` (no virtual environment, PYTHONPATH or LD_PRELOAD; the pythonfmu
    FMU's guard finds its interpreter from resources/python_env.txt). ``each_call``: seconds per call
    of each of the four calls made alone (labels ``<fmu>/<fmi2 function>``). ``fmi3`` is the native FMI 3.0
    FMU, timed through its own fmi3 functions in the same process, batches interleaved with the others;
    ``precomputed`` the precomputed C floor (no FMU: the physics with its terms computed once). ``outputs``:
    the names of the outputs a round trip gets (default: every output; without a Boolean one, no GetBoolean)."""
    fmus = {"native": built.native, "floor": built.floor, "pythonfmu": built.python, "fmi3": built.fmi3}
    v, reals, bools = _interfaces(built.model_description, outputs)
    cmd = ["env", "-i", "PATH=/usr/bin:/bin", str(built.host), "each_call" if each_call else "round_trip",
           repr(seconds), str(reps), str(v), ",".join(map(str, reals)), ",".join(map(str, bools))]
    for label in labels:
        if label == "precomputed":
            cmd += [label, "0", "-", "-", "-"]
            continue
        f = fmus[label]
        cmd += [label, str(f.version), str(f.binary), f.resource_uri, f.guid]
    done = subprocess.run(cmd, capture_output=True, text=True, env={"PATH": "/usr/bin:/bin"},
                          timeout=600 + 10 * reps * seconds * len(labels))
    if done.returncode != 0:
        raise RuntimeError(f"the C timing host failed (exit {done.returncode}):\n{done.stderr[-3000:]}")
    out = Series()
    for line in done.stdout.splitlines():
        parts = line.split()
        if len(parts) == 4 and parts[0] == "BATCH":
            out.add(parts[1], float(parts[3]))
    return out


# ------------------------------------------------------------------------------------------------
# The C physics against the package's scalar call
# ------------------------------------------------------------------------------------------------
def physics_against_package(built: Built, reps: int, seconds: float) -> Series:
    """Seconds per impact of the C physics (``C <method>``) and of ``restitution.impact`` with Python
    floats, the pythonfmu FMU's evaluation (``package <method>``), for each method of :data:`METHODS`;
    each repeat runs, per method, the C loop (a subprocess) and then the package."""
    import restitution as r

    sphere = r.Sphere(r.MATERIALS["s2_tool_steel"], d=6.35e-3).params()
    plate = r.Plate(r.MATERIALS["al_6061"], t=6.35e-3).params()
    out = Series()
    for _ in range(reps):
        for method, code in METHODS.items():
            done = subprocess.run([str(built.physics_loop), repr(seconds), str(code)], check=True,
                                  capture_output=True, text=True)
            out.add(f"C {method}", float(done.stdout.split()[0]))
            state = {"k": 0}

            def run(n, method=method, state=state):
                k = state["k"]
                for i in range(k, k + n):
                    r.impact(0.1 + 1e-6 * (i % 1000000), **sphere, **plate, zener_method=method, validate=False)
                state["k"] = k + n

            out.add(f"package {method}", _timed(run, seconds, 16))
    return out
