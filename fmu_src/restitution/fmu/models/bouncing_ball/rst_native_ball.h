/* The native BouncingBall backend: the ball of restitution/fmu/models/bouncing_ball/bouncing_ball_slave.py (which is
 * authoritative) in C99, on a value store holding every variable by value reference.
 *
 * The ball's whole state is in the store (its outputs and the local flight.* variables, as in the
 * Python FMU), so the front's FMU-state snapshot of the store is the ball's state. The store holds every
 * variable by value reference, as the generated interface header names them (RST_BOUNCINGBALL_VR_*).
 * The front checks ranges and the call sequence; this file only moves the ball. No global mutable state. */
#ifndef RST_NATIVE_BALL_H
#define RST_NATIVE_BALL_H

#include "rst_prefix.h"
#if defined(RST_PREFIXED)
#define rst_ball_clear RST_PREFIXED(rst_ball_clear)
#define rst_ball_initialize RST_PREFIXED(rst_ball_initialize)
#define rst_ball_do_step RST_PREFIXED(rst_ball_do_step)
#define rst_ball_states_changed RST_PREFIXED(rst_ball_states_changed)
#define rst_ball_update_derivatives RST_PREFIXED(rst_ball_update_derivatives)
#define rst_ball_contact_event RST_PREFIXED(rst_ball_contact_event)
#endif

#include <stddef.h>

/* The state before fmi2ExitInitializationMode (the slave's _INITIAL_STATE: at the plate, no contact yet). */
void rst_ball_clear(double *values);

/* fmi2ExitInitializationMode: the initial state (released from rest at h0 at `start_time` [s]). */
void rst_ball_initialize(double *values, double start_time);

/* fmi2DoStep from `current_time` [s] over `step_size` [s]: locates every contact inside the step. */
void rst_ball_do_step(double *values, double current_time, double step_size);

/* der(h), der(v) and the contact indicator from the state in the store (they are not part of the FMU
 * state: recomputed after a state is restored). */
void rst_ball_update_derivatives(double *values);

/* Model exchange: the host set h and v (or an input or parameter): the approach speed, der(h), der(v)
 * and the contact indicator follow from them. */
void rst_ball_states_changed(double *values);

/* Model exchange, at an event at time `t` [s]: a ball at or below the plate moving down meets it
 * (counted, its time and speed recorded) and rebounds with the COR on its input, or comes to rest.
 * Returns 1 when h and v changed. */
int rst_ball_contact_event(double *values, double t);

#endif
