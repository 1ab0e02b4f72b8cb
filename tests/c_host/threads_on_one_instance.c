/*
 * Several threads calling one FMU instance at once, the FMU compiled from its sources/ into this
 * executable (no prefix): every thread saves, restores and frees FMU states of its own, reads
 * values, serializes, and steps from the last successful time (steps of two threads may collide:
 * such a step is refused with fmi2Error, which is fine). FMI 2.0 does not ask an instance to be
 * thread-safe; the front's lock makes these instances so, and this host checks it under the
 * sanitizers. Prints DONE <worst status>; a crash or a sanitizer report is the failure.
 * Usage: threads_on_one_instance <GUID> <vr of a Real output>
 */
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>

#include "fmi2Functions.h"

#define THREADS 4
#define ROUNDS 3000

typedef struct {
    fmi2Component c;
    fmi2ValueReference vr;
    int worst; /* worst unexpected status seen by this thread */
} job;

static void logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status, fmi2String category,
                   fmi2String message, ...)
{
    (void)env, (void)name, (void)status, (void)category, (void)message; /* called by several threads */
}

static void *run(void *arg)
{
    job *j = (job *)arg;
    int k;
    for (k = 0; k < ROUNDS; k++) {
        fmi2FMUstate state = NULL;
        fmi2Real value, t;
        size_t size = 0;
        fmi2Status s = fmi2GetFMUstate(j->c, &state);
        if (s != fmi2OK)
            j->worst = s > j->worst ? s : j->worst;
        if (state != NULL) {
            if ((s = fmi2SetFMUstate(j->c, state)) != fmi2OK)
                j->worst = s > j->worst ? s : j->worst;
            if (fmi2SerializedFMUstateSize(j->c, state, &size) == fmi2OK && size > 0) {
                fmi2Byte *bytes = (fmi2Byte *)malloc(size);
                if (bytes != NULL && fmi2SerializeFMUstate(j->c, state, bytes, size) != fmi2OK)
                    j->worst = fmi2Error;
                free(bytes);
            }
            if ((s = fmi2FreeFMUstate(j->c, &state)) != fmi2OK)
                j->worst = s > j->worst ? s : j->worst;
        }
        if ((s = fmi2GetReal(j->c, &j->vr, 1, &value)) != fmi2OK)
            j->worst = s > j->worst ? s : j->worst;
        if (fmi2GetRealStatus(j->c, fmi2LastSuccessfulTime, &t) == fmi2OK)
            (void)fmi2DoStep(j->c, t, 1e-4, fmi2True); /* may collide with another thread's step */
    }
    return NULL;
}

int main(int argc, char **argv)
{
    const fmi2CallbackFunctions callbacks = {logger, calloc, free, NULL, NULL};
    pthread_t threads[THREADS];
    job jobs[THREADS];
    fmi2Component c;
    int i, worst = fmi2OK;
    if (argc != 3)
        return 2;
    c = fmi2Instantiate("shared", fmi2CoSimulation, argv[1], "", &callbacks, fmi2False, fmi2False);
    if (c == NULL || fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0) != fmi2OK ||
        fmi2EnterInitializationMode(c) != fmi2OK || fmi2ExitInitializationMode(c) != fmi2OK) {
        printf("SETUP_FAILED\n");
        return 3;
    }
    for (i = 0; i < THREADS; i++) {
        jobs[i].c = c;
        jobs[i].vr = (fmi2ValueReference)atoi(argv[2]);
        jobs[i].worst = fmi2OK;
        pthread_create(&threads[i], NULL, run, &jobs[i]);
    }
    for (i = 0; i < THREADS; i++) {
        pthread_join(threads[i], NULL);
        worst = jobs[i].worst > worst ? jobs[i].worst : worst;
    }
    fmi2FreeInstance(c);
    printf("DONE %d\n", worst);
    return 0;
}
