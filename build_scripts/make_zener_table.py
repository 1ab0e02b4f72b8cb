#!/usr/bin/env python
"""Regenerate fmu_src/restitution/data/zener_table.npz, the data of the "exact" Zener method.

Offline, from scratch: about 1-3 minutes on 2 cores.  Usage:

    .venv/bin/python build_scripts/make_zener_table.py [--out PATH] [--h 0.0078125] [--jobs 2]

What is solved
--------------
Zener's ODE, I. Green, Nonlinear Dyn (2022), Eq. (10)-(11):
sigma'' + (1 + lambda d/dtau) sigma^(3/2) = 0, sigma(0) = 0, sigma'(0) = 1, up to the
first return of sigma to 0 at tau0; e_ze = -sigma'(tau0).  With p = sigma' + lambda
sigma^(3/2) (Zener's form) the system is sigma' = p - lambda sigma^(3/2), p' = -sigma^(3/2).

The reference solver used here is deliberately NOT the package's solve_zener_ode (and not
the LSODA solve the tests use): it removes the sigma^(3/2) non-analyticity at both ends by
taking s = sqrt(sigma) as the independent variable there,

    dtau/ds = 2 s / (p - lambda s^3),   dp/ds = -2 s^4 / (p - lambda s^3),

which is analytic wherever sigma' = p - lambda s^3 != 0, so every phase is smooth and
the integrators keep their full order:
  1. s from 0 up to the point where sigma' = 1/2 (sigma' falls monotonically while rising),
  2. tau as the variable (sigma > 0, analytic) until sigma' = -sqrt(2) sigma^(5/4), past the
     maximum (after the maximum sigma' < 0 until the rebound; this switch point is where the
     s-form is well conditioned, for every lambda),
  3. s from there down to exactly 0: tau(0) = tau0 and e_ze = -p(0).
Phases 1 and 3 use DOP853; phase 2 uses DOP853 for lambda <= 20 and Radau (stiff slow
manifold) above.  All at rtol = 1e-13; agreement with independent solves is ~1e-12.

What is stored
--------------
1. For lambda <= LAM_ASYM = 6: Chebyshev interpolants (degree 24 on pieces of width 0.5)
   of ln e_ze and ln tau0, used to produce node values and slopes.
2. For lambda >= LAM_ASYM the structure of the problem is used (found and verified here):
   the substitution sigma = lambda^-4 S, p = lambda^-5 P, tau = lambda T maps Eq. (10) with
   parameter lambda onto the lambda = 1 system with initial velocity lambda^5.  Large
   lambda therefore means a fast initial layer, a long creep down the attracting slow
   manifold lambda sigma^(3/2) ~ p, and a universal final ejection.  Consequences:
       e_ze  = E_INF lambda^-5           (corrections ~exp(-3 lambda^(5/3)): < 1e-13 for
                                          lambda >= 4, below double precision for >= 6)
       tau0  = lambda (5 ln lambda + g(u)),  u = lambda^(-5/3),
       g(u)  = G0 + 3 u + 0.957 u^2 + 0.99 u^3 + ...,  smooth (analytic) in u.
   E_INF (the mean of e lambda^5 over the solves) and a Chebyshev series of g on
   [0, LAM_ASYM^(-5/3)] are fitted to direct solves at Chebyshev nodes in u (lambda from 6
   to ~300).  This representation is valid for all lambda >= 6, up to infinity.
3. The runtime table: cubic Hermite data (value and d/dlambda of e_ze and tau0) at nodes
   lambda = k h (h = 1/128 by default) taken from 1. below LAM_ASYM and from 2. above.  The
   values are first computed on the whole fine grid k = 0..K (K h >= 100 + h); then nodes are
   chosen greedily with dyadic widths (1, 2, 4, ... fine cells, aligned) such that the cubic
   Hermite error bound max|f^(4)/f| (h w)^4 / 384 stays below --tol (3e-10) for both
   functions (~2150 nodes instead of 12800: e_ze ~ lambda^-5 flattens at large lambda).  The
   runtime module builds the cubic pieces from them.

The script prints the achieved maximum relative errors of the final (interpolated) values
on a check grid between nodes, both against representations 1./2. (densely) and against
fresh reference solves at lambda values away from the nodes.
"""
from __future__ import annotations

import argparse
import math
import os
import sys
import time
from multiprocessing import Pool

import numpy as np
from numpy.polynomial import chebyshev as C
from scipy.integrate import solve_ivp
from scipy.special import beta

LAM_ASYM = 6.0  # lambda above which the asymptotic-structure representation is used
LAM_TABLE = 100.0  # the runtime table covers [0, LAM_TABLE] (plus one interval)
PIECE_WIDTH = 0.5
PIECE_NODES = 25
G_NODES = 14
RTOL = 1e-13

DEFAULT_OUT = os.path.join(
    os.path.dirname(os.path.abspath(__file__)), os.pardir, "fmu_src", "restitution", "data",
    "zener_table.npz")


# ---------------------------------------------------------------------------------------------
# reference solver (three phases, see module docstring)
# ---------------------------------------------------------------------------------------------
def reference_solve(lam: float, rtol: float = RTOL) -> tuple[float, float]:
    """(e_ze, tau0) [1] of Eq. (10)-(11) for lambda = lam [1], three-phase analytic form."""
    lam = float(lam)
    atol = 1e-40

    def f_s(s, y):  # y = (tau, p), s = sqrt(sigma)
        d = y[1] - lam * s**3
        return [2.0 * s / d, -2.0 * s**4 / d]

    def ev1(s, y):  # sigma' = 1/2 on the way up
        return y[1] - lam * s**3 - 0.5

    ev1.terminal, ev1.direction = True, -1
    r1 = solve_ivp(f_s, (0.0, 10.0), [0.0, 1.0], method="DOP853", rtol=rtol, atol=atol,
                   events=ev1)
    s1 = float(r1.t_events[0][0])
    tau1, p1 = (float(v) for v in r1.y_events[0][0])

    def f_tau(t, y):  # Zener's form, y = (sigma, p)
        q = max(y[0], 0.0) ** 1.5
        return [y[1] - lam * q, -q]

    def jac(t, y):
        r = 1.5 * math.sqrt(max(y[0], 0.0))
        return [[-lam * r, 1.0], [-r, 0.0]]

    def ev2(t, y):  # sigma' = -sqrt(2) sigma^(5/4) past the maximum
        sg = max(y[0], 0.0)
        return y[1] - lam * sg**1.5 + math.sqrt(2.0) * sg**1.25

    ev2.terminal, ev2.direction = True, -1
    method = "DOP853" if lam <= 20.0 else "Radau"
    kw = {"jac": jac} if method == "Radau" else {}
    t_end = tau1 + 50.0 + 3.0 * lam * (5.0 * math.log1p(lam) + 1.0)
    r2 = solve_ivp(f_tau, (tau1, t_end), [s1 * s1, p1], method=method, rtol=rtol, atol=atol,
                   events=ev2, **kw)
    if r2.status < 0 or len(r2.t_events[0]) == 0:
        raise RuntimeError(f"phase 2 failed for lambda={lam}: {r2.message}")
    tau2 = float(r2.t_events[0][0])
    sg2, p2 = (float(v) for v in r2.y_events[0][0])
    r3 = solve_ivp(f_s, (math.sqrt(sg2), 0.0), [tau2, p2], method="DOP853", rtol=rtol,
                   atol=atol)
    if r3.status < 0:
        raise RuntimeError(f"phase 3 failed for lambda={lam}: {r3.message}")
    return -float(r3.y[1, -1]), float(r3.y[0, -1])


def _solve_many(lams, jobs):
    lams = [float(x) for x in np.ravel(lams)]
    if jobs > 1:
        with Pool(jobs) as pool:
            out = pool.map(reference_solve, lams, chunksize=1)
    else:
        out = [reference_solve(x) for x in lams]
    return np.array(out)


def cheb_points(n):
    """Chebyshev points of the first kind on [-1, 1] (interior: no endpoints)."""
    return np.cos(np.pi * (np.arange(n) + 0.5) / n)


# ---------------------------------------------------------------------------------------------
# representations
# ---------------------------------------------------------------------------------------------
class SmallLambda:
    """Piecewise Chebyshev interpolants of ln e and ln tau0 on [0, LAM_ASYM]."""

    def __init__(self, jobs):
        self.edges = np.arange(0.0, LAM_ASYM + 0.5 * PIECE_WIDTH, PIECE_WIDTH)
        z = cheb_points(PIECE_NODES)
        lams = [0.5 * (a + b) + 0.5 * (b - a) * z for a, b in zip(self.edges[:-1], self.edges[1:])]
        vals = _solve_many(np.concatenate(lams), jobs).reshape(len(lams), PIECE_NODES, 2)
        self.ce, self.ct = [], []
        for k in range(len(lams)):
            ce = C.chebfit(z, np.log(vals[k, :, 0]), PIECE_NODES - 1)
            ct = C.chebfit(z, np.log(vals[k, :, 1]), PIECE_NODES - 1)
            self.ce.append(ce)
            self.ct.append(ct)
        tails = [max(abs(c[-4:]).max() for c in (ce, ct)) for ce, ct in zip(self.ce, self.ct)]
        print(f"  small-lambda pieces: {len(lams)} x {PIECE_NODES} nodes, largest of the last 4 "
              f"Chebyshev coefficients: {max(tails):.1e} (noise level of the solves)")

    def __call__(self, lam):
        """e, de/dlam, tau0, dtau0/dlam at scalar lam in [0, LAM_ASYM]."""
        k = min(int(lam / PIECE_WIDTH), len(self.ce) - 1)
        a, b = self.edges[k], self.edges[k + 1]
        z = (2.0 * lam - a - b) / (b - a)
        dz = 2.0 / (b - a)
        le, lt = C.chebval(z, self.ce[k]), C.chebval(z, self.ct[k])
        dle = C.chebval(z, C.chebder(self.ce[k])) * dz
        dlt = C.chebval(z, C.chebder(self.ct[k])) * dz
        e, t = math.exp(le), math.exp(lt)
        return e, e * dle, t, t * dlt


class LargeLambda:
    """e = E_INF lam^-5, tau0 = lam (5 ln lam + g(lam^(-5/3))) for lam >= LAM_ASYM."""

    def __init__(self, jobs):
        self.u_max = LAM_ASYM ** (-5.0 / 3.0)
        z = cheb_points(G_NODES)
        u = 0.5 * self.u_max * (z + 1.0)
        lam = u ** -0.6
        vals = _solve_many(lam, jobs)
        E = vals[:, 0] * lam**5
        g = vals[:, 1] / lam - 5.0 * np.log(lam)
        self.E_inf = float(np.mean(E))
        self.g_cheb = C.chebfit(z, g, G_NODES - 1)
        g0 = float(C.chebval(-1.0, self.g_cheb))
        print(f"  large-lambda fit: lambda in [{lam.min():.3g}, {lam.max():.3g}], "
              f"e lambda^5 = {self.E_inf:.13f} (spread {E.max() / E.min() - 1:.1e}), "
              f"g(0) = {g0:.12f}")
        print(f"  g Chebyshev coefficients: {' '.join(f'{abs(c):.0e}' for c in self.g_cheb)}")
        print(f"  g'(0) = {self.dg(0.0):.9f}, g''(0)/2 = {self._d2g0() / 2:.6f}")

    def g(self, u):
        return C.chebval(2.0 * u / self.u_max - 1.0, self.g_cheb)

    def dg(self, u):
        return C.chebval(2.0 * u / self.u_max - 1.0, C.chebder(self.g_cheb)) * 2.0 / self.u_max

    def _d2g0(self):
        return C.chebval(-1.0, C.chebder(self.g_cheb, 2)) * (2.0 / self.u_max) ** 2

    def __call__(self, lam):
        lam = float(lam)
        u = lam ** (-5.0 / 3.0)
        e = self.E_inf * lam**-5
        de = -5.0 * e / lam
        g = self.g(u)
        t = lam * (5.0 * math.log(lam) + g)
        dt = 5.0 * math.log(lam) + g + 5.0 - (5.0 / 3.0) * u * self.dg(u)
        return e, de, t, dt


# ---------------------------------------------------------------------------------------------
# Hermite table and its evaluation (same formulas as restitution.zener_exact)
# ---------------------------------------------------------------------------------------------
def select_nodes(f_list, h, k_max, tol, k_end):
    """Greedy dyadic node selection on the fine grid k h, k = 0..k_max, up to past k_end.

    Interval widths are powers of 2 (in fine cells, <= 128) and start at multiples of their
    width; an interval is accepted if the cubic Hermite error bound max|f^(4)/f| (h w)^4/384,
    with f^(4) from 4th differences on the fine grid over the interval and its neighbours,
    is <= tol for every f in f_list.  Returns the node indices (k_0 = 0, last > k_end).
    """
    r = np.zeros(k_max + 1)
    for f in f_list:
        q = np.zeros(k_max + 1)
        q[2:-2] = np.abs(np.diff(f, 4)) / h**4 / np.abs(f[2:-2])
        q[:2], q[-2:] = q[2], q[-3]
        r = np.maximum(r, q)
    nodes, k = [0], 0
    while k <= k_end:
        best = 1
        w = 2
        while w <= 128 and k % w == 0 and k + w <= k_max:
            if r[max(k - w, 0):min(k + 2 * w, k_max) + 1].max() * (w * h) ** 4 / 384.0 > tol:
                break
            best, w = w, 2 * w
        k += best
        nodes.append(k)
    return np.array(nodes, dtype=np.int64)


def hermite_pieces(k, f, df, h):
    """Cubic pieces a0 + t (a1 + t (a2 + t a3)) with t = lam/h - k_j in [0, k_{j+1} - k_j).

    (Same formulas as restitution.zener_exact; w is a power of 2, so dividing by it is exact.)
    """
    w = np.diff(k).astype(float)
    hw = h * w
    f0, f1, d0, d1 = f[:-1], f[1:], hw * df[:-1], hw * df[1:]
    return np.stack([f0, d0 / w, (3.0 * (f1 - f0) - 2.0 * d0 - d1) / w**2,
                     (2.0 * (f0 - f1) + d0 + d1) / w**3])


def hermite_eval(k, coef, h, lam):
    x = np.asarray(lam, dtype=float) / h
    j = np.searchsorted(k, x, side="right") - 1
    t = x - k[j]
    a0, a1, a2, a3 = coef[:, j]
    return a0 + t * (a1 + t * (a2 + t * a3))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default=DEFAULT_OUT)
    ap.add_argument("--h", type=float, default=1.0 / 128.0,
                    help="finest grid step of the runtime table (use a power of 2)")
    ap.add_argument("--tol", type=float, default=3e-10,
                    help="Hermite error bound used to choose the (dyadic) node spacing")
    ap.add_argument("--jobs", type=int, default=min(2, os.cpu_count() or 1))
    ap.add_argument("--n-check", type=int, default=60,
                    help="number of fresh reference solves between nodes for the final check")
    args = ap.parse_args(argv)
    t_start = time.time()
    h = args.h

    tau_hertz = 2.0 * 1.25**0.4 * 0.4 * beta(0.4, 0.5)
    e00, t00 = reference_solve(0.0)
    print(f"reference solver at lambda = 0: e - 1 = {e00 - 1:.1e}, "
          f"tau0/closed form - 1 = {t00 / tau_hertz - 1:.1e}")

    print("solving for the small-lambda pieces ...")
    small = SmallLambda(args.jobs)
    print("solving for the large-lambda representation ...")
    large = LargeLambda(args.jobs)

    # consistency of the two representations where they meet
    for lam in (LAM_ASYM - 1.0, LAM_ASYM):
        a, b = small(lam), large(lam)
        print(f"  at lambda = {lam}: small/large - 1: e {a[0] / b[0] - 1:.1e}, "
              f"tau0 {a[2] / b[2] - 1:.1e}, de {a[1] / b[1] - 1:.1e}, dtau0 {a[3] / b[3] - 1:.1e}")

    K = int(math.ceil((LAM_TABLE + h) / h - 1e-9))  # fine grid k h, k = 0..K, K h > 100
    grid = np.arange(K + 1) * h
    fine = np.array([small(x) if x <= LAM_ASYM else large(x) for x in grid])
    fine[0, 0] = 1.0  # e(0) = 1 exactly (the representation gives 1 - O(1e-14))
    fine[0, 2] = tau_hertz  # tau0(0), closed form
    if not (np.all(np.diff(fine[:, 0]) < 0) and np.all(np.diff(fine[:, 2]) > 0)):
        raise RuntimeError("e_ze / tau0 not monotonic on the fine grid")
    k_end = int(round(LAM_TABLE / h))
    k = select_nodes([fine[:, 0], fine[:, 2]], h, K, args.tol, k_end)
    e, de, tau0, dtau0 = fine[k].T
    widths, counts = np.unique(np.diff(k), return_counts=True)
    print(f"nodes: {k.size} of the {K + 1} fine-grid points (h = {h:g}); interval widths "
          + ", ".join(f"{w}h: {c}" for w, c in zip(widths, counts)))
    ce, ct = hermite_pieces(k, e, de, h), hermite_pieces(k, tau0, dtau0, h)

    # check 1: interpolation error vs the representations, 7 points inside every fine cell
    tt = (np.arange(1, 8) / 8.0)
    lam_c = (np.arange(K)[:, None] + tt[None, :]).ravel() * h
    lam_c = lam_c[lam_c <= LAM_TABLE]
    ref = np.array([small(x) if x <= LAM_ASYM else large(x) for x in lam_c])
    rel_e = hermite_eval(k, ce, h, lam_c) / ref[:, 0] - 1.0
    rel_t = hermite_eval(k, ct, h, lam_c) / ref[:, 2] - 1.0
    print(f"check 1: cubic Hermite vs representations at {lam_c.size} points between nodes:")
    for lo, hi in ((0.0, 1.5), (1.5, LAM_ASYM), (LAM_ASYM, LAM_TABLE)):
        m = (lam_c >= lo) & (lam_c <= hi)
        print(f"  lambda in [{lo:g}, {hi:g}]: max |rel err| e {np.abs(rel_e[m]).max():.2e}, "
              f"tau0 {np.abs(rel_t[m]).max():.2e}")

    # check 2: against fresh reference solves away from nodes (and from the fit nodes)
    rng = np.random.default_rng(12345)
    n1 = args.n_check * 2 // 3
    lam_chk = np.concatenate([rng.uniform(0.0, 1.5, n1 // 2),
                              rng.uniform(1.5, LAM_ASYM, n1 - n1 // 2),
                              np.exp(rng.uniform(math.log(LAM_ASYM), math.log(LAM_TABLE),
                                                 args.n_check - n1))])
    lam_chk = np.sort(np.append(lam_chk, [LAM_TABLE]))
    vals = _solve_many(lam_chk, args.jobs)
    rel_e = hermite_eval(k, ce, h, lam_chk) / vals[:, 0] - 1.0
    rel_t = hermite_eval(k, ct, h, lam_chk) / vals[:, 1] - 1.0
    print(f"check 2: table vs {lam_chk.size} fresh reference solves between nodes:")
    for lo, hi in ((0.0, 1.5), (1.5, LAM_TABLE)):
        m = (lam_chk >= lo) & (lam_chk <= hi) if lo == 0.0 else (lam_chk > lo) & (lam_chk <= hi)
        print(f"  lambda in {'[' if lo == 0 else '('}{lo:g}, {hi:g}]: max |rel err| "
              f"e {np.abs(rel_e[m]).max():.2e}, tau0 {np.abs(rel_t[m]).max():.2e}")
    # and the asymptotic form beyond the table
    lam_big = np.array([150.0, 1000.0, 1e4])
    vals = _solve_many(lam_big, args.jobs)
    for x, (e_r, t_r) in zip(lam_big, vals):
        e_a, _, t_a, _ = large(x)
        print(f"  asymptotic form at lambda = {x:g}: rel err e {e_a / e_r - 1:.1e}, "
              f"tau0 {t_a / t_r - 1:.1e}")

    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    np.savez(
        args.out,
        format_version=np.int64(2),
        h=np.float64(h),
        lam_table_max=np.float64(LAM_TABLE),
        k=k, e=e, de=de, tau0=tau0, dtau0=dtau0,
        asym_lam_min=np.float64(LAM_ASYM),
        asym_E_inf=np.float64(large.E_inf),
        asym_u_max=np.float64(large.u_max),
        asym_g_cheb=np.asarray(large.g_cheb, dtype=float),
        info=np.array(
            "Zener Eq. (10)-(11) of I. Green, Nonlinear Dyn (2022): e_ze = -sigma'(tau0) and tau0 "
            "[1]. e, de, tau0, dtau0: values and d/dlambda at the nodes lambda = k*h (k: int "
            "array, widths powers of 2), for cubic Hermite interpolation. For lambda >= "
            "asym_lam_min: e = asym_E_inf*lambda^-5, "
            "tau0 = lambda*(5 ln lambda + g(u)), u = lambda^(-5/3), g = chebval(2u/asym_u_max - 1, "
            "asym_g_cheb). Made by build_scripts/make_zener_table.py."),
    )
    size = os.path.getsize(args.out)
    print(f"wrote {os.path.abspath(args.out)}: {k.size} nodes, h = {h:g}, {size / 1024:.0f} KiB, "
          f"in {time.time() - t_start:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
