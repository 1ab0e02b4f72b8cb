/* Reads impacts (17 numbers a line: rst_impact_inputs' fields) on stdin and prints rst_impact's status and
 * result a line each (%a: exact): the tests' driver of the C physics under sanitizers and under Wine. */
#include <stdio.h>
#include "rst_physics.h"
int main(void)
{
    rst_impact_inputs in;
    rst_impact_result o;
    while (scanf("%lf %lf %lf %lf %lf %lf %lf %lf %lf %lf %lf %d %d %d %d %lf %lf", &in.v, &in.sphere_E,
                 &in.sphere_nu, &in.sphere_Sy, &in.sphere_rho, &in.sphere_d, &in.plate_E, &in.plate_nu,
                 &in.plate_Sy, &in.plate_rho, &in.plate_t, &in.restitution_model, &in.zener_method,
                 &in.plasticity, &in.plate_waves, &in.effect_tolerance, &in.ode_rtol) == 17) {
        int status = rst_impact(&in, &o);
        printf("%d %a %a %a %a %a %a %a %a %a %a %a %a %a %a %d %d %d %d %d %d\n", status, o.e, o.v_rebound,
               o.e_ep, o.V_c, o.V_star, o.eps_y, o.e_ze, o.lam, o.tau0, o.T, o.t_contact, o.m_a, o.m_eff,
               o.v_plate, o.plasticity_used, o.plate_waves_used, o.lambda_in_range, o.vstar_in_range,
               o.e_negative, o.valid);
    }
    return 0;
}
