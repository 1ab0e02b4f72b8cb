/* The precomputed C floor (benchmarks/bench_native_build.py): what one impact costs with no
 * FMI at all and the least work the physics allows: the parameter-only terms computed once
 * (rst_impact_terms_of), the speed-dependent work per impact (rst_impact_with_terms). The timing host runs
 * it as one of its variants, batches interleaved with the FMUs'. */
#ifndef PRECOMPUTED_FLOOR_H
#define PRECOMPUTED_FLOOR_H

#include "rst_physics.h"

/* The terms of the native FMU's start values (S2 tool steel on Al 6061, `exact`, the interface table's
 * start values); 0 on success. */
int precomputed_floor_open(rst_impact_terms *terms);

/* One impact at v [m/s]: e [1], and v_rebound [m/s] in *v_rebound. */
double precomputed_floor_impact(const rst_impact_terms *terms, double v, double *v_rebound);

#endif
