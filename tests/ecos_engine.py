"""The ``ecos`` command-line engine of the ecospy wheel, for the tests that run SSP files with it
(tests/hosts/test_native_hosts.py, tests/fmu/test_ssp.py): copied and made executable (the wheel installs
it without the x bit), with libtbb.so.12 from the system or from the ``tbb`` wheel (pip install tbb, whose
library lands in <venv>/lib), else the test skips naming what is missing."""
from __future__ import annotations

import importlib.util
import os
import shutil
import stat
import subprocess
import sys
from pathlib import Path
from typing import NamedTuple

import pytest


class Ecos(NamedTuple):
    exe: Path  #: the engine
    env: dict  #: the environment to run it in (LD_LIBRARY_PATH naming the tbb wheel's library where used)


def ecos_engine(folder: Path) -> Ecos:
    """ecos 0.7.2 copied into ``folder``; pytest.skip where ecospy, its binary or libtbb.so.12 is missing."""
    spec = importlib.util.find_spec("ecospy")  # not imported: that would load libecosc.so into pytest
    if spec is None or not spec.submodule_search_locations:
        pytest.skip("ecospy not installed (pip install ecospy==0.7.2; in the dev extra)")
    shipped = Path(next(iter(spec.submodule_search_locations))) / "binaries" / "ecos"
    if not shipped.is_file():
        pytest.skip(f"ecospy has no Linux ecos binary at {shipped}")
    exe = Path(folder) / "ecos"
    shutil.copy(shipped, exe)
    exe.chmod(exe.stat().st_mode | stat.S_IXUSR)
    env = dict(os.environ)
    wheel_lib = Path(sys.prefix) / "lib"
    if (wheel_lib / "libtbb.so.12").exists():
        env["LD_LIBRARY_PATH"] = os.pathsep.join(filter(None, [str(wheel_lib), env.get("LD_LIBRARY_PATH")]))
    probe = subprocess.run([str(exe), "--version"], capture_output=True, text=True, timeout=60, env=env)
    if probe.returncode != 0 and "libtbb" in probe.stderr:
        pytest.skip("ecos needs libtbb.so.12 (pip install tbb; or Debian: apt-get install libtbb12, "
                    "build_scripts/system_packages.sh)")
    assert probe.returncode == 0 and probe.stdout.strip() == "v0.7.2", probe.stdout + probe.stderr
    return Ecos(exe, env)
