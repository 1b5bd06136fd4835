/* What the files of the model share (contact.h is its public interface):
 * the functions one file defines for another, grouped by the file that
 * defines them, and the small ones every internal step takes inline. */
#ifndef FRACCONTACT_CONTACT_INTERNAL_H
#define FRACCONTACT_CONTACT_INTERNAL_H

#include <math.h>
#include <stddef.h>
#include <string.h>

#include "contact.h"
#include "g1.h"

/* parameters.c */
const char *shown(double value, char text[32]);
double spring_constant(const contact_params *p);
double memory_kernel_floor(const contact_params *p);

/* method.c */
const char *fixed_steps_only(const contact_params *p);

/* resolution.c */
void resolve_contact(contact_model *cm);

/* model.c */
int memory_at_rest(const contact_model *cm);

/* sdirk2.c, esdirk54.c and radau_iia.c: one step of length h from *in
 * with spring stiffness K into *out, returning the contact force's
 * impulse (sdirk_step below, by the damper); the compressed memory after
 * an accepted step. */
double sdirk_dashpot_step(contact_model *cm, const contact_state *in, double h, double K, contact_state *out);
double sdirk_springpot_step(contact_model *cm, const contact_state *in, double h, double K, contact_state *out);
void advance_modes(contact_model *cm, double h, double z1, double z2);
double esdirk_step(contact_model *cm, const contact_state *in, double h, double K, contact_state *out);
double radau_step(contact_model *cm, const contact_state *in, double h, double K, contact_state *out);
void radau_advance_modes(contact_model *cm, const contact_state *trial);
void radau_indentation_polynomial(const contact_state *s, const contact_state *trial, double p[6]);

/* control.c */
double next_step(double h, double error, double least);
double error_length(contact_model *cm, const contact_state *in, double K, const contact_state *out);
double error_speed(const contact_state *in, const contact_state *out);
double onset_step(const contact_model *cm);
double recovery_step(const contact_model *cm, double remaining);

/* events.c */
double flight_onset(double x1, double v, double a, double h);
void touch(contact_model *cm);
void fly(contact_model *cm, double tau, int touches);
double recover(contact_model *cm, double h, int *touches);
double locate_separation(contact_model *cm, const contact_state *s, double h, double K, contact_state *trial,
                         double *J);
double separation_within(contact_model *cm, const contact_state *s, double h, double K, contact_state *trial,
                         double *J);
double force_at_turn(contact_model *cm, const contact_state *s, double h, double K, const contact_state *end);
void begin_contact(contact_state *s, double t, double v);
void end_contact(contact_state *s, double t, double v);

/* g1_history.c and central.c: one step on the uniform grid. */
int history_reserve(contact_history *hist, size_t count);
int g1_history_step(contact_model *cm, double *impulse, unsigned stop_at);
void central_internal_step(contact_model *cm, double h, double *impulse);

/* Whether the parameters step on a uniform grid whatever happens. */
static inline int uniform_grid(const contact_params *p)
{
    const enum contact_method method = contact_method(p);
    return method == CONTACT_METHOD_G1_HISTORY || method == CONTACT_METHOD_CENTRAL;
}

/* The G1 ratio of the law on N intervals for x1^n = Gamma(n+1) D^(-(n-1)) x1
 * (docs/model.md §4): Gamma(N+n)/(Gamma(N) N^n). */
static inline double g1_ratio(int law, double n, double N)
{
    return law == CONTACT_LAW_G1 ? g1_line_ratio(1.0 - n, N) : g1_line_ratio_extrapolated(1.0 - n, N);
}

static inline int springpot(const contact_model *cm) { return cm->p.damper == CONTACT_DAMPER_SPRINGPOT; }

static inline int compressed_memory(const contact_model *cm)
{
    return springpot(cm) && cm->p.memory == CONTACT_MEMORY_COMPRESSED;
}

/* SDIRK2's step (sdirk2.c), the damper's own: inline, so that the fixed
 * steps call the one they take. */
static inline double sdirk_step(contact_model *cm, const contact_state *in, double h, double K, contact_state *out)
{
    return springpot(cm) ? sdirk_springpot_step(cm, in, h, K, out) : sdirk_dashpot_step(cm, in, h, K, out);
}

static inline int full_history(const contact_model *cm)
{
    return springpot(cm) && cm->p.memory == CONTACT_MEMORY_G1;
}

/* The spring force K x1^n at x1 > 0 (the Hertz sphere's n = 1.5 without pow). */
static inline double spring_force(const contact_model *cm, double K, double x1)
{
    const double n = cm->p.spring_exponent;
    return n == 1.5 ? K * x1 * sqrt(x1) : n == 1.0 ? K * x1 : K * pow(x1, n);
}

/* The springpot's passes over its modes sum in this many vector lanes
 * (radau_iia.c), the modes padded to whole lanes by modes that add zeros:
 * a divisor of CONTACT_MAX_MODES. */
#define CONTACT_MODE_LANES 8

/* contact_spring_stiffness, inline for the steps that take it every time. */
static inline double spring_stiffness(const contact_model *cm, long n_steps)
{
    if (cm->p.law == CONTACT_LAW_HERTZ || cm->p.g1_nodes > 0)
        return cm->k_fixed;
    return n_steps > 0 ? cm->k * g1_ratio(cm->p.law, cm->p.spring_exponent, (double)n_steps) : cm->k;
}

/* The larger and the smaller of two numbers, inline where libm's fmax and
 * fmin are calls (the controller takes several per step); b when a is NaN. */
static inline double larger(double a, double b) { return a > b ? a : b; }
static inline double smaller(double a, double b) { return a < b ? a : b; }

static inline int error_controlled(const contact_model *cm) { return cm->error_controlled; }

/* Whether a step from *s is an error-controlled one: in contact. Out of
 * contact a recovering springpot takes recover's SDIRK2 steps, and the
 * onset search among them must take the same. */
static inline int controlled_steps(const contact_model *cm, const contact_state *s)
{
    return cm->error_controlled && s->in_contact;
}

/* Whether an error-controlled step from *s is Radau IIA's: the compressed
 * springpot's in contact. */
static inline int radau_steps(const contact_model *cm, const contact_state *s)
{
    return springpot(cm) && controlled_steps(cm, s);
}

/* An error-controlled step: the dashpot's ESDIRK, the compressed
 * springpot's Radau IIA in contact and SDIRK2 out of it. */
static inline double controlled_step(contact_model *cm, const contact_state *in, double h, double K,
                                     contact_state *out)
{
    if (!springpot(cm))
        return esdirk_step(cm, in, h, K, out);
    if (!radau_steps(cm, in))
        return sdirk_step(cm, in, h, K, out);
    return radau_step(cm, in, h, K, out);
}

static inline double indentation_rate(const contact_model *cm, const contact_state *s)
{
    return s->v - (springpot(cm) ? s->x2_rate : s->F * cm->inv_c);
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

/* The contact's counters after a step whose largest force was `peak`. */
static inline void count_contact_step(contact_state *s, double peak)
{
    s->n++;
    if (peak > s->F_peak_contact)
        s->F_peak_contact = peak;
    if (peak > s->F_peak)
        s->F_peak = peak;
}

/* Copies the part of a state carried from step to step, the fields up to
 * x2_rate (contact.h): a trial's own fields after it are read off the
 * trial alone, so no step copies them. */
static inline void carry_state(contact_state *to, const contact_state *from)
{
    memcpy(to, from, offsetof(contact_state, step));
}

/* Makes a trial step the model's state, and its memory follow. */
static inline void accept_step(contact_model *cm, const contact_state *trial)
{
    if (compressed_memory(cm)) {
        if (controlled_steps(cm, trial))
            radau_advance_modes(cm, trial);
        else
            advance_modes(cm, trial->step, trial->x2_rate1, trial->x2_rate);
    }
    carry_state(&cm->s, trial);
}

#endif
