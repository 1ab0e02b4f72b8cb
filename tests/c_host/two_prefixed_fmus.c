/*
 * Two source FMUs in one executable: SpherePlateImpact and BouncingBall compiled from their
 * sources/ with FMI2_FUNCTION_PREFIX (SpherePlateImpact_ and BouncingBall_) and the standard FMI 2.0
 * headers, linked together with this file, as a simulator that embeds source FMUs does. It couples
 * them (ball.v_approach -> impact.v_approach, impact.e -> ball.e) for STEPS steps and prints
 *   BOUNCE <t> <h> <impacts> <e>   after every step with a new impact
 *   DONE <impacts> <h> <worst status>
 * Usage: two_prefixed_fmus <impact GUID> <ball GUID> <impact vr of v_approach> <impact vr of e>
 *                          <ball vr of v_approach> <ball vr of e> <ball vr of h> <ball vr of impacts>
 *                          <ball vr of contact_mode>
 */
#include <stdio.h>
#include <stdlib.h>

#include "fmi2FunctionTypes.h"

#define DECLARE(prefix)                                                                                    \
    fmi2InstantiateTYPE prefix##fmi2Instantiate;                                                           \
    fmi2FreeInstanceTYPE prefix##fmi2FreeInstance;                                                         \
    fmi2SetupExperimentTYPE prefix##fmi2SetupExperiment;                                                   \
    fmi2EnterInitializationModeTYPE prefix##fmi2EnterInitializationMode;                                   \
    fmi2ExitInitializationModeTYPE prefix##fmi2ExitInitializationMode;                                     \
    fmi2SetRealTYPE prefix##fmi2SetReal;                                                                   \
    fmi2SetIntegerTYPE prefix##fmi2SetInteger;                                                             \
    fmi2GetRealTYPE prefix##fmi2GetReal;                                                                   \
    fmi2GetIntegerTYPE prefix##fmi2GetInteger;                                                             \
    fmi2DoStepTYPE prefix##fmi2DoStep;

DECLARE(SpherePlateImpact_)
DECLARE(BouncingBall_)

#define STEPS 2000
#define STEP_SIZE 1e-3

static void logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status, fmi2String category,
                   fmi2String message, ...)
{
    (void)env;
    printf("LOG %s %d %s: %s\n", name, (int)status, category, message);
}

static int worst = fmi2OK;
static void check(fmi2Status status)
{
    if ((int)status > worst)
        worst = (int)status;
}

int main(int argc, char **argv)
{
    const fmi2CallbackFunctions callbacks = {logger, calloc, free, NULL, NULL};
    fmi2ValueReference imp_v, imp_e, ball_v, ball_e, ball_h, ball_n, ball_mode;
    fmi2Component imp, ball;
    fmi2Integer impacts = 0, last = 0, mode = 1;
    double t = 0.0, v, e, h = 0.0;
    int i;
    if (argc != 10) {
        fprintf(stderr, "usage: see the top of two_prefixed_fmus.c\n");
        return 2;
    }
    imp_v = (fmi2ValueReference)atoi(argv[3]);
    imp_e = (fmi2ValueReference)atoi(argv[4]);
    ball_v = (fmi2ValueReference)atoi(argv[5]);
    ball_e = (fmi2ValueReference)atoi(argv[6]);
    ball_h = (fmi2ValueReference)atoi(argv[7]);
    ball_n = (fmi2ValueReference)atoi(argv[8]);
    ball_mode = (fmi2ValueReference)atoi(argv[9]);
    imp = SpherePlateImpact_fmi2Instantiate("impact", fmi2CoSimulation, argv[1], "", &callbacks, fmi2False, fmi2False);
    ball = BouncingBall_fmi2Instantiate("ball", fmi2CoSimulation, argv[2], "", &callbacks, fmi2False, fmi2False);
    if (imp == NULL || ball == NULL) {
        printf("INSTANTIATE_FAILED\n");
        return 3;
    }
    check(SpherePlateImpact_fmi2SetupExperiment(imp, fmi2False, 0.0, 0.0, fmi2False, 0.0));
    check(BouncingBall_fmi2SetupExperiment(ball, fmi2False, 0.0, 0.0, fmi2False, 0.0));
    check(SpherePlateImpact_fmi2EnterInitializationMode(imp));
    check(BouncingBall_fmi2EnterInitializationMode(ball));
    check(BouncingBall_fmi2SetInteger(ball, &ball_mode, 1, &mode));
    check(SpherePlateImpact_fmi2ExitInitializationMode(imp));
    check(BouncingBall_fmi2ExitInitializationMode(ball));
    for (i = 0; i < STEPS; i++) {
        /* the master resolves the impact FMU's direct feedthrough: the COR for the current approach speed */
        check(BouncingBall_fmi2GetReal(ball, &ball_v, 1, &v));
        check(SpherePlateImpact_fmi2SetReal(imp, &imp_v, 1, &v));
        check(SpherePlateImpact_fmi2GetReal(imp, &imp_e, 1, &e));
        check(BouncingBall_fmi2SetReal(ball, &ball_e, 1, &e));
        check(SpherePlateImpact_fmi2DoStep(imp, t, STEP_SIZE, fmi2True));
        check(BouncingBall_fmi2DoStep(ball, t, STEP_SIZE, fmi2True));
        t += STEP_SIZE;
        check(BouncingBall_fmi2GetReal(ball, &ball_h, 1, &h));
        check(BouncingBall_fmi2GetInteger(ball, &ball_n, 1, &impacts));
        if (impacts != last)
            printf("BOUNCE %.17g %.17g %d %.17g\n", t, h, (int)impacts, e);
        last = impacts;
    }
    SpherePlateImpact_fmi2FreeInstance(imp);
    BouncingBall_fmi2FreeInstance(ball);
    printf("DONE %d %.17g %d\n", (int)impacts, h, worst);
    return 0;
}
