/* The native SpherePlateImpact backend: binds the FMU interface table that
 * restitution.fmu.interface.c_header generates (names -> value references) to the physics of
 * rst_physics.h, and evaluates it on a value store holding every variable by value reference.
 *
 * Front-independent on purpose: the generic C FMI front (cfront/, issue 11) owns the state machine,
 * the argument and range checks, logging and the value store; it calls rst_impact_bind once per
 * instance and rst_impact_evaluate whenever an input or parameter changed. No global mutable state:
 * the binding lives in the caller's instance. */
#ifndef RST_NATIVE_IMPACT_H
#define RST_NATIVE_IMPACT_H

#include "rst_prefix.h"
#if defined(FMI2_FUNCTION_PREFIX)
#define rst_impact_bind RST_PREFIXED(rst_impact_bind)
#define rst_impact_accept RST_PREFIXED(rst_impact_accept)
#define rst_impact_evaluate RST_PREFIXED(rst_impact_evaluate)
#endif

#include <stddef.h>

#define RST_IMPACT_N_INPUTS 17  /* v_approach, the 10 material/geometry parameters, 4 codes, 2 tolerances */
#define RST_IMPACT_N_OUTPUTS 19 /* 12 Real and 7 Boolean outputs */

typedef struct {
    size_t n_variables;                         /* the value store's length (largest vr + 1) */
    unsigned int input_vr[RST_IMPACT_N_INPUTS];
    unsigned int output_vr[RST_IMPACT_N_OUTPUTS];
} rst_impact_binding;

/* Bind against the generated SpherePlateImpact interface table. 0 on success; otherwise nonzero and
 * `message` names the variable that is missing or has an unexpected type. */
int rst_impact_bind(rst_impact_binding *binding, char *message, size_t size);

/* Return code of rst_impact_evaluate besides rst_physics.h's: an output is NaN or infinite (every
 * published output is finite: an evaluation failure: every output NaN/false). */
#define RST_IMPACT_NONFINITE 100

/* A value the interface table allows but this backend refuses: zener_method = 4 (ode), which only
 * the Python FMU integrates. Nonzero with `message` saying so; 0 otherwise. */
int rst_impact_accept(const rst_impact_binding *binding, unsigned int vr, double value, char *message, size_t size);

/* Evaluate the model on `values` (every variable by value reference; Integer codes and Boolean 0/1
 * as doubles): reads the inputs and parameters, writes every output. 0 (RST_PHYSICS_OK) on success;
 * otherwise the physics' error code, every Real output NaN, every Boolean 0, and `message` says why
 * (zener_method = 4 names the Python FMU, which integrates Eq. (10)). */
int rst_impact_evaluate(const rst_impact_binding *binding, double *values, char *message, size_t size);

#endif
