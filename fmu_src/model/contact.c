#include "contact.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "g1.h"
#include "soe.h"

/* Gamma(5/2) = 3 sqrt(pi) / 4: x1^(3/2) = Gamma(5/2) D^(-1/2) x1 (MODEL.md §3). */
#define GAMMA_5_2 1.329340388179137

/* Alexander's two-stage SDIRK: L-stable, second order, stiffly accurate.
 * L-stability keeps the step stable however fast the dashpot relaxes, and
 * damps rather than reflects what a long step cannot resolve. */
#define SDIRK_GAMMA 0.29289321881345248 /* 1 - 1/sqrt(2) */

/* A bound on contact onsets and separations inside one internal step; only
 * a diverging state could reach it. */
#define MAX_EVENTS_PER_STEP 1000

/* While a springpot's dent recovers in free flight, its memory relaxes on
 * the time scale of the time since separation: steps of a fraction f of it
 * (at least dt_max), O(log) many however long the flight. SDIRK2's error in
 * the recovery is O(f^2) (the second impact's eps was off by 4.7e-6 at
 * f = 1/8, 1.2e-6 at 1/16), so f shrinks with dt_max, f = RECOVERY_STEPS
 * dt_max / t_contact (at most 1/16), for an error of O(dt_max^2) like the
 * contact's: the flight to the next impact then takes about a sixth of the
 * last contact's steps. */
#define RECOVERY_STEPS 64.0

void contact_default_params(contact_params *p)
{
    p->R = 6.35e-3;
    p->E_i = 210e9;
    p->nu_i = 0.3;
    p->E_s = 2.64e9;
    p->nu_s = 0.4;
    p->k = 3.299e8;
    p->spring_exponent = 1.5;
    p->c = 6080.0;
    /* A springpot as damping as the dashpot at the impact's frequency
     * omega = pi / t_c ~ 2400 rad/s: c_alpha omega^alpha = c omega. */
    p->damper_order = 0.5;
    p->c_alpha = 3e5;
    p->memory_tolerance = 1e-6;
    p->tolerance = 0.0;
    p->dt_max = 0.0; /* fixed steps of CONTACT_DEFAULT_STEP; error-controlled ones uncapped */
    p->g = 0.0;
    p->gap0 = 0.0;
    p->law = CONTACT_LAW_G1;
    p->g1_nodes = 0;
    p->scene = CONTACT_SCENE_DROP;
    p->scheme = CONTACT_SCHEME_SDIRK2;
    p->damper = CONTACT_DAMPER_DASHPOT;
    p->memory = CONTACT_MEMORY_COMPRESSED;
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

static double memory_kernel_floor(const contact_params *p);

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
                      "the spring constant must be positive, finite and not denormal, or 0 to derive the Hertz "
                      "constant from R, E_i, nu_i, E_s, nu_s [N/m^n]");
    if (!(isfinite(p->spring_exponent) && p->spring_exponent >= 1.0 && p->spring_exponent <= 10.0))
        return contact_reject(msg, len, "spring_exponent", p->spring_exponent,
                      "the spring exponent n must lie in [1, 10] (1.5 Hertz sphere, 1 flat punch, 2 cone)");
    if (p->k == 0.0 && p->spring_exponent != 1.5) {
        char text[32];
        snprintf(msg, len,
                 "k = 0 is invalid with spring_exponent = %s: deriving k from R, E_i, nu_i, E_s, nu_s gives the "
                 "Hertz constant of a sphere, n = 1.5; give k for any other n",
                 shown(p->spring_exponent, text));
        return -1;
    }
    if (p->k == 0.0 && !invertible(hertz_constant(p->R, p->E_i, p->nu_i, p->E_s, p->nu_s)))
        return contact_reject(msg, len, "k", p->k,
                      "the Hertz constant derived from R, E_i, nu_i, E_s, nu_s is out of range (zero, denormal or "
                      "infinite)");
    if (!invertible(p->c))
        return contact_reject(msg, len, "c", p->c, "the dashpot constant must be positive, finite and not denormal [N s/m]");
    if (!(p->dt_max == 0.0 || invertible(p->dt_max)))
        return contact_reject(msg, len, "dt_max", p->dt_max,
                      "the largest internal step must be positive, finite and not denormal, or 0 for fixed steps "
                      "of 1e-7 s and no cap on error-controlled steps [s]");
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
    if (p->damper != CONTACT_DAMPER_DASHPOT && p->damper != CONTACT_DAMPER_SPRINGPOT)
        return contact_reject(msg, len, "damper", p->damper, "1 = dashpot, 2 = springpot");
    if (!(p->damper_order > 0.0 && p->damper_order <= 1.0))
        return contact_reject(msg, len, "damper_order", p->damper_order,
                              "the springpot's order alpha must lie in (0, 1] (1: a dashpot)");
    if (!invertible(p->c_alpha))
        return contact_reject(msg, len, "c_alpha", p->c_alpha,
                              "the springpot constant must be positive, finite and not denormal [N s^alpha/m]");
    if (p->memory != CONTACT_MEMORY_G1 && p->memory != CONTACT_MEMORY_COMPRESSED)
        return contact_reject(msg, len, "memory", p->memory, "1 = full G1 history, 2 = compressed (sum of exponentials)");
    if (!(p->memory_tolerance >= 1e-12 && p->memory_tolerance <= 1e-2))
        return contact_reject(msg, len, "memory_tolerance", p->memory_tolerance,
                              "the compressed memory's kernel tolerance must lie in [1e-12, 1e-2]");
    if (!(p->tolerance == 0.0 || (p->tolerance >= 1e-12 && p->tolerance <= 1e-2)))
        return contact_reject(msg, len, "tolerance", p->tolerance,
                              "the relative error per internal step must be 0 (fixed steps of dt_max) or lie in "
                              "[1e-12, 1e-2]");
    if (p->damper == CONTACT_DAMPER_SPRINGPOT && p->scheme == CONTACT_SCHEME_CENTRAL)
        return contact_reject(msg, len, "scheme", p->scheme,
                              "the central differences (2) drive the dashpot only; the springpot (damper = 2) needs 1");
    if (p->damper == CONTACT_DAMPER_SPRINGPOT && p->memory == CONTACT_MEMORY_COMPRESSED) {
        double a[CONTACT_MAX_MODES], b[CONTACT_MAX_MODES], eta;
        if (soe_kernel(p->damper_order, p->memory_tolerance, memory_kernel_floor(p), CONTACT_MEMORY_SPAN,
                       CONTACT_MAX_MODES, a, b, &eta) > CONTACT_MAX_MODES)
            return contact_reject(msg, len, "memory_tolerance", p->memory_tolerance,
                                  "the compressed memory would need more than 160 modes with this dt_max: "
                                  "loosen the tolerance or raise dt_max");
    }
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

static int unused_material(const contact_params *p, char *msg, size_t len)
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

/* A damper's parameter changed from its default while the other damper is
 * selected, or the compressed memory's tolerance with the full history. */
static int unused_damper_value(const contact_params *p, char *msg, size_t len)
{
    contact_params d;
    char text[32];
    const char *name = NULL, *why = NULL;
    double value = 0.0;
    contact_default_params(&d);
    if (p->damper == CONTACT_DAMPER_DASHPOT) {
        why = "damper = 1 (the dashpot, c) is selected; damper = 2 selects the springpot";
        if (p->damper_order != d.damper_order)
            name = "damper_order", value = p->damper_order;
        else if (p->c_alpha != d.c_alpha)
            name = "c_alpha", value = p->c_alpha;
        else if (p->memory != d.memory)
            name = "memory", value = p->memory;
        else if (p->memory_tolerance != d.memory_tolerance)
            name = "memory_tolerance", value = p->memory_tolerance;
    } else if (p->c != d.c) {
        name = "c", value = p->c;
        why = "damper = 2 (the springpot, c_alpha and damper_order) is selected";
    } else if (p->memory == CONTACT_MEMORY_G1 && p->memory_tolerance != d.memory_tolerance) {
        name = "memory_tolerance", value = p->memory_tolerance;
        why = "memory = 1 keeps the full G1 history, exact; the tolerance is memory = 2's";
    }
    if (!name)
        return 0;
    snprintf(msg, len, "%s = %s has no effect: %s", name, shown(value, text), why);
    return 1;
}

/* Why error-controlled steps do not apply with these parameters, or NULL:
 * they need a force that does not depend on the step count, the implicit
 * scheme, and a memory that takes any step (not the full G1 history's
 * uniform grid). */
static const char *fixed_steps_only(const contact_params *p)
{
    if (p->law != CONTACT_LAW_HERTZ && p->g1_nodes == 0)
        return "with g1_nodes = 0 the G1 laws count internal steps, whose number defines their error, so they "
               "take fixed steps of dt_max (set g1_nodes > 0 or law = 2 for error-controlled steps)";
    if (p->scheme == CONTACT_SCHEME_CENTRAL)
        return "the central differences (scheme = 2) take fixed steps of dt_max";
    if (p->damper == CONTACT_DAMPER_SPRINGPOT && p->memory == CONTACT_MEMORY_G1)
        return "the springpot's full G1 history (memory = 1) steps on a uniform grid of dt_max (memory = 2, "
               "the compressed memory, takes error-controlled steps)";
    return NULL;
}

static int tolerance_applies(const contact_params *p) { return p->tolerance > 0.0 && !fixed_steps_only(p); }

int contact_error_controlled(const contact_params *p) { return tolerance_applies(p); }

double contact_step_limit(const contact_params *p)
{
    if (p->dt_max > 0.0)
        return p->dt_max;
    return tolerance_applies(p) ? INFINITY : CONTACT_DEFAULT_STEP;
}

/* The shortest time over which the compressed memory's kernel holds its
 * tolerance. Fixed steps never go below dt_max. Error-controlled steps do,
 * far below it (the h20 impact's first steps at tolerance 1e-6 are about
 * 1e-7 s, at 1e-10 below 1e-9 s), and dt_max may be long (1e-3 s): on time
 * scales under delta the kernel's fitted part flattens out and its lumped
 * dashpot eta takes over, so the springpot would act as a dashpot there.
 * CONTACT_MEMORY_FLOOR = 1e-9 s is the smallest delta whose kernel fits
 * CONTACT_MAX_MODES at every alpha and memory_tolerance (at most 155 modes,
 * at 1e-12; 70 at the default 1e-6, 62 from dt_max = 1e-7): below it only
 * the onset's first steps of tight tolerances go, where the force and with
 * it the damper's share are negligible. Measured on the springpot's h20
 * impact (tolerance 1e-10, memory_tolerance 1e-10) against the full G1
 * history's extrapolated figures: F_peak, eps, t_contact and x2_end within
 * 1.3e-9 at alpha 0.5 and 0.8 with delta = 1e-9 s and 1e-11 s alike (the
 * steps' own error), up to 3.7e-8 off with delta = 1e-7 s. */
static double memory_kernel_floor(const contact_params *p)
{
    return tolerance_applies(p) ? fmin(contact_step_limit(p), CONTACT_MEMORY_FLOOR) : contact_step_limit(p);
}

static int unused_tolerance(const contact_params *p, char *msg, size_t len)
{
    char text[32];
    if (!(p->tolerance > 0.0) || !fixed_steps_only(p))
        return 0;
    snprintf(msg, len, "tolerance = %s has no effect: %s", shown(p->tolerance, text), fixed_steps_only(p));
    return 1;
}

int contact_unused_value(const contact_params *p, char *msg, size_t len)
{
    return unused_material(p, msg, len) || unused_damper_value(p, msg, len) || unused_tolerance(p, msg, len);
}

/* The spring constant k in use: given, or the Hertz constant derived. */
static double spring_constant(const contact_params *p)
{
    return p->k > 0.0 ? p->k : hertz_constant(p->R, p->E_i, p->nu_i, p->E_s, p->nu_s);
}

/* The time the spring K x1^n takes to stop a striker (1/inv_m its mass)
 * arriving at speed v, x_max / v with x_max = ((n + 1) v^2 / (2 K inv_m))^(1/(n+1))
 * the elastic impact's largest indentation (MODEL.md §2), or where a load
 * a > 0 presses the striker in, sqrt(x_a / a) with x_a = (a / (K inv_m))^(1/n)
 * its indentation at rest under it: the shorter. A step much longer sees the
 * striker stopped and thrown back within it, and the stages of a step that
 * holds a whole impact give back more than it brought (eps = sqrt(2) as the
 * mass vanishes). INFINITY without inertia (inv_m = 0) or either. */
static double turnaround_time(double n, double K, double inv_m, double v, double a)
{
    double t = INFINITY;
    if (!(inv_m > 0.0))
        return t;
    /* Power by power, so that no product of the inputs under- or overflows
     * (v^2 of a denormal v is 0, which made the step 0). */
    if (v > 0.0)
        t = pow((n + 1.0) / (2.0 * K), 1.0 / (n + 1.0)) * pow(inv_m, -1.0 / (n + 1.0)) * pow(v, (1.0 - n) / (n + 1.0));
    if (a > 0.0)
        t = fmin(t, sqrt(pow(a, 1.0 / n - 1.0) * pow(K, -1.0 / n) * pow(inv_m, -1.0 / n)));
    return t;
}

/* Whether the parameters step on a uniform grid whatever happens. */
static int uniform_grid(const contact_params *p)
{
    return p->scheme == CONTACT_SCHEME_CENTRAL
           || (p->damper == CONTACT_DAMPER_SPRINGPOT && p->memory == CONTACT_MEMORY_G1);
}

/* The time the damper alone takes to stop the striker: m / c for the
 * dashpot, (m / c_alpha)^(1/(2 - alpha)) for the springpot (the time scale
 * of m x'' = -c_alpha D^alpha x). */
static double damper_time(const contact_params *p, double inv_m)
{
    if (p->damper == CONTACT_DAMPER_SPRINGPOT)
        return pow(p->c_alpha * inv_m, -1.0 / (2.0 - p->damper_order));
    return 1.0 / (p->c * inv_m);
}

/* The turnaround time (above), or the damper's time where that is longer:
 * while the striker loads the specimen, the series damper bounds the force
 * (below c v for the dashpot), so no striker stops faster (a rigid spring
 * leaves the damper alone). */
static double stopping_time(const contact_params *p, double K, double inv_m, double v, double a)
{
    return fmax(turnaround_time(p->spring_exponent, K, inv_m, v, a), damper_time(p, inv_m));
}

/* The stopping time (above) of the first impact of a striker of mass m
 * starting at v: the fastest, since the striker arrives at v (or falls
 * through the gap under g) and every impact after loses speed. */
static double first_turnaround(const contact_params *p, double v, double m)
{
    const double v2 = v > 0.0 || p->g > 0.0 ? v * v + 2.0 * p->g * p->gap0 : 0.0;
    if (!(m > 0.0))
        return INFINITY;
    return stopping_time(p, spring_constant(p), 1.0 / m, v2 > 0.0 ? sqrt(v2) : 0.0, p->g);
}

/* "dt_max = 0 (fixed steps of 1e-07 s)" or "dt_max = 2e-07": the step as given. */
static const char *shown_step(const contact_params *p, char text[64])
{
    char value[32];
    if (p->dt_max > 0.0)
        snprintf(text, 64, "dt_max = %s", shown(p->dt_max, value));
    else
        snprintf(text, 64, "dt_max = 0 (fixed steps of %s s)", shown(CONTACT_DEFAULT_STEP, value));
    return text;
}

int contact_check_resolution(const contact_params *p, double v, double m, char *msg, size_t len)
{
    const double t = first_turnaround(p, v, m);
    char text[3][64];
    if (!uniform_grid(p) || !(t < CONTACT_RESOLUTION * contact_step_limit(p)))
        return 0;
    snprintf(msg, len,
             "%s is invalid with m = %s, v = %s: the spring stops the striker in %.3g s, which the %s uniform grid "
             "resolves only in steps of at most %.3g s (%d per stop); lower dt_max to that, or take scheme = 1 and "
             "memory = 2, whose steps shorten in contact",
             shown_step(p, text[0]), shown(m, text[1]), shown(v, text[2]), t,
             p->scheme == CONTACT_SCHEME_CENTRAL ? "central scheme's" : "full G1 history's", t / CONTACT_RESOLUTION,
             CONTACT_RESOLUTION);
    return -1;
}

int contact_step_warning(const contact_params *p, double v, double m, char *msg, size_t len)
{
    const double t = first_turnaround(p, v, m);
    char text[3][64];
    if (uniform_grid(p) || tolerance_applies(p) || !(t < CONTACT_RESOLUTION * contact_step_limit(p)))
        return 0;
    snprintf(msg, len,
             "%s does not resolve the impact of m = %s at v = %s: the spring stops the striker in %.3g s, less "
             "than %d steps; in contact the fixed steps are %.3g s instead (%d per stop)",
             shown_step(p, text[0]), shown(m, text[1]), shown(v, text[2]), t, CONTACT_RESOLUTION,
             t / CONTACT_REFINED, CONTACT_REFINED);
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
    if (p->damper == CONTACT_DAMPER_DASHPOT && m > 0.0 && !isfinite(m * p->g * (m * p->g) / p->c))
        return contact_reject(msg, len, "g", p->g, "the power (m g)^2 / c its weight can dissipate exceeds double precision");
    if (p->damper == CONTACT_DAMPER_DASHPOT && m == 0.0 && !isfinite(p->c * v * v))
        return contact_reject(msg, len, "v", v, "the power c v^2 of the dashpot driven at v exceeds double precision");
    return 0;
}

/* The G1 ratio of the law on N intervals for x1^n = Gamma(n+1) D^(-(n-1)) x1
 * (MODEL.md §4, §7): Gamma(N+n)/(Gamma(N) N^n). */
static double g1_ratio(int law, double n, double N)
{
    return law == CONTACT_LAW_G1 ? g1_line_ratio(1.0 - n, N) : g1_line_ratio_extrapolated(1.0 - n, N);
}

static int springpot(const contact_model *cm) { return cm->p.damper == CONTACT_DAMPER_SPRINGPOT; }

static int compressed_memory(const contact_model *cm)
{
    return springpot(cm) && cm->p.memory == CONTACT_MEMORY_COMPRESSED;
}

static int full_history(const contact_model *cm)
{
    return springpot(cm) && cm->p.memory == CONTACT_MEMORY_G1;
}

/* The fixed step in the current contact: dt_max where it resolves the
 * impact (CONTACT_RESOLUTION steps in its turnaround time) or the grid is
 * uniform, else CONTACT_REFINED steps in that time: a step that does not
 * resolve it is no one's choice, and a barely resolved one would show
 * SDIRK2's gain of energy in nearly elastic impacts, which grows with the
 * step like (h/t_c)^2.5 (docs/stability.md). Set where the onset speed or
 * the inertia change. */
static void resolve_contact(contact_model *cm)
{
    const double t = stopping_time(&cm->p, cm->k, cm->inv_m, cm->s.v_onset, cm->accel);
    cm->contact_step = uniform_grid(&cm->p) || t >= CONTACT_RESOLUTION * cm->h_max ? cm->h_max : t / CONTACT_REFINED;
}

void contact_configure(contact_model *cm, const contact_params *p)
{
    const double n = p->spring_exponent;
    cm->p = *p;
    cm->k = spring_constant(p);
    cm->n_gamma = n == 1.5 ? GAMMA_5_2 : tgamma(n + 1.0);
    cm->inv_c = 1.0 / p->c;
    cm->k_fixed = p->law == CONTACT_LAW_HERTZ ? cm->k
                  : p->g1_nodes > 0 ? cm->k * g1_ratio(p->law, n, (double)p->g1_nodes) : 0.0;
    /* An error-controlled step needs its stages' roots well inside its
     * tolerance, not to rounding. */
    cm->error_controlled = tolerance_applies(p);
    cm->h_max = contact_step_limit(p);
    resolve_contact(cm);
    cm->series_limit = cm->error_controlled ? pow(1e-3 * p->tolerance / 20.0, 2.0 / 7.0) : 0.0;
    cm->peak_force_seen = -1.0;
    cm->peak_length = 0.0;
    cm->modes.modes = 0;
    cm->modes.h = 0.0;
    cm->modes.trial_key[1] = 0.0;
    if (compressed_memory(cm))
        cm->modes.modes = soe_kernel(p->damper_order, p->memory_tolerance, memory_kernel_floor(p),
                                     CONTACT_MEMORY_SPAN, CONTACT_MAX_MODES, cm->modes.a, cm->modes.b,
                                     &cm->modes.eta);
}

void contact_release(contact_model *cm)
{
    free(cm->history.x2);
    free(cm->history.w);
    memset(&cm->history, 0, sizeof cm->history);
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
        resolve_contact(cm);
    } else {
        contact_drive(cm, v0, m, 0.0);
    }
}

void contact_drive(contact_model *cm, double v, double m, double slope)
{
    if (cm->p.scene != CONTACT_SCENE_DRIVEN)
        return;
    if (v != cm->s.v)
        cm->s.h_prev = 0.0; /* a multistep scheme's past no longer leads here: restart it */
    cm->s.v = v;
    cm->inv_m = m > 0.0 ? 1.0 / m : 0.0;
    cm->accel = m > 0.0 ? cm->p.g : slope;
    resolve_contact(cm);
}

/* The spring force K x1^n at x1 > 0 (the Hertz sphere's n = 1.5 without pow). */
static double spring_force(const contact_model *cm, double K, double x1)
{
    const double n = cm->p.spring_exponent;
    return n == 1.5 ? K * x1 * sqrt(x1) : n == 1.0 ? K * x1 : K * pow(x1, n);
}

double contact_damper_rate(const contact_model *cm)
{
    return springpot(cm) ? cm->s.x2_rate : cm->s.F * cm->inv_c;
}

void contact_rates(const contact_model *cm, double *x1_rate, double *v_rate, double *F_rate)
{
    const contact_state *s = &cm->s;
    const double n = cm->p.spring_exponent;
    double x1 = contact_elastic_indentation(cm);
    *x1_rate = s->in_contact ? s->v - contact_damper_rate(cm) : 0.0;
    *v_rate = cm->accel - cm->inv_m * s->F;
    *F_rate = x1 > 0.0 ? n * contact_spring_stiffness(cm, s->n) * pow(x1, n - 1.0) * *x1_rate : 0.0;
}

double contact_spring_stiffness(const contact_model *cm, long n_steps)
{
    if (cm->p.law == CONTACT_LAW_HERTZ || cm->p.g1_nodes > 0)
        return cm->k_fixed;
    return n_steps > 0 ? cm->k * g1_ratio(cm->p.law, cm->p.spring_exponent, (double)n_steps) : cm->k;
}

/* The root s > 0 of s^2 + beta s^3 = r (r > 0, beta >= 0): s^2 is the elastic
 * indentation of an implicit stage with n = 3/2. With u = beta sqrt(r) the root is
 *     sqrt(r) (1 - u/2 + 5u^2/8 - u^3 + 231u^4/128 - 7u^5/2 + 7293u^6/1024 - 15u^7 + ...),
 * so for u < 1e-4 (every fixed step of 1e-7 s at the paper's parameters:
 * u ~ 3e-5) the series to u^4 is exact to 4e-20, below rounding; to u^6 it is as
 * accurate as a stage needs while its error, below 20u^7, is: while
 * u^2 < series_limit (an error-controlled step's u is about 0.01 at the
 * paper's parameters; series_limit 0: never). The even powers of u are
 * powers of w = u^2 = beta^2 r and sqrt(r) u = beta r, so the series is
 * sqrt(r) E(w) + beta r O(w): the two polynomials need no square root and
 * are ready when it is, a shorter chain on every implicit stage.
 * Otherwise Newton's method, which converges from any start at or above the
 * root and from a close one below it because the cubic increases and is
 * convex for s > 0: from that series (off by < 20u^7, 1.6e-8 at most)
 * while u < 0.05, from sqrt(r) / (1 + u/2) (off by < u^2/2) while u <= 1,
 * and from cbrt(r / beta), above the root, when the split is stiff (u > 1). */
static double stage_root(double r, double beta, double series_limit)
{
    const double w = beta * beta * r, odd = beta * r;
    double s = sqrt(r), ds;
    int i;
    if (w < 1e-8) /* u < 1e-4, the fixed steps' case: to u^4, exact to 4e-20 */
        return s * (1.0 + w * (0.625 + w * (231.0 / 128.0))) - odd * (0.5 + w);
    if (w < 0.0025) { /* u < 0.05 */
        s = s * (1.0 + w * (0.625 + w * (231.0 / 128.0 + w * (7293.0 / 1024.0)))) - odd * (0.5 + w * (1.0 + 3.5 * w));
        if (w < series_limit)
            return s;
    } else {
        s = w > 1.0 ? cbrt(r / beta) : s / (1.0 + 0.5 * beta * s);
    }
    for (i = 0; i < 200; i++) {
        ds = (s * s * (1.0 + beta * s) - r) / (s * (2.0 + 3.0 * beta * s));
        s -= ds;
        /* Newton leaves a relative error of about half the square of the
         * last relative correction: after one of 1e-8 the iterate is exact
         * to rounding. */
        if (!(fabs(ds) > 1e-8 * s))
            break;
    }
    return s;
}

/* The root X > 0 of X + beta X^n = r (r > 0, beta >= 0, n >= 1) for any n:
 * Newton's method from the smaller of r and (r/beta)^(1/n), both at or above
 * the root, where the increasing convex function converges monotonically. */
static double power_root(double r, double beta, double n)
{
    double X = beta > 0.0 ? fmin(r, pow(r / beta, 1.0 / n)) : r, dX;
    int i;
    for (i = 0; i < 200; i++) {
        double Xn1 = pow(X, n - 1.0);
        dX = (X + beta * X * Xn1 - r) / (1.0 + n * beta * Xn1);
        X -= dX;
        if (!(fabs(dX) > 1e-9 * X))
            break;
    }
    return X;
}

/* The elastic indentation X of an implicit stage, X + beta X^n = r, and the
 * spring force K X^n there: the Hertz sphere's n = 1.5 inline (the common
 * case, on every step), any other n apart. */
static double other_stage_force(const contact_model *cm, double K, double r, double beta, double *X)
{
    const double n = cm->p.spring_exponent;
    *X = n == 1.0 ? r / (1.0 + beta) : power_root(r, beta, n);
    return spring_force(cm, K, *X);
}

static inline double stage_force(const contact_model *cm, double K, double r, double beta, double *X)
{
    double s;
    if (cm->p.spring_exponent != 1.5)
        return other_stage_force(cm, K, r, beta, X);
    s = stage_root(r, beta, cm->series_limit);
    *X = s * s;
    return K * s * *X;
}

/* What the damper makes of an implicit stage: its rate x2' = (F - A) inv_B,
 * linear in the force (the dashpot: A = 0, inv_B = 1/c; a springpot: its
 * memory's pull A and its stiffness over the stage as a viscosity 1/inv_B). */
typedef struct {
    double A, inv_B;
} damper_stage;

/* One implicit stage of x1' = v - x2', v' = accel - inv_m F with
 * F = K max(x1, 0)^n, x2' = (F - A) inv_B:
 *     X = xh + hg (V - x2'),  V = vh + hg (accel - inv_m F).
 * Eliminating V and x2' leaves X + beta X^n = r, one scalar root. Returns F. */
static inline double implicit_stage(const contact_model *cm, double K, double hg, double xh, double vh,
                                    damper_stage d, double *X, double *V)
{
    /* vh last: in an ESDIRK step it is the latest of the three to be known */
    double r = (xh + hg * (hg * cm->accel + d.A * d.inv_B)) + hg * vh;
    double F = 0.0;
    if (r > 0.0 && K > 0.0)
        F = stage_force(cm, K, r, K * hg * (d.inv_B + hg * cm->inv_m), X);
    else
        *X = r; /* out of contact the striker moves freely */
    *V = vh + hg * (cm->accel - cm->inv_m * F);
    return F;
}

/* ------------------------------------------------- the compressed memory */

/* The springpot F = c_alpha (eta x2' + sum_i a_i phi_i), phi_i' = -b_i phi_i
 * + x2' (MODEL.md §8), in the SDIRK stages of a step of length h: with
 * d_i = 1/(1 + gamma h b_i) each stage's modes are d_i (their explicit part
 * + gamma h x2'), so the force is linear in x2' with the coefficients below,
 * which depend on h alone and are kept for the step length last used. */
static const contact_modes *modes_for_step(contact_model *cm, double h)
{
    contact_modes *m = &cm->modes;
    const double hg = SDIRK_GAMMA * h, hb = (1.0 - SDIRK_GAMMA) * h;
    size_t i;
    if (m->h == h)
        return m;
    m->sum_p = m->sum_q = 0.0;
    for (i = 0; i < m->modes; i++) {
        double d = 1.0 / (1.0 + hg * m->b[i]);
        m->p[i] = m->a[i] * d;
        m->q[i] = m->p[i] * d * m->b[i];
        m->sum_p += m->p[i];
        m->sum_q += m->q[i];
        /* phi_new = keep phi + rate1 x2'_1 + rate2 x2'_2 over the step */
        m->keep[i] = d * (1.0 - hb * m->b[i] * d);
        m->rate1[i] = d * d * hb;
        m->rate2[i] = d * hg;
    }
    m->h = h;
    return m;
}

/* The two stages' damper terms of a springpot step from the modes phi:
 * stage 1 from sum p phi; stage 2, after the first stage's rate z1, from the
 * modes advanced explicitly by (1 - gamma) h. */
static void springpot_stages(contact_model *cm, double h, damper_stage *d1, double *S2)
{
    const contact_modes *m = modes_for_step(cm, h);
    const double c = cm->p.c_alpha;
    double S1 = 0.0, Sq = 0.0;
    size_t i;
    for (i = 0; i < m->modes; i++) {
        S1 += m->p[i] * m->phi[i];
        Sq += m->q[i] * m->phi[i];
    }
    d1->A = c * S1;
    d1->inv_B = 1.0 / (c * (m->eta + SDIRK_GAMMA * h * m->sum_p));
    *S2 = Sq;
}

static void springpot_second_stage(const contact_model *cm, double h, const damper_stage *d1, double Sq, double z1,
                                   damper_stage *d2)
{
    const contact_modes *m = &cm->modes;
    const double hg = SDIRK_GAMMA * h, hb = (1.0 - SDIRK_GAMMA) * h;
    d2->A = d1->A + cm->p.c_alpha * hb * (z1 * m->sum_p - (Sq + hg * z1 * m->sum_q));
    d2->inv_B = d1->inv_B;
}

/* The modes after an accepted step of length h with stage rates z1, z2. */
static void advance_modes(contact_model *cm, double h, double z1, double z2)
{
    const contact_modes *m = modes_for_step(cm, h);
    size_t i;
    for (i = 0; i < m->modes; i++)
        cm->modes.phi[i] = m->keep[i] * m->phi[i] + m->rate1[i] * z1 + m->rate2[i] * z2;
}

/* Whether the springpot holds no memory: before its first contact. */
static int memory_at_rest(const contact_model *cm)
{
    size_t i;
    if (!springpot(cm))
        return 1;
    if (cm->s.x2 != 0.0 || cm->s.x2_rate != 0.0)
        return 0;
    for (i = 0; i < cm->modes.modes; i++)
        if (cm->modes.phi[i] != 0.0)
            return 0;
    return 1;
}

/* ---------------------------------------------------------- SDIRK steps */

/* One SDIRK step of length h from *in with spring stiffness K (0: no
 * contact: free flight, exact while the damper rests). Writes t, x1, x2, v,
 * F, E_diss and what accepting the step needs (its length and the damper's
 * stage rates) of *out; returns the impulse of the contact force. Inlined
 * twice below, so that the dashpot's copy carries none of the springpot's
 * work: `springpot` and `compressed` are constants in each. */
static inline double sdirk_step_of(contact_model *cm, const contact_state *in, double h, double K, contact_state *out,
                                   const int springpot, const int compressed)
{
    const double hg = SDIRK_GAMMA * h, hb = (1.0 - SDIRK_GAMMA) * h;
    damper_stage d1 = {0.0, cm->inv_c}, d2 = {0.0, cm->inv_c};
    double X1, V1, X2, V2, F1, F2, z1, z2, impulse, Sq = 0.0;

    if (compressed)
        springpot_stages(cm, h, &d1, &Sq);
    F1 = implicit_stage(cm, K, hg, in->x1, in->v, d1, &X1, &V1);
    z1 = (F1 - d1.A) * d1.inv_B;
    if (compressed)
        springpot_second_stage(cm, h, &d1, Sq, z1, &d2);
    F2 = implicit_stage(cm, K, hg, in->x1 + hb * (V1 - z1), in->v + hb * (cm->accel - cm->inv_m * F1), d2, &X2,
                        &V2);
    z2 = (F2 - d2.A) * d2.inv_B;
    impulse = hb * F1 + hg * F2;

    *out = *in;
    out->t = in->t + h;
    out->x1 = X2;
    out->v = V2;
    out->F = F2;
    out->step = h;
    out->x2_rate1 = z1;
    out->x2_rate = z2;
    if (springpot) {
        /* The mean force J/h times the travel, as the dashpot below counts
         * (within O(h^3) of the integral of F x2'; at alpha = 1 the same). */
        out->x2 = in->x2 + hb * z1 + hg * z2;
        out->E_diss = in->E_diss + (h > 0.0 ? impulse * (out->x2 - in->x2) / h : 0.0);
        return impulse;
    }
    /* The dashpot carries the spring's force: x2' = F/c, dissipating F^2/c.
     * A step counts J^2/(c h), the dissipation of its mean force J/h: within
     * O(h^3) of the integral (which exceeds it by h Var(F)/c), and unlike a
     * quadrature of the stage forces it does not overshoot the energy there
     * is when a step is far too long to resolve the motion. */
    out->x2 = in->x2 + impulse * cm->inv_c;
    out->E_diss = in->E_diss + (h > 0.0 ? impulse * impulse * cm->inv_c / h : 0.0);
    return impulse;
}

static double sdirk_step(contact_model *cm, const contact_state *in, double h, double K, contact_state *out)
{
    if (!springpot(cm))
        return sdirk_step_of(cm, in, h, K, out, 0, 0);
    return sdirk_step_of(cm, in, h, K, out, 1, compressed_memory(cm));
}

/* ------------------------------------------------ error-controlled steps */

/* Kvaerno's ESDIRK of order 5 with an embedded solution of order 4
 * (A. Kvaerno, BIT 44 (2004) 489-502): an explicit first stage, then six
 * implicit stages of one diagonal gamma. Both solutions are L-stable and
 * stiffly accurate: the step's end is its last stage, the embedded
 * solution its sixth, so that their difference estimates the step's error
 * at no extra cost, and a step far too long for the motion damps it rather
 * than reflecting it. Measured on the h20 impact against the order 3(2)
 * of the same paper: at tolerance 1e-6 it takes 17 steps where that takes
 * 210, and its 6 stages per step cost less than twice the other's 3. */
#define ESDIRK_STAGES 7
#define ESDIRK_EMBEDDED 5
#define ESDIRK_GAMMA 0.26
static const double esdirk_a[ESDIRK_STAGES][ESDIRK_STAGES] = {
    {0.0},
    {ESDIRK_GAMMA, ESDIRK_GAMMA},
    {0.13, 0.8403332099679080963, ESDIRK_GAMMA},
    {0.2237196147832050559, 0.4767553231979969983, -0.06470895363112615134, ESDIRK_GAMMA},
    {0.1664856432324832153, 0.1045001884159172041, 0.03631482272098715162, -0.1309070445107399857, ESDIRK_GAMMA},
    {0.1385564023126822495, 0.0, -0.04245337201752043099, 0.02446657898003141966, 0.6194303907248067618,
     ESDIRK_GAMMA},
    {0.1365975117764029144, 0.0, -0.05496908796538376712, -0.04118626728321046868, 0.6299330489901640319,
     0.06962479448202728949, ESDIRK_GAMMA}};

/* The larger and the smaller of two numbers, inline where libm's fmax and
 * fmin are calls (the controller takes several per step); b when a is NaN. */
static inline double larger(double a, double b) { return a > b ? a : b; }
static inline double smaller(double a, double b) { return a < b ? a : b; }

/* The elastic indentation at the contact's peak force so far, kept for the
 * force it was derived from. */
static double peak_indentation(contact_model *cm, double K, double F_peak)
{
    if (F_peak != cm->peak_force_seen) {
        cm->peak_force_seen = F_peak;
        cm->peak_length = K > 0.0 ? pow(F_peak / K, 1.0 / cm->p.spring_exponent) : 0.0;
    }
    return cm->peak_length;
}

/* The springpot's compressed memory in the ESDIRK stages of a step of
 * length h, as in the SDIRK steps: with z_k the damper's rate x2' at stage
 * k, each implicit stage i has the modes
 *     phi_i = d (E_i + gamma h z_i),   d = 1/(1 + gamma h b),
 *     E_i = phi_n + h sum_{k<i} a_ik (z_k - b phi_k),
 * so its force c_alpha (eta z_i + sum a phi_i) is A_i + z_i / inv_B: the
 * memory's pull A_i = c_alpha sum a d E_i and the viscosity
 * 1/inv_B = c_alpha (eta + gamma h sum a d), one scalar root per stage
 * still. Stage 0 is the step's start. The stages' modes are kept for the
 * stages that follow: on the stack (10 kB), no allocation. */
typedef struct {
    double d[CONTACT_MAX_MODES];
    double phi[ESDIRK_STAGES][CONTACT_MAX_MODES];
} esdirk_memory;

/* The step's d and the stage 0 modes; returns inv_B. */
static double esdirk_memory_begin(const contact_model *cm, double h, esdirk_memory *mem)
{
    const contact_modes *m = &cm->modes;
    const double hg = ESDIRK_GAMMA * h;
    double sum_p = 0.0;
    size_t j;
    for (j = 0; j < m->modes; j++) {
        mem->d[j] = 1.0 / (1.0 + hg * m->b[j]);
        sum_p += m->a[j] * mem->d[j];
        mem->phi[0][j] = m->phi[j];
    }
    return 1.0 / (cm->p.c_alpha * (m->eta + hg * sum_p));
}

/* Stage i's explicit part E_i, left in phi[i] until the stage's rate is
 * known, from the rates z[0..i-1]; returns the memory's pull A_i. */
static double esdirk_memory_pull(const contact_model *cm, double h, int i, const double *z, esdirk_memory *mem)
{
    const contact_modes *m = &cm->modes;
    double Z = 0.0, A = 0.0;
    size_t j;
    int k;
    for (k = 0; k < i; k++)
        Z += esdirk_a[i][k] * z[k];
    /* the stages' sum a_ik phi_k first, a stage at a time over the modes
     * (contiguous: vectorised), then E_i and the pull */
    for (j = 0; j < m->modes; j++)
        mem->phi[i][j] = esdirk_a[i][0] * mem->phi[0][j];
    for (k = 1; k < i; k++)
        for (j = 0; j < m->modes; j++)
            mem->phi[i][j] += esdirk_a[i][k] * mem->phi[k][j];
    for (j = 0; j < m->modes; j++) {
        const double E = mem->phi[0][j] + h * (Z - m->b[j] * mem->phi[i][j]);
        mem->phi[i][j] = E;
        A += m->a[j] * mem->d[j] * E;
    }
    return cm->p.c_alpha * A;
}

/* Stage i's modes once its rate z_i is known. */
static void esdirk_memory_settle(const contact_model *cm, double h, int i, double z_i, esdirk_memory *mem)
{
    const double hgz = ESDIRK_GAMMA * h * z_i;
    size_t j;
    for (j = 0; j < cm->modes.modes; j++)
        mem->phi[i][j] = mem->d[j] * (mem->phi[i][j] + hgz);
}

/* The memory force's embedded error estimate: c_alpha sum a (phi_6 - phi_5),
 * the last stage's (the step's end) less the embedded solution's. */
static double esdirk_memory_error(const contact_model *cm, const esdirk_memory *mem)
{
    const contact_modes *m = &cm->modes;
    double change = 0.0;
    size_t j;
    for (j = 0; j < m->modes; j++)
        change += m->a[j] * (mem->phi[ESDIRK_STAGES - 1][j] - mem->phi[ESDIRK_EMBEDDED][j]);
    return cm->p.c_alpha * fabs(change);
}

/* The rates z_0..z_6 of an ESDIRK trial step from the model's state. */
static void esdirk_trial_rates(const contact_model *cm, const contact_state *trial, double z[ESDIRK_STAGES])
{
    z[0] = cm->s.x2_rate;
    z[1] = trial->x2_rate1;
    memcpy(z + 2, trial->x2_rate_inner, sizeof trial->x2_rate_inner);
    z[ESDIRK_STAGES - 1] = trial->x2_rate;
}

/* What identifies an ESDIRK trial from the model's state: its start time,
 * its length and its stage rates. */
static void esdirk_trial_key(const contact_model *cm, const contact_state *trial, double key[ESDIRK_STAGES + 2])
{
    key[0] = cm->s.t;
    key[1] = trial->step;
    esdirk_trial_rates(cm, trial, key + 2);
}

/* Keeps the end modes of the trial just taken from the model's state. */
static void esdirk_keep_trial(contact_model *cm, const contact_state *trial, const esdirk_memory *mem)
{
    esdirk_trial_key(cm, trial, cm->modes.trial_key);
    memcpy(cm->modes.trial_end, mem->phi[ESDIRK_STAGES - 1], cm->modes.modes * sizeof cm->modes.phi[0]);
}

/* The modes after an accepted ESDIRK step from the model's state: the last
 * stage's (stiffly accurate). Those of the last trial taken when it is the
 * one accepted (the same rates from the same modes: the same bits), else
 * recomputed from the trial's stage rates, so that whichever of an event
 * search's trials is accepted brings its own. */
static void esdirk_advance_modes(contact_model *cm, const contact_state *trial)
{
    esdirk_memory mem;
    double z[ESDIRK_STAGES], key[ESDIRK_STAGES + 2];
    int i;
    esdirk_trial_key(cm, trial, key);
    if (memcmp(key, cm->modes.trial_key, sizeof key) == 0) {
        memcpy(cm->modes.phi, cm->modes.trial_end, cm->modes.modes * sizeof cm->modes.phi[0]);
        cm->modes.trial_key[1] = 0.0;
        return;
    }
    esdirk_trial_rates(cm, trial, z);
    esdirk_memory_begin(cm, trial->step, &mem);
    for (i = 1; i < ESDIRK_STAGES; i++) {
        esdirk_memory_pull(cm, trial->step, i, z, &mem);
        esdirk_memory_settle(cm, trial->step, i, z[i], &mem);
    }
    memcpy(cm->modes.phi, mem.phi[ESDIRK_STAGES - 1], cm->modes.modes * sizeof cm->modes.phi[0]);
}

/* Whether a step from *s is an ESDIRK step: error-controlled in contact.
 * Out of contact a recovering springpot takes recover's SDIRK2 steps, and
 * the onset search among them must take the same. */
static int esdirk_steps(const contact_model *cm, const contact_state *s)
{
    return cm->error_controlled && s->in_contact;
}

/* One ESDIRK step of length h from *in with spring stiffness K (the
 * contract of sdirk_step), the damper a dashpot (mem NULL) or the
 * compressed springpot (mem its stages' scratch, its explicit stage 0 at
 * the start's rate in->x2_rate); inlined twice below, so that the
 * dashpot's copy carries none of the springpot's work. out->error is the
 * embedded estimate of its error over the tolerance: x1's and x2's
 * relative to the larger of the elastic indentation at the step's ends and
 * at the contact's peak force so far (relative in the force at onset, where
 * x1^n is not smooth, grading the first steps), v's relative to the speed
 * at onset or now; a springpot's modes are state too, and their force's
 * error counts as the travel it would drive over the step through the
 * stage's viscosity. The springpot's E_diss is the order-5 quadrature of
 * F x2', as the dashpot's of F^2/c (SDIRK2's mean force times the travel
 * is of order 2: measured 3e-3 off on the h20 impact at tolerance 1e-6,
 * where this is 2e-5). */
static inline double esdirk_step_of(contact_model *cm, const contact_state *in, double h, double K, contact_state *out,
                                    esdirk_memory *mem)
{
    const int last = ESDIRK_STAGES - 1;
    damper_stage damper = {0.0, cm->inv_c};
    double F[ESDIRK_STAGES], z[ESDIRK_STAGES], rise[ESDIRK_STAGES];
    double X = in->x1, V = in->v, X_embedded = 0.0, V_embedded = 0.0, x2_embedded = 0.0;
    double impulse = 0.0, work = 0.0, travel = 0.0, length, speed, error;
    int i, j;
    F[0] = in->F;
    z[0] = mem ? in->x2_rate : F[0] * cm->inv_c;
    if (mem)
        damper.inv_B = esdirk_memory_begin(cm, h, mem);
    for (i = 0; i <= last; i++) {
        if (i > 0) {
            /* each stage waits on the one before: the sums are ordered so
             * that its rise and force come in last, at one multiply-add */
            double xh = in->x1, vh = in->v;
            for (j = 0; j < i; j++) {
                xh += esdirk_a[i][j] * rise[j];
                vh += h * esdirk_a[i][j] * cm->accel;
                vh -= h * esdirk_a[i][j] * cm->inv_m * F[j];
            }
            if (mem)
                damper.A = esdirk_memory_pull(cm, h, i, z, mem);
            F[i] = implicit_stage(cm, K, ESDIRK_GAMMA * h, xh, vh, damper, &X, &V);
            z[i] = (F[i] - damper.A) * damper.inv_B;
            if (mem)
                esdirk_memory_settle(cm, h, i, z[i], mem);
            /* h x1' from the stage's equation X = xh + gamma h x1': a
             * shorter chain than h (V - z) */
            rise[i] = (X - xh) * (1.0 / ESDIRK_GAMMA);
        } else {
            rise[0] = h * (V - z[0]);
        }
        if (i == ESDIRK_EMBEDDED) {
            X_embedded = X;
            V_embedded = V;
            for (j = 0; j <= i; j++)
                x2_embedded += h * esdirk_a[i][j] * (mem ? z[j] : F[j]);
        }
    }
    for (j = 0; j <= last; j++) {
        impulse += h * esdirk_a[last][j] * F[j];
        if (mem) {
            travel += h * esdirk_a[last][j] * z[j];
            work += h * esdirk_a[last][j] * F[j] * z[j];
        } else
            work += h * esdirk_a[last][j] * F[j] * F[j];
    }
    length = larger(larger(fabs(in->x1), fabs(X)), DBL_MIN);
    if (in->F_peak_contact > larger(in->F, F[last])) /* past the peak: its indentation is the larger */
        length = larger(length, peak_indentation(cm, K, in->F_peak_contact));
    speed = larger(larger(fabs(in->v), fabs(V)), larger(fabs(in->v_onset), DBL_MIN));
    *out = *in;
    out->t = in->t + h;
    out->x1 = X;
    out->v = V;
    out->F = F[last];
    out->step = h;
    out->x2_rate1 = z[1];
    out->x2_rate = z[last];
    if (mem) {
        out->x2 = in->x2 + travel;
        out->E_diss = in->E_diss + work;
        memcpy(out->x2_rate_inner, z + 2, sizeof out->x2_rate_inner);
        error = larger(larger(fabs(X - X_embedded), fabs(travel - x2_embedded)),
                       esdirk_memory_error(cm, mem) * damper.inv_B * h) / length;
    } else {
        out->x2 = in->x2 + impulse * cm->inv_c;
        out->E_diss = in->E_diss + work * cm->inv_c;
        error = larger(fabs(X - X_embedded), fabs(impulse - x2_embedded) * cm->inv_c) / length;
    }
    out->error = larger(error, fabs(V - V_embedded) / speed) / cm->p.tolerance;
    return impulse;
}

static double springpot_esdirk_step(contact_model *cm, const contact_state *in, double h, double K, contact_state *out)
{
    esdirk_memory mem;
    const double J = esdirk_step_of(cm, in, h, K, out, &mem);
    if (in == &cm->s)
        esdirk_keep_trial(cm, out, &mem);
    return J;
}

/* An error-controlled step: the dashpot's, or the compressed springpot's
 * (out of contact a recovering springpot's SDIRK2 step: esdirk_steps). */
static double esdirk_step(contact_model *cm, const contact_state *in, double h, double K, contact_state *out)
{
    if (!springpot(cm))
        return esdirk_step_of(cm, in, h, K, out, NULL);
    if (!esdirk_steps(cm, in))
        return sdirk_step(cm, in, h, K, out);
    return springpot_esdirk_step(cm, in, h, K, out);
}

static int error_controlled(const contact_model *cm) { return cm->error_controlled; }

/* A contact step of length h: error-controlled or fixed. */
static double contact_step(contact_model *cm, const contact_state *in, double h, double K, contact_state *out)
{
    return error_controlled(cm) ? esdirk_step(cm, in, h, K, out) : sdirk_step(cm, in, h, K, out);
}

/* A double's bits and back (IEEE 754 binary64, as on every target). */
static uint64_t bits_of(double x)
{
    uint64_t b;
    memcpy(&b, &x, sizeof b);
    return b;
}

static double double_of(uint64_t b)
{
    double x;
    memcpy(&x, &b, sizeof x);
    return x;
}

/* x^(-1/5) for normal x > 0 to within 3e-4 relative: writing x = f 2^e
 * with f in [0.5, 1) and e = 5q + r, it is f^(-1/5) (a cubic, fitted here)
 * times 2^(-r/5) times 2^(-q), f and e read from x's bits (frexp and ldexp
 * are library calls: 3 % of an h20 impact). A step controller needs no
 * more, and it runs on every step, where pow costs a tenth of an impact. */
static double inverse_fifth_root(double x)
{
    static const double two_to_minus_fifths[5] = {1.0, 0.8705505632961241, 0.7578582832551990,
                                                  0.6597539553864471, 0.5743491774985174};
    const uint64_t b = bits_of(x), mantissa = b & 0x000fffffffffffffu;
    const int e = (int)(b >> 52) - 1022; /* x normal and positive: no sign, the exponent field 1..2046 */
    const int q = e >= 0 ? e / 5 : -((4 - e) / 5); /* floor(e / 5) */
    double f = double_of(mantissa | 0x3fe0000000000000u); /* in [0.5, 1) */
    f = 1.507151444062986 + f * (-1.048043078699986 + f * (0.7816167643411439 - f * 0.24092814993974934));
    return f * two_to_minus_fifths[e - 5 * q] * double_of((uint64_t)(1023 - q) << 52);
}

/* The step after one of length h with error ratio `error` (error over
 * tolerance): the usual controller 0.9 error^(-1/5) (the embedded
 * solution's order is 4), growing at most 5-fold and shrinking at most to
 * `least` of h. */
static double next_step(double h, double error, double least)
{
    double factor = error < DBL_MIN ? 5.0 : error < INFINITY ? 0.9 * inverse_fifth_root(error) : least; /* NaN: least */
    return h * smaller(larger(factor, least), 5.0);
}

/* Makes a trial step the model's state, and its memory follow. */
static inline void accept_step(contact_model *cm, const contact_state *trial)
{
    if (compressed_memory(cm)) {
        if (esdirk_steps(cm, trial))
            esdirk_advance_modes(cm, trial);
        else
            advance_modes(cm, trial->step, trial->x2_rate1, trial->x2_rate);
    }
    cm->s = *trial;
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

/* Contact begins where the model's state is. */
static void touch(contact_model *cm)
{
    cm->s.x1 = 0.0;
    cm->s.F = 0.0;
    begin_contact(&cm->s, cm->s.t, cm->s.v);
    resolve_contact(cm);
}

/* Free flight for tau while the damper rests, exact (the step with no
 * spring), then contact begins if `touches`. */
static void fly(contact_model *cm, double tau, int touches)
{
    contact_state trial;
    sdirk_step(cm, &cm->s, tau, 0.0, &trial);
    accept_step(cm, &trial);
    if (touches)
        touch(cm);
}

/* What an event watches at the end of a trial step: the elastic indentation
 * x1 (it reaches 0 at separation), the gap -x1 (it reaches 0 at onset), or
 * the indentation rate x1' = v - x2' (it reaches 0 where x1, and with it the
 * force, peaks). */
typedef double (*event_value)(const contact_model *cm, const contact_state *s);

static double indentation(const contact_model *cm, const contact_state *s)
{
    (void)cm;
    return s->x1;
}

static double gap(const contact_model *cm, const contact_state *s)
{
    (void)cm;
    return -s->x1;
}

static double indentation_rate(const contact_model *cm, const contact_state *s)
{
    return s->v - (springpot(cm) ? s->x2_rate : s->F * cm->inv_c);
}

/* The length tau in (0, h] of a step from *s at which the event value falls
 * to 0, given that it is > 0 at the start and f_end <= 0 after the full step:
 * Illinois regula falsi on the value at the step's end, which is continuous
 * in tau, until the bracket is narrower than precision h, its first trial
 * at guess h when guess lies in (0, 1). Returns a tau where it is <= 0,
 * that step's state in *at and its impulse in *impulse. */
static double event_time(contact_model *cm, const contact_state *s, double h, double K, event_value event,
                         double f_end, double precision, double guess, contact_state *at, double *impulse)
{
    double lo = 0.0, hi = h, flo = event(cm, s), fhi = f_end;
    int i, side = 0;
    *impulse = contact_step(cm, s, h, K, at);
    for (i = 0; i < 200 && fhi != 0.0 && hi - lo > precision * h; i++) {
        contact_state trial;
        double tau = i == 0 && guess > 0.0 && guess < 1.0 ? guess * h : (lo * fhi - hi * flo) / (fhi - flo), f, J;
        if (!(tau > lo && tau < hi))
            tau = 0.5 * (lo + hi);
        J = contact_step(cm, s, tau, K, &trial);
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
            *impulse = J;
            if (side == 1)
                flo *= 0.5;
            side = 1;
        }
    }
    return hi;
}

/* x1 over a step of length h from *s to *end as the cubic in theta = tau/h
 * that matches its values and slopes at both ends: p[0..3]. */
static void indentation_cubic(const contact_model *cm, const contact_state *s, const contact_state *end, double h,
                              double p[4])
{
    const double d0 = h * indentation_rate(cm, s), d1 = h * indentation_rate(cm, end), rise = end->x1 - s->x1;
    p[0] = s->x1;
    p[1] = d0;
    p[2] = 3.0 * rise - 2.0 * d0 - d1;
    p[3] = d0 + d1 - 2.0 * rise;
}

/* Where in (0, 1) the polynomial p[0] + p[1] theta + ... + p[degree]
 * theta^degree falls from > 0 at 0 to <= 0 at 1: Newton's method kept
 * inside the shrinking bracket, bisecting where it leaves it. */
static double polynomial_root(const double *p, int degree)
{
    double lo = 0.0, hi = 1.0, theta = 0.5;
    int i, j;
    for (i = 0; i < 60 && hi - lo > 1e-12; i++) {
        double value = p[degree], slope = 0.0;
        for (j = degree - 1; j >= 0; j--) {
            slope = slope * theta + value;
            value = value * theta + p[j];
        }
        if (value > 0.0)
            lo = theta;
        else
            hi = theta;
        theta = slope < 0.0 ? theta - value / slope : -1.0;
        if (!(theta > lo && theta < hi))
            theta = 0.5 * (lo + hi);
    }
    return theta;
}

/* The first trial of an event's search in an error-controlled step, as a
 * fraction of the step, from the cubic through its ends: where x1 falls to
 * 0 (separation) or where its slope does (the peak). Fixed steps locate
 * their events as they always have, without a guess. */
static double event_guess(const contact_model *cm, const contact_state *s, const contact_state *end, double h,
                          int peak)
{
    double p[4], slope[3];
    indentation_cubic(cm, s, end, h, p);
    if (!peak)
        return polynomial_root(p, 3);
    slope[0] = p[1];
    slope[1] = 2.0 * p[2];
    slope[2] = 3.0 * p[3];
    return polynomial_root(slope, 2);
}

/* How closely an error-controlled step from *s of length h locates the
 * separation, in seconds: to a tenth of the tolerance of the contact's
 * duration so far (the contact time's error; the speed and the dent hardly
 * change there, where the force vanishes). Fixed steps locate it to
 * rounding. */
static double separation_precision(const contact_model *cm, const contact_state *s, double h)
{
    return 0.1 * cm->p.tolerance * (s->t + h - s->t_onset);
}

/* Where an error-controlled step from *s of length h, whose end *trial lies
 * past the separation, meets it: a step to where the cubic through its ends
 * falls to 0, then Newton's method on the indentation at the step's end,
 * whose slope in the step's length is the indentation rate there, until it
 * moves by less than the separation's precision (from the cubic's root,
 * off by O(h^4), one correction usually suffices). The first trial beyond
 * the tolerance ends the search: the caller rejects it and shrinks the
 * step. Where Newton's method does not apply (the indentation rising at a
 * trial, or a correction leaving the step), regula falsi takes over.
 * Returns the length stepped, its state in *trial and its impulse in *J. */
static double separation_within(contact_model *cm, const contact_state *s, double h, double K,
                                contact_state *trial, double *J)
{
    const double precision = separation_precision(cm, s, h), x1_end = trial->x1;
    double tau = event_guess(cm, s, trial, h, 0) * h;
    int i;
    for (i = 0; i < 8; i++) {
        double rate, next;
        *J = esdirk_step(cm, s, tau, K, trial);
        rate = indentation_rate(cm, trial);
        if (trial->error > 1.0)
            return tau;
        next = tau - trial->x1 / rate;
        if (!(rate < 0.0 && next > 0.0 && next <= h))
            break;
        if (fabs(next - tau) < precision)
            return tau;
        tau = next;
    }
    return event_time(cm, s, h, K, indentation, x1_end, precision / h, -1.0, trial, J);
}

/* The force where the indentation turns inside a contact step from *s to
 * *end: sampling the peak at step ends alone would err by O(h^2) of the
 * force's curvature, more than the scheme itself. With fixed steps the turn
 * is located to rounding; an error-controlled step takes the force one step
 * from *s to where the cubic through the step's ends turns: that time is
 * off by O(h^4) of the motion's scale, and a force read delta from its peak
 * is low by O(delta^2), far below the tolerance. */
static double force_at_turn(contact_model *cm, const contact_state *s, double h, double K, const contact_state *end)
{
    contact_state at;
    double J;
    if (error_controlled(cm))
        contact_step(cm, s, event_guess(cm, s, end, h, 1) * h, K, &at);
    else
        event_time(cm, s, h, K, indentation_rate, indentation_rate(cm, end), 1e-15, -1.0, &at, &J);
    return at.F > end->F ? at.F : end->F;
}

/* The force's peak inside a contact step from *s to *end: at its end, or
 * where the indentation turns if it does there (once a contact; the test
 * inline, since every fixed step makes it). */
static inline double peak_force_within(contact_model *cm, const contact_state *s, double h, double K,
                                       const contact_state *end)
{
    if (!(indentation_rate(cm, s) > 0.0 && indentation_rate(cm, end) <= 0.0))
        return end->F;
    return force_at_turn(cm, s, h, K, end);
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

/* The contact's counters after a step whose largest force was `peak`. */
static void count_contact_step(contact_state *s, double peak)
{
    s->n++;
    if (peak > s->F_peak_contact)
        s->F_peak_contact = peak;
    if (peak > s->F_peak)
        s->F_peak = peak;
}

/* Out of contact for up to h while a springpot's dent recovers: an SDIRK
 * step with no spring, cut at the onset if the striker meets the surface.
 * Returns the length stepped, and whether contact began. */
static double recover(contact_model *cm, double h, int *touches)
{
    contact_state trial;
    double J;
    sdirk_step(cm, &cm->s, h, 0.0, &trial);
    *touches = trial.x1 > 0.0;
    if (*touches && cm->s.x1 < 0.0)
        h = event_time(cm, &cm->s, h, 0.0, gap, -trial.x1, 1e-15, -1.0, &trial, &J);
    else if (*touches) /* it starts on the surface: contact at once */
        h = 0.0;
    if (h > 0.0)
        accept_step(cm, &trial);
    if (*touches)
        touch(cm);
    return h;
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
        int separates, touches;
        if (!s->in_contact) {
            if (memory_at_rest(cm)) {
                tau = flight_onset(s->x1, s->v, cm->accel, h);
                touches = tau >= 0.0;
                fly(cm, touches ? tau : h, touches);
            } else {
                tau = recover(cm, h, &touches);
            }
            if (!touches)
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
        if (separates)
            tau = event_time(cm, s, h, K, indentation, trial.x1, 1e-15, -1.0, &trial, &J);
        peak = peak_force_within(cm, s, tau, K, &trial);
        accept_step(cm, &trial);
        count_contact_step(s, peak);
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

/* The first error-controlled step of a contact: where the spring's force
 * K (v h)^n, changing the striker's speed by F h / m and turning the rate
 * F / c into the dashpot, has moved the indentation by ONSET_MOVEMENT
 * tolerances relative to v h; x1^n is not smooth there, and the steps that
 * follow grow at most 5-fold each (grading). The ESDIRK's error on that
 * first step is a small part of the movement: measured on the h20 impact
 * (law 2, tolerance 1e-7), 1e-4 of it, so that a movement of 1000
 * tolerances leaves an estimated error of 0.09 of the tolerance. */
#define ONSET_MOVEMENT 1000.0

/* An error-controlled step where nothing sets its scale (a contact that
 * begins at rest): the cap, or the default fixed step where there is none;
 * the control shrinks it as it must. */
static double unscaled_step(const contact_model *cm)
{
    return isfinite(cm->h_max) ? cm->h_max : CONTACT_DEFAULT_STEP;
}

static double onset_step(const contact_model *cm)
{
    const double n = cm->p.spring_exponent, v = cm->s.v, tol = ONSET_MOVEMENT * cm->p.tolerance;
    double Kv, h;
    if (!(v > 0.0))
        return unscaled_step(cm);
    Kv = contact_spring_stiffness(cm, 1) * pow(v, n - 1.0);
    h = fmin(cm->h_max, pow(tol * cm->p.c / Kv, 1.0 / n));
    if (cm->inv_m > 0.0)
        h = fmin(h, pow(tol / (cm->inv_m * Kv), 1.0 / (n + 1.0)));
    return h;
}

/* A bound on the rejected trials of one error-controlled step: each
 * shrinks it at least 10-fold, so only a diverging state reaches it. */
#define MAX_REJECTED_STEPS 40

/* One accepted error-controlled contact step of at most `remaining`, cut
 * at separation: 0, 1 when it stopped at separation with CONTACT_SEPARATION
 * in stop_at, or -1 when no step length is accepted (a diverging state);
 * *advanced is the length stepped. */
static int controlled_internal_step(contact_model *cm, double remaining, double *impulse, unsigned stop_at,
                                    double *advanced)
{
    contact_state *s = &cm->s, trial;
    const double K = contact_spring_stiffness(cm, s->n + 1);
    double h = s->n == 0 ? onset_step(cm) : s->h_next, tau = 0.0, J = 0.0, peak, h_next;
    int rejected, separates = 0;
    for (rejected = 0; rejected <= MAX_REJECTED_STEPS; rejected++) {
        h = smaller(h, cm->h_max);
        /* the last step lands on the interval's end (forgiving a few ulp) */
        tau = h >= remaining * (1.0 - 1e-12) ? remaining : h;
        J = esdirk_step(cm, s, tau, K, &trial);
        separates = !(trial.x1 > 0.0) && !(indentation_rate(cm, &trial) > 0.0);
        if (separates)
            tau = separation_within(cm, s, tau, K, &trial, &J);
        if (trial.error <= 1.0)
            break;
        h = next_step(tau, trial.error, 0.02);
    }
    if (rejected > MAX_REJECTED_STEPS)
        return -1;
    /* A step cut short by the interval or the separation keeps the length
     * the error allowed for the next one; after a rejection the next does
     * not grow (Hairer's rule: the error rose faster than h^5 there). */
    h_next = larger(next_step(tau, trial.error, 0.1), tau < h ? h : 0.0);
    if (rejected > 0)
        h_next = smaller(h_next, tau);
    peak = peak_force_within(cm, s, tau, K, &trial);
    accept_step(cm, &trial);
    s->h_next = h_next;
    count_contact_step(s, peak);
    *impulse += J;
    *advanced = tau;
    if (!separates)
        return 0;
    s->x1 = 0.0;
    end_contact(s, s->t, s->v);
    return (stop_at & CONTACT_SEPARATION) != 0;
}

/* ------------------------------------------------- the full G1 history */

/* Room for x2 at `count` grid points, growing geometrically; 0, or -1 when
 * memory runs out (the history as it was). */
static int history_reserve(contact_history *hist, size_t count)
{
    size_t capacity = hist->capacity ? hist->capacity : 1024;
    double *x2, *w;
    if (count <= hist->capacity)
        return 0;
    while (capacity < count)
        capacity *= 2;
    /* New blocks before the old ones go, so that a failure changes nothing. */
    x2 = malloc(capacity * sizeof *x2);
    w = malloc(capacity * sizeof *w);
    if (!x2 || !w) {
        free(x2);
        free(w);
        return -1;
    }
    if (hist->capacity)
        memcpy(x2, hist->x2, hist->capacity * sizeof *x2);
    free(hist->x2);
    free(hist->w);
    hist->x2 = x2;
    hist->w = w;
    hist->capacity = capacity;
    hist->weights = 0;
    return 0;
}

/* Contact's onset and end after a grid step from *before (x1 crossed 0 at
 * the fraction of the step where its linear interpolation does). */
static int g1_contact_events(contact_model *cm, const contact_state *before, unsigned stop_at)
{
    contact_state *s = &cm->s;
    const double frac = before->x1 / (before->x1 - s->x1), h = s->t - before->t;
    const double t = before->t + frac * h, v = before->v + frac * (s->v - before->v);
    if (!before->in_contact && s->F > 0.0)
        begin_contact(s, t, v);
    if (s->F > 0.0)
        count_contact_step(s, s->F);
    /* as the SDIRK path: a contact ends with the indentation falling, not
     * while the striker still moves in and x1 rounds to 0 */
    if (before->in_contact && s->in_contact && !(s->F > 0.0) && !(s->v - s->x2_rate > 0.0))
        end_contact(s, t, v);
    if (s->in_contact == before->in_contact && s->impacts == before->impacts)
        return 0;
    return (stop_at & (s->in_contact ? CONTACT_ONSET : CONTACT_SEPARATION)) != 0;
}

/* One step of dt_max on the uniform grid from t = 0 (MODEL.md §7): the G1
 * history sum G_j = sum_{i=0..j} w_i x2_{j-i} (times h^-alpha) is D^alpha x2
 * at t_j - alpha h/2 to O(h^2), so (1 + alpha/2) G_j - (alpha/2) G_{j-1} is
 * D^alpha x2 at t_j to O(h^2); with BDF2 for the striker (backward Euler on
 * the first step) the step is second order and L-stable, and at alpha = 1
 * it is BDF2 throughout. The damper's relation is linear in F_j, as in a
 * stage. Contact begins and ends at a step (no step is split), its times
 * interpolated linearly. 0, 1 after an event of the mask stop_at, or -1
 * when memory runs out. */
static int g1_history_step(contact_model *cm, double *impulse, unsigned stop_at)
{
    contact_state *s = &cm->s;
    contact_history *hist = &cm->history;
    const double h = cm->h_max, alpha = cm->p.damper_order, c = cm->p.c_alpha;
    const size_t j = (size_t)s->steps; /* the new grid point; s->steps counts this step already */
    const contact_state before = *s;
    /* BDF2 from the second step on, unless the master's new rate restarted it */
    const int bdf2 = j >= 2 && s->h_prev == h;
    const double lead = bdf2 ? 1.0 + 0.5 * alpha : 1.0, hg = bdf2 ? 2.0 * h / 3.0 : h;
    const double x = s->x1 + s->x2;
    damper_stage d;
    double X, V, F, past, mu, nu, x_h, v_h;
    if (j > CONTACT_G1_HISTORY_MAX || history_reserve(hist, j + 1) != 0)
        return -1;
    if (hist->weights < j + 1 || hist->w_alpha != alpha) {
        g1_weights(alpha, hist->capacity, hist->w);
        hist->weights = hist->capacity;
        hist->w_alpha = alpha;
    }
    if (j == 1)
        hist->x2[0] = 0.0;
    hist->x2[j] = 0.0; /* so that the sum below is the past's part of G_j */
    s->h_prev = h;
    past = pow(h, alpha) * g1_history_sum(alpha, hist->w, hist->x2, j + 1, h);
    /* lead (x2_j + past) - (lead - 1) G_{j-1} = h^alpha F / c_alpha:
     * x2_j = mu F + nu, which a stage takes as A = -nu/mu, inv_B = mu/hg. */
    mu = pow(h, alpha) / (c * lead);
    nu = (lead - 1.0) * hist->G_prev / lead - past;
    x_h = bdf2 ? (4.0 * x - s->x_prev) / 3.0 : x;
    v_h = bdf2 ? (4.0 * s->v - hist->v_prev) / 3.0 : s->v;
    d.inv_B = mu / hg;
    d.A = -nu / mu;
    F = implicit_stage(cm, contact_spring_stiffness(cm, s->in_contact ? s->n + 1 : 1), hg, x_h, v_h, d, &X, &V);
    s->x_prev = x;
    hist->v_prev = s->v;
    s->t += h;
    s->x1 = X;
    s->v = V;
    s->x2 = mu * F + nu;
    s->x2_rate = (s->x2 - before.x2) / h;
    s->step = h;
    s->F = F;
    s->E_diss += 0.5 * (F + before.F) * (s->x2 - before.x2);
    hist->x2[j] = s->x2;
    hist->G_prev = s->x2 + past;
    *impulse += 0.5 * h * (F + before.F);
    return g1_contact_events(cm, &before, stop_at);
}

/* ------------------------------------------------ the paper's scheme */

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
        s->F = x1_next > 0.0 ? spring_force(cm, contact_spring_stiffness(cm, s->n), x1_next) : 0.0;
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
    if (full_history(cm))
        return g1_history_step(cm, impulse, stop_at);
    if (cm->p.scheme == CONTACT_SCHEME_CENTRAL) {
        central_internal_step(cm, h, impulse);
        return cm->s.in_contact != was_in_contact
               && (stop_at & (cm->s.in_contact ? CONTACT_ONSET : CONTACT_SEPARATION));
    }
    return sdirk_internal_step(cm, h, impulse, stop_at);
}

static int state_is_finite(const contact_model *cm)
{
    const contact_state *s = &cm->s;
    size_t i;
#define FINITE(field) &&isfinite(s->field)
#define ALWAYS_FINITE(field)
    if (!(1 CONTACT_STATE_FIELDS(FINITE, ALWAYS_FINITE, ALWAYS_FINITE) && isfinite(s->x2_rate)))
        return 0;
#undef FINITE
#undef ALWAYS_FINITE
    for (i = 0; i < cm->modes.modes; i++)
        if (!isfinite(cm->modes.phi[i]))
            return 0;
    return 1;
}

int contact_steps_uniformly(const contact_model *cm)
{
    return uniform_grid(&cm->p);
}

int contact_check_advance(const contact_model *cm, double H, char *msg, size_t len)
{
    double steps = H / cm->h_max, whole = floor(steps + 0.5);
    if (!full_history(cm))
        return 0;
    /* A sliver within the forgiveness of a whole step would be no step at
     * all here, but one step of dt_max for contact_advance. */
    if (whole < 1.0 || fabs(steps - whole) > 1e-9 * fmax(1.0, whole)) {
        snprintf(msg, len,
                 "memory = 1 (the full G1 history) steps on a uniform grid of dt_max = %.17g s: an advance by "
                 "%.17g s is not a whole number (at least 1) of its steps (use memory = 2 for any step)",
                 cm->h_max, H);
        return -1;
    }
    if ((double)cm->s.steps + whole > (double)CONTACT_G1_HISTORY_MAX) {
        snprintf(msg, len,
                 "memory = 1 (the full G1 history) keeps every step of the run, at most %d (t = %.17g s at "
                 "dt_max = %g s); use memory = 2, whose memory does not grow",
                 CONTACT_G1_HISTORY_MAX, CONTACT_G1_HISTORY_MAX * cm->h_max, cm->h_max);
        return -1;
    }
    return 0;
}

int contact_check_history_span(const contact_params *p, double v, double m, double span, int until_first_separation,
                               const char *name, char *msg, size_t len)
{
    const double h = contact_step_limit(p), reach = CONTACT_G1_HISTORY_MAX * h;
    double arrival;
    char text[2][32];
    if (p->damper != CONTACT_DAMPER_SPRINGPOT || p->memory != CONTACT_MEMORY_G1 || !(span > reach))
        return 0;
    if (until_first_separation && m > 0.0) {
        /* Such a run lasts as long as the striker's flight to the specimen
         * (it stops at once when the striker never gets there) and one
         * contact, whose length is not known in advance. */
        arrival = flight_onset(-p->gap0, v, p->g, span);
        if (arrival < 0.0 ? !(p->g > 0.0) : arrival <= reach)
            return 0;
    }
    snprintf(msg, len,
             "memory = 1 is invalid with %s = %s: the full G1 history keeps every step of dt_max = %s s, at most "
             "%d (to t = %.9g s), and this run may go on for longer; use memory = 2 (any length), a %s within "
             "that, or a larger dt_max",
             name, shown(span, text[0]), shown(h, text[1]), CONTACT_G1_HISTORY_MAX, reach, name);
    return -1;
}

/* The recovery's steps as a fraction of the time since separation. With
 * error-controlled steps dt_max says nothing of the accuracy wanted: the
 * fraction whose O(f^2) error (1.2e-6 at 1/16) is the tolerance. */
static double recovery_fraction(const contact_model *cm)
{
    const contact_state *s = &cm->s;
    if (cm->error_controlled)
        return fmin(1.0 / 16.0, sqrt(cm->p.tolerance / 1.2e-6) / 16.0);
    return s->t_contact > 0.0 ? fmin(1.0 / 16.0, RECOVERY_STEPS * cm->h_max / s->t_contact) : 1.0 / 16.0;
}

/* The next step out of contact while a springpot's memory relaxes: at
 * least dt_max with fixed steps, and with error-controlled ones that
 * fraction of the step the error allowed at the separation (dt_max may be
 * far longer than the memory's fastest relaxation then). */
static double recovery_step(const contact_model *cm, double remaining)
{
    const contact_state *s = &cm->s;
    const double since = s->impacts > 0 ? s->t - (s->t_onset + s->t_contact) : 0.0;
    const double f = recovery_fraction(cm);
    const double least = !cm->error_controlled ? cm->h_max : s->h_next > 0.0 ? f * s->h_next : unscaled_step(cm);
    return fmin(remaining, fmax(least, f * since));
}

double contact_advance(contact_model *cm, double H)
{
    return contact_advance_until(cm, H, 0u);
}

double contact_advance_until(contact_model *cm, double H, unsigned stop_at)
{
    const contact_state start = cm->s;
    const int64_t allowed = cm->max_steps > 0 ? start.steps + cm->max_steps : INT64_MAX;
    double phi_start[CONTACT_MAX_MODES];
    double remaining = H, impulse = 0.0;
    int stopped = 0, failed = 0, exceeded = 0, uniform = contact_steps_uniformly(cm);
    if (!(H > 0.0))
        return 0.0;
    if (compressed_memory(cm))
        memcpy(phi_start, cm->modes.phi, cm->modes.modes * sizeof *phi_start);
    while (remaining > 0.0 && !stopped && !failed) {
        double n, h, i, steps;
        if (cm->s.steps >= allowed) {
            failed = exceeded = 1;
            break;
        }
        if (!cm->s.in_contact && !uniform) {
            /* Free flight is exact at any length while the damper rests: one
             * step to the onset, or over the whole rest when the striker does
             * not arrive; a recovering springpot takes growing steps. */
            double tau;
            int touches;
            cm->s.steps++;
            if (memory_at_rest(cm)) {
                tau = flight_onset(cm->s.x1, cm->s.v, cm->accel, remaining);
                touches = tau >= 0.0;
                if (!touches)
                    tau = remaining;
                fly(cm, tau, touches);
            } else {
                tau = recover(cm, recovery_step(cm, remaining), &touches);
            }
            remaining -= tau;
            stopped = (touches && (stop_at & CONTACT_ONSET)) || (remaining > 0.0 && (stop_at & CONTACT_FLIGHT_STEP))
                      || (cm->poll && cm->s.steps % CONTACT_POLL_STEPS == 0 && cm->poll(cm->poll_ctx));
            continue;
        }
        if (error_controlled(cm)) {
            double advanced = 0.0;
            int status;
            cm->s.steps++;
            status = controlled_internal_step(cm, remaining, &impulse, stop_at, &advanced);
            failed = status < 0;
            stopped = status > 0;
            remaining = advanced < remaining ? remaining - advanced : 0.0;
            continue;
        }
        /* In contact: equal steps of at most dt_max (or what resolves the
         * impact) over the rest, rounding n up but forgiving the last few ulp
         * of the step and of the clock (H = n dt_max gives n steps, not n + 1
         * with a sliver, also when a master computes H as t_next - t, which
         * errs by an ulp of t), until the contact ends or the steps allowed
         * run out. */
        n = fmax(1.0, ceil((remaining - 4.0 * DBL_EPSILON * fabs(cm->s.t + remaining)) / cm->contact_step *
                           (1.0 - 1e-12)));
        h = remaining / n;
        steps = smaller(n, (double)(allowed - cm->s.steps));
        for (i = 0; i < steps && !stopped && !failed && (cm->s.in_contact || uniform); i++) {
            int status = internal_step(cm, h, &impulse, stop_at);
            failed = status < 0;
            stopped = status > 0;
        }
        remaining = i < n ? remaining - i * h : 0.0;
    }
    /* A non-finite value stays non-finite through the steps that follow
     * (and bounds their event searches), so one check at the end suffices. */
    if (failed || !state_is_finite(cm)) {
        cm->exceeded = exceeded;
        cm->s = start;
        if (compressed_memory(cm))
            memcpy(cm->modes.phi, phi_start, cm->modes.modes * sizeof *phi_start);
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
    /* A recovering dent (x2 falls towards 0, never below) may still meet a
     * striker that has not cleared the undeformed surface. */
    if (!memory_at_rest(cm) && !(s->v <= 0.0 && s->x1 + s->x2 <= 0.0))
        return 0;
    if (s->v > 0.0) /* heading in: it arrives unless a deceleration turns it in the gap first */
        return a < 0.0 && !(s->x1 + 0.5 * s->v * s->v / -a > 0.0);
    return 1;
}

int contact_rests(const contact_model *cm)
{
    const contact_state *s = &cm->s;
    return s->in_contact && !springpot(cm) && cm->accel == 0.0 && s->F <= DBL_EPSILON * s->F_peak_contact
           && fabs(s->v) <= DBL_EPSILON * fabs(s->v_onset);
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
    return 1.0 / (cm->n_gamma * cm->k);
}

double contact_semi_integral(const contact_model *cm)
{
    return cm->s.F * contact_semi_integral_per_force(cm);
}

/* ------------------------------------------------ the memory as values */

size_t contact_memory_count(const contact_model *cm)
{
    if (compressed_memory(cm))
        return 1 + cm->modes.modes;
    return full_history(cm) ? 4 + (size_t)cm->s.steps : 0;
}

double contact_memory_get(const contact_model *cm, size_t i)
{
    if (i == 0)
        return cm->s.x2_rate;
    if (compressed_memory(cm))
        return cm->modes.phi[i - 1];
    if (i < 3)
        return i == 1 ? cm->history.v_prev : cm->history.G_prev;
    return i - 3 < cm->history.capacity ? cm->history.x2[i - 3] : 0.0; /* x2(0) = 0 before the first step */
}

int contact_memory_accepts(const contact_model *cm, size_t count, char *msg, size_t len)
{
    size_t expected = contact_memory_count(cm);
    if (full_history(cm) && cm->s.steps > CONTACT_G1_HISTORY_MAX) {
        snprintf(msg, len, "a G1 history of %lld steps exceeds the limit of %d",
                 (long long)cm->s.steps, CONTACT_G1_HISTORY_MAX);
        return -1;
    }
    if (count != expected) {
        snprintf(msg, len, "the damper's memory holds %zu values where these parameters and %lld steps need %zu",
                 count, (long long)cm->s.steps, expected);
        return -1;
    }
    return 0;
}

int contact_memory_resize(contact_model *cm, size_t count)
{
    return full_history(cm) && count > 3 ? history_reserve(&cm->history, count - 3) : 0;
}

void contact_memory_set(contact_model *cm, size_t i, double value)
{
    if (i == 0)
        cm->s.x2_rate = value;
    else if (compressed_memory(cm))
        cm->modes.phi[i - 1] = value;
    else if (i < 3)
        *(i == 1 ? &cm->history.v_prev : &cm->history.G_prev) = value;
    else
        cm->history.x2[i - 3] = value;
}

void contact_copy(contact_model *to, const contact_model *from)
{
    const contact_modes *f = &from->modes;
    contact_modes *t = &to->modes;
    const size_t bytes = f->modes * sizeof f->a[0];
    /* all but the modes, then the modes' scalars and the used part of each array */
    memcpy(to, from, offsetof(contact_model, modes));
    to->history = from->history;
    t->modes = f->modes;
    t->eta = f->eta;
    t->h = f->h;
    t->sum_p = f->sum_p;
    t->sum_q = f->sum_q;
    t->trial_key[1] = 0.0; /* the last trial's modes are not copied */
    memcpy(t->a, f->a, bytes);
    memcpy(t->b, f->b, bytes);
    memcpy(t->phi, f->phi, bytes);
    memcpy(t->p, f->p, bytes);
    memcpy(t->q, f->q, bytes);
    memcpy(t->keep, f->keep, bytes);
    memcpy(t->rate1, f->rate1, bytes);
    memcpy(t->rate2, f->rate2, bytes);
}
