/* The precomputed C floor: see precomputed_floor.h. */
#include "precomputed_floor.h"

#include "rst_SpherePlateImpact_interface.h" /* generated: restitution.fmu.describe.c_header */

#define START(name) (RST_SPHEREPLATEIMPACT_VARIABLES[RST_SPHEREPLATEIMPACT_VR_##name].start)

int precomputed_floor_open(rst_impact_terms *terms)
{
    rst_impact_inputs in;
    /* the numeric material parameters are the ones used only where no preset material is selected */
    if (START(SPHERE_MATERIAL) != 0.0 || START(PLATE_MATERIAL) != 0.0)
        return 1;
    in.v = START(V_APPROACH);
    in.sphere_E = START(SPHERE_E), in.sphere_nu = START(SPHERE_NU), in.sphere_Sy = START(SPHERE_SY);
    in.sphere_rho = START(SPHERE_RHO), in.sphere_d = START(SPHERE_D);
    in.plate_E = START(PLATE_E), in.plate_nu = START(PLATE_NU), in.plate_Sy = START(PLATE_SY);
    in.plate_rho = START(PLATE_RHO), in.plate_t = START(PLATE_T), in.plate_edge_distance = START(PLATE_EDGE_DISTANCE);
    in.restitution_model = (int)START(RESTITUTION_MODEL), in.zener_method = (int)START(ZENER_METHOD);
    in.plasticity = (int)START(PLASTICITY), in.plate_waves = (int)START(PLATE_WAVES);
    in.effect_tolerance = START(EFFECT_TOLERANCE), in.ode_rtol = START(ZENER_ODE_TOLERANCE);
    rst_impact_terms_of(&in, terms);
    return terms->status;
}

double precomputed_floor_impact(const rst_impact_terms *terms, double v, double *v_rebound)
{
    rst_impact_result out;
    (void)rst_impact_with_terms(terms, v, &out); /* the terms' status was checked when they were made */
    *v_rebound = out.v_rebound;
    return out.e;
}
