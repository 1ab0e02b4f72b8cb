"""benchmarks/bench_pythonfmu.py --quick, in a child process (it loads a plain pythonfmu FMU, whose
binary can crash a process at exit): it builds the product FMU and its plain twin, times them and prints
the ratio beside its goal. Timing is not asserted (machines are noisy and shared): the printed ratio is
what the benchmark reports."""
import math
import re
import shutil
import sys

import pytest
from bench_script import run_benchmark


pytestmark = [
    pytest.mark.skipif(not sys.platform.startswith("linux"), reason="Linux-only (the guard is the linux64 binary)"),
    pytest.mark.skipif(shutil.which("gcc") is None, reason="gcc not available (the guard is compiled)"),
]


@pytest.mark.slow
def test_quick_run_prints_every_row_with_measured_values(tmp_path):
    done = run_benchmark("bench_pythonfmu.py", "--quick", "--work", str(tmp_path / "work"), cwd=tmp_path,
                         timeout=900)
    assert done.returncode == 0, done.stdout + done.stderr
    out = done.stdout
    for text in ("quick run", "product (guard + pythonfmu + slave + physics)", "plain pythonfmu twin",
                 "product with the physics replaced", "set, step, get e only"):
        assert text in out, (text, out)
    ratio = re.search(r"product / twin = ([0-9.]+)x \(goal <= 1\.5x: (met|NOT met)", out)
    assert ratio is not None, out
    value = float(ratio.group(1))
    assert math.isfinite(value) and value > 0.0
    assert (ratio.group(2) == "met") == (value <= 1.5)  # the verdict is the printed ratio's
    for call in ("set", "step", "get_real", "get_boolean"):
        assert re.search(rf"^  {call} +product +[0-9.-]+ us +twin +[0-9.-]+ us", out, re.M), (call, out)
    # both FMUs were built where asked, the product behind the guard, the twin without it
    work = tmp_path / "work"
    assert (work / "product" / "resources" / "python_env.txt").is_file()
    assert not (work / "twin" / "resources" / "python_env.txt").exists()
