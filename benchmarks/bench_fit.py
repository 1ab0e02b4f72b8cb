#!/usr/bin/env python
"""What a calibration from a drop test costs (restitution.fit), and optionally how often its intervals hold the truth.

    .venv/bin/python benchmarks/bench_fit.py [--reps N] [--seed N] [--coverage N]
        [--coverage-bayes M] [--drag] [--write]

The data are made here, with a fixed seed, from known parameters: a chrome-steel ball (d = 6.35 mm)
on an Al 6061 plate (t = 6.35 mm) whose yield strength is 250 MPa (the preset says 290 MPa, where
every fit starts). The plate yields first, so plate.Sy is the parameter fitted:

* 20 rebound pairs, approach speeds uniform over 0.5-5 m/s, 1 % relative Gaussian noise on v_out;
* one drop from h0 = 0.3 m: the impacts while the interval between them is 5 ms or more (17), each
  time with 30 us of Gaussian jitter.

Measured, in one run, the variants interleaved batch by batch (harness.py: CPU time of
this thread, ``time.thread_time``, so other jobs on a shared machine do not inflate it; medians over
``--reps`` batches):

(a) a 1-parameter fit (plate.Sy, with its 95 % profile-likelihood interval) of the 20 pairs, as a
    multiple of ONE vectorized ``restitution.impact`` call on the same 20 speeds (goal <= 100x);
(b) an emcee posterior of plate.Sy from the 20 pairs with the sampler's defaults (goal <= 1 s);
(c) a 1-parameter fit of the drop's impact times, its first impact speed v_1 fitted too (as when
    no drop height is given), and with v_1 from h0.

``--coverage N`` then fits N fresh data sets of each kind (new noise, same truth) and counts how
often the 95 % intervals contain the true plate.Sy; ``--coverage-bayes M`` does the same for M
posteriors of pairs (and, for the same data sets, the profile-likelihood intervals again).
``--drag`` fits noise-free drops computed with quadratic air drag, which the model leaves out, and
prints the bias it makes. ``--write`` puts the printed block into docs/performance.md between its
``bench_fit`` markers. The run the page shows (``--coverage 2000 --coverage-bayes 400 --drag``)
takes about 6 minutes on a shared 2-core machine; the costs alone, about 15 s.
"""
from __future__ import annotations

import argparse
import math
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
for _p in (ROOT / "fmu_src", ROOT / "benchmarks"):
    if str(_p) not in sys.path:
        sys.path.insert(0, str(_p))

import restitution as r  # noqa: E402
from accuracy_bench.docs_block import replace_block  # noqa: E402
from harness import interleaved, median, median_ratio, settle_allocator  # noqa: E402
from restitution.fit.datasets import ImpactTimes, ReboundPairs  # noqa: E402
from restitution.fit.estimate import base_of, fit_parameters  # noqa: E402
from restitution.fit.posterior import sample_posterior  # noqa: E402
from harness import cpu_name  # noqa: E402

DOC = ROOT / "docs" / "performance.md"
BEGIN, END = "<!-- bench_fit:begin -->", "<!-- bench_fit:end -->"

G = 9.80665
TRUE_SY = 250e6  #: [Pa] plate.Sy in the data
BASE = base_of(r.Sphere(r.MATERIALS["chrome_steel"], 6.35e-3), r.Plate(r.MATERIALS["al_6061"], 6.35e-3))
TRUTH = {**BASE, "plate_Sy": TRUE_SY}
NAMES = ["plate.Sy"]
H0, JITTER, MIN_INTERVAL = 0.3, 30e-6, 5e-3
GOAL_RATIO, GOAL_POSTERIOR = 100.0, 1.0  #: (a) fit / one impact call, (b) posterior [s]


def make_pairs(rng: np.random.Generator, n: int = 20) -> ReboundPairs:
    """n rebound pairs: v_in uniform over 0.5-5 m/s, v_out = e v_in with 1 % relative Gaussian noise."""
    v_in = rng.uniform(0.5, 5.0, n)
    return ReboundPairs(v_in, r.impact(v_in, **TRUTH).e * v_in * (1.0 + 0.01 * rng.standard_normal(n)))


def clean_drop() -> np.ndarray:
    """The impact times [s, from the release] of a drop from H0 (no noise), while the intervals stay >= 5 ms."""
    v, t = math.sqrt(2.0 * G * H0), math.sqrt(2.0 * H0 / G)
    times = [t]
    while True:
        v = float(r.impact(v, **TRUTH).e) * v
        if 2.0 * v / G < MIN_INTERVAL:
            return np.array(times)
        t += 2.0 * v / G
        times.append(t)


def make_times(rng: np.random.Generator, clean: np.ndarray) -> ImpactTimes:
    return ImpactTimes(clean + JITTER * rng.standard_normal(clean.size))


def costs(pairs: ReboundPairs, times: ImpactTimes, reps: int, batch_seconds: float, seed: int) -> dict:
    """Seconds of CPU per run of each variant (medians over ``reps`` interleaved batches) and the ratio (a)."""
    v_in = pairs.v_in
    counts = {}

    def impact_call(n):
        for _ in range(n):
            r.impact(v_in, **BASE)
        return n

    def fit(data, **kw):
        def run(n):
            for _ in range(n):
                res = fit_parameters(data, BASE, NAMES, **kw)
            counts[data.kind + ("_h0" if kw else "")] = res.evaluations
            return n
        return run

    def posterior(n):
        for _ in range(n):
            post = sample_posterior(pairs, BASE, NAMES, seed=seed)
        counts["posterior"] = (post.walkers, post.steps + post.burn)
        return n

    variants = {"impact": impact_call, "fit_pairs": fit(pairs), "posterior": posterior,
                "fit_times": fit(times), "fit_times_h0": fit(times, h0=H0)}
    for run in variants.values():  # imports, first-call caches
        run(1)
    settle_allocator()
    t = interleaved(variants, reps, batch_seconds)
    out = {name: median(values) for name, values in t.items()}
    out["ratio"] = median_ratio(t["fit_pairs"], t["impact"])
    out["spread"] = {name: (min(values), max(values)) for name, values in t.items()}
    out["evaluations"] = counts
    return out


def coverage(n: int, n_bayes: int, seed: int, clean: np.ndarray) -> dict:
    """How many of ``n`` fresh data sets of each kind give a 95 % interval that holds the true plate.Sy
    (and of ``n_bayes`` posteriors of pairs); the median relative half-width of the intervals; wall time."""
    out = {}
    kinds = {"pairs": (lambda g: make_pairs(g), {}), "times": (lambda g: make_times(g, clean), {}),
             "times_h0": (lambda g: make_times(g, clean), {"h0": H0})}
    for label, (make, kw) in kinds.items() if n else ():
        hits, widths, t0 = 0, [], time.perf_counter()
        for i in range(n):
            p = fit_parameters(make(np.random.default_rng([seed, 1, i])), BASE, NAMES, **kw)["plate.Sy"]
            hits += p.ci95[0] <= TRUE_SY <= p.ci95[1]
            widths.append(0.5 * (p.ci95[1] - p.ci95[0]) / p.estimate)
        out[label] = {"n": n, "hits": hits, "width": median(widths), "wall": time.perf_counter() - t0}
    if n_bayes:
        hits, same, widths, t0 = 0, 0, [], time.perf_counter()
        for i in range(n_bayes):
            data = make_pairs(np.random.default_rng([seed, 1, i]))  # the first n_bayes data sets of "pairs"
            post = sample_posterior(data, BASE, NAMES, seed=seed + i)
            lo, hi = post.interval95["plate.Sy"]
            hits += lo <= TRUE_SY <= hi
            widths.append(0.5 * (hi - lo) / post.median["plate.Sy"])
            ci = fit_parameters(data, BASE, NAMES)["plate.Sy"].ci95
            same += ci[0] <= TRUE_SY <= ci[1]
        out["posterior"] = {"n": n_bayes, "hits": hits, "width": median(widths), "wall": time.perf_counter() - t0,
                            "profile_same_data": same}
    return out


def drag_drop(h0: float, d: float = 6.35e-3, rho: float = 7700.0, rho_air: float = 1.2, cd: float = 0.47):
    """(impact times [s], terminal speed [m/s]) of a drop from rest at ``h0`` [m] with quadratic air drag
    (drag coefficient ``cd``), noise-free, while the intervals stay >= 5 ms: the closed forms of rise and fall
    against F = 1/2 rho_air cd A v^2 (what restitution.fit leaves out)."""
    m, area = rho * math.pi / 6.0 * d ** 3, math.pi * d * d / 4.0
    vt = math.sqrt(2.0 * m * G / (rho_air * cd * area))

    def fall(h):  # (speed at the plate, time) after falling from rest through h
        return vt * math.sqrt(-math.expm1(-2.0 * G * h / vt ** 2)), (vt / G) * math.acosh(math.exp(G * h / vt ** 2))

    v, t = fall(h0)
    times = [t]
    while True:
        u = float(r.impact(v, **TRUTH).e) * v
        rise, apex = (vt / G) * math.atan(u / vt), vt ** 2 / (2.0 * G) * math.log1p((u / vt) ** 2)
        v, down = fall(apex)
        if rise + down < MIN_INTERVAL:
            return np.array(times), vt
        t += rise + down
        times.append(t)


def drag_bias(heights=(0.1, 0.3, 1.0)) -> list[dict]:
    """plate.Sy fitted (v_1 fitted) to noise-free drops with air drag, from each of ``heights`` [m]."""
    rows = []
    for h0 in heights:
        times, vt = drag_drop(h0)
        p = fit_parameters(ImpactTimes(times), BASE, NAMES)["plate.Sy"]
        rows.append({"h0": h0, "n": times.size, "vt": vt, "v1": math.sqrt(2.0 * G * h0), "estimate": p.estimate,
                     "ci95": p.ci95})
    return rows


def _band(n: int) -> str:
    """The range a true 95 % coverage gives k/n in, 19 times in 20 (normal approximation of the binomial)."""
    half = 1.96 * math.sqrt(0.95 * 0.05 / n)
    return f"{100 * (0.95 - half):.1f}-{100 * min(0.95 + half, 1.0):.1f} %"


def report(c: dict, cov: dict | None, drag: list | None, args, n_pairs: int, n_times: int, wall: float) -> str:
    ms = 1e3
    ev = c["evaluations"]
    lines = [
        f"bench_fit.py on {time.strftime('%Y-%m-%d')}: {cpu_name()}, "
        f"{os.cpu_count()} cores (shared), Python {platform.python_version()}, numpy {np.__version__}, "
        f"load average {os.getloadavg()[0]:.1f}; CPU time of this thread, medians of {args.reps} interleaved "
        f"batches; seed {args.seed}; {wall:.0f} s",
        "",
        f"(a) one vectorized restitution.impact call, {n_pairs} speeds:  {c['impact'] * 1e6:8.1f} us",
        f"    1-parameter fit of {n_pairs} rebound pairs (plate.Sy + interval): {c['fit_pairs'] * ms:8.2f} ms "
        f"({ev['rebound_pairs']} model evaluations)",
        f"    fit / impact call = {c['ratio']:.0f}x (goal <= {GOAL_RATIO:.0f}x: "
        f"{'met' if c['ratio'] <= GOAL_RATIO else 'NOT met'})",
        f"(b) emcee posterior of plate.Sy, {n_pairs} pairs:  {c['posterior']:8.3f} s "
        f"({ev['posterior'][1]} steps of {ev['posterior'][0]} walkers; goal <= {GOAL_POSTERIOR:g} s: "
        f"{'met' if c['posterior'] <= GOAL_POSTERIOR else 'NOT met'})",
        f"(c) 1-parameter fit of {n_times} impact times, v_1 fitted: {c['fit_times'] * ms:8.2f} ms "
        f"({ev['impact_times']} model evaluations)",
        f"    the same with v_1 from h0 = {H0:g} m:            {c['fit_times_h0'] * ms:8.2f} ms "
        f"({ev['impact_times_h0']} model evaluations)",
    ]
    lo, hi = c["spread"]["fit_pairs"]
    lines.append(f"    (spread over the batches, fit of pairs: {lo * ms:.2f}-{hi * ms:.2f} ms)")
    if cov:
        lines += ["", f"coverage of the 95 % intervals of plate.Sy (true {TRUE_SY / 1e6:g} MPa), "
                  "fresh noise each time:"]
        labels = {"pairs": f"profile likelihood, {n_pairs} pairs", "times": f"profile likelihood, {n_times} impact "
                  "times, v_1 fitted", "times_h0": f"profile likelihood, {n_times} impact times, v_1 from h0",
                  "posterior": f"posterior 2.5-97.5 %, {n_pairs} pairs"}
        for key, w in cov.items():
            lines.append(f"  {labels[key]:<52} {w['hits']:4d}/{w['n']:<4d} = {100 * w['hits'] / w['n']:5.1f} % "
                         f"(a true 95 % gives {_band(w['n'])}); median half-width {100 * w['width']:.3g} %; "
                         f"{w['wall']:.0f} s")
            if "profile_same_data" in w:
                same = w["profile_same_data"]
                lines.append(f"  {'  profile likelihood, the same data sets':<52} "
                             f"{same:4d}/{w['n']:<4d} = {100 * same / w['n']:5.1f} %")
    if drag:
        lines += ["", f"air drag (left out by the model): plate.Sy fitted to noise-free drops computed with quadratic "
                  f"drag, C_d = 0.47 (terminal speed {drag[0]['vt']:.1f} m/s):"]
        for w in drag:
            lines.append(f"  h0 = {w['h0']:g} m ({w['n']} impacts, drag {100 * (w['v1'] / w['vt']) ** 2:.2g} % of the "
                         f"weight at {w['v1']:.2f} m/s): {w['estimate'] / 1e6:.3f} MPa, "
                         f"{100 * (w['estimate'] / TRUE_SY - 1):+.3f} %")
    return "\n".join(lines)


def write_doc(block: str, path: Path = DOC) -> None:
    replace_block(path, BEGIN, END, block)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--reps", type=int, default=9, help="interleaved batches of each measurement (default 9)")
    parser.add_argument("--batch-seconds", type=float, default=0.3, help="CPU seconds a batch aims at (default 0.3)")
    parser.add_argument("--seed", type=int, default=2026, help="seed of the data (default 2026)")
    parser.add_argument("--coverage", type=int, default=0, metavar="N",
                        help="fit N fresh data sets of each kind and count the intervals holding the truth")
    parser.add_argument("--coverage-bayes", type=int, default=0, metavar="M", help="the same for M posteriors of pairs")
    parser.add_argument("--drag", action="store_true", help="fit drops computed with air drag: the bias it makes")
    parser.add_argument("--write", action="store_true", help=f"put the result into {DOC.relative_to(ROOT)}")
    args = parser.parse_args(argv)

    wall0 = time.perf_counter()
    rng = np.random.default_rng(args.seed)
    clean = clean_drop()
    pairs, times = make_pairs(rng), make_times(rng, clean)
    c = costs(pairs, times, args.reps, args.batch_seconds, args.seed)
    cov = coverage(args.coverage, args.coverage_bayes, args.seed, clean) if args.coverage or args.coverage_bayes \
        else None
    drag = drag_bias() if args.drag else None
    block = report(c, cov, drag, args, pairs.n, times.n, time.perf_counter() - wall0)
    print(block)
    if args.write:
        write_doc(block)
        print(f"wrote {DOC}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
