/* The precomputed C floor: see precomputed_floor.h. */
#include "precomputed_floor.h"

#include <math.h>

#include "rst_SpherePlateImpact_interface.h" /* generated: restitution.fmu.describe.c_header */

#define START(name) (RST_SPHEREPLATEIMPACT_VARIABLES[RST_SPHEREPLATEIMPACT_VR_##name].start)
#define PI 3.14159265358979311600

int precomputed_floor_open(precomputed_floor_terms *terms)
{
    double Ea, Eb, E_prime, c_a, c_b, CSy, eps_y, R, omega_c, P_c, m_a, V_c, lambda_per_speed;
    if (START(SPHERE_MATERIAL) != 0.0 || START(PLATE_MATERIAL) != 0.0)
        return 1;
    Ea = START(SPHERE_E) / (1.0 - START(SPHERE_NU) * START(SPHERE_NU)); /* Eq. (1) */
    Eb = START(PLATE_E) / (1.0 - START(PLATE_NU) * START(PLATE_NU));
    E_prime = Ea * Eb / (Ea + Eb);
    c_a = 1.295 * exp(0.736 * START(SPHERE_NU)) * START(SPHERE_SY); /* Eq. (2) */
    c_b = 1.295 * exp(0.736 * START(PLATE_NU)) * START(PLATE_SY);
    CSy = c_a <= c_b ? c_a : c_b;
    eps_y = (c_a <= c_b ? START(SPHERE_SY) : START(PLATE_SY)) / E_prime; /* Eq. (3) */
    R = 0.5 * START(SPHERE_D);
    omega_c = pow(PI * CSy / (2.0 * E_prime), 2.0) * R;                   /* Eq. (4) */
    P_c = 4.0 / 3.0 * pow(R / E_prime, 2.0) * pow(0.5 * PI * CSy, 3.0); /* Eq. (5) */
    m_a = START(SPHERE_RHO) * PI * pow(START(SPHERE_D), 3.0) / 6.0;
    V_c = sqrt(0.8 * omega_c * P_c / m_a); /* Eq. (6) */
    lambda_per_speed = pow(PI, 0.6) / sqrt(3.0) * pow(R / START(PLATE_T), 2.0) * pow(START(PLATE_RHO) / Eb, 0.1)
                       * pow(START(SPHERE_RHO) / START(PLATE_RHO), 0.6) * pow(Ea / (Ea + Eb), 0.4); /* Eq. (12) */
    terms->log_V_c = log(V_c);
    terms->inv_V_c = 1.0 / V_c;
    terms->loss_factor = 0.0361 * pow(eps_y, -0.114);
    terms->loss_exponent = 9.5 * eps_y;
    terms->zener_rate = -1.68374 * lambda_per_speed;
    return 0;
}

double precomputed_floor_impact(const precomputed_floor_terms *terms, double v, double *v_rebound)
{
    double log_v = log(v), v_star = v * terms->inv_V_c, e_ep = 1.0, e_ze, e;
    if (v_star > 1.0) { /* Eq. (8): 1 - A ln V* (V* - 1)^B, floored at 0 */
        e_ep = 1.0 - terms->loss_factor * (log_v - terms->log_V_c) * exp(terms->loss_exponent * log(v_star - 1.0));
        if (e_ep < 0.0)
            e_ep = 0.0;
    }
    e_ze = exp(terms->zener_rate * exp(0.2 * log_v)); /* Eq. (13) of lambda = (lambda / v^(1/5)) v^(1/5) */
    e = 0.5 * (e_ze * (1.0 + e_ep) - (1.0 - e_ep)); /* Eq. (20) */
    *v_rebound = e * v;
    return e;
}
