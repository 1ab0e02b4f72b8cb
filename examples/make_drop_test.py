"""Make the SYNTHETIC example drop test of docs/calibration.md: rebound pairs, impact times and a recording.

    python examples/make_drop_test.py [--out examples/data] [--seed 2026]

Nothing here was measured. The data are made from known parameters with the package's model
(:func:`restitution.impact` for the apparent COR e(v)) and numpy's random numbers, so that a
calibration has a known answer to find:

* the bodies: a chrome-steel ball (AISI 52100, d = 6.35 mm) on an Al 6061 plate (t = 6.35 mm),
  the presets ``chrome_steel`` and ``al_6061``, except that the plate's yield strength is
  **250 MPa** (the preset says 290 MPa): a fit that starts from the preset has to move to find it.
  The plate yields first (Eq. 2: C(0.33) 250 MPa = 413 MPa < C(0.30) 1380 MPa = 2.23 GPa for the ball), so
  ``plate.Sy`` is what these data determine;
* ``drop_pairs.csv``: 20 separate impacts, approach speeds v_in spread over 0.5-5 m/s, rebound
  speeds v_out = e(v_in) v_in with 1 % relative Gaussian noise;
* ``drop_times.csv``: one drop from rest at h0 = 0.3 m (first impact at sqrt(2 g h0) = 2.43 m/s):
  v_(k+1) = e(v_k) v_k and t_(k+1) - t_k = 2 v_(k+1) / g (free flight, no drag), the impacts kept
  while the interval between them is 5 ms or more (17 impacts), each time [s, from the release]
  with 30 microseconds of Gaussian jitter;
* ``drop.wav``: the same drop heard by a microphone: 16-bit mono PCM at 44.1 kHz, about 1 s
  (90 kB). Each impact is a click starting at its (exact) time, two decaying modes at 3.7 and
  6.1 kHz whose amplitude is proportional to the impact speed, over light white noise; the
  recording starts 0.15 s before the first impact (its times are the drop's less 0.0974 s).

Every CSV starts with a comment line saying it is synthetic; the WAV file says so in its INFO
comment (a LIST chunk after the samples, which WAV readers skip). The script then reads the
files back with :func:`restitution.fit.reading.read_data` and checks that they hold what was
written and that the times found in the recording are the true ones to within 0.5 ms
(``--no-check`` skips this). The same ``--seed`` gives the same files, byte for byte.
"""
from __future__ import annotations

import argparse
import math
import struct
import sys
from pathlib import Path

import numpy as np

import restitution as r

HERE = Path(__file__).resolve().parent
DATA = HERE / "data"

SPHERE_KEY, DIAMETER = "chrome_steel", 6.35e-3  #: the ball [m]
PLATE_KEY, THICKNESS = "al_6061", 6.35e-3  #: the plate [m]
TRUE_PLATE_SY = 250e6  #: [Pa] the plate's yield strength in the data (the al_6061 preset: 290 MPa)
G = 9.80665  #: [m/s^2] standard gravity

N_PAIRS, V_RANGE, REL_NOISE = 20, (0.5, 5.0), 0.01  #: pairs, approach speeds [m/s], relative noise on v_out
H0, JITTER, MIN_INTERVAL = 0.3, 30e-6, 5e-3  #: drop height [m], timing jitter [s], last interval kept [s]

RATE = 44100  #: [Hz] sample rate of the recording
LEAD, TAIL = 0.15, 0.2  #: [s] recording before the first impact and after the last
MODES = ((3700.0, 1.2e-3, 1.0), (6100.0, 0.7e-3, 0.6))  #: (frequency [Hz], decay time [s], weight) of a click
CLICK = 12e-3  #: [s] length of a click (10 decay times of its slower mode)
LOUDEST = 0.7  #: peak of the first (fastest) impact's click, as a fraction of full scale
NOISE = 2e-4  #: standard deviation of the background noise, as a fraction of full scale (~7 16-bit steps)

SYNTHETIC = ("SYNTHETIC example drop test made by examples/make_drop_test.py (not a measurement): "
             f"{SPHERE_KEY} ball d = {DIAMETER * 1e3:g} mm on {PLATE_KEY} plate t = {THICKNESS * 1e3:g} mm, "
             f"true plate.Sy = {TRUE_PLATE_SY / 1e6:g} MPa")


def true_parameters() -> dict:
    """The :func:`restitution.impact` keywords of the bodies in the data (the presets, plate.Sy = 250 MPa)."""
    sphere = r.Sphere(r.MATERIALS[SPHERE_KEY], DIAMETER)
    plate = r.Plate(r.MATERIALS[PLATE_KEY], THICKNESS)
    return {**sphere.params(), **plate.params(), "plate_Sy": TRUE_PLATE_SY}


def rebound_pairs(rng: np.random.Generator, params: dict) -> tuple[np.ndarray, np.ndarray]:
    """(v_in, v_out) [m/s]: N_PAIRS approach speeds drawn uniformly over V_RANGE (sorted, to 0.1 mm/s)
    and their rebound speeds e(v_in) v_in with REL_NOISE relative Gaussian noise."""
    v_in = np.round(np.sort(rng.uniform(*V_RANGE, N_PAIRS)), 4)
    v_out = r.impact(v_in, **params).e * v_in * (1.0 + REL_NOISE * rng.standard_normal(N_PAIRS))
    return v_in, v_out


def drop(params: dict) -> tuple[np.ndarray, np.ndarray]:
    """(impact times [s] from the release, approach speeds [m/s]) of one drop from rest at H0, without
    noise: the impacts while the interval between them stays >= MIN_INTERVAL."""
    v, t = math.sqrt(2.0 * G * H0), math.sqrt(2.0 * H0 / G)
    times, speeds = [t], [v]
    while True:
        v = float(r.impact(v, **params).e) * v
        flight = 2.0 * v / G
        if flight < MIN_INTERVAL:
            return np.array(times), np.array(speeds)
        t += flight
        times.append(t)
        speeds.append(v)


def recording(rng: np.random.Generator, times: np.ndarray, speeds: np.ndarray) -> tuple[np.ndarray, float]:
    """(16-bit samples, offset [s]) of the drop as heard: a click at each impact ``times`` [s] (from the
    release), amplitude proportional to ``speeds``, over white noise; sample 0 is at time ``offset``."""
    offset = times[0] - LEAD
    n = int(math.ceil((times[-1] + TAIL - offset) * RATE))
    x = NOISE * rng.standard_normal(n)
    peak = sum(w for _f, _tau, w in MODES)
    for t_k, v_k in zip(times - offset, speeds):
        first = int(math.ceil(t_k * RATE))  # the first sample at or after the impact
        idx = np.arange(first, min(n, first + int(CLICK * RATE)))
        age = idx / RATE - t_k  # [s] since the impact, >= 0
        click = sum(w * np.sin(2.0 * math.pi * f * age) * np.exp(-age / tau) for f, tau, w in MODES)
        x[idx] += (LOUDEST / peak) * (v_k / speeds[0]) * click
    return np.clip(np.round(x * 32768.0), -32768, 32767).astype("<i2"), offset


def wav_bytes(samples: np.ndarray, comment: str) -> bytes:
    """A mono 16-bit PCM WAV file at RATE holding ``samples``, with ``comment`` in a LIST/INFO ICMT chunk
    after the samples (readers that do not know it skip it)."""
    data = samples.astype("<i2").tobytes()
    fmt = struct.pack("<HHIIHH", 1, 1, RATE, 2 * RATE, 2, 16)
    text = comment.encode("ascii") + b"\0"
    text += b"\0" * (len(text) % 2)
    info = b"INFO" + b"ICMT" + struct.pack("<I", len(text)) + text
    chunks = (b"fmt " + struct.pack("<I", len(fmt)) + fmt + b"data" + struct.pack("<I", len(data)) + data
              + b"\0" * (len(data) % 2) + b"LIST" + struct.pack("<I", len(info)) + info)
    return b"RIFF" + struct.pack("<I", 4 + len(chunks)) + b"WAVE" + chunks


def run(out_dir=DATA, seed: int = 2026, check: bool = True, verbose: bool = True) -> dict:
    """Write drop_pairs.csv, drop_times.csv and drop.wav into ``out_dir`` (made if missing) from ``seed``;
    returns the paths, the truth and the check's figures."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    params = true_parameters()
    rng_pairs, rng_times, rng_wav = (np.random.default_rng(s) for s in np.random.SeedSequence(seed).spawn(3))
    comment = f"# {SYNTHETIC}; seed {seed}\n"

    v_in, v_out = rebound_pairs(rng_pairs, params)
    pairs = out_dir / "drop_pairs.csv"
    pairs.write_text(comment + f"# {N_PAIRS} separate impacts, v_out with {100 * REL_NOISE:g} % relative Gaussian "
                     "noise\nv_in [m/s],v_out [m/s]\n"
                     + "".join(f"{a:.4f},{b:.5f}\n" for a, b in zip(v_in, v_out)), encoding="utf-8")

    clean, speeds = drop(params)
    jittered = clean + JITTER * rng_times.standard_normal(clean.size)
    times = out_dir / "drop_times.csv"
    times.write_text(comment + f"# one drop from h0 = {H0:g} m, times from the release with {JITTER * 1e6:g} us "
                     "Gaussian jitter\nt_impact [s]\n" + "".join(f"{t:.6f}\n" for t in jittered), encoding="utf-8")

    samples, offset = recording(rng_wav, clean, speeds)
    wav = out_dir / "drop.wav"
    wav.write_bytes(wav_bytes(samples, f"{SYNTHETIC}; seed {seed}; the drop of drop_times.csv, impacts at the "
                                       f"times less {offset:.4f} s, without jitter"))
    out = {"paths": {"pairs": pairs, "times": times, "wav": wav}, "params": params, "seed": seed,
           "v_in": v_in, "v_out": v_out, "times": clean, "speeds": speeds, "jittered": jittered, "offset": offset,
           "samples": samples.size}
    if check:
        out["check"] = check_files(out)
    if verbose:
        print(f"{SYNTHETIC}, seed {seed}")
        print(f"  {pairs}: {N_PAIRS} rebound pairs, v_in {v_in.min():.2f}-{v_in.max():.2f} m/s")
        print(f"  {times}: {clean.size} impact times, {clean[0]:.4f}-{clean[-1]:.4f} s, last interval "
              f"{1e3 * (clean[-1] - clean[-2]):.2f} ms")
        print(f"  {wav}: {samples.size / RATE:.2f} s at {RATE} Hz, {wav.stat().st_size / 1e3:.0f} kB")
        if check:
            c = out["check"]
            print(f"  read back: {c['impacts_found']} impacts found in the recording, largest error "
                  f"{1e3 * c['wav_error_max']:.3f} ms (median {1e3 * c['wav_error_median']:.3f} ms)")
    return out


def check_files(made: dict, tolerance: float = 0.5e-3) -> dict:
    """Read the files of :func:`run` back (restitution.fit): the tables hold what was written (to the digits
    written), the recording's impacts are the drop's to within ``tolerance`` [s]; RuntimeError otherwise."""
    from restitution.fit.datasets import ImpactTimes, ReboundPairs, Recording
    from restitution.fit.reading import read_data

    paths = made["paths"]
    pairs, times, heard = (read_data(paths[k]) for k in ("pairs", "times", "wav"))
    if not (isinstance(pairs, ReboundPairs) and pairs.sigma is None and pairs.n == N_PAIRS
            and np.allclose(pairs.v_in, made["v_in"], rtol=0, atol=1e-9)
            and np.allclose(pairs.v_out, made["v_out"], rtol=0, atol=6e-6)):
        raise RuntimeError(f"{paths['pairs']} does not read back as the {N_PAIRS} pairs written")
    if not (isinstance(times, ImpactTimes) and np.allclose(times.t, made["jittered"], rtol=0, atol=6e-7)):
        raise RuntimeError(f"{paths['times']} does not read back as the impact times written")
    if not isinstance(heard, Recording) or heard.rate != RATE or heard.samples.size != made["samples"]:
        raise RuntimeError(f"{paths['wav']} does not read back as the recording written")
    found, true = heard.times.t, made["times"] - made["offset"]
    if found.size != true.size:
        raise RuntimeError(f"{paths['wav']}: {found.size} impacts found, {true.size} made")
    error = np.abs(found - true)
    if error.max() > tolerance:
        raise RuntimeError(f"{paths['wav']}: impact {int(np.argmax(error)) + 1} found {1e3 * error.max():.3f} ms "
                           f"from its time (more than {1e3 * tolerance:g} ms)")
    return {"impacts_found": int(found.size), "wav_error_max": float(error.max()),
            "wav_error_median": float(np.median(error))}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, default=DATA, metavar="DIR",
                        help=f"folder to write the three files into (default: {DATA})")
    parser.add_argument("--seed", type=int, default=2026, help="seed of the noise (default 2026)")
    parser.add_argument("--no-check", action="store_true", help="do not read the files back")
    args = parser.parse_args(argv)
    try:
        run(args.out, seed=args.seed, check=not args.no_check)
    except (OSError, RuntimeError) as exc:
        print(f"make_drop_test.py: error: {exc}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
