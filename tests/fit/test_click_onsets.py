"""The click detector's onsets to the sample (restitution.fit.recording): a click that starts at a KNOWN
sample k must be reported at exactly k / rate, found in the samples (find_impacts) and in a 16-bit WAV file
(read_recording), at the usual rates.

The detector reports whole samples ("Sample i is at time i / rate"), and the onset is "the first sample of the
run of samples above the lower level max(LOW sigma, LOW_RISE before)" (its docstring). Its two stated errors
are excluded here by construction, so that the onset is k itself:

* late "by the time the click takes to reach the lower level": each click's first sample is a steep step, at
  least 0.5 x 0.05 of full scale, >= 8 times the lower level (below);
* early "when a noise sample just before it passes the lower level": the background is uniform noise in
  [-S, S], which never passes it. Its robust sigma is 1.4826 x median|x| = 1.4826 S / 2 = 0.74 S (more with
  the clicks in the median), so the lower level is at least LOW sigma >= 2.97 S > S.

So the tolerance is a hundredth of a sample (rounding of i / rate only): a detector one sample late or early
is off by 100 times that. The fit would absorb a constant shift in the drop's time origin; the impact times the
command writes would still be wrong, which is why they are checked here and not through a fit."""
from __future__ import annotations

import math
import wave

import numpy as np
import pytest

from restitution.fit.recording import find_impacts, read_recording

#: The uniform background's half-range [full scale]: ~33 steps of 16 bits.
S = 1e-3


def click_train(rate: int, rng, n_clicks: int = 12):
    """(samples, onset samples k): clicks at random whole samples 15-40 ms apart, each a decaying cosine of
    0.6-4 kHz (below 0.3 x rate), decay time 0.2-0.8 ms, amplitude 0.05-0.5, its phase within 1 rad of 0 or pi
    (first sample >= 0.54 x the amplitude, of either sign), over uniform noise in [-S, S]."""
    gaps = rng.integers(int(0.015 * rate), int(0.040 * rate), n_clicks)
    onsets = int(0.010 * rate) + np.concatenate([[0], np.cumsum(gaps[:-1])])
    x = rng.uniform(-S, S, onsets[-1] + int(0.030 * rate))
    for k in onsets:
        freq = rng.uniform(600.0, min(4000.0, 0.3 * rate))
        decay = rng.uniform(0.2e-3, 0.8e-3)
        phase = rng.uniform(-1.0, 1.0) + math.pi * rng.integers(0, 2)
        amplitude = rng.uniform(0.05, 0.5)
        j = np.arange(int(12 * decay * rate))  # the ring decays to e^-12 of its start before the next click
        x[k:k + j.size] += amplitude * np.exp(-j / (decay * rate)) * np.cos(2.0 * math.pi * freq * j / rate + phase)
    return x, onsets


def assert_at_the_samples(times, onsets, rate):
    assert times.size == onsets.size, (times * rate, onsets)
    # in samples: k exactly, to a hundredth of a sample (the rounding of k / rate)
    np.testing.assert_allclose(times * rate, onsets, rtol=0.0, atol=0.01)


@pytest.mark.parametrize("rate", [8000, 44100, 48000, 96000])
def test_onsets_are_the_known_first_samples(rate):
    rng = np.random.default_rng(rate)
    for _ in range(3):  # 36 clicks a rate, each at its own phase of the detector's windows
        x, onsets = click_train(rate, rng)
        assert_at_the_samples(find_impacts(x, rate), onsets, rate)


@pytest.mark.parametrize("rate", [8000, 44100])
def test_onsets_read_from_a_wav_file_are_the_known_first_samples(tmp_path, rate):
    """The same through a 16-bit PCM file and read_recording (quantising adds at most half a step, 1.5e-5, to
    the noise: still far under the lower level)."""
    x, onsets = click_train(rate, np.random.default_rng(rate + 1))
    path = tmp_path / "clicks.wav"
    with wave.open(str(path), "wb") as wav:
        wav.setnchannels(1)
        wav.setsampwidth(2)
        wav.setframerate(rate)
        wav.writeframes(np.round(x * 32767.0).astype("<i2").tobytes())
    recording = read_recording(path)
    assert recording.rate == rate
    assert_at_the_samples(np.asarray(recording.times.t), onsets, rate)
