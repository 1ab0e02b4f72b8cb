"""build_scripts/repeat_under_load.py: a pytest node run N times in one pytest process beside K busy
loops, each run's outcome reported with the stderr lines a child wrote after its "interrupted" line."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
SCRIPT = ROOT / "build_scripts" / "repeat_under_load.py"

TOY = '''
import subprocess, sys
from pathlib import Path

def test_toy(tmp_path):
    runs = Path(__file__).with_suffix(".runs")
    n = len(runs.read_text()) if runs.exists() else 0
    runs.write_text("x" * (n + 1))
    child = "import sys; sys.stderr.write('work\\\\ninterrupted: 3 of 9 missing\\\\nafter the mark %d\\\\n')" % n
    done = subprocess.run([sys.executable, "-c", child], capture_output=True, text=True)
    assert "interrupted" in done.stderr
    assert n != 1, "the second run fails"
'''


def test_after_mark_keeps_only_the_lines_after_the_interrupted_line():
    sys.path.insert(0, str(SCRIPT.parent))
    from repeat_under_load import after_mark

    assert after_mark(["a\nb\n", "x\n\ninterrupted: 1 of 2\nlog line\n\ntraceback\n"]) == ["log line", "traceback"]


def test_runs_a_node_n_times_and_reports_each(tmp_path):
    toy = tmp_path / "test_toy.py"
    toy.write_text(TOY, encoding="utf-8")
    done = subprocess.run([sys.executable, str(SCRIPT), "-n", "3", "-k", "1", f"{toy}::test_toy"],
                          capture_output=True, text=True, timeout=300, cwd=tmp_path)
    out = done.stdout
    assert done.returncode == 1, out + done.stderr  # one run of three failed
    assert "run   1: passed" in out and "run   2: failed" in out and "run   3: passed" in out, out
    assert "the second run fails" in out
    for k in range(3):
        assert f"stderr after 'interrupted': after the mark {k}" in out, out
    assert "stderr after 'interrupted': work" not in out and "interrupted': interrupted" not in out
    assert "2 of 3 runs passed (2 passed, 1 failed)" in out
    assert (tmp_path / "test_toy.runs").read_text() == "xxx"
