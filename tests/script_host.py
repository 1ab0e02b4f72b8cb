"""The scripted plain C host, tests/c_host/fmi_script_host.c, for the FMI 2.0 and the FMI 3.0 FMUs: its
build (one source, ``-DFMI_VERSION=2|3``, for Linux with gcc or for win64 with mingw-w64 or zig) and what a
script needs to know of an FMU (its version, GUID or instantiation token, value references, which
script command gets and sets each variable: ``real``, ``integer``, ``enumeration`` or ``boolean``, and
for model exchange the sizes of its state and event-indicator vectors), and the model-exchange lines
every ME script shares (start an instance, read its events)."""
from __future__ import annotations

import math
import subprocess
import zipfile
from dataclasses import dataclass
from pathlib import Path
from xml.etree import ElementTree

HOST_SOURCE = Path(__file__).resolve().parent / "c_host" / "fmi_script_host.c"
WARNINGS = ["-O2", "-Wall", "-Wextra", "-Werror"]
MINGW = "x86_64-w64-mingw32-gcc"

#: the script command suffix of each modelDescription type (FMI 2.0 gets and sets an Enumeration as an
#: Integer, FMI 3.0 with the Int64 functions; the host knows which)
KINDS = {"Real": "real", "Integer": "integer", "Float64": "real", "Int32": "integer", "Enumeration": "enumeration",
         "Boolean": "boolean"}


def build_host(exe: Path, fmi_version: int = 2, cc="gcc", flags=()) -> Path:
    """Compile the host for ``fmi_version`` (2 or 3) with ``cc`` (gcc, or mingw-w64 for win64; or a
    restitution.fmu.builders.toolchains.Compiler, e.g. zig for win64) into ``exe``; a failed build raises with the
    compiler's messages."""
    command, env = ([cc], None) if isinstance(cc, str) else (list(cc.command), cc.env)
    cmd = [*command, *WARNINGS, *flags, f"-DFMI_VERSION={fmi_version}", "-o", str(exe), str(HOST_SOURCE)]
    if any("mingw32" in part or "windows" in part for part in command):
        cmd += ["-D__USE_MINGW_ANSI_STDIO=1"] + (["-static", "-static-libgcc"] if cc == MINGW else [])
    else:
        cmd += ["-ldl"]
    build = subprocess.run(cmd, capture_output=True, text=True, timeout=300, env=env)
    if build.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)}\n{build.stderr}")
    return exe


@dataclass(frozen=True)
class Interface:
    """What the script host needs of one FMU."""

    version: int  #: 2 or 3
    token: str  #: the GUID (FMI 2.0) or instantiation token (FMI 3.0)
    identifier: str  #: the co-simulation modelIdentifier
    vr: dict  #: name -> value reference
    kind: dict  #: name -> "real", "integer", "enumeration" or "boolean"
    n_states: int = 0  #: continuous states (model exchange): the derivatives the modelDescription declares
    n_indicators: int = 0  #: event indicators (model exchange)
    states: tuple = ()  #: the names of the continuous states, in the order of the state vector

    @property
    def binary_dirs(self) -> tuple[str, str]:
        """(Linux, Windows) folders of binaries/ for this FMI version."""
        return ("linux64", "win64") if self.version == 2 else ("x86_64-linux", "x86_64-windows")

    def set(self, slot: int, name: str, value) -> str:
        """The script line that sets ``name`` to ``value`` with the call its type needs."""
        kind = self.kind[name]
        text = repr(float(value)) if kind == "real" else str(int(value))
        return f"set_{kind} {slot} {self.vr[name]} {text}"

    def me_start(self, slot: int, name: str, settings=(), t0: float = 0.0) -> list[str]:
        """The lines that instantiate ``name`` (slot ``slot``) for model exchange, set ``settings`` (name ->
        value) in initialization mode, initialize (ending in event mode), update the discrete states once
        and enter continuous-time mode at ``t0``."""
        lines = [f"instantiate_me {name}", f"setup {slot} {t0!r}", f"enter_init {slot}"]
        lines += [self.set(slot, n, v) for n, v in dict(settings).items()]
        return lines + [f"exit_init {slot}", f"update_discrete {slot}", f"enter_ct {slot}"]

    def integrate(self, slot: int, t0: float, t_end: float, dt: float, tol: float) -> str:
        """The host's Heun integration with bisected state events (fmi_script_host.c: integrate)."""
        return f"integrate {slot} {self.n_states} {self.n_indicators} {t0!r} {t_end!r} {dt!r} {tol!r}"


def events(stdout: str, slot: int = 0) -> list[tuple[float, bool]]:
    """(time, continuous states changed) of each EVENT line of ``slot`` the host printed."""
    out = []
    for line in stdout.splitlines():
        f = line.split()
        if f and f[0] == "EVENT" and int(f[1]) == slot:
            out.append((float(f[2]), f[3] == "1"))
    return out


def interface(fmu: Path) -> Interface:
    with zipfile.ZipFile(fmu) as z:
        root = ElementTree.fromstring(z.read("modelDescription.xml"))
    version = 3 if root.get("fmiVersion", "").startswith("3") else 2
    vr, kind, by_index, by_vr, derivative_of = {}, {}, [], {}, {}
    for sv in root.find("ModelVariables"):
        tag = sv[0].tag if version == 2 else sv.tag  # FMI 2.0: <ScalarVariable><Real/>; FMI 3.0: <Float64/>
        vr[sv.get("name")] = int(sv.get("valueReference"))
        kind[sv.get("name")] = KINDS.get(tag, tag)
        by_index.append(sv.get("name"))
        by_vr[int(sv.get("valueReference"))] = sv.get("name")
        # the state a derivative is of: FMI 2.0 <Real derivative="index">, FMI 3.0 derivative="valueReference"
        of = (sv[0] if version == 2 else sv).get("derivative")
        if of is not None:
            derivative_of[sv.get("name")] = int(of)
    structure = root.find("ModelStructure")
    if version == 2:
        derivatives = [by_index[int(u.get("index")) - 1] for u in structure.findall("Derivatives/Unknown")]
        states = tuple(by_index[derivative_of[d] - 1] for d in derivatives)
        n_indicators = int(root.get("numberOfEventIndicators", "0"))
    else:
        derivatives = [by_vr[int(u.get("valueReference"))] for u in structure.findall("ContinuousStateDerivative")]
        states = tuple(by_vr[derivative_of[d]] for d in derivatives)
        n_indicators = len(structure.findall("EventIndicator"))
    token = root.get("guid") if version == 2 else root.get("instantiationToken")
    return Interface(version, token, root.find("CoSimulation").get("modelIdentifier"), vr, kind, len(states),
                     n_indicators, states)


def free_fall_contacts(h0: float, g: float, e: float, v_min: float):
    """Times [s] and approach speeds [m/s] of the contacts of a ball dropped from rest at h0 that rebounds
    with a constant COR e until it would leave slower than v_min (closed form: free fall, then flights
    of 2 v/g from the plate). The independent reference for every model-exchange run of BouncingBall."""
    v = math.sqrt(2.0 * g * h0)
    t = v / g
    times, speeds = [t], [v]
    while e * v >= v_min:
        v *= e
        t += 2.0 * v / g
        times.append(t)
        speeds.append(v)
    return times, speeds


def located_contact_bounds(n: int, g: float, e: float, resolution: float):
    """How late (upper bounds, [s] and [m/s]) a host that locates each contact at most ``resolution``
    after the crossing of the trajectory it integrates exactly (and never before it) finds the ``n``
    contacts of free_fall_contacts, and how much faster it finds the ball arriving. A contact found eps
    late adds g eps to the approach speed, so e g eps to the next rebound, which lengthens every later
    flight: with du_k the excess approach speed and dt_k the delay of contact k,
    du_1 = g r, dt_1 = r; dt_{k+1} = dt_k + 2 e du_k / g + r, du_{k+1} = e du_k + g r (every term
    largest where each contact is found the whole resolution late)."""
    du, dt = g * resolution, resolution
    delays, excess = [dt], [du]
    for _ in range(n - 1):
        dt = dt + 2.0 * e * du / g + resolution
        du = e * du + g * resolution
        delays.append(dt)
        excess.append(du)
    return delays, excess


#: BouncingBall's settings for the model-exchange runs of the script host: the contacts of
#: free_fall_contacts until the rest at the 8th (e v_7 = 0.509 m/s just above v_min, e v_8 = 0.41 below:
#: a margin far beyond any located speed's error)
BALL_ME = {"h0": 0.3, "g": 9.80665, "v_min": 0.5, "e": 0.8}
BALL_ME_OUTPUTS = ("t_impact", "v_impact")


def ball_me_script(fmu: Interface, dt: float, tol: float, t_end: float = 2.5, slot: int = 0) -> list[str]:
    """BouncingBall as model exchange in the script host: BALL_ME set, integrated to ``t_end`` by the host's
    Heun solver in steps ``dt``, events bisected to ``tol``; then the states, derivatives, indicators,
    nominals, the contact count, the last contact's time and speed and whether the ball is at rest."""
    n, z = fmu.n_states, fmu.n_indicators
    lines = fmu.me_start(slot, "ball", BALL_ME)
    return lines + [fmu.integrate(slot, 0.0, t_end, dt, tol), f"get_states {slot} {n}", f"get_derivatives {slot} {n}",
                    f"get_indicators {slot} {z}", f"get_nominals {slot} {n}", f"get_integer {slot} {fmu.vr['impacts']}",
                    f"get_real {slot} " + " ".join(str(fmu.vr[k]) for k in BALL_ME_OUTPUTS),
                    f"get_boolean {slot} {fmu.vr['at_rest']}", f"terminate {slot}", f"free {slot}"]


@dataclass(frozen=True)
class BallRun:
    """What ball_me_script printed: every status, the located contacts (events that changed the states),
    the last vectors and values read."""

    statuses: list
    contacts: list  #: times [s] of the events whose update changed the continuous states
    vectors: dict  #: "STATES", "DERIVATIVES", "INDICATORS", "NOMINALS" -> list of floats
    impacts: int
    t_impact: float
    v_impact: float
    at_rest: bool
    done: bool


def ball_run(stdout: str, slot: int = 0) -> BallRun:
    statuses, vectors, values = [], {}, {}
    for line in stdout.splitlines():
        f = line.split()
        if not f:
            continue
        if f[0] == "STATUS":
            statuses.append(tuple(f[1:]))
        elif f[0] in ("STATES", "DERIVATIVES", "INDICATORS", "NOMINALS"):
            vectors[f[0]] = [float(x) for x in f[2:]]
        elif f[0] in ("REAL", "INTEGER", "BOOLEAN"):
            values[f[0]] = values.get(f[0], []) + [float(f[3])]
    contacts = [t for t, changed in events(stdout, slot) if changed]
    reals = values.get("REAL", [math.nan, math.nan])
    return BallRun(statuses, contacts, vectors, int(values.get("INTEGER", [-1])[0]), reals[0], reals[1],
                   bool(values.get("BOOLEAN", [0])[0]), stdout.rstrip().endswith("DONE"))


def check_ball_run(run: BallRun, dt: float, tol: float) -> tuple[list, list]:
    """Asserts what any correct host run of ball_me_script shows: every call OK; the contacts at the
    closed-form times (free_fall_contacts), each found no earlier than the exact crossing (less 1e-12 s of
    rounding) and no later than located_contact_bounds for the resolution (``tol``, or ``dt`` without
    bisection: Heun's method is exact to rounding in free flight, so the location is the only error);
    the last approach speed likewise; the ball at rest on the plate with no more events. Returns the
    bounds (delays of the contact times [s], excess of the speeds [m/s]) for other comparisons."""
    times, speeds = free_fall_contacts(**BALL_ME)
    resolution = tol if tol > 0 else dt
    delays, excess = located_contact_bounds(len(times), BALL_ME["g"], BALL_ME["e"], resolution)
    assert run.done
    assert [s for s in run.statuses if s[2] != "OK"] == [], run.statuses
    assert len(run.contacts) == len(times) == run.impacts == 8, (run.contacts, times)
    for k, (got, want, late) in enumerate(zip(run.contacts, times, delays)):
        assert -1e-12 <= got - want <= late + 1e-12, (k, got, want, got - want, late)
    assert run.t_impact == run.contacts[-1]
    assert -1e-9 <= run.v_impact - speeds[-1] <= excess[-1] + 1e-9, (run.v_impact, speeds[-1], excess[-1])
    assert run.at_rest and run.vectors["STATES"] == [0.0, 0.0] and run.vectors["DERIVATIVES"] == [0.0, 0.0]
    assert run.vectors["INDICATORS"] == [1.0] and run.vectors["NOMINALS"] == [1.0, 1.0]
    return delays, excess
