/* The scripted FMI host: the thin wrappers of the FMI 3.0 calls (those that differ
 * between the versions).
 * Part of fmi_script_host.c (its usage is there), included once by it: kept apart so that each file
 * stays readable; it relies on the types and helpers defined before the #include. */
#ifndef FMI_SCRIPT_HOST_FMI3_H
#define FMI_SCRIPT_HOST_FMI3_H

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
    bool event_mode = false, early_return = false;
    VR required[1] = {0};
    size_t n_required = 0;
    *known = 1;
    if (!strcmp(kind, "null_name")) name = NULL;
    else if (!strcmp(kind, "empty_name")) name = "";
    else if (!strcmp(kind, "wrong_guid")) guid = "{00000000-0000-0000-0000-000000000000}";
    else if (!strcmp(kind, "null_guid")) guid = NULL;
    else if (!strcmp(kind, "wrong_guid_no_logger")) guid = "{00000000-0000-0000-0000-000000000000}", log = NULL;
    else if (!strcmp(kind, "event_mode")) event_mode = true;
    else if (!strcmp(kind, "events")) event_mode = early_return = true; /* instantiate_ev: both, legitimately */
    else if (!strcmp(kind, "intermediate_update")) n_required = 1;
    else if (!strcmp(kind, "model_exchange")) return instantiate_me(name, guid, resources, false, true, environment, log);
    else if (!strcmp(kind, "scheduled_execution"))
        return instantiate_se(name, guid, resources, false, true, environment, log, NULL, NULL, NULL);
    else if (kind[0] != '\0') {
        *known = 0;
        return NULL;
    }
    return instantiate_cs(name, guid, resources, false, true, event_mode, early_return, required, n_required,
                          environment, log, NULL);
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
static InstanceOnlyT enter_step_mode3; /* co-simulation with event mode: event mode -> step mode */
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
    enter_step_mode3 = (InstanceOnlyT)me_sym("fmi3EnterStepMode");
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


#endif /* FMI_SCRIPT_HOST_FMI3_H */
