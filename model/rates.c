/* Model Exchange (docs/model_exchange.md): the model as an ODE that a
 * host's solver integrates, its states, their rates, the nominal values,
 * the event indicators and what the model does at an event. The force, the
 * springpot's kernel and the contact's bookkeeping are the co-simulation's
 * own (spring_force, the modes of model.c, events.c's begin_contact and
 * end_contact). */
#include <math.h>

#include "contact_internal.h"

int contact_me_check(const contact_params *p, char *msg, size_t len)
{
    if (p->law != CONTACT_LAW_HERTZ)
        return contact_reject(msg, len, "law", p->law,
                              "Model Exchange takes the closed-form force, law = 2 (hertz, any spring_exponent): "
                              "the G1 history sums (laws 1 and 3) are discrete-time, take co-simulation for them");
    if (p->damper == CONTACT_DAMPER_SPRINGPOT && p->memory != CONTACT_MEMORY_COMPRESSED)
        return contact_reject(msg, len, "memory", p->memory,
                              "Model Exchange takes the springpot's compressed memory, memory = 2 (its modes are "
                              "ODEs): the full G1 memory (memory = 1) is discrete-time, take co-simulation for it");
    if (p->scheme != CONTACT_SCHEME_GRADIENT)
        return contact_reject(msg, len, "scheme", p->scheme,
                              "Model Exchange has the host's solver integrate the model: the central-difference "
                              "scheme (scheme = 2) is a discrete-time method, take scheme = 1 or co-simulation");
    return 0;
}

/* The springpot's damper rate from F = c_alpha (eta x2' + sum_i a_i phi_i)
 * (docs/model.md §6) with the modes phi. */
static double springpot_rate(const contact_model *cm, double F, const double *phi)
{
    const contact_modes *m = &cm->modes;
    double pull = 0.0;
    size_t i;
    for (i = 0; i < m->modes; i++)
        pull += m->a[i] * phi[i];
    return (F / cm->p.c_alpha - pull) / m->eta;
}

int contact_me_set_states(contact_model *cm, const double *x)
{
    contact_state *s = &cm->s;
    const double x1 = x[CONTACT_ME_X] - x[CONTACT_ME_X2], F = x1 > 0.0 ? spring_force(cm, cm->k_fixed, x1) : 0.0,
                 rate = springpot(cm) ? springpot_rate(cm, F, x + CONTACT_ME_MODES) : F * cm->inv_c;
    size_t i;
    if (!isfinite(x1) || !isfinite(F) || !isfinite(rate) || !isfinite(F * rate))
        return -1;
    s->x2 = x[CONTACT_ME_X2];
    s->x1 = x1;
    if (cm->p.scene == CONTACT_SCENE_DROP)
        s->v = x[CONTACT_ME_V]; /* the driven scene's rate is its input (contact_drive) */
    s->E_diss = x[CONTACT_ME_E_DISS];
    for (i = 0; i < cm->modes.modes; i++)
        cm->modes.phi[i] = x[CONTACT_ME_MODES + i];
    s->F = F;
    s->x2_rate = rate;
    return 0;
}

void contact_me_get_states(const contact_model *cm, double *x)
{
    const contact_state *s = &cm->s;
    size_t i;
    x[CONTACT_ME_X] = contact_total_indentation(cm);
    x[CONTACT_ME_V] = s->v;
    x[CONTACT_ME_X2] = s->x2;
    x[CONTACT_ME_E_DISS] = s->E_diss;
    for (i = 0; i < CONTACT_MAX_MODES; i++)
        x[CONTACT_ME_MODES + i] = i < cm->modes.modes ? cm->modes.phi[i] : 0.0;
}

void contact_me_derivatives(const contact_model *cm, double *dx)
{
    const contact_state *s = &cm->s;
    const double rate = s->x2_rate;
    size_t i;
    dx[CONTACT_ME_X] = s->v;
    dx[CONTACT_ME_V] = cm->accel - cm->inv_m * s->F;
    dx[CONTACT_ME_X2] = rate;
    dx[CONTACT_ME_E_DISS] = s->F * rate;
    for (i = 0; i < CONTACT_MAX_MODES; i++)
        dx[CONTACT_ME_MODES + i] = i < cm->modes.modes ? rate - cm->modes.b[i] * cm->modes.phi[i] : 0.0;
}

/* The spring force's slope dF/dx1 = n K x1^(n-1) in contact, 0 outside. */
static double force_slope(const contact_model *cm, double x1)
{
    const double n = cm->p.spring_exponent;
    return x1 > 0.0 ? n * cm->k_fixed * (n == 1.5 ? sqrt(x1) : pow(x1, n - 1.0)) : 0.0;
}

void contact_me_directional(const contact_model *cm, const double *dx, double dv, double *df)
{
    const contact_state *s = &cm->s;
    const contact_modes *m = &cm->modes;
    const double dF = force_slope(cm, s->x1) * (dx[CONTACT_ME_X] - dx[CONTACT_ME_X2]);
    double d_rate, pull = 0.0;
    size_t i;
    for (i = 0; i < m->modes; i++)
        pull += m->a[i] * dx[CONTACT_ME_MODES + i];
    d_rate = springpot(cm) ? (dF / cm->p.c_alpha - pull) / m->eta : dF * cm->inv_c;
    df[CONTACT_ME_X] = cm->p.scene == CONTACT_SCENE_DROP ? dx[CONTACT_ME_V] : dv;
    df[CONTACT_ME_V] = -cm->inv_m * dF;
    df[CONTACT_ME_X2] = d_rate;
    df[CONTACT_ME_E_DISS] = dF * s->x2_rate + s->F * d_rate;
    for (i = 0; i < CONTACT_MAX_MODES; i++)
        df[CONTACT_ME_MODES + i] = i < m->modes ? d_rate - m->b[i] * dx[CONTACT_ME_MODES + i] : 0.0;
}

/* The elastic indentation of the impact's scale: where the spring's energy
 * K x1^(n+1)/(n+1) holds the approach's kinetic energy m v^2/2 (the
 * largest a dashpot's impact reaches), or where the spring's force is
 * c v when no mass is given (c_alpha v for the springpot: a scale, not its
 * force); 1 micrometre where neither says (the striker at rest). */
static double indentation_scale(const contact_model *cm, double v, double m)
{
    const double n = cm->p.spring_exponent, K = cm->k_fixed;
    double scale = 0.0;
    if (m > 0.0)
        scale = pow(0.5 * (n + 1.0) * m * v * v / K, 1.0 / (n + 1.0));
    else
        scale = pow((springpot(cm) ? cm->p.c_alpha : cm->p.c) * v / K, 1.0 / n);
    return isfinite(scale) && scale > 0.0 ? scale : 1e-6;
}

void contact_me_nominals(const contact_model *cm, double v0, double m, double *nominal)
{
    const double x = indentation_scale(cm, fabs(v0), m), v = fabs(v0) > 0.0 ? fabs(v0) : 1.0,
                 E = m > 0.0 ? 0.5 * m * v * v : spring_force(cm, cm->k_fixed, x) * x;
    size_t i;
    nominal[CONTACT_ME_X] = x;
    nominal[CONTACT_ME_V] = v;
    nominal[CONTACT_ME_X2] = x;
    nominal[CONTACT_ME_E_DISS] = isfinite(E) && E > 0.0 ? E : 1.0;
    for (i = 0; i < CONTACT_MAX_MODES; i++)
        nominal[CONTACT_ME_MODES + i] = x;
}

void contact_me_indicators(const contact_model *cm, double *z)
{
    const contact_state *s = &cm->s;
    z[0] = s->x1;
    /* the indentation's rate in contact, where its fall through 0 is the
     * force's peak; out of contact a constant that crosses nothing */
    z[1] = s->in_contact ? s->v - s->x2_rate : -1.0;
}

/* Whether the contact has begun (not in contact, and the striker inside
 * the surface or on it and moving in) or ended (in contact, and outside it
 * or on it and moving out). */
static int onset_now(const contact_state *s)
{
    return !s->in_contact && (s->x1 > 0.0 || (s->x1 == 0.0 && s->v - s->x2_rate > 0.0));
}

static int separation_now(const contact_state *s)
{
    return s->in_contact && (s->x1 < 0.0 || (s->x1 == 0.0 && s->v - s->x2_rate < 0.0));
}

int contact_me_event(contact_model *cm)
{
    contact_state *s = &cm->s;
    int event = 0;
    if (onset_now(s)) {
        begin_contact(s, s->t, s->v);
        event = CONTACT_ONSET;
    } else if (separation_now(s)) {
        end_contact(s, s->t, s->v);
        event = CONTACT_SEPARATION;
    }
    contact_me_accept(cm);
    return event;
}

void contact_me_accept(contact_model *cm)
{
    contact_state *s = &cm->s;
    if (s->F > s->F_peak_contact)
        s->F_peak_contact = s->F;
    if (s->F > s->F_peak)
        s->F_peak = s->F;
}
