"""The exact inverse of the clamped linear contact (restitution.export.linear_contact) against the forward law
integrated here with scipy's solve_ivp: x'' + 2 zeta x' + x = 0 from x = 0, x' = 1, released when the force
x + 2 zeta x' (not the penetration) reaches zero."""
from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from restitution.export.linear_contact import clamped_damping_ratio, unclamped_damping_ratio


def _clamped_rebound(zeta: float) -> float:
    """The rebound speed over the approach speed of the oscillator whose force is clamped at zero: the sphere
    leaves at the first zero of the force (a terminal event), with the speed it has there."""
    def force(_t, y):
        return y[0] + 2.0 * zeta * y[1]

    force.terminal, force.direction = True, -1
    sol = solve_ivp(lambda _t, y: [y[1], -2.0 * zeta * y[1] - y[0]], (0.0, 1e3), [0.0, 1.0], events=force,
                    method="DOP853", rtol=1e-12, atol=1e-14)
    assert sol.t_events[0].size == 1, "the force never returned to zero"
    return -sol.y_events[0][0][1]


@pytest.mark.parametrize("e", [0.1, 0.2, 0.3, 0.5, 0.6, 0.75, 0.9, 0.95, 0.98])
def test_inverse_gives_e_back_through_the_integrated_clamped_law(e):
    # DOP853 at rtol 1e-12 locates the event to ~1e-12; 1e-8 leaves room and is far below any use (1 %)
    assert _clamped_rebound(clamped_damping_ratio(e)) == pytest.approx(e, rel=1e-8, abs=1e-10)


def test_the_unclamped_map_overshoots_on_a_contact_that_cannot_pull():
    """The linear oscillator's formula, applied to a contact that cannot pull, gives back a higher e: about
    +10 % at e = 0.5 and about +30 % at e = 0.3, the rebound integrated here."""
    over = {e: _clamped_rebound(unclamped_damping_ratio(e)) / e - 1.0 for e in (0.3, 0.5, 0.9)}
    assert 0.08 < over[0.5] < 0.12 and 0.25 < over[0.3] < 0.35 and 0.0 < over[0.9] < 0.01, over


def test_damping_ratio_falls_as_e_rises():
    zetas = [clamped_damping_ratio(e) for e in np.linspace(0.05, 0.99, 30)]
    assert np.all(np.diff(zetas) < 0) and zetas[0] > 1.0  # e < exp(-2) needs an over-damped contact
