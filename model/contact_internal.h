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

/* A method's record, one const at the end of the method's own file, as
 * GSL's gsl_odeiv2_step_type: what the evolve loop, the events and the
 * resolution checks ask of a method. contact_configure chooses it once
 * (method_record); out of contact every method takes the damper's fixed
 * steps (free flight, a springpot's recovery). */
typedef double (*contact_trial_step)(contact_model *cm, const contact_state *in, double h, double K,
                                     contact_state *out);
struct contact_method_record {
    enum contact_method method;
    const char *name;         /* contact_method_name */
    int controls_error;       /* it chooses its steps by the tolerance (contact_error_controlled) */
    const char *uniform_grid; /* whose uniform grid of dt_max it steps on whatever happens, for messages
                                 ("central scheme's"), or NULL: its steps split at events */
    const char *fixed_steps;  /* why it takes fixed steps whatever the tolerance, or NULL */
    /* One trial step in contact of length h from *in with spring stiffness
     * K into *out, returning the contact force's impulse: the dashpot's and
     * the springpot's (NULL: not that damper's method, or a uniform grid,
     * whose grid_step takes its own steps). */
    contact_trial_step dashpot_step, springpot_step;
    /* What accepting the trial step *trial makes of the method's memory
     * (NULL: nothing, the state is all it carries). */
    void (*accept)(contact_model *cm, const contact_state *trial);
    /* Its dense output for the events: x1 over a contact step from *s to
     * *trial as a polynomial of dense_degree in theta = tau / h (NULL: the
     * events take the cubic through the step's ends). */
    void (*dense_indentation)(const contact_state *s, const contact_state *trial, double *p);
    int dense_degree;
    /* One internal step of dt_max on the uniform grid: 0, 1 after an event
     * of the mask stop_at (at the end of the step in which it happened), or
     * -1 (NULL: the steps split at events, evolve.c). */
    int (*grid_step)(contact_model *cm, double h, double *impulse, unsigned stop_at);
};

/* The records, at the ends of gradient.c, esdirk54.c, radau_iia.c,
 * g1_history.c and central.c. */
extern const contact_method_record gradient_method, esdirk54_method, radau_iia_method, g1_history_method,
    central_method;

/* method.c */
const contact_method_record *method_record(const contact_params *p);
const char *fixed_steps_only(const contact_params *p);

/* resolution.c */
void resolve_contact(contact_model *cm);

/* model.c */
int memory_at_rest(const contact_model *cm);

/* gradient.c: the fixed step of length h from *in with spring stiffness
 * K into *out, returning the contact force's impulse, by the damper
 * (fixed_step below). */
double gradient_dashpot_step(contact_model *cm, const contact_state *in, double h, double K, contact_state *out);
double gradient_springpot_step(contact_model *cm, const contact_state *in, double h, double K, contact_state *out);
void advance_modes(contact_model *cm, double h, double z);

/* radau_iia.c, its record's step, memory and dense output (the tests take
 * them one by one). */
double radau_step(contact_model *cm, const contact_state *in, double h, double K, contact_state *out);
void radau_advance_modes(contact_model *cm, const contact_state *trial);
void radau_indentation_polynomial(const contact_state *s, const contact_state *trial, double p[6]);

/* control.c */
double next_step(double h, double error, double least);
double error_length(contact_model *cm, const contact_state *in, double K, const contact_state *out);
double error_travel(double length, const contact_state *in, const contact_state *out);
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

/* g1_history.c */
int history_reserve(contact_history *hist, size_t count);
/* contact_x2_end of the full G1 history. */
double g1_history_x2_end(const contact_model *cm);

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

/* The fixed step (gradient.c), the damper's own: inline, so that the
 * fixed steps call the one they take. */
static inline double fixed_step(contact_model *cm, const contact_state *in, double h, double K, contact_state *out)
{
    return springpot(cm) ? gradient_springpot_step(cm, in, h, K, out) : gradient_dashpot_step(cm, in, h, K, out);
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

/* The l-th of the compressed memory's five arrays of Radau IIA's
 * reciprocals, one after another in its block (contact.h). */
#define RADAU_RECIPROCAL(m, l) ((m)->radau_d + (l) * (m)->room)

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

static inline int error_controlled(const contact_model *cm) { return cm->method->controls_error; }

/* The method's trial step in contact, the damper's. */
static inline contact_trial_step method_step(const contact_model *cm)
{
    return springpot(cm) ? cm->method->springpot_step : cm->method->dashpot_step;
}

/* A trial step from *in: the method's in contact; out of contact every
 * method takes the fixed step (a recovering springpot's steps, and the
 * onset search among them). */
static inline double trial_step(contact_model *cm, const contact_state *in, double h, double K, contact_state *out)
{
    return in->in_contact ? method_step(cm)(cm, in, h, K, out) : fixed_step(cm, in, h, K, out);
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

/* What accepting a fixed step makes of the memory (its record's accept):
 * the compressed memory's modes follow its mean rate. */
static inline void gradient_accept(contact_model *cm, const contact_state *trial)
{
    if (compressed_memory(cm))
        advance_modes(cm, trial->step, trial->x2_rate1);
}

/* Makes a fixed trial step the model's state, and its memory follow:
 * inline, for the fixed steps split at events and every method's steps
 * out of contact; calls through the record there cost the fixed steps
 * more than the noise (tests/instruction_counts.tsv). */
static inline void accept_fixed_step(contact_model *cm, const contact_state *trial)
{
    gradient_accept(cm, trial);
    carry_state(&cm->s, trial);
}

/* Makes a trial step of the model's method the model's state, and its
 * memory follow. */
static inline void accept_step(contact_model *cm, const contact_state *trial)
{
    if (cm->method->accept)
        cm->method->accept(cm, trial);
    carry_state(&cm->s, trial);
}

#endif
