"""The measurements a calibration fits, as plain data in SI units, each checked when made (a
:class:`DataError` naming the fault otherwise):

* :class:`ReboundPairs`: approach and rebound speeds of separate impacts [m/s], with an optional
  standard deviation of each rebound speed [m/s];
* :class:`ImpactTimes`: the times of the successive impacts of one drop [s], any origin;
* :class:`Recording`: the sound of one drop (samples and rate) and the impact times found in it.

Readers (:mod:`restitution.fit.reading`, :mod:`restitution.fit.recording`) make them from files; the
estimators (:mod:`restitution.fit.estimate`) take them.

Physically absurd values are refused as well, so that no sum or square of them overflows: a speed or
a sigma above :data:`MAX_SPEED`, a sigma below :data:`MIN_SIGMA` (the model's largest approach speed, :data:`restitution.domain.DOMAIN`),
an impact time beyond :data:`MAX_TIME` [s] from 0, and (:func:`check_drop_speeds`, once g is known)
an interval between impacts implying a rebound faster than MAX_SPEED."""
from __future__ import annotations

import os
import stat
from dataclasses import dataclass

import numpy as np

from restitution.domain import DOMAIN

__all__ = ["DataError", "ReboundPairs", "ImpactTimes", "Recording", "MIN_POINTS", "MAX_SPEED", "MIN_SIGMA", "MAX_TIME",
           "check_drop_speeds", "check_drop", "G_RANGE", "read_regular_file"]

#: The fewest points a fit accepts (pairs, or impact times).
MIN_POINTS = 3
#: The largest speed (v_in, v_out, sigma) a table may hold [m/s]: the model's domain of v_approach.
MAX_SPEED = DOMAIN["v"][1]
#: The smallest sigma a table may hold [m/s]: a nanometre per second, finer than any measurement of a
#: rebound speed (a residual over a smaller one squares beyond the floats).
MIN_SIGMA = 1e-9
#: The largest impact time, in magnitude, a table may hold [s] (about 32 million years: any clock's
#: origin, Unix time included, with room to spare; every difference of two such times is finite).
MAX_TIME = 1e15


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


def _mib(size: int) -> str:
    return f"{size / 2 ** 20:g} MiB"


def read_regular_file(path, limit: int, what: str = "file") -> bytes:
    """The bytes of the regular file ``path``, at most ``limit`` of them; DataError (one line naming the
    file) if it is missing or unreadable, is not a regular file (a directory, a device such as /dev/zero,
    a FIFO, a socket, or a symlink to one: checked before any byte is read, and a FIFO is opened without
    blocking), or holds more than ``limit`` bytes (the limit named: ``what`` says which)."""
    from restitution.output_files import file_kind, os_reason

    try:
        st = os.stat(path)
        if not stat.S_ISREG(st.st_mode):
            kind = file_kind(st.st_mode)
            link = f" (a symlink to {os.path.realpath(path)})" if os.path.islink(path) else ""
            raise DataError(f"{path}: cannot read: is {kind}{link}, not a regular file: give a file of measurements")
        if st.st_size > limit:
            raise DataError(f"{path}: {st.st_size} bytes: larger than the {_mib(limit)} a {what} may be")
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0))
        with open(fd, "rb", buffering=0) as stream:
            if not stat.S_ISREG(os.fstat(stream.fileno()).st_mode):  # replaced since the check
                raise DataError(f"{path}: is not a regular file: give a file of measurements")
            chunks, size = [], 0
            while size <= limit:
                chunk = stream.read(min(1 << 20, limit + 1 - size))
                if not chunk:
                    break
                chunks.append(chunk)
                size += len(chunk)
    except OSError as exc:
        raise DataError(f"{path}: cannot read: {os_reason(exc)}") from None
    if size > limit:  # it grew while read
        raise DataError(f"{path}: larger than the {_mib(limit)} a {what} may be")
    return b"".join(chunks)


def _at_most(where: str, name: str, values: np.ndarray, limit: float, unit: str, what: str, shown=None) -> None:
    """DataError naming the first row of ``values`` above ``limit`` (``shown``: the values to print)."""
    bad = np.flatnonzero(values > limit)
    if bad.size:
        value = float((values if shown is None else shown)[bad[0]])
        raise DataError(f"{where}{name} = {value:g} {unit} in row {bad[0] + 1}: beyond {limit:g} {unit} ({what}); "
                        "not a measurement")


def check_drop_speeds(times: "ImpactTimes", g: float) -> None:
    """DataError (one line) if an interval of ``times`` implies a rebound speed g (t_(k+1) - t_k) / 2
    [m/s] above :data:`MAX_SPEED` or not finite, for gravity ``g`` [m/s2]: a drop's rebounds are
    bounded by the model's domain as the pairs' speeds are."""
    with np.errstate(over="ignore", invalid="ignore"):
        speeds = 0.5 * float(g) * np.diff(np.asarray(times.t, dtype=float))
    bad = np.flatnonzero(~(np.isfinite(speeds) & (speeds <= MAX_SPEED)))
    if bad.size:
        i = bad[0]
        where = f"{times.source}: " if times.source else ""
        raise DataError(f"{where}t_impact rows {i + 1} and {i + 2} are {times.t[i + 1] - times.t[i]:g} s apart: a "
                        f"rebound at {speeds[i]:g} m/s with g = {float(g):g} m/s2, beyond the model's largest "
                        f"approach speed {MAX_SPEED:g} m/s; not one drop")


#: The gravity [m/s2] a drop may have: the range the BouncingBall FMU declares for its g.
G_RANGE = (1e-6, 1e6)


def check_drop(g: float, h0: float | None) -> None:
    """ValueError (one line) if the gravity ``g`` [m/s2] of a drop is outside :data:`G_RANGE`, or its height
    ``h0`` [m] (None: not given) is not positive or gives a first impact sqrt(2 g h0) beyond
    :data:`MAX_SPEED` (the speeds the fit then computes with would overflow)."""
    g = float(g)
    if not G_RANGE[0] <= g <= G_RANGE[1]:
        raise ValueError(f"g = {g:g} m/s2: outside the range a drop may have, [{G_RANGE[0]:g}, {G_RANGE[1]:g}] m/s2")
    if h0 is None:
        return
    h0 = float(h0)
    if not (h0 > 0.0 and np.isfinite(h0)):
        raise ValueError(f"h0 = {h0!r} m: a drop height is finite and > 0")
    if 2.0 * g * h0 > MAX_SPEED * MAX_SPEED:
        raise ValueError(f"h0 = {h0:g} m with g = {g:g} m/s2: a first impact at {np.sqrt(2.0 * g * h0):g} m/s, beyond "
                         f"the model's largest approach speed {MAX_SPEED:g} m/s")


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
        _at_most(where, "v_in", v_in, MAX_SPEED, "m/s", "the model's largest approach speed")
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
            _at_most(where, "sigma", sigma, MAX_SPEED, "m/s", "the model's largest approach speed")
            small = np.flatnonzero(sigma < MIN_SIGMA)
            if small.size:
                raise DataError(f"{where}sigma = {sigma[small[0]]:g} m/s in row {small[0] + 1}: below {MIN_SIGMA:g} m/s, "
                                "finer than any measurement of a speed")
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
        _at_most(where, "t_impact", np.abs(t), MAX_TIME, "s", "from the time origin", t)
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
