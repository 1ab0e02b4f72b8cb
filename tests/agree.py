"""Comparing two evaluations of the model within tolerances from its conditioning.

Never bit identity: two code paths, math libraries or CPUs may differ in the last bit of exp,
log and pow, and each output amplifies that by its own condition number
(:mod:`restitution.agreement` derives the bound case by case and documents it).
"""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from restitution.agreement import FLAGS, REALS, disagreements, tolerances


def stack(results) -> SimpleNamespace:
    """Scalar ImpactResults as one object of arrays (field by field)."""
    return SimpleNamespace(**{name: np.array([getattr(res, name) for res in results]) for name in REALS + FLAGS})


def assert_agree(a, b, v, params: dict, context: str = "", **options) -> None:
    """``a`` and ``b`` (results for ``impact(v, **params, **options)``) agree within the conditioning."""
    tol, flips = tolerances(v, params, **options)
    problems = disagreements(a, b, tol, flips)
    assert not problems, f"{context}: " + "; ".join(problems)
