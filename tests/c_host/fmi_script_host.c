/*
 * Scriptable FMI host in plain C, for FMI 2.0 and FMI 3.0, co-simulation and model exchange: drives
 * several instances of one FMU through a script read from stdin, the way C/C++ simulation tools call an
 * FMU. One program, one script language, for both versions: -DFMI_VERSION=3 selects the FMI 3.0 calls
 * (default 2), and only the thin wrappers of the calls that differ between the versions (instantiation,
 * the experiment, get/set by type, fmi3DoStep's out-arguments, FMU states, String calls, the logger,
 * the discrete-state update and the completed integrator step) are written twice.
 * It builds for Linux (gcc; dlopen(RTLD_LAZY | RTLD_LOCAL) of binaries/linux64/<id>.so, FMI 3.0:
 * binaries/x86_64-linux/<id>.so) and for Windows (x86_64-w64-mingw32-gcc; LoadLibrary of
 * binaries/win64/<id>.dll, FMI 3.0: binaries/x86_64-windows/<id>.dll); the process knows nothing
 * about Python.
 *
 * Usage:  fmi_script_host <unpacked_fmu_dir> <modelIdentifier> <guid | instantiationToken> < script
 * (on Windows the directory is a Windows path, e.g. Z:\tmp\fmu under Wine). FMI 2.0: the host passes
 * fmi2Instantiate the file: URI of <dir>/resources, percent-encoded as RFC 3986 asks. FMI 3.0: it passes
 * fmi3InstantiateCoSimulation the native path of <dir>/resources with a trailing separator.
 *
 * Script: one command per line (S is an instance slot, numbered from 0 in the order of
 * "instantiate"; values are parsed with strtod, so nan and inf are accepted; # starts a comment):
 *   instantiate NAME          fmi2Instantiate (co-simulation, loggingOn) | fmi3InstantiateCoSimulation
 *                             (loggingOn, no event mode, no early return, no intermediate variables)
 *   setup S T0                FMI 2.0: fmi2SetupExperiment(S, no tolerance, T0, no stop time). FMI 3.0 has
 *                             no such call: T0 is kept for the next enter_init (prints RECORDED, no STATUS)
 *   enter_init S              fmi2EnterInitializationMode | fmi3EnterInitializationMode(no tolerance, T0
 *                             of the last setup (default 0), no stop time)
 *   exit_init S | terminate S | reset S | free S
 *   set_real S VR VALUE       fmi2SetReal | fmi3SetFloat64       get_real S VR...
 *   set_integer S VR VALUE    fmi2SetInteger | fmi3SetInt32      get_integer S VR...
 *   set_enumeration S VR V    fmi2SetInteger | fmi3SetInt64 (FMI 3.0 sets Enumerations with Int64)
 *                                                                get_enumeration S VR...
 *   set_boolean S VR 0|1      fmi2SetBoolean | fmi3SetBoolean    get_boolean S VR...
 *   step S T H                fmi2DoStep | fmi3DoStep(S, T, H, noSetFMUStatePriorToCurrentPoint = true);
 *                             FMI 3.0 also prints STEPPED (the out-arguments) when the step is not refused
 *   get_state S | set_state S | free_state S                (one stored state per slot)
 *   serialize S | deserialize S [FROM]   via the slot's byte buffer (size, serialize; deserialize
 *                             the bytes of slot FROM, default S, into slot S's state)
 *   deserialize_file S PATH   deserialize the bytes of a file (hostile states)
 *   set_foreign_state S       set a state with a pointer that is no state of the FMU's
 *   instantiate_bad KIND      instantiate with one bad argument; prints BAD_INSTANCE <KIND> <NULL|NONNULL>
 *                             (a non-NULL one is freed). FMI 2.0 kinds: null_name, empty_name,
 *                             wrong_guid, null_guid, null_callbacks, null_logger, null_alloc,
 *                             model_exchange, bad_uri. FMI 3.0 kinds: null_name, empty_name, wrong_guid,
 *                             null_guid, wrong_guid_no_logger, event_mode, intermediate_update,
 *                             model_exchange, scheduled_execution. A kind of the other version is a
 *                             script error.
 *   get_string S VR | set_string S VR      String calls (these FMUs have no String variable)
 * Model exchange (each is one FMI call, STATUS as above, but integrate):
 *   instantiate_me NAME       fmi2Instantiate(fmi2ModelExchange, loggingOn) | fmi3InstantiateModelExchange
 *   set_time S T              fmi2SetTime | fmi3SetTime
 *   set_states S N X1..XN     fmi2SetContinuousStates | fmi3SetContinuousStates with an array of exactly N
 *                             elements (values not given are 0); "set_states S N null" passes NULL
 *   get_states S N | get_derivatives S N | get_indicators S N | get_nominals S N   [null]
 *                             fmi2GetContinuousStates | fmi3GetContinuousStates, fmi2GetDerivatives |
 *                             fmi3GetContinuousStateDerivatives, fmi2/3GetEventIndicators,
 *                             fmi2/3GetNominalsOfContinuousStates into an array of exactly N elements (or
 *                             NULL); prints STATES | DERIVATIVES | INDICATORS | NOMINALS <slot> <N values>
 *   enter_event S | enter_ct S   fmi2/3EnterEventMode | fmi2/3EnterContinuousTimeMode
 * FMI 3.0 co-simulation with event mode (enter_event and update_discrete as above):
 *   instantiate_ev NAME       fmi3InstantiateCoSimulation(loggingOn, eventModeUsed, earlyReturnAllowed)
 *   enter_step S              fmi3EnterStepMode
 *   update_discrete S [null]  fmi2NewDiscreteStates | fmi3UpdateDiscreteStates (null: NULL eventInfo / every
 *                             out-argument NULL); prints DISCRETE (below)
 *   completed_step S [null]   fmi2/3CompletedIntegratorStep(noSetFMUStatePriorToCurrentPoint = true) (null: NULL
 *                             out-arguments); prints COMPLETED <slot> <enterEventMode> <terminateSimulation>
 *   integrate S NX NZ T0 T_END DT TOL
 *                             the host's own solver, from continuous-time mode at T0 to T_END: Heun's method
 *                             (explicit trapezoidal rule; exact to rounding where the states' second
 *                             derivative is constant) in steps of DT, the last one shortened to end on T_END,
 *                             with NX states and NZ event indicators; an event where an indicator's domain
 *                             z > 0 changes either way (FMI's rule), located by bisecting the step to TOL
 *                             (TOL <= 0: the step) and handled at the first point found past the crossing:
 *                             event mode, discrete-state updates until none is needed, continuous-time mode;
 *                             completed_step after every step. Prints EVENT per event, INTEGRATED at the end,
 *                             and one STATUS: the worst of all its calls (it stops at the first Error)
 *
 * Output (stdout, flushed after every command and every log message):
 *   INFO <fmi2GetVersion> <fmi2GetTypesPlatform>  |  INFO <fmi3GetVersion> -    first, once loaded
 *   LOG <instance> <status> <category>: <message>      every logger callback (FMI 3.0's logger has no
 *                             instance name: the host gives each instance its name as environment)
 *   STATUS <command> <slot> <OK|Warning|Discard|Error|Fatal>   every FMI call
 *   REAL <slot> <vr> <%.17g>, INTEGER <slot> <vr> <integer> (Integer, Int32 and Enumeration),
 *   BOOLEAN <slot> <vr> <0|1>
 *   STEPPED <slot> <eventHandlingNeeded> <terminateSimulation> <earlyReturn> <%.17g lastSuccessfulTime>
 *   DISCRETE <slot> <discreteStatesNeedUpdate> <terminateSimulation> <nominalsChanged> <valuesChanged>
 *            <nextEventTimeDefined> <%.17g nextEventTime>
 *   EVENT <slot> <%.17g time> <valuesOfContinuousStatesChanged by some update> <terminateSimulation>
 *   INTEGRATED <slot> <%.17g time reached> <steps> <events>
 *   RECORDED setup <slot> <T0>  (FMI 3.0)
 *   SERIALIZED <slot> <bytes>
 *   INSTANCE <slot> <name>    or INSTANTIATE_FAILED (then exit code 3)
 *   FREED <slot>
 *   LIBPYTHON <0|1>           at the end: whether a Python library (Linux: libpython*, Windows:
 *                             python*.dll) is loaded into the process
 *   DONE                      the last line: the script ran to its end
 *
 * Exit codes: 0 script done, 1 usage/script error, 2 cannot load the binary or a symbol,
 * 3 instantiation returned NULL.
 *
 * Build:  gcc -O2 -Wall -Wextra -Werror [-DFMI_VERSION=3] -o fmi_script_host fmi_script_host.c -ldl
 *         x86_64-w64-mingw32-gcc -O2 -Wall -Wextra -Werror [-DFMI_VERSION=3] -D__USE_MINGW_ANSI_STDIO=1 \
 *             -static -static-libgcc -o fmi_script_host.exe fmi_script_host.c
 * (C99; __USE_MINGW_ANSI_STDIO: C99 printf/strtod, so %.17g round-trips, %zu works and "nan" parses.)
 * The headers beside this file are parts of it, each included once: fmi_script_host_platform.h (Linux or
 * Windows), fmi_script_host_fmi2.h and fmi_script_host_fmi3.h (each version's wrappers of the calls).
 */
#ifndef FMI_VERSION
#define FMI_VERSION 2
#endif
#if FMI_VERSION != 2 && FMI_VERSION != 3
#error "FMI_VERSION must be 2 or 3"
#endif
#ifndef _WIN32
#define _XOPEN_SOURCE 700 /* realpath */
#endif
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* --- what differs between the platforms: loading the binary, absolute paths, loaded libraries --- */
#include "fmi_script_host_platform.h"

#include <stdbool.h>
#include <stdint.h>

/* --- what both versions share: statuses (the same codes), instances, states ---------------------- */
typedef void *Instance;
typedef void *State;
typedef enum { ST_OK, ST_WARNING, ST_DISCARD, ST_ERROR, ST_FATAL, ST_PENDING, ST_NO_CALL = 100 } Status;
typedef Status (*InstanceOnlyT)(Instance);
typedef void (*FreeInstanceT)(Instance);
typedef const char *(*InfoT)(void);

#define MAX_SLOTS 16
#define MAX_VRS 256
#define MAX_TOKENS (MAX_VRS + 4)
#define MAX_PATH_BYTES 4096
#define MAX_NAME 256

static const char *status_name(Status s)
{
    static const char *names[] = {"OK", "Warning", "Discard", "Error", "Fatal", "Pending"};
    return ((unsigned)s < 6u) ? names[s] : "?";
}

static lib_handle lib;
static void *sym(const char *name)
{
    void *p = lib_sym(lib, name);
    if (!p) {
        fprintf(stderr, "fmi_script_host: missing symbol %s: %s\n", name, lib_why());
        exit(2);
    }
    return p;
}

static char slot_name[MAX_SLOTS + 1][MAX_NAME]; /* each instance's name (FMI 3.0: its log environment) */
static char resources[3 * MAX_PATH_BYTES + 64];   /* what instantiation is given for the resources */
static const char *token;                         /* the GUID or instantiation token of the command line */

/* The calls every version makes through the same signature. */
static FreeInstanceT free_instance;
static InstanceOnlyT exit_init, terminate, reset;

/* Model exchange: these calls have the same shape in FMI 2.0 and FMI 3.0 (fmi2Real = fmi3Float64 =
 * double), so one pointer each; they are looked up only when a model-exchange command needs them
 * (me_sym), so a co-simulation-only binary still loads. */
typedef Status (*SetTimeT)(Instance, double);
typedef Status (*SetVectorT)(Instance, const double[], size_t);
typedef Status (*GetVectorT)(Instance, double[], size_t);
enum { VEC_STATES, VEC_DERIVATIVES, VEC_INDICATORS, VEC_NOMINALS, N_VECTORS };
static const char *const vector_label[N_VECTORS] = {"STATES", "DERIVATIVES", "INDICATORS", "NOMINALS"};
static InstanceOnlyT enter_event_mode, enter_continuous_time_mode;
static SetTimeT set_time;
static SetVectorT set_states;
static GetVectorT get_vector[N_VECTORS];
/* what fmi2NewDiscreteStates' fmi2EventInfo / fmi3UpdateDiscreteStates' out-arguments say */
typedef struct {
    int need_update, terminate, nominals_changed, values_changed, next_time_defined;
    double next_time;
} EventUpdate;
static void me_functions(void); /* each version's: looks up the model-exchange calls */
static int me_loaded;
static void *me_sym(const char *name);

#if FMI_VERSION == 3
#include "fmi_script_host_fmi3.h"
#else
#include "fmi_script_host_fmi2.h"
#endif

/* ================================ the script: one copy for both versions ========================== */
static void report(const char *cmd, int slot, Status st)
{
    if (st != ST_NO_CALL) printf("STATUS %s %d %s\n", cmd, slot, status_name(st));
}

/* Split a line at blanks into at most max tokens (no strtok_r: not in every C runtime). */
static int split(char *line, char **tokens, int max)
{
    int n = 0;
    char *p = line;
    while (*p && n < max) {
        while (*p == ' ' || *p == '\t' || *p == '\r' || *p == '\n') *p++ = '\0';
        if (!*p) break;
        tokens[n++] = p;
        while (*p && *p != ' ' && *p != '\t' && *p != '\r' && *p != '\n') p++;
    }
    if (*p) *p = '\0';
    return n;
}

/* --- model exchange ------------------------------------------------------------------------------ */
static void *me_sym(const char *name)
{
    return sym(name); /* exits (code 2) naming a missing symbol */
}
static void need_me_functions(void)
{
    if (!me_loaded) me_functions();
    me_loaded = 1;
}

/* A vector of exactly n doubles (so the sanitizers see any access past what the host passed), or one
 * double for n = 0. */
static double *vector_of(size_t n)
{
    double *v = calloc(n ? n : 1, sizeof *v);
    if (!v) {
        fprintf(stderr, "fmi_script_host: out of memory\n");
        exit(1);
    }
    return v;
}

static void print_vector(const char *label, int slot, const double *v, size_t n)
{
    printf("%s %d", label, slot);
    for (size_t i = 0; i < n; i++) printf(" %.17g", v[i]);
    printf("\n");
}

/* The host's solver for "integrate": Heun's method (explicit trapezoidal rule, 2 derivative evaluations
 * a step; exact, to rounding, where the second derivative of the states is constant, as in free flight)
 * with the FMI state-event rule: an event where an indicator's domain z > 0 changes (either way), located
 * by bisection of the step to `tol`, and handled at the first point found past the crossing. */
typedef struct {
    Instance c;
    size_t nx, nz;
    double *k2;   /* scratch: the derivatives at the predictor */
    Status worst; /* the worst status of every call made */
} Solver;

static int solver_ok(Solver *sv, Status st)
{
    if (st > sv->worst) sv->worst = st;
    return st <= ST_WARNING;
}

/* Sets the FMU to time t + h and the states of one Heun step from (t, x) whose derivatives are dx;
 * the new states in x1, the indicators there in z1. */
static int heun_step(Solver *sv, double t, const double *x, const double *dx, double h, double *x1, double *z1)
{
    for (size_t i = 0; i < sv->nx; i++) x1[i] = x[i] + h * dx[i];
    if (!solver_ok(sv, set_time(sv->c, t + h)) || !solver_ok(sv, set_states(sv->c, x1, sv->nx)) ||
        !solver_ok(sv, get_vector[VEC_DERIVATIVES](sv->c, sv->k2, sv->nx)))
        return 0;
    for (size_t i = 0; i < sv->nx; i++) x1[i] = x[i] + 0.5 * h * (dx[i] + sv->k2[i]);
    return solver_ok(sv, set_states(sv->c, x1, sv->nx)) && solver_ok(sv, get_vector[VEC_INDICATORS](sv->c, z1, sv->nz));
}

static int crossed(const double *z0, const double *z1, size_t nz)
{
    for (size_t i = 0; i < nz; i++)
        if ((z0[i] > 0.0) != (z1[i] > 0.0)) return 1;
    return 0;
}

/* The event iteration: event mode, discrete-state updates until none is needed (at most 100), back to
 * continuous-time mode. *changed: some update changed the continuous states; *stop: terminate asked. */
static int handle_event(Solver *sv, int *changed, int *stop)
{
    EventUpdate u = {1, 0, 0, 0, 0, 0.0};
    *changed = *stop = 0;
    if (!solver_ok(sv, enter_event_mode(sv->c))) return 0;
    for (int i = 0; i < 100 && u.need_update && !u.terminate; i++) {
        if (!solver_ok(sv, update_discrete(sv->c, 0, &u))) return 0;
        *changed |= u.values_changed;
    }
    *stop = u.terminate;
    if (u.need_update && !u.terminate) {
        fprintf(stderr, "fmi_script_host: discrete states still need an update after 100 iterations\n");
        return 0;
    }
    return *stop || solver_ok(sv, enter_continuous_time_mode(sv->c));
}

/* integrate S NX NZ T0 T_END DT TOL: from continuous-time mode at time T0 to T_END in steps of DT (the last
 * one shortened to land on T_END), events located to TOL (TOL <= 0: to the step). Prints EVENT per event
 * and INTEGRATED at the end; returns the worst status of its calls. */
static Status integrate(int slot, Instance c, size_t nx, size_t nz, double t0, double t_end, double dt, double tol)
{
    Solver sv = {c, nx, nz, vector_of(nx), ST_OK};
    double *x = vector_of(nx), *dx = vector_of(nx), *x1 = vector_of(nx), *z0 = vector_of(nz), *z1 = vector_of(nz);
    double t = t0;
    long steps = 0, events = 0;
    int alive = solver_ok(&sv, get_vector[VEC_STATES](c, x, nx)) && solver_ok(&sv, get_vector[VEC_INDICATORS](c, z0, nz)) &&
                solver_ok(&sv, get_vector[VEC_DERIVATIVES](c, dx, nx));
    while (alive && t < t_end) {
        double h = t_end - t <= dt * (1.0 + 1e-9) ? t_end - t : dt;
        int event = 0, enter = 0, stop = 0, changed = 0;
        if (!heun_step(&sv, t, x, dx, h, x1, z1)) break;
        if (crossed(z0, z1, nz)) {
            double lo = 0.0, hi = h;
            event = 1;
            while (tol > 0.0 && hi - lo > tol) {
                double mid = lo + 0.5 * (hi - lo);
                if (mid <= lo || mid >= hi) break;
                if (!heun_step(&sv, t, x, dx, mid, x1, z1)) goto failed;
                if (crossed(z0, z1, nz)) hi = mid;
                else lo = mid;
            }
            if (hi < h && !heun_step(&sv, t, x, dx, hi, x1, z1)) break; /* the FMU at the point past it */
            h = hi;
        }
        if (!solver_ok(&sv, completed_step(c, 0, &enter, &stop))) break;
        t += h;
        steps++;
        memcpy(x, x1, nx * sizeof *x);
        memcpy(z0, z1, nz * sizeof *z0);
        if (event || enter) {
            if (!handle_event(&sv, &changed, &stop)) break;
            events++;
            printf("EVENT %d %.17g %d %d\n", slot, t, changed, stop);
            if (stop) break;
            if (!solver_ok(&sv, get_vector[VEC_STATES](c, x, nx)) || !solver_ok(&sv, get_vector[VEC_INDICATORS](c, z0, nz)))
                break;
        } else if (stop) {
            break;
        }
        alive = solver_ok(&sv, get_vector[VEC_DERIVATIVES](c, dx, nx));
    }
failed:
    printf("INTEGRATED %d %.17g %ld %ld\n", slot, t, steps, events);
    free(sv.k2), free(x), free(dx), free(x1), free(z0), free(z1);
    return sv.worst;
}

/* "integer", "enumeration" or "boolean" after "set_"/"get_", or -1 */
static int whole_kind(const char *cmd)
{
    const char *kind = cmd + 4;
    if (strncmp(cmd, "set_", 4) && strncmp(cmd, "get_", 4)) return -1;
    return !strcmp(kind, "integer") ? AS_INTEGER : !strcmp(kind, "enumeration") ? AS_ENUMERATION
           : !strcmp(kind, "boolean") ? AS_BOOLEAN : -1;
}

/* the vector a "get_<name>" model-exchange command reads, or -1 */
static int vector_kind(const char *cmd)
{
    static const char *const names[N_VECTORS] = {"get_states", "get_derivatives", "get_indicators", "get_nominals"};
    for (int i = 0; i < N_VECTORS; i++)
        if (!strcmp(cmd, names[i])) return i;
    return -1;
}

int main(int argc, char **argv)
{
    if (argc != 4) {
        fprintf(stderr, "usage: %s <unpacked_fmu_dir> <modelIdentifier> <guid | instantiationToken> < script\n",
                argv[0]);
        return 1;
    }
    char dir[MAX_PATH_BYTES];
    if (!absolute_path(argv[1], dir, sizeof dir)) {
        perror(argv[1]);
        return 1;
    }
    char lib_path[MAX_PATH_BYTES + 256];
    snprintf(lib_path, sizeof lib_path, BINARY_FORMAT, dir, argv[2]);
    resource_location(dir, resources, sizeof resources);
    token = argv[3];
    lib = lib_open(lib_path);
    if (!lib) {
        fprintf(stderr, "fmi_script_host: " LOADER " failed: %s\n", lib_why());
        return 2;
    }
    load_functions();
    fflush(stdout);

    Instance inst[MAX_SLOTS] = {0};
    State state[MAX_SLOTS] = {0};
    Byte *blob[MAX_SLOTS] = {0};
    size_t blob_size[MAX_SLOTS] = {0};
    int nslots = 0;

    char line[8192];
    char *tok[MAX_TOKENS];
    for (; fgets(line, sizeof line, stdin); fflush(stdout)) {
        int n = split(line, tok, MAX_TOKENS), known = 1;
        if (n == 0 || tok[0][0] == '#') continue;
        const char *cmd = tok[0];
        if (!strcmp(cmd, "instantiate") || !strcmp(cmd, "instantiate_me") || !strcmp(cmd, "instantiate_ev")) {
            if (n < 2 || nslots == MAX_SLOTS) return 1;
            snprintf(slot_name[nslots], MAX_NAME, "%s", tok[1]);
            inst[nslots] = instantiate_kind(!strcmp(cmd, "instantiate_me") ? "model_exchange"
                                            : !strcmp(cmd, "instantiate_ev") ? "events" : "", nslots, &known);
            if (!inst[nslots]) {
                printf("INSTANTIATE_FAILED\n");
                return 3;
            }
            printf("INSTANCE %d %s\n", nslots, tok[1]);
            nslots++;
            continue;
        }
        if (!strcmp(cmd, "instantiate_bad")) {
            const char *kind = n > 1 ? tok[1] : "";
            Instance c;
            snprintf(slot_name[MAX_SLOTS], MAX_NAME, "bad");
            c = kind[0] ? instantiate_kind(kind, MAX_SLOTS, &known) : NULL;
            if (!kind[0] || !known) {
                fprintf(stderr, "fmi_script_host: FMI %d.0 has no bad instantiation '%s'\n", FMI_VERSION, kind);
                return 1;
            }
            printf("BAD_INSTANCE %s %s\n", kind, c ? "NONNULL" : "NULL");
            if (c) free_instance(c);
            continue;
        }
        if (n < 2) return 1;
        int s = atoi(tok[1]);
        if (s < 0 || s >= nslots || !inst[s]) {
            fprintf(stderr, "fmi_script_host: bad slot in '%s'\n", cmd);
            return 1;
        }
        Instance c = inst[s];
        const char *a = n > 2 ? tok[2] : NULL, *b = n > 3 ? tok[3] : NULL;
        int as = whole_kind(cmd);
        if (!strcmp(cmd, "setup")) {
            report(cmd, s, setup(s, c, a ? strtod(a, NULL) : 0.0));
        } else if (!strcmp(cmd, "enter_init")) {
            report(cmd, s, enter_init(s, c));
        } else if (!strcmp(cmd, "exit_init")) {
            report(cmd, s, exit_init(c));
        } else if (!strcmp(cmd, "terminate")) {
            report(cmd, s, terminate(c));
        } else if (!strcmp(cmd, "reset")) {
            report(cmd, s, reset(c));
        } else if (!strcmp(cmd, "free")) {
            free_instance(c);
            inst[s] = NULL;
            printf("FREED %d\n", s);
        } else if (!strcmp(cmd, "set_real") && b) {
            report(cmd, s, set_real(c, (VR)strtoul(a, NULL, 10), strtod(b, NULL)));
        } else if (as >= 0 && cmd[0] == 's' && b) {
            report(cmd, s, set_whole(c, as, (VR)strtoul(a, NULL, 10), strtoll(b, NULL, 10)));
        } else if ((!strcmp(cmd, "get_real") || as >= 0) && a) {
            VR vrs[MAX_VRS];
            size_t nv = 0;
            for (int i = 2; i < n && nv < MAX_VRS; i++) vrs[nv++] = (VR)strtoul(tok[i], NULL, 10);
            if (as < 0) {
                double out[MAX_VRS];
                Status st = get_reals(c, vrs, nv, out);
                report(cmd, s, st);
                for (size_t i = 0; i < nv && st <= ST_WARNING; i++) printf("REAL %d %u %.17g\n", s, (unsigned)vrs[i], out[i]);
            } else {
                long long out[MAX_VRS];
                Status st = get_wholes(c, as, vrs, nv, out);
                report(cmd, s, st);
                for (size_t i = 0; i < nv && st <= ST_WARNING; i++)
                    printf("%s %d %u %lld\n", as == AS_BOOLEAN ? "BOOLEAN" : "INTEGER", s, (unsigned)vrs[i], out[i]);
            }
        } else if (!strcmp(cmd, "step") && b) {
            report(cmd, s, do_step(s, c, strtod(a, NULL), strtod(b, NULL)));
        } else if (!strcmp(cmd, "get_state")) {
            report(cmd, s, get_state(c, &state[s]));
        } else if (!strcmp(cmd, "set_state")) {
            report(cmd, s, set_state(c, state[s]));
        } else if (!strcmp(cmd, "free_state")) {
            report(cmd, s, free_state(c, &state[s]));
        } else if (!strcmp(cmd, "serialize")) {
            size_t size = 0;
            Status st = state_size(c, state[s], &size);
            if (st <= ST_WARNING) {
                free(blob[s]);
                blob[s] = malloc(size ? size : 1);
                blob_size[s] = size;
                st = serialize(c, state[s], blob[s], size);
            }
            report(cmd, s, st);
            printf("SERIALIZED %d %zu\n", s, blob_size[s]);
        } else if (!strcmp(cmd, "deserialize_file") && a) {
            FILE *f = fopen(a, "rb");
            static Byte bytes[1 << 16];
            size_t size = f ? fread(bytes, 1, sizeof bytes, f) : 0;
            if (f) fclose(f);
            report(cmd, s, deserialize(c, bytes, size, &state[s]));
        } else if (!strcmp(cmd, "set_foreign_state")) {
            double not_a_state[64] = {0};
            report(cmd, s, set_state(c, (State)not_a_state));
        } else if ((!strcmp(cmd, "get_string") || !strcmp(cmd, "set_string")) && a) {
            report(cmd, s, string_call(c, cmd[0] == 'g', (VR)strtoul(a, NULL, 10)));
        } else if (!strcmp(cmd, "set_time") && a) {
            need_me_functions();
            report(cmd, s, set_time(c, strtod(a, NULL)));
        } else if (!strcmp(cmd, "enter_step")) {
#if FMI_VERSION == 3
            need_me_functions();
            report(cmd, s, enter_step_mode3(c));
#else
            fprintf(stderr, "fmi_script_host: FMI 2.0 has no enter_step\n");
            return 1;
#endif
        } else if (!strcmp(cmd, "enter_event") || !strcmp(cmd, "enter_ct")) {
            need_me_functions();
            report(cmd, s, (cmd[6] == 'e' ? enter_event_mode : enter_continuous_time_mode)(c));
        } else if ((!strcmp(cmd, "set_states") || vector_kind(cmd) >= 0) && a) {
            /* N values or "null" (a NULL array); the array has exactly N elements */
            size_t nv = strtoul(a, NULL, 10);
            int null_array = b && !strcmp(b, "null"), kind = vector_kind(cmd);
            if (nv > MAX_VRS) return 1;
            double *v = vector_of(nv);
            need_me_functions();
            if (kind < 0) {
                for (size_t i = 0; i < nv && (int)i + 3 < n && !null_array; i++) v[i] = strtod(tok[i + 3], NULL);
                report(cmd, s, set_states(c, null_array ? NULL : v, nv));
            } else {
                Status st = get_vector[kind](c, null_array ? NULL : v, nv);
                report(cmd, s, st);
                if (st <= ST_WARNING && !null_array) print_vector(vector_label[kind], s, v, nv);
            }
            free(v);
        } else if (!strcmp(cmd, "update_discrete") || !strcmp(cmd, "completed_step")) {
            int null_args = a && !strcmp(a, "null");
            need_me_functions();
            if (cmd[0] == 'u') {
                EventUpdate u;
                Status st = update_discrete(c, null_args, &u);
                report(cmd, s, st);
                if (st <= ST_WARNING && !null_args)
                    printf("DISCRETE %d %d %d %d %d %d %.17g\n", s, u.need_update, u.terminate, u.nominals_changed,
                           u.values_changed, u.next_time_defined, u.next_time);
            } else {
                int enter = 0, stop = 0;
                Status st = completed_step(c, null_args, &enter, &stop);
                report(cmd, s, st);
                if (st <= ST_WARNING && !null_args) printf("COMPLETED %d %d %d\n", s, enter, stop);
            }
        } else if (!strcmp(cmd, "integrate") && n == 8) {
            size_t nx = strtoul(tok[2], NULL, 10), nz = strtoul(tok[3], NULL, 10);
            double t0 = strtod(tok[4], NULL), t_end = strtod(tok[5], NULL), dt = strtod(tok[6], NULL);
            if (nx > MAX_VRS || nz > MAX_VRS || !(dt > 0.0) || !(t_end - t0 < 1e9 * dt)) {
                fprintf(stderr, "fmi_script_host: integrate needs sizes <= %d and 0 < DT, (T_END - T0) / DT < 1e9\n",
                        MAX_VRS);
                return 1;
            }
            need_me_functions();
            report(cmd, s, integrate(s, c, nx, nz, t0, t_end, dt, strtod(tok[7], NULL)));
        } else if (!strcmp(cmd, "deserialize")) {
            int from = a ? atoi(a) : s;
            if (from < 0 || from >= nslots || !blob[from]) return 1;
            report(cmd, s, deserialize(c, blob[from], blob_size[from], &state[s]));
        } else {
            fprintf(stderr, "fmi_script_host: unknown or incomplete command '%s'\n", cmd);
            return 1;
        }
    }
    for (int s = 0; s < nslots; s++) free(blob[s]);
    printf("LIBPYTHON %d\n", python_loaded());
    printf("DONE\n");
    fflush(stdout);
    lib_close(lib);
    return 0;
}
