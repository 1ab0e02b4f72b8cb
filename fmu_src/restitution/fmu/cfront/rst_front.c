/* The FMI 2.0 co-simulation front: see rst_front.h. This file: the instance's life cycle, values
 * and steps (messages: rst_log.c; FMU states: rst_state.c).
 *
 * Which call is allowed in which mode follows the FMI 2.0 standard's co-simulation state table
 * (section 4.2.4). A call that is not allowed, or whose arguments are wrong, returns fmi2Error with a
 * log message and changes nothing: the instance stays in its mode and keeps its values (more
 * forgiving than the standard, which lets a master give up on an instance after any fmi2Error).
 * A backend that reports fmi2Error puts the instance into the error mode (fmi2Reset, fmi2SetFMUstate
 * or fmi2FreeInstance leave it); fmi2Fatal latches it for good.
 */
#include "rst_front_internal.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

/* Relative tolerance of the doStep time check: a master's t differs from the previous t + h by a
 * rounding or two; a skipped or repeated step differs by about h. */
#define TIME_RTOL 1e-9

/* ------------------------------------------------------------------------------------------------ */
/* Accessors for backends                                                                           */
/* ------------------------------------------------------------------------------------------------ */
double *rst_store(rst_instance *inst) { return inst->store; }
void *rst_backend(rst_instance *inst) { return inst->backend; }
const char *rst_instance_name(const rst_instance *inst) { return inst->name; }
rst_mode rst_mode_of(const rst_instance *inst) { return inst->mode; }
double rst_start_time(const rst_instance *inst) { return inst->has_start ? inst->start_time : 0.0; }

static const char *mode_name(rst_mode mode)
{
    switch (mode) {
    case RST_INSTANTIATED: return "instantiated";
    case RST_INITIALIZATION: return "initialization mode";
    case RST_STEP_COMPLETE: return "step mode";
    case RST_STEP_FAILED: return "step failed (after fmi2DoStep returned fmi2Discard)";
    case RST_TERMINATED: return "terminated";
    case RST_ERROR: return "error";
    default: return "fatal error";
    }
}

const char *front_type_name(rst_type type)
{
    return type == RST_REAL ? "Real" : type == RST_INTEGER ? "Integer" : "Boolean";
}

/* ------------------------------------------------------------------------------------------------ */
/* Entering and leaving a call                                                                      */
/* ------------------------------------------------------------------------------------------------ */
rst_instance *front_instance(fmi2Component c)
{
    rst_instance *inst = (rst_instance *)c;
    return (inst != NULL && inst->magic == RST_INSTANCE_MAGIC) ? inst : NULL;
}

void front_lock(rst_instance *inst)
{
#if defined(RST_LOCK_PTHREAD)
    pthread_mutex_lock(&inst->lock);
#elif defined(RST_LOCK_WIN32)
    AcquireSRWLockExclusive(&inst->lock);
#endif
    inst->in_call = 1;
}

void front_unlock(rst_instance *inst)
{
    rst_message *messages = front_take_messages(inst);
    inst->in_call = 0;
#if defined(RST_LOCK_PTHREAD)
    pthread_mutex_unlock(&inst->lock);
#elif defined(RST_LOCK_WIN32)
    ReleaseSRWLockExclusive(&inst->lock);
#endif
    front_deliver_messages(inst, messages);
}

/* Is `function` allowed in the instance's mode? Logs why not. */
int front_allowed(rst_instance *inst, const char *function, unsigned int modes)
{
    if (inst->mode == RST_FATAL) {
        rst_log(inst, fmi2Error, "%s: this instance reported fmi2Fatal earlier and cannot be used any more; "
                "free it (fmi2FreeInstance)", function);
        return 0;
    }
    if (!(modes & (unsigned int)inst->mode)) {
        rst_log(inst, fmi2Error, "%s is not allowed in %s (FMI 2.0 co-simulation state machine)", function,
                mode_name(inst->mode));
        return 0;
    }
    return 1;
}

/* A backend's answer: fmi2Error puts the instance into the error mode, fmi2Fatal latches it. */
fmi2Status front_backend_status(rst_instance *inst, fmi2Status status)
{
    if (status == fmi2Fatal)
        inst->mode = RST_FATAL;
    else if (status == fmi2Error)
        inst->mode = RST_ERROR;
    return status;
}

/* ------------------------------------------------------------------------------------------------ */
/* Values                                                                                           */
/* ------------------------------------------------------------------------------------------------ */
static void reset_store(rst_instance *inst)
{
    size_t i;
    for (i = 0; i < inst->model->n_variables; i++)
        inst->store[i] = inst->model->variables[i].start;
}

void front_describe_value(rst_type type, double value, char *out, size_t size)
{
    if (type == RST_REAL)
        rst_format_double(value, out, size);
    else if (type == RST_BOOLEAN)
        snprintf(out, size, "%s", value != 0.0 ? "True" : "False");
    else
        snprintf(out, size, "%.0f", value);
}

/* Is `value` inside the variable's declared range? (Reals: finite too.) */
int front_in_range(const rst_variable *var, double value)
{
    if (var->type == RST_BOOLEAN)
        return value == 0.0 || value == 1.0;
    if (!isfinite(value))
        return 0;
    if (var->low_open ? !(value > var->low) : !(value >= var->low))
        return 0;
    if (var->high_open ? !(value < var->high) : !(value <= var->high))
        return 0;
    return 1;
}

/* May the host set `var` in the current mode? (FMI 2.0: inputs and parameters in instantiated and
 * initialization mode; in step mode inputs and tunable parameters only.) */
static int settable(const rst_instance *inst, const rst_variable *var)
{
    if (var->causality != RST_INPUT && var->causality != RST_PARAMETER)
        return 0;
    if (inst->mode == RST_STEP_COMPLETE)
        return var->causality == RST_INPUT || var->variability == RST_TUNABLE;
    return 1;
}

/* Checks one value the host wants to set; logs and returns 0 if it is refused. */
static int check_set(rst_instance *inst, const char *function, fmi2ValueReference vr, rst_type type, double value)
{
    const rst_variable *var;
    char text[40];
    if (vr >= inst->model->n_variables) {
        rst_log(inst, fmi2Error, "%s: unknown value reference %u (this FMU has %u variables)", function, vr,
                (unsigned int)inst->model->n_variables);
        return 0;
    }
    var = &inst->model->variables[vr];
    if (var->type != type) {
        rst_log(inst, fmi2Error, "%s: %s (value reference %u) is a %s variable, not %s", function, var->name, vr,
                front_type_name(var->type), front_type_name(type));
        return 0;
    }
    if (!settable(inst, var)) {
        if (var->causality == RST_OUTPUT || var->causality == RST_LOCAL || var->causality == RST_CALCULATEDPARAMETER)
            rst_log(inst, fmi2Error, "%s: %s is %s and cannot be set", function, var->name,
                    var->causality == RST_OUTPUT  ? "an output"
                    : var->causality == RST_LOCAL ? "a local variable"
                                                  : "a calculated parameter");
        else
            rst_log(inst, fmi2Error, "%s: %s is a fixed parameter and cannot be set in %s (only before "
                    "fmi2ExitInitializationMode)", function, var->name, mode_name(inst->mode));
        return 0;
    }
    if (!front_in_range(var, value)) {
        front_describe_value(type, value, text, sizeof text);
        rst_log(inst, fmi2Error, "%s = %s is outside the allowed range: %s", var->name, text,
                var->range_text ? var->range_text : "finite");
        return 0;
    }
    if (inst->model->accept != NULL && inst->model->accept(inst, var, value) != fmi2OK)
        return 0;
    return 1;
}

static fmi2Status set_values(fmi2Component c, const char *function, rst_type type, const fmi2ValueReference vr[],
                             size_t n, const double *values)
{
    size_t i;
    fmi2Status status = fmi2OK;
    ENTER(function, SET_MODES)
    for (i = 0; i < n; i++)
        if (!check_set(inst, function, vr[i], type, values[i]))
            LEAVE(fmi2Error); /* all or nothing: a rejected value leaves every variable as it was */
    for (i = 0; i < n; i++)
        inst->store[vr[i]] = values[i];
    if (inst->model->set != NULL)
        status = front_backend_status(inst, inst->model->set(inst, type, vr, n, values));
    LEAVE(status);
}

static int check_get(rst_instance *inst, const char *function, fmi2ValueReference vr, rst_type type)
{
    if (vr >= inst->model->n_variables) {
        rst_log(inst, fmi2Error, "%s: unknown value reference %u (this FMU has %u variables)", function, vr,
                (unsigned int)inst->model->n_variables);
        return 0;
    }
    if (inst->model->variables[vr].type != type) {
        rst_log(inst, fmi2Error, "%s: %s (value reference %u) is a %s variable, not %s", function,
                inst->model->variables[vr].name, vr, front_type_name(inst->model->variables[vr].type),
                front_type_name(type));
        return 0;
    }
    return 1;
}

/* Reads `n` (at most 64) variables of `type` into `out`: inputs and parameters from the store, outputs,
 * locals and calculated parameters (what the model computes) from the backend in one call. */
static fmi2Status get_values(rst_instance *inst, const char *function, rst_type type, const fmi2ValueReference vr[],
                             size_t n, double *out)
{
    fmi2ValueReference outputs[64];
    double output_values[64];
    size_t position[64];
    size_t i, n_outputs = 0;
    fmi2Status status;
    for (i = 0; i < n; i++) {
        if (!check_get(inst, function, vr[i], type))
            return fmi2Error;
        out[i] = inst->store[vr[i]];
        if (inst->model->variables[vr[i]].causality == RST_OUTPUT ||
            inst->model->variables[vr[i]].causality == RST_LOCAL ||
            inst->model->variables[vr[i]].causality == RST_CALCULATEDPARAMETER) {
            position[n_outputs] = i;
            outputs[n_outputs++] = vr[i];
        }
    }
    if (n_outputs == 0 || inst->model->get_outputs == NULL)
        return fmi2OK;
    status = front_backend_status(inst, inst->model->get_outputs(inst, type, outputs, n_outputs, output_values));
    if (status < fmi2Error)
        for (i = 0; i < n_outputs; i++)
            out[position[i]] = output_values[i];
    return status;
}

/* `out` may hold a non-double type: read into doubles first, in chunks. */
#define GET_TYPED(function, rst_type_, c_type, convert)                                               \
    size_t i0;                                                                                        \
    double buffer[64];                                                                                \
    fmi2Status status = fmi2OK;                                                                       \
    ENTER(function, GET_MODES)                                                                        \
    if (n > 0 && (vr == NULL || value == NULL)) {                                                     \
        rst_log(inst, fmi2Error, "%s: NULL value reference or value array for %u variables", function, \
                (unsigned int)n);                                                                     \
        LEAVE(fmi2Error);                                                                             \
    }                                                                                                 \
    for (i0 = 0; i0 < n; i0 += 64) {                                                                  \
        size_t m = n - i0 < 64 ? n - i0 : 64, j;                                                      \
        fmi2Status s = get_values(inst, function, rst_type_, vr + i0, m, buffer);                     \
        if (s > status)                                                                               \
            status = s;                                                                               \
        if (s >= fmi2Error)                                                                           \
            LEAVE(status);                                                                            \
        for (j = 0; j < m; j++)                                                                       \
            value[i0 + j] = (c_type)convert(buffer[j]);                                               \
    }                                                                                                 \
    LEAVE(status);

static double same(double x) { return x; }
/* an Integer or Boolean held as a double, converted without undefined behaviour for any double */
static fmi2Integer to_integer(double x)
{
    if (!(x >= -2147483648.0 && x <= 2147483647.0))
        return 0;
    return (fmi2Integer)x;
}
static fmi2Boolean to_boolean(double x) { return x != 0.0 && !isnan(x) ? fmi2True : fmi2False; }

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Real value[])
{
    GET_TYPED("fmi2GetReal", RST_REAL, fmi2Real, same)
}

fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Integer value[])
{
    GET_TYPED("fmi2GetInteger", RST_INTEGER, fmi2Integer, to_integer)
}

fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Boolean value[])
{
    GET_TYPED("fmi2GetBoolean", RST_BOOLEAN, fmi2Boolean, to_boolean)
}

fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2String value[])
{
    size_t i;
    ENTER("fmi2GetString", GET_MODES)
    (void)value;
    for (i = 0; i < n; i++) {
        if (vr == NULL || vr[i] >= inst->model->n_variables)
            rst_log(inst, fmi2Error, "fmi2GetString: unknown value reference %u (this FMU has no String variables)",
                    vr ? vr[i] : 0u);
        else
            rst_log(inst, fmi2Error, "fmi2GetString: %s is a %s variable, not String", inst->model->variables[vr[i]].name,
                    front_type_name(inst->model->variables[vr[i]].type));
        LEAVE(fmi2Error);
    }
    LEAVE(fmi2OK);
}

#define SET_TYPED(function, rst_type_, convert)                                                       \
    size_t i0;                                                                                        \
    double buffer[64];                                                                                \
    rst_instance *checked = front_instance(c);                                                           \
    if (checked == NULL)                                                                              \
        return fmi2Error;                                                                             \
    if (n > 0 && (vr == NULL || value == NULL)) {                                                     \
        front_lock(checked);                                                                                \
        rst_log(checked, fmi2Error, "%s: NULL value reference or value array for %u variables", function, \
                (unsigned int)n);                                                                     \
        front_unlock(checked);                                                                              \
        return fmi2Error;                                                                             \
    }                                                                                                 \
    if (n <= 64) {                                                                                    \
        for (i0 = 0; i0 < n; i0++)                                                                    \
            buffer[i0] = convert(value[i0]);                                                          \
        return set_values(c, function, rst_type_, vr, n, buffer);                                     \
    } else { /* more than 64: all-or-nothing needs them in one piece */                              \
        double *all = (double *)checked->allocate(n, sizeof(double));                                 \
        fmi2Status status;                                                                            \
        if (all == NULL) {                                                                            \
            front_lock(checked);                                                                            \
            rst_log(checked, fmi2Error, "%s: out of memory for %u values", function, (unsigned int)n); \
            front_unlock(checked);                                                                          \
            return fmi2Error;                                                                         \
        }                                                                                             \
        for (i0 = 0; i0 < n; i0++)                                                                    \
            all[i0] = convert(value[i0]);                                                             \
        status = set_values(c, function, rst_type_, vr, n, all);                                      \
        checked->release(all);                                                                        \
        return status;                                                                                \
    }

static double from_boolean(fmi2Boolean b) { return (double)b; }
static double from_integer(fmi2Integer i) { return (double)i; }

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Real value[])
{
    SET_TYPED("fmi2SetReal", RST_REAL, same)
}

fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer value[])
{
    SET_TYPED("fmi2SetInteger", RST_INTEGER, from_integer)
}

fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Boolean value[])
{
    SET_TYPED("fmi2SetBoolean", RST_BOOLEAN, from_boolean)
}

fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2String value[])
{
    size_t i;
    ENTER("fmi2SetString", SET_MODES)
    (void)value;
    for (i = 0; i < n; i++) {
        rst_log(inst, fmi2Error, "fmi2SetString: value reference %u is not a String variable (this FMU has none)",
                vr ? vr[i] : 0u);
        LEAVE(fmi2Error);
    }
    LEAVE(fmi2OK);
}

/* ------------------------------------------------------------------------------------------------ */
/* Life cycle                                                                                       */
/* ------------------------------------------------------------------------------------------------ */
const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char *fmi2GetVersion(void) { return fmi2Version; }

static int hex_value(char ch)
{
    if (ch >= '0' && ch <= '9') return ch - '0';
    if (ch >= 'a' && ch <= 'f') return ch - 'a' + 10;
    if (ch >= 'A' && ch <= 'F') return ch - 'A' + 10;
    return -1;
}

/* fmuResourceLocation (file:///p, file:/p, file://localhost/p, percent-encoded) -> the path p in
 * `path` (room for strlen(uri) + 1 bytes). Returns NULL, or why it is not a file URI one can decode.
 * Windows drive paths (file:///C:/x) lose their leading slash. A '%' not followed by two hex digits
 * is taken literally (hosts that do not encode their paths exist); an encoded NUL is refused. */
static const char *decode_resource_location(const char *uri, char *path)
{
    const char *p = uri;
    size_t n = 0;
    if (strncmp(p, "file://localhost/", 17) == 0)
        p += 16;
    else if (strncmp(p, "file:///", 8) == 0)
        p += 7;
    else if (strncmp(p, "file:/", 6) == 0)
        p += 5;
    else
        return "it is not a file: URI";
    if (((p[1] >= 'A' && p[1] <= 'Z') || (p[1] >= 'a' && p[1] <= 'z')) && p[2] == ':')
        p++; /* /C:/... */
    for (; *p; p++) {
        int hi = *p == '%' ? hex_value(p[1]) : -1, lo = hi < 0 ? -1 : hex_value(p[2]);
        if (hi >= 0 && lo >= 0) {
            if (hi == 0 && lo == 0)
                return "it encodes a NUL character";
            path[n++] = (char)(hi * 16 + lo);
            p += 2;
        } else {
            path[n++] = *p;
        }
    }
    while (n > 1 && (path[n - 1] == '/' || path[n - 1] == '\\'))
        n--;
    path[n] = '\0';
    return NULL;
}

static void stderr_message(const char *name, const char *message)
{
    fprintf(stderr, "%s [%s]: %s\n", RST_MODEL.identifier, name ? name : "?", message);
}

static void free_memory(rst_instance *inst)
{
    fmi2CallbackFreeMemory release = inst->release;
    front_free_states(inst);
    front_deliver_messages(inst, front_take_messages(inst));
#if defined(RST_LOCK_PTHREAD)
    pthread_mutex_destroy(&inst->lock);
#endif
    inst->magic = 0;
    release(inst->backend);
    release(inst->store);
    release(inst->name);
    release(inst);
}

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation, const fmi2CallbackFunctions *functions,
                              fmi2Boolean visible, fmi2Boolean loggingOn)
{
    const rst_model *model = &RST_MODEL;
    rst_instance *inst;
    char *resource_dir = NULL;
    const char *why = NULL;
    size_t i;
    fmi2Status status;
    if (functions == NULL || functions->logger == NULL) {
        stderr_message(instanceName, "fmi2Instantiate: no logger in the callback functions (NULL); not instantiated");
        return NULL;
    }
    if (functions->allocateMemory == NULL || functions->freeMemory == NULL) {
        functions->logger(functions->componentEnvironment, instanceName ? instanceName : "", fmi2Error,
                          "logStatusError", "fmi2Instantiate: allocateMemory or freeMemory is NULL; not instantiated");
        return NULL;
    }
    if (instanceName == NULL || instanceName[0] == '\0') {
        functions->logger(functions->componentEnvironment, "", fmi2Error, "logStatusError",
                          "fmi2Instantiate: the instance name is NULL or empty; not instantiated");
        return NULL;
    }
    inst = (rst_instance *)functions->allocateMemory(1, sizeof *inst);
    if (inst == NULL)
        return NULL;
    inst->model = model;
    inst->logger = functions->logger;
    inst->allocate = functions->allocateMemory;
    inst->release = functions->freeMemory;
    inst->environment = functions->componentEnvironment;
    inst->logging_on = loggingOn != fmi2False;
    inst->categories = RST_ALL_CATEGORIES;
    inst->mode = RST_INSTANTIATED;
    inst->last_step_status = fmi2OK;
    inst->name = (char *)inst->allocate(strlen(instanceName) + 1, 1);
    inst->store = (double *)inst->allocate(model->n_variables ? model->n_variables : 1, sizeof(double));
    inst->backend = inst->allocate(model->backend_size ? model->backend_size : 1, 1);
    if (inst->name == NULL || inst->store == NULL || inst->backend == NULL) {
        functions->logger(functions->componentEnvironment, instanceName, fmi2Error, "logStatusError",
                          "fmi2Instantiate: out of memory");
        if (inst->name) inst->release(inst->name);
        if (inst->store) inst->release(inst->store);
        if (inst->backend) inst->release(inst->backend);
        inst->release(inst);
        return NULL;
    }
    strcpy(inst->name, instanceName);
    memset(inst->backend, 0, model->backend_size ? model->backend_size : 1);
    for (i = 0; i < model->n_variables; i++)
        inst->n_state += model->variables[i].state != 0;
    inst->pending_end = &inst->pending;
#if defined(RST_LOCK_PTHREAD)
    pthread_mutex_init(&inst->lock, NULL);
#elif defined(RST_LOCK_WIN32)
    InitializeSRWLock(&inst->lock);
#endif
    inst->magic = RST_INSTANCE_MAGIC;
    reset_store(inst);

    if (fmuType != fmi2CoSimulation) {
        rst_log(inst, fmi2Error, "fmi2Instantiate: %s is a co-simulation FMU; model exchange is not provided",
                model->identifier);
        free_memory(inst);
        return NULL;
    }
    if (fmuGUID == NULL || strcmp(fmuGUID, model->guid) != 0) {
        rst_log(inst, fmi2Error, "fmi2Instantiate: GUID %s does not match this FMU's %s (modelDescription.xml "
                "of another FMU or another build?)", fmuGUID ? fmuGUID : "(NULL)", model->guid);
        free_memory(inst);
        return NULL;
    }
    if (fmuResourceLocation != NULL && fmuResourceLocation[0] != '\0') {
        resource_dir = (char *)inst->allocate(strlen(fmuResourceLocation) + 1, 1);
        why = resource_dir == NULL ? "out of memory" : decode_resource_location(fmuResourceLocation, resource_dir);
        if (why != NULL) {
            rst_log(inst, fmi2Error, "fmi2Instantiate: cannot use the resource location %s: %s", fmuResourceLocation,
                    why);
            if (resource_dir != NULL)
                inst->release(resource_dir);
            free_memory(inst);
            return NULL;
        }
    }
    status = model->instantiate ? model->instantiate(inst, resource_dir, visible) : fmi2OK;
    if (resource_dir != NULL)
        inst->release(resource_dir);
    if (status != fmi2OK) {
        free_memory(inst);
        return NULL;
    }
    return inst;
}

void fmi2FreeInstance(fmi2Component c)
{
    rst_instance *inst = front_instance(c);
    if (inst == NULL)
        return;
    front_lock(inst);
    if (inst->model->free_instance != NULL)
        inst->model->free_instance(inst);
    front_unlock(inst);
    free_memory(inst);
}

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined, fmi2Real tolerance,
                               fmi2Real startTime, fmi2Boolean stopTimeDefined, fmi2Real stopTime)
{
    ENTER("fmi2SetupExperiment", RST_INSTANTIATED)
    if (!isfinite(startTime) || (stopTimeDefined && !(stopTime >= startTime && stopTime <= DBL_MAX)) ||
        (toleranceDefined && !(tolerance > 0.0 && tolerance <= DBL_MAX))) {
        char t0[40], t1[40], tol[40];
        rst_format_double(startTime, t0, sizeof t0);
        rst_format_double(stopTime, t1, sizeof t1);
        rst_format_double(tolerance, tol, sizeof tol);
        rst_log(inst, fmi2Error, "fmi2SetupExperiment: startTime = %s%s%s%s%s: the start time must be finite, a "
                "defined stop time finite and >= the start time, a defined tolerance finite and > 0", t0,
                stopTimeDefined ? ", stopTime = " : "", stopTimeDefined ? t1 : "",
                toleranceDefined ? ", tolerance = " : "", toleranceDefined ? tol : "");
        LEAVE(fmi2Error);
    }
    if (inst->model->setup_experiment != NULL) {
        fmi2Status s = front_backend_status(inst, inst->model->setup_experiment(inst, toleranceDefined, tolerance,
                                                                            startTime, stopTimeDefined, stopTime));
        if (s >= fmi2Error)
            LEAVE(s);
        status_ = s;
    }
    inst->has_start = 1;
    inst->start_time = startTime;
    LEAVE(status_);
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c)
{
    fmi2Status status = fmi2OK;
    ENTER("fmi2EnterInitializationMode", RST_INSTANTIATED)
    if (inst->model->enter_initialization != NULL)
        status = front_backend_status(inst, inst->model->enter_initialization(inst));
    if (status < fmi2Error)
        inst->mode = RST_INITIALIZATION;
    LEAVE(status);
}

fmi2Status fmi2ExitInitializationMode(fmi2Component c)
{
    fmi2Status status = fmi2OK;
    ENTER("fmi2ExitInitializationMode", RST_INITIALIZATION)
    if (inst->model->exit_initialization != NULL)
        status = front_backend_status(inst, inst->model->exit_initialization(inst));
    if (status < fmi2Error) {
        inst->mode = RST_STEP_COMPLETE;
        inst->has_time = inst->has_start;
        inst->next_time = inst->start_time;
        inst->last_time = inst->start_time;
    }
    LEAVE(status);
}

fmi2Status fmi2Terminate(fmi2Component c)
{
    fmi2Status status = fmi2OK;
    ENTER("fmi2Terminate", RST_STEP_COMPLETE | RST_STEP_FAILED)
    if (inst->model->terminate != NULL)
        status = front_backend_status(inst, inst->model->terminate(inst));
    if (status < fmi2Error)
        inst->mode = RST_TERMINATED;
    LEAVE(status);
}

fmi2Status fmi2Reset(fmi2Component c)
{
    fmi2Status status = fmi2OK;
    ENTER("fmi2Reset", ANY_LIVE_MODE)
    reset_store(inst);
    inst->mode = RST_INSTANTIATED;
    inst->has_start = inst->has_time = 0;
    inst->start_time = inst->next_time = inst->last_time = 0.0;
    inst->last_step_status = fmi2OK;
    if (inst->model->reset != NULL)
        status = front_backend_status(inst, inst->model->reset(inst));
    LEAVE(status);
}

/* ------------------------------------------------------------------------------------------------ */
/* Stepping                                                                                         */
/* ------------------------------------------------------------------------------------------------ */
fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint, fmi2Real communicationStepSize,
                      fmi2Boolean noSetFMUStatePriorToCurrentPoint)
{
    double t = currentCommunicationPoint, h = communicationStepSize;
    fmi2Status status = fmi2OK;
    char t_text[40], h_text[40], want[40];
    ENTER("fmi2DoStep", RST_STEP_COMPLETE)
    (void)noSetFMUStatePriorToCurrentPoint;
    if (!isfinite(t) || !isfinite(h) || !(h > 0.0) || !isfinite(t + h)) {
        rst_format_double(t, t_text, sizeof t_text);
        rst_format_double(h, h_text, sizeof h_text);
        rst_log(inst, fmi2Error, "fmi2DoStep: currentCommunicationPoint = %s, communicationStepSize = %s: the step "
                "size must be finite and > 0, the time finite", t_text, h_text);
        LEAVE(fmi2Error);
    }
    if (inst->has_time) {
        double scale = fabs(inst->next_time) > fabs(h) ? fabs(inst->next_time) : fabs(h);
        if (fabs(t - inst->next_time) > TIME_RTOL * scale) {
            rst_format_double(t, t_text, sizeof t_text);
            rst_format_double(inst->next_time, want, sizeof want);
            rst_log(inst, fmi2Error, "fmi2DoStep: currentCommunicationPoint = %s does not continue the previous "
                    "step, which ended at %s (a step cannot be skipped or repeated without fmi2SetFMUstate)",
                    t_text, want);
            LEAVE(fmi2Error);
        }
    }
    if (inst->model->do_step != NULL)
        status = front_backend_status(inst, inst->model->do_step(inst, t, h));
    inst->last_step_status = status;
    if (status <= fmi2Warning) {
        inst->has_time = 1;
        inst->next_time = t + h;
        inst->last_time = t + h;
    } else if (status == fmi2Discard) {
        inst->mode = RST_STEP_FAILED;
        inst->last_time = t;
    }
    LEAVE(status);
}

fmi2Status fmi2CancelStep(fmi2Component c)
{
    ENTER("fmi2CancelStep", 0)
    LEAVE(fmi2Error); /* no step is ever in progress: fmi2DoStep is synchronous */
}

fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *value)
{
    ENTER("fmi2GetStatus", RST_STEP_COMPLETE | RST_STEP_FAILED | RST_TERMINATED)
    if (value == NULL || s != fmi2DoStepStatus) {
        rst_log(inst, fmi2Error, "fmi2GetStatus: only fmi2DoStepStatus is provided, with a non-NULL value");
        LEAVE(fmi2Error);
    }
    *value = inst->last_step_status;
    LEAVE(fmi2OK);
}

fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *value)
{
    ENTER("fmi2GetRealStatus", RST_STEP_COMPLETE | RST_STEP_FAILED | RST_TERMINATED)
    if (value == NULL || s != fmi2LastSuccessfulTime) {
        rst_log(inst, fmi2Error, "fmi2GetRealStatus: only fmi2LastSuccessfulTime is provided, with a non-NULL value");
        LEAVE(fmi2Error);
    }
    *value = inst->last_time;
    LEAVE(fmi2OK);
}

fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *value)
{
    ENTER("fmi2GetIntegerStatus", RST_STEP_COMPLETE | RST_STEP_FAILED | RST_TERMINATED)
    (void)s;
    (void)value;
    rst_log(inst, fmi2Error, "fmi2GetIntegerStatus: no integer status is defined by FMI 2.0");
    LEAVE(fmi2Error);
}

fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *value)
{
    ENTER("fmi2GetBooleanStatus", RST_STEP_COMPLETE | RST_STEP_FAILED | RST_TERMINATED)
    if (value == NULL || s != fmi2Terminated) {
        rst_log(inst, fmi2Error, "fmi2GetBooleanStatus: only fmi2Terminated is provided, with a non-NULL value");
        LEAVE(fmi2Error);
    }
    *value = fmi2False; /* the slave never asks to end the simulation */
    LEAVE(fmi2OK);
}

fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *value)
{
    ENTER("fmi2GetStringStatus", RST_STEP_COMPLETE | RST_STEP_FAILED | RST_TERMINATED)
    (void)s;
    (void)value;
    rst_log(inst, fmi2Error, "fmi2GetStringStatus: fmi2PendingStatus does not exist here (no asynchronous steps)");
    LEAVE(fmi2Error);
}

/* ------------------------------------------------------------------------------------------------ */
/* Not provided (canGetDirectionalDerivatives, canInterpolateInputs, maxOutputDerivativeOrder = 0)   */
/* ------------------------------------------------------------------------------------------------ */
fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference vUnknown_ref[], size_t nUnknown,
                                        const fmi2ValueReference vKnown_ref[], size_t nKnown,
                                        const fmi2Real dvKnown[], fmi2Real dvUnknown[])
{
    ENTER("fmi2GetDirectionalDerivative", GET_MODES)
    (void)vUnknown_ref, (void)nUnknown, (void)vKnown_ref, (void)nKnown, (void)dvKnown, (void)dvUnknown;
    rst_log(inst, fmi2Error, "fmi2GetDirectionalDerivative is not provided (providesDirectionalDerivative = false)");
    LEAVE(fmi2Error);
}

fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                       const fmi2Integer order[], const fmi2Real value[])
{
    ENTER("fmi2SetRealInputDerivatives", SET_MODES)
    (void)vr, (void)nvr, (void)order, (void)value;
    rst_log(inst, fmi2Error, "fmi2SetRealInputDerivatives is not provided (canInterpolateInputs = false)");
    LEAVE(fmi2Error);
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                        const fmi2Integer order[], fmi2Real value[])
{
    ENTER("fmi2GetRealOutputDerivatives", RST_STEP_COMPLETE | RST_STEP_FAILED | RST_TERMINATED | RST_ERROR)
    (void)vr, (void)nvr, (void)order, (void)value;
    rst_log(inst, fmi2Error, "fmi2GetRealOutputDerivatives is not provided (maxOutputDerivativeOrder = 0)");
    LEAVE(fmi2Error);
}

