"""The measurements a calibration fits, as plain data in SI units, each checked when made (a
:class:`DataError` naming the fault otherwise):

* :class:`ReboundPairs`: approach and rebound speeds of separate impacts [m/s], with an optional
  standard deviation of each rebound speed [m/s];
* :class:`ImpactTimes`: the times of the successive impacts of one drop [s], any origin;
* :class:`Recording`: the sound of one drop (samples and rate) and the impact times found in it.

Readers (:mod:`restitution.fit.reading`, :mod:`restitution.fit.recording`) make them from files; the
estimators (:mod:`restitution.fit.estimate`) take them."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["DataError", "ReboundPairs", "ImpactTimes", "Recording", "MIN_POINTS"]

#: The fewest points a fit accepts (pairs, or impact times).
MIN_POINTS = 3


class DataError(ValueError):
    """Measurements that cannot be fitted: the message is one line naming the fault (and the file)."""


def _vector(name: str, values, where: str) -> np.ndarray:
    array = np.asarray(values, dtype=float)
    if array.ndim != 1:
        raise DataError(f"{where}{name}: expected one column of numbers, got shape {array.shape}")
    bad = np.flatnonzero(~np.isfinite(array))
    if bad.size:
        raise DataError(f"{where}{name}: row {bad[0] + 1} is not a finite number ({float(array[bad[0]])!r})")
    return array


@dataclass(frozen=True)
class ReboundPairs:
    """Approach speeds ``v_in`` and rebound speeds ``v_out`` [m/s] of separate impacts; ``sigma`` [m/s]: the
    standard deviation of each ``v_out`` where known (None: relative noise, estimated from the residuals).
    ``source``: where they came from, for messages."""

    v_in: np.ndarray
    v_out: np.ndarray
    sigma: np.ndarray | None = None
    source: str = ""

    def __post_init__(self):
        where = f"{self.source}: " if self.source else ""
        v_in, v_out = _vector("v_in", self.v_in, where), _vector("v_out", self.v_out, where)
        if v_in.size != v_out.size:
            raise DataError(f"{where}v_in and v_out have {v_in.size} and {v_out.size} values")
        if v_in.size < MIN_POINTS:
            raise DataError(f"{where}{v_in.size} pairs: a fit needs at least {MIN_POINTS}")
        for name, values in (("v_in", v_in), ("v_out", v_out)):
            bad = np.flatnonzero(values < 0.0) if name == "v_out" else np.flatnonzero(values <= 0.0)
            if bad.size:
                raise DataError(f"{where}{name} = {values[bad[0]]:g} m/s in row {bad[0] + 1}: speeds are magnitudes, "
                                f"{'>= 0' if name == 'v_out' else '> 0'}")
        faster = np.flatnonzero(v_out > v_in)
        if faster.size:
            i = faster[0]
            raise DataError(f"{where}row {i + 1}: v_out = {v_out[i]:g} m/s > v_in = {v_in[i]:g} m/s (a rebound is never "
                            "faster than the approach: are the columns swapped?)")
        sigma = None
        if self.sigma is not None:
            sigma = _vector("sigma", self.sigma, where)
            if sigma.size != v_in.size or np.any(sigma <= 0.0):
                raise DataError(f"{where}sigma: one positive value per pair is needed")
        object.__setattr__(self, "v_in", v_in)
        object.__setattr__(self, "v_out", v_out)
        object.__setattr__(self, "sigma", sigma)

    kind = "rebound_pairs"

    @property
    def n(self) -> int:
        return int(self.v_in.size)


@dataclass(frozen=True)
class ImpactTimes:
    """The times [s] of the successive impacts of one drop, increasing, any time origin."""

    t: np.ndarray
    source: str = ""

    def __post_init__(self):
        where = f"{self.source}: " if self.source else ""
        t = _vector("t_impact", self.t, where)
        if t.size < MIN_POINTS:
            raise DataError(f"{where}{t.size} impact times: a fit needs at least {MIN_POINTS}")
        steps = np.diff(t)
        bad = np.flatnonzero(steps <= 0.0)
        if bad.size:
            i = bad[0]
            raise DataError(f"{where}t_impact does not increase: row {i + 2} ({t[i + 1]:g} s) is not after row "
                            f"{i + 1} ({t[i]:g} s)")
        object.__setattr__(self, "t", t)

    kind = "impact_times"

    @property
    def n(self) -> int:
        return int(self.t.size)


@dataclass(frozen=True)
class Recording:
    """One drop's sound: ``samples`` (mono, floats in [-1, 1]) at ``rate`` [Hz], and the impact ``times`` [s]
    found in it (from the start of the recording)."""

    samples: np.ndarray
    rate: float
    times: ImpactTimes
    source: str = ""

    kind = "recording"

    @property
    def n(self) -> int:
        return self.times.n
