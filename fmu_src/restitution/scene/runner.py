"""Run a scene through SpherePlateImpact.fmu with an event-exact fmpy master (``simulation.master =
"event_mode"``: the FMI 3.0 BouncingBall.fmu co-simulated with it in event mode, below).

Each drop (ball, plate, drop height) is a bouncing-ball simulation: free flight in closed
form, impact instants located exactly, and the FMU asked for the rebound **only at impact
events** (``v_approach`` is set at the impact; the first impact's speed is already set in
initialization mode, so the evaluation at the exit from initialization mode is the first impact's;
the steps that carry the FMU across each flight reuse the cached result). FMI 2.0 and FMI 3.0
FMUs alike (through :class:`~restitution.cosim.FmuInstance`).

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

With ``simulation.master = "event_mode"`` the flight is not the runner's: each drop co-simulates the
native FMI 3.0 BouncingBall.fmu with the FMU (:mod:`restitution.cosim.event_mode`) on a grid of
``simulation.communication_step``; the ball returns from each step at the contact instant, and in
event mode the FMU is asked for the rebound at that contact's speed (its ``e`` is read whether or not
``cor`` was requested: the ball needs it). The impacts are the same, within roundings.
"""
from __future__ import annotations

import math
import sys
import time
from pathlib import Path

import numpy as np

from ..fmu.models.sphere_plate_impact.variables import fmu_values
from ..zener import ZENER_METHODS
from ..cosim.bouncing import impact_sequence
from ..cosim.interrupt import DeferredInterrupt
from .loader import Drop, Scene, SceneError
from .results import READ_FLAGS, READ_OUTPUTS, VALIDITY, DropResult, SceneResult, apex_heights

__all__ = ["SceneInterrupted", "run_scene", "chosen_fmu", "chosen_ball_fmu", "open_instance", "drop_parameters"]

class SceneInterrupted(KeyboardInterrupt):
    """An interrupted scene run: ``result`` holds the drops that finished."""

    def __init__(self, result: "SceneResult", n_drops: int):
        super().__init__(f"scene interrupted after {len(result.drops)} of {n_drops} drops")
        self.result = result
        self.n_drops = n_drops



# --- the FMU ---------------------------------------------------------------------------------

def chosen_fmu(fmu=None, rebuild: bool = False, log=None) -> Path:
    """Path of the FMU to run: ``fmu`` as given (checked), else :func:`restitution.fmu.default_fmu` (the
    installed FMU of a wheel, else dist/ of a source checkout or a per-user cache, built when missing or
    stale, or when ``rebuild`` is true)."""
    if fmu is not None:  # ValueError (one line naming --fmu) unless it is a SpherePlateImpact FMU
        from ..cosim.fmu import check_impact_fmu

        return check_impact_fmu(fmu)
    from ..fmu.builders.products import default_fmu

    return default_fmu(rebuild=rebuild, log=log)


def chosen_ball_fmu(ball_fmu=None, rebuild: bool = False, log=None) -> Path:
    """Path of the FMI 3.0 BouncingBall.fmu the event-mode master runs (``simulation.master =
    "event_mode"``): ``ball_fmu`` as given (ValueError, one line naming --ball-fmu, unless it is one with
    event mode), else ``fmi3/BouncingBall.fmu`` beside the default FMUs, built with them where missing or
    stale (:func:`restitution.fmu.default_fmu`)."""
    from ..cosim.event_mode import check_event_ball_fmu

    if ball_fmu is not None:
        return check_event_ball_fmu(ball_fmu)
    from ..fmu.builders.products import default_fmu

    path = default_fmu(rebuild=rebuild, log=log).parent / "fmi3" / "BouncingBall.fmu"
    if not path.is_file():
        raise ValueError("no native FMI 3.0 BouncingBall.fmu could be built here (it needs a C compiler): "
                         "give --ball-fmu PATH, or use simulation.master = \"closed_form\"")
    return check_event_ball_fmu(path)


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
        **drop.package_params(), restitution_model=scene.model.restitution_model, zener_method=zener_method, plasticity=plasticity,
        plate_waves=plate_waves, effect_tolerance=scene.model.effect_tolerance)


# --- the master ----------------------------------------------------------------------------------

def _contacts(instance, ball, scene: Scene, drop: Drop, rebound):
    """The impacts of one drop, ``([(t, v_approach, out), ...], stop_reason)``: the closed-form flight, or
    (``ball``: an event-mode BouncingBall instance) the co-simulation in event mode, where the ball is
    given SpherePlateImpact's e at each contact (read here whether or not the scene asked for it)."""
    sim = scene.simulation
    if ball is None:
        return impact_sequence(rebound, drop.drop_height, sim.gravity, sim.v_min, sim.max_bounces,
                               advance=instance.do_step)  # flights need no evaluation (inputs unchanged)
    from ..cosim.event_mode import drop_contacts

    get_e = instance.reader("e")

    def rebound_with_e(v):
        out = rebound(v)
        out.setdefault("e", get_e()[0])
        return out
    return drop_contacts(ball, rebound_with_e, drop.drop_height, sim.gravity, sim.v_min, sim.communication_step,
                         sim.max_bounces, advance=instance.do_step)


def _run_drop(instance, scene: Scene, drop: Drop, params: dict, read_names, read_cols,
              interrupt: DeferredInterrupt | None = None, ball=None) -> DropResult:
    sim = scene.simulation
    g = sim.gravity
    # Reset, then set the parameters and the first impact's speed in initialization mode: the
    # evaluation at the exit from initialization mode is then the first impact's, not a wasted one.
    v_first = math.sqrt(2.0 * g * drop.drop_height)
    seen = len(instance.messages)
    try:
        instance.reset(parameters={**params, "v_approach": v_first})
        failure = None
    except Exception as exc:  # noqa: BLE001 - a refused value (Error); the FMU's log says which
        failure = exc
    rejected = [text for status, text in instance.messages[seen:] if status >= _FMI_ERROR]
    if rejected or failure is not None:
        try:  # reset and back in step mode (out of initialization and any error mode): it can be reused or freed
            instance.reset()
        except Exception:  # noqa: BLE001 - the error being reported matters, not this one
            pass
    if rejected:  # a value this FMU does not accept (the loader checks the domain; another FMU may differ)
        raise _rejected(scene, drop, rejected[0]) from None
    if failure is not None:
        raise failure

    real_names = ("v_rebound", *read_names)
    set_speed = instance.writer("v_approach")
    get_real, get_bool = instance.reader(*real_names), instance.reader(*READ_FLAGS)

    def rebound(v):  # only the requested outputs, and the effects used
        set_speed([v])
        out = dict(zip(real_names, get_real()))  # floats: checked for NaN by impact_sequence
        out["flags"] = get_bool()
        if interrupt is not None:
            interrupt.check()  # here, between FMU calls, never inside one
        return out

    try:
        events, stop = _contacts(instance, ball, scene, drop, rebound)
    except ValueError as exc:
        raise RuntimeError(f"{drop.label}: {exc}; FMU log: {instance.last_message()}") from exc
    times = [t for t, _, _ in events]
    speeds = [v for _, v, _ in events]
    rows = [[out[n] for n in real_names] for _, _, out in events]
    flags = [out["flags"] for _, _, out in events]
    data = np.array(rows, dtype=float).reshape(len(rows), 1 + len(read_names))
    flags = np.array(flags, dtype=bool).reshape(len(rows), len(READ_FLAGS))
    v_reb = data[:, 0]
    columns = {}
    if "bounce_heights" in scene.outputs:
        columns["apex"] = apex_heights(v_reb, g)
    for j, col in enumerate(read_cols):
        columns[col] = data[:, 1 + j]
    said = [text for status, text in instance.messages[seen:] if status == _FMI_WARNING]
    return DropResult(drop=drop, time=np.array(times), v_approach=np.array(speeds), v_rebound=v_reb,
                      columns=columns, plasticity=flags[:, 0], plate_waves=flags[:, 1], stop_reason=stop,
                      gravity=g, validity={name: flags[:, 2 + k] for k, name in enumerate(VALIDITY)},
                      departures=said)


#: Status of a rejected value (Error, 3 in FMI 2.0 and 3.0; Fatal is 4).
_FMI_ERROR = 3
#: Status of the FMU's messages about impacts outside the validated domain (Warning, 1).
_FMI_WARNING = 1


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
              instance=None, progress: bool | None = None, rebuild: bool = False, on_drop=None,
              ball_fmu=None) -> SceneResult:
    """Simulate every drop of ``scene`` through the FMU.

    ``effects``: ``"scene"`` (the scene's modes, auto by default, see :meth:`Scene.effect_modes`)
    or ``"all_on"`` (plasticity = plate_waves = on, the reference). ``zener_method`` overrides
    the scene's. ``instance``: an open :class:`~restitution.cosim.FmuInstance` to reuse
    (else one is opened on ``fmu`` or the built/reused dist/ FMU, and closed afterwards).
    ``progress``: None or True: in a terminal, a bar once the run has taken a second; always a
    final line on stderr with the drops done; False: nothing. ``on_drop``: called with each
    :class:`DropResult` as soon as its drop finishes (e.g. :meth:`DropWriter.write`). An
    interrupt raises :class:`SceneInterrupted` with the finished drops. ``simulation.master = "event_mode"``:
    each drop is the FMI 3.0 BouncingBall.fmu (``ball_fmu``, else :func:`chosen_ball_fmu`'s) co-simulated
    with the FMU in event mode with early return (:mod:`restitution.cosim.event_mode`).
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
        fmu_path = chosen_fmu(fmu, rebuild=rebuild)
    ball_path = chosen_ball_fmu(ball_fmu, rebuild=rebuild and own) if scene.simulation.master == "event_mode" else None
    if own:
        instance = open_instance(fmu_path)
    ball = None
    if ball_path is not None:
        from ..cosim.event_mode import EventModeInstance

        try:
            ball = EventModeInstance(ball_path, "scene-ball")
        except BaseException:
            if own:
                instance.close()
            raise
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
                done = _run_drop(instance, scene, drop, params, read_names, read_cols, interrupt, ball)
                results.append(done)
                if on_drop is not None:
                    on_drop(done)
                if bar is not None:
                    bar.set_postfix_str(f"{sum(r.n_impacts for r in results)} impacts", refresh=False)
                    bar.update(1)
    except KeyboardInterrupt:
        _final_line(bar, progress, scene, method, results, len(drops), start, "interrupted")
        raise SceneInterrupted(result(), len(drops)) from None
    except BaseException:  # an I/O error writing a drop, ...: the bar is cleared, the error gets its own line
        if bar is not None:
            bar.close()
        raise
    finally:
        if own:
            instance.close()
        if ball is not None:
            ball.close()
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
