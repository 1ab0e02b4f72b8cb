"""Every `restitution` command with its standard output on a full disk: one line on stderr naming the
command and ENOSPC, exit 74; never a traceback, an "Exception ignored" at the interpreter's exit, or an
exit 0 with the output lost (argparse swallows the error of a help text longer than the output buffer)."""
import subprocess
import sys

import pytest

COMMANDS = [[], ["--version"], ["materials"], ["materials", "--help"], ["sweep", "--help"], ["scene", "--help"],
            ["scene", "run", "--help"], ["fmu", "--help"], ["fmu", "build", "--help"], ["cor", "--help"],
            ["fit", "--help"], ["export", "--help"],
            ["export", "table", "--sphere", "chrome_steel", "--d", "6 mm", "--plate", "al_6061", "--t", "3 mm",
             "--v-range", "1", "2"],
            ["sweep", "--grid", "v=1,2", "--scheduler", "serial", "--no-plot", "--no-progress"]]


@pytest.mark.parametrize("args", COMMANDS, ids=lambda a: " ".join(a) or "(none)")
def test_standard_output_on_a_full_disk_is_one_line_and_exit_74(args, tmp_path):
    if args[:1] == ["sweep"] and "--help" not in args:
        args = [*args, "--out", str(tmp_path / "s.csv")]
    with open("/dev/full", "w") as full:
        done = subprocess.run([sys.executable, "-m", "restitution", *(args or ["--help"])], stdout=full,
                              stderr=subprocess.PIPE, text=True, timeout=300, cwd=tmp_path)
    lines = done.stderr.strip().splitlines()
    assert done.returncode == 74, (done.returncode, done.stderr)
    assert len(lines) == 1 and "ENOSPC" in lines[0] and lines[0].startswith("restitution"), done.stderr
