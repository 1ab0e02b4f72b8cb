/* The SpherePlateImpact model in C99 (libm only): I. Green, Nonlinear Dyn (2022), JGM Eqs. (1)-(8),
 * Zener Eqs. (9)-(13a) and (22), fusion Eqs. (17)-(20).
 *
 * A transcription of the Python package `restitution` (model.py `_pipeline`, jgm.py, zener.py,
 * zener_exact.py, fusion.py), which is authoritative: where the two disagree, the C is wrong.
 * The same well-conditioned forms are used (e45 in log space, expm1 deficits 1 - e_ze, the fused
 * COR as a difference of two non-negative terms), so the two agree within each output's
 * conditioning (restitution.agreement), which tests/fmu/test_native_physics.py checks.
 *
 * Pure functions of their arguments: no global mutable state, safe from any thread. */
#ifndef RST_PHYSICS_H
#define RST_PHYSICS_H

#include "rst_prefix.h"
#if defined(RST_PREFIXED)
#define rst_impact RST_PREFIXED(rst_impact)
#define rst_zener_solution RST_PREFIXED(rst_zener_solution)
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* Codes of the Integer parameters, as in the FMU's interface. */
enum { RST_E45 = 1, RST_E44 = 2 };
enum { RST_ZENER_EXACT = 1, RST_ZENER_PAPER_FIT = 2, RST_ZENER_LINEAR = 3, RST_ZENER_ODE = 4 };
enum { RST_EFFECT_OFF = 0, RST_EFFECT_ON = 1, RST_EFFECT_AUTO = 2 };

/* Return codes of rst_impact. */
enum {
    RST_PHYSICS_OK = 0,
    RST_PHYSICS_BAD_CODE = 1,    /* an Integer parameter outside its codes */
    RST_PHYSICS_UNSUPPORTED = 2  /* zener_method = 4 (ode): only the Python FMU integrates Eq. (10) */
};

/* Inputs, SI units: speeds [m/s], moduli and strengths [Pa], densities [kg/m3], lengths [m].
 * The caller checks ranges (the FMU front does, against the interface's declared domain). */
typedef struct {
    double v;                                                  /* approach speed [m/s] >= 0 */
    double sphere_E, sphere_nu, sphere_Sy, sphere_rho, sphere_d;
    double plate_E, plate_nu, plate_Sy, plate_rho, plate_t;
    double plate_edge_distance; /* [m] impact point to the nearest edge; 0 or +inf: unbounded (edge monitor only) */
    int restitution_model;   /* RST_E45 or RST_E44 */
    int zener_method;        /* RST_ZENER_* */
    int plasticity;          /* RST_EFFECT_* */
    int plate_waves;         /* RST_EFFECT_* */
    double effect_tolerance; /* [1] what `auto` may neglect in e */
    double ode_rtol;         /* [1] tolerance of zener_method = 4 (unused here: rejected) */
} rst_impact_inputs;

/* Everything one impact produces (rst_impact_result): the fields of restitution.ImpactResult, same names
 * and units, generated from the package's result record at build time. */
#include "rst_impact_result.h"

/* Evaluate the model; RST_PHYSICS_OK, or an error code with every real output NaN and every flag 0. */
int rst_impact(const rst_impact_inputs *in, rst_impact_result *out);

/* Zener's (e_ze, 1 - e_ze, tau0) [1] for lambda >= 0 [1] by the `exact`, `paper_fit` or `linear`
 * method (restitution.zener.zener_solution); RST_PHYSICS_UNSUPPORTED for `ode`. */
int rst_zener_solution(double lam, int method, double *e_ze, double *deficit, double *tau0);

#ifdef __cplusplus
}
#endif
#endif
