/* The precomputed C floor (benchmarks/bench_native_build.py): the least C that computes e and
 * v_rebound of one impact, with no FMI: JGM's Eq. (8) (e45), lambda by Eq. (12), Zener's COR by the paper's
 * fit, Eq. (13), the apparent COR by Eq. (20); every term that depends on the parameters alone (Eqs. 1-6,
 * the speed-free factor of Eq. 12) computed once by precomputed_floor_open, so that an impact costs one
 * logarithm of v, one of V* - 1 and three exponentials. Written here from the paper (not the project's
 * physics, which computes every output). The timing host runs it as one of its variants, batches
 * interleaved with the FMUs'. */
#ifndef PRECOMPUTED_FLOOR_H
#define PRECOMPUTED_FLOOR_H

/* The parameter-only terms. */
typedef struct {
    double log_V_c;       /* ln V_c, V_c [m/s] of Eq. (6) */
    double inv_V_c;       /* 1 / V_c [s/m] */
    double loss_factor;   /* 0.0361 eps_y^-0.114 [1], Eq. (8) */
    double loss_exponent; /* 9.5 eps_y [1], Eq. (8) */
    double zener_rate;    /* -1.68374 lambda / v^(1/5) [(s/m)^(1/5)], Eqs. (12), (13) */
} precomputed_floor_terms;

/* The terms of the native FMU's start values (S2 tool steel on Al 6061, the interface table's start
 * values); 0 on success (1: the start values select a preset material, which this floor does not read). */
int precomputed_floor_open(precomputed_floor_terms *terms);

/* One impact at v [m/s] > 0: e [1], and v_rebound [m/s] in *v_rebound. */
double precomputed_floor_impact(const precomputed_floor_terms *terms, double v, double *v_rebound);

#endif
