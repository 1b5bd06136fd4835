/* Event location (docs/model.md §14): contact onset (the free flight's
 * parabola, or a recovering springpot's steps), the force's peak inside a
 * step, and separation, to rounding with fixed steps and to the tolerance
 * with error-controlled ones. */
#include <math.h>

#include "contact_internal.h"

/* Free flight is the parabola x1 + v t + a t^2 / 2 (x1 <= 0: the gap). The
 * first time in [0, h] at which it enters the specimen, or -1 if it stays
 * out: either it is inside at h, or a concave parabola (a < 0) peaks inside
 * the specimen within the step and leaves again. */
double flight_onset(double x1, double v, double a, double h)
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
void touch(contact_model *cm)
{
    cm->s.x1 = 0.0;
    cm->s.F = 0.0;
    begin_contact(&cm->s, cm->s.t, cm->s.v);
    resolve_contact(cm);
}

/* Free flight for tau while the damper rests, exact (the step with no
 * spring), then contact begins if `touches`. */
void fly(contact_model *cm, double tau, int touches)
{
    contact_state trial;
    fixed_step(cm, &cm->s, tau, 0.0, &trial);
    accept_fixed_step(cm, &trial);
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
    *impulse = trial_step(cm, s, h, K, at);
    for (i = 0; i < 200 && fhi != 0.0 && hi - lo > precision * h; i++) {
        contact_state trial;
        double tau = i == 0 && guess > 0.0 && guess < 1.0 ? guess * h : (lo * fhi - hi * flo) / (fhi - flo), f, J;
        if (!(tau > lo && tau < hi))
            tau = 0.5 * (lo + hi);
        J = trial_step(cm, s, tau, K, &trial);
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
 * inside the shrinking bracket, bisecting where it leaves it, until a
 * Newton step or the bracket is below 1e-12 (a Newton step that small
 * leaves the iterate exact to rounding). */
static double polynomial_root(const double *p, int degree)
{
    double lo = 0.0, hi = 1.0, theta = 0.5;
    int i, j;
    for (i = 0; i < 60 && hi - lo > 1e-12; i++) {
        double value = p[degree], slope = 0.0, next;
        for (j = degree - 1; j >= 0; j--) {
            slope = slope * theta + value;
            value = value * theta + p[j];
        }
        if (value > 0.0)
            lo = theta;
        else
            hi = theta;
        next = slope < 0.0 ? theta - value / slope : -1.0;
        if (fabs(next - theta) <= 1e-12)
            return smaller(larger(next, lo), hi);
        theta = next > lo && next < hi ? next : 0.5 * (lo + hi);
    }
    return theta;
}

/* x1 over an error-controlled step from *s to *end as a polynomial in
 * theta = tau / h, p[0..degree]: the method's dense output (Radau IIA's
 * collocation polynomial), or the cubic through the step's ends. Its
 * degree. */
static int indentation_polynomial(const contact_model *cm, const contact_state *s, const contact_state *end,
                                  double h, double p[6])
{
    if (cm->method->dense_indentation) {
        cm->method->dense_indentation(s, end, p);
        return cm->method->dense_degree;
    }
    indentation_cubic(cm, s, end, h, p);
    return 3;
}

/* Where in (0, 1) the polynomial p of this degree turns (its slope falls
 * to 0). */
static double polynomial_turn(const double *p, int degree)
{
    double slope[5];
    int i;
    for (i = 0; i < degree; i++)
        slope[i] = (i + 1) * p[i + 1];
    return polynomial_root(slope, degree - 1);
}

static double polynomial_at(const double *p, int degree, double theta)
{
    double value = p[degree];
    int i;
    for (i = degree - 1; i >= 0; i--)
        value = value * theta + p[i];
    return value;
}

/* The first trial of an event's search in an error-controlled step, as a
 * fraction of the step, from x1's polynomial over it: where x1 falls to 0
 * (separation) or where its slope does (the peak). Fixed steps locate their
 * events as they always have, without a guess. */
static double event_guess(const contact_model *cm, const contact_state *s, const contact_state *end, double h,
                          int peak)
{
    double p[6];
    const int degree = indentation_polynomial(cm, s, end, h, p);
    return peak ? polynomial_turn(p, degree) : polynomial_root(p, degree);
}

/* Where a fixed step from *s of length h, whose end *trial lies past the
 * separation, meets it: to rounding. Returns the length stepped, its state
 * in *trial and its impulse in *J. */
double locate_separation(contact_model *cm, const contact_state *s, double h, double K, contact_state *trial,
                         double *J)
{
    return event_time(cm, s, h, K, indentation, trial->x1, 1e-15, -1.0, trial, J);
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
double separation_within(contact_model *cm, const contact_state *s, double h, double K,
                                contact_state *trial, double *J)
{
    const double precision = separation_precision(cm, s, h), x1_end = trial->x1;
    double tau = event_guess(cm, s, trial, h, 0) * h;
    int i;
    for (i = 0; i < 8; i++) {
        double rate, next;
        *J = method_step(cm)(cm, s, tau, K, trial);
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
 * is located to rounding. Radau IIA reads it off its dense output, whose x1
 * errs by O(h^6) of the motion's scale. ESDIRK takes the force one step
 * from *s to where the cubic through the step's ends turns: that time is
 * off by O(h^4) of the motion's scale, and a force read delta from its peak
 * is low by O(delta^2), far below the tolerance. */
double force_at_turn(contact_model *cm, const contact_state *s, double h, double K, const contact_state *end)
{
    contact_state at;
    double J;
    if (cm->method->dense_indentation) {
        double p[6];
        const int degree = indentation_polynomial(cm, s, end, h, p);
        at.F = spring_force(cm, K, larger(polynomial_at(p, degree, polynomial_turn(p, degree)), 0.0));
    } else if (error_controlled(cm))
        trial_step(cm, s, event_guess(cm, s, end, h, 1) * h, K, &at);
    else
        event_time(cm, s, h, K, indentation_rate, indentation_rate(cm, end), 1e-15, -1.0, &at, &J);
    return at.F > end->F ? at.F : end->F;
}

/* Contact begins at time t with striker velocity v. */
void begin_contact(contact_state *s, double t, double v)
{
    s->n = 0;
    s->F_peak_contact = 0.0;
    s->v_onset = v;
    s->t_onset = t;
    s->in_contact = 1;
}

/* Contact ends at time t with striker velocity v. */
void end_contact(contact_state *s, double t, double v)
{
    s->F = 0.0;
    s->eps = s->v_onset > 0.0 ? -v / s->v_onset : 0.0;
    s->t_contact = t - s->t_onset;
    s->impacts++;
    s->in_contact = 0;
}

/* Out of contact for up to h while a springpot's dent recovers: a fixed
 * step with no spring, cut at the onset if the striker meets the surface.
 * Returns the length stepped, and whether contact began. */
double recover(contact_model *cm, double h, int *touches)
{
    contact_state trial;
    double J;
    fixed_step(cm, &cm->s, h, 0.0, &trial);
    *touches = trial.x1 > 0.0;
    if (*touches && cm->s.x1 < 0.0)
        h = event_time(cm, &cm->s, h, 0.0, gap, -trial.x1, 1e-15, -1.0, &trial, &J);
    else if (*touches) /* it starts on the surface: contact at once */
        h = 0.0;
    if (h > 0.0)
        accept_fixed_step(cm, &trial);
    if (*touches)
        touch(cm);
    return h;
}
