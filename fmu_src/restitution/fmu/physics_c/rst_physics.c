/* The SpherePlateImpact model in C99: see rst_physics.h. Each function names the Python function it
 * transcribes; equation numbers are those of I. Green, Nonlinear Dyn (2022). Operations keep the
 * Python package's order of evaluation (left to right), but for what is split into a parameter-only
 * term computed once (rst_impact_terms_of) and a speed factor: lambda = (lambda / v^(1/5)) v^(1/5) and
 * T = (T v^(1/5)) / v^(1/5), the same numbers within a few ulps. So the two differ only by a few ulps,
 * amplified by each output's conditioning (restitution.agreement's tolerances). */
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

/* E' = E_a' E_b' / (E_a' + E_b') [Pa], Eq. (1) left, from the reduced moduli E_a', E_b' [Pa]. */
static double effective_modulus(double Ea, double Eb) { return Ea * Eb / (Ea + Eb); }

/* C(nu) = 1.295 exp(0.736 nu) [1], Eq. (2). */
static double poisson_coefficient(double nu) { return 1.295 * num_exp(0.736 * nu); }

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

/* ln 0.0361 - 0.114 ln eps_y [1]: the part of Eq. (8)'s log-loss that depends on the materials only
 * (eps_y [1], Eq. 3); the first two terms of restitution_e45's sum, in the same order. */
static double e45_log_factor(double eps_y) { return log(0.0361) - 0.114 * log(eps_y); }

/* e45 [1], Eq. (8) (JGM Eq. 45), restitution.jgm.restitution_e45: the plastic loss
 * 0.0361 eps_y^-0.114 ln(V*) (V* - 1)^(9.5 eps_y) as one exp of the sum of logarithms (no underflow
 * just above V* = 1, no overflow for brittle pairs); 1 for V* <= 1; floored at 0 beyond the fit.
 * log_factor = e45_log_factor(eps_y) [1], exponent = 9.5 eps_y [1]. */
static double restitution_e45(double v_star, double log_factor, double exponent)
{
    double log_loss;
    if (!(v_star > 1.0))
        return 1.0;
    log_loss = log_factor + log(log(v_star)) + exponent * log(v_star - 1.0);
    return num_max(1.0 - num_exp(num_min(log_loss, RST_EXP_ARG_CAP)), 0.0);
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

/* lambda / v0^(1/5) [(s/m)^(1/5)], Eq. (12) without its speed factor:
 * pi^(3/5)/sqrt(3) ((d/2)/t)^2 v'^(-1/5) (rho_a/rho_b)^(3/5) (E_a'/(E_a'+E_b'))^(2/5), from the reduced
 * moduli E_a', E_b' [Pa], the densities [kg/m3], d and t [m]; v' = sqrt(E_b'/rho_b) [m/s] (Eq. 11).
 * lambda = lambda_per_speed v0^(1/5) (restitution.zener.lambda_speed_factor and lambda_from_root). */
static double lambda_per_speed(double Ea, double Eb, double rho_a, double rho_b, double d, double t)
{
    double r_over_t = 0.5 * d / t;
    double wave_speed = sqrt(Eb / rho_b);
    double prefactor = pow(RST_PI, 0.6) / sqrt(3.0);
    return prefactor * r_over_t * r_over_t * pow(1.0 / wave_speed, 0.2) * pow(rho_a / rho_b, 0.6)
           * pow(Ea / (Ea + Eb), 0.4);
}

/* k = (4/3) (d/2)^(1/2) E' [N/m^1.5], the Hertz stiffness under Eq. (10). */
static double hertz_stiffness(double E_prime, double d) { return (4.0 / 3.0) * sqrt(0.5 * d) * E_prime; }

/* T v0^(1/5) = (m_a / k)^(2/5) [s (m/s)^(1/5)], Eq. (9) T = (m_a / (k v0^(1/2)))^(2/5) without its
 * speed factor; m_a [kg], k [N/m^1.5]. */
static double time_scale_per_speed(double m_a, double k) { return pow(m_a / k, 0.4); }

/* `exact`, 0 <= lambda <= 100: the Hermite piece of the generated table that holds lambda, and lambda's
 * coordinate in it (*t); e_ze is the piece's first cubic in t (zener_exact._table_scalar). */
static const double *zener_exact_piece(double lam, double *t)
{
    double x = lam * RST_ZT_INV_H;
    int cell = (int)x;
    const double *c;
    if (cell >= RST_ZT_N_CELLS) /* unreachable for lambda <= 100; keeps the index inside the table */
        cell = RST_ZT_N_CELLS - 1;
    c = RST_ZT_PIECES[RST_ZT_CELL_PIECE[cell]];
    *t = x - c[0];
    return c;
}

static double zener_exact_restitution(const double *c, double t) { return c[1] + t * (c[2] + t * (c[3] + t * c[4])); }

/* `exact`, 0 <= lambda <= 100: (e_ze, 1 - e_ze, tau0) by the three cubics of lambda's piece. */
static void zener_exact_table(double lam, double *e_ze, double *deficit, double *tau0)
{
    double t;
    const double *c = zener_exact_piece(lam, &t);
    *e_ze = zener_exact_restitution(c, t);
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

/* (2 a / c_L) / t_contact [1] (zener.edge_echo_ratio) from echo_time = 2 a / c_L [s] and t_contact [s]:
 * +inf for an unbounded plate (a = 0 or +inf) or no contact, 0 where the contact never ends. */
static double edge_echo_ratio(int unbounded, double echo_time, double t_contact)
{
    if (unbounded || t_contact == 0.0)
        return INFINITY;
    return echo_time / t_contact;
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

/* The codes of `in` are those of rst_physics.h: RST_PHYSICS_OK, RST_PHYSICS_BAD_CODE or RST_PHYSICS_UNSUPPORTED. */
static int check_codes(const rst_impact_inputs *in)
{
    if ((in->restitution_model != RST_E45 && in->restitution_model != RST_E44)
        || in->plasticity < RST_EFFECT_OFF || in->plasticity > RST_EFFECT_AUTO
        || in->plate_waves < RST_EFFECT_OFF || in->plate_waves > RST_EFFECT_AUTO
        || in->zener_method < RST_ZENER_EXACT || in->zener_method > RST_ZENER_ODE)
        return RST_PHYSICS_BAD_CODE;
    return in->zener_method == RST_ZENER_ODE ? RST_PHYSICS_UNSUPPORTED : RST_PHYSICS_OK;
}

/* restitution.model._terms (the parameter-only parts of an impact, _material_terms among them):
 * JGM Eqs. (1)-(6), the Hertz stiffness and time unit of Eq. (9) without the speed, Eq. (12) without
 * the speed, the edge echo's travel time. Each C(nu) once (two exp), each reduced modulus once. */
void rst_impact_terms_of(const rst_impact_inputs *in, rst_impact_terms *terms)
{
    double Ea = reduced_modulus(in->sphere_E, in->sphere_nu), Eb = reduced_modulus(in->plate_E, in->plate_nu);
    double E_prime = effective_modulus(Ea, Eb);
    double CSy_a = poisson_coefficient(in->sphere_nu) * in->sphere_Sy; /* Eq. (2), per body */
    double CSy_b = poisson_coefficient(in->plate_nu) * in->plate_Sy;
    double CSy = num_min(CSy_a, CSy_b);
    double R = 0.5 * in->sphere_d;
    int sphere_first = CSy_a <= CSy_b; /* the body that yields first gives S_y of Eq. (3) */
    terms->status = check_codes(in);
    terms->restitution_model = in->restitution_model;
    terms->zener_method = in->zener_method;
    terms->plasticity = in->plasticity;
    terms->plate_waves = in->plate_waves;
    terms->effect_tolerance = in->effect_tolerance;
    terms->eps_y = (sphere_first ? in->sphere_Sy : in->plate_Sy) / E_prime; /* Eq. (3) */
    terms->m_a = sphere_mass(in->sphere_rho, in->sphere_d);
    terms->V_c = critical_velocity(critical_interference(CSy, E_prime, R), critical_load(CSy, E_prime, R), terms->m_a);
    terms->e45_log_factor = e45_log_factor(terms->eps_y);
    terms->e45_exponent = 9.5 * terms->eps_y;
    terms->lambda_per_v = lambda_per_speed(Ea, Eb, in->sphere_rho, in->plate_rho, in->sphere_d, in->plate_t);
    terms->time_per_v = time_scale_per_speed(terms->m_a, hertz_stiffness(E_prime, in->sphere_d));
    terms->unbounded = in->plate_edge_distance == 0.0 || in->plate_edge_distance == INFINITY;
    terms->echo_time = 2.0 * in->plate_edge_distance * dilatational_slowness(in->plate_E, in->plate_nu, in->plate_rho);
    terms->tau0_half_space = tau0_at_lambda0(in->zener_method);
    terms->skipped_tau0 = in->plate_waves == RST_EFFECT_AUTO ? terms->tau0_half_space : RST_TAU0_HERTZ;
}

/* e_ze [1] alone by `method` (rst_zener_solution's first value by the same operations; without the
 * deficit and tau0, which cost exp/expm1/pow in `paper_fit` and `linear`). */
static void zener_restitution(double lam, int method, double *e_ze)
{
    double deficit, tau0;
    if (method == RST_ZENER_PAPER_FIT)
        *e_ze = num_exp(-1.68374 * lam);
    else if (method == RST_ZENER_EXACT && lam <= RST_ZT_LAMBDA_MAX) {
        double t;
        const double *c = zener_exact_piece(lam, &t);
        *e_ze = zener_exact_restitution(c, t);
    } else
        (void)rst_zener_solution(lam, method, e_ze, &deficit, &tau0);
}

/* restitution.model._pipeline's steps that e and v_rebound need, at v [m/s]: Eq. (8), lambda (Eq. 12),
 * whether Zener is needed, e_ze, Eq. (20). */
int rst_impact_primary_of(const rst_impact_terms *terms, double v, rst_impact_primary *p)
{
    if (terms->status != RST_PHYSICS_OK)
        return terms->status;
    p->v = v;
    p->speed_factor = pow(v, 0.2); /* v^(1/5) [(m/s)^(1/5)]: lambda's (Eq. 12) and T's (Eq. 9) dependence on v */

    /* JGM, Eqs. (1)-(8) */
    p->V_star = v / terms->V_c;
    if (terms->plasticity == RST_EFFECT_OFF) {
        p->e_ep = 1.0;
    } else {
        p->e_ep = terms->restitution_model == RST_E45
                      ? restitution_e45(p->V_star, terms->e45_log_factor, terms->e45_exponent)
                      : restitution_e44(p->V_star);
        if (terms->plasticity == RST_EFFECT_AUTO && 1.0 - p->e_ep < terms->effect_tolerance)
            p->e_ep = 1.0;
    }

    /* Zener, Eqs. (12)-(13) */
    p->lam = terms->lambda_per_v * p->speed_factor;
    if (terms->plate_waves == RST_EFFECT_AUTO)
        p->needed = RST_ZENER_SLOPE_BOUND * p->lam >= terms->effect_tolerance;
    else
        p->needed = terms->plate_waves == RST_EFFECT_ON;
    if (p->needed)
        zener_restitution(p->lam, terms->zener_method, &p->e_ze);
    else
        p->e_ze = 1.0;

    /* Fusion, Eq. (20) */
    p->e = apparent_restitution(p->e_ep, p->e_ze);
    p->v_rebound = p->e * v;
    p->valid = p->lam <= RST_LAMBDA_STUDIED_MAX && p->V_star <= RST_VSTAR_FIT_MAX;
    return RST_PHYSICS_OK;
}

int rst_impact_edge_monitored(const rst_impact_terms *terms) { return !terms->unbounded; }

/* The rest of restitution.model._pipeline from the primary steps `p` of rst_impact_primary_of: Zener's
 * deficit and contact time, the time scale, the plate's motion, the monitors, the flags. */
int rst_impact_finish(const rst_impact_terms *terms, const rst_impact_primary *p, rst_impact_result *out)
{
    double deficit, tau0, e_ze;
    int status;
    if (terms->status != RST_PHYSICS_OK) {
        fail(out);
        return terms->status;
    }
    out->eps_y = terms->eps_y;
    out->m_a = terms->m_a;
    out->V_c = terms->V_c;
    out->V_star = p->V_star;
    if (p->needed) {
        status = rst_zener_solution(p->lam, terms->zener_method, &e_ze, &deficit, &tau0);
        if (status != RST_PHYSICS_OK) { /* unreachable: terms->status vetted the method */
            fail(out);
            return status;
        }
    } else {
        deficit = 0.0;
        tau0 = terms->skipped_tau0;
    }
    if (p->v > 0.0) {
        out->T = terms->time_per_v / p->speed_factor;
        out->t_contact = out->T * tau0;
    } else {
        out->T = INFINITY;
        out->t_contact = 0.0;
    }

    /* Fusion, Eqs. (17)-(20) */
    out->e = p->e;
    out->v_rebound = p->v_rebound;
    out->e_ep = p->e_ep;
    out->e_ze = p->e_ze;
    out->lam = p->lam;
    out->tau0 = tau0;
    out->m_eff = equivalent_plate_mass(terms->m_a, p->e_ze, deficit);
    out->mass_ratio = mass_ratio(p->e_ze, deficit);
    out->v_plate = plate_velocity(p->v, p->e_ep, deficit);
    out->plasticity_used = p->e_ep < 1.0;
    out->plate_waves_used = p->needed;
    out->lambda_in_range = p->lam <= RST_LAMBDA_STUDIED_MAX;
    out->vstar_in_range = p->V_star <= RST_VSTAR_FIT_MAX;
    out->e_negative = p->e < 0.0;
    out->contact_ends = tau0 < INFINITY;
    /* monitors (model._pipeline): the half-space contact is its own reference where Zener was skipped */
    out->wave_delay = p->needed ? tau0 / terms->tau0_half_space : 1.0;
    out->edge_echo = edge_echo_ratio(terms->unbounded, terms->echo_time, out->t_contact);
    out->concurrent = out->wave_delay <= RST_WAVE_DELAY_LIMIT;
    out->edge_clear = out->edge_echo >= 1.0;
    out->valid = out->lambda_in_range && out->vstar_in_range;
    return RST_PHYSICS_OK;
}

/* restitution.model._pipeline for one impact at v [m/s], its parameter-only terms precomputed. */
int rst_impact_with_terms(const rst_impact_terms *terms, double v, rst_impact_result *out)
{
    rst_impact_primary p;
    int status = rst_impact_primary_of(terms, v, &p);
    if (status != RST_PHYSICS_OK) {
        fail(out);
        return status;
    }
    return rst_impact_finish(terms, &p, out);
}

int rst_impact(const rst_impact_inputs *in, rst_impact_result *out)
{
    rst_impact_terms terms;
    rst_impact_terms_of(in, &terms);
    return rst_impact_with_terms(&terms, in->v, out);
}
