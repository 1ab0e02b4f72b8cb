"""Exact order statistics of many values in a few linear passes: the k-th smallest values the
percentiles of a sweep's statistics need, without sorting or partitioning all of them.

``np.partition`` picks the six order statistics of three interpolated percentiles from 10^6 values
in about 17 ms; a sweep's summary does so for each of its 14 Real outputs, where the model itself
evaluated the 10^6 cases in 75 ms. Here the values are first counted into equal-width bins over the
span where a small strided sample puts the wanted ranks (one subtraction, one multiplication, one
clip, one conversion to a bin number and one ``bincount``: about 3 ms), the bins that hold the
wanted ranks are found from the counts, and only those bins' members (a few hundred values for smooth
data) are partitioned. Where those bins hold much of the data (clustered or discrete values), the
values are partitioned whole.

The result is exact, not an approximation: the bin number ``floor(clip((x - lo) * scale))`` is a
non-decreasing function of x (correctly rounded subtraction and multiplication by a positive number
preserve order, as do clipping and truncation; values outside the span fall into the end bins), so
every member of a lower bin is <= every member of a higher one, and the values of rank
``start .. end - 1`` are exactly the members of the bin whose counts span those ranks. A wanted
bin's members are selected from the same way.

:func:`moments_and_order_statistics` also gives the mean and the sum of squared deviations, from
the shifted values before they are scaled into bins: two passes where the mean's own would be four.
"""
from __future__ import annotations

import math

import numpy as np

__all__ = ["order_statistics", "moments_and_order_statistics", "Scratch", "distinct"]

#: Equal-width bins a level counts into (a 16 kB count array; smooth data of 10^6 values leaves a few
#: hundred in the bin of each rank).
BINS = 4096
#: When the bins holding the ranks hold more than 1/CROWDED of the values (clustered or discrete
#: values, a heavy tail), they are partitioned whole instead: never much slower than np.partition.
CROWDED = 8
#: Values in the strided sample that places the bins, and the sample ranks the span reaches beyond
#: the wanted ones on each side (so that the wanted ranks fall inside the span for all but odd data).
SAMPLE = 4096
MARGIN = 64
#: Up to this many values, np.partition of them is as cheap as counting them into bins.
DIRECT = 20_000


class Scratch:
    """Work arrays reused from one call to the next (the bins of 10^6 values are 16 MB a call;
    fresh ones cost their page faults every time). Holds no values between calls."""

    def __init__(self):
        self._float = np.empty(0)
        self._bins = np.empty(0, dtype=np.intp)

    def arrays(self, n: int) -> tuple[np.ndarray, np.ndarray]:
        """(a float array, an intp array: np.bincount's own type, which it then counts without a
        converted copy), each of ``n`` elements."""
        if self._float.size < n:
            self._float = np.empty(n)
            self._bins = np.empty(n, dtype=np.intp)
        return self._float[:n], self._bins[:n]


#: Values squared per block by :func:`sum_of_squares` (a 512 kB buffer, in the cache).
SQUARE_BLOCK = 1 << 16


def sum_of_squares(x: np.ndarray) -> float:
    """sum(x^2) of a 1-d float array by numpy's pairwise summation, a block at a time.

    Not ``np.dot(x, x)``: that is BLAS, whose sum depends on the CPU's kernel and on its thread count,
    and whose threads, once woken by a long vector, spin on the other cores after it returns (a 10^6
    sweep's statistics cost 0.1 s of CPU more in whole). Here the order of the additions is numpy's,
    the same on every machine; the cost is one more pass over a buffer that stays in the cache."""
    total = 0.0
    buffer = np.empty(min(x.size, SQUARE_BLOCK))
    for start in range(0, x.size, SQUARE_BLOCK):
        block = x[start:start + SQUARE_BLOCK]
        squares = np.multiply(block, block, out=buffer[:block.size])
        total += float(squares.sum())
    return total


def order_statistics(values: np.ndarray, ranks, scratch: Scratch | None = None) -> np.ndarray:
    """The values of 0-based ``ranks`` (each in 0 .. n - 1) among ``values`` (finite floats, 1-d,
    left unchanged) as if sorted ascending: exactly ``np.partition(values, ranks)[ranks]``.

    ``scratch``: work arrays to reuse between calls (:class:`Scratch`); None makes its own."""
    values = np.asarray(values, dtype=float)
    ranks = np.asarray(ranks, dtype=np.int64)
    if ranks.size and (ranks.min() < 0 or ranks.max() >= values.size):
        raise IndexError(f"ranks {ranks.tolist()} are not all within 0 .. {values.size - 1}")
    return _select(values, ranks, scratch or Scratch())


def moments_and_order_statistics(values: np.ndarray, ranks, scratch: Scratch | None = None):
    """(mean, sum of squared deviations from the mean, :func:`order_statistics` of ``ranks``) of
    ``values`` (1-d floats, n >= 1), in the passes the order statistics make anyway: the values
    shifted by the bins' lower end are summed and squared before they are scaled into bins. None
    where the values are not all finite (their sum is not: a NaN or an infinity among them, or a
    sum beyond the largest double), for the caller to take the finite ones.

    About a shift s, the sum of squares is sum((x - s)^2) - n (mean - s)^2, which loses about
    (mean - s)^2 / variance ulps of it. The shift is the sample value at the lowest wanted rank,
    among the values; where it lies more than 8 standard deviations from the mean (an outlier's rank,
    or extreme data) the moments are computed again about the mean, in two more passes. Small
    inputs, and values the bins cannot spread, take those two passes too."""
    values = np.asarray(values, dtype=float)
    ranks = np.asarray(ranks, dtype=np.int64)
    scratch = scratch or Scratch()
    n = values.size
    lo, hi = _span(values, ranks) if n > DIRECT and ranks.size else (0.0, 0.0)
    if not lo < hi:
        moments = _moments(values, scratch)
        return None if moments is None else (*moments, _select(values, ranks, scratch))
    work, bins = scratch.arrays(n)
    with np.errstate(over="ignore", invalid="ignore"):
        np.subtract(values, lo, out=work)
        total = float(work.sum())
        if not math.isfinite(total):
            return None
        shift = total / n
        squares = sum_of_squares(work) - n * shift * shift
    if not (math.isfinite(squares) and n * shift * shift <= 64.0 * max(squares, 0.0)):
        moments = None  # about the mean instead, once the order statistics are picked
    else:
        moments = (lo + shift, squares)
    picked = _from_shifted(values, ranks, scratch, work, bins, lo, hi)
    moments = moments or _moments(values, scratch)
    return None if moments is None else (*moments, picked)


def _moments(values: np.ndarray, scratch: Scratch):
    """(mean, sum of squared deviations from it) about the mean: numpy's pairwise mean refined by the
    residuals' mean; None where the values are not all finite."""
    with np.errstate(over="ignore", invalid="ignore"):
        mean = float(values.mean())
        if not math.isfinite(mean):
            return None
        residual = np.subtract(values, mean, out=scratch.arrays(values.size)[0])
        shift = float(residual.mean())
        squares = sum_of_squares(residual) - values.size * shift * shift
    return (mean + shift, max(squares, 0.0)) if math.isfinite(squares) else None


def _select(values: np.ndarray, ranks: np.ndarray, scratch: Scratch) -> np.ndarray:
    n = values.size
    if n <= DIRECT or ranks.size == 0:
        return np.partition(values, ranks)[ranks] if ranks.size else np.empty(0)
    lo, hi = _span(values, ranks)
    if not lo < hi:  # the sample sees one value there: all values equal, or discrete or clustered ones
        low = values.min()
        return np.full(ranks.size, low) if low == values.max() else np.partition(values, ranks)[ranks]
    work, bins = scratch.arrays(n)
    with np.errstate(over="ignore"):  # a far value's distance may overflow to inf: clipped after scaling
        np.subtract(values, lo, out=work)
    return _from_shifted(values, ranks, scratch, work, bins, lo, hi)


def _from_shifted(values, ranks, scratch, work, bins, lo, hi) -> np.ndarray:
    """The order statistics, ``work`` holding ``values - lo``."""
    n = values.size
    with np.errstate(over="ignore"):  # a far value's scaled distance may overflow to inf: clipped below
        np.multiply(work, BINS / (hi - lo), out=work)
    np.clip(work, 0, BINS - 1, out=work)  # values beyond the span join the first or last bin
    np.copyto(bins, work, casting="unsafe")  # truncation: the floor of a number in [0, BINS - 1]
    ends = np.cumsum(np.bincount(bins, minlength=BINS))
    which = np.searchsorted(ends, ranks, side="right")  # the bin holding each rank
    picked = distinct(which)
    if (ends[picked] - np.where(picked > 0, ends[picked - 1], 0)).sum() > n // CROWDED:
        return np.partition(values, ranks)[ranks]  # the wanted bins hold much: counting won little
    # every wanted bin's members copied out before any is selected from: a nested level reuses the scratch
    wanted = [(values[bins == b], which == b, ends[b]) for b in picked]
    out = np.empty(ranks.size)
    for members, here, end in wanted:
        out[here] = _select(members, ranks[here] - (end - members.size), scratch)
    return out


def _span(values: np.ndarray, ranks: np.ndarray) -> tuple[float, float]:
    """The range the bins cover: from a strided sample of the values, a little beyond the sample's
    values at the lowest and highest wanted rank, so that a far outlier does not stretch the bins.
    Only the speed depends on it: values outside fall into the end bins, which stay exact."""
    n = values.size
    sample = np.sort(values[:: max(1, n // SAMPLE)])
    last = sample.size - 1
    low = max(0, int(ranks.min() * sample.size // n) - MARGIN)
    high = min(last, int(ranks.max() * sample.size // n) + 1 + MARGIN)
    return float(sample[low]), float(sample[high])


def distinct(values: np.ndarray, return_inverse: bool = False):
    """The distinct values of ``values`` (flattened), sorted (one NaN, last, for any NaNs), and with ``return_inverse``
    also the position of each value among them: ``np.unique``'s results, without its check for a masked
    array, which imports numpy.ma (0.03 s with bytecode caches, 0.2 s without) for the few values a
    summary's statistics ask it to sort."""
    values = np.asarray(values).ravel()
    order = np.argsort(values, kind="stable") if return_inverse else None
    ordered = values[order] if return_inverse else np.sort(values)
    first = np.empty(ordered.size, dtype=bool)
    first[:1] = True
    np.not_equal(ordered[1:], ordered[:-1], out=first[1:])
    if ordered.dtype.kind == "f" and ordered.size and ordered[-1] != ordered[-1]:  # NaNs, sorted last: one kept
        first[int(np.argmax(ordered != ordered)) + 1:] = False
    if not return_inverse:
        return ordered[first]
    inverse = np.empty(values.size, dtype=np.intp)
    inverse[order] = np.cumsum(first) - 1
    return ordered[first], inverse
