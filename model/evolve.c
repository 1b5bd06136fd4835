/* The evolve loop (docs/model.md §16): contact_advance steps the method
 * of the model's record over an interval, exact free flight out of
 * contact, fixed steps split at events, error-controlled ones or a uniform
 * grid's in contact, and leaves the state as it was where a step fails. */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "contact_internal.h"

/* A bound on contact onsets and separations inside one internal step; only
 * a diverging state could reach it. */
#define MAX_EVENTS_PER_STEP 1000

/* One fixed step of length h, split at contact onset and separation (the
 * fixed steps split at events are gradient.c's alone, so its step and
 * accept are taken inline here, not through its record). Returns 0, 1 when it
 * stopped early at an event of the mask stop_at (the state's time tells
 * where), or -1 when the events do not end (a diverging state). Inline, as
 * the controlled step below: contact_advance_until's loop takes one at
 * every internal step, and a call costs speed there. */
static inline int fixed_internal_step(contact_model *cm, double h, double *impulse, unsigned stop_at)
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
        K = spring_stiffness(cm, s->n + 1);
        J = fixed_step(cm, s, h, K, &trial);
        /* Separation is x1 falling to 0 on the way out: an indentation too
         * small for a double (x1 = v h underflows at v ~ 1e-317) is not one. */
        separates = !(trial.x1 > 0.0) && !(indentation_rate(cm, &trial) > 0.0);
        if (separates)
            tau = locate_separation(cm, s, h, K, &trial, &J);
        peak = peak_force_within(cm, s, tau, K, &trial);
        accept_fixed_step(cm, &trial);
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

/* A bound on the rejected trials of one error-controlled step: each
 * shrinks it at least 10-fold, so only a diverging state reaches it. */
#define MAX_REJECTED_STEPS 40

/* One accepted error-controlled contact step of at most `remaining`, cut
 * at separation: 0, 1 when it stopped at separation with CONTACT_SEPARATION
 * in stop_at, or -1 when no step length is accepted (a diverging state);
 * *advanced is the length stepped. */
static inline int controlled_internal_step(contact_model *cm, double remaining, double *impulse, unsigned stop_at,
                                           double *advanced)
{
    contact_state *s = &cm->s, trial;
    const double K = spring_stiffness(cm, s->n + 1);
    double h = s->n == 0 ? onset_step(cm) : s->h_next, tau = 0.0, J = 0.0, peak, h_next;
    int rejected, separates = 0;
    for (rejected = 0; rejected <= MAX_REJECTED_STEPS; rejected++) {
        h = smaller(h, cm->h_max);
        /* the last step lands on the interval's end (forgiving a few ulp) */
        tau = h >= remaining * (1.0 - 1e-12) ? remaining : h;
        J = method_step(cm)(cm, s, tau, K, &trial);
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

/* One internal step of a fixed-step method: 0, 1 after an event of the
 * mask stop_at (a uniform grid stops at the end of the step in which it
 * happened), or -1. */
static int internal_step(contact_model *cm, double h, double *impulse, unsigned stop_at)
{
    cm->s.steps++;
    if (cm->method->grid_step)
        return cm->method->grid_step(cm, h, impulse, stop_at);
    return fixed_internal_step(cm, h, impulse, stop_at);
}

/* Whether every value of the state is finite, one by one. */
static int each_is_finite(const contact_model *cm)
{
    const contact_state *s = &cm->s;
    size_t i;
#define FINITE(field) &&isfinite(s->field)
#define NOT_DOUBLE(field)
    if (!(1 CONTACT_STATE_FIELDS(FINITE, NOT_DOUBLE, NOT_DOUBLE) && isfinite(s->x2_rate)))
        return 0;
#undef FINITE
    for (i = 0; i < cm->modes.modes; i++)
        if (!isfinite(cm->modes.phi[i]))
            return 0;
    return 1;
}

/* Whether every value of the state is finite: their sum is where each is
 * (an infinity or a NaN stays in a sum), an add a value; only a sum that
 * is not, which finite values may also give by overflowing, asks them one
 * by one. */
static inline int state_is_finite(const contact_model *cm)
{
    const contact_state *s = &cm->s;
    double sum = s->x2_rate;
    size_t i;
#define ADD(field) sum += s->field;
    CONTACT_STATE_FIELDS(ADD, NOT_DOUBLE, NOT_DOUBLE)
#undef ADD
#undef NOT_DOUBLE
    for (i = 0; i < cm->modes.modes; i++)
        sum += cm->modes.phi[i];
    return isfinite(sum) || each_is_finite(cm);
}

/* How many equal steps of at most dt_max (or what resolves the impact)
 * cover the rest of an advance: n rounded up but forgiving the last few
 * ulp of the step and of the clock (H = n dt_max gives n steps, not n + 1
 * with a sliver, also when a master computes H as t_next - t, which errs
 * by an ulp of t). A rest no longer than one step is one, as the rounding
 * gives too: the library's pieces of dt_max take it at every step. */
static inline double equal_steps(const contact_model *cm, double remaining)
{
    if (remaining <= cm->contact_step)
        return 1.0;
    return larger(ceil((remaining - 4.0 * DBL_EPSILON * fabs(cm->s.t + remaining)) / cm->contact_step * (1.0 - 1e-12)),
                  1.0);
}

double contact_advance(contact_model *cm, double H)
{
    return contact_advance_until(cm, H, 0u);
}

double contact_advance_until(contact_model *cm, double H, unsigned stop_at)
{
    contact_state start;
    const int64_t allowed = cm->max_steps > 0 ? cm->s.steps + cm->max_steps : INT64_MAX;
    double phi_start[CONTACT_MAX_MODES];
    double remaining = H, impulse = 0.0;
    const int uniform = cm->method->uniform_grid != NULL;
    int stopped = 0, failed = 0, exceeded = 0;
    if (!(H > 0.0))
        return 0.0;
    carry_state(&start, &cm->s);
    if (compressed_memory(cm) && cm->modes.modes)
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
        if (cm->method->controls_error) {
            double advanced = 0.0;
            int status;
            cm->s.steps++;
            status = controlled_internal_step(cm, remaining, &impulse, stop_at, &advanced);
            failed = status < 0;
            stopped = status > 0;
            remaining = advanced < remaining ? remaining - advanced : 0.0;
            continue;
        }
        /* In contact: equal steps over the rest, until the contact ends or
         * the steps allowed run out. */
        n = equal_steps(cm, remaining);
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
        carry_state(&cm->s, &start);
        if (compressed_memory(cm) && cm->modes.modes)
            memcpy(cm->modes.phi, phi_start, cm->modes.modes * sizeof *phi_start);
        return NAN;
    }
    if (!stopped)
        cm->s.t = start.t + H;
    return impulse;
}
