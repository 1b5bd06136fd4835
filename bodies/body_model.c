/* The body FMU: a rigid body of mass m on the impact axis, held to an anchor
 * by a spring k_s and a damper c_s in parallel (unstretched at the start),
 * pushed by two contact forces: F against its motion (the contact in which
 * it is the striker: -F) and F2 along it (the contact in which it is the
 * second body: +F). The anchor is the ground (m_a = 0, the default) or a free
 * mass m_a inside this FMU (a vehicle behind its bumper beam, the crash box
 * between them), starting at the body's v0: a stiff element is never split
 * across FMUs, the contacts are the only coupling between them. Outputs: the
 * body's position x and velocity v (from where it starts, towards the
 * impact), the anchor's x_a and v_a, its mass, and the accelerations a
 * contact's proxy needs to move as the body does: a, of every force but F
 * (the spring, the damper and F2), for the contact it strikes (that
 * contact's input a), and a2, of every force but F2, for the contact that
 * strikes it (its a2); E_diss, the work its damper has dissipated.
 *
 * Over a step the forces are held. The relative motion y = x - x_a then
 * obeys mu y'' + c_s y' + k_s y = mu f/m with f = F2 - F and mu = m m_a/(m +
 * m_a) (mu = m on the ground), a damped oscillator integrated exactly, and
 * the centre of mass moves at the constant acceleration f/(m + m_a). */
#include <math.h>
#include <stddef.h>

#include "fmu_interface.h"
#include "fmu_vars.h"

enum {
    VR_F = 1, VR_F2 = 2, VR_x_a = 3, VR_v_a = 4, VR_m = 5, VR_k_s = 6, VR_c_s = 7, VR_v0 = 8,
    VR_x = 9, VR_v = 10, VR_a = 11, VR_a2 = 12, VR_mass = 13, VR_E_diss = 14, VR_m_a = 15
};

struct fmu_model {
    double F, F2; /* inputs */
    double m, k_s, c_s, v0, m_a; /* parameters */
    double x, v, x_a, v_a, a, a2, mass, E_diss; /* outputs (x, v, x_a, v_a, E_diss: the state) */
    double t;
    int started;
    fmu_reporter log;
};

static const fmu_variable variable_list[] = {
    {VR_F, "F", VAR_REAL, VAR_INPUT, offsetof(fmu_model, F)},
    {VR_F2, "F2", VAR_REAL, VAR_INPUT, offsetof(fmu_model, F2)},
    {VR_x_a, "x_a", VAR_REAL, VAR_OUTPUT, offsetof(fmu_model, x_a)},
    {VR_v_a, "v_a", VAR_REAL, VAR_OUTPUT, offsetof(fmu_model, v_a)},
    {VR_m, "m", VAR_REAL, VAR_PARAMETER, offsetof(fmu_model, m)},
    {VR_k_s, "k_s", VAR_REAL, VAR_PARAMETER, offsetof(fmu_model, k_s)},
    {VR_c_s, "c_s", VAR_REAL, VAR_PARAMETER, offsetof(fmu_model, c_s)},
    {VR_v0, "v0", VAR_REAL, VAR_PARAMETER, offsetof(fmu_model, v0)},
    {VR_x, "x", VAR_REAL, VAR_OUTPUT, offsetof(fmu_model, x)},
    {VR_v, "v", VAR_REAL, VAR_OUTPUT, offsetof(fmu_model, v)},
    {VR_a, "a", VAR_REAL, VAR_OUTPUT, offsetof(fmu_model, a)},
    {VR_a2, "a2", VAR_REAL, VAR_OUTPUT, offsetof(fmu_model, a2)},
    {VR_mass, "mass", VAR_REAL, VAR_OUTPUT, offsetof(fmu_model, mass)},
    {VR_E_diss, "E_diss", VAR_REAL, VAR_OUTPUT, offsetof(fmu_model, E_diss)},
    {VR_m_a, "m_a", VAR_REAL, VAR_PARAMETER, offsetof(fmu_model, m_a)},
};

static const fmu_variables variables = {variable_list, sizeof variable_list / sizeof variable_list[0]};

/* The spring's and damper's acceleration of the body now. */
static double own_acceleration(const fmu_model *fm)
{
    return -(fm->k_s * (fm->x - fm->x_a) + fm->c_s * (fm->v - fm->v_a)) / fm->m;
}

/* The outputs that follow from the state and the inputs. */
static void update_outputs(fmu_model *fm)
{
    const double own = own_acceleration(fm);
    fm->a = own + fm->F2 / fm->m;
    fm->a2 = own - fm->F / fm->m;
    fm->mass = fm->m;
}

/* The state at the start: the body at v0, a free anchor with it, the ground at rest. */
static void start_state(fmu_model *fm)
{
    fm->x = fm->x_a = 0.0;
    fm->v = fm->v0;
    fm->v_a = fm->m_a > 0.0 ? fm->v0 : 0.0;
    fm->E_diss = 0.0;
}

/* The start values that are not 0, and the outputs they give. */
static void start_values(fmu_model *fm)
{
    fm->m = 1.0;
    update_outputs(fm);
}

/* The value's rule, or NULL if it is fine. */
static const char *rule_broken(unsigned vr, double value)
{
    if (!isfinite(value))
        return "must be finite";
    if (vr == VR_m && !(value > 0.0))
        return "the body's mass must be positive [kg]";
    if (vr == VR_k_s && value < 0.0)
        return "the spring's stiffness must not be negative [N/m]";
    if (vr == VR_c_s && value < 0.0)
        return "the damper's constant must not be negative [N s/m]";
    if (vr == VR_m_a && value < 0.0)
        return "the anchor's mass must not be negative (0: the ground) [kg]";
    return NULL;
}

#define FM_RATES "x, v and x_a"

static int rate(const fmu_model *fm, unsigned vr, double *value)
{
    if (vr == VR_x)
        *value = fm->v;
    else if (vr == VR_v)
        *value = own_acceleration(fm) + (fm->F2 - fm->F) / fm->m;
    else if (vr == VR_x_a)
        *value = fm->v_a;
    else
        return 0;
    return 1;
}

/* e^(-beta t) C(t) and e^(-beta t) S(t) of the damped oscillator z'' + 2
 * beta z' + w2 z = 0, where C'' = S'' = lambda (.), lambda = beta^2 - w2,
 * C(0) = S'(0) = 1, C'(0) = S(0) = 0: z(t) = z0 eC + (z0' + beta z0) eS.
 * No damping overflows. */
static void damped(double beta, double w2, double t, double *eC, double *eS)
{
    const double lambda = beta * beta - w2;
    if (lambda < 0.0) { /* underdamped */
        const double wd = sqrt(-lambda), decay = exp(-beta * t);
        *eC = decay * cos(wd * t);
        *eS = decay * (wd * t > 0.0 ? sin(wd * t) / wd : t);
    } else if (lambda > 0.0 && beta * t < 500.0) { /* overdamped: cosh and sinh stay finite */
        const double gamma = sqrt(lambda), decay = exp(-beta * t);
        *eC = decay * cosh(gamma * t);
        *eS = decay * (gamma * t > 0.0 ? sinh(gamma * t) / gamma : t);
    } else if (lambda > 0.0) { /* so overdamped that e^(beta t) would overflow: gamma - beta = -w2/(beta + gamma) */
        const double gamma = sqrt(lambda), slow = exp(-w2 / (beta + gamma) * t), fast = exp(-(beta + gamma) * t);
        *eC = 0.5 * (slow + fast);
        *eS = 0.5 * (slow - fast) / gamma;
    } else { /* critical */
        const double decay = exp(-beta * t);
        *eC = decay;
        *eS = decay * t;
    }
}

/* The relative motion y = x - x_a over a step from (y, y_rate), forcing g
 * held: y'' + 2 beta y' + w2 y = g, exactly. */
static void relative_step(double beta, double w2, double g, double H, double y, double y_rate, double *y_end,
                          double *y_rate_end)
{
    if (w2 > 0.0) { /* about the equilibrium g/w2 */
        const double z = y - g / w2;
        double eC, eS;
        damped(beta, w2, H, &eC, &eS);
        *y_end = g / w2 + z * eC + (y_rate + beta * z) * eS;
        *y_rate_end = y_rate * eC - (w2 * z + beta * y_rate) * eS;
    } else if (beta > 0.0) { /* a damper alone: the rate relaxes to the terminal g/(2 beta) */
        const double terminal = g / (2.0 * beta), decay = -expm1(-2.0 * beta * H);
        *y_end = y + terminal * H + (y_rate - terminal) * decay / (2.0 * beta);
        *y_rate_end = terminal + (y_rate - terminal) * (1.0 - decay);
    } else {
        *y_end = y + H * (y_rate + 0.5 * H * g);
        *y_rate_end = y_rate + H * g;
    }
}

/* The body and its anchor over [t, t + H], the contact forces held. */
fm_status fm_do_step(fmu_model *fm, double t, double H)
{
    const double f = fm->F2 - fm->F, g = f / fm->m;
    const double total = fm->m + fm->m_a, mu = fm->m_a > 0.0 ? fm->m / (1.0 + fm->m / fm->m_a) : fm->m;
    const double y = fm->x - fm->x_a, y_rate = fm->v - fm->v_a;
    double y_end, y_rate_end;
    relative_step(0.5 * fm->c_s / mu, fm->k_s / mu, g, H, y, y_rate, &y_end, &y_rate_end);
    /* mu y'' y' = mu g y' - k_s y y' - c_s y'^2: the damper's work over the step is exact from the step's ends. */
    fm->E_diss += mu * g * (y_end - y) - 0.5 * mu * (y_rate_end * y_rate_end - y_rate * y_rate)
                  - 0.5 * fm->k_s * (y_end * y_end - y * y);
    if (fm->m_a > 0.0) { /* the centre of mass at f/(m + m_a), each mass about it */
        const double centre_v0 = (fm->m * fm->v + fm->m_a * fm->v_a) / total;
        const double centre = (fm->m * fm->x + fm->m_a * fm->x_a) / total + H * (centre_v0 + 0.5 * H * f / total);
        const double centre_v = centre_v0 + H * f / total;
        fm->x = centre + fm->m_a / total * y_end;
        fm->v = centre_v + fm->m_a / total * y_rate_end;
        fm->x_a = centre - fm->m / total * y_end;
        fm->v_a = centre_v - fm->m / total * y_rate_end;
    } else {
        fm->x = y_end;
        fm->v = y_rate_end;
    }
    fm->t = t + H;
    update_outputs(fm);
    return FM_OK;
}

#define F(field) {offsetof(fmu_model, field), FIELD_F64}

static const state_field state_fields[] = {F(F),  F(F2), F(m),   F(k_s), F(c_s),    F(v0), F(m_a),
                                           F(x),  F(v),  F(x_a), F(v_a), F(E_diss), F(t),
                                           {offsetof(fmu_model, started), FIELD_I32}};

/* Whether a state read is one the body can hold. */
static int state_accepted(const fmu_model *trial)
{
    return !rule_broken(VR_m, trial->m) && !rule_broken(VR_k_s, trial->k_s) && !rule_broken(VR_c_s, trial->c_s)
           && !rule_broken(VR_m_a, trial->m_a);
}

#define FM_OUTPUTS(fm) update_outputs(fm)
#include "fmu_defaults.h" /* the hooks not written above */
