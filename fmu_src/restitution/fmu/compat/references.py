"""The reference results of the compatibility information, computed by the package, never by the FMU:

* BouncingBall: :func:`ball_trajectory`, the closed-form flights of a ball dropped from rest with a
  constant coefficient of restitution (its ``_in.csv`` holds e constant);
* SpherePlateImpact: :func:`restitution.impact` at each sample's approach speed (its ``_in.csv`` holds a
  speed ramp), the FMU's default pair (S2 tool steel, d = 6.35 mm, on Al 6061, t = 6.35 mm).
"""
from __future__ import annotations

import math

import numpy as np

__all__ = ["ball_trajectory", "impact_outputs", "IMPACT_OUTPUTS"]

#: SpherePlateImpact's outputs in the reference: FMU name -> field of restitution.ImpactResult.
IMPACT_OUTPUTS = {"e": "e", "v_rebound": "v_rebound", "jgm.e": "e_ep", "zener.e": "e_ze"}


def _contact_delay(h: float, v_up: float, g: float) -> float:
    """Time [s] from height h [m] with upward speed v_up [m/s] to the plate under gravity g [m/s2]: the
    positive root of h + v_up tau - g tau^2 / 2 = 0 (ballistic flight)."""
    return (v_up + math.sqrt(v_up * v_up + 2.0 * g * h)) / g


def ball_trajectory(times, h0: float, g: float, e: float, v_min: float, wait_step: float | None = None):
    """Height h [m] and upward velocity v [m/s] of BouncingBall at ``times`` [s], dropped from rest at
    h0 [m] at t = 0 under gravity g [m/s2], rebounding from each contact with speed e * v_impact (e [1]
    constant) and at rest once that is below v_min [m/s].

    ``wait_step`` [s]: co-simulation with contact_mode wait and that communication step: from the contact
    until the next communication point the ball stays at the plate (h = 0, v = -v_impact), then leaves
    with e * v_impact; None: it leaves at the contact (model exchange, or contact_mode immediate)."""
    times = np.asarray(times, dtype=float)
    h, v = np.empty_like(times), np.empty_like(times)
    t_start, h_start, v_start = 0.0, float(h0), 0.0
    remaining = np.ones(times.shape, dtype=bool)
    while remaining.any():
        t_contact = t_start + _contact_delay(h_start, v_start, g)
        v_impact = g * (t_contact - t_start) - v_start
        flight = remaining & (times < t_contact)
        tau = times[flight] - t_start
        h[flight] = h_start + v_start * tau - 0.5 * g * tau * tau
        v[flight] = v_start - g * tau
        remaining &= ~flight
        rebound = e * v_impact
        if rebound < v_min:  # at rest on the plate from the contact on
            h[remaining], v[remaining] = 0.0, 0.0
            break
        t_leave = t_contact
        if wait_step is not None:
            t_leave = math.ceil(t_contact / wait_step - 1e-9) * wait_step
            waiting = remaining & (times <= t_leave)
            h[waiting], v[waiting] = 0.0, -v_impact
            remaining &= ~waiting
        t_start, h_start, v_start = t_leave, 0.0, rebound
    return h, v


def impact_outputs(speeds) -> dict:
    """{FMU output name: values} of SpherePlateImpact's :data:`IMPACT_OUTPUTS` at the approach ``speeds``
    [m/s], from :func:`restitution.impact` with the FMU's default parameters."""
    from ...materials import MATERIALS, Plate, Sphere
    from ...model import impact

    params = {**Sphere(MATERIALS["s2_tool_steel"], 6.35e-3).params(), **Plate(MATERIALS["al_6061"], 6.35e-3).params()}
    results = [impact(float(s), **params) for s in speeds]
    return {name: np.array([float(getattr(res, field)) for res in results])
            for name, field in IMPACT_OUTPUTS.items()}
