#include "contact.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "g1.h"

/* Gamma(5/2) = 3 sqrt(pi) / 4: x1^(3/2) = Gamma(5/2) D^(-1/2) x1 (MODEL.md §3). */
#define GAMMA_5_2 1.329340388179137

/* Alexander's two-stage SDIRK: L-stable, second order, stiffly accurate.
 * L-stability keeps the step stable however fast the dashpot relaxes, and
 * damps rather than reflects what a long step cannot resolve. */
#define SDIRK_GAMMA 0.29289321881345248 /* 1 - 1/sqrt(2) */

/* A bound on contact onsets and separations inside one internal step; only
 * a diverging state could reach it. */
#define MAX_EVENTS_PER_STEP 1000

void contact_default_params(contact_params *p)
{
    p->R = 6.35e-3;
    p->E_i = 210e9;
    p->nu_i = 0.3;
    p->E_s = 2.64e9;
    p->nu_s = 0.4;
    p->k = 3.299e8;
    p->c = 6080.0;
    p->dt_max = 1e-7;
    p->g = 0.0;
    p->gap0 = 0.0;
    p->law = CONTACT_LAW_G1;
    p->g1_nodes = 0;
    p->scene = CONTACT_SCENE_DROP;
    p->scheme = CONTACT_SCHEME_SDIRK2;
}

void contact_default_striker(double *v, double *m)
{
    *v = 0.626418; /* sqrt(2 g h) for the paper's 20 mm drop */
    *m = 0.7437;
}

double hertz_constant(double R, double E_i, double nu_i, double E_s, double nu_s)
{
    double E_star = 1.0 / ((1.0 - nu_i * nu_i) / E_i + (1.0 - nu_s * nu_s) / E_s);
    return 4.0 / 3.0 * E_star * sqrt(R);
}

/* The value as a user would type it: printf's %g (1.2e+09, 6080), with
 * more digits only where the double needs them to read back the same. */
static const char *shown(double value, char text[32])
{
    int digits = 6;
    do
        snprintf(text, 32, "%.*g", digits, value);
    while (strtod(text, NULL) != value && value == value && ++digits <= 17);
    return text;
}

int contact_reject(char *msg, size_t len, const char *name, double value, const char *rule)
{
    char text[32];
    snprintf(msg, len, "%s = %s is invalid: %s", name, shown(value, text), rule);
    return -1;
}

static int positive(double x) { return isfinite(x) && x > 0.0; }
/* Positive, finite, and not denormal: its reciprocal is finite too. */
static int invertible(double x) { return isnormal(x) && x > 0.0; }
static int nonnegative(double x) { return isfinite(x) && x >= 0.0; }
static int poisson_ratio(double x) { return isfinite(x) && x > -1.0 && x <= 0.5; }

int contact_check_params(const contact_params *p, char *msg, size_t len)
{
    if (!positive(p->R))
        return contact_reject(msg, len, "R", p->R, "the tip radius must be positive and finite [m]");
    if (!positive(p->E_i))
        return contact_reject(msg, len, "E_i", p->E_i, "Young's modulus must be positive and finite [Pa]");
    if (!poisson_ratio(p->nu_i))
        return contact_reject(msg, len, "nu_i", p->nu_i, "a Poisson ratio must lie in (-1, 0.5]");
    if (!positive(p->E_s))
        return contact_reject(msg, len, "E_s", p->E_s, "Young's modulus must be positive and finite [Pa]");
    if (!poisson_ratio(p->nu_s))
        return contact_reject(msg, len, "nu_s", p->nu_s, "a Poisson ratio must lie in (-1, 0.5]");
    if (!(p->k == 0.0 || invertible(p->k)))
        return contact_reject(msg, len, "k", p->k,
                      "the Hertz constant must be positive, finite and not denormal, or 0 to derive it from R, "
                      "E_i, nu_i, E_s, nu_s [N/m^1.5]");
    if (p->k == 0.0 && !invertible(hertz_constant(p->R, p->E_i, p->nu_i, p->E_s, p->nu_s)))
        return contact_reject(msg, len, "k", p->k,
                      "the Hertz constant derived from R, E_i, nu_i, E_s, nu_s is out of range (zero, denormal or "
                      "infinite)");
    if (!invertible(p->c))
        return contact_reject(msg, len, "c", p->c, "the dashpot constant must be positive, finite and not denormal [N s/m]");
    if (!invertible(p->dt_max))
        return contact_reject(msg, len, "dt_max", p->dt_max,
                      "the largest internal step must be positive, finite and not denormal [s]");
    if (!isfinite(p->g))
        return contact_reject(msg, len, "g", p->g, "gravity must be finite [m/s^2]");
    if (!nonnegative(p->gap0))
        return contact_reject(msg, len, "gap0", p->gap0, "the initial gap must be finite and >= 0 [m]");
    if (p->law < CONTACT_LAW_G1 || p->law > CONTACT_LAW_G1_EXTRAPOLATED)
        return contact_reject(msg, len, "law", p->law,
                      "1 = G1 history sum, 2 = closed-form Hertz, 3 = G1 with Richardson extrapolation");
    if (p->g1_nodes < 0)
        return contact_reject(msg, len, "g1_nodes", p->g1_nodes,
                      "the number of G1 intervals must be >= 0 (0 = internal steps since contact onset)");
    if (p->scene != CONTACT_SCENE_DROP && p->scene != CONTACT_SCENE_DRIVEN)
        return contact_reject(msg, len, "scene", p->scene, "1 = drop test, 2 = driven");
    if (p->scheme != CONTACT_SCHEME_SDIRK2 && p->scheme != CONTACT_SCHEME_CENTRAL)
        return contact_reject(msg, len, "scheme", p->scheme, "1 = implicit SDIRK2, 2 = the paper's central differences");
    return 0;
}

/* The parameters that only serve to derive k. */
static const struct {
    const char *name;
    size_t offset;
} materials[] = {{"R", offsetof(contact_params, R)},
                 {"E_i", offsetof(contact_params, E_i)},
                 {"nu_i", offsetof(contact_params, nu_i)},
                 {"E_s", offsetof(contact_params, E_s)},
                 {"nu_s", offsetof(contact_params, nu_s)}};

#define MATERIAL(p, i) (*(const double *)((const char *)(p) + materials[i].offset))

int contact_unused_material(const contact_params *p, char *msg, size_t len)
{
    contact_params d;
    char text[32];
    size_t i, used = 0, unused = 0;
    contact_default_params(&d);
    if (p->k == 0.0)
        return 0;
    for (i = 0; i < sizeof materials / sizeof materials[0]; i++)
        if (MATERIAL(p, i) != MATERIAL(&d, i) && used < len) {
            used += (size_t)snprintf(msg + used, len - used, "%s%s = %s", unused++ ? ", " : "", materials[i].name,
                                     shown(MATERIAL(p, i), text));
        }
    if (!unused)
        return 0;
    if (used < len)
        snprintf(msg + used, len - used,
                 " %s no effect: k = %s is given and wins (set k = 0 to derive k from R, E_i, nu_i, E_s, nu_s)",
                 unused > 1 ? "have" : "has", shown(p->k, text));
    return 1;
}

int contact_check_striker(const contact_params *p, int scene, double v, double m, char *msg, size_t len)
{
    if (!isfinite(v))
        return contact_reject(msg, len, "v", v, "the striker velocity must be finite [m/s]");
    if (scene == CONTACT_SCENE_DROP && !invertible(m))
        return contact_reject(msg, len, "m", m, "the drop test's striker mass must be positive, finite and not denormal [kg]");
    if (!(m == 0.0 || invertible(m)))
        return contact_reject(msg, len, "m", m,
                      "the striker mass must be positive, finite and not denormal, or 0 in the driven scene (no "
                      "striker inertia) [kg]");
    /* What a run must be able to hold in doubles: the striker's kinetic
     * energy, the power its weight can dissipate in the dashpot, and the
     * power of a dashpot driven at the rate v. */
    if (m > 0.0 && !isfinite(0.5 * m * v * v))
        return contact_reject(msg, len, "v", v, "the striker's kinetic energy m v^2 / 2 exceeds double precision");
    if (m > 0.0 && !isfinite(m * p->g * (m * p->g) / p->c))
        return contact_reject(msg, len, "g", p->g, "the power (m g)^2 / c its weight can dissipate exceeds double precision");
    if (m == 0.0 && !isfinite(p->c * v * v))
        return contact_reject(msg, len, "v", v, "the power c v^2 of the dashpot driven at v exceeds double precision");
    return 0;
}

/* The G1 ratio of the law on N intervals (MODEL.md §4). */
static double g1_ratio(int law, double N)
{
    return law == CONTACT_LAW_G1 ? g1_line_ratio(-0.5, N) : g1_line_ratio_extrapolated(-0.5, N);
}

void contact_configure(contact_model *cm, const contact_params *p)
{
    cm->p = *p;
    cm->k = p->k > 0.0 ? p->k : hertz_constant(p->R, p->E_i, p->nu_i, p->E_s, p->nu_s);
    cm->inv_c = 1.0 / p->c;
    cm->k_fixed = p->law == CONTACT_LAW_HERTZ ? cm->k
                  : p->g1_nodes > 0 ? cm->k * g1_ratio(p->law, (double)p->g1_nodes) : 0.0;
}

void contact_start(contact_model *cm, const contact_params *p, double v0, double m)
{
    memset(cm, 0, sizeof *cm);
    contact_configure(cm, p);
    cm->s.x1 = -p->gap0;
    cm->s.v = v0;
    if (p->scene == CONTACT_SCENE_DROP) {
        cm->inv_m = 1.0 / m;
        cm->accel = p->g;
    } else {
        contact_drive(cm, v0, m, 0.0);
    }
}

void contact_drive(contact_model *cm, double v, double m, double slope)
{
    if (cm->p.scene != CONTACT_SCENE_DRIVEN)
        return;
    cm->s.v = v;
    cm->inv_m = m > 0.0 ? 1.0 / m : 0.0;
    cm->accel = m > 0.0 ? cm->p.g : slope;
}

void contact_rates(const contact_model *cm, double *x1_rate, double *v_rate, double *F_rate)
{
    const contact_state *s = &cm->s;
    double x1 = contact_elastic_indentation(cm);
    *x1_rate = s->in_contact ? s->v - s->F * cm->inv_c : 0.0;
    *v_rate = cm->accel - cm->inv_m * s->F;
    *F_rate = x1 > 0.0 ? 1.5 * contact_spring_stiffness(cm, s->n) * sqrt(x1) * *x1_rate : 0.0;
}

double contact_spring_stiffness(const contact_model *cm, long n_steps)
{
    if (cm->p.law == CONTACT_LAW_HERTZ || cm->p.g1_nodes > 0)
        return cm->k_fixed;
    return n_steps > 0 ? cm->k * g1_ratio(cm->p.law, (double)n_steps) : cm->k;
}

/* The root s > 0 of s^2 + beta s^3 = r (r > 0, beta >= 0): s^2 is the elastic
 * indentation of an implicit stage. With u = beta sqrt(r) the root is
 *     sqrt(r) (1 - u/2 + 5u^2/8 - u^3 + 231u^4/128 - 3.5u^5 + ...),
 * so for u < 1e-4 (every step at the paper's parameters: u ~ 3e-5) the
 * series to u^4 is exact to 4e-20, below rounding. Otherwise Newton's
 * method, which converges from any start at or above the root and from a
 * close one below it because the cubic increases and is convex for s > 0:
 * from sqrt(r) / (1 + u/2) (off by < u^2/2) while u <= 1, and from
 * cbrt(r / beta), above the root, when the split is stiff (u > 1). */
static double stage_root(double r, double beta)
{
    double s = sqrt(r), u = beta * s, ds;
    int i;
    if (u < 1e-4)
        return s * (1.0 - u * (0.5 - u * (0.625 - u * (1.0 - u * (231.0 / 128.0)))));
    s = u > 1.0 ? cbrt(r / beta) : s / (1.0 + 0.5 * u);
    for (i = 0; i < 200; i++) {
        ds = (s * s * (1.0 + beta * s) - r) / (s * (2.0 + 3.0 * beta * s));
        s -= ds;
        /* Newton squares the relative error: after a correction of 1e-9 the
         * iterate is exact to rounding. */
        if (!(fabs(ds) > 1e-9 * s))
            break;
    }
    return s;
}

/* One implicit stage of x1' = v - F/c, v' = accel - inv_m F with
 * F = K max(x1, 0)^(3/2):  X = xh + hg (V - F/c),  V = vh + hg (accel - inv_m F).
 * Eliminating V leaves X + beta X^(3/2) = r, one scalar root. Returns F. */
static double implicit_stage(const contact_model *cm, double K, double hg,
                             double xh, double vh, double *X, double *V)
{
    double r = xh + hg * (vh + hg * cm->accel);
    double F = 0.0;
    if (r > 0.0 && K > 0.0) {
        double s = stage_root(r, K * hg * (cm->inv_c + hg * cm->inv_m));
        *X = s * s;
        F = K * s * s * s;
    } else {
        *X = r; /* out of contact the striker moves freely */
    }
    *V = vh + hg * (cm->accel - cm->inv_m * F);
    return F;
}

/* One SDIRK step of length h from *in with spring stiffness K (0: free
 * flight, where the step is exact). Writes t, x1, x2, v, F, E_diss of *out;
 * returns the impulse of the contact force over the step. */
static double sdirk_step(const contact_model *cm, const contact_state *in, double h,
                         double K, contact_state *out)
{
    const double hg = SDIRK_GAMMA * h, hb = (1.0 - SDIRK_GAMMA) * h;
    const double inv_c = cm->inv_c;
    double X1, V1, X2, V2, F1, F2, impulse;

    F1 = implicit_stage(cm, K, hg, in->x1, in->v, &X1, &V1);
    F2 = implicit_stage(cm, K, hg, in->x1 + hb * (V1 - F1 * inv_c),
                        in->v + hb * (cm->accel - cm->inv_m * F1), &X2, &V2);
    impulse = hb * F1 + hg * F2;

    *out = *in;
    out->t = in->t + h;
    out->x1 = X2;
    out->v = V2;
    out->F = F2;
    /* The dashpot carries the spring's force: x2' = F/c, dissipating F^2/c.
     * A step counts J^2/(c h), the dissipation of its mean force J/h: within
     * O(h^3) of the integral (which exceeds it by h Var(F)/c), and unlike a
     * quadrature of the stage forces it does not overshoot the energy there
     * is when a step is far too long to resolve the motion. */
    out->x2 = in->x2 + impulse * inv_c;
    out->E_diss = in->E_diss + (h > 0.0 ? impulse * impulse * inv_c / h : 0.0);
    return impulse;
}

static void begin_contact(contact_state *s, double t, double v);

/* Free flight is the parabola x1 + v t + a t^2 / 2 (x1 <= 0: the gap). The
 * first time in [0, h] at which it enters the specimen, or -1 if it stays
 * out: either it is inside at h, or a concave parabola (a < 0) peaks inside
 * the specimen within the step and leaves again. */
static double flight_onset(double x1, double v, double a, double h)
{
    double A = 0.5 * a, disc, q, r1, r2, t;
    if (x1 >= 0.0 && (v > 0.0 || (v == 0.0 && a > 0.0)))
        return 0.0;
    if (!(x1 + h * (v + A * h) > 0.0)) {
        double vertex = a < 0.0 ? -v / a : -1.0;
        if (!(vertex > 0.0 && vertex < h && x1 + vertex * (v + A * vertex) > 0.0))
            return -1.0;
    }
    if (A == 0.0)
        t = -x1 / v;
    else {
        /* Roots without cancellation; a convex parabola enters at its larger
         * root, a concave one at its smaller. */
        disc = v * v - 4.0 * A * x1;
        q = -0.5 * (v + copysign(sqrt(disc > 0.0 ? disc : 0.0), v));
        r1 = q != 0.0 ? q / A : 0.0;
        r2 = q != 0.0 ? x1 / q : r1;
        t = a > 0.0 ? fmax(r1, r2) : fmin(r1, r2);
    }
    return fmin(fmax(t, 0.0), h);
}

/* Free flight for tau, exact (the step with no spring), then contact begins
 * if `touch`. */
static void fly(contact_model *cm, double tau, int touch)
{
    contact_state trial;
    sdirk_step(cm, &cm->s, tau, 0.0, &trial);
    cm->s = trial;
    if (touch) {
        cm->s.x1 = 0.0;
        cm->s.F = 0.0;
        begin_contact(&cm->s, cm->s.t, cm->s.v);
    }
}

/* What an event watches at the end of a trial step: the elastic indentation
 * x1 (it reaches 0 at separation) or its rate x1' = v - F/c (it reaches 0
 * where x1, and with it the force, peaks). */
typedef double (*event_value)(const contact_model *cm, const contact_state *s);

static double indentation(const contact_model *cm, const contact_state *s)
{
    (void)cm;
    return s->x1;
}

static double indentation_rate(const contact_model *cm, const contact_state *s)
{
    return s->v - s->F * cm->inv_c;
}

/* The length tau in (0, h] of a contact step from *s at which the event
 * value falls to 0, given that it is > 0 at the start and f_end <= 0 after
 * the full step: Illinois regula falsi on the value at the step's end, which
 * is continuous in tau. Returns a tau where it is <= 0, and that step's state
 * in *at. */
static double event_time(const contact_model *cm, const contact_state *s, double h, double K,
                         event_value event, double f_end, contact_state *at)
{
    double lo = 0.0, hi = h, flo = event(cm, s), fhi = f_end;
    int i, side = 0;
    sdirk_step(cm, s, h, K, at);
    for (i = 0; i < 200 && fhi != 0.0 && hi - lo > 1e-15 * h; i++) {
        contact_state trial;
        double tau = (lo * fhi - hi * flo) / (fhi - flo), f;
        if (!(tau > lo && tau < hi))
            tau = 0.5 * (lo + hi);
        sdirk_step(cm, s, tau, K, &trial);
        f = event(cm, &trial);
        if (f > 0.0) {
            lo = tau;
            flo = f;
            if (side == -1)
                fhi *= 0.5;
            side = -1;
        } else {
            hi = tau;
            fhi = f;
            *at = trial;
            if (side == 1)
                flo *= 0.5;
            side = 1;
        }
    }
    return hi;
}

/* The force's peak inside a contact step from *s to *end, if the
 * indentation turns there: sampling the peak at step ends alone would err by
 * O(h^2) of the force's curvature, more than the scheme itself. */
static double peak_force_within(const contact_model *cm, const contact_state *s, double h, double K,
                                const contact_state *end)
{
    contact_state at;
    double f_end = indentation_rate(cm, end);
    if (!(indentation_rate(cm, s) > 0.0 && f_end <= 0.0))
        return end->F;
    event_time(cm, s, h, K, indentation_rate, f_end, &at);
    return at.F > end->F ? at.F : end->F;
}

/* Contact begins at time t with striker velocity v. */
static void begin_contact(contact_state *s, double t, double v)
{
    s->n = 0;
    s->F_peak_contact = 0.0;
    s->v_onset = v;
    s->t_onset = t;
    s->in_contact = 1;
}

/* Contact ends at time t with striker velocity v. */
static void end_contact(contact_state *s, double t, double v)
{
    s->F = 0.0;
    s->eps = s->v_onset > 0.0 ? -v / s->v_onset : 0.0;
    s->t_contact = t - s->t_onset;
    s->impacts++;
    s->in_contact = 0;
}

static void accept_contact_step(contact_state *s, const contact_state *trial, double peak)
{
    *s = *trial;
    s->n++;
    if (peak > s->F_peak_contact)
        s->F_peak_contact = peak;
    if (peak > s->F_peak)
        s->F_peak = peak;
}

/* One SDIRK step of length h, split at contact onset and separation.
 * Returns 0, 1 when it stopped early at an event of the mask stop_at (the
 * state's time tells where), or -1 when the events do not end (a diverging
 * state). */
static int sdirk_internal_step(contact_model *cm, double h, double *impulse, unsigned stop_at)
{
    contact_state *s = &cm->s, trial;
    int events;
    for (events = 0; events < MAX_EVENTS_PER_STEP; events++) {
        double tau = h, K, J, peak;
        int separates;
        if (!s->in_contact) {
            tau = flight_onset(s->x1, s->v, cm->accel, h);
            fly(cm, tau < 0.0 ? h : tau, tau >= 0.0);
            if (tau < 0.0)
                return 0;
            if (stop_at & CONTACT_ONSET)
                return 1;
            h -= tau;
            continue;
        }
        K = contact_spring_stiffness(cm, s->n + 1);
        J = sdirk_step(cm, s, h, K, &trial);
        /* Separation is x1 falling to 0 on the way out: an indentation too
         * small for a double (x1 = v h underflows at v ~ 1e-317) is not one. */
        separates = !(trial.x1 > 0.0) && !(indentation_rate(cm, &trial) > 0.0);
        if (separates) {
            tau = event_time(cm, s, h, K, indentation, trial.x1, &trial);
            J = sdirk_step(cm, s, tau, K, &trial);
        }
        peak = peak_force_within(cm, s, tau, K, &trial);
        accept_contact_step(s, &trial, peak);
        *impulse += J;
        if (!separates)
            return 0;
        s->x1 = 0.0;
        end_contact(s, s->t, s->v);
        if (stop_at & CONTACT_SEPARATION)
            return 1;
        h -= tau;
    }
    return -1;
}

/* The paper's explicit scheme (MODEL.md §5), kept for comparison: x'' by
 * central differences (Stormer), the dashpot x2' = F/c by forward Euler with
 * the force of the step's start, so it is stable only while the dashpot's
 * relaxation lambda h < 2. Onset and separation are where x1 changes sign,
 * their times interpolated linearly; no step is split. */
static void central_internal_step(contact_model *cm, double h, double *impulse)
{
    contact_state *s = &cm->s;
    const double x = s->x1 + s->x2, x1 = s->x1, t = s->t, F = s->F;
    const double a = cm->accel - cm->inv_m * F;
    double x_next, x1_next;
    if (s->h_prev != h) /* (re)start the two-step recursion from the velocity */
        s->x_prev = x - h * s->v + 0.5 * h * h * a;
    x_next = cm->inv_m > 0.0 ? 2.0 * x - s->x_prev + h * h * a : x + h * s->v;
    s->x2 += h * F * cm->inv_c;
    s->E_diss += h * F * F * cm->inv_c;
    *impulse += h * F;
    x1_next = x_next - s->x2;
    if (!s->in_contact && x1_next > 0.0)
        begin_contact(s, t + h * (x1 < 0.0 ? x1 / (x1 - x1_next) : 0.0), s->v);
    s->x_prev = x;
    s->h_prev = h;
    s->x1 = x1_next;
    s->t = t + h;
    if (s->in_contact) {
        s->n++;
        s->F = x1_next > 0.0 ? contact_spring_stiffness(cm, s->n) * x1_next * sqrt(x1_next) : 0.0;
    }
    if (cm->inv_m > 0.0) /* second-order velocity at the step's end */
        s->v = (x_next - x) / h + 0.5 * h * (cm->accel - cm->inv_m * s->F);
    if (s->F > s->F_peak_contact)
        s->F_peak_contact = s->F;
    if (s->F > s->F_peak)
        s->F_peak = s->F;
    if (s->in_contact && !(x1_next > 0.0))
        end_contact(s, t + h * x1 / (x1 - x1_next), s->v);
}

/* One internal step: 0, 1 after an event of the mask stop_at (the central
 * scheme stops at the end of the step in which it happened), or -1. */
static int internal_step(contact_model *cm, double h, double *impulse, unsigned stop_at)
{
    int was_in_contact = cm->s.in_contact;
    cm->s.steps++;
    if (cm->p.scheme == CONTACT_SCHEME_CENTRAL) {
        central_internal_step(cm, h, impulse);
        return cm->s.in_contact != was_in_contact
               && (stop_at & (cm->s.in_contact ? CONTACT_ONSET : CONTACT_SEPARATION));
    }
    return sdirk_internal_step(cm, h, impulse, stop_at);
}

static int state_is_finite(const contact_state *s)
{
#define FINITE(field) && isfinite(s->field)
#define ALWAYS_FINITE(field)
    return 1 CONTACT_STATE_FIELDS(FINITE, ALWAYS_FINITE, ALWAYS_FINITE);
#undef FINITE
#undef ALWAYS_FINITE
}

double contact_advance(contact_model *cm, double H)
{
    return contact_advance_until(cm, H, 0u);
}

double contact_advance_until(contact_model *cm, double H, unsigned stop_at)
{
    const contact_state start = cm->s;
    double remaining = H, impulse = 0.0;
    int stopped = 0;
    if (!(H > 0.0))
        return 0.0;
    while (remaining > 0.0 && !stopped) {
        double n, h, i;
        if (!cm->s.in_contact && cm->p.scheme == CONTACT_SCHEME_SDIRK2) {
            /* Free flight is exact at any length: one step to the onset, or
             * over the whole rest when the striker does not arrive. */
            double tau = flight_onset(cm->s.x1, cm->s.v, cm->accel, remaining);
            cm->s.steps++;
            fly(cm, tau < 0.0 ? remaining : tau, tau >= 0.0);
            remaining = tau < 0.0 ? 0.0 : remaining - tau;
            stopped = tau >= 0.0 && (stop_at & CONTACT_ONSET);
            continue;
        }
        /* In contact: equal steps of at most dt_max over the rest, rounding
         * n up but forgiving the last few ulp (H = n dt_max gives n steps,
         * not n + 1 with a sliver), until the contact ends. */
        n = fmax(1.0, ceil(remaining / cm->p.dt_max * (1.0 - 1e-12)));
        h = remaining / n;
        for (i = 0; i < n && !stopped && (cm->s.in_contact || cm->p.scheme == CONTACT_SCHEME_CENTRAL); i++) {
            int status = internal_step(cm, h, &impulse, stop_at);
            if (status < 0) {
                cm->s = start;
                return NAN;
            }
            stopped = status;
        }
        remaining = i < n ? remaining - i * h : 0.0;
    }
    /* A non-finite value stays non-finite through the steps that follow
     * (and bounds their event searches), so one check at the end suffices. */
    if (!state_is_finite(&cm->s)) {
        cm->s = start;
        return NAN;
    }
    if (!stopped)
        cm->s.t = start.t + H;
    return impulse;
}

int contact_never_returns(const contact_model *cm)
{
    const contact_state *s = &cm->s;
    const double a = cm->accel;
    if (s->in_contact || a > 0.0)
        return 0;
    if (s->v > 0.0) /* heading in: it arrives unless a deceleration turns it in the gap first */
        return a < 0.0 && !(s->x1 + 0.5 * s->v * s->v / -a > 0.0);
    return 1;
}

double contact_elastic_indentation(const contact_model *cm)
{
    return cm->s.x1 > 0.0 ? cm->s.x1 : 0.0;
}

double contact_total_indentation(const contact_model *cm)
{
    return cm->s.x1 + cm->s.x2;
}

double contact_semi_integral_per_force(const contact_model *cm)
{
    return 1.0 / (GAMMA_5_2 * cm->k);
}

double contact_semi_integral(const contact_model *cm)
{
    return cm->s.F * contact_semi_integral_per_force(cm);
}
