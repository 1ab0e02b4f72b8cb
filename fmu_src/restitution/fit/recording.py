"""The impact times of one drop, from a sound recording: a WAV file (16-bit PCM, mono or stereo, any
sample rate) in which each impact of the bouncing ball is a short click above the background noise.

* :func:`read_wav`: the samples (floats in [-1, 1], the channels averaged) and the rate [Hz];
* :func:`find_impacts`: the onset time [s] of each click, from the first sample (time 0);
* :func:`read_recording`: both, as a :class:`~restitution.fit.datasets.Recording`.

The detector (:func:`find_impacts`)
-----------------------------------
Let ``a = |x|``, ``x`` the samples less their median (the DC offset), and ``sigma`` the noise's
standard deviation estimated robustly, ``1.4826 * median(|x - median(x)|)`` (a click train fills a
few per cent of a drop's recording: the median does not see it), at least one 16-bit step. At each
sample ``n`` two levels are compared:

* ``ahead[n]``, the largest ``a`` over the next :data:`AHEAD` = 0.25 ms (from ``n`` on): long enough
  to hold the first peak of a click ringing at 1 kHz or more, whatever its phase at the onset;
* ``before[n]``, the largest ``a`` over the previous :data:`BEFORE` = 1 ms: the background, or the
  ring-down of the previous click.

A click starts where ``ahead >= RISE * before`` (a new rise, :data:`RISE` = 2.5 times what came just
before) and ``ahead >= GATE * sigma`` (well out of the noise, :data:`GATE` = 7: a Gaussian noise
sample exceeds 7 sigma once in 4e11). Over noise alone ``before`` is about 2.6 sigma, so a click is
found when its first peak reaches 7-8 sigma (measured: clicks of amplitude 10 sigma are now and then
missed, 20 sigma never). Comparing with the last millisecond rather than with a fixed threshold is
what keeps a ring-down from counting as impacts: a decaying ring never rises 2.5-fold over its own
previous millisecond (nor does a ring of two modes 100-400 Hz apart, beating), while the next click
does, even before the previous one has died out. The dead time after a detected click is therefore
short, :data:`DEAD_TIME` = 1 ms (during it the rise of the click itself, over its first cycles, could
meet the test again): the bounce intervals of a drop shrink geometrically to a few ms, and an interval is
resolved when it is longer than the dead time and the previous ring has fallen to ``e / RISE`` of its
peak one :data:`BEFORE` before the next impact (``e`` the coefficient of restitution, click amplitudes
taken proportional to the impact speed): an interval of at least ``1 ms + tau * ln(RISE / e)``, 1 ms +
1.1 ``tau`` for a ring decaying as ``exp(-t / tau)`` and e = 0.8.

The onset is then refined backwards from the first sample at the detection level (within ``AHEAD``
of the detecting sample): it is the first sample of the run of samples above the lower level ``max(LOW
* sigma, LOW_RISE * before)`` (:data:`LOW` = 4, :data:`LOW_RISE` = 1.5; never above the detection
level) that leads to it with no gap longer than :data:`AHEAD` (the zero crossings of the first
cycles): the first sample where the click stands out of what was there before. Sample ``i`` is at time
``i / rate``; the onset is late by the time the click takes to reach the lower level, a fraction of
its first quarter period (hundredths of a millisecond at 3-8 kHz), or early when a noise sample just
before it passes the lower level: well under a millisecond either way.

Limits: a ring below about 1 kHz (a period longer than :data:`BEFORE`) may count its own cycles as
impacts; impacts closer than the interval above merge; a hum or a rumble raises ``sigma`` and with it
the weakest click found; noise that is not stationary (handling, voices, impulsive crackle) can be
taken for clicks. Every step is an elementwise comparison, a maximum or a median of the samples: the
times do not depend on the machine."""
from __future__ import annotations

import io
import wave
from pathlib import Path

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

from restitution.fit.datasets import MIN_POINTS, DataError, ImpactTimes, Recording, read_regular_file

__all__ = ["read_wav", "find_impacts", "read_recording", "noise_sigma", "AHEAD", "BEFORE", "DEAD_TIME", "RISE",
           "GATE", "LOW", "LOW_RISE", "MIN_RATE", "MAX_RATE", "MAX_WAV_BYTES"]

#: Length [s] of the window ahead of each sample whose largest magnitude is tested.
AHEAD = 0.25e-3
#: Length [s] of the window before each sample: the level a click must rise over.
BEFORE = 1.0e-3
#: Dead time [s] after a detected onset, during which no other onset is taken.
DEAD_TIME = 1.0e-3
#: A click is a rise of at least this factor over the largest magnitude of the previous BEFORE [1].
RISE = 2.5
#: ... and of at least this many noise standard deviations [1].
GATE = 7.0
#: The onset is the first sample above LOW noise standard deviations [1] ...
LOW = 4.0
#: ... and above LOW_RISE times the level before the click [1].
LOW_RISE = 1.5
#: The lowest sample rate [Hz] accepted: 8 kHz times an onset to 0.125 ms (one sample).
MIN_RATE = 8000
#: The highest sample rate [Hz] accepted: 1 MHz, over five times the fastest audio recorders (192 kHz);
#: the detector's windows grow with the rate, and a header claiming gigahertz is not a recording.
MAX_RATE = 1_000_000
#: The largest WAV file read [bytes]: 64 MiB, some 12 minutes of mono 16-bit sound at 44.1 kHz (a drop
#: lasts seconds); read whole into memory, so a header claiming more frames than the file holds costs
#: nothing.
MAX_WAV_BYTES = 64 * 2 ** 20

#: One step of a 16-bit sample, as a fraction of full scale [1].
_LSB = 1.0 / 32768.0
#: What the WAV format codes the wave module refuses are, for the message.
_FORMATS = {3: "32-bit float samples", 6: "A-law samples", 7: "mu-law samples", 2: "ADPCM samples",
            0xFFFE: "a WAVE_FORMAT_EXTENSIBLE header"}


def _format_name(message: str) -> str:
    """What ``wave.Error('unknown format: N')`` means, in words."""
    code = message.rsplit(":", 1)[-1].strip()
    try:
        return _FORMATS.get(int(code), f"format code {int(code)}")
    except ValueError:
        return message


def read_wav(path) -> tuple[np.ndarray, float]:
    """The samples of the WAV file ``path`` as floats in [-1, 1] (sample / 32768; a stereo file's two
    channels averaged) and its sample rate [Hz]. DataError (one line naming the file) if it cannot be
    read, is not a regular file, is larger than :data:`MAX_WAV_BYTES`, is not a WAV file, is not 16-bit
    PCM, has a rate outside :data:`MIN_RATE` .. :data:`MAX_RATE`, or holds no sample. The frames are
    those the file holds, whatever number its header claims."""
    path = Path(path)
    raw = read_regular_file(path, MAX_WAV_BYTES, "WAV file")
    try:
        with wave.open(io.BytesIO(raw), "rb") as wav:
            channels, width, rate = wav.getnchannels(), wav.getsampwidth(), wav.getframerate()
            if width != 2:
                raise DataError(f"{path}: {8 * width}-bit samples: a 16-bit PCM WAV file is needed")
            if channels not in (1, 2):
                raise DataError(f"{path}: {channels} channels: a mono or stereo WAV file is needed")
            if rate < MIN_RATE:
                raise DataError(f"{path}: sample rate {rate} Hz: at least {MIN_RATE} Hz is needed to "
                                "time impacts to well under a millisecond")
            if rate > MAX_RATE:
                raise DataError(f"{path}: sample rate {rate} Hz: above the {MAX_RATE} Hz (1 MHz) accepted; "
                                "is the header damaged?")
            data = wav.readframes(min(wav.getnframes(), len(raw) // (width * channels)))
    except wave.Error as exc:
        text = str(exc)
        if text.startswith("unknown format"):
            raise DataError(f"{path}: {_format_name(text)}: a 16-bit PCM WAV file is needed") from None
        raise DataError(f"{path}: not a WAV file ({text})") from None
    except EOFError:
        raise DataError(f"{path}: not a WAV file (its header is cut short)") from None
    whole = len(data) // (2 * channels)  # a file cut short mid-frame: its whole frames
    if whole == 0:
        raise DataError(f"{path}: no samples: the WAV file is empty")
    ints = np.frombuffer(data, dtype="<i2", count=whole * channels).reshape(whole, channels)
    samples = ints[:, 0] * _LSB if channels == 1 else (ints[:, 0].astype(float) + ints[:, 1]) * (0.5 * _LSB)
    return np.asarray(samples, dtype=float), float(rate)


def _samples(seconds: float, rate: float) -> int:
    """A duration [s] as a number of samples at ``rate`` [Hz], at least 1."""
    return max(1, int(round(seconds * rate)))


def _window_max(a: np.ndarray, start: int, width: int) -> np.ndarray:
    """``out[n] = max(a[n + start : n + start + width])`` for every ``n``, the samples outside ``a``
    taken as 0 (``a >= 0``)."""
    padded = np.concatenate([np.zeros(max(0, -start)), a, np.zeros(max(0, start + width))])
    offset = max(0, -start) + start
    return sliding_window_view(padded, width)[offset:offset + a.size].max(axis=1)


def noise_sigma(samples) -> float:
    """The standard deviation of the background noise of ``samples`` [same unit], estimated from the
    median absolute deviation (unbiased for Gaussian noise, blind to clicks filling less than half of
    the recording), at least one 16-bit step."""
    x = np.asarray(samples, dtype=float)
    centred = x - np.median(x)
    return max(1.4826 * float(np.median(np.abs(centred - np.median(centred)))), _LSB)


def find_impacts(samples, rate) -> np.ndarray:
    """The onset times [s] of the clicks in ``samples`` (mono, floats in [-1, 1]) sampled at ``rate``
    [Hz], increasing, time 0 at the first sample: the rise-over-background detector of the module's
    docstring. An empty array if there is none."""
    x = np.asarray(samples, dtype=float)
    rate = float(rate)
    if x.ndim != 1 or not np.isfinite(rate) or rate <= 0.0 or not np.all(np.isfinite(x)):
        raise ValueError(f"find_impacts: one channel of finite samples and a positive rate are needed, got "
                         f"shape {x.shape} and {rate!r} Hz")
    if x.size == 0:
        return np.zeros(0)
    a = np.abs(x - np.median(x))
    sigma = noise_sigma(x)
    ahead_n, before_n, dead_n = _samples(AHEAD, rate), _samples(BEFORE, rate), _samples(DEAD_TIME, rate)
    ahead = _window_max(a, 0, ahead_n)
    before = _window_max(a, -before_n, before_n)
    rises = (ahead >= RISE * before) & (ahead >= GATE * sigma)
    rises[:before_n] = False  # a full millisecond of background first: not a ring the recording starts in
    candidates = np.flatnonzero(rises & ~np.concatenate([[False], rises[:-1]]))
    onsets, free_from = [], 0
    for n in candidates:
        if n < free_from:
            continue
        level = max(GATE * sigma, RISE * before[n])
        window = a[n:n + ahead_n]
        peak = n + int(np.argmax(window >= level))
        low = min(max(LOW * sigma, LOW_RISE * before[n]), level)
        above = n + np.flatnonzero(a[n:peak + 1] >= low)  # ends with peak
        start = above.size - 1
        while start > 0 and above[start] - above[start - 1] <= ahead_n:
            start -= 1
        onset = int(above[start])
        onsets.append(onset)
        free_from = onset + dead_n
    return np.asarray(onsets, dtype=float) / rate


def read_recording(path) -> Recording:
    """The recording of one drop in the WAV file ``path`` and the impact times [s] found in it
    (:func:`find_impacts`); DataError if the file cannot be read (:func:`read_wav`) or fewer than
    :data:`~restitution.fit.datasets.MIN_POINTS` impacts stand out of its noise."""
    samples, rate = read_wav(path)
    times = find_impacts(samples, rate)
    if times.size < MIN_POINTS:
        raise DataError(f"{path}: no detectable impacts: {times.size} found, a fit needs at least {MIN_POINTS} "
                        "(clicks standing out of the background noise)")
    return Recording(samples=samples, rate=rate, times=ImpactTimes(times, source=str(path)), source=str(path))
