"""benchmarks/bench_ball.py --quick without the Reference FMUs' source: it builds our native
BouncingBall (FMI 2.0 and FMI 3.0) and its timing host, runs, says in one line that the Reference ratios are
skipped, and prints our own figures and the FMI 3.0 / FMI 2.0 ratios beside their goals. Timing is not
asserted (machines are noisy and shared)."""
import os
import re
import shutil
import sys

import pytest
from bench_script import run_benchmark


pytestmark = [
    pytest.mark.skipif(not sys.platform.startswith("linux"), reason="Linux-only (linux64 binaries, C host)"),
    pytest.mark.skipif(shutil.which("gcc") is None, reason="gcc not available"),
]


def _quick(tmp_path, *args, reference=None):
    env = {k: v for k, v in os.environ.items() if k != "RESTITUTION_REFERENCE_FMUS"}
    if reference is not None:
        env["RESTITUTION_REFERENCE_FMUS"] = str(reference)
    return run_benchmark("bench_ball.py", "--quick", *args, cwd=tmp_path, timeout=600, env=env)


@pytest.mark.slow
def test_quick_run_without_the_reference_source(tmp_path):
    done = _quick(tmp_path)
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-4000:]
    lines = done.stdout.splitlines()
    assert lines[0].startswith("no Reference FMUs source") and "skipped" in lines[0], lines[:3]
    assert sum("skipped (no Reference source)" in line for line in lines) == 2, done.stdout
    assert not any(x.strip().startswith("Reference") for x in lines), done.stdout  # no Reference timings
    for operation in ("step", "rhs"):
        row = next(x for x in lines if re.match(rf"\s+{re.escape(operation)}\s+native FMI 3.0 / native FMI 2.0", x))
        ratio = float(re.search(r"(\d+\.\d+)x", row).group(1))
        assert 0.0 < ratio < float("inf") and "goal <= 1.1x" in row, row
    for label in ("native FMI 2.0", "native FMI 3.0"):
        assert sum(x.strip().startswith(label) and x.strip().endswith(" ns") for x in lines) == 3, done.stdout


@pytest.mark.slow
def test_a_folder_that_is_no_checkout_is_named_and_skipped(tmp_path):
    """RESTITUTION_REFERENCE_FMUS naming a folder without the Reference BouncingBall's sources: one line
    naming it, our own figures only."""
    empty = tmp_path / "not-reference-fmus"
    empty.mkdir()
    done = _quick(tmp_path, reference=empty)
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-4000:]
    first = done.stdout.splitlines()[0]
    assert str(empty) in first and "is not a Reference-FMUs checkout" in first, first

