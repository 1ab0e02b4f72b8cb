"""The whole model: a scalar ``impact`` call against the vectorized one, per case."""
from __future__ import annotations

import math

import numpy as np

import restitution as r  # noqa: E402

from .config import Config, STEEL_ON_AL
from harness import interleaved, median, median_ratio


def sweep_cases(n: int, seed: int = 3):
    """S2 tool steel sphere (d = 6.35 mm) on Al 6061: v log-uniform in [0.1, 10] m/s,
    t/d log-uniform in [0.25, 4] (lambda ~ 0.003 ... 2.2), in random order."""
    gen = np.random.default_rng(seed)
    d = STEEL_ON_AL["sphere"][1]
    v = 10.0 ** gen.uniform(-1.0, 1.0, n)
    t = d * 10.0 ** gen.uniform(math.log10(0.25), math.log10(4.0), n)
    sphere = r.Sphere(r.MATERIALS[STEEL_ON_AL["sphere"][0]], d)
    plate = r.Plate(r.MATERIALS[STEEL_ON_AL["plate"]], d)
    params = {**sphere.params(), **plate.params()}
    params.pop("plate_t")
    return v, t, params


def model_costs(cfg: Config) -> dict:
    v, t, params = sweep_cases(cfg.n_vector)
    n_scalar = 1000
    vs = [float(x) for x in v[:n_scalar]]
    ts = [float(x) for x in t[:n_scalar]]

    def scalar(method, validate=True):
        def run(n):
            f = r.impact
            for _ in range(n):
                for vi, ti in zip(vs, ts):
                    f(vi, plate_t=ti, zener_method=method, validate=validate, **params)
            return n * n_scalar
        return run

    def vector(method):
        def run(n):
            for _ in range(n):
                r.impact(v, plate_t=t, zener_method=method, **params)
            return n * v.size
        return run
    variants = {}
    for method in ("exact", "paper_fit", "linear"):
        variants[(method, "scalar")] = scalar(method)
        variants[(method, "scalar, validate=False")] = scalar(method, validate=False)
        variants[(method, "vectorized")] = vector(method)
    timings = interleaved(variants, cfg.reps, cfg.batch_seconds * 5)
    out = {}
    for method in ("exact", "paper_fit", "linear"):
        out[method] = {kind: median(timings[(method, kind)])
                       for kind in ("scalar", "scalar, validate=False", "vectorized")}
        out[method]["scalar_over_vectorized"] = median_ratio(timings[(method, "scalar")],
                                                             timings[(method, "vectorized")])
    out["exact_over_paper_fit"] = median_ratio(timings[("exact", "scalar")], timings[("paper_fit", "scalar")])
    return out
