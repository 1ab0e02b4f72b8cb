"""One folder per model, each holding everything that is the model's own:

* ``variables.py``: its interface table (:func:`table`), which everything else reads;
* ``<folder>_slave.py``: the pythonfmu slave (the reference implementation, for Python hosts);
* ``rst_native_*.c/.h``: the native C backend, and ``rst_native_*_fmu.c``, its glue to the C FMI front
  (``../cfront``, written once for every model).

``restitution_slave_support.py`` is what the slaves share (shipped beside each slave in its FMU).
"""
from __future__ import annotations

import importlib
from pathlib import Path

HERE = Path(__file__).resolve().parent
#: Model identifier -> its folder under models/.
FOLDERS = {"SpherePlateImpact": "sphere_plate_impact", "BouncingBall": "bouncing_ball"}
#: What the slaves import, shipped beside each slave script in the FMU's resources/.
SLAVE_SUPPORT = HERE / "restitution_slave_support.py"


def folder(model: str) -> Path:
    """The folder of ``model``."""
    if model not in FOLDERS:
        raise KeyError(f"unknown model {model!r}: one of {', '.join(FOLDERS)}")
    return HERE / FOLDERS[model]


def slave_script(model: str) -> Path:
    """The pythonfmu slave script of ``model`` (its module name is unique across models: two pythonfmu
    FMUs whose scripts share a module name clash in one process)."""
    return folder(model) / f"{FOLDERS[model]}_slave.py"


def native_sources(model: str) -> list[Path]:
    """The C files of ``model``'s native backend and its glue to the front."""
    return sorted(p for p in folder(model).iterdir() if p.suffix in (".c", ".h"))


def table(model: str):
    """The interface table of ``model`` ("SpherePlateImpact" or "BouncingBall")."""
    folder(model)  # a clear error for an unknown model
    return importlib.import_module(f"{__name__}.{FOLDERS[model]}.variables").TABLE
