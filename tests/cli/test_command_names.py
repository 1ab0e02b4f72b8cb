"""One name for each command: `restitution sweep`, `restitution scene`, `restitution fmu` in every usage line and
error, however the command is started (the `restitution` command, `python -m restitution.X`, the old console
scripts), and no help or error text that names the older forms."""
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PYTHON = sys.executable
SCRIPTS = Path(PYTHON).parent
ENV = {**os.environ, "PYTHONPATH": str(ROOT / "fmu_src"), "COLUMNS": "100"}
#: The forms the commands were shown under before, which no help or error text may name.
OLD = ("python -m restitution.", "restitution-fmu", "restitution-sweep", "restitution-scene")

#: What each command's --help starts with, per subcommand path.
HELP = {("sweep",): "usage: restitution sweep ", ("scene",): "usage: restitution scene ",
        ("scene", "run"): "usage: restitution scene run ", ("scene", "report"): "usage: restitution scene report ",
        ("scene", "check"): "usage: restitution scene check ", ("fmu",): "usage: restitution fmu ",
        ("fmu", "build"): "usage: restitution fmu build ", ("export",): "usage: restitution export "}


def _run(args, cwd=None):
    return subprocess.run(args, capture_output=True, text=True, env=ENV, cwd=cwd, timeout=300)


def _starts(command):
    """The ways to start ``command`` (sweep, scene, fmu): the restitution command, python -m, the old script."""
    ways = [[PYTHON, "-m", "restitution", command], [PYTHON, "-m", f"restitution.{command}"]]
    script = SCRIPTS / f"restitution-{command}"
    if script.exists():
        ways.append([str(script)])
    return ways


def _no_old_name(text: str):
    for old in OLD:
        assert old not in text, (old, text)


@pytest.mark.parametrize("path", sorted(HELP))
def test_every_help_starts_with_the_one_name(path):
    for start in _starts(path[0]):
        proc = _run([*start, *path[1:], "--help"])
        assert proc.returncode == 0, proc.stderr
        first = proc.stdout.splitlines()[0]
        assert first.startswith(HELP[path]), (start, first)
        _no_old_name(proc.stdout + proc.stderr)


@pytest.mark.parametrize("args, where", [
    (["sweep", "--set", "plate.t=3GPa", "--scheduler", "serial", "--no-plot"],
     "restitution sweep: error: --set plate.t"),
    (["sweep", "--bogus"], "restitution sweep: error: unrecognized arguments: --bogus"),
    (["scene", "check", "missing.toml"], "restitution scene: error: "),
    (["scene", "frobnicate"], "restitution scene: error: argument command: invalid choice"),
    (["fmu"], "restitution fmu: error: the following arguments are required: command"),
    (["fmu", "build", "--bogus"], "restitution fmu: error: unrecognized arguments: --bogus"),
])
def test_every_error_names_the_one_name(tmp_path, args, where):
    for start in _starts(args[0]):
        proc = _run([*start, *args[1:]], cwd=tmp_path)
        assert proc.returncode == 2, (start, proc.stderr)
        assert "Traceback" not in proc.stderr
        assert where in proc.stderr.splitlines()[-1], (start, proc.stderr)
        _no_old_name(proc.stdout + proc.stderr)


def test_the_sweep_examples_in_its_help_use_the_one_name():
    proc = _run([PYTHON, "-m", "restitution", "sweep", "--help"])
    examples = [line.strip() for line in proc.stdout.splitlines() if "--pair" in line or "spec.toml" in line]
    commands = [line for line in examples if not line.startswith(("-", "#", "[", "material", "usage"))
                and "restitution" in line]
    assert commands and all(line.startswith("restitution sweep ") for line in commands), commands
