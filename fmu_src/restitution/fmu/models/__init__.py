"""One folder per model: its interface table (``variables.py``), and beside it what implements it.

:func:`table` gives a model's :class:`~restitution.fmu.table.Table` by model identifier.
"""
from __future__ import annotations

import importlib

#: Model identifier -> its folder under models/.
FOLDERS = {"SpherePlateImpact": "sphere_plate_impact", "BouncingBall": "bouncing_ball"}


def table(model: str):
    """The interface table of ``model`` ("SpherePlateImpact" or "BouncingBall")."""
    if model not in FOLDERS:
        raise KeyError(f"unknown model {model!r}: one of {', '.join(FOLDERS)}")
    return importlib.import_module(f"{__name__}.{FOLDERS[model]}.variables").TABLE
