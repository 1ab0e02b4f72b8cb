"""The reference for Zener's COR and contact time: scipy's Radau at rtol 1e-13 on Zener's first-order
form in tau, started from its own analytic series; independent of every method under test."""
from __future__ import annotations

import math
import sys

import numpy as np

from .config import Config, RANGES


def reference_solve(lam: float, rtol: float = 1e-13) -> tuple[float, float]:
    """(e_ze, tau0) of Eq. (10)-(11) by scipy Radau in Zener's form (sigma, p), tau as variable.

    sigma' = p - lam max(sigma, 0)^1.5, p' = -max(sigma, 0)^1.5, p = sigma' + lam sigma^1.5,
    started at a tiny tau_s from the series sigma = tau - (2/5) lam tau^(5/2) - (4/35) tau^(7/2)
    + (3/20) lam^2 tau^4, p = 1 - (2/5) tau^(5/2) + (3/20) lam tau^4; the rebound is the
    terminal event sigma = 0 (falling), where e_ze = -p.
    """
    from scipy.integrate import solve_ivp

    lam = float(lam)
    ts = 1e-6
    if lam > 0.0:
        ts = min(ts, (1e-17 / lam) ** 0.25, (1e-17 / lam ** 3) ** (1.0 / 4.5))
    sig0 = ts - 0.4 * lam * ts ** 2.5 - (4.0 / 35.0) * ts ** 3.5 + 0.15 * lam * lam * ts ** 4
    p0 = 1.0 - 0.4 * ts ** 2.5 + 0.15 * lam * ts ** 4
    sqrt = math.sqrt

    def rhs(_t, y):
        s = float(y[0])
        q = s * sqrt(s) if s > 0.0 else 0.0
        return [float(y[1]) - lam * q, -q]

    def jac(_t, y):
        s = float(y[0])
        g = 1.5 * sqrt(s) if s > 0.0 else 0.0
        return [[-lam * g, 1.0], [-g, 0.0]]

    def rebound(_t, y):
        return float(y[0])

    rebound.terminal = True
    rebound.direction = -1.0
    size = lam ** -5.0 if lam > 1.0 else 1.0  # e_ze ~ 0.68 lam^-5 for large lam
    t_end = 20.0 + 2.0 * lam * (5.0 * math.log1p(lam) + 1.0)
    sol = solve_ivp(rhs, (ts, t_end), [sig0, p0], method="Radau", rtol=rtol, atol=rtol * 1e-3 * size,
                    jac=jac, events=rebound)
    if sol.status < 0 or not len(sol.t_events[0]):
        raise RuntimeError(f"reference solve failed at lambda = {lam}: {sol.message}")
    return -float(sol.y_events[0][0][1]), float(sol.t_events[0][0])


def reference_many(lams, jobs: int, rtol: float = 1e-13):
    args = [(float(x), rtol) for x in lams]
    if jobs > 1 and sys.platform.startswith("linux") and len(args) > 1:
        import multiprocessing

        with multiprocessing.get_context("fork").Pool(jobs) as pool:
            out = pool.starmap(reference_solve, args, chunksize=1)
    else:
        out = [reference_solve(*a) for a in args]
    return np.array([o[0] for o in out]), np.array([o[1] for o in out])


def lambda_points(cfg: Config) -> dict:
    """Off-node lambda points of each range (the exact table's nodes are multiples of 1/128)."""
    small = [0.0] + [1.5 * (k + 0.37) / cfg.n_small for k in range(cfg.n_small)] + [1.5]
    large = [1.5 * (100.0 / 1.5) ** ((k + 0.61) / cfg.n_large) for k in range(cfg.n_large)] + [100.0]
    return {RANGES[0]: np.array(small), RANGES[1]: np.array(large)}
