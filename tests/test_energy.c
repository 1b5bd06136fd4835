/* The fixed step never creates energy (docs/model.md §11): a seeded random
 * sweep of configurations, every step of each checked against the energy
 * identity of the discrete gradient, and single steps of any length from
 * random states. */
#include <float.h>
#include <inttypes.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>

#include "check.h"
#include "contact.h"
#include "contact_internal.h"

/* The sweep's sizes: impacts run whole, and single steps. */
#ifndef IMPACTS
#define IMPACTS 100000
#endif
#ifndef SINGLE_STEPS
#define SINGLE_STEPS 200000
#endif

/* Rounding: a step computes each of v, x2, E_diss and the modes in at
 * most four operations from the state before it, each rounding by at most
 * half an ulp of the largest value it adds (an energy, quadratic in v and
 * x1, doubles their relative error); its root X solves X - x1 + b F = rho
 * to a few roundings of those terms (the quartic's coefficients and its
 * Horner sums, two or three each; Newton's method stops after a
 * correction of 1e-8 of X, which leaves it exact to rounding: quadratic
 * convergence), and the mean force F turns the root's residual into
 * energy; this test's own sums of the energies round as much again. So 16
 * ulp of the size of the terms (the energies at both ends, the damper's
 * work in all, and F times the root's terms, root_work) bound what
 * rounding alone can do to the balance of one step. */
#define ROUNDING (16.0 * DBL_EPSILON)

static uint64_t seed = 0x9E3779B97F4A7C15u;

/* xorshift64*: uniform in [0, 1). */
static double uniform(void)
{
    seed ^= seed >> 12;
    seed ^= seed << 25;
    seed ^= seed >> 27;
    return (double)((seed * 2685821657736338717u) >> 11) * 0x1.0p-53;
}

static double log_uniform(double lo, double hi) { return lo * pow(hi / lo, uniform()); }

/* The elastic Hertz contact time of a spring k x^n on a mass m arriving
 * at v (docs/model.md §2, any n): the sweep's time scale. */
static double contact_time(double k, double n, double m, double v)
{
    const double x_max = pow((n + 1.0) * m * v * v / (2.0 * k), 1.0 / (n + 1.0));
    return 2.0 / (n + 1.0) * exp(lgamma(1.0 / (n + 1.0)) + lgamma(0.5) - lgamma(1.0 / (n + 1.0) + 0.5)) * x_max / v;
}

/* The energy of the striker and the spring and its terms' size: the
 * kinetic energy (the mass 1/inv_m; none when the motion is prescribed),
 * the spring's K x1^(n+1)/(n+1), less the potential of the acceleration
 * apart from the contact (gravity: m accel (x1 + x2)); and the energy
 * the springpot's modes' springs hold, c_alpha a_i phi_i^2/2. */
typedef struct {
    double E, size, stored;
} energy;

static energy energy_of(const contact_model *cm, const contact_state *s, double K)
{
    const double n = cm->p.spring_exponent, m = cm->inv_m > 0.0 ? 1.0 / cm->inv_m : 0.0;
    const double kinetic = 0.5 * m * s->v * s->v, elastic = s->x1 > 0.0 ? K * pow(s->x1, n + 1.0) / (n + 1.0) : 0.0;
    const double potential = m * cm->accel * (s->x1 + s->x2);
    double stored = 0.0;
    size_t i;
    if (compressed_memory(cm))
        for (i = 0; i < cm->modes.modes; i++)
            stored += 0.5 * cm->p.c_alpha * cm->modes.a[i] * cm->modes.phi[i] * cm->modes.phi[i];
    return (energy){kinetic + elastic - potential, kinetic + elastic + fabs(m * cm->accel) * (fabs(s->x1) + fabs(s->x2)),
                    stored};
}

/* A random configuration: law, exponent, mass, speed, stiffness, damper,
 * gravity; its step from a 200th of the contact time up to where the
 * model would refine it (CONTACT_RESOLUTION steps in the turnaround,
 * about t_c / 18), so that a whole impact is a few hundred steps. */
static double random_params(contact_params *p, double *v, double *m, int springpot_too)
{
    double t_c;
    contact_default_params(p);
    p->law = 1 + (int)(3.0 * uniform());
    p->spring_exponent = uniform() < 0.5 ? (double)(2 + (int)(3.0 * uniform())) / 2.0 : 1.0 + 2.0 * uniform();
    *m = log_uniform(1e-3, 1e3);
    *v = log_uniform(1e-3, 30.0);
    p->k = log_uniform(1e5, 1e12);
    p->c = log_uniform(1.0, 1e9);
    p->g = uniform() < 0.25 ? 9.81 : 0.0;
    if (springpot_too && uniform() < 0.1) {
        p->damper = CONTACT_DAMPER_SPRINGPOT;
        p->damper_order = 0.05 + 0.95 * uniform();
        p->c_alpha = log_uniform(1.0, 1e9);
    }
    t_c = contact_time(p->k, p->spring_exponent, *m, *v);
    p->dt_max = t_c * log_uniform(1.0 / 200.0, 1.0 / 18.0);
    return t_c;
}

static double worst = 0.0; /* the largest gain of a step over the rounding allowed it */

/* The work of the mean force J/h of a step of length h from *s to *end
 * over the terms of its root X - x1 + b F = rho (gradient.c,
 * gradient_step_of): the indentations x1 and X, the striker's travel,
 * b F = J (inv_B + h inv_m/2), and the springpot's memory's pull A, which
 * moves x2 by h A inv_B = J inv_B - dx2 (1/inv_B = c for the dashpot, which
 * pulls nothing; c_alpha (eta + h/2 sum q_i) for the springpot); and the
 * work of gravity over the striker's travel. */
static double root_work(const contact_model *cm, const contact_state *s, const contact_state *end, double h,
                        double J)
{
    const contact_modes *modes = &cm->modes;
    const double inv_B = compressed_memory(cm) ? 1.0 / (cm->p.c_alpha * (modes->eta + 0.5 * h * modes->sum_q))
                                               : cm->inv_c;
    const double travel = 0.5 * h * (fabs(s->v) + fabs(end->v)), m = cm->inv_m > 0.0 ? 1.0 / cm->inv_m : 0.0;
    if (!(h > 0.0))
        return 0.0;
    return fabs(J / h) * (fabs(s->x1) + fabs(end->x1) + travel + fabs(J) * (inv_B + 0.5 * h * cm->inv_m)
                          + fabs(J * inv_B - (end->x2 - s->x2)))
           + fabs(m * cm->accel) * travel;
}

/* One step's balance: the energy after, with the damper's work since
 * (E_diss the damper's work in all after the step: it rounds with it),
 * against the energy before and the work `input` done on the contact;
 * and the springpot's passivity: its modes' springs gain at most the
 * work done on it. */
static void balance(const char *what, long config, energy before, energy after, double work, double E_diss,
                    double input, double root)
{
    const double gain = after.E + work - before.E - input, stored = after.stored - before.stored - work;
    const double allowed = ROUNDING * (before.size + after.size + fabs(E_diss) + fabs(input) + root);
    const double allowed_stored = ROUNDING * (before.stored + after.stored + fabs(work));
    if (gain / allowed > worst)
        worst = gain / allowed;
    CHECK(gain <= allowed, "%s %ld: a step created %.3g J, %.3g of the rounding allowed", what, config, gain,
          gain / allowed);
    CHECK(stored <= allowed_stored, "%s %ld: the springpot's modes gained %.3g J more than the work on it", what,
          config, stored);
}

/* Whole impacts of the drop test, one internal step at a time (in
 * contact an advance of its fixed step, which may be shorter than dt_max
 * where that does not resolve the impact: resolution.c; out of contact
 * to the onset), each with the stiffness of its step; and the impact's
 * restitution without gravity, where the stiffness never rises from one
 * step to the next (the Hertz law, and the G1 law: docs/model.md §11). */
static void test_impacts(void)
{
    long i;
    for (i = 0; i < IMPACTS; i++) {
        contact_params p;
        contact_model cm;
        double v, m, t_c = random_params(&p, &v, &m, 1);
        int steps;
        if (contact_start(&cm, &p, v, m) != 0) {
            CHECK(0, "impact %ld: the model did not start", i);
            continue;
        }
        for (steps = 0; cm.s.impacts == 0 && steps < 2000 && cm.s.t < 4.0 * t_c; steps++) {
            const double K = contact_spring_stiffness(&cm, cm.s.in_contact ? cm.s.n + 1 : 1);
            const energy before = energy_of(&cm, &cm.s, K);
            const contact_state start = cm.s;
            const double J = contact_advance_until(&cm, cm.s.in_contact ? cm.contact_step : p.dt_max, CONTACT_ONSET);
            balance("impact", i, before, energy_of(&cm, &cm.s, K), cm.s.E_diss - start.E_diss, cm.s.E_diss, 0.0,
                    root_work(&cm, &start, &cm.s, cm.s.t - start.t, J));
        }
        /* law 3's stiffness may rise from one step to the next, which adds energy (docs/model.md §11) */
        if (p.g == 0.0 && cm.s.impacts > 0 && p.law != CONTACT_LAW_G1_EXTRAPOLATED)
            CHECK(cm.s.eps <= 1.0 + ROUNDING * steps, "impact %ld: eps = %.17g", i, cm.s.eps);
        contact_release(&cm);
    }
}

/* Single trial steps of any length, from random states in contact, of the
 * drop test and of the driven scene (no inertia: the prescribed motion
 * does the work J (v + v')/2 on the contact, exactly for a speed that
 * changes linearly over the step). */
static void test_single_steps(void)
{
    long i;
    for (i = 0; i < SINGLE_STEPS; i++) {
        contact_params p;
        contact_model cm;
        contact_state out;
        double v, m, t_c = random_params(&p, &v, &m, 1), h = t_c * log_uniform(1e-6, 1e3), K, J, root, input = 0.0;
        const int driven = uniform() < 0.25;
        energy before;
        size_t j;
        if (driven)
            p.scene = CONTACT_SCENE_DRIVEN;
        if (contact_start(&cm, &p, v, m) != 0) {
            CHECK(0, "step %ld: the model did not start", i);
            continue;
        }
        if (driven)
            contact_drive(&cm, v * (2.0 * uniform() - 0.5), 0.0, (2.0 * uniform() - 1.0) * v / t_c);
        cm.s.in_contact = 1;
        cm.s.n = (int64_t)(10.0 * uniform());
        cm.s.x1 = uniform() < 0.1 ? 0.0 : pow(v * t_c, 1.0 + 0.2 * (uniform() - 0.5)) * uniform();
        cm.s.x2 = v * t_c * uniform();
        if (!driven)
            cm.s.v = v * (2.0 * uniform() - 1.0);
        for (j = 0; j < cm.modes.modes; j++)
            cm.modes.phi[j] = v * t_c * (uniform() - 0.5);
        K = spring_stiffness(&cm, cm.s.n + 1);
        before = energy_of(&cm, &cm.s, K);
        J = fixed_step(&cm, &cm.s, h, K, &out);
        if (driven)
            input = J * 0.5 * (cm.s.v + out.v);
        root = root_work(&cm, &cm.s, &out, h, J);
        accept_fixed_step(&cm, &out);
        balance(driven ? "driven step" : "step", i, before, energy_of(&cm, &cm.s, K), cm.s.E_diss, cm.s.E_diss, input,
                root);
        contact_release(&cm);
    }
}

int main(void)
{
    test_impacts();
    test_single_steps();
    printf("test_energy: %d impacts and %d single steps; the largest gain of a step, %.3g of its rounding\n",
           IMPACTS, SINGLE_STEPS, worst);
    return check_summary("test_energy");
}
