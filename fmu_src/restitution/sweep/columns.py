"""A sweep's columns: which inputs and outputs of the interface table it carries (by FMU name), the derived
``t_over_d``, the material pairs' names, a column that holds one value, and the counts of the validity
flags. What the table (:mod:`~restitution.sweep.table`), the statistics and the plots read of a sweep's
columns sits here, below the spec (:mod:`~restitution.sweep.spec`), which builds the cases."""
from __future__ import annotations

import numpy as np

from ..fmu.models.sphere_plate_impact.variables import MATERIAL_SELECTORS, TABLE
from ..materials import MATERIALS, TABLE4_CASES, table4_case

__all__ = ["SETTABLE", "INPUTS", "INPUT_NAMES", "START", "INTEGER_INPUTS", "CODES", "OUTPUTS", "OUTPUT_NAMES",
           "T_OVER_D", "resolve_pair", "pair_label", "is_one_value_view", "VALIDITY", "table_counts"]

#: The FMU's inputs and parameters a sweep sets: all but the material selectors (a sweep gives the
#: materials as pairs and sets their properties, the selectors stay custom).
SETTABLE = tuple(v for v in TABLE.settable if v.name not in MATERIAL_SELECTORS)
#: (FMU name, impact() keyword, FMI type, start value) of each of them.
INPUTS = tuple((v.name, v.key, v.type, v.start) for v in SETTABLE)
INPUT_NAMES = tuple(row[0] for row in INPUTS)
START = {row[0]: row[3] for row in INPUTS}
INTEGER_INPUTS = tuple(row[0] for row in INPUTS if row[2] == "Integer")

#: Integer-coded parameters: the words accepted for each code (as in the FMU's descriptions).
CODES = {v.name: v.codes for v in SETTABLE if v.choices is not None}

#: (FMU name, ImpactResult field, FMI type): the FMU's outputs, as restitution.model.published gives them.
OUTPUTS = tuple((v.name, v.key, v.type) for v in TABLE.outputs)
OUTPUT_NAMES = tuple(row[0] for row in OUTPUTS)

#: Derived axis: plate.t = t_over_d * sphere.d.
T_OVER_D = "t_over_d"
#: The validity flags of a table, each a column every table keeps.
VALIDITY = ("valid", "jgm.in_range", "zener.in_range")


# --- material pairs -------------------------------------------------------------------
def resolve_pair(pair: str):
    """(sphere Material, plate Material) of ``"sphere_key/plate_key"`` (keys of
    :data:`restitution.MATERIALS`) or ``"table4:A1"`` (Green 2022 Table 4 cases)."""
    text = pair.strip()
    if text.lower().startswith("table4:"):
        case = text.split(":", 1)[1].strip().upper()
        if case not in TABLE4_CASES:
            raise ValueError(f"pair {pair!r}: Table 4 cases are {', '.join(TABLE4_CASES)}")
        return table4_case(case)
    sphere, sep, plate = text.partition("/")
    if not sep:
        raise ValueError(f"pair {pair!r}: write it as sphere_material/plate_material, e.g. s2_tool_steel/al_6061")
    missing = [k for k in (sphere.strip(), plate.strip()) if k not in MATERIALS]
    if missing:
        raise ValueError(f"pair {pair!r}: unknown material(s) {missing}; known: {', '.join(sorted(MATERIALS))}")
    return MATERIALS[sphere.strip()], MATERIALS[plate.strip()]


def pair_label(pair: str) -> str:
    """Readable name of a pair: 'S2 tool steel on Aluminum 6061'."""
    if not pair:
        return "sphere and plate as set"
    if pair.lower().startswith("table4:"):
        return f"Table 4 case {pair.split(':', 1)[1].strip().upper()}"
    sphere, plate = resolve_pair(pair)
    return f"{sphere.name} on {plate.name}"


# --- the columns' values -----------------------------------------------------------------
def is_one_value_view(column: np.ndarray) -> bool:
    """Whether ``column`` (1-d, more than one case) is a view of one value (stride 0), as
    :meth:`SweepSpec.cases` gives a column that holds one value over its range: what can be checked,
    sent and evaluated once for the whole range."""
    return column.ndim == 1 and column.size > 1 and column.strides[0] == 0


def table_counts(columns: dict) -> dict:
    """Cases, evaluated cases (``ok``), cases inside the validated ranges (``valid``) and evaluated
    cases outside each range (``valid``, ``jgm.in_range``, ``zener.in_range`` false), as ints."""
    n = int(np.size(columns["case"]))
    ok = np.asarray(columns["ok"], dtype=bool) if "ok" in columns else np.ones(n, dtype=bool)
    counts = {"cases": n, "ok": int(np.count_nonzero(ok)),
              "inside": int(np.count_nonzero(columns["valid"])) if "valid" in columns else n}
    for flag in VALIDITY:
        counts[flag] = int(np.count_nonzero(ok & ~np.asarray(columns[flag], dtype=bool))) if flag in columns else 0
    return counts
