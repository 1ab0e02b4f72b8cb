"""The native physics cross-compiled for Windows (mingw-w64, static runtime) computes the package's
model: the same stdin/stdout driver as the sanitizer test of tests/test_native_physics.py, built with
x86_64-w64-mingw32-gcc and run under Wine, its results compared with restitution.impact within the
per-case tolerances of restitution.agreement (Windows' C runtime maths differ from glibc's in the last
bits; the tolerances come from each output's conditioning, never bit identity).

Needs Debian's gcc-mingw-w64-x86-64 and wine64; skips saying which is missing. Marked slow: the
first Wine start creates a prefix (~10-30 s).
"""
from __future__ import annotations

import math
import os
import shutil
import subprocess

import numpy as np
import pytest

import restitution as r
from restitution.agreement import disagreements, tolerances
from restitution.fmu.native.compile import CFLAGS, prepare_sources

from test_native_physics import _DRIVER, NAMES, random_cases

MINGW = "x86_64-w64-mingw32-gcc"
WINE = shutil.which("wine64") or shutil.which("wine")
REALS = ("e", "v_rebound", "e_ep", "V_c", "V_star", "eps_y", "e_ze", "lam", "tau0", "T", "t_contact", "m_a",
         "m_eff", "v_plate")
FLAGS = ("plasticity_used", "plate_waves_used", "lambda_in_range", "vstar_in_range", "e_negative", "valid")

pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(shutil.which(MINGW) is None, reason=f"{MINGW} missing (Debian: gcc-mingw-w64-x86-64)"),
    pytest.mark.skipif(WINE is None, reason="wine64 missing (Debian: wine64)"),
]


def test_win64_physics_under_wine_equals_the_package(tmp_path):
    src = prepare_sources(tmp_path / "src")
    (src / "driver.c").write_text(_DRIVER)
    exe = tmp_path / "driver.exe"
    subprocess.run([MINGW, *CFLAGS, "-D__USE_MINGW_ANSI_STDIO=1", "-static", "-static-libgcc", "-o", str(exe),
                    str(src / "driver.c"), str(src / "rst_physics.c")], check=True, capture_output=True, text=True)
    rng = np.random.default_rng(64)
    v, params = random_cases(rng, 60)
    cases, lines = [], []
    for i in range(len(v)):
        m, z, p, w = 1 + i % 2, 1 + i % 3, i % 3, (i // 3) % 3
        case = [v[i]] + [params[n][i] for n in NAMES]
        cases.append((case, (m, z, p, w)))
        lines.append(" ".join(repr(float(x)) for x in case) + f" {m} {z} {p} {w} 1e-06 1e-10")
    env = dict(os.environ, WINEPREFIX=str(tmp_path / "wineprefix"), WINEDEBUG="-all")
    run = subprocess.run([WINE, str(exe)], input="\n".join(lines) + "\n", capture_output=True, text=True,
                         timeout=300, env=env)
    assert run.returncode == 0, run.stderr[-2000:]
    outputs = [line for line in run.stdout.splitlines() if line.strip()]
    assert len(outputs) == len(cases), run.stdout[-2000:]
    for (case, (m, z, p, w)), line in zip(cases, outputs):
        fields = line.split()
        assert int(fields[0]) == 0, line
        options = dict(restitution_model=r.RESTITUTION_MODELS[m - 1], zener_method=r.ZENER_METHODS[z - 1],
                       plasticity=r.EFFECT_MODES[p], plate_waves=r.EFFECT_MODES[w])
        got = {name: float.fromhex(x) if x not in ("inf", "nan") else float(x) for name, x in zip(REALS, fields[1:15])}
        got.update((name, bool(int(x))) for name, x in zip(FLAGS, fields[15:]))
        p_case = dict(zip(NAMES, case[1:]))
        tol, flips = tolerances(case[0], p_case, **options)
        problems = disagreements(type("R", (), got), r.impact(case[0], **p_case, **options), tol, flips)
        assert not problems, f"{options}: {problems}"
    assert math.isfinite(float.fromhex(outputs[0].split()[1]))
