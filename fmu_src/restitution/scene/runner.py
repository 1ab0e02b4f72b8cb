"""Run a scene through SpherePlateImpact.fmu with an event-exact fmpy master.

Each drop (ball, plate, drop height) is a bouncing-ball simulation: free flight in closed
form, impact instants located exactly, and the FMU asked for the rebound **only at impact
events** (``v_approach`` is set at the impact; the first impact's speed is already set in
initialization mode, so the evaluation at fmi2ExitInitializationMode is the first impact's;
the fmi2DoStep calls that carry the FMU across each flight reuse the cached result).

Only the outputs the scene requested are read, plus ``v_rebound`` (the master needs it to
fly on) and the two Boolean outputs ``effects.plasticity`` / ``effects.plate_waves`` (to
report which effects each impact used):

================== ==================================
requested          FMU outputs read at each impact
================== ==================================
bounce_heights     (apex from v_rebound)
cor                e, jgm.e, zener.e
contact_durations  zener.t_contact
================== ==================================

The effect modes are the scene's (default ``auto``), with ``plate_waves = on`` when
contact durations are requested (a skipped Zener evaluation would report the Hertz
half-space duration). ``effects="all_on"`` runs the same scene with every effect on, the
reference the report compares against.
"""
from __future__ import annotations

import csv
import math
import os
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..fmu.models.sphere_plate_impact.variables import TABLE, fmu_values
from ..model import ZENER_SLOPE_BOUND, impact
from ..zener import ZENER_METHODS
from ..cosim.bouncing import Trajectory, impact_sequence
from ..cosim.interrupt import DeferredInterrupt
from .loader import MAX_BOUNCES, Drop, Scene, SceneError

__all__ = ["DropResult", "SceneResult", "SceneInterrupted", "DropWriter", "run_scene", "ensure_fmu",
           "open_instance", "COLUMNS", "READ_OUTPUTS", "VALIDITY", "drop_parameters"]

def _fmu_outputs(*names):
    """(FMU output names, result column names, units) of the outputs ``names``, from the interface table."""
    rows = [TABLE[name] for name in names]
    return names, tuple(v.key for v in rows), tuple(v.unit for v in rows)


#: requested output -> (FMU output names, result column names, units)
READ_OUTPUTS = {
    "bounce_heights": ((), ("apex",), ("m",)),  # from the impact speeds (host side), not an FMU output
    "cor": _fmu_outputs("e", "jgm.e", "zener.e"),
    "contact_durations": _fmu_outputs("zener.t_contact"),
}
#: column -> CSV header
COLUMNS = {"apex": "apex_m", "e": "e", "e_ep": "e_ep", "e_ze": "e_ze", "t_contact": "t_contact_s"}
#: Validity flags read at every impact (FMU Boolean outputs, also the CSV headers): inside
#: JGM's V* <= 1000 and Zener's lambda <= 1.5, and both.
VALIDITY = ("valid", "jgm.in_range", "zener.in_range")
_FLAGS = ("effects.plasticity", "effects.plate_waves", *VALIDITY)


class SceneInterrupted(KeyboardInterrupt):
    """An interrupted scene run: ``result`` holds the drops that finished."""

    def __init__(self, result: "SceneResult", n_drops: int):
        super().__init__(f"scene interrupted after {len(result.drops)} of {n_drops} drops")
        self.result = result
        self.n_drops = n_drops



# --- the FMU ---------------------------------------------------------------------------------

def ensure_fmu(fmu=None, rebuild: bool = False, log=None) -> Path:
    """Path of the FMU to run: ``fmu`` as given, else the default SpherePlateImpact.fmu
    (dist/ of a source checkout, a per-user cache otherwise), (re)built when missing, built from
    other sources, or when ``rebuild`` is true (:func:`restitution.fmu.default_fmu`)."""
    if fmu is not None:  # ValueError (one line naming --fmu) unless it is a SpherePlateImpact FMU
        from ..sweep.backends import check_impact_fmu

        return check_impact_fmu(fmu)
    from ..cosim.fmu import build_default_fmu

    return build_default_fmu(rebuild=rebuild, log=log)


def open_instance(fmu_path):
    """One FmuInstance reused for every drop of a scene (parameters are set per drop)."""
    from ..cosim import FmuInstance

    # Import scipy.integrate in the host before the FMU can: zener_method = ode imports it
    # lazily, and when that first import happens inside an FMU callback the process aborted
    # at exit ("corrupted double-linked list") in 5 of 100 runs here (0 of 100 with this import).
    import scipy.integrate  # noqa: F401

    return FmuInstance(fmu_path, instance_name="scene")


def drop_parameters(scene: Scene, drop: Drop, plasticity: str, plate_waves: str, zener_method: str) -> dict:
    return fmu_values(
        **_package_params(drop), restitution_model=scene.model.restitution_model, zener_method=zener_method, plasticity=plasticity,
        plate_waves=plate_waves, effect_tolerance=scene.model.effect_tolerance)


# --- results -----------------------------------------------------------------------------------

def apex_heights(v_rebound, gravity: float) -> np.ndarray:
    """Height reached after each impact [m] from the rebound speeds [m/s]: v^2 / (2 g), 0 where the
    ball does not leave the plate (v_rebound <= 0)."""
    v = np.asarray(v_rebound, dtype=float)
    return np.where(v > 0.0, v * v / (2.0 * gravity), 0.0)


@dataclass
class DropResult(Trajectory):
    """Every impact of one drop; arrays indexed by impact number."""

    drop: Drop
    time: np.ndarray  #: impact instants [s]
    v_approach: np.ndarray  #: [m/s]
    v_rebound: np.ndarray  #: [m/s]
    columns: dict  #: requested columns (apex, e, e_ep, e_ze, t_contact) -> arrays
    plasticity: np.ndarray  #: effects.plasticity at each impact
    plate_waves: np.ndarray  #: effects.plate_waves at each impact
    stop_reason: str  #: "v_min", "e<=0" or "max_bounces"
    gravity: float = 9.80665  #: [m/s2]
    validity: dict = field(default_factory=dict)  #: VALIDITY flag -> Boolean array, per impact

    @property
    def out_of_range(self) -> int:
        """Impacts outside the models' validated ranges (``valid`` false)."""
        valid = self.validity.get("valid")
        return 0 if valid is None else int(np.count_nonzero(~valid))

    @property
    def apex(self) -> np.ndarray:
        """Height the ball reaches after each impact [m] (0 where it does not leave the plate)."""
        return apex_heights(self.v_rebound, self.gravity)

    @property
    def cor(self) -> np.ndarray:
        """The COR applied at each impact, rebound over approach speed [1] (the FMU's e)."""
        return self.v_rebound / self.v_approach

    @property
    def at_rest(self) -> bool:
        """False when the drop stopped at its bounce limit with the ball still bouncing."""
        return self.stop_reason != "max_bounces"

    @property
    def rest_time(self) -> float:
        return float(self.time[-1]) if self.time.size else 0.0

    @property
    def drop_height(self) -> float:
        """[m]"""
        return self.drop.drop_height


@dataclass
class SceneResult:
    scene: Scene
    drops: list  #: DropResult per drop, in scene order
    plasticity_mode: str
    plate_waves_mode: str
    zener_method: str
    wall_time: float  #: seconds spent simulating the drops (FMU instantiation excluded)
    fmu_path: Path | None = None
    notes: list = field(default_factory=list)

    @property
    def n_impacts(self) -> int:
        return sum(d.n_impacts for d in self.drops)

    def effect_counts(self) -> dict:
        """Impacts in total and where each effect was active."""
        return {"impacts": self.n_impacts,
                "plasticity": int(sum(d.plasticity.sum() for d in self.drops)),
                "plate_waves": int(sum(d.plate_waves.sum() for d in self.drops))}

    def columns(self) -> list:
        return [c for out in self.scene.outputs for c in READ_OUTPUTS[out][1]]

    @property
    def out_of_range(self) -> int:
        """Impacts outside the models' validated ranges (``valid`` false), over every drop."""
        return sum(d.out_of_range for d in self.drops)

    def not_at_rest(self) -> list:
        """The drops that stopped at ``simulation.max_bounces`` with the ball still bouncing."""
        return [d for d in self.drops if not d.at_rest]

    def rest_warning(self) -> str | None:
        """What to do when some drops did not come to rest within their bounce limit, else None."""
        stuck = self.not_at_rest()
        if not stuck:
            return None
        sim = self.scene.simulation
        first = stuck[0]
        why = (" With e this close to 1 the model loses almost no energy per impact (little plastic deformation "
               "and almost none into the plate's waves), so the ball would bounce for a long time."
               if first.cor[-1] > 0.99 else "")
        return (f"warning: {len(stuck)} of {len(self.drops)} drops did not come to rest within "
                f"simulation.max_bounces = {sim.max_bounces} impacts (first: {first.drop.label}, last e = "
                f"{first.cor[-1]:.6g}, last rebound {first.v_rebound[-1]:.3g} m/s > v_min = {sim.v_min:g} m/s); "
                f"their rows end at the bounce limit.{why} Raise simulation.max_bounces (at most {MAX_BOUNCES}) "
                f"or simulation.v_min")

    def warning(self) -> str | None:
        """One line when any impact lies outside the validated ranges, else None."""
        n = self.out_of_range
        if not n:
            return None
        jgm = sum(int(np.count_nonzero(~d.validity["jgm.in_range"])) for d in self.drops)
        zener = sum(int(np.count_nonzero(~d.validity["zener.in_range"])) for d in self.drops)
        return (f"warning: {n} of {self.n_impacts} impacts lie outside the models' validated ranges "
                f"(valid = 0: {jgm} with V* > 1000, {zener} with lambda > 1.5); their e is an extrapolation")

    def write_csv(self, path) -> Path:
        """One row per impact: drop, impact instant and speed, requested outputs, effects used,
        validity flags (:class:`DropWriter`)."""
        with DropWriter(path, self.scene) as writer:
            for d in self.drops:
                writer.write(d)
        return Path(path)

    def write_summary_csv(self, path) -> Path:
        path = Path(path)
        with path.open("w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["ball", "plate", "drop_height_m", "impacts", "rest_time_s", "stop_reason",
                        "plasticity_impacts", "plate_wave_impacts", "out_of_range_impacts"])
            for d in self.drops:
                w.writerow([d.drop.ball.name, d.drop.plate.name, f"{d.drop.drop_height:.9g}", d.n_impacts,
                            f"{d.rest_time:.9g}", d.stop_reason, int(d.plasticity.sum()), int(d.plate_waves.sum()),
                            d.out_of_range])
        return path

    def summary(self) -> str:
        """Text table of the drops and of what was left out and why."""
        lines = [f"{self.scene.name}: {len(self.drops)} drops, {self.n_impacts} impacts, "
                 f"{self.wall_time:.3f} s (zener_method = {self.zener_method}, plasticity = {self.plasticity_mode}, "
                 f"plate_waves = {self.plate_waves_mode})"]
        width = max([len(d.drop.label) for d in self.drops] + [4])
        lines.append(f"  {'drop':<{width}}  impacts  plasticity  plate waves  out of range  stop")
        for d in self.drops:
            lines.append(f"  {d.drop.label:<{width}}  {d.n_impacts:7d}  {int(d.plasticity.sum()):10d}  "
                         f"{int(d.plate_waves.sum()):11d}  {d.out_of_range:12d}  {d.stop_reason}")
        lines += [f"  {line}" for line in explain(self)]
        lines += self._bounce_table()
        return "\n".join(lines)

    def _bounce_table(self, shown: int = 5) -> list:
        """Per drop, the height reached and the COR at its first ``shown`` impacts."""
        width = max([len(d.drop.label) for d in self.drops] + [4])
        n = min(shown, max([d.n_impacts for d in self.drops] + [0]))
        rows = [[f"{h * 1e3:.4g} ({e:.3g})" for h, e in zip(d.apex[:n], d.cor[:n])] for d in self.drops]
        cell = 2 + max([len(c) for row in rows for c in row] + [len(f"impact {n}")])
        lines = ["  bounce height after each impact [mm] (e [1]); every impact is in the CSV",
                 f"  {'drop':<{width}}" + "".join(f"{'impact ' + str(k + 1):>{cell}}" for k in range(n))]
        for d, row in zip(self.drops, rows):
            more = f"  ... {d.n_impacts - n} more" if d.n_impacts > n else ""
            lines.append(f"  {d.drop.label:<{width}}" + "".join(f"{c:>{cell}}" for c in row) + more)
        return lines

    def plot(self, path) -> Path:
        """One panel per requested output (bounce heights vs time, COR and contact durations vs speed)."""
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        outs = self.scene.outputs
        fig, axes = plt.subplots(len(outs), 1, figsize=(8, 3.2 * len(outs)), squeeze=False)
        colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
        for ax, out in zip(axes[:, 0], outs):
            balls = [b.name for b in self.scene.balls]
            for k, d in enumerate(self.drops):
                color = colors[k % len(colors)]
                style = ("-", "--", ":", "-.")[balls.index(d.drop.ball.name) % 4]
                if out == "bounce_heights":
                    t = np.linspace(0.0, d.rest_time * 1.02 if d.rest_time > 0 else 1.0, 2000)
                    ax.plot(t, d.height(t) * 1e3, style, color=color, lw=1, label=d.drop.label)
                elif out == "cor":
                    ax.plot(d.v_approach, d.columns["e"], "o-", color=color, ms=3, lw=1, label=d.drop.label)
                    ax.plot(d.v_approach, d.columns["e_ep"], "v:", color=color, ms=3, lw=1)
                    ax.plot(d.v_approach, d.columns["e_ze"], "^--", color=color, ms=3, lw=1)
                else:
                    ax.plot(d.v_approach, d.columns["t_contact"] * 1e6, "o-", color=color, ms=3, lw=1,
                            label=d.drop.label)
            if out == "bounce_heights":
                ax.set(xlabel="time [s]", ylabel="height [mm]", title="bounce heights")
                _readable_heights(ax, [d.apex for d in self.drops] + [[d.drop_height for d in self.drops]])
            elif out == "cor":
                ax.set(xlabel="approach speed [m/s]", ylabel="COR [1]",
                       title="COR: e (o, solid), e_ep (v, dotted), e_ze (^, dashed)")
                ax.axhline(0.0, color="0.6", lw=0.5)
            else:
                ax.set(xlabel="approach speed [m/s]", ylabel="contact duration [µs]", title="contact durations")
                ax.set_yscale("log")
            ax.grid(alpha=0.3)
        axes[0, 0].legend(fontsize=7, loc="best")
        fig.suptitle(f"{self.scene.name} (plasticity = {self.plasticity_mode}, plate_waves = {self.plate_waves_mode}, "
                     f"zener_method = {self.zener_method})", fontsize=9)
        fig.tight_layout()
        path = Path(path)
        fig.savefig(path, dpi=120)
        plt.close(fig)
        return path


def _readable_heights(ax, heights) -> None:
    """A logarithmic height axis [mm] when the bounces span more than a decade and a half, so that
    a 0.1 mm bounce after a 1 m drop stays visible; its floor is half the lowest bounce."""
    positive = np.concatenate([np.asarray(h, dtype=float).ravel() for h in heights]) * 1e3
    positive = positive[positive > 0.0]
    if positive.size and positive.max() > 30.0 * positive.min():
        ax.set_yscale("log")
        ax.set_ylim(positive.min() / 2.0, positive.max() * 1.5)
        ax.set_ylabel("height [mm], logarithmic")


class DropWriter:
    """The per-impact CSV of a scene, written drop by drop: each finished drop's rows are on
    disk (flushed and fsynced) before the next drop starts, so an interrupt loses none."""

    def __init__(self, path, scene: Scene):
        self.path = Path(path)
        self.cols = [c for out in scene.outputs for c in READ_OUTPUTS[out][1]]
        self.file = self.path.open("w", newline="")
        self.csv = csv.writer(self.file)
        self.csv.writerow(["ball", "plate", "drop_height_m", "impact", "time_s", "v_approach_m_s",
                           *(COLUMNS[c] for c in self.cols), "plasticity", "plate_waves", *VALIDITY])
        self._sync()

    def write(self, d: DropResult) -> None:
        flags = [d.validity.get(name, np.ones(d.n_impacts, bool)) for name in VALIDITY]
        for i in range(d.n_impacts):
            self.csv.writerow([d.drop.ball.name, d.drop.plate.name, f"{d.drop.drop_height:.9g}", i + 1,
                               f"{d.time[i]:.12g}", f"{d.v_approach[i]:.12g}",
                               *(f"{d.columns[c][i]:.12g}" for c in self.cols),
                               int(d.plasticity[i]), int(d.plate_waves[i]), *(int(f[i]) for f in flags)])
        self._sync()

    def _sync(self):
        self.file.flush()
        os.fsync(self.file.fileno())

    def close(self):
        self.file.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


# --- why effects were left out ---------------------------------------------------------------

def _package_params(drop: Drop) -> dict:
    return dict(**drop.ball.material.params("sphere"), sphere_d=drop.ball.diameter,
                **drop.plate.material.params("plate"), plate_t=drop.plate.thickness)


def critical_velocity_of(drop: Drop) -> float:
    """V_c [m/s] of the ball/plate pair, Eq. (6), from the package (host side, for the explanations only)."""
    return float(impact(0.0, **_package_params(drop), plasticity="off", plate_waves="off").V_c)


def zener_lambda_of(drop: Drop, v) -> np.ndarray:
    """Zener's lambda [1] of the drop's pair at the approach speeds ``v`` [m/s], Eq. (12), from the package."""
    return impact(np.asarray(v, dtype=float), **_package_params(drop), plasticity="off", plate_waves="off").lam


def explain(result: SceneResult) -> list[str]:
    """What was left out of the scene and why, computed host side from the impact speeds
    (the FMU is not asked for anything more)."""
    scene, tol = result.scene, result.scene.model.effect_tolerance
    counts = result.effect_counts()
    n = counts["impacts"]
    lines = []
    skipped = n - counts["plasticity"]
    if result.plasticity_mode == "off":
        lines.append("plasticity: off (scene setting)")
    elif skipped == 0:
        lines.append(f"plasticity: active at all {n} impacts")
    else:
        below = brittle = 0
        for d in result.drops:
            inactive = ~d.plasticity
            if d.drop.ball.material.brittle and d.drop.plate.material.brittle:
                brittle += int(inactive.sum())
            else:
                below += int(np.sum(inactive & (d.v_approach <= critical_velocity_of(d.drop))))
        small = skipped - below - brittle
        parts = [f"{brittle} where neither body can yield (both brittle, V* << 1)" if brittle else "",
                 f"{below} where V* <= 1" if below else "",
                 f"{small} where 1 - e_ep < effect_tolerance = {tol:g}" if small else ""]
        lines.append(f"plasticity: skipped at {skipped} of {n} impacts: " + "; ".join(p for p in parts if p))
    skipped = n - counts["plate_waves"]
    if result.plate_waves_mode == "off":
        lines.append("plate waves: off (scene setting)")
    elif result.plate_waves_mode == "on":
        why = ("contact durations requested: Zener's tau0 is needed" if "contact_durations" in scene.outputs
               and scene.model.plate_waves == "auto" else "plate_waves = on")
        lines.append(f"plate waves: computed at all {n} impacts ({why})")
    elif skipped == 0:
        lines.append(f"plate waves: needed at all {n} impacts ({ZENER_SLOPE_BOUND} lambda >= effect_tolerance = {tol:g})")
    else:
        lam_max = max(float(np.max(zener_lambda_of(d.drop, d.v_approach[~d.plate_waves])))
                      for d in result.drops if np.any(~d.plate_waves))
        lines.append(f"plate waves: skipped at {skipped} of {n} impacts: 1 - e_ze <= {ZENER_SLOPE_BOUND} lambda "
                     f"<= {ZENER_SLOPE_BOUND * lam_max:.2g} < effect_tolerance = {tol:g}")
    return lines


# --- the master ----------------------------------------------------------------------------------

def _run_drop(instance, scene: Scene, drop: Drop, params: dict, read_names, read_cols,
              interrupt: DeferredInterrupt | None = None) -> DropResult:
    sim = scene.simulation
    g, v_min = sim.gravity, sim.v_min
    slave = instance.slave
    # Reset, then set the parameters and the first impact's speed in initialization mode: the
    # evaluation at fmi2ExitInitializationMode is then the first impact's, not a wasted one.
    v_first = math.sqrt(2.0 * g * drop.drop_height)
    slave.reset()
    seen = len(instance.messages)
    slave.setupExperiment(startTime=0.0)
    slave.enterInitializationMode()
    try:
        instance.set(**params, v_approach=v_first)
        slave.exitInitializationMode()
        failure = None
    except Exception as exc:  # noqa: BLE001 - fmpy raises on fmi2Error; the FMU's log says which value
        failure = exc
    rejected = [text for status, text in instance.messages[seen:] if status >= _FMI2_ERROR]
    if rejected or failure is not None:
        try:  # reset and back in step mode (out of initialization and any error mode): it can be reused or freed
            instance.reset()
        except Exception:  # noqa: BLE001 - the error being reported matters, not this one
            pass
    if rejected:  # a value this FMU does not accept (the loader checks the domain; another FMU may differ)
        raise _rejected(scene, drop, rejected[0]) from None
    if failure is not None:
        raise failure

    vr_in = [instance.vr("v_approach")]
    real_names = ("v_rebound", *read_names)
    vr_real = [instance.vr(n) for n in real_names]
    vr_bool = [instance.vr(name) for name in _FLAGS]
    get_real, get_bool, set_real, do_step = slave.getReal, slave.getBoolean, slave.setReal, slave.doStep

    def rebound(v):  # only the requested outputs, and the effects used
        set_real(vr_in, [v])
        out = dict(zip(real_names, get_real(vr_real)))  # floats: checked for NaN by impact_sequence
        out["flags"] = get_bool(vr_bool)
        if interrupt is not None:
            interrupt.check()  # here, between FMU calls, never inside one
        return out

    try:
        events, stop = impact_sequence(rebound, drop.drop_height, g, v_min, sim.max_bounces,
                                       advance=do_step)  # flights need no evaluation (inputs unchanged)
    except ValueError as exc:
        raise RuntimeError(f"{drop.label}: {exc}; FMU log: {instance.last_message()}") from exc
    times = [t for t, _, _ in events]
    speeds = [v for _, v, _ in events]
    rows = [[out[n] for n in real_names] for _, _, out in events]
    flags = [out["flags"] for _, _, out in events]
    data = np.array(rows, dtype=float).reshape(len(rows), 1 + len(read_names))
    flags = np.array(flags, dtype=bool).reshape(len(rows), len(_FLAGS))
    v_reb = data[:, 0]
    columns = {}
    if "bounce_heights" in scene.outputs:
        columns["apex"] = apex_heights(v_reb, g)
    for j, col in enumerate(read_cols):
        columns[col] = data[:, 1 + j]
    return DropResult(drop=drop, time=np.array(times), v_approach=np.array(speeds), v_rebound=v_reb,
                      columns=columns, plasticity=flags[:, 0], plate_waves=flags[:, 1], stop_reason=stop,
                      gravity=g, validity={name: flags[:, 2 + k] for k, name in enumerate(VALIDITY)})


#: fmi2Status of a rejected value (fmi2Error; fmi2Fatal is 4).
_FMI2_ERROR = 3


def _rejected(scene: Scene, drop: Drop, message: str) -> SceneError:
    """A loader-style error naming the scene key behind the FMU variable that ``message`` (the FMU's
    log line, "<variable> = <value> is outside ...") is about."""
    variable = message.split(" = ", 1)[0].strip()
    i, j = scene.balls.index(drop.ball), scene.plates.index(drop.plate)
    if variable == "sphere.d":
        key = f"balls[{i}].diameter"
    elif variable.startswith("sphere."):
        key = f"balls[{i}].material"
    elif variable == "plate.t":
        key = f"plates[{j}].thickness"
    elif variable.startswith("plate."):
        key = f"plates[{j}].material"
    elif variable == "v_approach":
        key = f"balls[{i}].drop_heights[{drop.ball.drop_heights.index(drop.drop_height)}]"
    elif variable in ("effect_tolerance", "zener_method", "restitution_model", "plasticity", "plate_waves"):
        key = f"model.{variable}"
    else:
        key = variable
    return SceneError(f"the FMU rejects this value: {message}", key,
                      str(scene.path) if scene.path is not None else scene.name)


def run_scene(scene: Scene, fmu=None, *, effects: str = "scene", zener_method: str | None = None,
              instance=None, progress: bool | None = None, rebuild: bool = False, on_drop=None) -> SceneResult:
    """Simulate every drop of ``scene`` through the FMU.

    ``effects``: ``"scene"`` (the scene's modes, auto by default, see :meth:`Scene.effect_modes`)
    or ``"all_on"`` (plasticity = plate_waves = on, the reference). ``zener_method`` overrides
    the scene's. ``instance``: an open :class:`~restitution.cosim.FmuInstance` to reuse
    (else one is opened on ``fmu`` or the built/reused dist/ FMU, and closed afterwards).
    ``progress``: None or True: in a terminal, a bar once the run has taken a second; always a
    final line on stderr with the drops done; False: nothing. ``on_drop``: called with each
    :class:`DropResult` as soon as its drop finishes (e.g. :meth:`DropWriter.write`). An
    interrupt raises :class:`SceneInterrupted` with the finished drops.
    """
    if effects == "scene":
        plasticity, plate_waves = scene.effect_modes()
    elif effects == "all_on":
        plasticity, plate_waves = "on", "on"
    else:
        raise ValueError(f"effects = {effects!r} is not 'scene' or 'all_on'")
    method = zener_method or scene.model.zener_method
    if method not in ZENER_METHODS:
        raise ValueError(f"zener_method = {method!r} is not one of {ZENER_METHODS}")
    read_names = [n for out in scene.outputs for n in READ_OUTPUTS[out][0]]
    read_cols = [c for out in scene.outputs for c in READ_OUTPUTS[out][1] if c != "apex"]

    own = instance is None
    fmu_path = None
    if own:
        fmu_path = ensure_fmu(fmu, rebuild=rebuild)
        instance = open_instance(fmu_path)
    drops = scene.drops()
    results = []
    start = time.perf_counter()

    def result():
        return SceneResult(scene=scene, drops=results, plasticity_mode=plasticity, plate_waves_mode=plate_waves,
                           zener_method=method, wall_time=time.perf_counter() - start, fmu_path=fmu_path)

    bar = _progress(drops, scene, progress, method)
    try:
        with DeferredInterrupt() as interrupt:
            for drop in drops:
                interrupt.check()
                params = drop_parameters(scene, drop, plasticity, plate_waves, method)
                done = _run_drop(instance, scene, drop, params, read_names, read_cols, interrupt)
                results.append(done)
                if on_drop is not None:
                    on_drop(done)
                if bar is not None:
                    bar.set_postfix_str(f"{sum(r.n_impacts for r in results)} impacts", refresh=False)
                    bar.update(1)
    except KeyboardInterrupt:
        _final_line(bar, progress, scene, method, results, len(drops), start, "interrupted")
        raise SceneInterrupted(result(), len(drops)) from None
    finally:
        if own:
            instance.close()
    _final_line(bar, progress, scene, method, results, len(drops), start, "done")
    return result()


def _progress(drops, scene, progress, method):
    """A tqdm bar in a terminal (shown after a second); None when redirected or not wanted."""
    if progress is False or not sys.stderr.isatty():
        return None
    try:
        from tqdm import tqdm
    except ModuleNotFoundError:  # the bar is a convenience, not a requirement
        return None
    return tqdm(total=len(drops), desc=f"{scene.stem} ({method})", unit="drop", delay=1.0, leave=False,
                file=sys.stderr)


def _final_line(bar, progress, scene, method, results, n_drops, start, state):
    if bar is not None:
        bar.close()
    if progress is False:
        return
    sys.stdout.flush()
    print(f"{scene.stem} ({method}): {len(results)}/{n_drops} drops {state}, "
          f"{sum(r.n_impacts for r in results)} impacts, {time.perf_counter() - start:.3g} s", file=sys.stderr,
          flush=True)
