"""Impact times from a sound recording (restitution.fit.recording): every impact of a synthetic drop
is found once, at its onset, and nothing else; a WAV file that cannot be used is a one-line DataError.

The truth comes from this file, not from the code under test: a ball dropped from H0 = 0.3 m
(g = 9.80665 m/s2) with a constant coefficient of restitution E = 0.8 hits at t_k, bouncing off at
v_{k+1} = E v_k and landing again 2 v_{k+1} / g later, until the interval falls under 3 ms (23
impacts, the last intervals 5.7, 4.6 and 3.7 ms). Each impact is a click of our own making: a damped
sine starting at t_k, 3-8 kHz, decay time 0.3-0.8 ms (ringing 1-3 ms above the noise), random phase,
amplitude proportional to the impact speed (0.8 of full scale for the first, 136 times weaker for the
last), over white Gaussian noise 20 times weaker than the weakest click, written as 16-bit PCM with
the standard library's ``wave`` at 44.1 and 48 kHz, mono and stereo (the second channel the same
clicks at 0.6 and its own noise)."""
import math
import struct
import wave

import numpy as np
import pytest

from restitution.fit.datasets import DataError, Recording
from restitution.fit.recording import find_impacts, read_recording, read_wav

G = 9.80665  # [m/s2]
H0 = 0.3  # [m]
E = 0.8  # [1]
#: The last interval of the synthetic drops [s]: the detector must resolve bounces a few ms apart.
SHORTEST = 3e-3
#: Each true onset found within this [s]. The issue asks for onsets "to well under a millisecond":
#: half a millisecond is the loosest bound that still means it (a fit of the intervals then sees an
#: error of a few per cent at the shortest, 3.7 ms, interval, and far less on the long ones);
#: the detector's own error on these recordings is a few hundredths of a millisecond.
TOLERANCE = 0.5e-3
#: ... and their median error within this [s]: a tenth of a millisecond, a fraction of a click's
#: first period, so that a systematic delay (a detector timing the click's peak, not its onset)
#: cannot hide under TOLERANCE.
MEDIAN_TOLERANCE = 0.1e-3


def drop(h0=H0, e=E, shortest=SHORTEST, t0=0.25):
    """The impact times [s] (the first at ``t0``) and speeds [m/s] of a ball dropped from ``h0`` [m]
    bouncing with the constant coefficient of restitution ``e``, until an interval is under
    ``shortest`` [s]."""
    v, t = math.sqrt(2.0 * G * h0), t0
    times, speeds = [], []
    while True:
        times.append(t)
        speeds.append(v)
        interval = 2.0 * e * v / G
        if interval < shortest:
            return np.array(times), np.array(speeds)
        v, t = e * v, t + interval


def clicks(rate, times, speeds, rng, loudest=0.8, snr=20.0, tail=0.3):
    """The samples [full scale] at ``rate`` [Hz] of the clicks of impacts at ``times`` [s] with
    ``speeds`` [m/s], over white noise ``snr`` times weaker (standard deviation) than the weakest
    click's amplitude; the clicks are also returned alone (for a second channel)."""
    n = int((times[-1] + tail) * rate)
    t = np.arange(n) / rate
    signal = np.zeros(n)
    for tk, vk in zip(times, speeds):
        amplitude = loudest * vk / speeds[0]
        freq, decay, phase = rng.uniform(3e3, 8e3), rng.uniform(0.3e-3, 0.8e-3), rng.uniform(0.0, 2.0 * math.pi)
        first = math.ceil(tk * rate)
        s = t[first:first + int(15 * decay * rate)] - tk
        signal[first:first + s.size] += amplitude * np.exp(-s / decay) * np.sin(2.0 * math.pi * freq * s + phase)
    sigma = loudest * speeds[-1] / speeds[0] / snr
    return signal + rng.normal(0.0, sigma, n), signal, sigma


def write_wav(path, channels, rate, width=2):
    """Write ``channels`` (a list of arrays in [-1, 1]) to the WAV file ``path`` at ``rate`` [Hz], as
    16-bit PCM (or 8-bit unsigned with ``width=1``)."""
    frames = np.stack(channels, axis=1)
    if width == 2:
        data = np.clip(np.round(frames * 32767.0), -32768, 32767).astype("<i2").tobytes()
    else:
        data = np.clip(np.round(frames * 127.0 + 128.0), 0, 255).astype(np.uint8).tobytes()
    with wave.open(str(path), "wb") as wav:
        wav.setnchannels(len(channels))
        wav.setsampwidth(width)
        wav.setframerate(rate)
        wav.writeframes(data)
    return path


def synthetic_drop(tmp_path, rate, stereo, seed):
    """A synthetic drop's WAV file and its true impact times [s]."""
    rng = np.random.default_rng(seed)
    times, speeds = drop()
    left, signal, sigma = clicks(rate, times, speeds, rng)
    channels = [left, 0.6 * signal + rng.normal(0.0, sigma, signal.size)] if stereo else [left]
    return write_wav(tmp_path / f"drop_{rate}_{len(channels)}_{seed}.wav", channels, rate), times


def onset_errors(found, truth):
    """The error [s] of each found onset against the true one it matches; asserts that every true
    onset is found exactly once and that nothing else is."""
    assert found.size == truth.size, f"{found.size} onsets found, {truth.size} impacts made"
    nearest = np.abs(found[:, None] - truth[None, :]).argmin(axis=1)
    assert np.array_equal(nearest, np.arange(truth.size)), "an impact found twice, another missed"
    return found - truth


def test_the_synthetic_drop_reaches_intervals_of_a_few_ms():
    times, speeds = drop()
    intervals = np.diff(times)
    assert times.size == 23 and 3e-3 < intervals[-1] < 4e-3
    assert speeds[0] / speeds[-1] == pytest.approx(E ** -22)


@pytest.mark.parametrize("stereo", [False, True], ids=["mono", "stereo"])
@pytest.mark.parametrize("rate", [44100, 48000])
@pytest.mark.parametrize("seed", [1, 2])
def test_every_onset_is_found_once_well_under_a_millisecond(tmp_path, rate, stereo, seed):
    path, truth = synthetic_drop(tmp_path, rate, stereo, seed)
    recording = read_recording(path)
    assert isinstance(recording, Recording) and recording.rate == rate and recording.source == str(path)
    errors = onset_errors(recording.times.t, truth)
    assert np.abs(errors).max() < TOLERANCE
    assert np.median(np.abs(errors)) < MEDIAN_TOLERANCE


def test_a_dc_offset_and_silence_without_noise_change_nothing():
    rate = 44100
    times, speeds = drop()
    _, signal, _ = clicks(rate, times, speeds, np.random.default_rng(3))
    quantized = np.round(signal * 32767.0) / 32768.0  # digital silence between the clicks
    for samples in (quantized, quantized + 0.05):
        errors = onset_errors(find_impacts(samples, rate), times)
        assert np.abs(errors).max() < TOLERANCE


@pytest.mark.parametrize("beat", [0.0, 150.0, 250.0], ids=["one mode", "beating 150 Hz", "beating 250 Hz"])
def test_ring_downs_are_not_impacts(beat):
    """Three loud clicks ringing long (3 ms decay: above the noise for ~20 ms) 100 ms apart: three
    onsets. With two modes ``beat`` [Hz] apart the ring's envelope falls to nothing and rises again
    every 1 / beat: still one impact each."""
    rate = 48000
    t = np.arange(int(0.4 * rate)) / rate
    rng = np.random.default_rng(4)
    samples = rng.normal(0.0, 1e-3, t.size)
    truth = np.array([0.05, 0.15, 0.25])
    for tk in truth:
        s = np.where(t >= tk, t - tk, 0.0)
        modes = np.sin(2.0 * math.pi * 4e3 * s) + (np.sin(2.0 * math.pi * (4e3 + beat) * s) if beat else 0.0)
        samples += np.where(t >= tk, (0.45 if beat else 0.9) * np.exp(-s / 3e-3) * modes, 0.0)
    errors = onset_errors(find_impacts(samples, rate), truth)
    assert np.abs(errors).max() < TOLERANCE


def test_read_wav_scales_and_averages_the_channels(tmp_path):
    left = np.array([0, 1, -1, 32767, -32768, 100], dtype="<i2")
    right = np.array([0, 3, -2, 32767, -32768, -100], dtype="<i2")
    for channels, expected in (([left], left / 32768.0), ([left, right], (left / 32768.0 + right / 32768.0) / 2.0)):
        path = tmp_path / f"{len(channels)}.wav"
        with wave.open(str(path), "wb") as wav:
            wav.setnchannels(len(channels))
            wav.setsampwidth(2)
            wav.setframerate(22050)
            wav.writeframes(np.stack(channels, axis=1).astype("<i2").tobytes())
        samples, rate = read_wav(path)
        assert rate == 22050.0 and np.array_equal(samples, expected)
        assert samples.min() >= -1.0 and samples.max() <= 1.0


def one_line_error(path, *words):
    """The DataError of read_recording(path): one line naming the file and each of ``words``."""
    with pytest.raises(DataError) as caught:
        read_recording(path)
    message = str(caught.value)
    assert "\n" not in message and str(path) in message
    for word in words:
        assert word in message, message
    return message


def test_noise_alone_has_no_detectable_impacts(tmp_path):
    rng = np.random.default_rng(5)
    path = write_wav(tmp_path / "noise.wav", [rng.normal(0.0, 0.01, 3 * 44100)], 44100)
    one_line_error(path, "no detectable impacts", "0 found")


def test_two_clicks_are_too_few(tmp_path):
    rate = 44100
    times, speeds = drop()
    _, signal, sigma = clicks(rate, times[:2], speeds[:2], np.random.default_rng(6), snr=200.0)
    rng = np.random.default_rng(7)
    path = write_wav(tmp_path / "two.wav", [signal + rng.normal(0.0, sigma, signal.size)], rate)
    one_line_error(path, "no detectable impacts", "2 found", "at least 3")


def test_files_that_are_not_16_bit_pcm_wav(tmp_path):
    rng = np.random.default_rng(8)
    noise = rng.normal(0.0, 0.1, 4410)
    one_line_error(write_wav(tmp_path / "eight.wav", [noise], 44100, width=1), "8-bit", "16-bit PCM")
    text = tmp_path / "text.wav"
    text.write_text("v_in,v_out\n1,0.5\n")
    one_line_error(text, "not a WAV file")
    good = write_wav(tmp_path / "good.wav", [noise], 44100).read_bytes()
    cut = tmp_path / "cut.wav"
    cut.write_bytes(good[:30])  # the header cut short
    one_line_error(cut, "not a WAV file")
    (tmp_path / "zero.wav").write_bytes(b"")
    one_line_error(tmp_path / "zero.wav", "not a WAV file")
    empty = write_wav(tmp_path / "empty.wav", [np.zeros(0)], 44100)
    one_line_error(empty, "no samples")
    floats = tmp_path / "float.wav"  # IEEE float samples (format 3), 32-bit
    data = np.asarray(noise, dtype="<f4").tobytes()
    floats.write_bytes(b"RIFF" + struct.pack("<I", 36 + len(data)) + b"WAVEfmt " +
                       struct.pack("<IHHIIHH", 16, 3, 1, 44100, 4 * 44100, 4, 32) +
                       b"data" + struct.pack("<I", len(data)) + data)
    one_line_error(floats, "float", "16-bit PCM")
    one_line_error(write_wav(tmp_path / "slow.wav", [noise], 4000), "4000 Hz")
    one_line_error(tmp_path / "missing.wav", "cannot read", "No such file")
    (tmp_path / "folder.wav").mkdir()
    one_line_error(tmp_path / "folder.wav", "cannot read", "directory")


def _claiming(path, rate, n=4410):
    """A mono 16-bit WAV file of ``n`` silent frames whose header claims the sample ``rate`` [Hz] (written
    here, field by field: RIFF's fmt and data chunks)."""
    data = bytes(2 * n)
    path.write_bytes(b"RIFF" + struct.pack("<I", 36 + len(data)) + b"WAVEfmt " +
                     struct.pack("<IHHIIHH", 16, 1, 1, rate, (2 * rate) % 2 ** 32, 2, 16) +
                     b"data" + struct.pack("<I", len(data)) + data)
    return path


@pytest.mark.parametrize("rate", [1_000_001, 2 ** 31, 4_000_000_000])
def test_a_sample_rate_beyond_a_megahertz_is_refused_at_once(tmp_path, rate):
    """Headers claiming a rate above 1 MHz (the stated maximum; the detector's windows grow with the rate,
    2^31 Hz took 46 s) are refused from the header, in well under the seconds the detector would take."""
    import time

    start = time.perf_counter()
    one_line_error(_claiming(tmp_path / "fast.wav", rate), f"sample rate {rate} Hz", "1000000 Hz")
    assert time.perf_counter() - start < 2.0


def test_a_wav_file_over_the_size_limit_is_refused_naming_the_limit(tmp_path):
    """64 MiB and one byte (a sparse file: no disk used) is refused before it is read; 64 MiB is stated
    in docs/calibration.md."""
    path = tmp_path / "long.wav"
    with open(path, "wb") as f:
        f.truncate(64 * 2 ** 20 + 1)
    one_line_error(path, "64 MiB", str(64 * 2 ** 20 + 1))
