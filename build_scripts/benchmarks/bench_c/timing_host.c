#define _POSIX_C_SOURCE 199309L
#include <dlfcn.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "fmi2FunctionTypes.h"

#define MAX_FMUS 8
#define MAX_VRS 64

typedef struct {
    const char *label;
    void *dl;
    fmi2Component c;
    fmi2SetRealTYPE *set_real;
    fmi2DoStepTYPE *do_step;
    fmi2GetRealTYPE *get_real;
    fmi2GetBooleanTYPE *get_boolean;
    fmi2FreeInstanceTYPE *free_instance;
    fmi2TerminateTYPE *terminate;
    double t;
    long k;
} fmu;

static void logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status, fmi2String category,
                   fmi2String message, ...)
{
    (void)env;
    if (status != fmi2OK)
        fprintf(stderr, "LOG %s %d %s: %s\n", name ? name : "?", (int)status, category ? category : "",
                message ? message : "");
}

static double cpu_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static size_t parse_vrs(const char *text, fmi2ValueReference *vr)
{
    size_t n = 0;
    char *end;
    while (*text && n < MAX_VRS) {
        vr[n++] = (fmi2ValueReference)strtoul(text, &end, 10);
        text = *end == ',' ? end + 1 : end;
    }
    return n;
}

static void *symbol(fmu *f, const char *name)
{
    void *p = dlsym(f->dl, name);
    if (p == NULL) {
        fprintf(stderr, "%s: %s not found\n", f->label, name);
        exit(2);
    }
    return p;
}

/* a function pointer from dlsym without the object-to-function pointer cast ISO C forbids */
#define LOAD(target, name)                  \
    do {                                    \
        void *p_ = symbol(f, name);         \
        memcpy(&(target), &p_, sizeof p_);  \
    } while (0)

static fmi2ValueReference vr_v, vr_reals[MAX_VRS], vr_bools[MAX_VRS];
static size_t n_reals, n_bools;
static double sink;

#define SET 1
#define STEP 2
#define GET_REAL 4
#define GET_BOOLEAN 8
#define ROUND_TRIP (SET | STEP | GET_REAL | GET_BOOLEAN)
static const char *const CALL_NAMES[] = {"fmi2SetReal", "fmi2DoStep", "fmi2GetReal", "fmi2GetBoolean"};

/* n round trips made of the `calls` (ROUND_TRIP: all four); the status of every call OR-ed together
 * (0: every call returned fmi2OK) */
static int round_trips(fmu *f, int calls, long n)
{
    fmi2Real reals[MAX_VRS];
    fmi2Boolean bools[MAX_VRS];
    const fmi2Real h = 1e-3;
    int bad = 0;
    long i;
    reals[0] = 0.0, bools[0] = fmi2False;
    for (i = 0; i < n; i++) {
        fmi2Real v = 0.1 + 1e-6 * (double)(f->k++ % 1000000);
        if (calls & SET)
            bad |= (int)f->set_real(f->c, &vr_v, 1, &v);
        if (calls & STEP) {
            bad |= (int)f->do_step(f->c, f->t, h, fmi2True);
            f->t += h;
        }
        if (calls & GET_REAL)
            bad |= (int)f->get_real(f->c, vr_reals, n_reals, reals);
        if (calls & GET_BOOLEAN)
            bad |= (int)f->get_boolean(f->c, vr_bools, n_bools, bools);
        sink += reals[0] + (double)bools[0];
    }
    return bad;
}

/* Round trips in chunks of CHUNK until `seconds` of CPU time have passed; seconds per round trip. */
#define CHUNK 64
static double timed_batch(fmu *f, int calls, double seconds)
{
    double t0 = cpu_seconds(), elapsed;
    long count = 0;
    do {
        if (round_trips(f, calls, CHUNK)) {
            fprintf(stderr, "%s: a call did not return fmi2OK\n", f->label);
            exit(4);
        }
        count += CHUNK;
        elapsed = cpu_seconds() - t0;
    } while (elapsed < seconds);
    return elapsed / (double)count;
}

int main(int argc, char **argv)
{
    fmu fmus[MAX_FMUS];
    fmi2CallbackFunctions callbacks = {logger, calloc, free, NULL, NULL};
    double batch;
    long reps, r;
    int m = 0, i, each;
    if (argc < 11 || (argc - 7) % 4 != 0 || (argc - 7) / 4 > MAX_FMUS
            || (strcmp(argv[1], "round_trip") != 0 && strcmp(argv[1], "each_call") != 0)) {
        fprintf(stderr, "usage: %s round_trip|each_call BATCH_SECONDS REPS VR_V REAL_VRS BOOL_VRS "
                "{LABEL BINARY RESOURCE_URI GUID}...\n", argv[0]);
        return 1;
    }
    each = strcmp(argv[1], "each_call") == 0;
    batch = atof(argv[2]);
    reps = atol(argv[3]);
    vr_v = (fmi2ValueReference)strtoul(argv[4], NULL, 10);
    n_reals = parse_vrs(argv[5], vr_reals);
    n_bools = parse_vrs(argv[6], vr_bools);
    for (i = 7; i + 3 < argc; i += 4, m++) {
        fmu *f = &fmus[m];
        fmi2InstantiateTYPE *instantiate;
        fmi2SetupExperimentTYPE *setup;
        fmi2EnterInitializationModeTYPE *enter_init;
        fmi2ExitInitializationModeTYPE *exit_init;
        memset(f, 0, sizeof *f);
        f->label = argv[i];
        f->dl = dlopen(argv[i + 1], RTLD_NOW | RTLD_LOCAL);
        if (f->dl == NULL) {
            fprintf(stderr, "%s: dlopen failed: %s\n", f->label, dlerror());
            return 2;
        }
        LOAD(instantiate, "fmi2Instantiate");
        LOAD(setup, "fmi2SetupExperiment");
        LOAD(enter_init, "fmi2EnterInitializationMode");
        LOAD(exit_init, "fmi2ExitInitializationMode");
        LOAD(f->set_real, "fmi2SetReal");
        LOAD(f->do_step, "fmi2DoStep");
        LOAD(f->get_real, "fmi2GetReal");
        LOAD(f->get_boolean, "fmi2GetBoolean");
        LOAD(f->terminate, "fmi2Terminate");
        LOAD(f->free_instance, "fmi2FreeInstance");
        f->c = instantiate(f->label, fmi2CoSimulation, argv[i + 3], argv[i + 2], &callbacks, fmi2False, fmi2False);
        if (f->c == NULL) {
            fprintf(stderr, "%s: fmi2Instantiate returned NULL\n", f->label);
            return 3;
        }
        if (setup(f->c, fmi2False, 0.0, 0.0, fmi2False, 0.0) != fmi2OK || enter_init(f->c) != fmi2OK
                || exit_init(f->c) != fmi2OK) {
            fprintf(stderr, "%s: initialisation failed\n", f->label);
            return 3;
        }
    }
    for (r = 0; r < reps; r++)
        for (i = 0; i < m; i++) {
            fmu *f = &fmus[(i + r) % m];
            int call;
            timed_batch(f, ROUND_TRIP, 0.1 * batch); /* warm-up: caches, branch predictors */
            if (!each) {
                printf("BATCH %s %ld %.6e\n", f->label, r, timed_batch(f, ROUND_TRIP, batch));
                fflush(stdout);
                continue;
            }
            for (call = 0; call < 4; call++) {
                printf("BATCH %s/%s %ld %.6e\n", f->label, CALL_NAMES[call], r, timed_batch(f, 1 << call, batch));
                fflush(stdout);
            }
        }
    for (i = 0; i < m; i++) {
        fmus[i].terminate(fmus[i].c);
        fmus[i].free_instance(fmus[i].c);
    }
    fprintf(stderr, "checksum %g\n", sink);
    return 0;
}
