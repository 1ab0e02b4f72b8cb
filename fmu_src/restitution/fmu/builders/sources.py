"""What each FMU is built from: which files of the package an FMU bundles, and the hash of its sources
recorded inside it (``resources/build_info.json``), which decides whether a built FMU is stale.

Read by the builders (:mod:`.python_fmu`, :mod:`.native`, :mod:`.guard`); imports nothing of them.
"""
from __future__ import annotations

import hashlib
import json
import shutil
import zipfile
from pathlib import Path

from ..models import FOLDERS, HERE as MODELS, SLAVE_SUPPORT, native_sources, slave_script

FMU_DIR = Path(__file__).resolve().parent.parent
BUILD_DIR = Path(__file__).resolve().parent
DESCRIBE_DIR = FMU_DIR / "describe"
PACKAGE = FMU_DIR.parent  # the restitution package the FMUs bundle
FRONT = FMU_DIR / "cfront"
GUARD = FMU_DIR / "pythonfmu_guard"
PHYSICS_C = FMU_DIR / "physics_c"

#: The front's version layers (one per FMI version; a binary is built with one of them and the core,
#: every other file of cfront/).
FRONT_LAYERS = {"2.0": "rst_fmi2.c", "3.0": "rst_fmi3.c"}
#: FMU model identifier -> pythonfmu slave script (shipped with the package, in the model's folder).
FMUS = {model: slave_script(model) for model in FOLDERS}
#: The binaries/ folders pythonfmu's own binaries fill (its wheel's; the guard replaces the Linux one).
PYTHONFMU_FOLDERS = ("linux64", "win64")
#: The models with a native backend (every one).
BACKENDS = tuple(FOLDERS)
#: Where the FMUs of each FMI version go, below the build's output directory.
VERSION_DIRS = {"2.0": "fmi2", "3.0": "fmi3"}

#: Where the build records what it was built from, inside the FMU.
BUILD_INFO = "resources/build_info.json"

#: Subfolders of the package the FMUs bundle; the others (cosim/, scene/, sweep/, ...) are host-side
#: helpers whose imports (fmpy, dask, matplotlib, ...) the slaves never need. Bundling them made the
#: guard's loader require those packages at start-up in a plain C host (python_env.txt require=).
BUNDLED_SUBDIRS = {"data"}
#: Modules at the package's top that read a user's text (a value with its unit, an option, a material by
#: name) and the command that uses them: host side only, the FMUs never pass text. Not bundled: units.py
#: would make the guard's loader require pint (its lazy import counts), which a plain C host need not
#: have; and a copy loaded from resources/ is imported whole, so nothing bundled may import these at its
#: top (tests/fmu/test_package.py checks both).
HOST_ONLY_MODULES = {"units.py", "inputs.py", "options.py", "cor.py"}
#: Of fmu/, the slaves need only the interface tables (pure data): these files, and models/*/variables.py.
BUNDLED_FMU_FILES = {"__init__.py", "table.py"}


def front_files(fmi_version: str = "2.0") -> list[Path]:
    """The C files of the front for one FMI version: the core and that version's layer."""
    others = {name for version, name in FRONT_LAYERS.items() if version != fmi_version}
    return sorted(p for p in FRONT.glob("*.[ch]") if p.name not in others)


def bundle_filter(directory, names):
    """copytree filter: no caches; below the package root only BUNDLED_SUBDIRS and, of fmu/, the
    interface tables; at the root, not the HOST_ONLY_MODULES."""
    ignored = set(shutil.ignore_patterns("__pycache__", "*.pyc", "*.egg-info")(directory, names))
    here = Path(directory).resolve()
    if here == PACKAGE:
        ignored |= {n for n in names if (PACKAGE / n).is_dir() and n not in BUNDLED_SUBDIRS | {"fmu"}}
        ignored |= HOST_ONLY_MODULES & set(names)
    elif here == FMU_DIR:
        ignored |= {n for n in names if n not in BUNDLED_FMU_FILES | {"models"}}
    elif here == MODELS or here.parent == MODELS:
        ignored |= {n for n in names if (here / n).is_file() and n not in ("__init__.py", "variables.py")}
    return ignored


def _table_files() -> list[Path]:
    """The interface tables' files the FMUs bundle (see :func:`bundle_filter`)."""
    return ([FMU_DIR / name for name in sorted(BUNDLED_FMU_FILES)] + [MODELS / "__init__.py"]
            + sorted(MODELS.glob("*/__init__.py")) + sorted(MODELS.glob("*/variables.py")))


def source_files(model: str) -> list[Path]:
    """Every file the pythonfmu ``<model>.fmu`` is built from: the slave, the bundled physics modules,
    tables and data, the builders and describers (build/, describe/), the guard (C front and loader) and the
    license it carries."""
    files = [slave_script(model), SLAVE_SUPPORT, *_table_files()]
    files += sorted(BUILD_DIR.glob("*.py")) + sorted(DESCRIBE_DIR.glob("*.py"))  # the builders and describers
    files += [PACKAGE / "LICENSE.txt", MODELS / "text.py"] + sorted(MODELS.glob("*/documentation.py"))  # documentation/
    files += sorted(FRONT.glob("*.[ch]")) + sorted(GUARD.glob("*.[ch]"))
    files += sorted(PACKAGE.glob("*.py"))
    for sub in sorted(BUNDLED_SUBDIRS):
        files += sorted(p for p in (PACKAGE / sub).rglob("*") if p.is_file() and "__pycache__" not in p.parts)
    return files


def source_hash(model: str) -> str:
    """SHA-256 over the names and contents of :func:`source_files` (what makes an FMU stale)."""
    digest = hashlib.sha256()
    for path in source_files(model):
        digest.update(path.relative_to(PACKAGE).as_posix().encode() + b"\0")
        digest.update(path.read_bytes())
        digest.update(b"\0")
    return digest.hexdigest()


def native_source_hash(model: str) -> str:
    """SHA-256 over the pythonfmu FMU's source hash (the interface and the physics the C follows) and
    every C file and generator the native ``<model>.fmu`` is built from."""
    digest = hashlib.sha256(source_hash(model).encode())
    paths = (sorted(FRONT.glob("*.[ch]")) + sorted(PHYSICS_C.glob("*.[ch]")) + sorted(PHYSICS_C.glob("*.py"))
             + native_sources(model))
    for path in paths:
        digest.update(path.name.encode() + b"\0" + path.read_bytes() + b"\0")
    return digest.hexdigest()


def recorded_source_hash(fmu: Path) -> str | None:
    """The source hash recorded in a built FMU, or None (not ours, older build, unreadable)."""
    try:
        with zipfile.ZipFile(fmu) as z:
            return json.loads(z.read(BUILD_INFO)).get("source_hash")
    except (OSError, KeyError, ValueError, zipfile.BadZipFile):
        return None
