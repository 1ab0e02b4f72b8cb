"""Which steps of :func:`restitution.model.impact` an asked set of outputs needs (``impact(outputs=...)``)."""
from __future__ import annotations

from functools import lru_cache
from typing import NamedTuple

#: What each output needs computed first, by name (an output, or a step of the pipeline named after the
#: output it gives; ``zener``: Zener's whole solution, e_ze with its deficit 1 - e_ze and tau0): the rest (V_c, V_star, eps_y, lam, T, m_a, plate_waves_used and the flags of lambda
#: and V*) need only the parameter terms, the speed and lambda, which every call computes.
DEPENDS = {
    "e": ("e_ep", "e_ze"), "v_rebound": ("e",), "e_negative": ("e",), "plasticity_used": ("e_ep",),
    "v_plate": ("e_ep", "zener"), "tau0": ("zener",), "contact_ends": ("zener",), "t_contact": ("T", "zener"),
    "m_eff": ("mass_ratio",), "mass_ratio": ("zener",), "wave_delay": ("zener",), "concurrent": ("wave_delay",),
    "zener": ("e_ze",), "valid": ("lambda_in_range", "vstar_in_range"),
    "edge_echo": ("t_contact",), "edge_clear": ("edge_echo",),
}


class Wanted(NamedTuple):
    """A checked ``outputs=``."""

    names: tuple  #: the outputs asked for, in order, each once
    steps: frozenset  #: those and every step they depend on


def dependencies(name: str, record: tuple) -> frozenset:
    """``name`` and every step it depends on (:data:`DEPENDS`, followed to the end); ValueError, one line,
    for a name not in ``record`` (the outputs there are)."""
    if name.__class__ is not str or name not in record:
        raise ValueError(f"unknown output {name!r}; the outputs are {', '.join(record)}")
    closure, todo = set(), [name]
    while todo:
        step = todo.pop()
        if step not in closure:
            closure.add(step)
            todo.extend(DEPENDS.get(step, ()))
    return frozenset(closure)


@lru_cache(maxsize=64)
def wanted(names: tuple, record: tuple) -> Wanted:
    """The :class:`Wanted` of the output ``names`` (a tuple of distinct names) out of ``record``."""
    if not names:
        raise ValueError(f"outputs is empty; ask for some of {', '.join(record)} (or None: all)")
    return Wanted(names, frozenset().union(*(dependencies(name, record) for name in names)))
