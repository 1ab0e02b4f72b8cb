/* The native SpherePlateImpact backend: the physics of rst_physics.h on a value store that holds
 * every variable of the FMU by value reference, as the generated interface header names them
 * (restitution.fmu.describe.c_header: RST_SPHEREPLATEIMPACT_VR_*, and the codes of the choices).
 *
 * Front-independent on purpose: the C FMI front (cfront/) owns the state machine, the argument and
 * range checks, logging and the value store; its glue (rst_native_impact_fmu.c) calls
 * rst_impact_evaluate_cached whenever an input or parameter changed, with the instance's cache of the
 * parameter-only terms, which it marks stale whenever anything but v_approach may have changed. No
 * global mutable state. */
#ifndef RST_NATIVE_IMPACT_H
#define RST_NATIVE_IMPACT_H

#include "rst_prefix.h"
#if defined(RST_PREFIXED)
#define rst_impact_accept RST_PREFIXED(rst_impact_accept)
#define rst_impact_evaluate RST_PREFIXED(rst_impact_evaluate)
#define rst_impact_evaluate_cached RST_PREFIXED(rst_impact_evaluate_cached)
#define rst_impact_evaluate_primary RST_PREFIXED(rst_impact_evaluate_primary)
#define rst_impact_evaluate_rest RST_PREFIXED(rst_impact_evaluate_rest)
#endif

#include <stddef.h>

#include "rst_physics.h"

/* Return code of rst_impact_evaluate besides rst_physics.h's: an output is NaN or infinite (every
 * published output is finite: an evaluation failure: every output NaN/false). */
#define RST_IMPACT_NONFINITE 100

/* A value the interface table allows but this backend refuses: zener_method = 4 (ode), which only
 * the Python FMU integrates. Nonzero with `message` saying so; 0 otherwise. */
int rst_impact_accept(unsigned int vr, double value, char *message, size_t size);
/* The value references rst_impact_accept may refuse a value of (it accepts every value of the others),
 * as an initializer; the generated interface header included before this one names them. */
#define RST_IMPACT_ACCEPT_VRS {RST_SPHEREPLATEIMPACT_VR_ZENER_METHOD}

/* Evaluate the model on `values` (every variable by value reference; Integer codes and Boolean 0/1
 * as doubles): reads the inputs and parameters, writes every output. 0 (RST_PHYSICS_OK) on success;
 * otherwise the physics' error code, every Real output NaN, every Boolean 0, and `message` says why
 * (zener_method = 4 names the Python FMU, which integrates Eq. (10)). */
int rst_impact_evaluate(double *values, char *message, size_t size);

/* What an instance keeps between evaluations: the parameter-only terms (rst_impact_terms_of) of the
 * store's parameters, while `fresh`. All zero (as the front allocates backend data) is stale. Whoever
 * owns it sets fresh = 0 whenever a store slot other than v_approach may have changed (a parameter set,
 * a reset, a restored FMU state): a fresh cache is trusted without looking at the store. */
typedef struct {
    int fresh;
    rst_impact_terms terms;
} rst_impact_cache;

/* rst_impact_evaluate with a cache: where the cache is stale, resolves the materials (writes the
 * calculated parameters <body>.used.*) and recomputes the terms; then evaluates at the store's
 * v_approach. Same results, return codes and messages as rst_impact_evaluate. */
int rst_impact_evaluate_cached(rst_impact_cache *cache, double *values, char *message, size_t size);

/* rst_impact_evaluate_cached in two parts, for a front that publishes what a host reads:
 * rst_impact_evaluate_primary writes e and v_rebound (and the calculated parameters where the cache was
 * stale) and keeps in `primary` what the rest needs; rst_impact_evaluate_rest, with the same cache and
 * `primary`, writes every other output. The two in turn are rst_impact_evaluate_cached (which calls them):
 * the same values, return codes and messages, the checks of finiteness split between them. */
int rst_impact_evaluate_primary(rst_impact_cache *cache, double *values, rst_impact_primary *primary, char *message,
                                size_t size);
int rst_impact_evaluate_rest(const rst_impact_cache *cache, const rst_impact_primary *primary, double *values,
                             char *message, size_t size);

#endif
