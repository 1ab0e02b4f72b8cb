#define _POSIX_C_SOURCE 199309L
#include <dlfcn.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "fmi2FunctionTypes.h"
#include "fmi3FunctionTypes.h"
#include "precomputed_floor.h"
#include "load_symbol.h"

#define MAX_FMUS 8
#define MAX_VRS 64

/* One FMU of either FMI version: the four calls of a round trip through the version's own functions
 * (FMI 3.0: fmi3SetFloat64, fmi3DoStep with its out-arguments, fmi3GetFloat64, fmi3GetBoolean with C bool);
 * or (version 0) the precomputed C floor, the physics called directly with its terms computed once. */
typedef struct {
    const char *label;
    int version; /* 2 or 3; 0: the precomputed C floor */
    precomputed_floor_terms terms; /* version 0 */
    void *dl;
    void *c;
    fmi2SetRealTYPE *set_real;
    fmi2DoStepTYPE *do_step;
    fmi2GetRealTYPE *get_real;
    fmi2GetBooleanTYPE *get_boolean;
    fmi2FreeInstanceTYPE *free_instance;
    fmi2TerminateTYPE *terminate;
    fmi3SetFloat64TYPE *set_float64;
    fmi3DoStepTYPE *do_step3;
    fmi3GetFloat64TYPE *get_float64;
    fmi3GetBooleanTYPE *get_boolean3;
    fmi3FreeInstanceTYPE *free_instance3;
    fmi3TerminateTYPE *terminate3;
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

static void logger3(fmi3InstanceEnvironment env, fmi3Status status, fmi3String category, fmi3String message)
{
    if (status != fmi3OK)
        fprintf(stderr, "LOG %s %d %s: %s\n", env ? (const char *)env : "?", (int)status, category ? category : "",
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

static fmi2ValueReference vr_v, vr_reals[MAX_VRS], vr_bools[MAX_VRS];
static size_t n_reals, n_bools;
static double sink;

#define SET 1
#define STEP 2
#define GET_REAL 4
#define GET_BOOLEAN 8
#define ROUND_TRIP (SET | STEP | GET_REAL | GET_BOOLEAN)
static const char *const CALL_NAMES[] = {"fmi2SetReal", "fmi2DoStep", "fmi2GetReal", "fmi2GetBoolean"};

/* n FMI 3.0 round trips made of the `calls`; the status of every call OR-ed together (0: every call
 * returned fmi3OK) */
static int round_trips3(fmu *f, int calls, long n)
{
    fmi3Float64 reals[MAX_VRS];
    fmi3Boolean bools[MAX_VRS];
    fmi3Boolean event, terminate, early;
    fmi3Float64 last;
    const fmi3Float64 h = 1e-3;
    int bad = 0;
    long i;
    reals[0] = 0.0, bools[0] = fmi3False;
    for (i = 0; i < n; i++) {
        fmi3Float64 v = 0.1 + 1e-6 * (double)(f->k++ % 1000000);
        if (calls & SET)
            bad |= (int)f->set_float64(f->c, &vr_v, 1, &v, 1);
        if (calls & STEP) {
            bad |= (int)f->do_step3(f->c, f->t, h, fmi3True, &event, &terminate, &early, &last);
            f->t += h;
        }
        if (calls & GET_REAL)
            bad |= (int)f->get_float64(f->c, vr_reals, n_reals, reals, n_reals);
        if (calls & GET_BOOLEAN)
            bad |= (int)f->get_boolean3(f->c, vr_bools, n_bools, bools, n_bools);
        sink += reals[0] + (double)bools[0];
    }
    return bad;
}

/* n impacts of the precomputed C floor at the round trips' speeds: e and v_rebound, nothing else */
static int round_trips0(fmu *f, long n)
{
    long i;
    for (i = 0; i < n; i++) {
        double v_rebound, e = precomputed_floor_impact(&f->terms, 0.1 + 1e-6 * (double)(f->k++ % 1000000), &v_rebound);
        sink += e + v_rebound;
    }
    return 0;
}

/* n round trips made of the `calls` (ROUND_TRIP: all four; with no Boolean outputs asked for, no
 * GetBoolean); the status of every call OR-ed together (0: every call returned fmi2OK) */
static int round_trips(fmu *f, int calls, long n)
{
    if (n_bools == 0)
        calls &= ~GET_BOOLEAN;
    if (f->version == 0)
        return round_trips0(f, n);
    if (f->version == 3)
        return round_trips3(f, calls, n);
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

/* Round trips in chunks of CHUNK until `seconds` of CPU time have passed; seconds per round trip. A chunk
 * is long enough that reading the thread's CPU clock (a system call, some hundred ns) adds below 1 ns to a
 * round trip of the native FMU or the precomputed floor. */
#define CHUNK 1024
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

/* Open, instantiate and initialise an FMI 2.0 FMU; 0 on success. */
static int open2(fmu *f, const char *resource_uri, const char *guid)
{
    static fmi2CallbackFunctions callbacks = {logger, calloc, free, NULL, NULL};
    fmi2InstantiateTYPE *instantiate;
    fmi2SetupExperimentTYPE *setup;
    fmi2EnterInitializationModeTYPE *enter_init;
    fmi2ExitInitializationModeTYPE *exit_init;
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
    f->c = instantiate(f->label, fmi2CoSimulation, guid, resource_uri, &callbacks, fmi2False, fmi2False);
    if (f->c == NULL) {
        fprintf(stderr, "%s: fmi2Instantiate returned NULL\n", f->label);
        return 1;
    }
    return setup(f->c, fmi2False, 0.0, 0.0, fmi2False, 0.0) != fmi2OK || enter_init(f->c) != fmi2OK
           || exit_init(f->c) != fmi2OK;
}

/* Open, instantiate and initialise an FMI 3.0 FMU (resource path: a native directory path); 0 on success. */
static int open3(fmu *f, const char *resource_path, const char *token)
{
    fmi3InstantiateCoSimulationTYPE *instantiate;
    fmi3EnterInitializationModeTYPE *enter_init;
    fmi3ExitInitializationModeTYPE *exit_init;
    LOAD(instantiate, "fmi3InstantiateCoSimulation");
    LOAD(enter_init, "fmi3EnterInitializationMode");
    LOAD(exit_init, "fmi3ExitInitializationMode");
    LOAD(f->set_float64, "fmi3SetFloat64");
    LOAD(f->do_step3, "fmi3DoStep");
    LOAD(f->get_float64, "fmi3GetFloat64");
    LOAD(f->get_boolean3, "fmi3GetBoolean");
    LOAD(f->terminate3, "fmi3Terminate");
    LOAD(f->free_instance3, "fmi3FreeInstance");
    f->c = instantiate(f->label, token, resource_path, fmi3False, fmi3False, fmi3False, fmi3False, NULL, 0,
                       (fmi3InstanceEnvironment)f->label, logger3, NULL);
    if (f->c == NULL) {
        fprintf(stderr, "%s: fmi3InstantiateCoSimulation returned NULL\n", f->label);
        return 1;
    }
    return enter_init(f->c, fmi3False, 0.0, 0.0, fmi3False, 0.0) != fmi3OK || exit_init(f->c) != fmi3OK;
}

#define PER_FMU 5 /* LABEL FMI_VERSION BINARY RESOURCES GUID (version 0: the precomputed C floor, the rest "-") */
int main(int argc, char **argv)
{
    fmu fmus[MAX_FMUS];
    double batch;
    long reps, r;
    int m = 0, i, each;
    if (argc < 7 + PER_FMU || (argc - 7) % PER_FMU != 0 || (argc - 7) / PER_FMU > MAX_FMUS
            || (strcmp(argv[1], "round_trip") != 0 && strcmp(argv[1], "each_call") != 0)) {
        fprintf(stderr, "usage: %s round_trip|each_call BATCH_SECONDS REPS VR_V REAL_VRS BOOL_VRS "
                "{LABEL 2|3 BINARY RESOURCE_URI|RESOURCE_PATH GUID|TOKEN | LABEL 0 - - -}...\n", argv[0]);
        return 1;
    }
    each = strcmp(argv[1], "each_call") == 0;
    batch = atof(argv[2]);
    reps = atol(argv[3]);
    vr_v = (fmi2ValueReference)strtoul(argv[4], NULL, 10);
    n_reals = parse_vrs(argv[5], vr_reals);
    n_bools = parse_vrs(argv[6], vr_bools);
    for (i = 7; i + PER_FMU - 1 < argc; i += PER_FMU, m++) {
        fmu *f = &fmus[m];
        memset(f, 0, sizeof *f);
        f->label = argv[i];
        f->version = atoi(argv[i + 1]);
        if (f->version == 0) {
            if (precomputed_floor_open(&f->terms) != 0) {
                fprintf(stderr, "%s: the precomputed C floor cannot evaluate the start values\n", f->label);
                return 3;
            }
            continue;
        }
        if (f->version != 2 && f->version != 3) {
            fprintf(stderr, "%s: FMI version %s is not 0, 2 or 3\n", f->label, argv[i + 1]);
            return 1;
        }
        f->dl = dlopen(argv[i + 2], RTLD_NOW | RTLD_LOCAL);
        if (f->dl == NULL) {
            fprintf(stderr, "%s: dlopen failed: %s\n", f->label, dlerror());
            return 2;
        }
        if ((f->version == 2 ? open2 : open3)(f, argv[i + 3], argv[i + 4])) {
            fprintf(stderr, "%s: instantiation or initialisation failed\n", f->label);
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
        if (fmus[i].version == 0)
            continue;
        if (fmus[i].version == 3) {
            fmus[i].terminate3(fmus[i].c);
            fmus[i].free_instance3(fmus[i].c);
        } else {
            fmus[i].terminate(fmus[i].c);
            fmus[i].free_instance(fmus[i].c);
        }
    }
    fprintf(stderr, "checksum %g\n", sink);
    return 0;
}
