/* The fixed steps (docs/model.md §11): the discrete-gradient step, an
 * energy-consistent scheme (O. Gonzalez, J. Nonlinear Sci. 6 (1996)
 * 449-467). Over a step of length h from (x1, v, x2) to (X, v', x2'):
 *     F   = (V(X) - V(x1)) / (X - x1),   V(x) = K x^(n+1)/(n+1) for x > 0, else 0
 *     v'  = v + h (accel - F/m)
 *     x2' = x2 + h z,                    z = (F - A) inv_B, the damper's mean rate
 *     X   = x1 + h (v + v')/2 - h z
 * so that the striker's energy and the spring's change by -F (x2' - x2)
 * and, with the dashpot (A = 0, inv_B = 1/c), the step dissipates
 * h F^2 / c >= 0 however long it is; the springpot's modes take a step
 * that dissipates each on its own (§6). One scalar root per step. */
#include <float.h>
#include <math.h>
#include <stddef.h>

#include "stage.h"


/* The discrete gradient of V(x) = K max(x, 0)^(n+1)/(n+1) between x1 and X,
 * (V(X) - V(x1))/(X - x1), for any exponent n, to a few roundings at any
 * X: where the two are close (hi <= 2 lo), as
 *     K lo^n expm1((n+1) u) / ((n+1) expm1(u)),   u = log1p((hi - lo)/lo),
 * without the secant's cancellation, which would make it noisy in X, and
 * the step's root with it (the root's residual is energy). */
static double secant_force(double K, double n, double x1, double X)
{
    const double lo = smaller(x1, X), hi = larger(x1, X);
    double u;
    if (!(hi > 0.0))
        return 0.0;
    if (!(lo > 0.0))
        return K * pow(hi, n + 1.0) / ((n + 1.0) * (hi - lo));
    if (hi > 2.0 * lo)
        return K * (pow(hi, n + 1.0) - pow(lo, n + 1.0)) / ((n + 1.0) * (hi - lo));
    u = log1p((hi - lo) / lo);
    return u > 0.0 ? K * pow(lo, n) * expm1((n + 1.0) * u) / ((n + 1.0) * expm1(u)) : K * pow(lo, n);
}

/* The root X of X - x1 + b F(x1, X) = rho (b >= 0, K > 0) for any exponent
 * and sign of x1 and X, and the secant F there: the left side increases
 * with X (V is convex) and the root lies in [hi - b K top^n, hi],
 * hi = x1 + rho, top the larger of hi and x1 (below hi the secant is at
 * most K top^n). Newton's method
 * from hi, kept inside the bracket, bisecting where it leaves it, until a
 * Newton step below 1e-8 of X leaves the root exact to rounding: the
 * energy a step keeps is off by F times the root's residual. */
static double power_mean_force(double K, double n, double x1, double rho, double b, double *X)
{
    double hi = x1 + rho, lo = hi - b * K * pow(larger(larger(hi, x1), 0.0), n), x = hi;
    int i;
    for (i = 0; i < 200; i++) {
        const double F = secant_force(K, n, x1, x), g = x - x1 + b * F - rho, d = x - x1, m = 0.5 * (x1 + x);
        /* the secant's slope in X: (F(X) - F)/(X - x1), or near X = x1 > 0
         * the slope of its series, (n K m^(n-1)/2) (1 + (n-1) r/6 (1 + (n-2) r/4)),
         * exact to O(r^3): where the dashpot is stiff (b slope >> 1) the
         * slope's error is the rate at which Newton's method converges */
        const double r = m > 0.0 ? d / m : 0.0;
        const double slope = m > 0.0 && fabs(r) <= 1e-3
                                 ? 0.5 * n * K * pow(m, n - 1.0) * (1.0 + (n - 1.0) * r / 6.0 * (1.0 + (n - 2.0) * r / 4.0))
                                 : (K * pow(larger(x, 0.0), n) - F) / d;
        const double next = x - g / (1.0 + b * slope);
        if (g > 0.0)
            hi = x;
        else
            lo = x;
        if (g == 0.0 || hi - lo <= 4.0 * DBL_EPSILON * fabs(x))
            break;
        if (next > lo && next < hi) {
            const int done = !(fabs(next - x) > 1e-8 * fabs(next));
            x = next;
            if (done)
                break;
        } else {
            x = 0.5 * (lo + hi);
        }
    }
    *X = x;
    return secant_force(K, n, x1, x);
}

/* The same for the Hertz sphere's n = 3/2 from x1 >= 0 to X >= 0, the
 * common case, without pow: in s = sqrt(X), s0 = sqrt(x1), the secant is
 * (2K/5)(s^4/(s + s0) + s0 s^2 + s0^3), and (s + s0) times the equation is
 *     G(s) = q s^4 + c3 s^2 (s + s0) + c1 (s + s0),
 *     q = 2 b K/5,  c3 = 1 + q s0,  c1 = q s0^3 - (x1 + rho),
 * whose root is X >= 0 where c1 < 0. G is convex for s >= 0, so Newton's
 * method converges monotonically from above: from the root of
 * s^2 + q s^3 = x1 + rho (stage_root), above it since the secant is at
 * least (2K/5) s^3. Returns -1 where the root is X < 0; the spring's
 * force at X in *F_end. */
static inline double hertz_mean_force(double K, double x1, double rho, double b, double *X, double *F_end)
{
    const double q = 0.4 * b * K, s0 = sqrt(x1), c3 = 1.0 + q * s0, c1 = q * s0 * x1 - (x1 + rho);
    double s, ds;
    int i;
    if (!(c1 < 0.0))
        return -1.0;
    s = stage_root(x1 + rho, q, 0.0);
    for (i = 0; i < 200; i++) {
        const double ss = s * s, t = s + s0;
        ds = (ss * (q * ss + c3 * t) + c1 * t) / (s * (4.0 * q * ss + c3 * (3.0 * s + 2.0 * s0)) + c1);
        s -= ds;
        if (!(fabs(ds) > 1e-8 * s))
            break;
    }
    *X = s * s;
    *F_end = K * s * *X;
    return 0.4 * K * (*X * *X / (s + s0) + s0 * *X + s0 * x1);
}

/* The step's mean spring force F and its end X, the root of
 * X - x1 + b F(x1, X) = rho, and the spring's force at X in *F_end. */
static inline double mean_force(const contact_model *cm, double K, double x1, double rho, double b, double *X,
                                double *F_end)
{
    const double n = cm->p.spring_exponent;
    double F;
    if (!(K > 0.0)) { /* out of contact the striker moves freely */
        *X = x1 + rho;
        *F_end = 0.0;
        return 0.0;
    }
    if (n == 1.5 && x1 >= 0.0 && (F = hertz_mean_force(K, x1, rho, b, X, F_end)) >= 0.0)
        return F;
    F = -1.0;
    if (n == 1.0 && x1 >= 0.0) { /* a linear spring: the secant is K (X + x1)/2 while X >= 0 */
        *X = (x1 + rho - 0.5 * b * K * x1) / (1.0 + 0.5 * b * K);
        if (*X >= 0.0)
            F = 0.5 * K * (*X + x1);
    }
    if (F < 0.0)
        F = power_mean_force(K, n, x1, rho, b, X);
    *F_end = *X > 0.0 ? spring_force(cm, K, *X) : 0.0;
    return F;
}

/* The springpot F = c_alpha (eta x2' + sum_i a_i phi_i), phi_i' = -b_i phi_i
 * + x2' (docs/model.md §6), over a step of length h: each mode i, a Maxwell
 * arm of a spring c_alpha a_i and a dashpot, steps as
 *     phi_i' - phi_i = mu_i h z - beta_i (phi_i + phi_i')/2,
 *     beta_i = 2 tanh(h b_i/2),  mu_i = beta_i/(h b_i)  (1 at b_i = 0)
 * and pulls with c_alpha a_i mu_i (phi_i + phi_i')/2 over it: the work of
 * that pull over the travel h z exceeds the spring's change of energy by
 * c_alpha a_i beta_i times the mean stretch squared, so each mode
 * dissipates; and the step is exact where the mode relaxes freely (keep_i
 * = e^(-h b_i)) and where it flows at a steady rate (phi_i = z/b_i). With
 * d_i = 1/(1 + beta_i/2) the mean pull is linear in z,
 * c_alpha (sum p_i phi_i + z h/2 sum q_i), p_i = a_i mu_i d_i, q_i = p_i mu_i;
 * the coefficients depend on h alone and are kept for the step length
 * last used. */
static const contact_modes *modes_for_step(contact_model *cm, double h)
{
    contact_modes *m = &cm->modes;
    size_t i;
    if (m->h == h)
        return m;
    m->sum_q = 0.0;
    for (i = 0; i < m->modes; i++) {
        const double x = h * m->b[i], beta = 2.0 * tanh(0.5 * x), mu = x > 0.0 ? beta / x : 1.0;
        const double d = 1.0 / (1.0 + 0.5 * beta);
        m->p[i] = m->a[i] * mu * d;
        m->q[i] = m->p[i] * mu;
        m->sum_q += m->q[i];
        /* phi_new = keep phi + rate z over the step */
        m->keep[i] = (1.0 - 0.5 * beta) * d;
        m->rate[i] = mu * h * d;
    }
    m->h = h;
    return m;
}

/* The springpot's mean force over a step of length h as the damper of
 * the step: its memory's pull A and its viscosity 1/inv_B. */
static damper_stage springpot_mean(contact_model *cm, double h)
{
    const contact_modes *m = modes_for_step(cm, h);
    const double c = cm->p.c_alpha;
    double S = 0.0;
    size_t i;
    for (i = 0; i < m->modes; i++)
        S += m->p[i] * m->phi[i];
    return (damper_stage){c * S, 1.0 / (c * (m->eta + 0.5 * h * m->sum_q))};
}

/* The modes after an accepted step of length h with the mean rate z. */
void advance_modes(contact_model *cm, double h, double z)
{
    const contact_modes *m = modes_for_step(cm, h);
    size_t i;
    for (i = 0; i < m->modes; i++)
        cm->modes.phi[i] = m->keep[i] * m->phi[i] + m->rate[i] * z;
}

/* One step of length h from *in with spring stiffness K (0: no contact:
 * free flight, exact while the damper rests). Writes t, x1, x2, v, F,
 * E_diss and what accepting the step needs (its length and the damper's
 * mean rate) of *out; returns the impulse of the contact force. Inlined
 * in the dashpot's and the springpot's steps below, so that the dashpot's
 * carries none of the springpot's work: `compressed` is a constant in
 * each. */
static inline double gradient_step_of(contact_model *cm, const contact_state *in, double h, double K,
                                      contact_state *out, const int compressed)
{
    const damper_stage d = compressed ? springpot_mean(cm, h) : (damper_stage){0.0, cm->inv_c};
    /* X - x1 = h (v + h (accel - F/m)/2) - h (F - A) inv_B */
    const double b = h * (d.inv_B + 0.5 * h * cm->inv_m), rho = h * (in->v + 0.5 * h * cm->accel + d.A * d.inv_B);
    double X, F_end;
    const double F = mean_force(cm, K, in->x1, rho, b, &X, &F_end), z = (F - d.A) * d.inv_B;

    carry_state(out, in);
    out->t = in->t + h;
    out->x1 = X;
    out->v = in->v + h * (cm->accel - cm->inv_m * F);
    out->F = F_end;
    out->step = h;
    out->x2_rate1 = z;
    out->x2_rate = springpot(cm) ? z : out->F * cm->inv_c;
    /* the damper's work F (x2' - x2): with the dashpot h F^2/c */
    out->x2 = in->x2 + h * z;
    out->E_diss = in->E_diss + h * F * z;
    return h * F;
}

double gradient_dashpot_step(contact_model *cm, const contact_state *in, double h, double K, contact_state *out)
{
    return gradient_step_of(cm, in, h, K, out, 0);
}

double gradient_springpot_step(contact_model *cm, const contact_state *in, double h, double K, contact_state *out)
{
    return gradient_step_of(cm, in, h, K, out, compressed_memory(cm));
}

const contact_method_record gradient_method = {
    .method = CONTACT_METHOD_GRADIENT,
    .name = "gradient",
    .dashpot_step = gradient_dashpot_step,
    .springpot_step = gradient_springpot_step,
    .accept = gradient_accept,
};
