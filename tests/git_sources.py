"""The package as an earlier commit had it, taken from git: what the tests that hold a change to "every value
as before, bit for bit" run beside the current sources (a child process imports it, or a build compiles
it)."""
from __future__ import annotations

import io
import shutil
import subprocess
import tarfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def package_at(commit: str, where: Path) -> Path:
    """``fmu_src`` of ``commit`` (its ``restitution`` package) extracted under ``where``; the test is skipped,
    saying why, where git or the commit is missing (a copy without the history)."""
    if shutil.which("git") is None:
        pytest.skip(f"git is needed to take the package of commit {commit}")
    done = subprocess.run(["git", "-C", str(ROOT), "archive", commit, "fmu_src/restitution"], capture_output=True)
    if done.returncode != 0:
        pytest.skip(f"commit {commit} is not in this checkout's history: {done.stderr.decode(errors='replace')[:200]}")
    with tarfile.open(fileobj=io.BytesIO(done.stdout)) as tar:
        tar.extractall(where)
    return where / "fmu_src"
