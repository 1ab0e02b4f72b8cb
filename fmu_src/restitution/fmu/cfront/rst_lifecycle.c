/* The front's core: see rst_front.h. This file: the instance's life cycle and steps, for every FMI
 * version: instantiation, the transitions of the state machine, the co-simulation step (entering and
 * leaving a call, the accessors and the mode checks: rst_call.c; values and their checks: rst_values.c;
 * messages: rst_log.c; FMU states: rst_state.c; model exchange: rst_exchange.c; each version's entry
 * points: rst_fmi2.c, rst_fmi3.c). The files of the core call downward only: this one calls the others,
 * rst_state.c and rst_exchange.c call rst_values.c, and every one calls rst_call.c and rst_log.c, which
 * call no other file of the core.
 *
 * Which call is allowed in which mode follows the co-simulation state machine of FMI 2.0 (section
 * 4.2.4), which FMI 3.0's restricts to the same transitions for an FMU without event mode,
 * intermediate updates or configuration mode; an FMI 3.0 co-simulation instance whose host asked for
 * event mode (eventModeUsed, a model with do_step_to_event) adds FMI 3.0's event mode: initialization
 * ends there, fmi3EnterStepMode leaves it, fmi3EnterEventMode enters it from step mode, and only there
 * fmi3UpdateDiscreteStates runs. A call that is not allowed, or whose arguments are
 * wrong, returns an error with a log message and changes nothing: the instance stays in its mode and
 * keeps its values (more forgiving than the standards, which let an importer give up on an instance
 * after any error). A backend that reports RST_ERROR puts the instance into the error mode (reset,
 * restoring an FMU state or freeing the instance leave it); RST_FATAL latches it for good.
 */
#include "rst_instance.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

/* Relative tolerance of the step time check: an importer's t differs from the previous t + h by a
 * rounding or two; a skipped or repeated step differs by about h. */
#define TIME_RTOL 1e-9

/* ------------------------------------------------------------------------------------------------ */
/* Life cycle                                                                                       */
/* ------------------------------------------------------------------------------------------------ */
static int hex_value(char ch)
{
    if (ch >= '0' && ch <= '9') return ch - '0';
    if (ch >= 'a' && ch <= 'f') return ch - 'a' + 10;
    if (ch >= 'A' && ch <= 'F') return ch - 'A' + 10;
    return -1;
}

/* file:///p, file:/p, file://localhost/p, percent-encoded -> p. Windows drive paths (file:///C:/x) lose
 * their leading slash. A '%' not followed by two hex digits is taken literally (hosts that do not
 * encode their paths exist); an encoded NUL is refused. Trailing separators are dropped. */
const char *front_decode_file_uri(const char *uri, char *path)
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

static void free_memory(rst_instance *inst)
{
    rst_release_fn release = inst->release;
    front_free_states(inst);
    front_deliver_messages(inst, front_take_messages(inst));
#if defined(RST_LOCK_ATOMIC)
    pthread_cond_destroy(&inst->waiters);
#endif
#if defined(RST_LOCK_PTHREAD)
    pthread_mutex_destroy(&inst->lock);
#endif
    inst->magic = 0;
    release(inst->head.backend);
    release(inst->head.store);
    release(inst->name);
    release(inst);
}

void front_discard_instance(rst_instance *inst) { free_memory(inst); }

rst_instance *front_new_instance(const rst_api *api, void (*host_logger)(void), void *environment,
                                 rst_allocate_fn allocate, rst_release_fn release, const char *function,
                                 const char *name, int logging_on)
{
    const rst_model *model = &RST_MODEL;
    rst_instance *inst = (rst_instance *)allocate(1, sizeof *inst);
    size_t i;
    if (inst == NULL)
        return NULL;
    inst->model = model;
    inst->api = api;
    inst->host_logger = host_logger;
    inst->environment = environment;
    inst->allocate = allocate;
    inst->release = release;
    inst->logging_on = logging_on != 0;
    inst->categories = RST_ALL_CATEGORIES;
    inst->mode = RST_MODE_INSTANTIATED;
    inst->last_step_status = RST_OK;
    inst->name = (char *)allocate(strlen(name) + 1, 1);
    inst->head.store = (double *)allocate(model->n_variables ? model->n_variables : 1, sizeof(double));
    inst->head.backend = allocate(model->backend_size ? model->backend_size : 1, 1);
    if (inst->name == NULL || inst->head.store == NULL || inst->head.backend == NULL) {
        char message[80];
        snprintf(message, sizeof message, "%s: out of memory", function);
        api->emit(host_logger, environment, name, RST_ERROR, "logStatusError", message);
        if (inst->name) release(inst->name);
        if (inst->head.store) release(inst->head.store);
        if (inst->head.backend) release(inst->head.backend);
        release(inst);
        return NULL;
    }
    strcpy(inst->name, name);
    memset(inst->head.backend, 0, model->backend_size ? model->backend_size : 1);
    for (i = 0; i < model->n_variables; i++)
        inst->n_state += model->variables[i].state != 0;
    inst->pending_end = &inst->pending;
#if defined(RST_LOCK_ATOMIC)
    pthread_cond_init(&inst->waiters, NULL);
#endif
#if defined(RST_LOCK_PTHREAD)
    pthread_mutex_init(&inst->lock, NULL);
#elif defined(RST_LOCK_WIN32)
    InitializeSRWLock(&inst->lock);
#endif
    inst->magic = RST_INSTANCE_MAGIC;
    front_reset_store(inst);
    return inst;
}

rst_instance *front_instantiate(rst_instance *inst, const char *function, const char *token,
                                const char *resource_dir, int visible, int model_exchange)
{
    rst_status status;
    if (model_exchange && !inst->model->model_exchange) {
        rst_log(inst, RST_ERROR, "%s: %s is a co-simulation FMU; model exchange is not provided", function,
                inst->model->identifier);
        free_memory(inst);
        return NULL;
    }
    inst->model_exchange = model_exchange;
    if (token == NULL || strcmp(token, inst->model->guid) != 0) {
        rst_log(inst, RST_ERROR, "%s: %s %s does not match this FMU's %s (modelDescription.xml of another model, "
                "interface or version?)", function, inst->api->token_name,
                token ? token : "(NULL)", inst->model->guid);
        free_memory(inst);
        return NULL;
    }
    status = inst->model->instantiate ? inst->model->instantiate(inst, resource_dir, visible) : RST_OK;
    if (status != RST_OK) {
        free_memory(inst);
        return NULL;
    }
    return inst;
}

void front_free_instance(void *c)
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

static rst_status setup_locked(rst_instance *inst, const char *function, const rst_experiment *e)
{
    rst_status status = RST_OK;
    if (!isfinite(e->start_time) || (e->stop_time_defined && !(e->stop_time >= e->start_time && e->stop_time <= DBL_MAX)) ||
        (e->tolerance_defined && !(e->tolerance > 0.0 && e->tolerance <= DBL_MAX))) {
        char t0[40], t1[40], tol[40];
        rst_format_double(e->start_time, t0, sizeof t0);
        rst_format_double(e->stop_time, t1, sizeof t1);
        rst_format_double(e->tolerance, tol, sizeof tol);
        rst_log(inst, RST_ERROR, "%s: startTime = %s%s%s%s%s: the start time must be finite, a "
                "defined stop time finite and >= the start time, a defined tolerance finite and > 0", function, t0,
                e->stop_time_defined ? ", stopTime = " : "", e->stop_time_defined ? t1 : "",
                e->tolerance_defined ? ", tolerance = " : "", e->tolerance_defined ? tol : "");
        return RST_ERROR;
    }
    if (inst->model->setup_experiment != NULL) {
        status = front_backend_status(inst, inst->model->setup_experiment(inst, e->tolerance_defined, e->tolerance,
                                                                          e->start_time, e->stop_time_defined,
                                                                          e->stop_time));
        if (status >= RST_ERROR)
            return status;
    }
    inst->has_start = 1;
    inst->start_time = e->start_time;
    return status;
}

rst_status front_setup_experiment(void *c, const char *function, const rst_experiment *experiment)
{
    ENTER(function, RST_MODE_INSTANTIATED)
    LEAVE(setup_locked(inst, function, experiment));
}

rst_status front_enter_initialization(void *c, const char *function, const rst_experiment *experiment)
{
    rst_status status = RST_OK;
    ENTER(function, RST_MODE_INSTANTIATED)
    if (experiment != NULL) {
        status = setup_locked(inst, function, experiment);
        if (status >= RST_ERROR)
            LEAVE(status);
    }
    if (inst->model->enter_initialization != NULL) {
        rst_status s = front_backend_status(inst, inst->model->enter_initialization(inst));
        status = s > status ? s : status;
    }
    if (status < RST_ERROR)
        inst->mode = RST_MODE_INITIALIZATION;
    LEAVE(status);
}

rst_status front_exit_initialization(void *c, const char *function)
{
    rst_status status = RST_OK;
    ENTER(function, RST_MODE_INITIALIZATION)
    if (inst->model->exit_initialization != NULL)
        status = front_backend_status(inst, inst->model->exit_initialization(inst));
    if (status < RST_ERROR) {
        /* co-simulation steps from here; model exchange starts with an event (FMI 2.0 and 3.0), and so
         * does FMI 3.0 co-simulation with eventModeUsed (the host leaves it with fmi3EnterStepMode) */
        inst->mode = inst->model_exchange || inst->event_mode_used ? RST_MODE_EVENT : RST_MODE_STEP_COMPLETE;
        inst->has_time = inst->has_start;
        inst->next_time = inst->start_time;
        inst->last_time = inst->start_time;
    }
    LEAVE(status);
}

rst_status front_terminate(void *c, const char *function)
{
    rst_status status = RST_OK;
    ENTER(function, RST_MODE_STEP_COMPLETE | RST_MODE_STEP_FAILED | ME_MODES)
    if (inst->model->terminate != NULL)
        status = front_backend_status(inst, inst->model->terminate(inst));
    if (status < RST_ERROR)
        inst->mode = RST_MODE_TERMINATED;
    LEAVE(status);
}

rst_status front_reset(void *c, const char *function)
{
    rst_status status = RST_OK;
    ENTER(function, ANY_LIVE_MODE)
    front_reset_store(inst);
    inst->mode = RST_MODE_INSTANTIATED;
    inst->has_start = inst->has_time = 0;
    inst->start_time = inst->next_time = inst->last_time = 0.0;
    inst->last_step_status = RST_OK;
    if (inst->model->reset != NULL)
        status = front_backend_status(inst, inst->model->reset(inst));
    LEAVE(status);
}

/* ------------------------------------------------------------------------------------------------ */
/* Stepping                                                                                         */
/* ------------------------------------------------------------------------------------------------ */
rst_status front_refuse(void *c, const char *function, unsigned int modes, const char *why)
{
    ENTER(function, modes)
    rst_log(inst, RST_ERROR, "%s: %s", function, why);
    LEAVE(RST_ERROR);
}

/* The backend's step: do_step, or do_step_to_event where the host asked for events (FMI 3.0); `end` says
 * where the step ended and whether an event waits for the host. */
static rst_status backend_step(rst_instance *inst, double t, double h, rst_step_end *end)
{
    end->reached = t + h;
    end->event_pending = 0;
    if (inst->model->do_step_to_event != NULL && (inst->early_return_allowed || inst->event_mode_used))
        return inst->model->do_step_to_event(inst, t, h, inst->early_return_allowed, inst->event_mode_used, end);
    return inst->model->do_step != NULL ? inst->model->do_step(inst, t, h) : RST_OK;
}

rst_status front_do_step(void *c, const char *function, double t, double h, double *last_successful_time,
                         _Bool *event_handling_needed, _Bool *terminate_simulation, _Bool *early_return)
{
    rst_status status = RST_OK;
    rst_step_end end;
    char t_text[40], h_text[40], want[40];
    ENTER(function, RST_MODE_STEP_COMPLETE)
    if (!isfinite(t) || !isfinite(h) || !(h > 0.0) || !isfinite(t + h)) {
        rst_format_double(t, t_text, sizeof t_text);
        rst_format_double(h, h_text, sizeof h_text);
        rst_log(inst, RST_ERROR, "%s: currentCommunicationPoint = %s, communicationStepSize = %s: the step "
                "size must be finite and > 0, the time finite", function, t_text, h_text);
        LEAVE(RST_ERROR);
    }
    if (inst->has_time) {
        double scale = fabs(inst->next_time) > fabs(h) ? fabs(inst->next_time) : fabs(h);
        if (fabs(t - inst->next_time) > TIME_RTOL * scale) {
            rst_format_double(t, t_text, sizeof t_text);
            rst_format_double(inst->next_time, want, sizeof want);
            rst_log(inst, RST_ERROR, "%s: currentCommunicationPoint = %s does not continue the previous "
                    "step, which ended at %s (a step cannot be skipped or repeated without %s)",
                    function, t_text, want, inst->api->set_state);
            LEAVE(RST_ERROR);
        }
    }
    status = front_backend_status(inst, backend_step(inst, t, h, &end));
    inst->last_step_status = status;
    if (status <= RST_WARNING) {
        /* an early return ends the step at the event (t <= reached < t + h): the next step starts there */
        double reached = end.reached >= t && end.reached < t + h ? end.reached : t + h;
        inst->has_time = 1;
        inst->next_time = reached;
        inst->last_time = reached;
        if (event_handling_needed != NULL) { /* FMI 3.0: an event waiting for the host's event mode
                                                 * (eventModeUsed only); a step that ended before t + h
                                                 * (earlyReturnAllowed only) */
            *event_handling_needed = end.event_pending != 0;
            *terminate_simulation = 0;
            *early_return = reached < t + h;
        }
    } else if (status == RST_DISCARD) {
        inst->mode = RST_MODE_STEP_FAILED;
        inst->last_time = t;
        if (event_handling_needed != NULL) { /* FMI 3.0: the instance cannot step on (fmi3Terminate, fmi3Reset
                                              * or fmi3SetFMUState) */
            *event_handling_needed = 0;
            *terminate_simulation = 1;
            *early_return = 0;
        }
    }
    if (last_successful_time != NULL)
        *last_successful_time = inst->last_time;
    LEAVE(status);
}
