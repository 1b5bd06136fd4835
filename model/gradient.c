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

/* The step's root inline in it, and the dashpot's step specialised (all
 * inline, the springpot's branches gone): a call or a branch there costs
 * the fixed steps more than the noise (tests/instruction_counts.tsv). The
 * roots' rare paths (COLD) stay out of line: inline, their values would
 * crowd the common path's out of the registers. */
#if defined(__GNUC__)
#define HOT_INLINE inline __attribute__((always_inline))
#define SPECIALISED __attribute__((flatten))
#define COLD __attribute__((noinline, cold))
#else
#define HOT_INLINE inline
#define SPECIALISED
#define COLD
#endif


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

/* The step's force (docs/model.md §11): the blend
 *     F = (1 - theta) S + theta K max(X, 0)^n
 * of the discrete gradient S = secant_force and the spring's force at the
 * step's end, theta = max(0, 1 - 2/z) with z = h lambda, lambda the rate
 * at which the damper relaxes the spring at the step's start: 0 (the
 * discrete gradient, second order) wherever the step resolves that
 * relaxation, z <= 2, and just enough beyond to keep the elastic
 * indentation from overshooting its relaxed value (the linear relaxation's
 * factor (1 - z (1 - theta)/2)/(1 + z (1 + theta)/2) is then 0), where the
 * discrete gradient would let it ring from step to step. A springpot
 * relaxes the spring through the viscous part of its step resistance
 * alone: its elastic part splits the motion with the spring instead, a
 * split the blend would only make first order (gradient_step_of). */
typedef struct {
    double F, S, F_end; /* the step's force, the discrete gradient, the spring's force at X */
    double theta;
} step_force;

/* theta from h inv_B (the damper's compliance over the step) and the
 * spring's stiffness F'(x1) at the step's start. */
static double relaxation_weight(double h_inv_B, double stiffness)
{
    const double z = h_inv_B * stiffness;
    return z > 2.0 ? 1.0 - 2.0 / z : 0.0;
}

/* The root X of X - x1 + b F(X) = rho (b >= 0, K > 0) for any exponent and
 * sign of x1 and X: the left side increases with X (the secant of a convex
 * V does, and so does the spring's force) and the root lies in
 * [hi - b K top^n, hi], hi = x1 + rho, top the larger of hi and x1 (below
 * hi the force is at most K top^n). Newton's method from hi, kept inside
 * the bracket, bisecting where it leaves it, until a Newton step below
 * 1e-8 of X leaves the root exact to rounding: the energy a step keeps is
 * off by F times the root's residual. */
static COLD step_force power_mean_force(double K, double n, double theta, double x1, double rho, double b, double *X)
{
    double hi = x1 + rho, lo = hi - b * K * pow(larger(larger(hi, x1), 0.0), n), x = hi;
    step_force f;
    int i;
    for (i = 0; i < 200; i++) {
        const double S = secant_force(K, n, x1, x), F_end = K * pow(larger(x, 0.0), n), d = x - x1;
        const double m = 0.5 * (x1 + x), r = m > 0.0 ? d / m : 0.0, g = x - x1 + b * ((1.0 - theta) * S + theta * F_end) - rho;
        /* the secant's slope in X: (F(X) - S)/(X - x1), or near X = x1 > 0
         * the slope of its series, (n K m^(n-1)/2) (1 + (n-1) r/6 (1 + (n-2) r/4)),
         * exact to O(r^3): where the dashpot is stiff (b slope >> 1) the
         * slope's error is the rate at which Newton's method converges */
        const double slope = m > 0.0 && fabs(r) <= 1e-3
                                 ? 0.5 * n * K * pow(m, n - 1.0) * (1.0 + (n - 1.0) * r / 6.0 * (1.0 + (n - 2.0) * r / 4.0))
                                 : (F_end - S) / d;
        const double end_slope = x > 0.0 ? n * K * pow(x, n - 1.0) : 0.0;
        const double next = x - g / (1.0 + b * ((1.0 - theta) * slope + theta * end_slope));
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
    f.S = secant_force(K, n, x1, x);
    f.F_end = K * pow(larger(x, 0.0), n);
    f.F = (1.0 - theta) * f.S + theta * f.F_end;
    return f;
}

/* hertz_mean_force's fallback start, the root of s^2 + q4 s^3 = r: out of
 * line, so that the common start keeps its values in registers. */
static COLD double hertz_start_above(double r, double q4) { return stage_root(r, q4, 0.0); }

/* power_mean_force's root for the Hertz sphere's n = 3/2 from x1 >= 0 to
 * X >= 0, the common case, without pow: in s = sqrt(X), s0 = sqrt(x1), the secant is
 * (2K/5)(s^4/(s + s0) + s0 s^2 + s0^3) and the end's force K s^3, and
 * (s + s0) times the equation is
 *     G(s) = (q + w) s^4 + w s0 s^3 + c3 s^2 (s + s0) + c1 (s + s0),
 *     q = (1 - theta) 2 b K/5,  w = theta b K,  c3 = 1 + q s0,  c1 = q s0^3 - (x1 + rho),
 * whose root is X >= 0 where c1 < 0. G is convex for s >= 0, so Newton's
 * method converges monotonically from above, and from below where G
 * rises: from X's Chebyshev step off x1, x1 + d, d = d1 - g2 d1^2/(2 g1),
 * d1 = -g0/g1, with g0, g1, g2 the left side X - x1 + b F - rho and its
 * first two derivatives at x1 (F = K x1^(3/2), F' = 3/2 K s0, F'' = 3/4
 * K/s0; the secant's derivatives there are 1/2 and 1/3 of the force's),
 * which is off by O(d^3) and so, where the step moves x1 little, leaves
 * one Newton iteration to rounding; where that start is no good one (x1 =
 * 0, x1 + d < 0, or G falls there), from the root of s^2 + (q + w) s^3 = x1 + rho
 * (stage_root), above the root since the force is at least (q + w)/b s^3.
 * Returns 0 where the root is X < 0, and -1 where the start is no good
 * one and may_fall_back is 0 (the common step's, which calls nothing).
 * Inline twice (mean_force): with theta = 0.0 written out, where the step
 * does not blend, the blend's terms fold away (its w = 0 is tested, not
 * multiplied, as 0 * w is not 0 to the compiler). */
static HOT_INLINE int hertz_mean_force(double K, double theta, double x1, double s0, double rho, double b, double *X,
                                       step_force *f, const int may_fall_back)
{
    const int blends = theta != 0.0;
    const double bK = b * K, q = 0.4 * (1.0 - theta) * bK, w = theta * bK, c3 = 1.0 + q * s0;
    const double bF = bK * x1 * s0, c1 = 0.4 * (1.0 - theta) * bF - (x1 + rho), q4 = blends ? q + w : q;
    /* G(s) = (((q4 s + a3) s + a2) s + c1) s + c1 s0 and its slope, by Horner */
    const double a3 = blends ? w * s0 + c3 : c3, a2 = c3 * s0, a0 = c1 * s0;
    double s = -1.0, ds;
    int i;
    if (!(c1 < 0.0))
        return 0;
    if (x1 > 0.0) {
        const double g1 = 1.0 + 0.75 * bK * s0 * (1.0 + theta), d1 = (rho - bF) / g1;
        s = sqrt(x1 + d1 * (1.0 - 0.125 * bK * (1.0 + 2.0 * theta) * d1 / (s0 * g1)));
    }
    if (!(s > 0.0)) {
        if (!may_fall_back)
            return -1;
        s = hertz_start_above(x1 + rho, q4);
    }
    for (i = 0; i < 200; i++) {
        const double slope = ((4.0 * q4 * s + 3.0 * a3) * s + 2.0 * a2) * s + c1;
        if (!(slope > 0.0)) { /* a start below the root where G falls: from above instead */
            if (!may_fall_back)
                return -1;
            s = hertz_start_above(x1 + rho, q4);
            continue;
        }
        ds = ((((q4 * s + a3) * s + a2) * s + c1) * s + a0) / slope;
        s -= ds;
        if (!(fabs(ds) > 1e-8 * s))
            break;
    }
    *X = s * s;
    f->F_end = K * s * *X;
    f->S = 0.4 * K * (*X * *X / (s + s0) + s0 * *X + s0 * x1);
    f->F = blends ? (1.0 - theta) * f->S + theta * f->F_end : f->S;
    return 1;
}

/* The step's force *f and its end X, the root of X - x1 + b F(X) = rho:
 * 1, or 0 where common_only and the step is not a common one, free flight
 * or the Hertz sphere's in contact from a good start (nothing written then).
 * theta is at least theta_min. */
static HOT_INLINE int mean_force(const contact_model *cm, double K, double h_inv_B, double x1, double rho, double b,
                                 double *X, step_force *out, const int common_only, const double theta_min)
{
    const double n = cm->p.spring_exponent;
    step_force f = {0.0, 0.0, 0.0, 0.0};
    double theta, s0;
    int root;
    if (common_only && K > 0.0 && !(n == 1.5 && x1 > 0.0))
        return 0;
    if (!(K > 0.0)) { /* out of contact the striker moves freely */
        *X = x1 + rho;
        *out = f;
        return 1;
    }
    if (n == 1.5 && x1 >= 0.0) {
        s0 = sqrt(x1);
        f.theta = theta = larger(relaxation_weight(h_inv_B, 1.5 * K * s0), theta_min);
        root = theta > 0.0 ? hertz_mean_force(K, theta, x1, s0, rho, b, X, &f, !common_only)
                           : hertz_mean_force(K, 0.0, x1, s0, rho, b, X, &f, !common_only);
        if (root > 0)
            *out = f;
        if (root > 0 || common_only)
            return root > 0;
    }
    f.theta = theta = x1 > 0.0 || n == 1.0 ? relaxation_weight(h_inv_B, n * K * pow(larger(x1, 0.0), n - 1.0)) : 0.0;
    f.theta = theta = larger(theta, theta_min);
    if (n == 1.0 && x1 >= 0.0) { /* a linear spring: F = K (X (1 + theta) + x1 (1 - theta))/2 while X >= 0 */
        *X = (x1 + rho - 0.5 * b * K * (1.0 - theta) * x1) / (1.0 + 0.5 * b * K * (1.0 + theta));
        if (*X >= 0.0) {
            f.S = 0.5 * K * (*X + x1);
            f.F_end = K * *X;
            f.F = (1.0 - theta) * f.S + theta * f.F_end;
            *out = f;
            return 1;
        }
    }
    f = power_mean_force(K, n, theta, x1, rho, b, X);
    f.theta = theta;
    *out = f;
    return 1;
}

/* The springpot F = c_alpha (eta x2' + sum_i a_i phi_i), phi_i' = -b_i phi_i
 * + x2' (docs/model.md §6), over a step of length h: each mode i, a Maxwell
 * arm of a spring c_alpha a_i and a dashpot, steps as
 *     phi_i' - phi_i = mu_i h z - beta_i m_i,   m_i = (phi_i + phi_i')/2,
 *     beta_i = 2 tanh(h b_i/2),  mu_i = beta_i/(h b_i)  (1 at b_i = 0)
 * and pulls with c_alpha a_i (mu_i m_i + (1 - mu_i) z/b_i) over it: the work
 * of that pull over the travel h z exceeds the spring's change of energy by
 * c_alpha a_i (beta_i m_i^2 + (1 - mu_i) h z^2/b_i) >= 0, so each mode
 * dissipates; and the step is exact where the mode relaxes freely (keep_i
 * = e^(-h b_i), which damps a mode far faster than the step at once) and
 * where it flows at a steady rate (phi_i = z/b_i, pulling a_i z/b_i, the
 * viscosity of a fast mode). With d_i = 1/(1 + beta_i/2) the mean pull is
 * linear in z, c_alpha (sum p_i phi_i + z h/2 sum_q), p_i = a_i mu_i d_i,
 * sum_q the sum of p_i mu_i + 2 a_i (1 - mu_i)/(h b_i); the springs pull
 * with c_alpha sum a_i phi_i' = c_alpha (sum q_i phi_i + z sum_rate) after
 * it, q_i = a_i keep_i, sum_rate that of a_i rate_i. The coefficients
 * depend on h alone and are kept for the step length last used. */
static const contact_modes *modes_for_step(contact_model *cm, double h)
{
    contact_modes *m = &cm->modes;
    double sum_lag = 0.0;
    size_t i;
    if (m->h == h)
        return m;
    m->sum_q = m->sum_rate = 0.0;
    for (i = 0; i < m->modes; i++) {
        const double x = h * m->b[i], beta = 2.0 * tanh(0.5 * x), mu = x > 0.0 ? beta / x : 1.0;
        /* (1 - mu)/x, by its series x/12 - x^3/120 where 1 - mu cancels */
        const double lag = x < 1e-3 ? x * (1.0 / 12.0 - x * x / 120.0) : (1.0 - mu) / x;
        const double d = 1.0 / (1.0 + 0.5 * beta);
        m->p[i] = m->a[i] * mu * d;
        m->sum_q += m->p[i] * mu + 2.0 * m->a[i] * lag;
        sum_lag += m->a[i] * lag;
        /* phi_new = keep phi + rate z over the step */
        m->keep[i] = (1.0 - 0.5 * beta) * d;
        m->rate[i] = mu * h * d;
        m->q[i] = m->a[i] * m->keep[i];
        m->sum_rate += m->a[i] * m->rate[i];
    }
    /* of the step resistance c_alpha (eta + h sum_q/2), the part that
     * dissipates: the lumped dashpot and the modes' viscous pull
     * c_alpha a_i (1 - mu_i) z/b_i (the rest pulls through their springs) */
    cm->viscous_share = (float)((m->eta + h * sum_lag) / (m->eta + 0.5 * h * m->sum_q));
    m->h = h;
    return m;
}

/* The springpot's mean force over a step of length h as the damper of
 * the step: its memory's pull A and its viscosity 1/inv_B; and in *held
 * the part of its springs' pull after the step that is not the rate's,
 * sum a_i keep_i phi_i. */
static damper_stage springpot_mean(contact_model *cm, double h, double *held)
{
    const contact_modes *m = modes_for_step(cm, h);
    const double c = cm->p.c_alpha;
    double S = 0.0, H = 0.0;
    size_t i;
    for (i = 0; i < m->modes; i++) {
        S += m->p[i] * m->phi[i];
        H += m->q[i] * m->phi[i];
    }
    *held = H;
    return (damper_stage){c * S, 1.0 / (c * (m->eta + 0.5 * h * m->sum_q))};
}

/* The springpot's rate x2' at the end of a step with the force F there and
 * the mean rate z: its force balance F = c_alpha (eta x2' + sum a_i phi_i')
 * with the modes after the step (the state the error-controlled steps start
 * from must satisfy it); the mean rate where there is no lumped dashpot. */
static double springpot_end_rate(const contact_model *cm, double F, double z, double held)
{
    const contact_modes *m = &cm->modes;
    return m->eta > 0.0 ? (F / cm->p.c_alpha - (held + z * m->sum_rate)) / m->eta : z;
}

/* The modes after an accepted step of length h with the mean rate z. */
void advance_modes(contact_model *cm, double h, double z)
{
    const contact_modes *m = modes_for_step(cm, h);
    size_t i;
    for (i = 0; i < m->modes; i++)
        cm->modes.phi[i] = m->keep[i] * m->phi[i] + m->rate[i] * z;
}

/* The compressed springpot's blend on a contact's first step, from x1 <= 0
 * towards X_free (the end without the force, above the step's): where the
 * springpot's springs take part of the motion, theta = (n - 1)/(2n) makes
 * the mean force from x1 = 0 the mean of the end forces, K X^n/2. With the
 * secant's K X^n/(n + 1) the motion's split between the two springs would
 * start off balance by a part of the force, and where the springpot is
 * nearly a spring nothing damps that split's step-to-step mode. Weighted
 * by the springpot's elastic share of its resistance and by the share of
 * the motion its springs take, kappa/(kappa + s), kappa the spring's
 * stiffness at X_free and s = 2 (elastic resistance)/h its springs'. */
static COLD double onset_weight(const contact_model *cm, double K, double X_free, double h_inv_B)
{
    const double n = cm->p.spring_exponent, elastic = 1.0 - cm->viscous_share;
    const double kappa = X_free > 0.0 ? n * K * pow(X_free, n - 1.0) : 0.0, s = 2.0 * elastic / h_inv_B;
    return kappa > 0.0 ? (0.5 - 0.5 / n) * elastic * kappa / (kappa + s) : 0.0;
}

/* One step of length h from *in with spring stiffness K (0: no contact:
 * free flight, exact while the damper rests). Writes t, x1, x2, v, F,
 * E_diss, the damper's rate and what accepting a springpot's step needs
 * (its length and the mean rate) of *out, and the impulse of the contact
 * force in *J; returns 1, or 0 where common_only and the step is not the
 * common one (mean_force; nothing written then). Inlined in the dashpot's
 * and the springpot's steps below, so that the dashpot's carries none of
 * the springpot's work: `springpot_damper`, `compressed` and `common_only`
 * are constants in each. */
static inline int gradient_step_of(contact_model *cm, const contact_state *in, double h, double K, contact_state *out,
                                   double *J, const int springpot_damper, const int compressed, const int common_only)
{
    double held = 0.0;
    const damper_stage d = compressed ? springpot_mean(cm, h, &held) : (damper_stage){0.0, cm->inv_c};
    /* X - x1 = h (v + h (accel - F/m)/2) - h (F - A) inv_B, the pull A only
     * where there is one (0 * inv_B is not 0 to the compiler) */
    const double coast = in->v + 0.5 * h * cm->accel;
    const double b = h * (d.inv_B + 0.5 * h * cm->inv_m), rho = h * (compressed ? coast + d.A * d.inv_B : coast);
    /* the compressed springpot relaxes the spring through the viscous part
     * of its resistance alone (mean_force) */
    const double h_inv_B = compressed ? h * d.inv_B * cm->viscous_share : h * d.inv_B;
    const double theta_min = compressed && !(in->x1 > 0.0) ? onset_weight(cm, K, in->x1 + rho, h * d.inv_B) : 0.0;
    double X, z;
    step_force f;
    if (!mean_force(cm, K, h_inv_B, in->x1, rho, b, &X, &f, common_only, theta_min))
        return 0;
    z = (f.F - d.A) * d.inv_B;
    carry_state(out, in);
    out->t = in->t + h;
    out->x1 = X;
    out->v = in->v + h * (cm->accel - cm->inv_m * f.F);
    out->F = f.F_end;
    if (springpot_damper) { /* what accepting a springpot's step needs (the dashpot's, nothing) */
        out->step = h;
        out->x2_rate1 = z;
    }
    out->x2_rate = compressed ? springpot_end_rate(cm, out->F, z, held) : springpot_damper ? z : out->F * cm->inv_c;
    out->x2 = in->x2 + h * z;
    /* what the step dissipates: the damper's work F (x2' - x2), with the
     * dashpot h F^2/c, and the blend's theta (X - x1)(F_end - S) >= 0 */
    out->E_diss = in->E_diss + h * f.F * z;
    if (f.theta > 0.0)
        out->E_diss += f.theta * (X - in->x1) * (f.F_end - f.S);
    *J = h * f.F;
    return 1;
}

/* The dashpot's step other than the common ones, out of line. */
static COLD double any_dashpot_step(contact_model *cm, const contact_state *in, double h, double K, contact_state *out)
{
    double J;
    gradient_step_of(cm, in, h, K, out, &J, 0, 0, 0);
    return J;
}

/* The dashpot's step: the common ones inline and calling nothing, so that
 * they save no registers across a call; any other, the same code, out of
 * line. */
SPECIALISED double gradient_dashpot_step(contact_model *cm, const contact_state *in, double h, double K,
                                         contact_state *out)
{
    double J;
    if (gradient_step_of(cm, in, h, K, out, &J, 0, 0, 1))
        return J;
    return any_dashpot_step(cm, in, h, K, out);
}

double gradient_springpot_step(contact_model *cm, const contact_state *in, double h, double K, contact_state *out)
{
    double J;
    gradient_step_of(cm, in, h, K, out, &J, 1, compressed_memory(cm), 0);
    return J;
}

const contact_method_record gradient_method = {
    .method = CONTACT_METHOD_GRADIENT,
    .name = "gradient",
    .dashpot_step = gradient_dashpot_step,
    .springpot_step = gradient_springpot_step,
    .accept = gradient_accept,
};
