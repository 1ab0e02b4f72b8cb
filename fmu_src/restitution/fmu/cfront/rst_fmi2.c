/* The FMI 2.0 layer of the front (co-simulation and model exchange): every fmi2 function, each a
 * translation of FMI 2.0's types into the core's (rst_lifecycle.c, rst_call.c, rst_values.c, rst_exchange.c, rst_log.c, rst_state.c)
 * and back. What FMI 2.0 alone has lives here: the host's memory callbacks, the fmuResourceLocation URI,
 * fmi2SetupExperiment, the co-simulation status queries, fmi2EventInfo and the '%' escaping its
 * printf-style logger needs. */
#include "rst_instance.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "fmi2Functions.h"

#define MESSAGE_SIZE 2048

/* The FMI 2.0 logger reads the message as a printf format: every '%' is doubled. */
static void emit(void (*host_logger)(void), void *environment, const char *instance_name, rst_status status,
                 const char *category, const char *message)
{
    char escaped[2 * MESSAGE_SIZE];
    size_t k = 0;
    const char *p;
    for (p = message; *p && k + 2 < sizeof escaped; p++) {
        if (*p == '%')
            escaped[k++] = '%';
        escaped[k++] = *p;
    }
    escaped[k] = '\0';
    ((fmi2CallbackLogger)host_logger)(environment, instance_name, (fmi2Status)status, category, escaped);
}

static const rst_api FMI2 = {
    "fmi2", "FMI 2.0", "GUID", "fmi2GetFMUstate", "fmi2SetFMUstate", "fmi2DeSerializeFMUstate",
    "fmi2SerializedFMUstateSize", {"Real", "Integer", "Boolean", "Integer"}, 0, emit};

/* Converters between FMI 2.0's arrays and the core's doubles (a Real is one: no converter). */
static double integer_to_double(fmi2Integer x) { return (double)x; }
static double boolean_to_double(fmi2Boolean x) { return (double)x; }
/* an Integer or Boolean held as a double, converted without undefined behaviour for any double */
static fmi2Integer double_to_integer(double x)
{
    return (x >= -2147483648.0 && x <= 2147483647.0) ? (fmi2Integer)x : 0;
}
static fmi2Boolean double_to_boolean(double x) { return x != 0.0 && !isnan(x); }
RST_CONVERTERS(read_integer, write_integer, fmi2Integer, integer_to_double, double_to_integer)
RST_CONVERTERS(read_boolean, write_boolean, fmi2Boolean, boolean_to_double, double_to_boolean)

/* ------------------------------------------------------------------------------------------------ */
/* Life cycle                                                                                       */
/* ------------------------------------------------------------------------------------------------ */
const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char *fmi2GetVersion(void) { return fmi2Version; }

static void stderr_message(const char *name, const char *message)
{
    fprintf(stderr, "%s [%s]: %s\n", RST_MODEL.identifier, name ? name : "?", message);
}

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation, const fmi2CallbackFunctions *functions,
                              fmi2Boolean visible, fmi2Boolean loggingOn)
{
    rst_instance *inst;
    char *resource_dir = NULL;
    const char *why = NULL;
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
    inst = front_new_instance(&FMI2, (void (*)(void))functions->logger, functions->componentEnvironment,
                              functions->allocateMemory, functions->freeMemory, "fmi2Instantiate", instanceName,
                              loggingOn != fmi2False);
    if (inst == NULL)
        return NULL;
    if (fmuType != fmi2CoSimulation && fmuType != fmi2ModelExchange) {
        rst_log(inst, RST_ERROR, "fmi2Instantiate: fmuType = %d is neither fmi2ModelExchange (0) nor "
                "fmi2CoSimulation (1)", (int)fmuType);
        front_discard_instance(inst);
        return NULL;
    }
    if (fmuResourceLocation != NULL && fmuResourceLocation[0] != '\0') {
        resource_dir = (char *)inst->allocate(strlen(fmuResourceLocation) + 1, 1);
        why = resource_dir == NULL ? "out of memory" : front_decode_file_uri(fmuResourceLocation, resource_dir);
        if (why != NULL) {
            rst_log(inst, RST_ERROR, "fmi2Instantiate: cannot use the resource location %s: %s", fmuResourceLocation,
                    why);
            if (resource_dir != NULL)
                inst->release(resource_dir);
            front_discard_instance(inst);
            return NULL;
        }
    }
    {
        rst_release_fn release = inst->release;
        inst = front_instantiate(inst, "fmi2Instantiate", fmuGUID, resource_dir, visible != fmi2False,
                                 fmuType == fmi2ModelExchange);
        if (resource_dir != NULL)
            release(resource_dir);
    }
    return inst;
}

void fmi2FreeInstance(fmi2Component c) { front_free_instance(c); }

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean loggingOn, size_t nCategories,
                               const fmi2String categories[])
{
    return (fmi2Status)front_set_debug_logging(c, "fmi2SetDebugLogging", loggingOn != fmi2False, nCategories,
                                               categories);
}

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined, fmi2Real tolerance,
                               fmi2Real startTime, fmi2Boolean stopTimeDefined, fmi2Real stopTime)
{
    rst_experiment e;
    e.tolerance_defined = toleranceDefined != fmi2False;
    e.tolerance = tolerance;
    e.start_time = startTime;
    e.stop_time_defined = stopTimeDefined != fmi2False;
    e.stop_time = stopTime;
    return (fmi2Status)front_setup_experiment(c, "fmi2SetupExperiment", &e);
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c)
{
    return (fmi2Status)front_enter_initialization(c, "fmi2EnterInitializationMode", NULL);
}

fmi2Status fmi2ExitInitializationMode(fmi2Component c)
{
    return (fmi2Status)front_exit_initialization(c, "fmi2ExitInitializationMode");
}

fmi2Status fmi2Terminate(fmi2Component c) { return (fmi2Status)front_terminate(c, "fmi2Terminate"); }
fmi2Status fmi2Reset(fmi2Component c) { return (fmi2Status)front_reset(c, "fmi2Reset"); }

/* ------------------------------------------------------------------------------------------------ */
/* Values: an Enumeration is an Integer in FMI 2.0                                                  */
/* ------------------------------------------------------------------------------------------------ */
#define INTEGERS (RST_AS_INTEGER | RST_AS_ENUMERATION)

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Real value[])
{
    return (fmi2Status)front_get(c, "fmi2GetReal", RST_AS_REAL, vr, n, value, n, NULL);
}

fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Integer value[])
{
    return (fmi2Status)front_get(c, "fmi2GetInteger", INTEGERS, vr, n, value, n, write_integer);
}

fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Boolean value[])
{
    return (fmi2Status)front_get(c, "fmi2GetBoolean", RST_AS_BOOLEAN, vr, n, value, n, write_boolean);
}

fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2String value[])
{
    (void)value;
    return (fmi2Status)front_refuse_type(c, "fmi2GetString", "String", vr, n, 0);
}

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Real value[])
{
    return (fmi2Status)front_set(c, "fmi2SetReal", RST_AS_REAL, vr, n, value, n, NULL);
}

fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer value[])
{
    return (fmi2Status)front_set(c, "fmi2SetInteger", INTEGERS, vr, n, value, n, read_integer);
}

fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Boolean value[])
{
    return (fmi2Status)front_set(c, "fmi2SetBoolean", RST_AS_BOOLEAN, vr, n, value, n, read_boolean);
}

fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2String value[])
{
    (void)value;
    return (fmi2Status)front_refuse_type(c, "fmi2SetString", "String", vr, n, 1);
}

/* ------------------------------------------------------------------------------------------------ */
/* FMU states                                                                                       */
/* ------------------------------------------------------------------------------------------------ */
fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *FMUstate)
{
    return (fmi2Status)front_get_state(c, "fmi2GetFMUstate", FMUstate);
}

fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate FMUstate)
{
    return (fmi2Status)front_set_state(c, "fmi2SetFMUstate", FMUstate);
}

fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *FMUstate)
{
    return (fmi2Status)front_free_state(c, "fmi2FreeFMUstate", FMUstate);
}

fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate FMUstate, size_t *size)
{
    return (fmi2Status)front_serialized_size(c, "fmi2SerializedFMUstateSize", FMUstate, size);
}

fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate FMUstate, fmi2Byte serializedState[], size_t size)
{
    return (fmi2Status)front_serialize(c, "fmi2SerializeFMUstate", FMUstate, (unsigned char *)serializedState, size);
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte serializedState[], size_t size,
                                   fmi2FMUstate *FMUstate)
{
    return (fmi2Status)front_deserialize(c, "fmi2DeSerializeFMUstate", (const unsigned char *)serializedState, size,
                                         FMUstate);
}

/* ------------------------------------------------------------------------------------------------ */
/* Stepping and its status                                                                          */
/* ------------------------------------------------------------------------------------------------ */
fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint, fmi2Real communicationStepSize,
                      fmi2Boolean noSetFMUStatePriorToCurrentPoint)
{
    (void)noSetFMUStatePriorToCurrentPoint;
    return (fmi2Status)front_do_step(c, "fmi2DoStep", currentCommunicationPoint, communicationStepSize, NULL,
                                     NULL, NULL, NULL);
}

fmi2Status fmi2CancelStep(fmi2Component c)
{
    ENTER("fmi2CancelStep", 0)
    LEAVE(RST_ERROR); /* no step is ever in progress: fmi2DoStep is synchronous */
}

#define STATUS_MODES (RST_MODE_STEP_COMPLETE | RST_MODE_STEP_FAILED | RST_MODE_TERMINATED)

fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *value)
{
    ENTER("fmi2GetStatus", STATUS_MODES)
    if (value == NULL || s != fmi2DoStepStatus) {
        rst_log(inst, RST_ERROR, "fmi2GetStatus: only fmi2DoStepStatus is provided, with a non-NULL value");
        LEAVE(RST_ERROR);
    }
    *value = (fmi2Status)inst->last_step_status;
    LEAVE(RST_OK);
}

fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *value)
{
    ENTER("fmi2GetRealStatus", STATUS_MODES)
    if (value == NULL || s != fmi2LastSuccessfulTime) {
        rst_log(inst, RST_ERROR, "fmi2GetRealStatus: only fmi2LastSuccessfulTime is provided, with a non-NULL value");
        LEAVE(RST_ERROR);
    }
    *value = inst->last_time;
    LEAVE(RST_OK);
}

fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *value)
{
    (void)s, (void)value;
    return (fmi2Status)front_refuse(c, "fmi2GetIntegerStatus", STATUS_MODES, "no integer status is defined by FMI 2.0");
}

fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *value)
{
    ENTER("fmi2GetBooleanStatus", STATUS_MODES)
    if (value == NULL || s != fmi2Terminated) {
        rst_log(inst, RST_ERROR, "fmi2GetBooleanStatus: only fmi2Terminated is provided, with a non-NULL value");
        LEAVE(RST_ERROR);
    }
    *value = fmi2False; /* the slave never asks to end the simulation */
    LEAVE(RST_OK);
}

fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *value)
{
    (void)s, (void)value;
    return (fmi2Status)front_refuse(c, "fmi2GetStringStatus", STATUS_MODES,
                                    "fmi2PendingStatus does not exist here (no asynchronous steps)");
}

/* ------------------------------------------------------------------------------------------------ */
/* Not provided (canGetDirectionalDerivatives, canInterpolateInputs, maxOutputDerivativeOrder = 0)   */
/* ------------------------------------------------------------------------------------------------ */
fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference vUnknown_ref[], size_t nUnknown,
                                        const fmi2ValueReference vKnown_ref[], size_t nKnown,
                                        const fmi2Real dvKnown[], fmi2Real dvUnknown[])
{
    (void)vUnknown_ref, (void)nUnknown, (void)vKnown_ref, (void)nKnown, (void)dvKnown, (void)dvUnknown;
    return (fmi2Status)front_refuse(c, "fmi2GetDirectionalDerivative", GET_MODES,
                                    "not provided (providesDirectionalDerivative = false)");
}

fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                       const fmi2Integer order[], const fmi2Real value[])
{
    (void)vr, (void)nvr, (void)order, (void)value;
    return (fmi2Status)front_refuse(c, "fmi2SetRealInputDerivatives", SET_MODES,
                                    "not provided (canInterpolateInputs = false)");
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                        const fmi2Integer order[], fmi2Real value[])
{
    (void)vr, (void)nvr, (void)order, (void)value;
    return (fmi2Status)front_refuse(c, "fmi2GetRealOutputDerivatives", STATUS_MODES | RST_MODE_ERROR,
                                    "not provided (maxOutputDerivativeOrder = 0)");
}

/* ------------------------------------------------------------------------------------------------ */
/* Model exchange                                                                                   */
/* ------------------------------------------------------------------------------------------------ */
fmi2Status fmi2EnterEventMode(fmi2Component c) { return (fmi2Status)front_enter_event_mode(c, "fmi2EnterEventMode"); }

fmi2Status fmi2NewDiscreteStates(fmi2Component c, fmi2EventInfo *eventInfo)
{
    rst_event_update update;
    rst_status status;
    if (eventInfo == NULL)
        return (fmi2Status)front_refuse(c, "fmi2NewDiscreteStates", RST_MODE_EVENT, "eventInfo must not be NULL");
    status = front_update_discrete_states(c, "fmi2NewDiscreteStates", &update);
    if (status < RST_ERROR) {
        eventInfo->newDiscreteStatesNeeded = update.discrete_states_need_update ? fmi2True : fmi2False;
        eventInfo->terminateSimulation = update.terminate_simulation ? fmi2True : fmi2False;
        eventInfo->nominalsOfContinuousStatesChanged = update.nominals_changed ? fmi2True : fmi2False;
        eventInfo->valuesOfContinuousStatesChanged = update.states_changed ? fmi2True : fmi2False;
        eventInfo->nextEventTimeDefined = update.next_event_time_defined ? fmi2True : fmi2False;
        eventInfo->nextEventTime = update.next_event_time;
    }
    return (fmi2Status)status;
}

fmi2Status fmi2EnterContinuousTimeMode(fmi2Component c)
{
    return (fmi2Status)front_enter_continuous_time_mode(c, "fmi2EnterContinuousTimeMode");
}

fmi2Status fmi2CompletedIntegratorStep(fmi2Component c, fmi2Boolean noSetFMUStatePriorToCurrentPoint,
                                       fmi2Boolean *enterEventMode, fmi2Boolean *terminateSimulation)
{
    int enter = 0, terminate = 0;
    rst_status status;
    (void)noSetFMUStatePriorToCurrentPoint;
    status = front_completed_integrator_step(c, "fmi2CompletedIntegratorStep", enterEventMode ? &enter : NULL,
                                             terminateSimulation ? &terminate : NULL);
    if (status < RST_ERROR) {
        *enterEventMode = enter ? fmi2True : fmi2False;
        *terminateSimulation = terminate ? fmi2True : fmi2False;
    }
    return (fmi2Status)status;
}

fmi2Status fmi2SetTime(fmi2Component c, fmi2Real time) { return (fmi2Status)front_set_time(c, "fmi2SetTime", time); }

fmi2Status fmi2SetContinuousStates(fmi2Component c, const fmi2Real x[], size_t nx)
{
    return (fmi2Status)front_set_continuous_states(c, "fmi2SetContinuousStates", x, nx);
}

fmi2Status fmi2GetDerivatives(fmi2Component c, fmi2Real derivatives[], size_t nx)
{
    return (fmi2Status)front_get_derivatives(c, "fmi2GetDerivatives", derivatives, nx);
}

fmi2Status fmi2GetEventIndicators(fmi2Component c, fmi2Real eventIndicators[], size_t ni)
{
    return (fmi2Status)front_get_event_indicators(c, "fmi2GetEventIndicators", eventIndicators, ni);
}

fmi2Status fmi2GetContinuousStates(fmi2Component c, fmi2Real x[], size_t nx)
{
    return (fmi2Status)front_get_continuous_states(c, "fmi2GetContinuousStates", x, nx);
}

fmi2Status fmi2GetNominalsOfContinuousStates(fmi2Component c, fmi2Real x_nominal[], size_t nx)
{
    return (fmi2Status)front_get_nominals(c, "fmi2GetNominalsOfContinuousStates", x_nominal, nx);
}
