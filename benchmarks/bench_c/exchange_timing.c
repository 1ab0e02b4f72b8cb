/* What model exchange costs a host, in a plain C host: the native BouncingBall binary loaded with dlopen
 * and driven as an integrator drives it. Compiled once per FMI version (-DFMI_VERSION=2 or 3).
 *
 *   exchange_timing BINARY TOKEN RESOURCE_DIR SECONDS
 *
 * prints, per operation and in CPU seconds of this thread (CLOCK_THREAD_CPUTIME_ID: other processes on
 * a shared machine slow a batch but are not counted):
 *   rhs <s>        one right-hand-side evaluation: set time, set the states (h, v), get the derivatives
 *   indicators <s> one read of the event indicator (what a solver checks every step)
 *   event <s>      one contact: enter event mode, the discrete-state update (count, rebound), enter
 *                  continuous-time mode and read back the changed states
 * Each is run in batches of a fixed CPU time after an untimed warm-up; the median batch is printed. */
#define _POSIX_C_SOURCE 200809L
#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#if FMI_VERSION == 3
#include "fmi3Functions.h"
#else
#include "fmi2Functions.h"
#endif

#define BATCHES 7
#define N_STATES 2

static double cpu_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void *symbol(void *library, const char *name)
{
    void *f = dlsym(library, name);
    if (f == NULL) {
        fprintf(stderr, "missing %s\n", name);
        exit(2);
    }
    return f;
}

static int failed(int status, const char *what)
{
    if (status > 1) { /* worse than a warning */
        fprintf(stderr, "%s returned %d\n", what, status);
        exit(3);
    }
    return 0;
}

/* A function pointer from dlsym without the object-to-function pointer cast ISO C forbids. */
#define LOAD(target, name)                 \
    do {                                   \
        void *p_ = symbol(library, name);  \
        memcpy(&(target), &p_, sizeof p_); \
    } while (0)

/* The version's calls, each behind a wrapper of one signature: the host below is version-neutral. */
#if FMI_VERSION == 3
static struct {
    fmi3SetTimeTYPE *set_time;
    fmi3SetContinuousStatesTYPE *set_states;
    fmi3GetContinuousStatesTYPE *get_states;
    fmi3GetContinuousStateDerivativesTYPE *get_derivatives;
    fmi3GetEventIndicatorsTYPE *get_indicators;
    fmi3EnterEventModeTYPE *enter_event_mode;
    fmi3UpdateDiscreteStatesTYPE *update;
    fmi3EnterContinuousTimeModeTYPE *enter_continuous;
} api;

static int update(void *c, int *changed)
{
    fmi3Boolean need, terminate, nominals, values, next_defined;
    fmi3Float64 next;
    int status = (int)api.update(c, &need, &terminate, &nominals, &values, &next_defined, &next);
    *changed = values;
    return status;
}

static void logger(fmi3InstanceEnvironment env, fmi3Status status, fmi3String category, fmi3String message)
{
    (void)env, (void)category;
    if (status > fmi3Warning)
        fprintf(stderr, "%s\n", message);
}

static void *open_instance(void *library, const char *token, const char *resources)
{
    fmi3InstantiateModelExchangeTYPE *instantiate;
    fmi3EnterInitializationModeTYPE *enter;
    fmi3ExitInitializationModeTYPE *leave;
    void *c;
    int changed;
    LOAD(instantiate, "fmi3InstantiateModelExchange");
    LOAD(enter, "fmi3EnterInitializationMode");
    LOAD(leave, "fmi3ExitInitializationMode");
    LOAD(api.set_time, "fmi3SetTime");
    LOAD(api.set_states, "fmi3SetContinuousStates");
    LOAD(api.get_states, "fmi3GetContinuousStates");
    LOAD(api.get_derivatives, "fmi3GetContinuousStateDerivatives");
    LOAD(api.get_indicators, "fmi3GetEventIndicators");
    LOAD(api.enter_event_mode, "fmi3EnterEventMode");
    LOAD(api.update, "fmi3UpdateDiscreteStates");
    LOAD(api.enter_continuous, "fmi3EnterContinuousTimeMode");
    c = instantiate("timing", token, resources, fmi3False, fmi3False, NULL, logger);
    if (c == NULL)
        exit(4);
    failed((int)enter(c, fmi3False, 0.0, 0.0, fmi3False, 0.0), "enter initialization");
    failed((int)leave(c), "exit initialization");
    failed(update(c, &changed), "update");
    return c;
}
#else
static struct {
    fmi2SetTimeTYPE *set_time;
    fmi2SetContinuousStatesTYPE *set_states;
    fmi2GetContinuousStatesTYPE *get_states;
    fmi2GetDerivativesTYPE *get_derivatives;
    fmi2GetEventIndicatorsTYPE *get_indicators;
    fmi2EnterEventModeTYPE *enter_event_mode;
    fmi2NewDiscreteStatesTYPE *update;
    fmi2EnterContinuousTimeModeTYPE *enter_continuous;
} api;

static int update(void *c, int *changed)
{
    fmi2EventInfo info;
    int status = (int)api.update(c, &info);
    *changed = info.valuesOfContinuousStatesChanged;
    return status;
}

static void logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status, fmi2String category,
                   fmi2String message, ...)
{
    (void)env, (void)name, (void)category;
    if (status > fmi2Warning)
        fprintf(stderr, "%s\n", message);
}

static void *open_instance(void *library, const char *token, const char *resources)
{
    static const fmi2CallbackFunctions callbacks = {logger, calloc, free, NULL, NULL};
    fmi2InstantiateTYPE *instantiate;
    fmi2SetupExperimentTYPE *setup;
    fmi2EnterInitializationModeTYPE *enter;
    fmi2ExitInitializationModeTYPE *leave;
    char uri[4096];
    void *c;
    int changed;
    LOAD(instantiate, "fmi2Instantiate");
    LOAD(setup, "fmi2SetupExperiment");
    LOAD(enter, "fmi2EnterInitializationMode");
    LOAD(leave, "fmi2ExitInitializationMode");
    LOAD(api.set_time, "fmi2SetTime");
    LOAD(api.set_states, "fmi2SetContinuousStates");
    LOAD(api.get_states, "fmi2GetContinuousStates");
    LOAD(api.get_derivatives, "fmi2GetDerivatives");
    LOAD(api.get_indicators, "fmi2GetEventIndicators");
    LOAD(api.enter_event_mode, "fmi2EnterEventMode");
    LOAD(api.update, "fmi2NewDiscreteStates");
    LOAD(api.enter_continuous, "fmi2EnterContinuousTimeMode");
    snprintf(uri, sizeof uri, "file://%s", resources);
    c = instantiate("timing", fmi2ModelExchange, token, uri, &callbacks, fmi2False, fmi2False);
    if (c == NULL)
        exit(4);
    failed((int)setup(c, fmi2False, 0.0, 0.0, fmi2False, 0.0), "setup");
    failed((int)enter(c), "enter initialization");
    failed((int)leave(c), "exit initialization");
    failed(update(c, &changed), "update");
    return c;
}
#endif

enum { RHS, INDICATORS, EVENT };

/* One operation of `kind` on instance `c`; `k` varies the state so that no call sees the same input
 * twice in a row. */
static void operate(void *c, int kind, long k, double *sink)
{
    double x[N_STATES], dx[N_STATES], z[1];
    int changed = 0;
    double t = 1e-6 * (double)(k & 1023);
    if (kind == EVENT) {
        x[0] = -1e-9; /* just through the plate, moving down: a contact and a rebound every time */
        x[1] = -2.0 - 1e-3 * (double)(k & 15);
        failed((int)api.set_states(c, x, N_STATES), "set states");
        failed((int)api.enter_event_mode(c), "enter event mode");
        failed(update(c, &changed), "update");
        failed((int)api.enter_continuous(c), "enter continuous-time mode");
        failed((int)api.get_states(c, x, N_STATES), "get states");
        *sink += x[1] + changed;
        return;
    }
    if (kind == INDICATORS) { /* the read alone, at the state the last evaluation set */
        failed((int)api.get_indicators(c, z, 1), "indicators");
        *sink += z[0];
        return;
    }
    x[0] = 0.1 + 1e-6 * (double)(k & 1023);
    x[1] = -1.0 + 1e-6 * (double)(k & 511);
    failed((int)api.set_time(c, t), "set time");
    failed((int)api.set_states(c, x, N_STATES), "set states");
    failed((int)api.get_derivatives(c, dx, N_STATES), "derivatives");
    *sink += dx[0];
}

static int by_value(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The median over BATCHES of the CPU seconds per operation, each batch running `seconds`. */
static double time_kind(void *c, int kind, double seconds, double *sink)
{
    double per[BATCHES];
    int b;
    long k = 0;
    double warm_end = cpu_seconds() + 0.1 * seconds;
    while (cpu_seconds() < warm_end)
        operate(c, kind, k++, sink);
    for (b = 0; b < BATCHES; b++) {
        long n = 0;
        double start = cpu_seconds(), now = start;
        while (now - start < seconds) {
            int i;
            for (i = 0; i < 256; i++)
                operate(c, kind, k++, sink);
            n += 256;
            now = cpu_seconds();
        }
        per[b] = (now - start) / (double)n;
    }
    qsort(per, BATCHES, sizeof per[0], by_value);
    return per[BATCHES / 2];
}

int main(int argc, char **argv)
{
    void *library, *c;
    double seconds, sink = 0.0;
    if (argc != 5) {
        fprintf(stderr, "usage: %s BINARY TOKEN RESOURCE_DIR SECONDS\n", argv[0]);
        return 2;
    }
    library = dlopen(argv[1], RTLD_NOW | RTLD_LOCAL);
    if (library == NULL) {
        fprintf(stderr, "%s\n", dlerror());
        return 2;
    }
    seconds = atof(argv[4]);
    c = open_instance(library, argv[2], argv[3]);
    failed((int)api.enter_continuous(c), "enter continuous-time mode");
    printf("rhs %.6e\n", time_kind(c, RHS, seconds, &sink));
    printf("indicators %.6e\n", time_kind(c, INDICATORS, seconds, &sink));
    printf("event %.6e\n", time_kind(c, EVENT, seconds, &sink));
    fprintf(stderr, "checksum %g\n", sink);
    return 0;
}
