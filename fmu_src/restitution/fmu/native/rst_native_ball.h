/* The native BouncingBall backend: the ball of restitution/fmu/slaves/bouncing_ball_slave.py (which is
 * authoritative) in C99, on a value store holding every variable by value reference.
 *
 * The ball's whole state is in the store (its outputs and the local flight.* variables, as in the
 * Python FMU), so the front's FMU-state snapshot of the store is the ball's state. The front checks
 * ranges and the call sequence; this file only moves the ball. No global mutable state. */
#ifndef RST_NATIVE_BALL_H
#define RST_NATIVE_BALL_H

#include "rst_prefix.h"
#if defined(FMI2_FUNCTION_PREFIX)
#define rst_ball_bind RST_PREFIXED(rst_ball_bind)
#define rst_ball_clear RST_PREFIXED(rst_ball_clear)
#define rst_ball_initialize RST_PREFIXED(rst_ball_initialize)
#define rst_ball_do_step RST_PREFIXED(rst_ball_do_step)
#endif

#include <stddef.h>

enum {
    RST_BALL_H0, RST_BALL_G, RST_BALL_V_MIN, RST_BALL_CONTACT_MODE, RST_BALL_E,
    RST_BALL_H, RST_BALL_V, RST_BALL_V_APPROACH, RST_BALL_IMPACTS, RST_BALL_T_IMPACT, RST_BALL_V_IMPACT,
    RST_BALL_T_REBOUND, RST_BALL_V_REBOUND, RST_BALL_E_APPLIED, RST_BALL_IN_CONTACT, RST_BALL_AT_REST,
    RST_BALL_T_START, RST_BALL_H_START, RST_BALL_V_START,
    RST_BALL_N_SLOTS
};

typedef struct {
    size_t n_variables;                /* the value store's length */
    unsigned int vr[RST_BALL_N_SLOTS]; /* value reference of each slot */
} rst_ball_binding;

/* Bind against the generated BouncingBall interface table; 0 on success, else `message` says why. */
int rst_ball_bind(rst_ball_binding *binding, char *message, size_t size);

/* The state before fmi2ExitInitializationMode (the slave's _INITIAL_STATE: at the plate, no contact yet). */
void rst_ball_clear(const rst_ball_binding *binding, double *values);

/* fmi2ExitInitializationMode: the initial state (released from rest at h0 at `start_time` [s]). */
void rst_ball_initialize(const rst_ball_binding *binding, double *values, double start_time);

/* fmi2DoStep from `current_time` [s] over `step_size` [s]: locates every contact inside the step. */
void rst_ball_do_step(const rst_ball_binding *binding, double *values, double current_time, double step_size);

#endif
