/* The step controller of the error-controlled steps (docs/model.md §13):
 * the next step from the error ratio, the first step of a contact, and the
 * steps of a springpot's recovery out of contact. */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "contact_internal.h"

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
 * are library calls). A step controller needs no more, and it runs on
 * every step, where pow is costly. */
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

/* The scale of a step's errors in x1 and x2: the larger of the elastic
 * indentation at the step's ends and at the contact's peak force so far
 * (relative in the force at onset, where x1^n is not smooth, grading the
 * first steps). */
double error_length(contact_model *cm, const contact_state *in, double K, const contact_state *out)
{
    double length = larger(larger(fabs(in->x1), fabs(out->x1)), DBL_MIN);
    if (in->F_peak_contact > larger(in->F, out->F)) /* past the peak: its indentation is the larger */
        length = larger(length, peak_indentation(cm, K, in->F_peak_contact));
    return length;
}

/* The scale of a step's error in x2: x1's (error_length above), or x2's
 * travel over the step where that is longer. A dashpot far softer than the
 * spring lets x2 follow the striker once its fast relaxation (c / k') is
 * over, on steps far longer than that: x2's error is then the force's
 * relative error times the travel, and set against the tiny indentation
 * it would shrink the steps to x1 / v, without end. */
double error_travel(double length, const contact_state *in, const contact_state *out)
{
    return larger(length, fabs(out->x2 - in->x2));
}

/* The scale of a step's error in v: the speed at onset or now. */
double error_speed(const contact_state *in, const contact_state *out)
{
    return larger(larger(fabs(in->v), fabs(out->v)), larger(fabs(in->v_onset), DBL_MIN));
}

/* The step after one of length h with error ratio `error` (error over
 * tolerance): the usual controller 0.9 error^(-1/5) (the embedded
 * solution's order is 4), growing at most 5-fold and shrinking at most to
 * `least` of h. */
double next_step(double h, double error, double least)
{
    double factor = error < DBL_MIN ? 5.0 : error < INFINITY ? 0.9 * inverse_fifth_root(error) : least; /* NaN: least */
    return h * smaller(larger(factor, least), 5.0);
}

/* The first error-controlled step of a contact: where the spring's force
 * K (v h)^n, changing the striker's speed by F h / m and turning the rate
 * F / c into the dashpot, has moved the indentation by ONSET_MOVEMENT
 * tolerances relative to v h; x1^n is not smooth there, and the steps that
 * follow grow at most 5-fold each (grading). The ESDIRK's error on that
 * first step is a small part of the movement, so that a movement of 1000
 * tolerances leaves an estimated error well within the tolerance. */
#define ONSET_MOVEMENT 1000.0

/* An error-controlled step where nothing sets its scale (a contact that
 * begins at rest): the cap, or the default fixed step where there is none;
 * the control shrinks it as it must. */
static double unscaled_step(const contact_model *cm)
{
    return isfinite(cm->h_max) ? cm->h_max : CONTACT_DEFAULT_STEP;
}

/* The springpot's first step: where the dent, c_alpha D^alpha x2 = K (v t)^n,
 *     x2 = K v^n Gamma(n + 1) / Gamma(n + 1 + alpha) t^(n + alpha) / c_alpha,
 * has moved SPRINGPOT_ONSET_MOVEMENT tolerances relative to v h: the
 * dashpot's c says nothing of its time scale. Its x2 is less smooth there
 * than the dashpot's (t^(n + alpha)), the embedded error a larger part of
 * the movement, hence the smaller movement; 0 where the power underflows. */
#define SPRINGPOT_ONSET_MOVEMENT 30.0

static double springpot_onset_step(const contact_model *cm, double Kv)
{
    const double n = cm->p.spring_exponent, alpha = cm->p.damper_order;
    const double scale = tgamma(n + 1.0 + alpha) / tgamma(n + 1.0);
    return pow(SPRINGPOT_ONSET_MOVEMENT * cm->p.tolerance * cm->p.c_alpha * scale / Kv, 1.0 / (n + alpha - 1.0));
}

double onset_step(const contact_model *cm)
{
    const double n = cm->p.spring_exponent, v = cm->s.v, tol = ONSET_MOVEMENT * cm->p.tolerance;
    double Kv, h;
    if (!(v > 0.0))
        return unscaled_step(cm);
    Kv = contact_spring_stiffness(cm, 1) * pow(v, n - 1.0);
    h = springpot(cm) ? springpot_onset_step(cm, Kv) : 0.0;
    h = fmin(cm->h_max, h > 0.0 ? h : pow(tol * cm->p.c / Kv, 1.0 / n));
    if (cm->inv_m > 0.0)
        h = fmin(h, pow(tol / (cm->inv_m * Kv), 1.0 / (n + 1.0)));
    return h;
}

/* While a springpot's dent recovers in free flight, its memory relaxes on
 * the time scale of the time since separation: steps of a fraction f of it
 * (at least dt_max), O(log) many however long the flight. The fixed step's
 * error in the recovery is O(f^2), so f shrinks with dt_max, f = RECOVERY_STEPS
 * dt_max / t_contact (at most 1/16), for an error of O(dt_max^2) like the
 * contact's. */
#define RECOVERY_STEPS 64.0

/* The recovery's steps as a fraction of the time since separation. With
 * error-controlled steps dt_max says nothing of the accuracy wanted: the
 * fraction whose O(f^2) error (its constant, 1.2e-6 at 1/16, below) is the
 * tolerance. */
static double recovery_fraction(const contact_model *cm)
{
    const contact_state *s = &cm->s;
    if (error_controlled(cm))
        return fmin(1.0 / 16.0, sqrt(cm->p.tolerance / 1.2e-6) / 16.0);
    return s->t_contact > 0.0 ? fmin(1.0 / 16.0, RECOVERY_STEPS * cm->h_max / s->t_contact) : 1.0 / 16.0;
}

/* The next step out of contact while a springpot's memory relaxes: at
 * least dt_max with fixed steps, and with error-controlled ones that
 * fraction of the step the error allowed at the separation (dt_max may be
 * far longer than the memory's fastest relaxation then). */
double recovery_step(const contact_model *cm, double remaining)
{
    const contact_state *s = &cm->s;
    const double since = s->impacts > 0 ? s->t - (s->t_onset + s->t_contact) : 0.0;
    const double f = recovery_fraction(cm);
    const double least = !error_controlled(cm) ? cm->h_max : s->h_next > 0.0 ? f * s->h_next : unscaled_step(cm);
    return fmin(remaining, fmax(least, f * since));
}
