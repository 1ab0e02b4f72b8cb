"""e44 against e45 over V* in [1, 1000] (no ground truth exists: both are fits)."""
from __future__ import annotations


import numpy as np

from restitution.jgm import restitution_e44, restitution_e45
import restitution as r  # noqa: E402

from .config import Config
from harness import interleaved, median, median_ratio


JGM_PAIRS = (("s2_tool_steel", "al_6061"), ("tungsten_carbide", "al_6061"), ("brass_260", "s7_tool_steel"),
             ("s2_tool_steel", "s2_tool_steel"))


def jgm_fits(cfg: Config) -> dict:
    vstar = np.geomspace(1.0, 1000.0, 4001)
    rows = []
    for sphere_key, plate_key in JGM_PAIRS:
        if sphere_key not in r.MATERIALS or plate_key not in r.MATERIALS:
            continue
        a, b = r.MATERIALS[sphere_key], r.MATERIALS[plate_key]
        res = r.impact(1.0, a.E, a.nu, a.Sy, a.rho, 6.35e-3, b.E, b.nu, b.Sy, b.rho, 6.35e-3)
        eps_y = res.eps_y
        e45 = restitution_e45(vstar, eps_y)
        e44 = restitution_e44(vstar)
        diff = e44 - e45
        k = int(np.argmax(np.abs(diff)))
        rows.append({"pair": f"{sphere_key} on {plate_key}", "eps_y": float(eps_y),
                     "max_abs": float(np.abs(diff).max()), "mean_abs": float(np.abs(diff).mean()),
                     "vstar_at_max": float(vstar[k]), "e44_at_max": float(e44[k]), "e45_at_max": float(e45[k]),
                     "e44_1000": float(e44[-1]), "e45_1000": float(e45[-1])})
    # cost of each fit, scalar (the FMU's restitution_model = 1 / 2 makes the same choice)
    gen = np.random.default_rng(5)
    vs = [float(x) for x in 10.0 ** gen.uniform(0.0, 3.0, 1000)]
    eps = rows[0]["eps_y"] if rows else 0.004

    def c45(n):
        for _ in range(n):
            for x in vs:
                restitution_e45(x, eps)
        return n * len(vs)

    def c44(n):
        for _ in range(n):
            for x in vs:
                restitution_e44(x)
        return n * len(vs)
    timings = interleaved({"e45": c45, "e44": c44}, cfg.reps, cfg.batch_seconds)
    return {"rows": rows, "cost_e45": median(timings["e45"]), "cost_e44": median(timings["e44"]),
            "e44_over_e45": median_ratio(timings["e44"], timings["e45"])}
