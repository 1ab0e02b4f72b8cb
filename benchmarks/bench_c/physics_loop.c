#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "rst_physics.h"

static double cpu_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static rst_impact_inputs in;
static double sink;
static long k;

static double timed(double seconds)
{
    rst_impact_result out;
    double t0 = cpu_seconds(), elapsed;
    long count = 0, i;
    do {
        for (i = 0; i < 1024; i++) {
            in.v = 0.1 + 1e-6 * (double)(k++ % 1000000);
            if (rst_impact(&in, &out) != 0)
                exit(3);
            sink += out.e + out.t_contact;
        }
        count += 1024;
        elapsed = cpu_seconds() - t0;
    } while (elapsed < seconds);
    return elapsed / (double)count;
}

int main(int argc, char **argv)
{
    double seconds;
    if (argc != 3)
        return 2;
    seconds = atof(argv[1]);
    in.v = 1.0;
    in.sphere_E = 207e9, in.sphere_nu = 0.30, in.sphere_Sy = 2.0e9, in.sphere_rho = 7861.0, in.sphere_d = 6.35e-3;
    in.plate_E = 69e9, in.plate_nu = 0.33, in.plate_Sy = 0.290e9, in.plate_rho = 2700.0, in.plate_t = 6.35e-3;
    in.restitution_model = 1, in.plasticity = 2, in.plate_waves = 2;
    in.effect_tolerance = 1e-6, in.ode_rtol = 1e-10;
    in.zener_method = atoi(argv[2]);
    timed(0.1 * seconds);
    printf("%.6e %g\n", timed(seconds), sink);
    return 0;
}
