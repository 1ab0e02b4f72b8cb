"""The 95 % interval of a sweep output's mean at SMALL n (restitution.sweep.statistics): mean -+ t(0.975, n - 1)
s / sqrt(n), Student's t at n - 1 degrees of freedom. The reference is scipy.stats.t.ppf(0.975, n - 1) and
numpy's std(ddof=1), computed here, at n = 2, 3, 5, 10, where the degrees of freedom matter most: t at n
instead of n - 1 is 66 % too narrow at n = 2, 26 % at 3, 7 % at 5, 1.5 % at 10 (and 0.2 % at n = 25, 8e-8 at
4000, the sizes tests/sweep/test_sweep_statistics.py looks at). Tolerance 1e-9 relative: rounding only (the
quantile is computed to ~1e-13, tests/sweep/test_sweep_student_t.py; the mean and std by other sums).

Every way the statistics are computed is covered: describe() of one group and of many groups at once (the
per-grid-point statistics), and a real sweep's summary (mean_ci95 of the whole sweep and of each grid point)."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats

from restitution.sweep import SweepSpec, run_sweep
from restitution.sweep.statistics import SweepStatistics, describe

SMALL_N = (2, 3, 5, 10)


def reference_half(values) -> float:
    values = np.asarray(values, dtype=float)
    n = values.size
    return float(stats.t.ppf(0.975, n - 1) * np.std(values, ddof=1) / math.sqrt(n))


@pytest.mark.parametrize("n", SMALL_N)
def test_one_group_at_small_n(n):
    values = np.random.default_rng(n).normal(0.6, 0.05, n)
    d = describe(values)
    assert int(d["n"][0]) == n
    assert d["mean"][0] == pytest.approx(np.mean(values), rel=1e-12)
    assert d["ci_half"][0] == pytest.approx(reference_half(values), rel=1e-9)


def test_groups_of_different_small_sizes_at_once():
    """One call with groups of 2, 3, 5 and 10 values, interleaved: each group's half-width is its own."""
    rng = np.random.default_rng(7)
    groups = rng.permutation(np.repeat(np.arange(len(SMALL_N)), SMALL_N))
    values = rng.normal(1.0, 0.1, groups.size)
    d = describe(values, groups, len(SMALL_N))
    for g, n in enumerate(SMALL_N):
        mine = values[groups == g]
        assert int(d["n"][g]) == n
        assert d["ci_half"][g] == pytest.approx(reference_half(mine), rel=1e-9), n


@pytest.mark.parametrize("n", (2, 3, 5))
def test_the_interval_covers_the_true_mean_95_percent_of_the_time_at_small_n(n):
    """10,000 data sets of n normal draws each, made here: the interval holds the true mean in 95 % of them.
    Binomial sd sqrt(10000 0.95 0.05) = 21.8 data sets: the bound +-80 is 3.7 sd (a false failure once in 4000
    runs; the seed is fixed). Student's t at n degrees of freedom would cover 85.5 %, 91.4 % and 93.8 % at n = 2,
    3 and 5: 950, 360 and 120 data sets short."""
    n_sets = 10_000
    rng = np.random.default_rng(100 + n)
    draws = rng.normal(0.5, 0.02, (n_sets, n))
    d = describe(draws.ravel(), np.repeat(np.arange(n_sets), n), n_sets)
    hits = int(np.count_nonzero(np.abs(d["mean"] - 0.5) <= d["ci_half"]))
    assert abs(hits - 0.95 * n_sets) <= 80, hits


@pytest.mark.parametrize("samples", (2, 5))
def test_a_sweeps_summary_at_small_n(samples):
    """A real random sweep (plate.Sy scattered, two approach speeds on a grid): mean_ci95 of the whole sweep
    (2 x ``samples`` values) and of each grid point (``samples`` values), against the table's own values."""
    spec = SweepSpec(pairs=["s2_tool_steel/al_6061"], grid={"v_approach": [1.0, 2.0]}, fixed={"t_over_d": 0.5},
                     random={"plate.Sy": "uniform_rel:0.15"}, samples=samples, seed=11)
    res = run_sweep(spec, scheduler="serial")
    statistics = SweepStatistics(spec)
    statistics.add(res.columns)
    summary = statistics.summary()
    e = np.asarray(res["e"], dtype=float)
    entry = summary["outputs"]["e"]
    assert entry["n"] == 2 * samples
    lo, hi = entry["mean_ci95"]
    assert (hi - lo) / 2 == pytest.approx(reference_half(e), rel=1e-9)
    assert (hi + lo) / 2 == pytest.approx(np.mean(e), rel=1e-12)
    for point in summary["by_point"]:
        mine = e[np.asarray(res["v_approach"]) == point["v_approach"]]
        lo, hi = point["outputs"]["e"]["mean_ci95"]
        assert point["outputs"]["e"]["n"] == samples == mine.size
        assert (hi - lo) / 2 == pytest.approx(reference_half(mine), rel=1e-9)
