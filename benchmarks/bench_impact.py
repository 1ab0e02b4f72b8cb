#!/usr/bin/env python
"""What ``restitution.impact`` costs on an array of cases, against a plain numpy expression of the same equations.

    .venv/bin/python benchmarks/bench_impact.py [--cases N] [--repeats N] [--quick]

One sphere/plate pair (S2 tool steel, d = 6.35 mm, on Al 6061), ``--cases`` cases (default 10^6) with
random approach speeds (0.005 ... 20 m/s, log-uniform: V_c = 0.026 m/s, so both branches of Eq. (8)) and
plate thicknesses (t/d 0.1 ... 10, log-uniform), the default options (``zener_method="exact"``, ``restitution_model="e45"``, both effects ``"auto"``).

* ``impact``: ``restitution.impact(v, **params, plate_t=t)``, every output (the default);
* ``numpy``: the equations written out here with numpy, computing e, e_ep, e_ze and v_rebound only, with
  every term that depends on the parameters alone computed once, as Python floats, before timing:
  e_ep by Eq. (8), lambda by Eq. (12), e_ze by the exact method's piecewise cubic Hermite interpolation
  of the tabulated solution of Eq. (10) (data/zener_table.npz: node values and slopes, read here and
  turned into cubics here; a case's cell found by one multiply and a truncation, as the table is laid
  out for), e by Eq. (20) and v_rebound = e v. Before timing its four outputs are compared with impact()'s
  (:func:`disagreement`; the benchmark stops if they differ).

The two sides take turns (impact, numpy, impact, ...), ``--repeats`` times each, CPU time of this thread
(``time.thread_time``); the ratio printed is the median of the per-turn ratios, beside the goal
(<= 2x). The machine is shared: ratios are the result, absolute times only say how busy it was.
``--quick`` runs 10^4 cases three times (a test runs it).
"""
from __future__ import annotations

import argparse
import io
import math
import platform
import statistics
import sys
import time
from datetime import datetime, timezone
from importlib.resources import files
from pathlib import Path

import numpy as np
from harness import cpu_name

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT / "fmu_src") not in sys.path:
    sys.path.insert(0, str(ROOT / "fmu_src"))

GOAL = 2.0  #: impact / numpy expression, at most
DIAMETER = 6.35e-3  #: sphere diameter [m]
SPHERE, PLATE = "s2_tool_steel", "al_6061"


def cases(n: int, seed: int = 2026):
    """(v [m/s], t [m]) of ``n`` random cases, log-uniform."""
    rng = np.random.default_rng(seed)
    return 10.0 ** rng.uniform(math.log10(0.005), math.log10(20.0), n), DIAMETER * 10.0 ** rng.uniform(-1.0, 1.0, n)


def parameters() -> dict:
    """impact()'s parameters of the pair (plate_t apart)."""
    from restitution.materials import MATERIALS, Plate, Sphere

    params = {**Sphere(MATERIALS[SPHERE], DIAMETER).params(), **Plate(MATERIALS[PLATE], DIAMETER).params()}
    del params["plate_t"]
    return params


def scalar_terms(p: dict) -> dict:
    """The parameter-only terms, as Python floats, from the paper's equations written out here."""
    Ea = p["sphere_E"] / (1.0 - p["sphere_nu"] ** 2)  # Eq. (1)
    Eb = p["plate_E"] / (1.0 - p["plate_nu"] ** 2)
    E_prime = Ea * Eb / (Ea + Eb)
    c_a = 1.295 * math.exp(0.736 * p["sphere_nu"]) * p["sphere_Sy"]  # Eq. (2)
    c_b = 1.295 * math.exp(0.736 * p["plate_nu"]) * p["plate_Sy"]
    CSy = min(c_a, c_b)
    eps_y = (p["sphere_Sy"] if c_a <= c_b else p["plate_Sy"]) / E_prime  # Eq. (3)
    R = 0.5 * p["sphere_d"]
    omega_c = (math.pi * CSy / (2.0 * E_prime)) ** 2 * R  # Eq. (4)
    P_c = 4.0 / 3.0 * (R / E_prime) ** 2 * (0.5 * math.pi * CSy) ** 3  # Eq. (5)
    m_a = p["sphere_rho"] * math.pi * p["sphere_d"] ** 3 / 6.0
    V_c = math.sqrt(0.8 * omega_c * P_c / m_a)  # Eq. (6)
    wave_speed = math.sqrt(Eb / p["plate_rho"])  # Eq. (12): lambda = lam_coefficient v^(1/5) / t^2
    lam_coefficient = (math.pi ** 0.6 / math.sqrt(3.0) * R * R * wave_speed ** -0.2
                       * (p["sphere_rho"] / p["plate_rho"]) ** 0.6 * (Ea / (Ea + Eb)) ** 0.4)
    return {"V_c": V_c, "loss_coefficient": 0.0361 * eps_y ** -0.114, "loss_exponent": 9.5 * eps_y,
            "lam_coefficient": lam_coefficient}


def hermite_cells():
    """The exact method's table as cubics per cell of width h: (1/h, start node of each cell's piece,
    the four coefficients in t = lambda/h - start of each cell's piece), from the tabulated values and
    slopes of e_ze (data/zener_table.npz)."""
    raw = files("restitution").joinpath("data", "zener_table.npz").read_bytes()
    with np.load(io.BytesIO(raw)) as table:
        k, h, f, df = table["k"], float(table["h"]), table["e"], table["de"]
    w = np.diff(k).astype(float)
    f0, f1, d0, d1 = f[:-1], f[1:], h * w * df[:-1], h * w * df[1:]
    coefficients = (f0, d0 / w, (3.0 * (f1 - f0) - 2.0 * d0 - d1) / w ** 2, (2.0 * (f0 - f1) + d0 + d1) / w ** 3)
    cell = np.repeat(np.arange(w.size), np.diff(k))
    return 1.0 / h, k[:-1][cell].astype(float), tuple(np.ascontiguousarray(c[cell]) for c in coefficients)


def numpy_expression(v, t, terms, cells):
    """(e, e_ep, e_ze, v_rebound) of the cases, the equations written with numpy."""
    inv_h, start, (a0, a1, a2, a3) = cells
    v_star = v / terms["V_c"]
    with np.errstate(invalid="ignore"):  # (V* - 1)^p of V* < 1: NaN, not selected
        e_ep = np.where(v_star > 1.0, 1.0 - terms["loss_coefficient"] * np.log(v_star)
                        * (v_star - 1.0) ** terms["loss_exponent"], 1.0)  # Eq. (8)
    e_ep = np.maximum(e_ep, 0.0)
    lam = terms["lam_coefficient"] * v ** 0.2 / (t * t)  # Eq. (12)
    x = lam * inv_h
    cell = x.astype(np.intp)
    s = x - start[cell]
    e_ze = a0[cell] + s * (a1[cell] + s * (a2[cell] + s * a3[cell]))
    e = 0.5 * (e_ze * (1.0 + e_ep) - (1.0 - e_ep))  # Eq. (20)
    return e, e_ep, e_ze, e * v


#: ``plasticity="auto"`` sets e_ep = 1 where 1 - e_ep < 1e-6 (impact()'s default ``effect_tolerance``),
#: which the expression does not do: e and e_ep may differ by that much (v_rebound by that times v).
AUTO_SKIP = 1e-6


def disagreement(plain, result, v) -> dict:
    """The largest difference of each output of :func:`numpy_expression` from impact()'s ``result`` beyond
    what the two may differ by: 1e-12 relative (rounding) plus, for e, e_ep and v_rebound, the auto skip
    of small plastic losses. Empty when they agree."""
    worst = {}
    for name, value in zip(("e", "e_ep", "e_ze", "v_rebound"), plain):
        allowed = 1e-12 * np.maximum(1.0, np.abs(value))
        if name != "e_ze":
            allowed = allowed + AUTO_SKIP * (v if name == "v_rebound" else 1.0)
        excess = float(np.max(np.abs(value - getattr(result, name)) - allowed))
        if not excess <= 0.0:
            worst[name] = excess
    return worst


def measure(n: int, repeats: int) -> dict:
    import restitution

    v, t = cases(n)
    params = parameters()
    terms, cells = scalar_terms(params), hermite_cells()
    result = restitution.impact(v, **params, plate_t=t)
    plain = numpy_expression(v, t, terms, cells)
    wrong = disagreement(plain, result, v)
    if wrong:
        raise SystemExit(f"the numpy expression and impact() disagree beyond their allowance: {wrong}")
    times = {"impact": [], "numpy": []}
    for _ in range(repeats):
        start = time.thread_time()
        restitution.impact(v, **params, plate_t=t)
        times["impact"].append(time.thread_time() - start)
        start = time.thread_time()
        numpy_expression(v, t, terms, cells)
        times["numpy"].append(time.thread_time() - start)
    ratios = [a / b for a, b in zip(times["impact"], times["numpy"])]
    return {"cases": n, "impact_s": statistics.median(times["impact"]), "numpy_s": statistics.median(times["numpy"]),
            "ratio": statistics.median(ratios)}


def report(m: dict) -> str:
    met = "met" if m["ratio"] <= GOAL else "NOT met"
    return (f"impact / numpy expression, {m['cases']:.3g} cases: impact {m['impact_s']:.4g} s, numpy "
            f"{m['numpy_s']:.4g} s: {m['ratio']:.2f}x (goal <= {GOAL:g}x: {met})")


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, action="append", help="cases per call (repeatable; default 10^6)")
    parser.add_argument("--repeats", type=int, default=15, help="turns of each side (default 15)")
    parser.add_argument("--quick", action="store_true", help="10^4 cases, 3 turns")
    args = parser.parse_args(argv)
    sizes = [10_000] if args.quick else (args.cases or [1_000_000])
    repeats = 3 if args.quick else args.repeats
    print(f"bench_impact.py on {datetime.now(timezone.utc):%Y-%m-%d %H:%M} UTC: {cpu_name()}"
          f", {len(__import__('os').sched_getaffinity(0))} cores; Python {platform.python_version()}, numpy {np.__version__}; "
          f"{SPHERE} d = {DIAMETER * 1e3:g} mm on {PLATE}, default options, {repeats} interleaved turns, thread CPU time")
    for n in sizes:
        print(report(measure(n, repeats)), flush=True)


if __name__ == "__main__":
    main()
