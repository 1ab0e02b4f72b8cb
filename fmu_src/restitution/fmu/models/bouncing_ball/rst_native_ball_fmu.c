/* The native BouncingBall FMU: the C front (cfront/rst_front.h) bound to the native ball
 * (rst_native_ball.h). The ball's whole state lives in the front's value store, so the front's
 * FMU-state snapshot of the store is the ball's state and nothing needs saving or restoring here.
 * Co-simulation: the ball's own step (every contact located in closed form); FMI 3.0 adds early return
 * at each contact and event mode, where the host sets the COR for the contact's exact speed. Model exchange: the host
 * integrates h and v, locates each contact as a zero crossing of contact_indicator, and the event
 * update rebounds the ball with the COR on its input (or brings it to rest). */
#include "rst_front.h"

#include "rst_BouncingBall_interface.h" /* generated: restitution.fmu.describe.c_header */
#include "rst_model_info.h"             /* generated: identifier and GUID of modelDescription.xml */
#include "rst_native_ball.h"

static rst_status instantiate(rst_instance *inst, const char *resource_dir, int visible)
{
    (void)resource_dir, (void)visible;
    rst_ball_clear(rst_store(inst));
    return RST_OK;
}

static rst_status reset(rst_instance *inst)
{
    rst_ball_clear(rst_store(inst));
    return RST_OK;
}

static rst_status exit_initialization(rst_instance *inst)
{
    rst_ball_initialize(rst_store(inst), rst_start_time(inst));
    return RST_OK;
}

static rst_status do_step(rst_instance *inst, double t, double h)
{
    rst_ball_do_step(rst_store(inst), t, h);
    return RST_OK;
}

/* FMI 3.0 co-simulation with early return or event mode (rst_model.do_step_to_event). Early return: the
 * step ends at the first contact. Event mode: a contact waits at the plate for the host's event mode,
 * where the host sets the COR for that contact's speed and fmi3UpdateDiscreteStates rebounds. Event mode
 * without early return: the steps of contact_mode, a contact still waiting at the end of a step (wait)
 * pending for the event mode. */
static rst_status do_step_to_event(rst_instance *inst, double t, double h, int early_return, int event_mode,
                                   rst_step_end *end)
{
    double *values = rst_store(inst);
    if (early_return) {
        end->reached = rst_ball_step_to_contact(values, t, h, event_mode);
    } else {
        rst_ball_do_step(values, t, h);
        end->reached = t + h;
    }
    end->event_pending = event_mode && rst_ball_contact_pending(values);
    return RST_OK;
}

/* Model exchange: the host set the states (h, v), an input or a parameter; what depends on them follows. */
static rst_status set(rst_instance *inst, rst_type type, const rst_vr vr[], size_t n, const double values[])
{
    (void)type, (void)vr, (void)n, (void)values;
    if (rst_is_model_exchange(inst))
        rst_ball_states_changed(rst_store(inst));
    return RST_OK;
}

/* fmi2SetFMUstate: the store holds the restored state; what is recomputed from it follows (model
 * exchange: also the approach speed from the restored v). */
static rst_status restore_state(rst_instance *inst)
{
    if (rst_is_model_exchange(inst))
        rst_ball_states_changed(rst_store(inst));
    else
        rst_ball_update_derivatives(rst_store(inst));
    return RST_OK;
}

/* Model exchange: the contact located by the host's solver (contact_indicator crossed zero). FMI 3.0
 * co-simulation event mode: the pending contact rebounds with the COR the host has just set (the
 * co-simulation FMU shows the host no continuous states: nothing else to report). */
static rst_status update_discrete_states(rst_instance *inst, rst_event_update *result)
{
    if (!rst_is_model_exchange(inst)) {
        rst_ball_contact_update(rst_store(inst), rst_time(inst));
        return RST_OK;
    }
    result->states_changed = rst_ball_contact_event(rst_store(inst), rst_time(inst));
    result->nominals_changed = result->states_changed; /* the nominals are the new flight's scale */
    return RST_OK;
}

static void nominals(rst_instance *inst, double out[])
{
    rst_ball_nominals(rst_store(inst), out);
}

const rst_model RST_MODEL = {
    .identifier = RST_MODEL_IDENTIFIER, .guid = RST_MODEL_GUID,
    .variables = RST_MODEL_VARIABLES, .n_variables = RST_MODEL_N_VARIABLES, .backend_size = 0,
    .instantiate = instantiate, .exit_initialization = exit_initialization, .do_step = do_step, .reset = reset,
    .set = set, .restore_state = restore_state, .update_discrete_states = update_discrete_states,
    .nominals = nominals, .model_exchange = 1, .do_step_to_event = do_step_to_event,
    RST_MODEL_EXCHANGE_VECTORS};
