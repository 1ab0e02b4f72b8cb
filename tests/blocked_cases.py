"""The cases and comparisons of tests/physics/test_blocked_evaluation.py, in a module of their own: a child
process imports them with the package of another commit (which has no restitution._blocks)."""
from __future__ import annotations

import numpy as np

from cases import params_for, random_cases

N = 4 * 32768 + 777  # four whole blocks of restitution._blocks and a part of one (checked by the test)
OPTIONS = {"default": {}, "e44, paper_fit": dict(restitution_model="e44", zener_method="paper_fit"),
           "on, on, linear": dict(plasticity="on", plate_waves="on", zener_method="linear"),
           "tolerance 1e-3, edge 5 cm": dict(effect_tolerance=1e-3, plate_edge_distance=0.05)}
CHOSEN = ("e", "v_rebound", "t_contact", "edge_clear")


def case_sets() -> dict:
    """name -> (v, parameters): per-case parameters over the domain; one pair with scalar parameters; a 2-D
    array of speeds."""
    rng = np.random.default_rng(47)
    v, params = random_cases(rng, N)
    one_pair = params_for("s2/al6061")
    speeds = np.exp(rng.uniform(np.log(1e-6), np.log(1e3), N))
    speeds[::101] = 0.0
    grid = np.exp(rng.uniform(np.log(1e-3), np.log(50.0), (300, 250)))
    return {"per-case parameters": (v, params), "scalar parameters": (speeds, one_pair),
            "2-D speeds": (grid, params_for("T4-A1", 0.2))}


def evaluate(impact, sets: dict) -> dict:
    """(set, options, 'whole' or 'chosen') -> name -> array, by ``impact`` (this package's or another's)."""
    out = {}
    for set_name, (v, params) in sets.items():
        for opt_name, options in OPTIONS.items():
            whole = impact(v, **params, **options, validate=False)
            out[(set_name, opt_name, "whole")] = {k: np.asarray(x) for k, x in whole.as_dict().items()}
            chosen = impact(v, **params, **options, validate=False, outputs=CHOSEN)
            out[(set_name, opt_name, "chosen")] = {k: np.asarray(x) for k, x in chosen.items()}
    return out


def differing(a: dict, b: dict) -> list:
    """The (key, output) pairs whose arrays differ in any bit (NaNs compared by their bits too)."""
    bad = []
    for key in a:
        for name, x in a[key].items():
            y = b[key][name]
            same = x.shape == y.shape and x.dtype == y.dtype and (
                np.array_equal(x.view(np.uint64), y.view(np.uint64)) if x.dtype == float else np.array_equal(x, y))
            if not same:
                bad.append((key, name))
    return bad
