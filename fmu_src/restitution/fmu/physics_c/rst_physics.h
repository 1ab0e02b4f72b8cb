/* The SpherePlateImpact model in C99 (libm only): I. Green, Nonlinear Dyn (2022), JGM Eqs. (1)-(8),
 * Zener Eqs. (9)-(13a) and (22), fusion Eqs. (17)-(20).
 *
 * A transcription of the Python package `restitution` (model.py `_terms` and `_pipeline`, jgm.py, zener.py,
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
#define rst_impact_terms_of RST_PREFIXED(rst_impact_terms_of)
#define rst_impact_with_terms RST_PREFIXED(rst_impact_with_terms)
#define rst_zener_solution RST_PREFIXED(rst_zener_solution)
#define rst_impact_primary_of RST_PREFIXED(rst_impact_primary_of)
#define rst_impact_finish RST_PREFIXED(rst_impact_finish)
#define rst_impact_edge_monitored RST_PREFIXED(rst_impact_edge_monitored)
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

/* What an impact needs that depends on the parameters only (materials, geometry, options; not on v),
 * computed once by rst_impact_terms_of so that a run of impacts at changing speeds pays only for the
 * speed-dependent work (rst_impact_with_terms). SI units. Fill it only with rst_impact_terms_of. */
typedef struct {
    int status;            /* RST_PHYSICS_OK, or the code rst_impact_with_terms returns (bad code, ode) */
    int restitution_model; /* the codes of rst_impact_inputs, as given (error messages quote them) */
    int zener_method, plasticity, plate_waves;
    double effect_tolerance; /* [1] */
    double eps_y;            /* [1] yield strain, Eq. (3) */
    double m_a;              /* [kg] sphere mass */
    double V_c;              /* [m/s] critical velocity, Eq. (6) */
    double e45_log_factor;   /* [1] ln 0.0361 - 0.114 ln eps_y: the parameter part of Eq. (8)'s log-loss */
    double e45_exponent;     /* [1] 9.5 eps_y: the exponent of (V* - 1) in Eq. (8) */
    double lambda_per_v;     /* [(s/m)^(1/5)] lambda / v^(1/5), Eq. (12) */
    double time_per_v;       /* [s (m/s)^(1/5)] T v^(1/5) = (m_a / k)^(2/5), Eq. (9) */
    double echo_time;        /* [s] 2 a / c_L, the edge echo's travel time (unused for an unbounded plate) */
    int unbounded;           /* plate_edge_distance 0 or +inf: no edge echo */
    double tau0_half_space;  /* [1] tau0 of the method at lambda = 0 (the wave delay's reference) */
    double skipped_tau0;     /* [1] tau0 reported where the plate-wave effect is skipped */
} rst_impact_terms;

/* The parameter-only terms of `in` (in->v is not read). Never fails: a bad or unsupported code is
 * recorded in terms->status. */
void rst_impact_terms_of(const rst_impact_inputs *in, rst_impact_terms *terms);

/* One impact at approach speed v [m/s] >= 0 with the terms of rst_impact_terms_of; RST_PHYSICS_OK, or
 * terms->status with every real output NaN and every flag 0. */
int rst_impact_with_terms(const rst_impact_terms *terms, double v, rst_impact_result *out);

/* One impact in two parts, for a host that reads e and v_rebound at every step and the rest seldom:
 * rst_impact_primary_of computes what e and v_rebound need (JGM's e_ep, lambda, Zener's e_ze alone),
 * rst_impact_finish the rest of the record from it. Together they are rst_impact_with_terms (which
 * calls them): the same operations, the same values. */
typedef struct {
    double v;            /* [m/s] the approach speed */
    double speed_factor; /* [(m/s)^(1/5)] v^(1/5) */
    double V_star;       /* [1] v / V_c */
    double e_ep;         /* [1] Eq. (7) or (8), after the effect mode */
    double lam;          /* [1] Eq. (12) */
    double e_ze;         /* [1] Zener's COR (1 where skipped) */
    double e;            /* [1] Eq. (20) */
    double v_rebound;    /* [m/s] e v */
    int needed;          /* Zener computed (plate_waves_used) */
    int valid;           /* lambda <= 1.5 and V* <= 1000 */
} rst_impact_primary;

/* The primary steps at v [m/s]; RST_PHYSICS_OK or terms->status (then `p` is not filled). */
int rst_impact_primary_of(const rst_impact_terms *terms, double v, rst_impact_primary *p);

/* The whole record from the primary steps; RST_PHYSICS_OK, or terms->status with every real NaN. */
int rst_impact_finish(const rst_impact_terms *terms, const rst_impact_primary *p, rst_impact_result *out);

/* Does the edge-echo monitor depend on the speed (a bounded plate)? 0: edge_echo is +inf, edge_clear 1. */
int rst_impact_edge_monitored(const rst_impact_terms *terms);

/* Evaluate the model: rst_impact_terms_of then rst_impact_with_terms at in->v; RST_PHYSICS_OK, or an
 * error code with every real output NaN and every flag 0. */
int rst_impact(const rst_impact_inputs *in, rst_impact_result *out);

/* Zener's (e_ze, 1 - e_ze, tau0) [1] for lambda >= 0 [1] by the `exact`, `paper_fit` or `linear`
 * method (restitution.zener.zener_solution); RST_PHYSICS_UNSUPPORTED for `ode`. */
int rst_zener_solution(double lam, int method, double *e_ze, double *deficit, double *tau0);

#ifdef __cplusplus
}
#endif
#endif
