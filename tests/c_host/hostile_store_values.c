/*
 * The native backends' own defence against hostile store values (the front rejects such values before
 * they get there): NaN, infinities, huge, zero, subnormal, fractional and negative values, one at a time
 * in every slot of SpherePlateImpact's store but the outputs (rst_impact_evaluate) and in every slot of
 * BouncingBall's but the outputs and locals (rst_ball_initialize, then 200 rst_ball_do_step calls).
 * tests/fmu/test_native_backend.py compiles it with the generated backends (rst_native_impact.c,
 * rst_native_ball.c), their interface headers and rst_physics.c under ASan + UBSan (any report aborts) and
 * runs it as a child process: no undefined behaviour, no hang, no crash; it prints "done 0" when through.
 */
#include <math.h>
#include <stdio.h>
#include "rst_native_impact.h"
#include "rst_native_ball.h"
#include "rst_SpherePlateImpact_interface.h"
#undef RST_MODEL_N_VARIABLES /* the generic names of the table, which a model's glue uses: here both models */
#undef RST_MODEL_VARIABLES
#undef RST_MODEL_N_STATES
#undef RST_MODEL_N_EVENT_INDICATORS
#undef RST_MODEL_STATE_VRS
#undef RST_MODEL_DERIVATIVE_VRS
#undef RST_MODEL_EVENT_INDICATOR_VRS
#include "rst_BouncingBall_interface.h"
int main(void)
{
    static const double bad[] = {NAN, INFINITY, -INFINITY, 1e300, -1e300, 0.0, -0.0, 4.9e-324, 2.5, -1.0, 5.0};
    char message[256];
    double store[64], t = 0.0;
    size_t slot, k, i;
    int failures = 0;
    for (slot = 0; slot < RST_SPHEREPLATEIMPACT_N_VARIABLES; slot++) {
        if (RST_SPHEREPLATEIMPACT_VARIABLES[slot].causality == RST_OUTPUT)
            continue;
        for (k = 0; k < sizeof bad / sizeof bad[0]; k++) {
            for (i = 0; i < RST_SPHEREPLATEIMPACT_N_VARIABLES; i++)
                store[i] = 1.0;
            store[slot] = bad[k];
            (void)rst_impact_evaluate(store, message, sizeof message);
        }
    }
    for (slot = 0; slot < RST_BOUNCINGBALL_N_VARIABLES; slot++) {
        if (RST_BOUNCINGBALL_VARIABLES[slot].causality == RST_OUTPUT
            || RST_BOUNCINGBALL_VARIABLES[slot].causality == RST_LOCAL)
            continue;
        for (k = 0; k < sizeof bad / sizeof bad[0]; k++) {
            for (i = 0; i < RST_BOUNCINGBALL_N_VARIABLES; i++)
                store[i] = 0.0;
            store[RST_BOUNCINGBALL_VR_H0] = 0.3;
            store[RST_BOUNCINGBALL_VR_G] = 9.81;
            store[RST_BOUNCINGBALL_VR_V_MIN] = 0.1;
            store[RST_BOUNCINGBALL_VR_CONTACT_MODE] = RST_BOUNCINGBALL_CONTACT_MODE_IMMEDIATE;
            store[RST_BOUNCINGBALL_VR_E] = 0.8;
            store[slot] = bad[k];
            rst_ball_initialize(store, 0.0);
            for (t = 0.0, i = 0; i < 200; i++, t += 0.01)
                rst_ball_do_step(store, t, 0.01);
        }
    }
    printf("done %d\n", failures);
    return 0;
}
