"""BouncingBall's interface: one row per variable, in value-reference order.

Parameters and the input carry the slave's names; outputs and locals the key of the quantity the
ball evolves (all of them are part of the FMU state). No output depends directly on the input at
the same communication point, and none of the initial unknowns depends on it (they follow from h0
and g alone: a host connecting the COR from SpherePlateImpact sees no algebraic loop at
initialization): the COR acts only inside fmi2DoStep (co-simulation) or at the contact event
(model exchange, where h and v are the continuous states, der(h) and der(v) their derivatives and
contact_indicator the event indicator; these three are recomputed, not part of the state).
"""
from __future__ import annotations

import math

from ...table import Table, input_, local, output, parameter

#: contact_mode's choices, codes 1 and 2
CONTACT_MODES = ("wait", "immediate")
#: Upper bound of h0 [m] and of g [m/s2] (1000 km; 1e5 standard gravities): the largest speed,
#: sqrt(2 g h0) = 1.4e6 m/s, and every time and height then stay finite.
MAX_HEIGHT_OR_GRAVITY = 1e6
STANDARD_GRAVITY = 9.80665  # [m/s2]
#: Lower bound of g [m/s2] (the surface of a kilometre-sized asteroid): the contact indicator's
#: apex term v^2/(2 g) stays finite for every speed the ball can reach.
MIN_GRAVITY = 1e-6
#: Lower bound of v_min [m/s]. After a rebound the contact indicator is the apex height
#: v^2/(2 g) >= MIN_REST_SPEED^2/(2 * 1e6 m/s2) = 5e-19 m > 0, so the ball is strictly in flight
#: (never at the indicator's zero), and the last flight, 2 v_min/g, stays far above the time
#: resolution of a solver's clock; a smaller threshold only adds bounces no solver resolves.
MIN_REST_SPEED = 1e-6


def _evolved(name, key, unit, description, vtype="Real", initial_dependencies=()):
    return output(name, key, unit, description, vtype=vtype, state=True, initial_dependencies=initial_dependencies)


TABLE = Table("BouncingBall", "Ball in free flight above a plate; locates each contact inside the step and "
              "rebounds with the coefficient of restitution on its input (connect to SpherePlateImpact.fmu)", (
    parameter("h0", "h0", "m", 0.3, "Drop height: the ball is released from rest at the start time, "
              "0 <= h0 <= 1e6 m (0: at rest on the plate from the start)", (0.0, MAX_HEIGHT_OR_GRAVITY, False, False),
              variability="fixed"),
    parameter("g", "g", "m/s2", STANDARD_GRAVITY, "Gravitational acceleration, 1e-6 <= g <= 1e6 m/s2",
              (MIN_GRAVITY, MAX_HEIGHT_OR_GRAVITY, False, False), variability="fixed"),
    parameter("v_min", "v_min", "m/s", 0.1, "The ball comes to rest when its rebound speed would be below v_min, "
              ">= 1e-6 m/s", (MIN_REST_SPEED, math.inf, False, True), variability="fixed"),
    parameter("contact_mode", "contact_mode", None, 1,
              "1 = wait (at contact stay at the plate until the next communication point, then rebound with the COR "
              "input), 2 = immediate (rebound at contact with the COR input held since the last communication point)",
              vtype="Integer", variability="fixed", choices=CONTACT_MODES),
    input_("e", "e", "1", 1.0, "Coefficient of restitution for the current approach speed "
           "(from SpherePlateImpact.e), -1 <= e <= 1; e <= 0: the ball stays at the plate", (-1.0, 1.0, False, False),
           range_text="-1 <= e <= 1"),
    _evolved("h", "h", "m", "Height of the ball above the plate", initial_dependencies=("h0",)),
    _evolved("v", "v", "m/s", "Vertical velocity of the ball, upward positive"),
    _evolved("v_approach", "v_approach", "m/s", "Speed of the ball toward the plate, max(-v, 0) "
             "(while waiting at the plate: the impact speed); connect to SpherePlateImpact.v_approach"),
    _evolved("impacts", "impacts", None, "Number of contacts with the plate so far (saturates at 2147483647)",
             "Integer"),
    _evolved("t_impact", "t_impact", "s", "Time of the last contact, located inside the step (-1: none yet)"),
    _evolved("v_impact", "v_impact", "m/s", "Approach speed at the last contact"),
    _evolved("t_rebound", "t_rebound", "s", "Time the ball left the plate after the last contact (-1: not yet)"),
    _evolved("v_rebound", "v_rebound", "m/s", "Rebound speed after the last contact (0: at rest)"),
    _evolved("e_applied", "e_applied", "1", "COR applied at the last rebound (0 until the first rebound, while "
             "t_rebound = -1)"),
    _evolved("in_contact", "in_contact", None, "Waiting at the plate for the COR (contact_mode = 1)", "Boolean"),
    _evolved("at_rest", "at_rest", None, "The ball has come to rest on the plate", "Boolean", ("h0",)),
    local("flight.t_start", "t_start", "s", "Start time of the current free flight"),
    local("flight.h_start", "h_start", "m", "Height at the start of the current free flight"),
    local("flight.v_start", "v_start", "m/s", "Upward velocity at the start of the current free flight"),
    # model exchange: the host integrates h and v between the contacts, located as state events
    local("der(h)", "der_h", "m/s", "Time derivative of h: v in flight, 0 at rest (model exchange: the host "
          "integrates h with it)", state=False, derivative="h", initial_dependencies=()),
    local("der(v)", "der_v", "m/s2", "Time derivative of v: -g in flight, 0 at rest (model exchange: the host "
          "integrates v with it)", state=False, derivative="v", initial_dependencies=("h0", "g")),
    local("contact_indicator", "contact_indicator", "m", "Event indicator of the contact with the plate: in flight "
          "h + max(v, 0)^2/(2 g), the height the ball reaches before it falls (h once it falls; a crossing to <= 0 is "
          "a contact: model exchange; strictly > 0 after every rebound), 1 m at rest (no more contacts)", state=False,
          event_indicator=True),
))
