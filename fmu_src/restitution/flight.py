"""A ball's free flight under gravity, no drag: the one Python form the bouncing ball's pythonfmu slave,
the co-simulation master (:func:`restitution.cosim.bouncing.impact_sequence`) and the drop model of a
calibration (:func:`restitution.fit.forward.bounce_train`) share. The native ball (``rst_native_ball.c``)
writes the same expression in C; ``tests/fmu/test_native_ball.py`` ties the two."""
from __future__ import annotations

from ._num import sqrt

__all__ = ["flight_to_plate"]


def flight_to_plate(h_start, v_start, g):
    """(duration [s], approach speed [m/s]) of a free flight that starts at height ``h_start`` [m] >= 0
    with upward speed ``v_start`` [m/s] under gravity ``g`` [m/s2] > 0 and ends at the plate (height 0).

    The approach speed is v_hit = sqrt(v_start^2 + 2 g h_start) (energy); the duration is the root of
    h_start + v_start s - g s^2 / 2 = 0, written (v_start + v_hit) / g, the form without cancellation
    for a large v_start. From the plate (h_start = 0) it is 2 v_start / g. Floats or numpy arrays."""
    v_hit = sqrt(v_start * v_start + 2.0 * g * h_start)
    return (v_start + v_hit) / g, v_hit
