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
#ifdef _WIN32
#include <windows.h>
#include <tlhelp32.h>
#define BINARY_FORMAT "%s\\binaries\\" PLATFORM_DIR "\\%s.dll"
#if FMI_VERSION == 3
#define PLATFORM_DIR "x86_64-windows"
#else
#define PLATFORM_DIR "win64"
#endif
#define PATH_SEPARATOR '\\'
#define URI_PLAIN "-._~/:" /* bytes a file: URI keeps as they are (':' of the drive, Z:/...) */
typedef HMODULE lib_handle;
static lib_handle lib_open(const char *path) { return LoadLibraryExA(path, NULL, LOAD_WITH_ALTERED_SEARCH_PATH); }
static void *lib_sym(lib_handle lib, const char *name) { return (void *)(size_t)GetProcAddress(lib, name); }
static void lib_close(lib_handle lib) { FreeLibrary(lib); }
#define LOADER "LoadLibrary"
static const char *lib_why(void)
{
    static char why[64];
    snprintf(why, sizeof why, "Windows error %lu", (unsigned long)GetLastError());
    return why;
}
static int absolute_path(const char *path, char *out, size_t size) { return _fullpath(out, path, size) != NULL; }
static int python_loaded(void)
{
    HANDLE snap = CreateToolhelp32Snapshot(TH32CS_SNAPMODULE, GetCurrentProcessId());
    MODULEENTRY32 module;
    int python = 0;
    if (snap == INVALID_HANDLE_VALUE) return 0;
    module.dwSize = sizeof module;
    for (BOOL more = Module32First(snap, &module); more; more = Module32Next(snap, &module))
        python |= _strnicmp(module.szModule, "python", 6) == 0;
    CloseHandle(snap);
    return python;
}
#else
#include <dlfcn.h>
#define BINARY_FORMAT "%s/binaries/" PLATFORM_DIR "/%s.so"
#if FMI_VERSION == 3
#define PLATFORM_DIR "x86_64-linux"
#else
#define PLATFORM_DIR "linux64"
#endif
#define PATH_SEPARATOR '/'
#define URI_PLAIN "-._~/"
typedef void *lib_handle;
static lib_handle lib_open(const char *path) { return dlopen(path, RTLD_LAZY | RTLD_LOCAL); }
static void *lib_sym(lib_handle lib, const char *name) { return dlsym(lib, name); }
static void lib_close(lib_handle lib) { dlclose(lib); }
#define LOADER "dlopen"
static const char *lib_why(void)
{
    const char *why = dlerror();
    return why ? why : "unknown error";
}
static int absolute_path(const char *path, char *out, size_t size)
{
    char *full = realpath(path, NULL);
    int ok = full != NULL && strlen(full) < size;
    if (ok) strcpy(out, full);
    free(full);
    return ok;
}
static int python_loaded(void)
{
    char line[8192];
    int python = 0;
    FILE *maps = fopen("/proc/self/maps", "r");
    while (maps && fgets(line, sizeof line, maps))
        python |= strstr(line, "libpython") != NULL;
    if (maps) fclose(maps);
    return python;
}
#endif


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
/* ================================ FMI 3.0 ========================================================= */
typedef uint32_t VR;
typedef uint8_t Byte;
typedef void (*Logger3T)(void *environment, Status status, const char *category, const char *message);
typedef void (*IntermediateUpdate3T)(void *environment, double time, bool clocksTicked, bool setRequested,
                                     bool getAllowed, bool stepFinished, bool canReturnEarly, bool *earlyReturnRequested,
                                     double *earlyReturnTime);
typedef Instance (*InstantiateCS3T)(const char *, const char *, const char *, bool, bool, bool, bool, const VR[],
                                    size_t, void *, Logger3T, IntermediateUpdate3T);
typedef Instance (*InstantiateME3T)(const char *, const char *, const char *, bool, bool, void *, Logger3T);
typedef Instance (*InstantiateSE3T)(const char *, const char *, const char *, bool, bool, void *, Logger3T,
                                    void (*)(void *), void (*)(void), void (*)(void));
typedef Status (*EnterInit3T)(Instance, bool, double, double, bool, double);
typedef Status (*SetFloat64T)(Instance, const VR[], size_t, const double[], size_t);
typedef Status (*GetFloat64T)(Instance, const VR[], size_t, double[], size_t);
typedef Status (*SetInt32T)(Instance, const VR[], size_t, const int32_t[], size_t);
typedef Status (*GetInt32T)(Instance, const VR[], size_t, int32_t[], size_t);
typedef Status (*SetInt64T)(Instance, const VR[], size_t, const int64_t[], size_t);
typedef Status (*GetInt64T)(Instance, const VR[], size_t, int64_t[], size_t);
typedef Status (*SetBoolean3T)(Instance, const VR[], size_t, const bool[], size_t);
typedef Status (*GetBoolean3T)(Instance, const VR[], size_t, bool[], size_t);
typedef Status (*String3T)(Instance, const VR[], size_t, const char *[], size_t);
typedef Status (*DoStep3T)(Instance, double, double, bool, bool *, bool *, bool *, double *);
typedef Status (*GetStateT)(Instance, State *);
typedef Status (*SetStateT)(Instance, State);
typedef Status (*StateSizeT)(Instance, State, size_t *);
typedef Status (*SerializeT)(Instance, State, Byte[], size_t);
typedef Status (*DeserializeT)(Instance, const Byte[], size_t, State *);

static double start_time[MAX_SLOTS]; /* the T0 of the last "setup" of each slot */
static InstantiateCS3T instantiate_cs;
static InstantiateME3T instantiate_me;
static InstantiateSE3T instantiate_se;
static EnterInit3T enter_init3;
static SetFloat64T set_float64;
static GetFloat64T get_float64;
static SetInt32T set_int32;
static GetInt32T get_int32;
static SetInt64T set_int64;
static GetInt64T get_int64;
static SetBoolean3T set_boolean3;
static GetBoolean3T get_boolean3;
static String3T get_string3, set_string3;
static DoStep3T do_step3;
static GetStateT get_state, free_state;
static SetStateT set_state;
static StateSizeT state_size;
static SerializeT serialize;
static DeserializeT deserialize;
static InfoT get_version;

static void logger(void *environment, Status status, const char *category, const char *message)
{
    printf("LOG %s %s %s: %s\n", environment ? (const char *)environment : "?", status_name(status),
           category ? category : "", message ? message : "");
    fflush(stdout);
}

static void load_functions(void)
{
    instantiate_cs = (InstantiateCS3T)sym("fmi3InstantiateCoSimulation");
    instantiate_me = (InstantiateME3T)sym("fmi3InstantiateModelExchange");
    instantiate_se = (InstantiateSE3T)sym("fmi3InstantiateScheduledExecution");
    free_instance = (FreeInstanceT)sym("fmi3FreeInstance");
    enter_init3 = (EnterInit3T)sym("fmi3EnterInitializationMode");
    exit_init = (InstanceOnlyT)sym("fmi3ExitInitializationMode");
    terminate = (InstanceOnlyT)sym("fmi3Terminate");
    reset = (InstanceOnlyT)sym("fmi3Reset");
    set_float64 = (SetFloat64T)sym("fmi3SetFloat64");
    get_float64 = (GetFloat64T)sym("fmi3GetFloat64");
    set_int32 = (SetInt32T)sym("fmi3SetInt32");
    get_int32 = (GetInt32T)sym("fmi3GetInt32");
    set_int64 = (SetInt64T)sym("fmi3SetInt64");
    get_int64 = (GetInt64T)sym("fmi3GetInt64");
    set_boolean3 = (SetBoolean3T)sym("fmi3SetBoolean");
    get_boolean3 = (GetBoolean3T)sym("fmi3GetBoolean");
    get_string3 = (String3T)sym("fmi3GetString");
    set_string3 = (String3T)sym("fmi3SetString");
    do_step3 = (DoStep3T)sym("fmi3DoStep");
    get_state = (GetStateT)sym("fmi3GetFMUState");
    set_state = (SetStateT)sym("fmi3SetFMUState");
    free_state = (GetStateT)sym("fmi3FreeFMUState");
    state_size = (StateSizeT)sym("fmi3SerializedFMUStateSize");
    serialize = (SerializeT)sym("fmi3SerializeFMUState");
    deserialize = (DeserializeT)sym("fmi3DeserializeFMUState");
    get_version = (InfoT)sym("fmi3GetVersion");
    printf("INFO %s -\n", get_version());
}

/* FMI 3.0 wants the resources as a native path ending with a separator. */
static void resource_location(const char *dir, char *out, size_t size)
{
    snprintf(out, size, "%s%cresources%c", dir, PATH_SEPARATOR, PATH_SEPARATOR);
}

/* kind "" instantiates slot `slot` properly; *known = 0 for a kind FMI 3.0 has not */
static Instance instantiate_kind(const char *kind, int slot, int *known)
{
    const char *name = slot_name[slot], *guid = token;
    void *environment = slot_name[slot];
    Logger3T log = logger;
    bool event_mode = false;
    VR required[1] = {0};
    size_t n_required = 0;
    *known = 1;
    if (!strcmp(kind, "null_name")) name = NULL;
    else if (!strcmp(kind, "empty_name")) name = "";
    else if (!strcmp(kind, "wrong_guid")) guid = "{00000000-0000-0000-0000-000000000000}";
    else if (!strcmp(kind, "null_guid")) guid = NULL;
    else if (!strcmp(kind, "wrong_guid_no_logger")) guid = "{00000000-0000-0000-0000-000000000000}", log = NULL;
    else if (!strcmp(kind, "event_mode")) event_mode = true;
    else if (!strcmp(kind, "intermediate_update")) n_required = 1;
    else if (!strcmp(kind, "model_exchange")) return instantiate_me(name, guid, resources, false, true, environment, log);
    else if (!strcmp(kind, "scheduled_execution"))
        return instantiate_se(name, guid, resources, false, true, environment, log, NULL, NULL, NULL);
    else if (kind[0] != '\0') {
        *known = 0;
        return NULL;
    }
    return instantiate_cs(name, guid, resources, false, true, event_mode, false, required, n_required, environment,
                          log, NULL);
}

static Status setup(int s, Instance c, double t0)
{
    (void)c;
    start_time[s] = t0; /* given to fmi3EnterInitializationMode */
    printf("RECORDED setup %d %.17g\n", s, t0);
    return ST_NO_CALL;
}
static Status enter_init(int s, Instance c) { return enter_init3(c, false, 0.0, start_time[s], false, 0.0); }
static Status set_real(Instance c, VR vr, double v) { return set_float64(c, &vr, 1, &v, 1); }
static Status get_reals(Instance c, const VR vrs[], size_t n, double out[]) { return get_float64(c, vrs, n, out, n); }

enum { AS_INTEGER, AS_ENUMERATION, AS_BOOLEAN };
static Status set_whole(Instance c, int as, VR vr, long long v)
{
    int32_t i32 = (int32_t)v;
    int64_t i64 = (int64_t)v;
    bool b = v != 0;
    return as == AS_INTEGER ? set_int32(c, &vr, 1, &i32, 1)
           : as == AS_ENUMERATION ? set_int64(c, &vr, 1, &i64, 1) : set_boolean3(c, &vr, 1, &b, 1);
}
static Status get_wholes(Instance c, int as, const VR vrs[], size_t n, long long out[])
{
    int32_t i32[MAX_VRS];
    int64_t i64[MAX_VRS];
    bool b[MAX_VRS];
    Status st = as == AS_INTEGER ? get_int32(c, vrs, n, i32, n)
                : as == AS_ENUMERATION ? get_int64(c, vrs, n, i64, n) : get_boolean3(c, vrs, n, b, n);
    for (size_t i = 0; i < n; i++) out[i] = as == AS_INTEGER ? i32[i] : as == AS_ENUMERATION ? i64[i] : b[i];
    return st;
}
static Status do_step(int s, Instance c, double t, double h)
{
    bool event = true, stop = true, early = true;
    double last = -1.0;
    Status st = do_step3(c, t, h, true, &event, &stop, &early, &last);
    if (st <= ST_DISCARD) printf("STEPPED %d %d %d %d %.17g\n", s, event, stop, early, last);
    return st;
}
static Status string_call(Instance c, int get, VR vr)
{
    const char *text[1] = {"text"};
    return (get ? get_string3 : set_string3)(c, &vr, 1, text, 1);
}

typedef Status (*UpdateDiscrete3T)(Instance, bool *, bool *, bool *, bool *, bool *, double *);
typedef Status (*CompletedStep3T)(Instance, bool, bool *, bool *);
static UpdateDiscrete3T update_discrete3;
static CompletedStep3T completed_step3;
static void me_functions(void)
{
    enter_event_mode = (InstanceOnlyT)me_sym("fmi3EnterEventMode");
    enter_continuous_time_mode = (InstanceOnlyT)me_sym("fmi3EnterContinuousTimeMode");
    set_time = (SetTimeT)me_sym("fmi3SetTime");
    set_states = (SetVectorT)me_sym("fmi3SetContinuousStates");
    get_vector[VEC_STATES] = (GetVectorT)me_sym("fmi3GetContinuousStates");
    get_vector[VEC_DERIVATIVES] = (GetVectorT)me_sym("fmi3GetContinuousStateDerivatives");
    get_vector[VEC_INDICATORS] = (GetVectorT)me_sym("fmi3GetEventIndicators");
    get_vector[VEC_NOMINALS] = (GetVectorT)me_sym("fmi3GetNominalsOfContinuousStates");
    update_discrete3 = (UpdateDiscrete3T)me_sym("fmi3UpdateDiscreteStates");
    completed_step3 = (CompletedStep3T)me_sym("fmi3CompletedIntegratorStep");
}
/* fmi3UpdateDiscreteStates; null_args: every out-argument NULL */
static Status update_discrete(Instance c, int null_args, EventUpdate *u)
{
    bool need = true, stop = true, nominals = true, values = true, defined = true;
    double next = -1.0;
    Status st = null_args ? update_discrete3(c, NULL, NULL, NULL, NULL, NULL, NULL)
                          : update_discrete3(c, &need, &stop, &nominals, &values, &defined, &next);
    u->need_update = need, u->terminate = stop, u->nominals_changed = nominals, u->values_changed = values;
    u->next_time_defined = defined, u->next_time = next;
    return st;
}
/* fmi3CompletedIntegratorStep(noSetFMUStatePriorToCurrentPoint = true); null_args: NULL out-arguments */
static Status completed_step(Instance c, int null_args, int *enter_event, int *stop)
{
    bool enter = true, terminate_now = true;
    Status st = null_args ? completed_step3(c, true, NULL, NULL) : completed_step3(c, true, &enter, &terminate_now);
    *enter_event = enter, *stop = terminate_now;
    return st;
}

#else
/* ================================ FMI 2.0 ========================================================= */
typedef unsigned int VR;
typedef char Byte;
typedef int fmi2Integer;
typedef int fmi2Boolean;
typedef enum { fmi2ModelExchange, fmi2CoSimulation } fmi2Type;
typedef void (*fmi2CallbackLogger)(void *, const char *, Status, const char *, const char *, ...);
typedef struct {
    fmi2CallbackLogger logger;
    void *(*allocateMemory)(size_t, size_t);
    void (*freeMemory)(void *);
    void (*stepFinished)(void *, Status);
    void *componentEnvironment;
} fmi2CallbackFunctions;

typedef Instance (*InstantiateT)(const char *, fmi2Type, const char *, const char *, const fmi2CallbackFunctions *,
                                 fmi2Boolean, fmi2Boolean);
typedef Status (*SetupT)(Instance, fmi2Boolean, double, double, fmi2Boolean, double);
typedef Status (*SetRealT)(Instance, const VR[], size_t, const double[]);
typedef Status (*GetRealT)(Instance, const VR[], size_t, double[]);
typedef Status (*SetIntT)(Instance, const VR[], size_t, const fmi2Integer[]);
typedef Status (*GetIntT)(Instance, const VR[], size_t, fmi2Integer[]);
typedef Status (*DoStepT)(Instance, double, double, fmi2Boolean);
typedef Status (*GetStateT)(Instance, State *);
typedef Status (*SetStateT)(Instance, State);
typedef Status (*StateSizeT)(Instance, State, size_t *);
typedef Status (*SerializeT)(Instance, State, Byte[], size_t);
typedef Status (*DeserializeT)(Instance, const Byte[], size_t, State *);
typedef Status (*StringT)(Instance, const VR[], size_t, const char *[]);

static InstantiateT instantiate2;
static SetupT setup2;
static InstanceOnlyT enter_init2;
static SetRealT set_real2;
static GetRealT get_real2;
static SetIntT set_integer2, set_boolean2;
static GetIntT get_integer2, get_boolean2;
static DoStepT do_step2;
static GetStateT get_state, free_state;
static SetStateT set_state;
static StateSizeT state_size;
static SerializeT serialize;
static DeserializeT deserialize;
static StringT get_string2, set_string2;
static InfoT get_version, get_platform;

static void logger(void *environment, const char *instance, Status status, const char *category,
                   const char *message, ...)
{
    va_list ap;
    (void)environment;
    printf("LOG %s %s %s: ", instance ? instance : "?", status_name(status), category ? category : "");
    va_start(ap, message);
    vprintf(message ? message : "", ap);
    va_end(ap);
    printf("\n");
    fflush(stdout);
}

static void load_functions(void)
{
    instantiate2 = (InstantiateT)sym("fmi2Instantiate");
    free_instance = (FreeInstanceT)sym("fmi2FreeInstance");
    setup2 = (SetupT)sym("fmi2SetupExperiment");
    enter_init2 = (InstanceOnlyT)sym("fmi2EnterInitializationMode");
    exit_init = (InstanceOnlyT)sym("fmi2ExitInitializationMode");
    terminate = (InstanceOnlyT)sym("fmi2Terminate");
    reset = (InstanceOnlyT)sym("fmi2Reset");
    set_real2 = (SetRealT)sym("fmi2SetReal");
    get_real2 = (GetRealT)sym("fmi2GetReal");
    set_integer2 = (SetIntT)sym("fmi2SetInteger");
    get_integer2 = (GetIntT)sym("fmi2GetInteger");
    set_boolean2 = (SetIntT)sym("fmi2SetBoolean");
    get_boolean2 = (GetIntT)sym("fmi2GetBoolean");
    do_step2 = (DoStepT)sym("fmi2DoStep");
    get_state = (GetStateT)sym("fmi2GetFMUstate");
    set_state = (SetStateT)sym("fmi2SetFMUstate");
    free_state = (GetStateT)sym("fmi2FreeFMUstate");
    state_size = (StateSizeT)sym("fmi2SerializedFMUstateSize");
    serialize = (SerializeT)sym("fmi2SerializeFMUstate");
    deserialize = (DeserializeT)sym("fmi2DeSerializeFMUstate");
    get_string2 = (StringT)sym("fmi2GetString");
    set_string2 = (StringT)sym("fmi2SetString");
    get_version = (InfoT)sym("fmi2GetVersion");
    get_platform = (InfoT)sym("fmi2GetTypesPlatform");
    printf("INFO %s %s\n", get_version(), get_platform());
}

/* The file: URI of <dir>/resources, percent-encoded as RFC 3986 asks (unreserved bytes and '/' as
 * is; the platform's path separator becomes '/'; a Windows drive path gets file:///Z:/...). */
static void resource_location(const char *dir, char *uri, size_t size)
{
    char raw[MAX_PATH_BYTES + 16];
    size_t k = (size_t)snprintf(uri, size, "file://");
    snprintf(raw, sizeof raw, "%s%cresources", dir, PATH_SEPARATOR);
    if (raw[0] != '/' && raw[0] != PATH_SEPARATOR) uri[k++] = '/';
    for (const unsigned char *p = (const unsigned char *)raw; *p && k + 4 < size; p++) {
        if (*p == PATH_SEPARATOR)
            uri[k++] = '/';
        else if ((*p >= 'a' && *p <= 'z') || (*p >= 'A' && *p <= 'Z') || (*p >= '0' && *p <= '9') ||
                 strchr(URI_PLAIN, *p))
            uri[k++] = (char)*p;
        else
            k += (size_t)snprintf(uri + k, size - k, "%%%02X", *p);
    }
    uri[k] = '\0';
}

/* kind "" instantiates slot `slot` properly; *known = 0 for a kind FMI 2.0 has not */
static Instance instantiate_kind(const char *kind, int slot, int *known)
{
    static fmi2CallbackFunctions cb = {logger, calloc, free, NULL, NULL};
    static fmi2CallbackFunctions no_logger = {NULL, calloc, free, NULL, NULL};
    static fmi2CallbackFunctions no_alloc = {logger, NULL, free, NULL, NULL};
    const char *name = slot_name[slot], *guid = token, *uri = resources;
    const fmi2CallbackFunctions *callbacks = &cb;
    fmi2Type type = fmi2CoSimulation;
    *known = 1;
    if (!strcmp(kind, "null_name")) name = NULL;
    else if (!strcmp(kind, "empty_name")) name = "";
    else if (!strcmp(kind, "wrong_guid")) guid = "{00000000-0000-0000-0000-000000000000}";
    else if (!strcmp(kind, "null_guid")) guid = NULL;
    else if (!strcmp(kind, "null_callbacks")) callbacks = NULL;
    else if (!strcmp(kind, "null_logger")) callbacks = &no_logger;
    else if (!strcmp(kind, "null_alloc")) callbacks = &no_alloc;
    else if (!strcmp(kind, "model_exchange")) type = fmi2ModelExchange;
    else if (!strcmp(kind, "bad_uri")) uri = "file:///nonexistent/%00/resources";
    else if (kind[0] != '\0') {
        *known = 0;
        return NULL;
    }
    return instantiate2(name, type, guid, uri, callbacks, 0, 1);
}

static Status setup(int s, Instance c, double t0)
{
    (void)s;
    return setup2(c, 0, 0.0, t0, 0, 0.0);
}
static Status enter_init(int s, Instance c)
{
    (void)s;
    return enter_init2(c);
}
static Status set_real(Instance c, VR vr, double v) { return set_real2(c, &vr, 1, &v); }
static Status get_reals(Instance c, const VR vrs[], size_t n, double out[]) { return get_real2(c, vrs, n, out); }

enum { AS_INTEGER, AS_ENUMERATION, AS_BOOLEAN }; /* FMI 2.0 gets and sets an Enumeration as an Integer */
static Status set_whole(Instance c, int as, VR vr, long long v)
{
    fmi2Integer x = (fmi2Integer)v;
    return (as == AS_BOOLEAN ? set_boolean2 : set_integer2)(c, &vr, 1, &x);
}
static Status get_wholes(Instance c, int as, const VR vrs[], size_t n, long long out[])
{
    fmi2Integer x[MAX_VRS];
    Status st = (as == AS_BOOLEAN ? get_boolean2 : get_integer2)(c, vrs, n, x);
    for (size_t i = 0; i < n; i++) out[i] = x[i];
    return st;
}
static Status do_step(int s, Instance c, double t, double h)
{
    (void)s;
    return do_step2(c, t, h, 1);
}
static Status string_call(Instance c, int get, VR vr)
{
    const char *text[1] = {"text"};
    return (get ? get_string2 : set_string2)(c, &vr, 1, text);
}

typedef struct {
    fmi2Boolean newDiscreteStatesNeeded, terminateSimulation, nominalsOfContinuousStatesChanged,
        valuesOfContinuousStatesChanged, nextEventTimeDefined;
    double nextEventTime;
} fmi2EventInfo;
typedef Status (*NewDiscreteStatesT)(Instance, fmi2EventInfo *);
typedef Status (*CompletedStep2T)(Instance, fmi2Boolean, fmi2Boolean *, fmi2Boolean *);
static NewDiscreteStatesT new_discrete_states2;
static CompletedStep2T completed_step2;
static void me_functions(void)
{
    enter_event_mode = (InstanceOnlyT)me_sym("fmi2EnterEventMode");
    enter_continuous_time_mode = (InstanceOnlyT)me_sym("fmi2EnterContinuousTimeMode");
    set_time = (SetTimeT)me_sym("fmi2SetTime");
    set_states = (SetVectorT)me_sym("fmi2SetContinuousStates");
    get_vector[VEC_STATES] = (GetVectorT)me_sym("fmi2GetContinuousStates");
    get_vector[VEC_DERIVATIVES] = (GetVectorT)me_sym("fmi2GetDerivatives");
    get_vector[VEC_INDICATORS] = (GetVectorT)me_sym("fmi2GetEventIndicators");
    get_vector[VEC_NOMINALS] = (GetVectorT)me_sym("fmi2GetNominalsOfContinuousStates");
    new_discrete_states2 = (NewDiscreteStatesT)me_sym("fmi2NewDiscreteStates");
    completed_step2 = (CompletedStep2T)me_sym("fmi2CompletedIntegratorStep");
}
/* fmi2NewDiscreteStates; null_args: a NULL fmi2EventInfo */
static Status update_discrete(Instance c, int null_args, EventUpdate *u)
{
    fmi2EventInfo info = {1, 1, 1, 1, 1, -1.0};
    Status st = new_discrete_states2(c, null_args ? NULL : &info);
    u->need_update = info.newDiscreteStatesNeeded, u->terminate = info.terminateSimulation;
    u->nominals_changed = info.nominalsOfContinuousStatesChanged;
    u->values_changed = info.valuesOfContinuousStatesChanged;
    u->next_time_defined = info.nextEventTimeDefined, u->next_time = info.nextEventTime;
    return st;
}
/* fmi2CompletedIntegratorStep(noSetFMUStatePriorToCurrentPoint = true); null_args: NULL out-arguments */
static Status completed_step(Instance c, int null_args, int *enter_event, int *stop)
{
    fmi2Boolean enter = 1, terminate_now = 1;
    Status st = null_args ? completed_step2(c, 1, NULL, NULL) : completed_step2(c, 1, &enter, &terminate_now);
    *enter_event = enter, *stop = terminate_now;
    return st;
}
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
        if (!strcmp(cmd, "instantiate") || !strcmp(cmd, "instantiate_me")) {
            if (n < 2 || nslots == MAX_SLOTS) return 1;
            snprintf(slot_name[nslots], MAX_NAME, "%s", tok[1]);
            inst[nslots] = instantiate_kind(cmd[11] == '_' ? "model_exchange" : "", nslots, &known);
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
