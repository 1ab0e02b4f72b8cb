"""What the accuracy benchmark measures and its goals: the full and quick configurations."""
from __future__ import annotations

from dataclasses import dataclass


#: The benchmark's targets: name -> (goal text, test on the measured value).
TARGETS = {
    "exact_rel_error": ("<= 1e-8", lambda x: x <= 1e-8),
    "exact_over_paper_fit_package": ("<= 2x", lambda x: x <= 2.0),
    "exact_over_paper_fit_fmu": ("<= 1.2x", lambda x: x <= 1.2),
    "fmu_over_floor": ("<= 1.5x", lambda x: x <= 1.5),
    "scalar_over_vectorized": (">= 50x", lambda x: x >= 50.0),
}


STEEL_ON_AL = dict(sphere=("s2_tool_steel", 6.35e-3), plate="al_6061")


@dataclass(frozen=True)
class Config:
    """How much to measure: ``FULL`` for docs/, ``QUICK`` for the tests."""

    n_small: int  # lambda points in (0, 1.5) (plus 0 and 1.5)
    n_large: int  # lambda points in (1.5, 100) (plus 100)
    ode_rtols: tuple
    reps: int  # timing batches per variant
    batch_seconds: float  # CPU time per timing batch
    n_vector: int  # cases in the vectorized calls
    n_vector_ode: int  # cases in the vectorized ode call (a Python loop of solves)
    ode_reps: int
    cosim_steps: tuple
    reference_check: tuple  # lambdas where the reference is re-solved at rtol 1e-12


FULL = Config(n_small=48, n_large=32, ode_rtols=tuple(10.0 ** -k for k in range(3, 13)), reps=11,
              batch_seconds=0.02, n_vector=100_000, n_vector_ode=200, ode_reps=3,
              cosim_steps=(1e-2, 1e-3, 1e-4, 1e-5), reference_check=(0.3, 1.5, 10.0, 100.0))


QUICK = Config(n_small=5, n_large=3, ode_rtols=(1e-3, 1e-6, 1e-9, 1e-12), reps=5, batch_seconds=0.005,
               n_vector=10_000, n_vector_ode=20, ode_reps=1, cosim_steps=(1e-2, 1e-3), reference_check=())


RANGES = ("[0, 1.5]", "(1.5, 100]")
