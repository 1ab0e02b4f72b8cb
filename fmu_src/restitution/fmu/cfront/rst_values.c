/* The front's values: see rst_front.h. This file: the value store and the get and set calls of every
 * FMI version, with their checks (value references, types, what may be set in which mode, declared
 * ranges, counts); a set stores all its values or none. The instance's life cycle and steps are in
 * rst_lifecycle.c.
 */
#include "rst_instance.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* Values converted per chunk on the stack; a longer set is converted in one allocated piece (all or
 * nothing needs every value checked before any is stored). */
#define CHUNK 64

/* Every variable back to its start value (a new instance, fmi2Reset). */
void front_reset_store(rst_instance *inst)
{
    size_t i;
    for (i = 0; i < inst->model->n_variables; i++)
        inst->head.store[i] = inst->model->variables[i].start;
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

const char *front_type_name(rst_type type)
{
    return type == RST_REAL ? "Real" : type == RST_INTEGER ? "Integer" : "Boolean";
}

/* The access kind of a variable: its type, or Enumeration for an Integer with named codes. */
static rst_access access_of(const rst_variable *var)
{
    if (var->type == RST_REAL)
        return RST_AS_REAL;
    if (var->type == RST_BOOLEAN)
        return RST_AS_BOOLEAN;
    return var->enumeration ? RST_AS_ENUMERATION : RST_AS_INTEGER;
}

/* The name the version gives an access kind (FMI 2.0: Real, Integer, Boolean; FMI 3.0: Float64, ...);
 * of a set of kinds, the first. */
static const char *access_name(const rst_instance *inst, unsigned int kinds)
{
    int i;
    for (i = 0; i < 4; i++)
        if (kinds & (1u << i))
            return inst->api->type_names[i];
    return "?";
}

/* "a" or "an" before a type name ("an Integer", "an Enumeration", "a Real"). */
static const char *article(const char *name)
{
    return strchr("AEIOU", name[0]) != NULL ? "an" : "a";
}

/* Is `vr` the independent variable time (FMI 3.0)? */
static int is_time(const rst_instance *inst, rst_vr vr)
{
    return inst->api->time_variable && vr == inst->model->n_variables;
}

/* The independent variable: the start time until initialization ends, then the end of the last step
 * (co-simulation) or the time the host set (model exchange). */
double rst_time(const rst_instance *inst)
{
    if (inst->mode == RST_MODE_INSTANTIATED || inst->mode == RST_MODE_INITIALIZATION)
        return rst_start_time(inst);
    return inst->last_time;
}

/* check_vr beyond its common case: time, or a value reference refused (logged). */
static int check_other_vr(rst_instance *inst, const char *function, rst_vr vr, unsigned int kinds)
{
    const rst_variable *var;
    if (is_time(inst, vr)) {
        if (kinds & RST_AS_REAL)
            return 1;
        rst_log(inst, RST_ERROR, "%s: time (value reference %u) is %s %s variable, not %s", function, vr,
                article(access_name(inst, RST_AS_REAL)), access_name(inst, RST_AS_REAL), access_name(inst, kinds));
        return 0;
    }
    if (vr >= inst->model->n_variables) {
        rst_log(inst, RST_ERROR, "%s: unknown value reference %u (this FMU has %u variables)", function, vr,
                (unsigned int)(inst->model->n_variables + (inst->api->time_variable ? 1 : 0)));
        return 0;
    }
    var = &inst->model->variables[vr];
    if (!(kinds & (unsigned int)access_of(var))) {
        const char *type = access_name(inst, (unsigned int)access_of(var));
        rst_log(inst, RST_ERROR, "%s: %s (value reference %u) is %s %s variable, not %s", function, var->name, vr,
                article(type), type, access_name(inst, kinds));
        return 0;
    }
    return 1;
}

/* Is `vr` a variable of one of the `kinds` (time included)? Logs why not. The common case (a variable of
 * the table, of a kind asked for) inline, without the messages. */
static inline int check_vr(rst_instance *inst, const char *function, rst_vr vr, unsigned int kinds)
{
    if (vr < inst->model->n_variables && (kinds & (unsigned int)access_of(&inst->model->variables[vr])))
        return 1;
    return check_other_vr(inst, function, vr, kinds);
}

/* May the host set `var` in the current mode? (Inputs and parameters in instantiated and
 * initialization mode; in step mode and event mode inputs and tunable parameters only; in
 * continuous-time mode inputs only.) */
static int settable(const rst_instance *inst, const rst_variable *var)
{
    if (var->causality != RST_INPUT && var->causality != RST_PARAMETER)
        return 0;
    if (inst->mode == RST_MODE_STEP_COMPLETE || inst->mode == RST_MODE_EVENT)
        return var->causality == RST_INPUT || var->variability == RST_TUNABLE;
    if (inst->mode == RST_MODE_CONTINUOUS)
        return var->causality == RST_INPUT;
    return 1;
}

/* Does the backend's accept hook look at `vr` (rst_model.accept_vrs)? */
static int accept_asked(const rst_model *model, rst_vr vr)
{
    size_t i;
    if (model->accept == NULL)
        return 0;
    if (model->accept_vrs == NULL)
        return 1;
    for (i = 0; i < model->n_accept_vrs; i++)
        if (model->accept_vrs[i] == vr)
            return 1;
    return 0;
}

/* Checks one value the host wants to set; logs and returns 0 if it is refused. */
static int check_set(rst_instance *inst, const char *function, rst_vr vr, unsigned int kinds, double value)
{
    const rst_variable *var;
    char text[40], buffer[80];
    if (!check_vr(inst, function, vr, kinds))
        return 0;
    if (vr >= inst->model->n_variables) { /* what check_vr accepts beyond the table: time */
        rst_log(inst, RST_ERROR, "%s: time is the independent variable and cannot be set", function);
        return 0;
    }
    var = &inst->model->variables[vr];
    if (!settable(inst, var)) {
        if (var->causality == RST_OUTPUT || var->causality == RST_LOCAL || var->causality == RST_CALCULATEDPARAMETER)
            rst_log(inst, RST_ERROR, "%s: %s is %s and cannot be set", function, var->name,
                    var->causality == RST_OUTPUT  ? "an output"
                    : var->causality == RST_LOCAL ? "a local variable"
                                                  : "a calculated parameter");
        else
            rst_log(inst, RST_ERROR, "%s: %s is a %s parameter and cannot be set in %s (only %s)", function,
                    var->name, var->variability == RST_TUNABLE ? "tunable" : "fixed",
                    front_mode_name(inst, inst->mode, buffer, sizeof buffer),
                    var->variability == RST_TUNABLE ? "in event mode, step mode or before initialization ends"
                                                    : "before initialization ends");
        return 0;
    }
    /* The value the variable holds, bit for bit, was checked when the variable got it (its start value,
     * inside its declared range; a set call; a validated FMU state): hosts that set every input at every
     * step pay the range and the backend's checks for the values that changed only. */
    if (memcmp(&value, &inst->head.store[vr], sizeof value) == 0)
        return 1;
    if (!front_in_range(var, value)) {
        front_describe_value(var->type, value, text, sizeof text);
        rst_log(inst, RST_ERROR, "%s = %s is outside the allowed range: %s", var->name, text,
                var->range_text ? var->range_text : "finite");
        return 0;
    }
    if (accept_asked(inst->model, vr) && inst->model->accept(inst, var, value) != RST_OK)
        return 0;
    return 1;
}

/* The set of a call: every value checked, then all stored, or none (a rejected value leaves every
 * variable as it was). The backend hears of the new values once per type. */
static rst_status set_checked(rst_instance *inst, const char *function, unsigned int kinds, const rst_vr vr[],
                              size_t n, const double *values)
{
    size_t i;
    for (i = 0; i < n; i++)
        if (!check_set(inst, function, vr[i], kinds, values[i]))
            return RST_ERROR;
    for (i = 0; i < n; i++)
        inst->head.store[vr[i]] = values[i];
    if (inst->model->set == NULL || n == 0)
        return RST_OK;
    /* the kinds of one call are of one storage type (Integer and Enumeration are both integers) */
    return front_backend_status(inst, inst->model->set(inst, inst->model->variables[vr[0]].type, vr, n, values));
}

static int check_counts(rst_instance *inst, const char *function, const rst_vr vr[], size_t n, const void *values,
                        size_t n_values)
{
    if (n > 0 && (vr == NULL || values == NULL)) {
        rst_log(inst, RST_ERROR, "%s: NULL value reference or value array for %u variables", function,
                (unsigned int)n);
        return 0;
    }
    if (n_values != n) {
        rst_log(inst, RST_ERROR, "%s: %u values for %u value references (every variable here is a scalar: one "
                "value each)", function, (unsigned int)n_values, (unsigned int)n);
        return 0;
    }
    return 1;
}

rst_status front_set(void *c, const char *function, unsigned int kinds, const rst_vr vr[], size_t n,
                     const void *values, size_t n_values, rst_read_fn read)
{
    double buffer[CHUNK], *all = buffer;
    rst_status status;
    size_t i;
    ENTER(function, SET_MODES)
    if (!check_counts(inst, function, vr, n, values, n_values))
        LEAVE(RST_ERROR);
    if (n > CHUNK) {
        all = (double *)inst->allocate(n, sizeof(double));
        if (all == NULL) {
            rst_log(inst, RST_ERROR, "%s: out of memory for %u values", function, (unsigned int)n);
            LEAVE(RST_ERROR);
        }
    }
    if (read == NULL) /* doubles: copied (so that the values checked are those stored), a few: no memcpy call */
        for (i = 0; i < n; i++)
            all[i] = ((const double *)values)[i];
    else if (n > 0) /* (values may be NULL then) */
        read(values, 0, n, all);
    status = set_checked(inst, function, kinds, vr, n, all);
    if (all != buffer)
        inst->release(all);
    LEAVE(status);
}

/* Reads `n` (at most CHUNK) variables into `out`: inputs and parameters from the store, outputs,
 * locals and calculated parameters (what the model computes) from the backend in one call. */
static rst_status get_chunk(rst_instance *inst, const char *function, unsigned int kinds, const rst_vr vr[],
                            size_t n, double *out)
{
    rst_vr outputs[CHUNK];
    double output_values[CHUNK];
    size_t position[CHUNK];
    size_t i, n_outputs = 0;
    rst_status status;
    int computed_by_backend = inst->model->get_outputs != NULL;
    for (i = 0; i < n; i++) {
        const rst_variable *var = vr[i] < inst->model->n_variables ? &inst->model->variables[vr[i]] : NULL;
        if (var == NULL || !(kinds & (unsigned int)access_of(var))) { /* time, or refused with a message */
            if (!check_vr(inst, function, vr[i], kinds))
                return RST_ERROR;
            out[i] = rst_time(inst);
            continue;
        }
        out[i] = inst->head.store[vr[i]];
        if (computed_by_backend && (var->causality == RST_OUTPUT || var->causality == RST_LOCAL ||
                                    var->causality == RST_CALCULATEDPARAMETER)) {
            position[n_outputs] = i;
            outputs[n_outputs++] = vr[i];
        }
    }
    if (n_outputs == 0)
        return RST_OK;
    if (n_outputs == n) /* all of them (a host reading its outputs): straight into `out` */
        return front_backend_status(inst, inst->model->get_outputs(inst, inst->model->variables[vr[0]].type, vr, n,
                                                                   out));
    status = front_backend_status(inst, inst->model->get_outputs(inst, inst->model->variables[outputs[0]].type,
                                                                 outputs, n_outputs, output_values));
    if (status < RST_ERROR)
        for (i = 0; i < n_outputs; i++)
            out[position[i]] = output_values[i];
    return status;
}

rst_status front_read(rst_instance *inst, const char *function, unsigned int kinds, const rst_vr vr[], size_t n,
                      void *values, rst_write_fn write)
{
    size_t i0;
    double buffer[CHUNK];
    rst_status status = RST_OK;
    if (write == NULL && n <= CHUNK) /* the commonest get: a few doubles, one run */
        return get_chunk(inst, function, kinds, vr, n, (double *)values);
    for (i0 = 0; i0 < n; i0 += CHUNK) {
        size_t m = n - i0 < CHUNK ? n - i0 : CHUNK;
        /* doubles (write NULL) straight into the host's array: on an error its values are undefined */
        rst_status s = get_chunk(inst, function, kinds, vr + i0, m, write == NULL ? (double *)values + i0 : buffer);
        if (s > status)
            status = s;
        if (s >= RST_ERROR)
            return status;
        if (write != NULL)
            write(values, i0, m, buffer);
    }
    return status;
}

rst_status front_get(void *c, const char *function, unsigned int kinds, const rst_vr vr[], size_t n,
                     void *values, size_t n_values, rst_write_fn write)
{
    ENTER(function, GET_MODES)
    if (!check_counts(inst, function, vr, n, values, n_values))
        LEAVE(RST_ERROR);
    LEAVE(front_read(inst, function, kinds, vr, n, values, write));
}

rst_status front_refuse_type(void *c, const char *function, const char *type_name, const rst_vr vr[], size_t n,
                             int set)
{
    size_t i;
    ENTER(function, set ? SET_MODES : GET_MODES)
    for (i = 0; i < n; i++) {
        if (vr != NULL && is_time(inst, vr[i]))
            rst_log(inst, RST_ERROR, "%s: time is %s %s variable, not %s", function,
                    article(access_name(inst, RST_AS_REAL)), access_name(inst, RST_AS_REAL), type_name);
        else if (vr == NULL || vr[i] >= inst->model->n_variables)
            rst_log(inst, RST_ERROR, "%s: unknown value reference %u (this FMU has no %s variables)", function,
                    vr ? vr[i] : 0u, type_name);
        else {
            const char *type = access_name(inst, (unsigned int)access_of(&inst->model->variables[vr[i]]));
            rst_log(inst, RST_ERROR, "%s: %s is %s %s variable, not %s", function, inst->model->variables[vr[i]].name,
                    article(type), type, type_name);
        }
        LEAVE(RST_ERROR);
    }
    LEAVE(RST_OK);
}
