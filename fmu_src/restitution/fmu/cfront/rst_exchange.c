/* The front's model exchange, for every FMI version: the event and continuous-time modes, time, the
 * continuous states, their derivatives and the event indicators. The model names its state vector,
 * derivatives and indicators by value reference (rst_model.state_vrs, ...): states live in the value
 * store like every variable (so FMU states, get and set need nothing more), and derivatives and
 * indicators are variables the backend computes, read as a get call reads them.
 *
 * Modes (FMI 2.0 section 3.2.3, FMI 3.0 section 3.2): initialization ends in event mode; the host
 * updates the discrete states there until no further update is needed, enters continuous-time mode,
 * integrates (time, states, derivatives, indicators), and comes back to event mode at an event.
 * Wrong modes and arguments are refused with an error and change nothing, as everywhere in the front.
 * FMI 3.0 co-simulation with eventModeUsed shares the event mode and its update (fmi3EnterEventMode from
 * step mode, fmi3UpdateDiscreteStates, fmi3EnterStepMode back); everything else here is model exchange's.
 */
#include "rst_instance.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define VECTOR_MODES (RST_MODE_INITIALIZATION | ME_MODES | RST_MODE_TERMINATED)

/* Is this a model-exchange instance? Logs why not. */
static int only_model_exchange(rst_instance *inst, const char *function)
{
    if (inst->model_exchange)
        return 1;
    rst_log(inst, RST_ERROR, "%s: this instance is a co-simulation instance (model exchange only)", function);
    return 0;
}

/* Is this a model-exchange instance whose vector has `expected` elements where the host gave `n` (and a
 * non-NULL array where n > 0)? Logs why not. */
static int check_vector(rst_instance *inst, const char *function, const void *array, size_t n, size_t expected,
                        const char *what)
{
    if (!only_model_exchange(inst, function))
        return 0;
    if (n != expected) {
        rst_log(inst, RST_ERROR, "%s: %u %s asked for; %s has %u", function, (unsigned int)n, what,
                inst->model->identifier, (unsigned int)expected);
        return 0;
    }
    if (n > 0 && array == NULL) {
        rst_log(inst, RST_ERROR, "%s: the array of %u %s is NULL", function, (unsigned int)n, what);
        return 0;
    }
    return 1;
}

/* Reads the model's variables `vrs` (its states, derivatives or indicators: Reals of its table) as a get
 * call does. A model that computes everything into the store (no get_outputs hook, BouncingBall) has them
 * copied from it: an integrator reads them at every right-hand-side evaluation, and they need none of a get
 * call's checks of host-given value references. */
static rst_status read_vector(rst_instance *inst, const char *function, const unsigned int *vrs, size_t n,
                              double out[])
{
    size_t i;
    if (inst->model->get_outputs != NULL)
        return front_read(inst, function, RST_AS_REAL, vrs, n, out, NULL);
    for (i = 0; i < n; i++)
        out[i] = inst->head.store[vrs[i]];
    return RST_OK;
}

/* Model exchange: from continuous-time mode. FMI 3.0 co-simulation: from step mode, where the host asked
 * for event mode at instantiation. */
rst_status front_enter_event_mode(void *c, const char *function)
{
    ENTER(function, RST_MODE_CONTINUOUS | RST_MODE_STEP_COMPLETE)
    if (!inst->model_exchange && !inst->event_mode_used) {
        if (strcmp(inst->api->prefix, "fmi3") != 0) /* FMI 2.0 co-simulation has no event mode at all */
            only_model_exchange(inst, function);
        else
            rst_log(inst, RST_ERROR, "%s: this co-simulation instance was instantiated with eventModeUsed = "
                    "false; it has no event mode", function);
        LEAVE(RST_ERROR);
    }
    inst->mode = RST_MODE_EVENT;
    LEAVE(RST_OK);
}

rst_status front_enter_continuous_time_mode(void *c, const char *function)
{
    ENTER(function, RST_MODE_EVENT)
    if (!only_model_exchange(inst, function))
        LEAVE(RST_ERROR);
    inst->mode = RST_MODE_CONTINUOUS;
    LEAVE(RST_OK);
}

/* FMI 3.0 co-simulation: event mode -> step mode (the next fmi3DoStep starts at the event's time). */
rst_status front_enter_step_mode(void *c, const char *function)
{
    ENTER(function, RST_MODE_EVENT)
    if (inst->model_exchange) {
        rst_log(inst, RST_ERROR, "%s: this instance is a model-exchange instance (co-simulation only; model "
                "exchange leaves event mode with fmi3EnterContinuousTimeMode)", function);
        LEAVE(RST_ERROR);
    }
    inst->mode = RST_MODE_STEP_COMPLETE;
    LEAVE(RST_OK);
}

rst_status front_update_discrete_states(void *c, const char *function, rst_event_update *result)
{
    rst_status status = RST_OK;
    ENTER(function, RST_MODE_EVENT)
    memset(result, 0, sizeof *result);
    if (inst->model->update_discrete_states != NULL)
        status = front_backend_status(inst, inst->model->update_discrete_states(inst, result));
    LEAVE(status);
}

rst_status front_completed_integrator_step(void *c, const char *function, int *enter_event_mode, int *terminate)
{
    ENTER(function, RST_MODE_CONTINUOUS)
    if (enter_event_mode == NULL || terminate == NULL) {
        rst_log(inst, RST_ERROR, "%s: enterEventMode and terminateSimulation must not be NULL", function);
        LEAVE(RST_ERROR);
    }
    *enter_event_mode = 0; /* no step events: every event is a state event located by the host */
    *terminate = 0;
    LEAVE(RST_OK);
}

rst_status front_set_time(void *c, const char *function, double time)
{
    char text[40];
    ENTER(function, ME_MODES)
    if (!only_model_exchange(inst, function)) /* a co-simulation instance in event mode */
        LEAVE(RST_ERROR);
    if (!isfinite(time)) {
        rst_format_double(time, text, sizeof text);
        rst_log(inst, RST_ERROR, "%s: time = %s must be finite", function, text);
        LEAVE(RST_ERROR);
    }
    inst->last_time = time;
    LEAVE(RST_OK);
}

rst_status front_set_continuous_states(void *c, const char *function, const double x[], size_t n)
{
    size_t i;
    char text[40];
    rst_status status = RST_OK;
    ENTER(function, RST_MODE_CONTINUOUS | RST_MODE_EVENT | RST_MODE_INITIALIZATION)
    if (!check_vector(inst, function, x, n, inst->model->n_states, "continuous states"))
        LEAVE(RST_ERROR);
    for (i = 0; i < n; i++)
        if (!isfinite(x[i])) {
            rst_format_double(x[i], text, sizeof text);
            rst_log(inst, RST_ERROR, "%s: %s = %s must be finite; nothing was changed", function,
                    inst->model->variables[inst->model->state_vrs[i]].name, text);
            LEAVE(RST_ERROR);
        }
    for (i = 0; i < n; i++)
        inst->head.store[inst->model->state_vrs[i]] = x[i];
    if (inst->model->set != NULL && n > 0)
        status = front_backend_status(inst, inst->model->set(inst, RST_REAL, inst->model->state_vrs, n, x));
    LEAVE(status);
}

rst_status front_get_continuous_states(void *c, const char *function, double x[], size_t n)
{
    ENTER(function, VECTOR_MODES)
    if (!check_vector(inst, function, x, n, inst->model->n_states, "continuous states"))
        LEAVE(RST_ERROR);
    LEAVE(read_vector(inst, function, inst->model->state_vrs, n, x));
}

rst_status front_get_derivatives(void *c, const char *function, double dx[], size_t n)
{
    ENTER(function, VECTOR_MODES)
    if (!check_vector(inst, function, dx, n, inst->model->n_states, "state derivatives"))
        LEAVE(RST_ERROR);
    LEAVE(read_vector(inst, function, inst->model->derivative_vrs, n, dx));
}

rst_status front_get_event_indicators(void *c, const char *function, double z[], size_t n)
{
    ENTER(function, VECTOR_MODES)
    if (!check_vector(inst, function, z, n, inst->model->n_event_indicators, "event indicators"))
        LEAVE(RST_ERROR);
    LEAVE(read_vector(inst, function, inst->model->event_indicator_vrs, n, z));
}

rst_status front_get_nominals(void *c, const char *function, double nominals[], size_t n)
{
    size_t i;
    ENTER(function, VECTOR_MODES)
    if (!check_vector(inst, function, nominals, n, inst->model->n_states, "nominals"))
        LEAVE(RST_ERROR);
    if (inst->model->nominals != NULL && n > 0) {
        inst->model->nominals(inst, nominals);
        LEAVE(RST_OK);
    }
    for (i = 0; i < n; i++)
        nominals[i] = 1.0; /* the default: the table declares no nominal */
    LEAVE(RST_OK);
}

rst_status front_get_sizes(void *c, const char *function, size_t *n_states, size_t *n_event_indicators)
{
    ENTER(function, ANY_LIVE_MODE)
    if (!only_model_exchange(inst, function))
        LEAVE(RST_ERROR);
    if (n_states == NULL && n_event_indicators == NULL) {
        rst_log(inst, RST_ERROR, "%s: the size argument is NULL", function);
        LEAVE(RST_ERROR);
    }
    if (n_states != NULL)
        *n_states = inst->model->n_states;
    if (n_event_indicators != NULL)
        *n_event_indicators = inst->model->n_event_indicators;
    LEAVE(RST_OK);
}
