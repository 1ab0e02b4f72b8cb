"""Where e < 0 is shown, it is said what it means, in one sentence with the flag's name (``e_negative``),
the same words everywhere (:data:`restitution.assumptions.E_NEGATIVE_MEANING`): ``restitution cor``, the fit
report, a sweep's statistics and a scene's summary; and ``restitution cor`` says what ``valid`` covers.

The e < 0 case: a chrome-steel ball (d = 6.35 mm) on a 2 mm Al 6061 sheet at 3 m/s: Eq. (20) gives
e = -0.068 with lambda = 1.08 (inside Zener's studied range, so valid is true beside e < 0: what a user met)."""
from __future__ import annotations

import dataclasses
import subprocess
import sys

import numpy as np

import restitution
from restitution.assumptions import E_NEGATIVE_MEANING, VALID_MEANING

NEGATIVE = ["--sphere", "chrome_steel", "--d", "6.35 mm", "--plate", "al_6061", "--t", "2 mm", "--v", "3 m/s"]
NORMAL = ["--sphere", "chrome_steel", "--d", "6.35 mm", "--plate", "al_6061", "--t", "3.18 mm", "--v", "2.3 m/s"]


def _cor(args):
    done = subprocess.run([sys.executable, "-m", "restitution", "cor", *args], capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 0, done.stderr
    return done.stdout


def _impact(sphere, d, plate, t, v):
    return restitution.impact(v, **restitution.MATERIALS[sphere].params("sphere"),
                              **restitution.MATERIALS[plate].params("plate"), sphere_d=d, plate_t=t)


def test_the_case_has_e_below_0_inside_the_validated_ranges():
    r = _impact("chrome_steel", 6.35e-3, "al_6061", 2e-3, 3.0)
    assert r.e < 0 and r.e_negative and r.valid and r.v_rebound < 0


def test_cor_says_what_e_below_0_means_where_it_is_shown():
    out = _cor(NEGATIVE)
    assert out.startswith("e = -0.0680 ")
    lines = out.splitlines()
    said = [line for line in lines if E_NEGATIVE_MEANING in line]
    assert len(said) == 1 and "e_negative" in said[0], out
    assert "v_rebound = -0.204" in out and "see e_negative" in out
    valid = next(k for k, line in enumerate(lines) if line.startswith("  valid = yes"))
    assert lines[valid + 1].strip() == f"valid: {VALID_MEANING}"  # beside it
    assert "lambda <= 1.5 and V* <= 1000" in VALID_MEANING and "does not cover e < 0" in VALID_MEANING


def test_cor_of_a_normal_case_does_not():
    out = _cor(NORMAL)
    assert out.startswith("e = 0.2353 ")
    assert E_NEGATIVE_MEANING not in out and "e_negative = yes" not in out and "see e_negative" not in out
    assert f"valid: {VALID_MEANING}" in out  # what valid means is said in every case


def test_the_fit_report_says_what_e_below_0_means_at_its_points():
    from restitution.fit.calibration import Calibration
    from restitution.fit.datasets import ReboundPairs
    from restitution.fit.estimate import base_of, fit_parameters
    from restitution.fit.report import table

    base = base_of(restitution.Sphere(restitution.MATERIALS["chrome_steel"], 6.35e-3),
                   restitution.Plate(restitution.MATERIALS["al_6061"], 6.35e-3))
    rng = np.random.default_rng(5)
    v_in = rng.uniform(0.5, 5.0, 12)
    data = ReboundPairs(v_in, restitution.impact(v_in, **base).e * v_in * (1 + 0.01 * rng.standard_normal(12)))
    result = fit_parameters(data, base, ["plate.Sy"])
    assert E_NEGATIVE_MEANING not in table(Calibration(data, base, result))  # none below 0: not said
    # the flags the fit counts, with three points below 0 (what a thin plate's fit gives)
    negative = np.zeros(12, bool)
    negative[[2, 5, 7]] = True
    flags = {**result.flags, "e_negative": negative, "any": result.flags["any"] | negative}
    marked = dataclasses.replace(result, flags=flags, out_of_range=int(flags["any"].sum()))
    words = table(Calibration(data, base, marked))
    line = next(line for line in words.splitlines() if E_NEGATIVE_MEANING in line)
    assert line.strip().startswith("e < 0 (e_negative) at 3 of 12 points: ")


def test_one_copy_of_the_words():
    """The sweep statistics and the scene summary take the same lines (restitution.assumptions.meaning_lines)
    and the same constant (no second copy of the text)."""
    from pathlib import Path

    from restitution import assumptions
    from restitution.scene import results
    from restitution.sweep import statistics

    assert statistics.E_NEGATIVE_MEANING is E_NEGATIVE_MEANING
    assert statistics.meaning_lines is assumptions.meaning_lines and results.meaning_lines is assumptions.meaning_lines
    source = Path(restitution.__file__).parent
    holders = [p.relative_to(source).as_posix() for p in source.rglob("*.py")
               if "keeps moving with the plate after the impact instead" in p.read_text(encoding="utf-8")]
    assert holders == ["assumptions.py"], holders
