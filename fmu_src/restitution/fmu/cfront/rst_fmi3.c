/* The FMI 3.0 layer of the front (co-simulation and model exchange): every fmi3 function, each a
 * translation of FMI 3.0's types into the core's (rst_lifecycle.c, rst_call.c, rst_values.c, rst_exchange.c, rst_log.c, rst_state.c)
 * and back. What FMI 3.0 alone has lives here: the independent variable `time` (value reference
 * n_variables, after the table), Enumerations got and set with the Int64 functions, the instantiation
 * token and resource path, the experiment given to fmi3EnterInitializationMode, fmi3DoStep's and
 * fmi3UpdateDiscreteStates' out-arguments, and co-simulation's event mode and early return for a model
 * that offers them (rst_model.do_step_to_event: eventModeUsed and earlyReturnAllowed are honoured; the
 * other models refuse eventModeUsed and never return early). The FMU has no clocks, intermediate
 * updates or configuration mode and is not offered for scheduled execution: those functions exist (a
 * host may look them up) and refuse with a message. */
#include "rst_instance.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi3Functions.h"

/* FMI 3.0's logger takes the message as it is (no format) and may be absent. */
static void emit(void (*host_logger)(void), void *environment, const char *instance_name, rst_status status,
                 const char *category, const char *message)
{
    (void)instance_name; /* the host knows which instance its environment stands for */
    if (host_logger != NULL)
        ((fmi3LogMessageCallback)host_logger)(environment, (fmi3Status)status, category, message);
}

static const rst_api FMI3 = {
    "fmi3", "FMI 3.0", "instantiation token", "fmi3GetFMUState", "fmi3SetFMUState", "fmi3DeserializeFMUState",
    "fmi3SerializedFMUStateSize", {"Float64", "Int32", "Boolean", "Enumeration"}, 1, emit};

/* Converters between FMI 3.0's arrays and the core's doubles (a Float64 is one: no converter). */
static double int32_to_double(fmi3Int32 x) { return (double)x; }
static double int64_to_double(fmi3Int64 x) { return (double)x; }
static double boolean_to_double(fmi3Boolean x) { return x ? 1.0 : 0.0; }
/* integers held as doubles, converted without undefined behaviour for any double */
static fmi3Int32 double_to_int32(double x)
{
    return (x >= -2147483648.0 && x <= 2147483647.0) ? (fmi3Int32)x : 0;
}
static fmi3Int64 double_to_int64(double x)
{
    return (x >= -9223372036854775808.0 && x < 9223372036854775808.0) ? (fmi3Int64)x : 0;
}
static fmi3Boolean double_to_boolean(double x) { return x != 0.0 && !isnan(x); }
RST_CONVERTERS(read_int32, write_int32, fmi3Int32, int32_to_double, double_to_int32)
RST_CONVERTERS(read_int64, write_int64, fmi3Int64, int64_to_double, double_to_int64)
RST_CONVERTERS(read_boolean, write_boolean, fmi3Boolean, boolean_to_double, double_to_boolean)

#define ANY_MODE (RST_MODE_INSTANTIATED | RST_MODE_INITIALIZATION | RST_MODE_STEP_COMPLETE | RST_MODE_STEP_FAILED | \
                  RST_MODE_TERMINATED | RST_MODE_ERROR)
#define AFTER_INSTANTIATION (ANY_MODE & ~(unsigned int)RST_MODE_INSTANTIATED)

/* ------------------------------------------------------------------------------------------------ */
/* Life cycle                                                                                       */
/* ------------------------------------------------------------------------------------------------ */
const char *fmi3GetVersion(void) { return fmi3Version; }

static void stderr_message(const char *name, const char *message)
{
    fprintf(stderr, "%s [%s]: %s\n", RST_MODEL.identifier, name ? name : "?", message);
}

/* A message from an instantiation function before there is an instance. */
static void instantiation_message(fmi3LogMessageCallback logger, fmi3InstanceEnvironment environment,
                                  const char *name, const char *message)
{
    if (logger != NULL)
        logger(environment, fmi3Error, "logStatusError", message);
    else
        stderr_message(name, message);
}

/* A new instance named `name` (NULL, with a message, for a NULL or empty name or out of memory). */
static rst_instance *new_instance(const char *function, fmi3String name, fmi3Boolean logging_on,
                                  fmi3InstanceEnvironment environment, fmi3LogMessageCallback logger)
{
    char message[96];
    if (name == NULL || name[0] == '\0') {
        snprintf(message, sizeof message, "%s: the instance name is NULL or empty; not instantiated", function);
        instantiation_message(logger, environment, "", message);
        return NULL;
    }
    return front_new_instance(&FMI3, (void (*)(void))logger, environment, calloc, free, function, name, logging_on);
}

/* The instance `inst` given its resource path (a directory with a trailing separator, or NULL) as the
 * backend wants it: the directory itself. NULL: refused (freed, with a message). */
static rst_instance *instantiate(rst_instance *inst, const char *function, fmi3String token, fmi3String resourcePath,
                                 fmi3Boolean visible, int model_exchange)
{
    char *resource_dir = NULL;
    rst_release_fn release = inst->release;
    if (resourcePath != NULL && resourcePath[0] != '\0') {
        size_t n = strlen(resourcePath);
        resource_dir = (char *)inst->allocate(n + 1, 1);
        if (resource_dir == NULL) {
            rst_log(inst, RST_ERROR, "%s: out of memory", function);
            front_discard_instance(inst);
            return NULL;
        }
        memcpy(resource_dir, resourcePath, n + 1);
        while (n > 1 && (resource_dir[n - 1] == '/' || resource_dir[n - 1] == '\\'))
            resource_dir[--n] = '\0';
    }
    inst = front_instantiate(inst, function, token, resource_dir, visible, model_exchange);
    if (resource_dir != NULL)
        release(resource_dir);
    return inst;
}

fmi3Instance fmi3InstantiateCoSimulation(fmi3String instanceName, fmi3String instantiationToken,
                                         fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                         fmi3Boolean eventModeUsed, fmi3Boolean earlyReturnAllowed,
                                         const fmi3ValueReference requiredIntermediateVariables[],
                                         size_t nRequiredIntermediateVariables,
                                         fmi3InstanceEnvironment instanceEnvironment,
                                         fmi3LogMessageCallback logMessage,
                                         fmi3IntermediateUpdateCallback intermediateUpdate)
{
    rst_instance *inst;
    int events = RST_MODEL.do_step_to_event != NULL; /* hasEventMode and mightReturnEarlyFromDoStep */
    (void)requiredIntermediateVariables, (void)intermediateUpdate; /* refused below where asked for */
    inst = new_instance("fmi3InstantiateCoSimulation", instanceName, loggingOn, instanceEnvironment, logMessage);
    if (inst == NULL)
        return NULL;
    if ((eventModeUsed && !events) || nRequiredIntermediateVariables > 0) {
        rst_log(inst, RST_ERROR, "fmi3InstantiateCoSimulation: %s is not provided by %s (%s = false); not "
                "instantiated", nRequiredIntermediateVariables > 0 ? "intermediate update" : "event mode",
                inst->model->identifier,
                nRequiredIntermediateVariables > 0 ? "providesIntermediateUpdate" : "hasEventMode");
        front_discard_instance(inst);
        return NULL;
    }
    inst = instantiate(inst, "fmi3InstantiateCoSimulation", instantiationToken, resourcePath, visible, 0);
    if (inst != NULL && events) { /* (a model without events ignores earlyReturnAllowed: it never returns early) */
        inst->event_mode_used = eventModeUsed != 0;
        inst->early_return_allowed = earlyReturnAllowed != 0;
    }
    return inst;
}

fmi3Instance fmi3InstantiateModelExchange(fmi3String instanceName, fmi3String instantiationToken,
                                          fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                          fmi3InstanceEnvironment instanceEnvironment,
                                          fmi3LogMessageCallback logMessage)
{
    rst_instance *inst = new_instance("fmi3InstantiateModelExchange", instanceName, loggingOn, instanceEnvironment,
                                      logMessage);
    if (inst == NULL)
        return NULL;
    return instantiate(inst, "fmi3InstantiateModelExchange", instantiationToken, resourcePath, visible, 1);
}

fmi3Instance fmi3InstantiateScheduledExecution(fmi3String instanceName, fmi3String instantiationToken,
                                               fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                               fmi3InstanceEnvironment instanceEnvironment,
                                               fmi3LogMessageCallback logMessage, fmi3ClockUpdateCallback clockUpdate,
                                               fmi3LockPreemptionCallback lockPreemption,
                                               fmi3UnlockPreemptionCallback unlockPreemption)
{
    (void)instantiationToken, (void)resourcePath, (void)visible, (void)loggingOn, (void)clockUpdate;
    (void)lockPreemption, (void)unlockPreemption;
    instantiation_message(logMessage, instanceEnvironment, instanceName,
                          "fmi3InstantiateScheduledExecution: this FMU is a co-simulation FMU; scheduled execution "
                          "is not provided");
    return NULL;
}

void fmi3FreeInstance(fmi3Instance instance) { front_free_instance(instance); }

fmi3Status fmi3SetDebugLogging(fmi3Instance instance, fmi3Boolean loggingOn, size_t nCategories,
                               const fmi3String categories[])
{
    return (fmi3Status)front_set_debug_logging(instance, "fmi3SetDebugLogging", loggingOn, nCategories, categories);
}

fmi3Status fmi3EnterInitializationMode(fmi3Instance instance, fmi3Boolean toleranceDefined, fmi3Float64 tolerance,
                                       fmi3Float64 startTime, fmi3Boolean stopTimeDefined, fmi3Float64 stopTime)
{
    rst_experiment e;
    e.tolerance_defined = toleranceDefined;
    e.tolerance = tolerance;
    e.start_time = startTime;
    e.stop_time_defined = stopTimeDefined;
    e.stop_time = stopTime;
    return (fmi3Status)front_enter_initialization(instance, "fmi3EnterInitializationMode", &e);
}

fmi3Status fmi3ExitInitializationMode(fmi3Instance instance)
{
    return (fmi3Status)front_exit_initialization(instance, "fmi3ExitInitializationMode");
}

/* model exchange, and co-simulation instantiated with eventModeUsed (the others are refused) */
fmi3Status fmi3EnterEventMode(fmi3Instance instance)
{
    return (fmi3Status)front_enter_event_mode(instance, "fmi3EnterEventMode");
}

fmi3Status fmi3Terminate(fmi3Instance instance) { return (fmi3Status)front_terminate(instance, "fmi3Terminate"); }
fmi3Status fmi3Reset(fmi3Instance instance) { return (fmi3Status)front_reset(instance, "fmi3Reset"); }

/* ------------------------------------------------------------------------------------------------ */
/* Values                                                                                           */
/* ------------------------------------------------------------------------------------------------ */
#define GET(name, kinds, c_type, write)                                                                          \
    fmi3Status fmi3Get##name(fmi3Instance instance, const fmi3ValueReference valueReferences[],                 \
                             size_t nValueReferences, c_type values[], size_t nValues)                         \
    {                                                                                                          \
        return (fmi3Status)front_get(instance, "fmi3Get" #name, kinds, valueReferences, nValueReferences,      \
                                     values, nValues, write);                                                  \
    }
#define SET(name, kinds, c_type, read)                                                                           \
    fmi3Status fmi3Set##name(fmi3Instance instance, const fmi3ValueReference valueReferences[],                 \
                             size_t nValueReferences, const c_type values[], size_t nValues)                   \
    {                                                                                                          \
        return (fmi3Status)front_set(instance, "fmi3Set" #name, kinds, valueReferences, nValueReferences,      \
                                     values, nValues, read);                                                   \
    }
/* The types this FMU has no variables of: every value reference is refused. */
#define NO_GET(name, c_type)                                                                                     \
    fmi3Status fmi3Get##name(fmi3Instance instance, const fmi3ValueReference valueReferences[],                 \
                             size_t nValueReferences, c_type values[], size_t nValues)                         \
    {                                                                                                          \
        (void)values, (void)nValues;                                                                           \
        return (fmi3Status)front_refuse_type(instance, "fmi3Get" #name, #name, valueReferences,                \
                                             nValueReferences, 0);                                             \
    }
#define NO_SET(name, c_type)                                                                                     \
    fmi3Status fmi3Set##name(fmi3Instance instance, const fmi3ValueReference valueReferences[],                 \
                             size_t nValueReferences, const c_type values[], size_t nValues)                   \
    {                                                                                                          \
        (void)values, (void)nValues;                                                                           \
        return (fmi3Status)front_refuse_type(instance, "fmi3Set" #name, #name, valueReferences,                \
                                             nValueReferences, 1);                                             \
    }

GET(Float64, RST_AS_REAL, fmi3Float64, NULL)
GET(Int32, RST_AS_INTEGER, fmi3Int32, write_int32)
GET(Int64, RST_AS_ENUMERATION, fmi3Int64, write_int64) /* Enumerations are got and set as Int64 */
GET(Boolean, RST_AS_BOOLEAN, fmi3Boolean, write_boolean)
SET(Float64, RST_AS_REAL, fmi3Float64, NULL)
SET(Int32, RST_AS_INTEGER, fmi3Int32, read_int32)
SET(Int64, RST_AS_ENUMERATION, fmi3Int64, read_int64)
SET(Boolean, RST_AS_BOOLEAN, fmi3Boolean, read_boolean)
NO_GET(Float32, fmi3Float32)
NO_GET(Int8, fmi3Int8)
NO_GET(UInt8, fmi3UInt8)
NO_GET(Int16, fmi3Int16)
NO_GET(UInt16, fmi3UInt16)
NO_GET(UInt32, fmi3UInt32)
NO_GET(UInt64, fmi3UInt64)
NO_GET(String, fmi3String)
NO_SET(Float32, fmi3Float32)
NO_SET(Int8, fmi3Int8)
NO_SET(UInt8, fmi3UInt8)
NO_SET(Int16, fmi3Int16)
NO_SET(UInt16, fmi3UInt16)
NO_SET(UInt32, fmi3UInt32)
NO_SET(UInt64, fmi3UInt64)
NO_SET(String, fmi3String)

fmi3Status fmi3GetBinary(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                         size_t valueSizes[], fmi3Binary values[], size_t nValues)
{
    (void)valueSizes, (void)values, (void)nValues;
    return (fmi3Status)front_refuse_type(instance, "fmi3GetBinary", "Binary", valueReferences, nValueReferences, 0);
}

fmi3Status fmi3SetBinary(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                         const size_t valueSizes[], const fmi3Binary values[], size_t nValues)
{
    (void)valueSizes, (void)values, (void)nValues;
    return (fmi3Status)front_refuse_type(instance, "fmi3SetBinary", "Binary", valueReferences, nValueReferences, 1);
}

fmi3Status fmi3GetClock(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                        fmi3Clock values[])
{
    (void)values;
    return (fmi3Status)front_refuse_type(instance, "fmi3GetClock", "Clock", valueReferences, nValueReferences, 0);
}

fmi3Status fmi3SetClock(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                        const fmi3Clock values[])
{
    (void)values;
    return (fmi3Status)front_refuse_type(instance, "fmi3SetClock", "Clock", valueReferences, nValueReferences, 1);
}

/* ------------------------------------------------------------------------------------------------ */
/* FMU states                                                                                       */
/* ------------------------------------------------------------------------------------------------ */
fmi3Status fmi3GetFMUState(fmi3Instance instance, fmi3FMUState *FMUState)
{
    return (fmi3Status)front_get_state(instance, "fmi3GetFMUState", FMUState);
}

fmi3Status fmi3SetFMUState(fmi3Instance instance, fmi3FMUState FMUState)
{
    return (fmi3Status)front_set_state(instance, "fmi3SetFMUState", FMUState);
}

fmi3Status fmi3FreeFMUState(fmi3Instance instance, fmi3FMUState *FMUState)
{
    return (fmi3Status)front_free_state(instance, "fmi3FreeFMUState", FMUState);
}

fmi3Status fmi3SerializedFMUStateSize(fmi3Instance instance, fmi3FMUState FMUState, size_t *size)
{
    return (fmi3Status)front_serialized_size(instance, "fmi3SerializedFMUStateSize", FMUState, size);
}

fmi3Status fmi3SerializeFMUState(fmi3Instance instance, fmi3FMUState FMUState, fmi3Byte serializedState[],
                                 size_t size)
{
    return (fmi3Status)front_serialize(instance, "fmi3SerializeFMUState", FMUState, serializedState, size);
}

fmi3Status fmi3DeserializeFMUState(fmi3Instance instance, const fmi3Byte serializedState[], size_t size,
                                   fmi3FMUState *FMUState)
{
    return (fmi3Status)front_deserialize(instance, "fmi3DeserializeFMUState", serializedState, size, FMUState);
}

/* ------------------------------------------------------------------------------------------------ */
/* Stepping                                                                                         */
/* ------------------------------------------------------------------------------------------------ */
static fmi3Status refuse_null_step_outputs(fmi3Instance instance)
{
    return (fmi3Status)front_refuse(instance, "fmi3DoStep", ANY_MODE | RST_MODE_EVENT, "eventHandlingNeeded, "
                                    "terminateSimulation, earlyReturn and lastSuccessfulTime must not be NULL");
}

fmi3Status fmi3DoStep(fmi3Instance instance, fmi3Float64 currentCommunicationPoint, fmi3Float64 communicationStepSize,
                      fmi3Boolean noSetFMUStatePriorToCurrentPoint, fmi3Boolean *eventHandlingNeeded,
                      fmi3Boolean *terminateSimulation, fmi3Boolean *earlyReturn, fmi3Float64 *lastSuccessfulTime)
{
    (void)noSetFMUStatePriorToCurrentPoint;
    /* a branch each (one expression of the four compiles to vector compares, slower on the common path) */
    if (RST_UNLIKELY(eventHandlingNeeded == NULL))
        return refuse_null_step_outputs(instance);
    if (RST_UNLIKELY(terminateSimulation == NULL))
        return refuse_null_step_outputs(instance);
    if (RST_UNLIKELY(earlyReturn == NULL))
        return refuse_null_step_outputs(instance);
    if (RST_UNLIKELY(lastSuccessfulTime == NULL))
        return refuse_null_step_outputs(instance);
    /* front_do_step writes lastSuccessfulTime where the step ran (its end, the event it returned early at, its
     * start after a discard) and, below fmi3Error, the three flags (fmi3Boolean is bool: a pointer of another
     * type would not compile) */
    return (fmi3Status)front_do_step(instance, "fmi3DoStep", currentCommunicationPoint, communicationStepSize,
                                     lastSuccessfulTime, eventHandlingNeeded, terminateSimulation, earlyReturn);
}

/* co-simulation instantiated with eventModeUsed: event mode -> step mode */
fmi3Status fmi3EnterStepMode(fmi3Instance instance)
{
    return (fmi3Status)front_enter_step_mode(instance, "fmi3EnterStepMode");
}

fmi3Status fmi3GetOutputDerivatives(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                    size_t nValueReferences, const fmi3Int32 orders[], fmi3Float64 values[],
                                    size_t nValues)
{
    (void)valueReferences, (void)nValueReferences, (void)orders, (void)values, (void)nValues;
    return (fmi3Status)front_refuse(instance, "fmi3GetOutputDerivatives", ANY_MODE,
                                    "not provided (maxOutputDerivativeOrder = 0)");
}

/* ------------------------------------------------------------------------------------------------ */
/* Not provided: dependencies at run time, partial derivatives, configuration, clocks, scheduled     */
/* execution; then model exchange                                                                    */
/* ------------------------------------------------------------------------------------------------ */
fmi3Status fmi3GetNumberOfVariableDependencies(fmi3Instance instance, fmi3ValueReference valueReference,
                                               size_t *nDependencies)
{
    (void)valueReference, (void)nDependencies;
    return (fmi3Status)front_refuse(instance, "fmi3GetNumberOfVariableDependencies", AFTER_INSTANTIATION,
                                    "not provided (the dependencies are declared in modelDescription.xml's "
                                    "ModelStructure)");
}

fmi3Status fmi3GetVariableDependencies(fmi3Instance instance, fmi3ValueReference dependent,
                                       size_t elementIndicesOfDependent[], fmi3ValueReference independents[],
                                       size_t elementIndicesOfIndependents[], fmi3DependencyKind dependencyKinds[],
                                       size_t nDependencies)
{
    (void)dependent, (void)elementIndicesOfDependent, (void)independents, (void)elementIndicesOfIndependents;
    (void)dependencyKinds, (void)nDependencies;
    return (fmi3Status)front_refuse(instance, "fmi3GetVariableDependencies", AFTER_INSTANTIATION,
                                    "not provided (the dependencies are declared in modelDescription.xml's "
                                    "ModelStructure)");
}

#define DERIVATIVE(name, flag)                                                                                   \
    fmi3Status fmi3Get##name(fmi3Instance instance, const fmi3ValueReference unknowns[], size_t nUnknowns,      \
                             const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[],       \
                             size_t nSeed, fmi3Float64 sensitivity[], size_t nSensitivity)                     \
    {                                                                                                          \
        (void)unknowns, (void)nUnknowns, (void)knowns, (void)nKnowns, (void)seed, (void)nSeed;                 \
        (void)sensitivity, (void)nSensitivity;                                                                 \
        return (fmi3Status)front_refuse(instance, "fmi3Get" #name, ANY_MODE, "not provided (" flag " = false)"); \
    }
DERIVATIVE(DirectionalDerivative, "providesDirectionalDerivatives")
DERIVATIVE(AdjointDerivative, "providesAdjointDerivatives")

#define NO_CLOCKS "this FMU has no clocks"

fmi3Status fmi3EnterConfigurationMode(fmi3Instance instance)
{
    return (fmi3Status)front_refuse(instance, "fmi3EnterConfigurationMode", ANY_MODE,
                                    "not provided (this FMU has no structural parameters)");
}

fmi3Status fmi3ExitConfigurationMode(fmi3Instance instance)
{
    return (fmi3Status)front_refuse(instance, "fmi3ExitConfigurationMode", ANY_MODE,
                                    "not provided (this FMU has no structural parameters)");
}

fmi3Status fmi3GetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                  size_t nValueReferences, fmi3Float64 intervals[], fmi3IntervalQualifier qualifiers[])
{
    (void)valueReferences, (void)nValueReferences, (void)intervals, (void)qualifiers;
    return (fmi3Status)front_refuse(instance, "fmi3GetIntervalDecimal", ANY_MODE, "not provided (" NO_CLOCKS ")");
}

fmi3Status fmi3GetIntervalFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                   size_t nValueReferences, fmi3UInt64 counters[], fmi3UInt64 resolutions[],
                                   fmi3IntervalQualifier qualifiers[])
{
    (void)valueReferences, (void)nValueReferences, (void)counters, (void)resolutions, (void)qualifiers;
    return (fmi3Status)front_refuse(instance, "fmi3GetIntervalFraction", ANY_MODE, "not provided (" NO_CLOCKS ")");
}

fmi3Status fmi3GetShiftDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                               size_t nValueReferences, fmi3Float64 shifts[])
{
    (void)valueReferences, (void)nValueReferences, (void)shifts;
    return (fmi3Status)front_refuse(instance, "fmi3GetShiftDecimal", ANY_MODE, "not provided (" NO_CLOCKS ")");
}

fmi3Status fmi3GetShiftFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                size_t nValueReferences, fmi3UInt64 counters[], fmi3UInt64 resolutions[])
{
    (void)valueReferences, (void)nValueReferences, (void)counters, (void)resolutions;
    return (fmi3Status)front_refuse(instance, "fmi3GetShiftFraction", ANY_MODE, "not provided (" NO_CLOCKS ")");
}

fmi3Status fmi3SetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                  size_t nValueReferences, const fmi3Float64 intervals[])
{
    (void)valueReferences, (void)nValueReferences, (void)intervals;
    return (fmi3Status)front_refuse(instance, "fmi3SetIntervalDecimal", ANY_MODE, "not provided (" NO_CLOCKS ")");
}

fmi3Status fmi3SetIntervalFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                   size_t nValueReferences, const fmi3UInt64 counters[],
                                   const fmi3UInt64 resolutions[])
{
    (void)valueReferences, (void)nValueReferences, (void)counters, (void)resolutions;
    return (fmi3Status)front_refuse(instance, "fmi3SetIntervalFraction", ANY_MODE, "not provided (" NO_CLOCKS ")");
}

fmi3Status fmi3SetShiftDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                               size_t nValueReferences, const fmi3Float64 shifts[])
{
    (void)valueReferences, (void)nValueReferences, (void)shifts;
    return (fmi3Status)front_refuse(instance, "fmi3SetShiftDecimal", ANY_MODE, "not provided (" NO_CLOCKS ")");
}

fmi3Status fmi3SetShiftFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                size_t nValueReferences, const fmi3UInt64 counters[], const fmi3UInt64 resolutions[])
{
    (void)valueReferences, (void)nValueReferences, (void)counters, (void)resolutions;
    return (fmi3Status)front_refuse(instance, "fmi3SetShiftFraction", ANY_MODE, "not provided (" NO_CLOCKS ")");
}

fmi3Status fmi3EvaluateDiscreteStates(fmi3Instance instance)
{
    return (fmi3Status)front_refuse(instance, "fmi3EvaluateDiscreteStates", ANY_MODE | RST_MODE_EVENT,
                                    "not provided (providesEvaluateDiscreteStates = false)");
}

fmi3Status fmi3UpdateDiscreteStates(fmi3Instance instance, fmi3Boolean *discreteStatesNeedUpdate,
                                    fmi3Boolean *terminateSimulation, fmi3Boolean *nominalsOfContinuousStatesChanged,
                                    fmi3Boolean *valuesOfContinuousStatesChanged, fmi3Boolean *nextEventTimeDefined,
                                    fmi3Float64 *nextEventTime)
{
    rst_event_update update;
    rst_status status;
    if (discreteStatesNeedUpdate == NULL || terminateSimulation == NULL || nominalsOfContinuousStatesChanged == NULL ||
        valuesOfContinuousStatesChanged == NULL || nextEventTimeDefined == NULL || nextEventTime == NULL)
        return (fmi3Status)front_refuse(instance, "fmi3UpdateDiscreteStates", RST_MODE_EVENT,
                                        "its out-arguments must not be NULL");
    status = front_update_discrete_states(instance, "fmi3UpdateDiscreteStates", &update);
    if (status < RST_ERROR) {
        *discreteStatesNeedUpdate = update.discrete_states_need_update != 0;
        *terminateSimulation = update.terminate_simulation != 0;
        *nominalsOfContinuousStatesChanged = update.nominals_changed != 0;
        *valuesOfContinuousStatesChanged = update.states_changed != 0;
        *nextEventTimeDefined = update.next_event_time_defined != 0;
        *nextEventTime = update.next_event_time;
    }
    return (fmi3Status)status;
}

fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance instance)
{
    return (fmi3Status)front_enter_continuous_time_mode(instance, "fmi3EnterContinuousTimeMode");
}

fmi3Status fmi3CompletedIntegratorStep(fmi3Instance instance, fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                                       fmi3Boolean *enterEventMode, fmi3Boolean *terminateSimulation)
{
    int enter = 0, terminate = 0;
    rst_status status;
    (void)noSetFMUStatePriorToCurrentPoint;
    status = front_completed_integrator_step(instance, "fmi3CompletedIntegratorStep", enterEventMode ? &enter : NULL,
                                             terminateSimulation ? &terminate : NULL);
    if (status < RST_ERROR) {
        *enterEventMode = enter != 0;
        *terminateSimulation = terminate != 0;
    }
    return (fmi3Status)status;
}

fmi3Status fmi3SetTime(fmi3Instance instance, fmi3Float64 time)
{
    return (fmi3Status)front_set_time(instance, "fmi3SetTime", time);
}

fmi3Status fmi3SetContinuousStates(fmi3Instance instance, const fmi3Float64 continuousStates[],
                                   size_t nContinuousStates)
{
    return (fmi3Status)front_set_continuous_states(instance, "fmi3SetContinuousStates", continuousStates,
                                                   nContinuousStates);
}

fmi3Status fmi3GetContinuousStateDerivatives(fmi3Instance instance, fmi3Float64 derivatives[],
                                             size_t nContinuousStates)
{
    return (fmi3Status)front_get_derivatives(instance, "fmi3GetContinuousStateDerivatives", derivatives,
                                             nContinuousStates);
}

fmi3Status fmi3GetEventIndicators(fmi3Instance instance, fmi3Float64 eventIndicators[], size_t nEventIndicators)
{
    return (fmi3Status)front_get_event_indicators(instance, "fmi3GetEventIndicators", eventIndicators,
                                                  nEventIndicators);
}

fmi3Status fmi3GetContinuousStates(fmi3Instance instance, fmi3Float64 continuousStates[], size_t nContinuousStates)
{
    return (fmi3Status)front_get_continuous_states(instance, "fmi3GetContinuousStates", continuousStates,
                                                   nContinuousStates);
}

fmi3Status fmi3GetNominalsOfContinuousStates(fmi3Instance instance, fmi3Float64 nominals[], size_t nContinuousStates)
{
    return (fmi3Status)front_get_nominals(instance, "fmi3GetNominalsOfContinuousStates", nominals, nContinuousStates);
}

fmi3Status fmi3GetNumberOfEventIndicators(fmi3Instance instance, size_t *nEventIndicators)
{
    return (fmi3Status)front_get_sizes(instance, "fmi3GetNumberOfEventIndicators", NULL, nEventIndicators);
}

fmi3Status fmi3GetNumberOfContinuousStates(fmi3Instance instance, size_t *nContinuousStates)
{
    return (fmi3Status)front_get_sizes(instance, "fmi3GetNumberOfContinuousStates", nContinuousStates, NULL);
}

fmi3Status fmi3ActivateModelPartition(fmi3Instance instance, fmi3ValueReference clockReference,
                                      fmi3Float64 activationTime)
{
    (void)clockReference, (void)activationTime;
    return (fmi3Status)front_refuse(instance, "fmi3ActivateModelPartition", ANY_MODE,
                                    "not provided (scheduled execution is not offered)");
}
