/* What a bouncing ball's FMI front costs a host: a plain C host that loads bouncing-ball FMUs (ours, FMI 2.0
 * and FMI 3.0, and the Modelica Reference FMUs' BouncingBall where its source is at hand) with dlopen and
 * times, interleaved, the two call sequences a host makes most often:
 *
 *   step  one co-simulation step: DoStep(t, 1 ms), then Get of the outputs h and v (1 ms: the Reference
 *         ball's fixed internal solver step, so that it makes one Euler step per DoStep and what is compared
 *         is mostly the two fronts; ours moves the ball in closed form)
 *   rhs   one model-exchange right-hand-side evaluation: SetTime(t), SetContinuousStates(h, v),
 *         GetDerivatives(der(h), der(v)) (the calls an ME integrator makes each time it evaluates the
 *         right-hand side)
 *   rhs+z the same, then GetEventIndicators (what a solver adds where it checks for a state event)
 *
 * The same sequence, with the same arguments, for every FMU. `step` runs whole simulations from a drop
 * (1 m, COR 0.7, g 9.81) of STEPS_PER_RUN steps, a fresh instance for each (instantiation untimed); `rhs`
 * hands the FMU a free flight's states (never at the plate) at times cycling through it.
 *
 *   ball_timing BATCH_SECONDS REPS {LABEL 2|3 BINARY RESOURCE TOKEN H_VR,V_VR SETTINGS}...
 *
 * RESOURCE: FMI 2.0 a file: URI, FMI 3.0 a directory path ending with a separator. SETTINGS: what is set
 * before initialization, `-` for nothing, else comma-separated VR=VALUE (a Real) or VR:VALUE (an Integer;
 * FMI 3.0: an Int64, for enumerations). For each repetition, each operation and each FMU in turn (the first
 * one rotating), a warm-up of BATCH_SECONDS / 10, then BATCH_SECONDS timed; prints
 *   BATCH <label> <step|rhs|rhs+z> <rep> <CPU seconds per operation>
 * in CPU time of the calling thread (CLOCK_THREAD_CPUTIME_ID: other processes on a shared machine slow a
 * batch without being counted). */
#define _POSIX_C_SOURCE 200809L
#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "fmi2FunctionTypes.h"
#include "fmi3FunctionTypes.h"
#include "load_symbol.h"

#define MAX_FMUS 4
#define MAX_SETTINGS 8
#define STEP_SIZE 1e-3
#define STEPS_PER_RUN 3000 /* 3 s: the Reference FMUs' default stop time */
#define RHS_PER_RUN 1000
#define FLIGHT 0.4        /* [s] of free fall from 1 m: the ball stays above the plate (it lands at 0.45 s) */
#define GRAVITY 9.81

typedef struct {
    const char *label;
    int version;
    void *dl;
    const char *resource, *token;
    unsigned int vr_hv[2];
    unsigned int setting_vr[MAX_SETTINGS];
    double setting_value[MAX_SETTINGS];
    int setting_integer[MAX_SETTINGS];
    int n_settings;
    /* FMI 2.0 */
    fmi2InstantiateTYPE *instantiate2;
    fmi2SetupExperimentTYPE *setup2;
    fmi2EnterInitializationModeTYPE *enter_init2;
    fmi2ExitInitializationModeTYPE *exit_init2;
    fmi2SetRealTYPE *set_real2;
    fmi2SetIntegerTYPE *set_integer2;
    fmi2GetRealTYPE *get_real2;
    fmi2DoStepTYPE *do_step2;
    fmi2NewDiscreteStatesTYPE *new_discrete_states2;
    fmi2EnterContinuousTimeModeTYPE *enter_continuous2;
    fmi2SetTimeTYPE *set_time2;
    fmi2SetContinuousStatesTYPE *set_states2;
    fmi2GetDerivativesTYPE *get_derivatives2;
    fmi2GetEventIndicatorsTYPE *get_indicators2;
    fmi2FreeInstanceTYPE *free2;
    /* FMI 3.0 */
    fmi3InstantiateCoSimulationTYPE *instantiate_cs3;
    fmi3InstantiateModelExchangeTYPE *instantiate_me3;
    fmi3EnterInitializationModeTYPE *enter_init3;
    fmi3ExitInitializationModeTYPE *exit_init3;
    fmi3SetFloat64TYPE *set_float64;
    fmi3SetInt64TYPE *set_int64;
    fmi3GetFloat64TYPE *get_float64;
    fmi3DoStepTYPE *do_step3;
    fmi3UpdateDiscreteStatesTYPE *update3;
    fmi3EnterContinuousTimeModeTYPE *enter_continuous3;
    fmi3SetTimeTYPE *set_time3;
    fmi3SetContinuousStatesTYPE *set_states3;
    fmi3GetContinuousStateDerivativesTYPE *get_derivatives3;
    fmi3GetEventIndicatorsTYPE *get_indicators3;
    fmi3FreeInstanceTYPE *free3;
} fmu;

static double sink; /* what the timed loops read, so that nothing is optimized away */

static double cpu_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void fail(const fmu *f, const char *what)
{
    fprintf(stderr, "%s: %s\n", f->label, what);
    exit(3);
}

static void logger2(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status, fmi2String category,
                    fmi2String message, ...)
{
    (void)env;
    if (status != fmi2OK)
        fprintf(stderr, "[%s] %s %d: %s\n", name, category, (int)status, message);
}

static void logger3(fmi3InstanceEnvironment env, fmi3Status status, fmi3String category, fmi3String message)
{
    if (status != fmi3OK)
        fprintf(stderr, "[%s] %s %d: %s\n", (const char *)env, category, (int)status, message);
}

static void *symbol(const fmu *f, const char *name)
{
    void *p = dlsym(f->dl, name);
    if (p == NULL)
        fail(f, name);
    return p;
}

static void load(fmu *f)
{
    if (f->version == 2) {
        LOAD(f->instantiate2, "fmi2Instantiate");
        LOAD(f->setup2, "fmi2SetupExperiment");
        LOAD(f->enter_init2, "fmi2EnterInitializationMode");
        LOAD(f->exit_init2, "fmi2ExitInitializationMode");
        LOAD(f->set_real2, "fmi2SetReal");
        LOAD(f->set_integer2, "fmi2SetInteger");
        LOAD(f->get_real2, "fmi2GetReal");
        LOAD(f->do_step2, "fmi2DoStep");
        LOAD(f->new_discrete_states2, "fmi2NewDiscreteStates");
        LOAD(f->enter_continuous2, "fmi2EnterContinuousTimeMode");
        LOAD(f->set_time2, "fmi2SetTime");
        LOAD(f->set_states2, "fmi2SetContinuousStates");
        LOAD(f->get_derivatives2, "fmi2GetDerivatives");
        LOAD(f->get_indicators2, "fmi2GetEventIndicators");
        LOAD(f->free2, "fmi2FreeInstance");
    } else {
        LOAD(f->instantiate_cs3, "fmi3InstantiateCoSimulation");
        LOAD(f->instantiate_me3, "fmi3InstantiateModelExchange");
        LOAD(f->enter_init3, "fmi3EnterInitializationMode");
        LOAD(f->exit_init3, "fmi3ExitInitializationMode");
        LOAD(f->set_float64, "fmi3SetFloat64");
        LOAD(f->set_int64, "fmi3SetInt64");
        LOAD(f->get_float64, "fmi3GetFloat64");
        LOAD(f->do_step3, "fmi3DoStep");
        LOAD(f->update3, "fmi3UpdateDiscreteStates");
        LOAD(f->enter_continuous3, "fmi3EnterContinuousTimeMode");
        LOAD(f->set_time3, "fmi3SetTime");
        LOAD(f->set_states3, "fmi3SetContinuousStates");
        LOAD(f->get_derivatives3, "fmi3GetContinuousStateDerivatives");
        LOAD(f->get_indicators3, "fmi3GetEventIndicators");
        LOAD(f->free3, "fmi3FreeInstance");
    }
}

/* An instance of `f` (co-simulation or model exchange), its settings made and initialized: in step mode,
 * or in continuous-time mode after the initial event's updates. */
static void *start(const fmu *f, int model_exchange)
{
    static const fmi2CallbackFunctions callbacks = {logger2, calloc, free, NULL, NULL};
    void *c;
    int i, bad = 0;
    if (f->version == 2)
        c = f->instantiate2(f->label, model_exchange ? fmi2ModelExchange : fmi2CoSimulation, f->token, f->resource,
                            &callbacks, fmi2False, fmi2False);
    else if (model_exchange)
        c = f->instantiate_me3(f->label, f->token, f->resource, fmi3False, fmi3False, (void *)f->label, logger3);
    else
        c = f->instantiate_cs3(f->label, f->token, f->resource, fmi3False, fmi3False, fmi3False, fmi3False, NULL, 0,
                               (void *)f->label, logger3, NULL);
    if (c == NULL)
        fail(f, "instantiation returned NULL");
    for (i = 0; i < f->n_settings; i++) {
        const fmi2ValueReference vr = f->setting_vr[i];
        if (f->version == 2 && f->setting_integer[i]) {
            fmi2Integer x = (fmi2Integer)f->setting_value[i];
            bad |= f->set_integer2(c, &vr, 1, &x);
        } else if (f->version == 2) {
            bad |= f->set_real2(c, &vr, 1, &f->setting_value[i]);
        } else if (f->setting_integer[i]) {
            fmi3Int64 x = (fmi3Int64)f->setting_value[i];
            bad |= f->set_int64(c, &vr, 1, &x, 1);
        } else {
            bad |= f->set_float64(c, &vr, 1, &f->setting_value[i], 1);
        }
    }
    if (f->version == 2)
        bad |= f->setup2(c, fmi2False, 0.0, 0.0, fmi2False, 0.0) | f->enter_init2(c) | f->exit_init2(c);
    else
        bad |= f->enter_init3(c, fmi3False, 0.0, 0.0, fmi3False, 0.0) | f->exit_init3(c);
    if (model_exchange) {
        int more = 1, rounds = 0;
        while (more && rounds++ < 100) {
            if (f->version == 2) {
                fmi2EventInfo info;
                bad |= f->new_discrete_states2(c, &info);
                more = info.newDiscreteStatesNeeded;
            } else {
                fmi3Boolean need, terminate, nominals, values, defined;
                fmi3Float64 next;
                bad |= f->update3(c, &need, &terminate, &nominals, &values, &defined, &next);
                more = need;
            }
        }
        bad |= f->version == 2 ? f->enter_continuous2(c) : f->enter_continuous3(c);
    }
    if (bad)
        fail(f, "a call of the set-up did not return OK");
    return c;
}

static void stop(const fmu *f, void *c)
{
    if (f->version == 2)
        f->free2(c);
    else
        f->free3(c);
}

/* One simulation of STEPS_PER_RUN steps; the CPU seconds of the steps alone. */
static double step_run(const fmu *f)
{
    void *c = start(f, 0);
    double hv[2] = {0.0, 0.0}, t = 0.0, t0, elapsed;
    int i, bad = 0;
    fmi3Boolean event, terminate, early;
    fmi3Float64 last;
    t0 = cpu_seconds();
    if (f->version == 2)
        for (i = 0; i < STEPS_PER_RUN; i++, t += STEP_SIZE) {
            bad |= f->do_step2(c, t, STEP_SIZE, fmi2True);
            bad |= f->get_real2(c, f->vr_hv, 2, hv);
            sink += hv[0] + hv[1];
        }
    else
        for (i = 0; i < STEPS_PER_RUN; i++, t += STEP_SIZE) {
            bad |= f->do_step3(c, t, STEP_SIZE, fmi3True, &event, &terminate, &early, &last);
            bad |= f->get_float64(c, f->vr_hv, 2, hv, 2);
            sink += hv[0] + hv[1];
        }
    elapsed = cpu_seconds() - t0;
    stop(f, c);
    if (bad)
        fail(f, "a step did not return OK");
    return elapsed;
}

/* RHS_PER_RUN right-hand-side evaluations along a free fall from 1 m, each with the event indicator where
 * `indicators`; the CPU seconds they took. */
static double rhs_run(const fmu *f, void *c, int indicators)
{
    double x[2], dx[2], z[1] = {0.0}, t0, elapsed;
    int i, bad = 0;
    t0 = cpu_seconds();
    for (i = 0; i < RHS_PER_RUN; i++) {
        double t = FLIGHT * (double)i / RHS_PER_RUN;
        x[0] = 1.0 - 0.5 * GRAVITY * t * t;
        x[1] = -GRAVITY * t;
        if (f->version == 2) {
            bad |= f->set_time2(c, t);
            bad |= f->set_states2(c, x, 2);
            bad |= f->get_derivatives2(c, dx, 2);
            if (indicators)
                bad |= f->get_indicators2(c, z, 1);
        } else {
            bad |= f->set_time3(c, t);
            bad |= f->set_states3(c, x, 2);
            bad |= f->get_derivatives3(c, dx, 2);
            if (indicators)
                bad |= f->get_indicators3(c, z, 1);
        }
        sink += dx[0] + dx[1] + z[0];
    }
    elapsed = cpu_seconds() - t0;
    if (bad)
        fail(f, "a right-hand-side call did not return OK");
    return elapsed;
}

/* Runs of operation `op` (0: step, 1: rhs, 2: rhs+z) until `seconds` of CPU time were timed; seconds per
 * operation. */
static double batch(const fmu *f, int op, double seconds)
{
    double timed = 0.0;
    long count = 0;
    int rhs = op > 0;
    void *c = rhs ? start(f, 1) : NULL;
    do {
        timed += rhs ? rhs_run(f, c, op == 2) : step_run(f);
        count += rhs ? RHS_PER_RUN : STEPS_PER_RUN;
    } while (timed < seconds);
    if (c != NULL)
        stop(f, c);
    return timed / (double)count;
}

static void parse_settings(fmu *f, const char *text)
{
    const char *p = text;
    if (strcmp(text, "-") == 0)
        return;
    while (*p) {
        char *end;
        if (f->n_settings == MAX_SETTINGS)
            fail(f, "too many settings");
        f->setting_vr[f->n_settings] = (unsigned int)strtoul(p, &end, 10);
        if (*end != '=' && *end != ':')
            fail(f, "a setting is not VR=VALUE or VR:VALUE");
        f->setting_integer[f->n_settings] = *end == ':';
        f->setting_value[f->n_settings] = strtod(end + 1, &end);
        f->n_settings++;
        p = *end == ',' ? end + 1 : end;
        if (*end != ',' && *end != '\0')
            fail(f, "settings are separated by commas");
    }
}

#define PER_FMU 7 /* LABEL FMI_VERSION BINARY RESOURCE TOKEN H_VR,V_VR SETTINGS */
int main(int argc, char **argv)
{
    static const char *const OPERATIONS[] = {"step", "rhs", "rhs+z"};
    fmu fmus[MAX_FMUS];
    double seconds;
    long reps, r;
    int m = 0, i, op;
    if (argc < 3 + PER_FMU || (argc - 3) % PER_FMU != 0 || (argc - 3) / PER_FMU > MAX_FMUS) {
        fprintf(stderr, "usage: %s BATCH_SECONDS REPS {LABEL 2|3 BINARY RESOURCE TOKEN H_VR,V_VR SETTINGS}...\n",
                argv[0]);
        return 1;
    }
    seconds = atof(argv[1]);
    reps = atol(argv[2]);
    for (i = 3; i + PER_FMU - 1 < argc; i += PER_FMU, m++) {
        fmu *f = &fmus[m];
        char *end;
        memset(f, 0, sizeof *f);
        f->label = argv[i];
        f->version = atoi(argv[i + 1]);
        if (f->version != 2 && f->version != 3)
            fail(f, "the FMI version is not 2 or 3");
        f->dl = dlopen(argv[i + 2], RTLD_NOW | RTLD_LOCAL);
        if (f->dl == NULL)
            fail(f, dlerror());
        f->resource = argv[i + 3];
        f->token = argv[i + 4];
        f->vr_hv[0] = (unsigned int)strtoul(argv[i + 5], &end, 10);
        if (*end != ',')
            fail(f, "H_VR,V_VR");
        f->vr_hv[1] = (unsigned int)strtoul(end + 1, NULL, 10);
        parse_settings(f, argv[i + 6]);
        load(f);
    }
    for (r = 0; r < reps; r++)
        for (op = 0; op < 3; op++)
            for (i = 0; i < m; i++) {
                const fmu *f = &fmus[(i + r) % m];
                batch(f, op, 0.1 * seconds); /* warm-up: caches, branch predictors */
                printf("BATCH %s %s %ld %.6e\n", f->label, OPERATIONS[op], r, batch(f, op, seconds));
                fflush(stdout);
            }
    fprintf(stderr, "checksum %g\n", sink);
    return 0;
}
