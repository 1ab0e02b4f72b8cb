/* The scripted FMI host: the thin wrappers of the FMI 2.0 calls (those that differ
 * between the versions).
 * Part of fmi_script_host.c (its usage is there), included once by it: kept apart so that each file
 * stays readable; it relies on the types and helpers defined before the #include. */
#ifndef FMI_SCRIPT_HOST_FMI2_H
#define FMI_SCRIPT_HOST_FMI2_H

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

#endif /* FMI_SCRIPT_HOST_FMI2_H */
