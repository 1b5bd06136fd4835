/* Whether fixed steps resolve an impact: the time a striker takes to stop,
 * the refusal of a dashpot too soft for the spring to carry its force,
 * the uniform grids' check of dt_max against it, the warning where the
 * fixed steps are refined in contact and the refusal where those cannot
 * stop the striker, the fixed step of a contact, and the check that an
 * advance takes no more steps than a caller allows. */
#include <float.h>
#include <math.h>
#include <stdio.h>

#include "contact_internal.h"

/* The time the spring K x1^n takes to stop a striker (1/inv_m its mass)
 * arriving at speed v, x_max / v with x_max = ((n + 1) v^2 / (2 K inv_m))^(1/(n+1))
 * the elastic impact's largest indentation (docs/model.md §2), or where a load
 * a > 0 presses the striker in, sqrt(x_a / a) with x_a = (a / (K inv_m))^(1/n)
 * its indentation at rest under it: the shorter. A step much longer sees the
 * striker stopped and thrown back within it. INFINITY without inertia (inv_m = 0) or either. */
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

/* The speed at which a striker starting at v reaches the specimen, falling
 * through the gap gap0 under g (0 where it does not arrive). */
static double arrival_speed(const contact_params *p, double v)
{
    const double fall = 2.0 * p->g * p->gap0, s = sqrt(fabs(fall));
    if (!(v > 0.0 || p->g > 0.0))
        return 0.0;
    if (fall >= 0.0)
        return hypot(v, s); /* not from v^2, which underflows for a tiny v */
    return v > s ? sqrt((v - s) * (v + s)) : 0.0;
}

/* The stopping time (above) of the first impact of a striker of mass m
 * starting at v: the fastest, since the striker arrives at v (or falls
 * through the gap under g) and every impact after loses speed. */
static double first_turnaround(const contact_params *p, double v, double m)
{
    if (!(m > 0.0))
        return INFINITY;
    return stopping_time(p, spring_constant(p), 1.0 / m, arrival_speed(p, v), p->g);
}

/* Whether the method shortens its fixed steps in a contact they do not
 * resolve: neither a uniform grid nor error-controlled steps do. */
static int refines_fixed_steps(const contact_method_record *m) { return !m->uniform_grid && !m->controls_error; }

/* Why the refined fixed steps (`step`, shorter than dt_max) of a contact
 * from the indentation x1 at the rate `rate` under the load a, up to t_end,
 * cannot stop the striker, or NULL: each must advance the clock, and the
 * first must indent the specimen and push back by normal numbers where the
 * striker moves in (or a load presses it in). Else the
 * spring never acts (or the clock never moves), the contact never ends and
 * the steps run to the step limit, which no estimate of the least work
 * (that counts on the striker stopping in its turnaround time) foresees. */
static const char *refined_fault(const contact_params *p, double K, double x1, double rate, double a, double step,
                                 double t_end, char why[96])
{
    const double first = x1 + fmax(rate, 0.0) * step + 0.5 * fmax(a, 0.0) * step * step;
    const double F = K * pow(first, p->spring_exponent);
    char text[32];
    if (!(step > 4.0 * DBL_EPSILON * fabs(t_end)))
        snprintf(why, 96, "which do not advance the clock at t = %.17g s", t_end);
    else if ((rate > 0.0 || a > 0.0) && !(first >= DBL_MIN && F >= DBL_MIN))
        snprintf(why, 96, "the first indenting by %s m with %.3g N, below the normal doubles: never stopping it",
                 shown(first, text), F);
    else
        return NULL;
    return why;
}

/* The refusal of a striker of mass m at v whose contact's refined steps
 * cannot stop it (refined_fault: why), `from` saying where. */
static int reject_refined(double m, double v, double step, const char *from, const char *why, char *msg, size_t len)
{
    char text[2][32];
    snprintf(msg, len,
             "m = %s, v = %s are invalid%s: the spring stops the striker in %.3g s, resolved in %d steps of "
             "%.3g s, %s; raise m or v",
             shown(m, text[0]), shown(v, text[1]), from, step * CONTACT_REFINED, CONTACT_REFINED, step, why);
    return -1;
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

/* The refusal of a dashpot too soft for the spring to carry its force: once
 * the dashpot has relaxed (in c / k' after the onset) x2 follows the
 * striker and the spring carries c v, at x1^n = c v / k. Where that is
 * below the normal doubles the force is a denormal of few digits, whose
 * rounding the error control takes for error: the steps collapse, and the
 * contact ends where x1 rounds to 0 with the striker still moving in.
 * A striker arriving at a denormal speed indents by less than a double
 * holds and meets no contact (not this rule's). */
static int reject_soft_dashpot(const contact_params *p, double v, char *msg, size_t len)
{
    const double K = spring_constant(p);
    char text[3][32];
    if (p->damper != CONTACT_DAMPER_DASHPOT || !(v >= DBL_MIN) || !(p->c * v < DBL_MIN * K))
        return 0;
    snprintf(msg, len,
             "c = %s is invalid for the striker arriving at v = %s: the spring would carry the dashpot's force c v "
             "at x1^n = c v / k = %s, below the smallest normal double (%.3g); raise c above %.3g, or v",
             shown(p->c, text[0]), shown(v, text[1]), shown(p->c / K * v, text[2]), DBL_MIN, DBL_MIN * K / v);
    return -1;
}

int contact_check_resolution(const contact_params *p, double v, double m, char *msg, size_t len)
{
    const double t = first_turnaround(p, v, m);
    const char *grid = method_record(p)->uniform_grid, *fault;
    char text[3][64], why[96];
    if (reject_soft_dashpot(p, arrival_speed(p, v), msg, len))
        return -1;
    if (!(t < CONTACT_RESOLUTION * contact_step_limit(p)))
        return 0;
    if (refines_fixed_steps(method_record(p))) {
        fault = refined_fault(p, spring_constant(p), 0.0, arrival_speed(p, v), p->g, t / CONTACT_REFINED, 0.0, why);
        return fault ? reject_refined(m, v, t / CONTACT_REFINED, "", fault, msg, len) : 0;
    }
    if (!grid)
        return 0;
    snprintf(msg, len,
             "%s is invalid with m = %s, v = %s: the spring stops the striker in %.3g s, which the %s uniform grid "
             "resolves only in steps of at most %.3g s (%d per stop); lower dt_max to that, or take scheme = 1 and "
             "memory = 2, whose steps shorten in contact",
             shown_step(p, text[0]), shown(m, text[1]), shown(v, text[2]), t, grid, t / CONTACT_RESOLUTION,
             CONTACT_RESOLUTION);
    return -1;
}

int contact_step_warning(const contact_params *p, double v, double m, char *msg, size_t len)
{
    const double t = first_turnaround(p, v, m);
    char text[3][64];
    if (!refines_fixed_steps(method_record(p)) || !(t < CONTACT_RESOLUTION * contact_step_limit(p)))
        return 0;
    snprintf(msg, len,
             "%s does not resolve the impact of m = %s at v = %s: the spring stops the striker in %.3g s, less "
             "than %d steps; in contact the fixed steps are %.3g s instead (%d per stop)",
             shown_step(p, text[0]), shown(m, text[1]), shown(v, text[2]), t, CONTACT_RESOLUTION,
             t / CONTACT_REFINED, CONTACT_REFINED);
    return 1;
}

/* The fixed step of a contact whose onset speed is v (resolve_contact). */
static double contact_step_at(const contact_model *cm, double v)
{
    const double t = stopping_time(&cm->p, cm->k, cm->inv_m, v, cm->accel);
    return !refines_fixed_steps(cm->method) || t >= CONTACT_RESOLUTION * cm->h_max ? cm->h_max : t / CONTACT_REFINED;
}

/* The least time an advance by H from the model's state spends in contact
 * (contact_check_work). The turnaround time after the onset is the fastest
 * a striker stops (x_max / v, the elastic spring's, which slows it down all
 * the way; a damper in series only softens it), and a striker pressing in
 * stays in contact until it stops: at x1 = 0 the force vanishes and x1'
 * is v. A prescribed rate stays in contact until it reverses. */
static double least_contact(const contact_model *cm, double H)
{
    const contact_state *s = &cm->s;
    double onset = 0.0, since = 0.0, v = s->v, turn;
    if (!s->in_contact) {
        onset = flight_onset(s->x1, s->v, cm->accel, H);
        if (onset < 0.0)
            return 0.0;
        v += cm->accel * onset;
    } else if (cm->inv_m > 0.0) {
        since = s->t - s->t_onset;
        v = s->v > 0.0 ? s->v_onset : 0.0;
    }
    if (!(v > 0.0))
        return 0.0;
    if (!(cm->inv_m > 0.0))
        turn = cm->accel < 0.0 ? v / -cm->accel : INFINITY;
    else /* a striker pulled away may turn sooner */
        turn = cm->accel >= 0.0 ? turnaround_time(cm->p.spring_exponent, cm->k, cm->inv_m, v, cm->accel) - since : 0.0;
    return fmin(H - onset, fmax(turn, 0.0));
}

/* The full G1 history's advance by H (whole steps of dt_max, as
 * contact_check_advance takes them): each step sums over all before it. */
static int check_history_work(const contact_model *cm, double H, double max_work, char *msg, size_t len)
{
    const double before = (double)cm->s.steps, after = before + floor(H / cm->h_max + 0.5);
    const double work = contact_history_work(before, after);
    char text[32];
    if (!(work > max_work))
        return 0;
    snprintf(msg, len,
             "memory = 1 (the full G1 history) is invalid for this advance from t = %.17g s: its %.3g steps of "
             "dt_max = %s s would sum over up to %.3g steps each, the work of %.3g internal steps (one more per %d "
             "summed), more than %.0e; use memory = 2, a larger dt_max, or shorter advances (communication steps)",
             cm->s.t, after - before, shown(cm->h_max, text), after, work, CONTACT_HISTORY_PER_UNIT, max_work);
    return -1;
}

/* The contact an advance by H meets: the striker's speed at its onset (the
 * model's onset speed while in contact), or -1 where it meets none. */
static double onset_speed(const contact_model *cm, double H)
{
    const contact_state *s = &cm->s;
    double onset;
    if (s->in_contact)
        return s->v_onset;
    onset = flight_onset(s->x1, s->v, cm->accel, H);
    return onset < 0.0 ? -1.0 : s->v + cm->accel * onset;
}

int contact_check_work(const contact_model *cm, double H, double max_steps, char *msg, size_t len)
{
    double steps, v, step = cm->h_max;
    char text[64], why[96], from[64];
    if (full_history(cm))
        return check_history_work(cm, H, max_steps, msg, len);
    v = onset_speed(cm, H);
    if (v >= 0.0)
        step = cm->s.in_contact ? cm->contact_step : contact_step_at(cm, v);
    if (step < cm->h_max) {
        /* the clock the refined steps must advance: the contact's, from its
         * onset over the steps of its load and release (CONTACT_REFINED
         * each), as far as this advance goes */
        const double rate = cm->s.in_contact ? cm->s.v : v;
        const double onset = cm->s.t + (cm->s.in_contact ? 0.0 : flight_onset(cm->s.x1, cm->s.v, cm->accel, H));
        const double last = fmin(cm->s.t + H, onset + 2.0 * CONTACT_REFINED * step);
        const char *fault = refined_fault(&cm->p, cm->k, fmax(cm->s.x1, 0.0), rate, cm->accel, step, last, why);
        if (fault) {
            snprintf(from, sizeof from, " for this advance from t = %.17g s", cm->s.t);
            return reject_refined(1.0 / cm->inv_m, v, step, from, fault, msg, len);
        }
    }
    if (!(H / step > max_steps)) /* not even all of it in contact: the common case, known at once */
        return 0;
    /* in steps of the contact's (refined) step, not of dt_max */
    steps = contact_least_steps(&cm->p, H, least_contact(cm, H)) * (cm->h_max / step);
    if (!(steps > max_steps))
        return 0;
    snprintf(msg, len,
             "%s is invalid for this advance from t = %.17g s: it would take at least %.3g internal steps of at most "
             "%.3g s, more than %.0e; raise dt_max, or take shorter advances (communication steps)",
             shown_step(&cm->p, text), cm->s.t, steps, step, max_steps);
    return -1;
}

/* The fixed step in the current contact: dt_max where it resolves the
 * impact (CONTACT_RESOLUTION steps in its turnaround time) or the method
 * does not refine its steps, else CONTACT_REFINED steps in that time: a step that does not
 * resolve it is no one's choice, and a barely resolved one errs by
 * O((h/t_c)^2) of order one (docs/stability.md). Set where the onset speed
 * or the inertia change. */
void resolve_contact(contact_model *cm)
{
    cm->contact_step = contact_step_at(cm, cm->s.v_onset);
}
