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
"""
from __future__ import annotations

import numpy as np

__all__ = ["order_statistics", "Scratch"]

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


def order_statistics(values: np.ndarray, ranks, scratch: Scratch | None = None) -> np.ndarray:
    """The values of 0-based ``ranks`` (each in 0 .. n - 1) among ``values`` (finite floats, 1-d,
    left unchanged) as if sorted ascending: exactly ``np.partition(values, ranks)[ranks]``.

    ``scratch``: work arrays to reuse between calls (:class:`Scratch`); None makes its own."""
    values = np.asarray(values, dtype=float)
    ranks = np.asarray(ranks, dtype=np.int64)
    if ranks.size and (ranks.min() < 0 or ranks.max() >= values.size):
        raise IndexError(f"ranks {ranks.tolist()} are not all within 0 .. {values.size - 1}")
    return _select(values, ranks, scratch or Scratch())


def _select(values: np.ndarray, ranks: np.ndarray, scratch: Scratch) -> np.ndarray:
    n = values.size
    if n <= DIRECT or ranks.size == 0:
        return np.partition(values, ranks)[ranks] if ranks.size else np.empty(0)
    lo, hi = _span(values, ranks)
    if not lo < hi:  # the sample sees one value there: all values equal, or discrete or clustered ones
        low = values.min()
        return np.full(ranks.size, low) if low == values.max() else np.partition(values, ranks)[ranks]
    work, bins = scratch.arrays(n)
    with np.errstate(over="ignore"):  # a far value's distance may overflow to inf: clipped below
        np.subtract(values, lo, out=work)
        np.multiply(work, BINS / (hi - lo), out=work)
    np.clip(work, 0, BINS - 1, out=work)  # values beyond the span join the first or last bin
    np.copyto(bins, work, casting="unsafe")  # truncation: the floor of a number in [0, BINS - 1]
    ends = np.cumsum(np.bincount(bins, minlength=BINS))
    which = np.searchsorted(ends, ranks, side="right")  # the bin holding each rank
    picked = np.unique(which)
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
