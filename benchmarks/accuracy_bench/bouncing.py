"""The bouncing ball: fixed-step co-simulation of the two FMUs against the event-exact master, over
communication step sizes, with wall time."""
from __future__ import annotations

from pathlib import Path
import math
import time

import numpy as np

import restitution as r  # noqa: E402

from .config import Config
from harness import median


def bouncing(cfg: Config, fmus: dict, work: Path, drop_height: float = 0.3, t_end: float = 1.0,
             n_bounces: int = 5) -> dict:
    from restitution.cosim import FmuInstance, bounce, fmu_rebound, impact_fmu_parameters

    sphere = r.Sphere(r.MATERIALS["s2_tool_steel"], 6.35e-3)
    plate = r.Plate(r.MATERIALS["al_6061"], 6.35e-3)
    params = impact_fmu_parameters(sphere, plate)
    g = 9.80665
    with FmuInstance(fmus["SpherePlateImpact"], "bench_exact", parameters=params) as fmu:
        rebound = fmu_rebound(fmu)
        walls = []
        for _ in range(max(3, cfg.ode_reps)):
            t0 = time.perf_counter()
            exact = bounce(rebound, drop_height=drop_height, gravity=g)
            walls.append(time.perf_counter() - t0)
    out = {"exact_wall": median(walls), "rows": [], "n_bounces": n_bounces, "drop_height": drop_height,
           "t_end": t_end, "master": None}
    if "BouncingBall" not in fmus:
        out["master"] = "unavailable (no BouncingBall FMU)"
        return out
    from restitution.cosim.fixed_step import BALL_IMPACT_CONNECTIONS, BALL_RECORD, FixedStepMaster, ball_bounces

    out["master"] = "restitution.cosim.FixedStepMaster (fmpy)"
    variants = (("fixed step, ball waits for the COR (contact_mode 1)", 1, None),
                ("fixed step, ball rebounds at once (contact_mode 2)", 2, None),
                ("fixed step with state restore at events", 1, ("ball.impacts", "ball.t_impact")))
    for step in cfg.cosim_steps:
        for label, mode, event in variants:
            with FmuInstance(fmus["SpherePlateImpact"], "bench_impact", parameters=params) as impact, \
                    FmuInstance(fmus["BouncingBall"], "bench_ball",
                                parameters={"h0": drop_height, "g": g, "contact_mode": mode}) as ball:
                master = FixedStepMaster({"ball": ball, "impact": impact}, BALL_IMPACT_CONNECTIONS)
                res = master.run(step, t_end, record=BALL_RECORD, event=event)
            b = ball_bounces(res, g)
            k = min(n_bounces, b["t_impact"].size, b["v_rebound"].size, exact.n_impacts)
            ok = k == n_bounces
            dt = np.abs(b["t_impact"][:k] - exact.time[:k])
            dapex = np.abs(b["apex"][:k] / exact.apex[:k] - 1.0)
            de = np.abs(b["e_applied"][:k] - exact.e[:k])
            out["rows"].append({"master": label, "step": step, "wall": res.wall_time, "steps": res.steps,
                                "dt_max": float(dt.max()) if ok else math.inf,
                                "apex_rel_max": float(dapex.max()) if ok else math.inf,
                                "de_max": float(de.max()) if ok else math.inf})
    return out
