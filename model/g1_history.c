/* The springpot's full G1 history (docs/model.md §7): x2 at every step of
 * the uniform grid from t = 0, and its BDF2 step. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "stage.h"

/* Room for x2 at `count` grid points, growing geometrically; 0, or -1 when
 * memory runs out (the history as it was). */
int history_reserve(contact_history *hist, size_t count)
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

/* x2 at the fraction theta of the grid step after point i, continued from
 * the step's start by the parabola through x2 at points i - 2, i - 1 and i:
 * x2[i] + slope theta + curve theta^2. Before a separation x2 is smooth;
 * past it F = 0, and x2 = I^alpha(F/c_alpha) recovers with a second
 * derivative ~ (t - t_s)^(alpha - 1), so that a secant to the grid point
 * after the separation would err at the order 1 + alpha. */
static void x2_continued(const double *x2, size_t i, double *slope, double *curve)
{
    const double d1 = x2[i] - x2[i - 1], d2 = x2[i - 1] - x2[i - 2];
    *slope = 0.5 * (3.0 * d1 - d2);
    *curve = 0.5 * (d1 - d2);
}

/* Whether the separation in the grid step just taken is located with x2
 * continued from the contact's side: the contact spans the three grid
 * points before the step that x2_continued takes. */
static int separation_extrapolates(const contact_state *s) { return s->n >= 3; }

/* The fraction of the grid step from *before (point j - 1) to the state
 * (point j) where the indentation x1 = x - x2 falls to 0 at a separation:
 * the root in the step of x, linear between the two grid points (its
 * curvature -F/m + g is the force's, near 0 there), less x2_continued. 1
 * when that stays in contact to the step's end (the root beyond it by the
 * scheme's error); x1's secant where x2 cannot be continued or x1 was not
 * positive before. */
static double separation_fraction(const contact_model *cm, const contact_state *before)
{
    const contact_state *s = &cm->s;
    const double C = before->x1;
    double slope, curve, A, B;
    if (!separation_extrapolates(before) || !(C > 0.0))
        return before->x1 / (before->x1 - s->x1);
    /* x1(theta) = C + B theta + A theta^2 */
    x2_continued(cm->history.x2, (size_t)s->steps - 1, &slope, &curve);
    A = -curve;
    B = (s->x1 + s->x2) - (before->x1 + before->x2) - slope;
    if (!(C + B + A < 0.0))
        return 1.0;
    /* the root between theta = 0 (x1 > 0) and 1 (x1 < 0), without
     * cancellation; B^2 - 4AC > 0 there but for rounding */
    return 2.0 * C / (sqrt(larger(B * B - 4.0 * A * C, 0.0)) - B);
}

double g1_history_x2_end(const contact_model *cm)
{
    const contact_state *s = &cm->s;
    const double *x2 = cm->history.x2;
    const double theta = 1.0 - (s->t - (s->t_onset + s->t_contact)) / cm->h_max;
    const size_t i = (size_t)s->steps - 1;
    double slope, curve;
    if (!separation_extrapolates(s))
        return x2[i] + theta * (s->x2 - x2[i]);
    x2_continued(x2, i, &slope, &curve);
    return x2[i] + theta * (slope + theta * curve);
}

/* Contact's onset and end after a grid step from *before: x1 crossed 0 at
 * the fraction of the step where its linear interpolation does (onset) or
 * separation_fraction's (end), v interpolated linearly there. */
static int g1_contact_events(contact_model *cm, const contact_state *before, unsigned stop_at)
{
    contact_state *s = &cm->s;
    const double h = s->t - before->t;
    double frac;
    if (!before->in_contact && s->F > 0.0) {
        frac = before->x1 / (before->x1 - s->x1);
        begin_contact(s, before->t + frac * h, before->v + frac * (s->v - before->v));
    }
    if (s->F > 0.0)
        count_contact_step(s, s->F);
    /* as the fixed steps: a contact ends with the indentation falling, not
     * while the striker still moves in and x1 rounds to 0 */
    if (before->in_contact && s->in_contact && !(s->F > 0.0) && !(s->v - s->x2_rate > 0.0)) {
        frac = separation_fraction(cm, before);
        end_contact(s, before->t + frac * h, before->v + frac * (s->v - before->v));
    }
    if (s->in_contact == before->in_contact && s->impacts == before->impacts)
        return 0;
    return (stop_at & (s->in_contact ? CONTACT_ONSET : CONTACT_SEPARATION)) != 0;
}

/* One step of dt_max on the uniform grid from t = 0 (docs/model.md §7): the G1
 * history sum G_j = sum_{i=0..j} w_i x2_{j-i} (times h^-alpha) is D^alpha x2
 * at t_j - alpha h/2 to O(h^2), so (1 + alpha/2) G_j - (alpha/2) G_{j-1} is
 * D^alpha x2 at t_j to O(h^2); with BDF2 for the striker (backward Euler on
 * the first step) the step is second order and L-stable, and at alpha = 1
 * it is BDF2 throughout. The damper's relation is linear in F_j, as in a
 * stage. Contact begins and ends at a step (no step is split), at times
 * located within it (g1_contact_events). 0, 1 after an event of the mask stop_at, or -1
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

/* The record's grid step: the grid is dt_max's from t = 0, whatever the
 * step the caller divided its advance into. */
static int g1_grid_step(contact_model *cm, double h, double *impulse, unsigned stop_at)
{
    (void)h;
    return g1_history_step(cm, impulse, stop_at);
}

const contact_method_record g1_history_method = {
    .method = CONTACT_METHOD_G1_HISTORY,
    .name = "g1_history",
    .uniform_grid = "full G1 history's",
    .fixed_steps = "the springpot's full G1 history (memory = 1) steps on a uniform grid of dt_max (memory = 2, "
                   "the compressed memory, takes error-controlled steps)",
    .grid_step = g1_grid_step,
};
