/* The native SpherePlateImpact FMU: the C front (cfront/rst_front.h) bound to the native backend
 * (rst_native_impact.h). The front checks every call and value; this file only decides when to
 * evaluate: lazily, when an output is read or a step taken after an input or parameter changed (e and
 * v_rebound then; the other outputs on their first read after it, or where a departure is to be logged); and
 * when the parameter-only terms must be recomputed: after anything but v_approach was set, a reset or
 * a restored FMU state (a run of impacts at changing speeds pays only for the speed-dependent work).
 * The same holds for model exchange, where the model has no states and no events. */
#include "rst_front.h"

#include <stdio.h>

#include "rst_SpherePlateImpact_interface.h" /* generated: restitution.fmu.describe.c_header */
#include "rst_model_info.h"                  /* generated: identifier and GUID of modelDescription.xml */
#include "rst_native_impact.h"

typedef struct {
    int stale;         /* an input or parameter changed since the last evaluation */
    int rest_stale;    /* the outputs other than e and v_rebound are not computed yet for the last evaluation */
    rst_impact_primary primary; /* the last evaluation's steps that e and v_rebound needed (the rest starts there) */
    rst_impact_cache cache; /* the parameter-only terms; stale (fresh = 0) after anything but v_approach changed */
    int failed;        /* the last evaluation failed: outputs are NaN/false */
    unsigned int warned; /* the conditions of log_departures logged since instantiation or reset (bits) */
} impact_backend;

static rst_status instantiate(rst_instance *inst, const char *resource_dir, int visible)
{
    impact_backend *b = (impact_backend *)rst_backend(inst);
    (void)resource_dir, (void)visible; /* no resources, no user interface */
    b->stale = 1;
    b->cache.fresh = 0;
    return RST_OK;
}

/* The inputs as the failure message shows them (the Python slave's _describe_inputs). */
static void describe_inputs(rst_instance *inst, char *out, size_t size)
{
    size_t i, k = 0;
    out[0] = '\0';
    for (i = 0; i < RST_MODEL_N_VARIABLES && k + 1 < size; i++) {
        const rst_variable *var = &RST_MODEL_VARIABLES[i];
        char value[40];
        int n;
        if (var->causality != RST_INPUT && var->causality != RST_PARAMETER)
            continue;
        if (var->type == RST_REAL)
            rst_format_double(rst_store(inst)[i], value, sizeof value);
        else
            snprintf(value, sizeof value, "%.0f", rst_store(inst)[i]);
        n = snprintf(out + k, size - k, "%s%s = %s", k ? ", " : "", var->name, value);
        if (n < 0)
            break;
        k += (size_t)n;
    }
}

#define OUT(name) rst_store(inst)[RST_SPHEREPLATEIMPACT_VR_##name]

/* An impact outside the validated domain, logged once per instance and condition with a warning (the
 * call still returns OK: reported, never clipped). The conditions and their words are
 * restitution.assumptions' (tests compare the two FMUs' messages). */
static void log_departures(rst_instance *inst, impact_backend *b)
{
    enum { LAMBDA = 1, V_STAR = 2, NEGATIVE = 4, EDGE = 8 };
    if (!OUT(ZENER_IN_RANGE) && !(b->warned & LAMBDA)) {
        b->warned |= LAMBDA;
        rst_log(inst, RST_WARNING, "zener.lambda = %.4g is above 1.5, the range Zener's plate-wave model was studied "
                "on: e = %.4g is an extrapolation (valid = false)", OUT(ZENER_LAMBDA), OUT(E));
    }
    if (!OUT(JGM_IN_RANGE) && !(b->warned & V_STAR)) {
        b->warned |= V_STAR;
        rst_log(inst, RST_WARNING, "jgm.V_star = %.4g is above 1000, the range of the JGM fits: e = %.4g is an "
                "extrapolation (valid = false)", OUT(JGM_V_STAR), OUT(E));
    }
    if (OUT(E_NEGATIVE) && !(b->warned & NEGATIVE)) {
        b->warned |= NEGATIVE;
        rst_log(inst, RST_WARNING, "e = %.4g is below 0: the sphere keeps moving with the plate after the impact "
                "(e_negative)", OUT(E));
    }
    if (!OUT(MONITOR_EDGE_CLEAR) && !(b->warned & EDGE)) {
        b->warned |= EDGE;
        rst_log(inst, RST_WARNING, "monitor.edge_echo = %.4g is below 1: a wave reflected from the plate's edge "
                "returns during the contact, which Zener's unbounded plate excludes (edge_clear = false)",
                OUT(MONITOR_EDGE_ECHO));
    }
}

/* The outputs besides e and v_rebound, on their first read after an evaluation (a step reads e and
 * v_rebound alone at the cost of those two). */
static void evaluate_rest(rst_instance *inst, impact_backend *b)
{
    char message[256], inputs[1024];
    if (!b->rest_stale)
        return;
    b->rest_stale = 0;
    b->failed = rst_impact_evaluate_rest(&b->cache, &b->primary, rst_store(inst), message, sizeof message) != 0;
    if (b->failed) {
        describe_inputs(inst, inputs, sizeof inputs);
        rst_log(inst, RST_ERROR, "evaluation failed for %s: %s", inputs, message);
    }
}

/* Does the step need the rest now, to log a departure not logged yet? */
static int departure_to_log(const impact_backend *b)
{
    enum { LAMBDA = 1, V_STAR = 2, NEGATIVE = 4, EDGE = 8 };
    return (!b->primary.valid && (b->warned & (LAMBDA | V_STAR)) != (LAMBDA | V_STAR))
           || (b->primary.e < 0.0 && !(b->warned & NEGATIVE))
           || (rst_impact_edge_monitored(&b->cache.terms) && !(b->warned & EDGE));
}

static void evaluate(rst_instance *inst, impact_backend *b)
{
    char message[256], inputs[1024];
    if (!b->stale)
        return;
    b->stale = 0;
    b->failed = rst_impact_evaluate_primary(&b->cache, rst_store(inst), &b->primary, message, sizeof message) != 0;
    b->rest_stale = !b->failed;
    if (b->failed) {
        describe_inputs(inst, inputs, sizeof inputs);
        rst_log(inst, RST_ERROR, "evaluation failed for %s: %s", inputs, message);
    } else if (departure_to_log(b)) {
        evaluate_rest(inst, b);
        if (!b->failed && (!OUT(VALID) || !OUT(MONITOR_EDGE_CLEAR) || OUT(E_NEGATIVE)))
            log_departures(inst, b);
    }
}

/* the variables rst_impact_accept looks at (the front asks about no other) */
static const unsigned int ACCEPT_VRS[] = RST_IMPACT_ACCEPT_VRS;

static rst_status accept(rst_instance *inst, const rst_variable *var, double value)
{
    char message[256];
    if (rst_impact_accept(var->vr, value, message, sizeof message) != 0) {
        rst_log(inst, RST_ERROR, "%s", message);
        return RST_ERROR;
    }
    return RST_OK;
}

/* Any slot of the store may have changed (a reset, a restored FMU state): evaluate again, terms too. */
static rst_status changed(rst_instance *inst)
{
    impact_backend *b = (impact_backend *)rst_backend(inst);
    b->stale = 1;
    b->cache.fresh = 0;
    return RST_OK;
}

/* fmi2Reset: a fresh start, whose departures are logged again (as the pythonfmu FMU, whose reset makes a
 * new slave) */
static rst_status reset(rst_instance *inst)
{
    ((impact_backend *)rst_backend(inst))->warned = 0;
    return changed(inst);
}

/* New inputs or parameters: evaluate again; the terms only if something else than v_approach was set. */
static rst_status set(rst_instance *inst, rst_type type, const rst_vr vr[], size_t n,
                      const double values[])
{
    impact_backend *b = (impact_backend *)rst_backend(inst);
    size_t i;
    (void)type, (void)values;
    b->stale = 1;
    for (i = 0; i < n; i++)
        if (vr[i] != RST_SPHEREPLATEIMPACT_VR_V_APPROACH)
            b->cache.fresh = 0;
    return RST_OK;
}

static rst_status exit_initialization(rst_instance *inst)
{
    evaluate(inst, (impact_backend *)rst_backend(inst));
    return RST_OK;
}

static rst_status get_outputs(rst_instance *inst, rst_type type, const rst_vr vr[], size_t n,
                              double values[])
{
    impact_backend *b = (impact_backend *)rst_backend(inst);
    const double *store = rst_store(inst);
    size_t i;
    (void)type;
    evaluate(inst, b);
    for (i = 0; i < n && b->rest_stale; i++)
        if (vr[i] != RST_SPHEREPLATEIMPACT_VR_E && vr[i] != RST_SPHEREPLATEIMPACT_VR_V_REBOUND)
            evaluate_rest(inst, b);
    for (i = 0; i < n; i++)
        values[i] = store[vr[i]];
    return RST_OK;
}

static rst_status do_step(rst_instance *inst, double t, double h)
{
    impact_backend *b = (impact_backend *)rst_backend(inst);
    (void)t, (void)h;
    evaluate(inst, b);
    if (b->failed) {
        rst_log(inst, RST_DISCARD, "%sDoStep discarded: the model could not be evaluated for the current inputs "
                "(see the error above)", rst_fmi_prefix(inst));
        return RST_DISCARD;
    }
    return RST_OK;
}

const rst_model RST_MODEL = {
    .identifier = RST_MODEL_IDENTIFIER, .guid = RST_MODEL_GUID,
    .variables = RST_MODEL_VARIABLES, .n_variables = RST_MODEL_N_VARIABLES, .backend_size = sizeof(impact_backend),
    .instantiate = instantiate, .exit_initialization = exit_initialization, .accept = accept,
    .accept_vrs = ACCEPT_VRS, .n_accept_vrs = sizeof ACCEPT_VRS / sizeof ACCEPT_VRS[0], .set = set,
    .get_outputs = get_outputs, .do_step = do_step, .reset = reset, .restore_state = changed,
    /* model exchange: no states and no events, the outputs a function of the inputs (direct feedthrough) */
    .model_exchange = 1, RST_MODEL_EXCHANGE_VECTORS};
