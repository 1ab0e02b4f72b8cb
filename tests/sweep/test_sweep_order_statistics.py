"""restitution.sweep.order_statistics: the k-th smallest values, exactly as np.partition picks them.

The reference is numpy's own selection (np.partition, a different algorithm: introselect), so every
comparison is exact equality: selection copies values, it computes none, and the order statistics of
a given array are unique numbers whatever the method. The data are made to stress what the counting
into bins relies on: smooth, heavy-tailed, discrete, constant, sorted and reversed values, far
outliers, a span that overflows a double, ranks at both ends, and a wanted bin crowded enough for a
nested level.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from restitution.sweep import order_statistics as osx
from restitution.sweep.order_statistics import Scratch, order_statistics

N = 200_000  # above the direct-partition size, so that the bins are used


def _datasets():
    rng = np.random.default_rng(20261126)
    u = rng.random(N)
    return {
        "uniform": u,
        "normal": rng.normal(3.0, 0.2, N),
        "lognormal sigma 5": rng.lognormal(0.0, 5.0, N),
        "cauchy": rng.standard_cauchy(N),
        "one far outlier": np.r_[u, 1e300],
        "both far ends": np.r_[u * 1e-12 + 1.0, -1e308, 1e308],  # their span overflows to inf
        "two values": np.r_[np.zeros(N // 2), np.ones(N // 2)],
        "three codes": rng.integers(0, 3, N).astype(float),
        "constant": np.full(N, 2.5),
        "mostly constant": np.r_[np.full(N - 10, 7.0), rng.random(10)],
        "sorted": np.sort(u),
        "reversed": np.sort(u)[::-1].copy(),
        "negative and tiny": -rng.random(N) * 1e-300,
        "periodic with the sample's stride": np.tile(np.arange(N // osx.SAMPLE, dtype=float), osx.SAMPLE + 1)[:N],
        "a crowded middle": np.r_[rng.random(N // 2), 0.5 + rng.random(N // 2) * 1e-9],
    }


@pytest.mark.parametrize("name", list(_datasets()))
def test_the_percentiles_ranks_are_np_partitions(name):
    values = _datasets()[name]
    n = values.size
    before = values.copy()
    ranks = []
    for p in (2.5, 50.0, 97.5):
        below = int(np.floor((n - 1) * p / 100))
        ranks += [below, min(below + 1, n - 1)]
    got = order_statistics(values, ranks)
    assert np.array_equal(got, np.partition(values, ranks)[ranks])
    assert np.array_equal(values, before)  # left unchanged


@pytest.mark.parametrize("name", ["uniform", "cauchy", "one far outlier", "sorted", "three codes"])
def test_any_ranks_in_any_order_and_the_extremes(name):
    values = _datasets()[name]
    n = values.size
    ranks = [n - 1, 0, 1, n // 3, n // 3, n - 2, n // 2]
    got = order_statistics(values, ranks, Scratch())
    assert np.array_equal(got, np.partition(values, ranks)[ranks])


def test_one_scratch_serves_arrays_of_every_size_in_turn():
    rng = np.random.default_rng(7)
    scratch = Scratch()
    for n in (300_000, 50_000, 1_000, 120_000):
        values = rng.gamma(2.0, size=n)
        ranks = [n // 40, n // 2, n - n // 40]
        assert np.array_equal(order_statistics(values, ranks, scratch), np.partition(values, ranks)[ranks])


def test_a_nested_level_is_exact(monkeypatch):
    """Fewer bins make each wanted bin hold more than the direct size, so that bin is counted again."""
    monkeypatch.setattr(osx, "BINS", 8)
    monkeypatch.setattr(osx, "CROWDED", 1)  # never give up on crowded bins here
    values = np.random.default_rng(3).random(N)
    ranks = [5_000, 100_000, 100_001, 195_000]
    assert np.array_equal(order_statistics(values, ranks), np.partition(values, ranks)[ranks])


def test_small_inputs_and_bad_ranks():
    assert np.array_equal(order_statistics([3.0, 1.0, 2.0], [0, 2]), [1.0, 3.0])
    assert order_statistics(np.arange(5.0), []).size == 0
    with pytest.raises(IndexError, match="within 0 .. 4"):
        order_statistics(np.arange(5.0), [5])
    with pytest.raises(IndexError):
        order_statistics(np.arange(5.0), [-1])


# --- the moments computed in the same passes --------------------------------------------------------
def _exact_moments(values):
    """The mean and the sum of squared deviations by math.fsum (exactly rounded sums): the reference."""

    mean = math.fsum(values) / values.size
    mean += math.fsum(values - mean) / values.size  # the residual's exact sum corrects the division
    return mean, math.fsum((values - mean) ** 2)


@pytest.mark.parametrize("name", ["uniform", "normal", "lognormal sigma 5", "cauchy", "one far outlier",
                                  "sorted", "three codes", "constant", "a crowded middle"])
def test_moments_come_with_the_order_statistics(name):
    """Mean to 1e-13 and sum of squares to 1e-11 relative (of its own size; its shifted form may lose up
    to 64 + log2(n) ulps by design, and the pairwise sums log2(n) more), order statistics exact."""
    values = _datasets()[name]
    with np.errstate(over="ignore"):
        finite_moments = np.isfinite(np.sum(values ** 2))
    n = values.size
    ranks = [n // 40, n // 40 + 1, n // 2, n // 2 + 1, n - n // 40 - 1, n - n // 40]
    got = osx.moments_and_order_statistics(values, ranks, Scratch())
    if not finite_moments:  # a square beyond the largest double: the caller is told to take another way
        assert got is None or np.isfinite(got[1])
        return
    mean, squares, picked = got
    want_mean, want_squares = _exact_moments(values)
    assert mean == pytest.approx(want_mean, rel=1e-13, abs=1e-300)
    assert squares == pytest.approx(want_squares, rel=1e-11, abs=1e-300)
    assert np.array_equal(picked, np.partition(values, ranks)[ranks])


def test_a_large_offset_keeps_the_variance():
    """1e8 + unit noise: squares about a shift far from zero lose nothing (about zero, they would lose all)."""
    values = 1e8 + np.random.default_rng(5).normal(size=N)
    mean, squares, _ = osx.moments_and_order_statistics(values, [N // 2], Scratch())
    want_mean, want_squares = _exact_moments(values)
    assert mean == pytest.approx(want_mean, rel=1e-15)
    assert squares == pytest.approx(want_squares, rel=1e-9)  # 64 ulps of 1e16 over a variance of 1: 1e-13


def test_an_outlier_at_the_lowest_rank_moves_the_moments_about_the_mean():
    """Ranks that include the minimum, a far outlier: the shift is far from the mean, and the moments are
    computed about the mean instead (still to 1e-11)."""
    values = np.r_[np.random.default_rng(6).random(N), -1e9]
    mean, squares, picked = osx.moments_and_order_statistics(values, [0, N // 2], Scratch())
    want_mean, want_squares = _exact_moments(values)
    assert mean == pytest.approx(want_mean, rel=1e-13) and squares == pytest.approx(want_squares, rel=1e-11)
    assert picked[0] == -1e9


def test_values_not_all_finite_give_none():
    for bad in (np.nan, np.inf, -np.inf):
        values = np.r_[np.random.default_rng(1).random(N), bad]
        assert osx.moments_and_order_statistics(values, [N // 2], Scratch()) is None
    assert osx.moments_and_order_statistics(np.array([1.0, np.nan]), [0], Scratch()) is None  # small too


@pytest.mark.parametrize("values", [
    np.array([]), np.array([np.nan]), np.array([3.0, np.nan, 1.0, np.nan, 3.0, -0.0, 0.0]),
    np.random.default_rng(7).integers(0, 5, 40).astype(float), np.random.default_rng(8).integers(0, 300, 2000),
    np.arange(12.0).reshape(3, 4)[::-1]], ids=["empty", "nan", "nans and zeros", "few floats", "ints", "2-D"])
def test_distinct_is_numpys_unique(values):
    """distinct() gives np.unique's distinct values and inverse (numpy's own, the reference: the same sorted
    numbers, one NaN for any NaNs), without importing numpy.ma."""
    want, want_inverse = np.unique(values, return_inverse=True)
    got, inverse = osx.distinct(values, return_inverse=True)
    assert np.array_equal(got, want, equal_nan=True) and got.dtype == want.dtype
    assert np.array_equal(inverse, want_inverse.ravel())
    assert np.array_equal(osx.distinct(values), want, equal_nan=True)


@pytest.mark.parametrize("n", [0, 1, 7, osx.SQUARE_BLOCK - 1, osx.SQUARE_BLOCK, osx.SQUARE_BLOCK + 1,
                               3 * osx.SQUARE_BLOCK + 5])
def test_sum_of_squares_is_the_exact_sum_to_the_pairwise_error(n):
    """sum(x^2) against math.fsum of the squares (the exactly rounded sum of the rounded squares): the
    terms are >= 0, so numpy's pairwise sums err by at most about log2(n) ulps of the total, and each
    block's sum is added once more (n / block more additions): 1e-13 relative bounds both for n < 2^18."""
    x = np.random.default_rng(n).normal(size=n) * 3.0
    want = math.fsum((x * x).tolist())
    assert osx.sum_of_squares(x) == pytest.approx(want, rel=1e-13, abs=0.0)
    assert osx.sum_of_squares(x[::2]) == pytest.approx(math.fsum((x[::2] * x[::2]).tolist()), rel=1e-13, abs=0.0)
