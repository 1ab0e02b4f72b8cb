"""The project's build backend (pyproject.toml: ``backend-path = ["build_scripts"]``): setuptools', except that
a wheel carries the FMUs built, so that ``pip install restitution`` gives every FMU without a compiler.

``build_wheel`` first builds every FMU (``python -m restitution.fmu build``, from the tree being built, with
zig from PyPI for every platform: ``RESTITUTION_COMPILER=zig``, no gcc or mingw-w64) into
``fmu_src/restitution/fmu/installed_fmus/`` (package data, never committed; removed again after the wheel is
written), the SSP files among them (the build writes them into its ``ssp/``). The wheel's
extra build requirements (zig, pythonfmu, fmpy and the package's dependencies) are asked for by
``get_requires_for_build_wheel`` alone: the sdist and the editable install (the Quickstart's) need only
setuptools. ``SOURCE_DATE_EPOCH`` passes through, so the FMUs of two wheels of a commit are identical.
"""
from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from setuptools import build_meta as _setuptools
from setuptools.build_meta import (build_editable, build_sdist, get_requires_for_build_editable,  # noqa: F401
                                   get_requires_for_build_sdist, prepare_metadata_for_build_editable,
                                   prepare_metadata_for_build_wheel)

#: What building the FMUs needs beside setuptools (the versions of pyproject.toml's fmu extra and
#: dependencies).
FMU_BUILD_REQUIRES = ["ziglang==0.17.1", "pythonfmu==0.7.0", "fmpy==0.3.32", "numpy>=2.4", "scipy>=1.17",
                      "pint>=0.25"]
PAYLOAD = Path("fmu_src") / "restitution" / "fmu" / "installed_fmus"


def get_requires_for_build_wheel(config_settings=None):
    return [*_setuptools.get_requires_for_build_wheel(config_settings), *FMU_BUILD_REQUIRES]


def build_fmus(payload: Path = PAYLOAD) -> Path:
    """Every FMU of the tree and its SSP files (``restitution fmu build`` writes both; a ``dist/ssp`` of
    an earlier build in the tree is not used) into ``payload``, built in a scratch folder first so that a
    failed build leaves nothing; returns ``payload``."""
    root = Path.cwd()
    env = dict(os.environ, RESTITUTION_COMPILER="zig",
               PYTHONPATH=os.pathsep.join(filter(None, [str(root / "fmu_src"), os.environ.get("PYTHONPATH")])))
    with tempfile.TemporaryDirectory(prefix="restitution-fmus-") as scratch:
        out = Path(scratch) / "fmus"
        subprocess.run([sys.executable, "-m", "restitution.fmu", "build", "--out", str(out)], check=True, env=env,
                       cwd=scratch, stdout=sys.stderr)  # the build's lines where a frontend shows them
        shutil.rmtree(payload, ignore_errors=True)
        shutil.move(str(out), str(payload))
    return payload


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    payload = build_fmus()
    try:
        return _setuptools.build_wheel(wheel_directory, config_settings, metadata_directory)
    finally:
        shutil.rmtree(payload, ignore_errors=True)
