/* The C wrapper floor (benchmarks/bench_native_build.py): the project's C front with a backend
 * that does nothing. Same hooks as the native glue; outputs are constants. */
#include "rst_front.h"

#include "rst_SpherePlateImpact_interface.h" /* generated: restitution.fmu.describe.c_header */
#include "rst_model_info.h"                  /* generated: identifier and GUID of modelDescription.xml */

static rst_status instantiate(rst_instance *inst, const char *resource_dir, int visible)
{
    (void)inst, (void)resource_dir, (void)visible;
    return RST_OK;
}

static rst_status accept(rst_instance *inst, const rst_variable *var, double value)
{
    (void)inst, (void)var, (void)value;
    return RST_OK;
}

static rst_status set(rst_instance *inst, rst_type type, const rst_vr vr[], size_t n,
                      const double values[])
{
    (void)inst, (void)type, (void)vr, (void)n, (void)values;
    return RST_OK;
}

static rst_status nothing(rst_instance *inst)
{
    (void)inst;
    return RST_OK;
}

static rst_status get_outputs(rst_instance *inst, rst_type type, const rst_vr vr[], size_t n,
                              double values[])
{
    size_t i;
    (void)inst, (void)vr;
    for (i = 0; i < n; i++)
        values[i] = type == RST_BOOLEAN ? 1.0 : 0.5;
    return RST_OK;
}

static rst_status do_step(rst_instance *inst, double t, double h)
{
    (void)inst, (void)t, (void)h;
    return RST_OK;
}

const rst_model RST_MODEL = {
    .identifier = RST_MODEL_IDENTIFIER, .guid = RST_MODEL_GUID,
    .variables = RST_MODEL_VARIABLES, .n_variables = RST_MODEL_N_VARIABLES, .backend_size = 1,
    .instantiate = instantiate, .exit_initialization = nothing, .accept = accept, .set = set,
    .get_outputs = get_outputs, .do_step = do_step, .reset = nothing, .restore_state = nothing};
