"""Why a scene run left effects out: computed host side from the impact speeds and the package
(the FMU is asked for nothing more)."""
from __future__ import annotations

import numpy as np

from ..model import ZENER_SLOPE_BOUND, impact
from .loader import Drop


def critical_velocity_of(drop: Drop) -> float:
    """V_c [m/s] of the ball/plate pair, Eq. (6), from the package (host side, for the explanations only)."""
    return float(impact(0.0, **drop.package_params(), plasticity="off", plate_waves="off").V_c)


def zener_lambda_of(drop: Drop, v) -> np.ndarray:
    """Zener's lambda [1] of the drop's pair at the approach speeds ``v`` [m/s], Eq. (12), from the package."""
    return impact(np.asarray(v, dtype=float), **drop.package_params(), plasticity="off", plate_waves="off").lam


def explain(result) -> list[str]:
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
