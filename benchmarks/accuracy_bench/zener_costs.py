"""Zener's COR by every method: accuracy against the reference, cost of scalar and vectorized calls."""
from __future__ import annotations


import numpy as np

from restitution.zener import zener_restitution

from .config import Config, RANGES
from harness import clock, timed, interleaved, median, median_ratio


def method_list(cfg: Config):
    """(label, method, rtol) of every Zener variant measured."""
    rows = [("exact", "exact", None), ("paper_fit", "paper_fit", None), ("linear", "linear", None)]
    rows += [(f"ode rtol {rtol:.0e}", "ode", rtol) for rtol in cfg.ode_rtols]
    return rows


def _errors(x, ref):
    x = np.asarray(x, dtype=float)
    with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
        ab = np.abs(x - ref)
        rel = ab / np.abs(ref)
    ab = np.where(np.isnan(ab), np.inf, ab)
    rel = np.where(np.isnan(rel), np.inf, rel)
    return {"max_abs": float(ab.max()), "mean_abs": float(ab.mean()), "max_rel": float(rel.max()),
            "mean_rel": float(rel.mean())}


def zener_accuracy(cfg: Config, lams: dict, ref: dict) -> dict:
    """{(label, range): {"e": errors, "tau0": errors, "ode_seconds": [...]}}."""
    out = {}
    for label, method, rtol in method_list(cfg):
        for rng in RANGES:
            es, taus, secs = [], [], []
            for lam in lams[rng]:
                t0 = clock()
                e, tau = zener_restitution(float(lam), method, rtol if rtol is not None else 1e-10)
                secs.append(clock() - t0)
                es.append(e)
                taus.append(tau)
            out[(label, rng)] = {"e": _errors(es, ref[rng][0]), "tau0": _errors(taus, ref[rng][1]),
                                 "seconds": secs}
    return out


def zener_scalar_costs(cfg: Config, lams: dict, accuracy: dict) -> dict:
    """{(label, range): seconds per scalar zener_restitution call}; plus exact/paper_fit ratios."""
    rng_gen = np.random.default_rng(7)
    sets = {RANGES[0]: [float(x) for x in rng_gen.uniform(0.0, 1.5, 1000)],
            RANGES[1]: [float(x) for x in rng_gen.uniform(1.5, 100.0, 1000)]}
    costs, ratios = {}, {}
    for rng in RANGES:
        lam_set = sets[rng]
        variants = {}
        for label, method, _rtol in method_list(cfg):
            if method == "ode":
                continue

            def run(n, method=method, lam_set=lam_set):
                f = zener_restitution
                for _ in range(n):
                    for lam in lam_set:
                        f(lam, method)
                return n * len(lam_set)
            variants[label] = run
        timings = interleaved(variants, cfg.reps, cfg.batch_seconds)
        for label, ts in timings.items():
            costs[(label, rng)] = median(ts)
        ratios[rng] = median_ratio(timings["exact"], timings["paper_fit"])
        for label, method, rtol in method_list(cfg):
            if method == "ode":  # a solve per call: the accuracy pass is the timing (median over lambda)
                extra = []
                for _ in range(cfg.ode_reps - 1):
                    for lam in lams[rng]:
                        t0 = clock()
                        zener_restitution(float(lam), "ode", rtol)
                        extra.append(clock() - t0)
                costs[(label, rng)] = median(accuracy[(label, rng)]["seconds"] + extra)
    return {"costs": costs, "exact_over_paper_fit": ratios}


def zener_vector_costs(cfg: Config) -> dict:
    """{(label, range): seconds per element of a vectorized zener_restitution call}."""
    gen = np.random.default_rng(11)
    out = {}
    for rng, (lo, hi) in zip(RANGES, ((0.0, 1.5), (1.5, 100.0))):
        variants = {}
        for label, method, rtol in method_list(cfg):
            n_el = cfg.n_vector_ode if method == "ode" else cfg.n_vector
            if method == "ode" and rtol not in (cfg.ode_rtols[0], cfg.ode_rtols[-1]):
                continue  # a loop of scalar solves: two tolerances show it
            lam = gen.uniform(lo, hi, n_el)

            def run(n, method=method, lam=lam, rtol=rtol):
                for _ in range(n):
                    zener_restitution(lam, method, rtol if rtol is not None else 1e-10)
                return n * lam.size
            variants[label] = run
        reps = {k: v for k, v in variants.items() if not k.startswith("ode")}
        for label, ts in interleaved(reps, cfg.reps, cfg.batch_seconds * 5).items():
            out[(label, rng)] = median(ts)
        for label, run in variants.items():
            if label.startswith("ode"):
                out[(label, rng)] = median([timed(run, 1) for _ in range(cfg.ode_reps)])
    return out
