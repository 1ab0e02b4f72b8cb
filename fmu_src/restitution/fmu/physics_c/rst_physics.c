/* The SpherePlateImpact model in C99: see rst_physics.h. Each function names the Python function it
 * transcribes; equation numbers are those of I. Green, Nonlinear Dyn (2022). Operations keep the
 * Python package's order of evaluation (left to right), so the two differ only where libm and
 * numpy/CPython's math differ in the last bit, amplified by the output's conditioning. */
#include "rst_physics.h"

#include <math.h>

#include "rst_zener_table.h" /* generated at build time by restitution.fmu.physics_c.zener_table_header */

#define RST_PI 3.14159265358979311600 /* math.pi */

/* Below this argument restitution._num.exp returns an exact 0 (and expm1 -1), not a subnormal. */
#define RST_EXP_MIN_ARG (-708.0)
/* restitution.jgm._EXP_ARG_CAP: cap of exp() arguments in the JGM fits. */
#define RST_EXP_ARG_CAP 700.0
#define RST_VSTAR_FIT_MAX 1000.0      /* restitution.jgm.VSTAR_FIT_MAX [1] */
#define RST_E44_BRANCH_JOIN 60.0      /* restitution.jgm.E44_BRANCH_JOIN [1] */
#define RST_LAMBDA_STUDIED_MAX 1.5    /* restitution.zener.LAMBDA_STUDIED_MAX [1] */
#define RST_ZENER_SLOPE_BOUND 1.731   /* restitution.model.ZENER_SLOPE_BOUND [1] */

/* restitution._num.exp: exp(x), 0 for x < -708 (and for NaN, as the Python comparison does). */
static double num_exp(double x) { return x >= RST_EXP_MIN_ARG ? exp(x) : 0.0; }

/* restitution._num.expm1: exp(x) - 1, -1 for x < -708. */
static double num_expm1(double x) { return x >= RST_EXP_MIN_ARG ? expm1(x) : -1.0; }

static double num_min(double a, double b) { return a <= b ? a : b; }
static double num_max(double a, double b) { return a >= b ? a : b; }

/* --- JGM, Eqs. (1)-(8) (restitution.jgm) ------------------------------------------------------ */

/* E_i' = E_i / (1 - nu_i^2) [Pa], Eq. (1) right. */
static double reduced_modulus(double E, double nu) { return E / (1.0 - nu * nu); }

/* E' = E_a' E_b' / (E_a' + E_b') [Pa], Eq. (1) left. */
static double effective_modulus(double E_a, double nu_a, double E_b, double nu_b)
{
    double Ea = reduced_modulus(E_a, nu_a), Eb = reduced_modulus(E_b, nu_b);
    return Ea * Eb / (Ea + Eb);
}

/* C(nu) = 1.295 exp(0.736 nu) [1], Eq. (2). */
static double poisson_coefficient(double nu) { return 1.295 * num_exp(0.736 * nu); }

/* C S_y = min[C(nu_a) S_ya, C(nu_b) S_yb] [Pa], Eq. (2). */
static double critical_pressure(double nu_a, double Sy_a, double nu_b, double Sy_b)
{
    return num_min(poisson_coefficient(nu_a) * Sy_a, poisson_coefficient(nu_b) * Sy_b);
}

/* eps_y = S_y / E' [1], Eq. (3), S_y of the body that yields first (C(nu_a) S_ya <= C(nu_b) S_yb: sphere). */
static double yield_strain(double E_prime, double nu_a, double Sy_a, double nu_b, double Sy_b)
{
    int sphere_first = poisson_coefficient(nu_a) * Sy_a <= poisson_coefficient(nu_b) * Sy_b;
    return (sphere_first ? Sy_a : Sy_b) / E_prime;
}

/* omega_c = (pi C S_y / (2 E'))^2 R [m], Eq. (4). */
static double critical_interference(double CSy, double E_prime, double R)
{
    double x = RST_PI * CSy / (2.0 * E_prime);
    return x * x * R;
}

/* P_c = 4/3 (R/E')^2 (pi/2 C S_y)^3 [N], Eq. (5). */
static double critical_load(double CSy, double E_prime, double R)
{
    double r = R / E_prime, p = 0.5 * RST_PI * CSy;
    return (4.0 / 3.0) * r * r * p * p * p;
}

/* m_a = rho_a pi d^3 / 6 [kg]. */
static double sphere_mass(double rho_a, double d) { return rho_a * RST_PI * d * d * d / 6.0; }

/* V_c = sqrt(4 omega_c P_c / (5 m_a)) [m/s], Eq. (6). */
static double critical_velocity(double omega_c, double P_c, double m_a) { return sqrt(0.8 * omega_c * P_c / m_a); }

/* e45 [1], Eq. (8) (JGM Eq. 45), restitution.jgm.restitution_e45: the plastic loss
 * 0.0361 eps_y^-0.114 ln(V*) (V* - 1)^(9.5 eps_y) as one exp of the sum of logarithms (no underflow
 * just above V* = 1, no overflow for brittle pairs); 1 for V* <= 1; floored at 0 beyond the fit. */
static double restitution_e45(double v_star, double eps_y)
{
    int above = v_star > 1.0;
    double vm1 = above ? v_star - 1.0 : 1.0;
    double log_v = log(above ? v_star : 2.0);
    double log_loss = log(0.0361) - 0.114 * log(eps_y) + log(log_v) + 9.5 * eps_y * log(vm1);
    double e = 1.0 - num_exp(num_min(log_loss, RST_EXP_ARG_CAP));
    return above ? num_max(e, 0.0) : 1.0;
}

/* e44 [1], Eq. (7) (JGM Eqs. 43-44), restitution.jgm.restitution_e44, second branch reconstructed
 * as ((V* - 60)/940)^2.366 (docs/paper_departures.md; the OCR'd (V* - 60)^2.366 cannot be right); floored at 0. */
static double restitution_e44(double v_star)
{
    int above = v_star > 1.0, upper = v_star > RST_E44_BRANCH_JOIN;
    double vm1 = above ? v_star - 1.0 : 1.0;
    double low = 1.0 - 0.1 * log(above ? v_star : 1.0) * pow(vm1 / 59.0, 0.156);
    double v_hi = upper ? v_star : RST_E44_BRANCH_JOIN;
    double ratio = (v_hi - RST_E44_BRANCH_JOIN) / 940.0;
    double high = 1.0 - 0.1 * log(60.0) - 0.11 * log(v_hi / RST_E44_BRANCH_JOIN)
                  * num_exp(num_min(2.366 * log(upper ? ratio : 1.0), RST_EXP_ARG_CAP));
    double e = upper ? high : low;
    return above ? num_max(e, 0.0) : 1.0;
}

/* --- Zener, Eqs. (9)-(13a), (22) (restitution.zener, restitution.zener_exact) -------------------- */

/* lambda [1], Eq. (12): pi^(3/5)/sqrt(3) ((d/2)/t)^2 (v0/v')^(1/5) (rho_a/rho_b)^(3/5) (E_a'/(E_a'+E_b'))^(2/5),
 * v' = sqrt(E_b'/rho_b) [m/s]. */
static double inelasticity_parameter(double v0, double E_a, double nu_a, double rho_a, double d,
                                     double E_b, double nu_b, double rho_b, double t)
{
    double Ea = reduced_modulus(E_a, nu_a), Eb = reduced_modulus(E_b, nu_b);
    double r_over_t = 0.5 * d / t;
    double wave_speed = sqrt(reduced_modulus(E_b, nu_b) / rho_b);
    double prefactor = pow(RST_PI, 0.6) / sqrt(3.0);
    return prefactor * r_over_t * r_over_t * pow(v0 / wave_speed, 0.2) * pow(rho_a / rho_b, 0.6)
           * pow(Ea / (Ea + Eb), 0.4);
}

/* k = (4/3) (d/2)^(1/2) E' [N/m^1.5], the Hertz stiffness under Eq. (10). */
static double hertz_stiffness(double E_prime, double d) { return (4.0 / 3.0) * sqrt(0.5 * d) * E_prime; }

/* T = (m_a / (k v0^(1/2)))^(2/5) [s], Eq. (9). */
static double time_scale(double m_a, double k, double v0) { return pow(m_a / (k * sqrt(v0)), 0.4); }

/* `exact`, 0 <= lambda <= 100: the Hermite piece of the generated table (zener_exact._table_scalar). */
static void zener_exact_table(double lam, double *e_ze, double *deficit, double *tau0)
{
    double x = lam * RST_ZT_INV_H;
    int cell = (int)x;
    const double *c;
    double t;
    if (cell >= RST_ZT_N_CELLS) /* unreachable for lambda <= 100; keeps the index inside the table */
        cell = RST_ZT_N_CELLS - 1;
    c = RST_ZT_PIECES[RST_ZT_CELL_PIECE[cell]];
    t = x - c[0];
    *e_ze = c[1] + t * (c[2] + t * (c[3] + t * c[4]));
    *deficit = c[5] + t * (c[6] + t * (c[7] + t * c[8]));
    *tau0 = c[9] + t * (c[10] + t * (c[11] + t * c[12]));
}

/* `exact`, lambda > 100: e_ze = E_INF lambda^-5, tau0 = lambda (5 ln lambda + g(lambda^(-5/3))), g by
 * Clenshaw's recurrence on its Chebyshev series (zener_exact._asym). */
static void zener_exact_asymptotic(double lam, double *e_ze, double *deficit, double *tau0)
{
    double u = pow(lam, -5.0 / 3.0);
    double z2 = 2.0 * (2.0 * u / RST_ZT_U_MAX - 1.0);
    double b1 = 0.0, b2 = 0.0, g;
    int k;
    for (k = RST_ZT_N_CHEB - 1; k > 0; k--) {
        double next = RST_ZT_G_CHEB[k] + z2 * b1 - b2;
        b2 = b1;
        b1 = next;
    }
    g = RST_ZT_G_CHEB[0] + 0.5 * z2 * b1 - b2;
    *e_ze = RST_ZT_E_INF * pow(1.0 / lam, 5.0);
    *deficit = 1.0 - *e_ze;
    *tau0 = lam * (5.0 * log(lam) + g);
}

/* Eqs. (13), (13a) as published, tau0 held at lambda = 169.2 beyond (zener.zener_paper_fit and
 * zener_paper_fit_deficit: 1 - e_ze as -expm1(-1.68374 lambda)). */
static void zener_paper_fit(double lam, double *e_ze, double *deficit, double *tau0)
{
    *e_ze = num_exp(-1.68374 * lam);
    *deficit = -num_expm1(-1.68374 * lam);
    *tau0 = 3.215 * num_exp(0.318 * pow(num_min(lam, RST_PAPER_FIT_LAMBDA_CAP), 1.5));
}

/* The linearised ODE, Eq. (22), in closed form (zener.zener_linear, zener_linear_deficit): for
 * lambda < 2, e = exp(-pi lambda / sqrt(4 - lambda^2)), tau0 = 2 pi / sqrt(4 - lambda^2);
 * e = 0, tau0 = +inf beyond (never returns to sigma = 0). */
static void zener_linear(double lam, double *e_ze, double *deficit, double *tau0)
{
    int under = lam < 2.0;
    double lam_u = under ? lam : 0.0;
    double root = sqrt(4.0 - lam_u * lam_u);
    *e_ze = under ? num_exp(-RST_PI * lam_u / root) : 0.0;
    *tau0 = under ? 2.0 * RST_PI / root : INFINITY;
    *deficit = under ? -num_expm1(-RST_PI * lam_u / sqrt(4.0 - lam_u * lam_u)) : 1.0;
}

int rst_zener_solution(double lam, int method, double *e_ze, double *deficit, double *tau0)
{
    switch (method) {
    case RST_ZENER_EXACT:
        if (lam <= RST_ZT_LAMBDA_MAX)
            zener_exact_table(lam, e_ze, deficit, tau0);
        else
            zener_exact_asymptotic(lam, e_ze, deficit, tau0);
        return RST_PHYSICS_OK;
    case RST_ZENER_PAPER_FIT:
        zener_paper_fit(lam, e_ze, deficit, tau0);
        return RST_PHYSICS_OK;
    case RST_ZENER_LINEAR:
        zener_linear(lam, e_ze, deficit, tau0);
        return RST_PHYSICS_OK;
    case RST_ZENER_ODE:
        return RST_PHYSICS_UNSUPPORTED;
    default:
        return RST_PHYSICS_BAD_CODE;
    }
}

/* tau0 [1] of each method at lambda = 0: what `plate_waves = auto` reports where it skips the effect
 * (model._TAU0_AT_LAMBDA0). */
static double tau0_at_lambda0(int method)
{
    switch (method) {
    case RST_ZENER_PAPER_FIT: return RST_TAU0_PAPER_FIT_0;
    case RST_ZENER_LINEAR: return RST_TAU0_LINEAR_0;
    default: return RST_TAU0_HERTZ;
    }
}

/* --- Monitors of Zener's assumptions, sections 3 and 4 (restitution.zener) ------------------------- */

/* 1 / c_L [s/m], the plate's bulk dilatational slowness (zener.dilatational_slowness): 0 at nu = 0.5. */
static double dilatational_slowness(double E_b, double nu_b, double rho_b)
{
    return sqrt(rho_b * (1.0 + nu_b) * (1.0 - 2.0 * nu_b) / (E_b * (1.0 - nu_b)));
}

/* (2 a / c_L) / t_contact [1] (zener.edge_echo_ratio): +inf for an unbounded plate (a = 0 or +inf) or no
 * contact, 0 where the contact never ends. */
static double edge_echo_ratio(double edge_distance, double slowness, double t_contact)
{
    if (edge_distance == 0.0 || edge_distance == INFINITY || t_contact == 0.0)
        return INFINITY;
    return 2.0 * edge_distance * slowness / t_contact;
}

/* --- Fusion, Eqs. (17)-(20) (restitution.fusion) ------------------------------------------------ */

/* e = (e_ze (1 + e_ep) - (1 - e_ep)) / 2 [1], Eq. (20) regrouped as a difference of non-negative terms. */
static double apparent_restitution(double e_ep, double e_ze) { return 0.5 * (e_ze * (1.0 + e_ep) - (1.0 - e_ep)); }

/* m_b = (1 + e_ze) m_a / (1 - e_ze) [kg], Eq. (19), with the deficit 1 - e_ze as the method computed it;
 * +inf for a zero deficit (half-space). */
static double equivalent_plate_mass(double m_a, double e_ze, double deficit)
{
    return deficit > 0.0 ? (1.0 + e_ze) * m_a / deficit : INFINITY;
}

/* m_a / m_b = (1 - e_ze) / (1 + e_ze) [1], Eq. (19) solved for the mass ratio, in [0, 1] (fusion.mass_ratio). */
static double mass_ratio(double e_ze, double deficit) { return deficit / (1.0 + e_ze); }

/* v_b2 = (1 + e_ep)(1 - e_ze)/2 v_a1 [m/s], Eq. (17) with m_b of Eq. (19). */
static double plate_velocity(double v_a1, double e_ep, double deficit) { return 0.5 * (1.0 + e_ep) * deficit * v_a1; }

/* Every real of the record NaN, every flag 0 (the record's fields, rst_impact_result.h). */
static void fail(rst_impact_result *out)
{
#define NOT_A_NUMBER(field) out->field = NAN;
#define CLEARED(field) out->field = 0;
    RST_IMPACT_RESULT_REALS(NOT_A_NUMBER)
    RST_IMPACT_RESULT_FLAGS(CLEARED)
#undef NOT_A_NUMBER
#undef CLEARED
}

/* restitution.model._pipeline for one impact. */
int rst_impact(const rst_impact_inputs *in, rst_impact_result *out)
{
    double E_prime, CSy, R, k, e_ep, lam, e_ze, deficit, tau0, skipped_tau0, e;
    int needed, status;
    if ((in->restitution_model != RST_E45 && in->restitution_model != RST_E44)
        || in->plasticity < RST_EFFECT_OFF || in->plasticity > RST_EFFECT_AUTO
        || in->plate_waves < RST_EFFECT_OFF || in->plate_waves > RST_EFFECT_AUTO
        || in->zener_method < RST_ZENER_EXACT || in->zener_method > RST_ZENER_ODE) {
        fail(out);
        return RST_PHYSICS_BAD_CODE;
    }
    if (in->zener_method == RST_ZENER_ODE) {
        fail(out);
        return RST_PHYSICS_UNSUPPORTED;
    }

    /* JGM, Eqs. (1)-(8) */
    E_prime = effective_modulus(in->sphere_E, in->sphere_nu, in->plate_E, in->plate_nu);
    CSy = critical_pressure(in->sphere_nu, in->sphere_Sy, in->plate_nu, in->plate_Sy);
    out->eps_y = yield_strain(E_prime, in->sphere_nu, in->sphere_Sy, in->plate_nu, in->plate_Sy);
    R = 0.5 * in->sphere_d;
    out->m_a = sphere_mass(in->sphere_rho, in->sphere_d);
    out->V_c = critical_velocity(critical_interference(CSy, E_prime, R), critical_load(CSy, E_prime, R), out->m_a);
    k = hertz_stiffness(E_prime, in->sphere_d);
    out->V_star = in->v / out->V_c;
    if (in->plasticity == RST_EFFECT_OFF) {
        e_ep = 1.0;
    } else {
        e_ep = in->restitution_model == RST_E45 ? restitution_e45(out->V_star, out->eps_y)
                                                : restitution_e44(out->V_star);
        if (in->plasticity == RST_EFFECT_AUTO && 1.0 - e_ep < in->effect_tolerance)
            e_ep = 1.0;
    }

    /* Zener, Eqs. (9)-(13a) */
    lam = inelasticity_parameter(in->v, in->sphere_E, in->sphere_nu, in->sphere_rho, in->sphere_d,
                                 in->plate_E, in->plate_nu, in->plate_rho, in->plate_t);
    if (in->plate_waves == RST_EFFECT_AUTO) {
        needed = RST_ZENER_SLOPE_BOUND * lam >= in->effect_tolerance;
        skipped_tau0 = tau0_at_lambda0(in->zener_method);
    } else {
        needed = in->plate_waves == RST_EFFECT_ON;
        skipped_tau0 = RST_TAU0_HERTZ;
    }
    if (needed) {
        status = rst_zener_solution(lam, in->zener_method, &e_ze, &deficit, &tau0);
        if (status != RST_PHYSICS_OK) {
            fail(out);
            return status;
        }
    } else {
        e_ze = 1.0;
        deficit = 0.0;
        tau0 = skipped_tau0;
    }
    if (in->v > 0.0) {
        out->T = time_scale(out->m_a, k, in->v);
        out->t_contact = out->T * tau0;
    } else {
        out->T = INFINITY;
        out->t_contact = 0.0;
    }

    /* Fusion, Eqs. (17)-(20) */
    e = apparent_restitution(e_ep, e_ze);
    out->e = e;
    out->v_rebound = e * in->v;
    out->e_ep = e_ep;
    out->e_ze = e_ze;
    out->lam = lam;
    out->tau0 = tau0;
    out->m_eff = equivalent_plate_mass(out->m_a, e_ze, deficit);
    out->mass_ratio = mass_ratio(e_ze, deficit);
    out->v_plate = plate_velocity(in->v, e_ep, deficit);
    out->plasticity_used = e_ep < 1.0;
    out->plate_waves_used = needed;
    out->lambda_in_range = lam <= RST_LAMBDA_STUDIED_MAX;
    out->vstar_in_range = out->V_star <= RST_VSTAR_FIT_MAX;
    out->e_negative = e < 0.0;
    out->contact_ends = tau0 < INFINITY;
    /* monitors (model._pipeline): the half-space contact is its own reference where Zener was skipped */
    out->wave_delay = needed ? tau0 / tau0_at_lambda0(in->zener_method) : 1.0;
    out->edge_echo = edge_echo_ratio(in->plate_edge_distance,
                                     dilatational_slowness(in->plate_E, in->plate_nu, in->plate_rho), out->t_contact);
    out->concurrent = out->wave_delay <= RST_WAVE_DELAY_LIMIT;
    out->edge_clear = out->edge_echo >= 1.0;
    out->valid = out->lambda_in_range && out->vstar_in_range;
    return RST_PHYSICS_OK;
}
