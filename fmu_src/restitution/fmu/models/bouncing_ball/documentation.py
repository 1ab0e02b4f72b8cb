"""BouncingBall's documentation beyond its interface table: free flight, contacts, the rest rule,
``contact_mode`` and model exchange (``documentation/index.html`` of every BouncingBall FMU, written by
:func:`restitution.fmu.describe.documentation.index_html`). The facts are those of the slave's docstring
(``bouncing_ball_slave.py``) and of docs/host_contract.md ("FMI 3.0 and model exchange"); plain text,
variable names between backticks."""
from __future__ import annotations

from ..text import Section

DOCUMENTATION = (
    Section("What it computes", (
        "The ball's side of a co-simulation with SpherePlateImpact.fmu: a ball in vertical free flight above a "
        "fixed plate, which rebounds at each contact with the coefficient of restitution (COR) on its input `e`. "
        "The impact FMU supplies that COR for the ball's approach speed. Connect",
        (
            "`BouncingBall.v_approach` \u2192 `SpherePlateImpact.v_approach`",
            "`SpherePlateImpact.e` \u2192 `BouncingBall.e`",
        ),
        "and give SpherePlateImpact the ball's sphere (its material and diameter).",
        "Free flight: the ball is released from rest at height `h0` at the start time; in flight, under the "
        "gravitational acceleration `g` (upward positive), h(t) = h_s + v_s (t \u2212 t_s) \u2212 g (t \u2212 "
        "t_s)\u00b2/2 and v(t) = v_s \u2212 g (t \u2212 t_s) from the start of the current flight "
        "(t_s, h_s, v_s: `flight.t_start`, `flight.h_start`, `flight.v_start`). The flight is kept in this closed "
        "form, so the position at any time does not depend on the step size: every error in a co-simulation of "
        "this FMU comes from the coupling, none from integrating the flight.",
        "Contacts: a contact is where the flight reaches the plate, h = 0, at the approach speed "
        "`v_approach` = max(\u2212v, 0). The ball rebounds from the plate with v = e \u00b7 |v|. The impact is "
        "instantaneous (the contact duration, tens of microseconds, is not spent). `impacts` counts the contacts "
        "(it saturates at 2147483647); `t_impact`, `v_impact`, `t_rebound`, `v_rebound` and `e_applied` describe "
        "the last one.",
        "Rest: the ball comes to rest on the plate (h = v = 0, `at_rest` true; no more motion) when its rebound "
        "speed would be below `v_min`, or when e \u2264 0. `h0` = 0 starts it at rest on the plate.",
    )),
    Section("Co-simulation: contact_mode", (
        "A co-simulation master exchanges values only at communication points, so the ball cannot ask for the "
        "COR of an impact inside a step. Each contact is located inside `fmi2DoStep` / `fmi3DoStep`, in closed "
        "form (the root of the flight parabola), and `contact_mode` says what happens then:",
        (
            "1 = wait (default): at the contact the ball stops at the plate (h = 0, `in_contact` true), keeps its "
            "approach speed and reports it as `v_approach`; at the start of the next step it rebounds with the COR "
            "then on its input `e`, which a master that resolves SpherePlateImpact's direct feedthrough has "
            "computed for exactly that approach speed. The COR is right; the rebound is late by the rest of the "
            "step (less than one communication step).",
            "2 = immediate: the ball rebounds at the contact instant with the COR held on its input since the "
            "last communication point, the COR for the speed the ball had then, not its impact speed. The timing "
            "is right; the COR is off by O(step).",
        ),
        "Every step takes a bounded time, whatever the step and the parameters: in immediate mode the bounces "
        "after the first rebound of a step start at the plate with the same COR, their impact times and speeds "
        "form a geometric series, and the step jumps to the last impact inside it in closed form.",
    )),
    Section("Model exchange", (
        "The host integrates the continuous states `h` and `v` with their derivatives `der(h)` = v and `der(v)` "
        "= \u2212g in flight (both 0 at rest). The one event indicator, `contact_indicator`, is in flight the "
        "height the ball reaches before it falls, h + max(v, 0)\u00b2/(2 g): h while the ball falls, so the "
        "host's solver locates each contact where it crosses zero, and the apex height while it rises.",
        "At that event (fmi2NewDiscreteStates in FMI 2.0, fmi3UpdateDiscreteStates in FMI 3.0) the FMU looks at "
        "the states the host set: a ball whose indicator is \u2264 0 meets the plate at the speed |v|, is put on "
        "the plate (h = 0), counted, its time and approach speed recorded, and rebounds with v = e \u00b7 |v| "
        "with the COR on its input `e` (set it from SpherePlateImpact.e for the current `v_approach` before the "
        "update); the FMU reports that the states changed. An event where the indicator is > 0 changes nothing.",
        "After a rebound the indicator is v\u00b2/(2 g) \u2265 v_min\u00b2/(2 g) > 0: the ball is strictly in "
        "flight, never at the indicator's zero, so a host that compares each indicator with its value after the "
        "last event sees every contact. A rebound slower than `v_min`, or e \u2264 0, brings the ball to rest: "
        "h = v = 0 and the indicator held at 1 m, so no more events (no chatter near rest). `contact_mode` does "
        "not apply: the rebound is at the contact itself. There are no time events and no step events.",
    ), model_exchange=True),
    Section("Assumptions and validity", (
        (
            "Vertical motion only, under uniform gravity `g`, without air drag; the plate is fixed.",
            "Instantaneous impacts: the ball leaves the plate at the time it reaches it (in contact_mode 1, at "
            "the next communication point), with the COR on its input at that moment.",
            "The COR is what the host puts on `e` (-1 \u2264 e \u2264 1). From SpherePlateImpact it is valid where "
            "that FMU's `valid` is true, for each impact.",
            "`h0` and `g` are at most 1e6 (m, m/s\u00b2) and `v_min` at least 1e-6 m/s, so every speed, time and "
            "height stays finite and the last flight, 2 v_min/g, stays above a solver's time resolution.",
        ),
    )),
)
