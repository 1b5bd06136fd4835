/* The parameters: the paper's defaults, their checks (an error naming the
 * parameter, its value and the rule), the striker's, and the warnings for
 * values that have no effect (docs/model.md §1, §2). */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "contact_internal.h"
#include "soe.h"

void contact_default_params(contact_params *p)
{
#define PARAMETER_MODEL_FMU_LIBRARY(name, type, unit, value, ...) p->name = value;
#define PARAMETER_MODEL_LIBRARY(name, type, unit, value, ...) p->name = value;
#include "parameters.def"
}

/* The defaults of the inputs the library shares with the FMU: the paper's
 * h20 striker (v = sqrt(2 g h) for its 20 mm drop), no second body. */
static const struct {
#define INPUT_FMU_LIBRARY(name, type, ...) CONTACT_TYPE(type) name;
#include "parameters.def"
} bodies_default = {
#define INPUT_FMU_LIBRARY(name, type, unit, value, ...) value,
#include "parameters.def"
};

void contact_default_striker(double *v, double *m)
{
    *v = bodies_default.v;
    *m = bodies_default.m;
}

double hertz_constant(double R, double E_i, double nu_i, double E_s, double nu_s)
{
    double E_star = 1.0 / ((1.0 - nu_i * nu_i) / E_i + (1.0 - nu_s * nu_s) / E_s);
    return 4.0 / 3.0 * E_star * sqrt(R);
}

/* The value as a user would type it: printf's %g (1.2e+09, 6080), with
 * more digits only where the double needs them to read back the same. */
const char *shown(double value, char text[32])
{
    char digits_of[32]; /* formatted here: GCC's sanitizer build cannot see that text is never null */
    int digits = 6;
    do
        snprintf(digits_of, sizeof digits_of, "%.*g", digits, value);
    while (strtod(digits_of, NULL) != value && value == value && ++digits <= 17);
    return memcpy(text, digits_of, sizeof digits_of);
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
    if (p->scheme != CONTACT_SCHEME_GRADIENT && p->scheme != CONTACT_SCHEME_CENTRAL)
        return contact_reject(msg, len, "scheme", p->scheme, "1 = the implicit discrete gradient, 2 = the paper's central differences");
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
    if (p->damper == CONTACT_DAMPER_SPRINGPOT && p->memory == CONTACT_MEMORY_COMPRESSED
        && p->damper_order < CONTACT_MEMORY_MIN_ORDER)
        return contact_reject(msg, len, "damper_order", p->damper_order,
                              "the compressed memory (memory = 2) takes alpha >= 0.001, where its kernel holds "
                              "memory_tolerance; below, take memory = 1 (the full G1 history)");
    if (p->damper == CONTACT_DAMPER_SPRINGPOT && p->scheme == CONTACT_SCHEME_CENTRAL)
        return contact_reject(msg, len, "scheme", p->scheme,
                              "the central differences (2) drive the dashpot only; the springpot (damper = 2) needs 1");
    /* A kernel floor at or above CONTACT_MEMORY_FLOOR fits CONTACT_MAX_MODES
     * at every alpha and memory_tolerance, as the floor was chosen (tests:
     * test_contact's test_kernels_above_the_floor_fit): only a smaller dt_max
     * needs its kernel built to count the modes. */
    if (p->damper == CONTACT_DAMPER_SPRINGPOT && p->memory == CONTACT_MEMORY_COMPRESSED
        && memory_kernel_floor(p) < CONTACT_MEMORY_FLOOR) {
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

/* The shortest time delta over which the compressed memory's kernel holds
 * its tolerance. Fixed steps never go below dt_max. Error-controlled steps
 * do, far below it at tight tolerances, and dt_max may be long: on time
 * scales under delta the kernel's fitted part flattens out and its lumped
 * dashpot eta takes over, so the springpot would act as a dashpot there.
 * CONTACT_MEMORY_FLOOR is the smallest delta whose kernel fits
 * CONTACT_MAX_MODES at every alpha and memory_tolerance: below it only the
 * onset's first steps of tight tolerances go, where the force and with it
 * the damper's share are negligible (docs/model.md §6). */
double memory_kernel_floor(const contact_params *p)
{
    return contact_error_controlled(p) ? fmin(contact_step_limit(p), CONTACT_MEMORY_FLOOR) : contact_step_limit(p);
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
double spring_constant(const contact_params *p)
{
    return p->k > 0.0 ? p->k : hertz_constant(p->R, p->E_i, p->nu_i, p->E_s, p->nu_s);
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

double contact_reduced_mass(double m, double m2)
{
    return m > 0.0 && m2 > 0.0 ? 1.0 / (1.0 / m + 1.0 / m2) : m;
}

/* The striker's rules applied to the relative motion, whose approach
 * speed and reduced mass the message names as such (the rule's own words
 * say v and m). */
static int check_relative_motion(const contact_params *p, int scene, double u, double m_r, char *msg, size_t len)
{
    int n;
    if (contact_check_striker(p, scene, u, m_r, msg, len) == 0)
        return 0;
    n = snprintf(msg, len, "the relative motion of the two bodies (v - v2 = %g m/s, reduced mass m m2/(m + m2) = %g "
                 "kg) breaks the striker's rule: ", u, m_r);
    if (n > 0 && (size_t)n < len)
        contact_check_striker(p, scene, u, m_r, msg + n, len - (size_t)n);
    return -1;
}

int contact_check_bodies(const contact_params *p, int scene, double v, double m, double v2, double m2, char *msg,
                         size_t len)
{
    if (contact_check_striker(p, scene, v, m, msg, len) != 0)
        return -1;
    if (!isfinite(v2))
        return contact_reject(msg, len, "v2", v2, "the second body's velocity must be finite [m/s]");
    if (!(m2 == 0.0 || (m2 >= DBL_MIN && m2 <= DBL_MAX)))
        return contact_reject(msg, len, "m2", m2,
                              "the second body's mass must be positive, finite and not denormal, or 0 (held "
                              "fixed) [kg]");
    if (isfinite(v) && !isfinite(v - v2))
        return contact_reject(msg, len, "v2", v2, "the approach speed v - v2 must be finite [m/s]");
    return v2 == 0.0 && m2 == 0.0 ? 0 : check_relative_motion(p, scene, v - v2, contact_reduced_mass(m, m2), msg, len);
}

int contact_arrival_warning(const contact_params *p, double v, char *msg, size_t len)
{
    char text[3][32];
    if (p->scene != CONTACT_SCENE_DROP || !isfinite(v) || contact_flight_arrives(-p->gap0, v, p->g))
        return 0; /* a v that is not finite is refused, not warned about */
    snprintf(msg, len,
             "v = %s with g = %s and gap0 = %s: the striker never reaches the specimen (its flight closes the gap "
             "only with g > 0, or v > 0 and v^2 > -2 g gap0): no impact ever happens",
             shown(v, text[0]), shown(p->g, text[1]), shown(p->gap0, text[2]));
    return 1;
}
