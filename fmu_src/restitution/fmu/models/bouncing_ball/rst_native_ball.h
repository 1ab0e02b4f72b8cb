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
#define rst_ball_step_to_contact RST_PREFIXED(rst_ball_step_to_contact)
#define rst_ball_contact_pending RST_PREFIXED(rst_ball_contact_pending)
#define rst_ball_contact_update RST_PREFIXED(rst_ball_contact_update)
#define rst_ball_states_changed RST_PREFIXED(rst_ball_states_changed)
#define rst_ball_update_derivatives RST_PREFIXED(rst_ball_update_derivatives)
#define rst_ball_contact_event RST_PREFIXED(rst_ball_contact_event)
#define rst_ball_nominals RST_PREFIXED(rst_ball_nominals)
#endif

#include <stddef.h>

/* The state before fmi2ExitInitializationMode (the slave's _INITIAL_STATE: at the plate, no contact yet). */
void rst_ball_clear(double *values);

/* fmi2ExitInitializationMode: the initial state (released from rest at h0 at `start_time` [s]). */
void rst_ball_initialize(double *values, double start_time);

/* fmi2DoStep from `current_time` [s] over `step_size` [s]: locates every contact inside the step. */
void rst_ball_do_step(double *values, double current_time, double step_size);

/* FMI 3.0 co-simulation with early return: the step from `current_time` [s] over `step_size` [s] ends at
 * the first contact inside it (closed form, no time tolerance: a contact after the end belongs to a
 * later step), and returns the time it reached (that contact, or the end). A contact still pending at
 * `current_time` (the ball waiting at the plate) rebounds first, with the COR on the input. At the
 * contact: with `event_mode` the ball waits at the plate for the host's event mode
 * (rst_ball_contact_update); without, contact_mode decides: wait (it waits for the next step, which
 * starts at the contact) or immediate (it rebounds at once with the COR on the input). */
double rst_ball_step_to_contact(double *values, double current_time, double step_size, int event_mode);

/* The ball waits at the plate for the COR: a contact is pending. */
int rst_ball_contact_pending(const double *values);

/* FMI 3.0 co-simulation event mode at time `t` [s]: a pending contact rebounds with the COR on the input
 * (or comes to rest) at `t`; returns 1 when it did, 0 when no contact was pending. */
int rst_ball_contact_update(double *values, double t);

/* der(h), der(v) and the contact indicator from the state in the store (they are not part of the FMU
 * state: recomputed after a state is restored). */
void rst_ball_update_derivatives(double *values);

/* Model exchange: the host set h and v (or an input or parameter): the approach speed, der(h), der(v)
 * and the contact indicator follow from them. */
void rst_ball_states_changed(double *values);

/* Model exchange, at an event at time `t` [s]: a ball not at rest whose contact indicator is <= 0
 * (at or below the plate, not rising above it) meets the plate at speed |v| (counted, its time and
 * speed recorded), is put on the plate (h = 0) and rebounds with the COR on its input (then the
 * indicator is v^2/(2 g) > 0: strictly in flight), or comes to rest (indicator 1 m). Returns 1 when h
 * and v changed. */
int rst_ball_contact_event(double *values, double t);

/* Model exchange: the nominals of h [m] and v [m/s], the scale of the current flight: its apex
 * height h + max(v, 0)^2/(2 g) (which a free flight keeps) and the speed sqrt(2 g apex) it meets the
 * plate with (1 and 1 at rest, or for a state below the plate). A solver whose absolute tolerance is
 * its relative one times the nominal (fmpy's CVode) then integrates every flight, however low, to
 * the same relative accuracy: the rebounds near rest are micrometres high and would otherwise drown
 * in an absolute tolerance meant for the drop. They change at every contact (reported as changed). */
void rst_ball_nominals(const double *values, double nominals[2]);

#endif
