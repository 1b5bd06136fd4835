/* The contact model against identities that hold whatever its step:
 * momentum, energy, closed forms, order of convergence, stability. */
#include <float.h>
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "contact.h"
#include "contact_internal.h"
#include "soe.h"

static const double V0 = 0.626418, M = 0.7437; /* the paper's h20 drop */

/* The elastic Hertz contact time t_c = HERTZ_TC x_max / v0 (docs/model.md §2):
 * 2 int_0^1 (1 - u^(5/2))^(-1/2) du, which u^(5/2) = w turns into a beta
 * function, 2 sqrt(pi) Gamma(7/5) / Gamma(9/10) = 2.9432692... */
static double hertz_tc_factor(void)
{
    return 2.0 * sqrt(acos(-1.0)) * tgamma(1.4) / tgamma(0.9);
}

static double hertz_contact_time(double k)
{
    return hertz_tc_factor() * pow(5.0 * M * V0 * V0 / (4.0 * k), 0.4) / V0;
}

/* Rounding: a step rounds each of v, x1, x2 and E_diss once or twice by at
 * most half an ulp of the value, and an energy doubles the velocity's
 * relative error: 4 ulp per step bounds what rounding alone accumulates,
 * relative to the figure's scale (reports/stability/core.py,
 * ROUNDING_ULPS). */
static double rounding(int64_t steps)
{
    return 4.0 * DBL_EPSILON * (double)(steps + 4);
}

/* A drop test until the first impact ends or t_end passes, in steps of
 * dt_max (one contact_advance each, as the FMU does). */
static contact_model drop(int law, double c, double dt, double t_end)
{
    contact_params p;
    contact_model cm;
    contact_default_params(&p);
    p.law = law;
    p.c = c;
    p.dt_max = dt;
    contact_start(&cm, &p, V0, M);
    while (cm.s.impacts == 0 && cm.s.t < t_end)
        contact_advance(&cm, dt);
    return cm;
}

static void test_hertz_constant(void)
{
    /* Equal materials with nu = 0: E* = E/2, so k = (2/3) E sqrt(R). */
    CHECK_REL(hertz_constant(0.01, 3e9, 0.0, 3e9, 0.0), 2e8, 1e-15, "k for E = 3 GPa, R = 1 cm");
    /* A rigid indenter leaves E* = E_s / (1 - nu_s^2). */
    CHECK_REL(hertz_constant(6.35e-3, INFINITY, 0.3, 2.64e9, 0.4),
              4.0 / 3.0 * 2.64e9 / 0.84 * sqrt(6.35e-3), 1e-15, "rigid indenter");
}

/* m v + c x2 is a linear invariant, which the fixed step keeps as any
 * Runge-Kutta method does (m dv = -h F = -c dx2, docs/model.md §11):
 * x2_end = m v0 (1 + eps) / c holds to rounding, at any step and any c.
 * Measured: at most 2.9e-14 (c = 608, 72 000 steps; the roundings add up
 * like a random walk, ~sqrt(steps) ulp); allowed 1e-13. */
static void test_momentum_identity(void)
{
    static const double cs[] = {608.0, 6080.0, 60800.0, 6.08e6}; /* below ~600 it never rebounds */
    int law, i;
    for (law = 1; law <= 2; law++)
        for (i = 0; i < 4; i++) {
            contact_model cm = drop(law, cs[i], 1e-7, 0.05);
            CHECK(cm.s.impacts == 1, "law %d, c %g: no separation", law, cs[i]);
            CHECK_REL(cm.s.x2, M * V0 * (1.0 + cm.s.eps) / cs[i], 1e-13, "x2_end vs m v0 (1 + eps) / c");
        }
}

/* Law 2 conserves 1/2 m v^2 + (2/5) k x1^(5/2) + E_diss, and the fixed
 * step keeps it exactly (docs/model.md §11): to rounding at every step. */
static void test_energy_balance(void)
{
    contact_params p;
    contact_model cm;
    double E0 = 0.5 * M * V0 * V0, worst = 0.0;
    contact_default_params(&p);
    p.law = CONTACT_LAW_HERTZ;
    contact_start(&cm, &p, V0, M);
    while (cm.s.impacts == 0) {
        double x1 = contact_elastic_indentation(&cm);
        double E = 0.5 * M * cm.s.v * cm.s.v + 0.4 * cm.k * x1 * x1 * sqrt(x1) + cm.s.E_diss;
        if (fabs(E - E0) > worst)
            worst = fabs(E - E0);
        contact_advance(&cm, 1e-7);
    }
    CHECK(worst <= rounding(cm.s.steps) * E0, "energy balance off by %.3g of the impact energy, allowed %.3g",
          worst / E0, rounding(cm.s.steps));
}

/* Self-convergence of the Hertz law at the paper's parameters: errors that
 * fall by 4 per halving of the step are second order. */
static void test_second_order(void)
{
    double dts[] = {8e-7, 4e-7, 2e-7, 1e-7}, eps[4], x2[4], tc[4];
    int i;
    for (i = 0; i < 4; i++) {
        contact_model cm = drop(CONTACT_LAW_HERTZ, 6080.0, dts[i], 0.05);
        eps[i] = cm.s.eps;
        x2[i] = cm.s.x2;
        tc[i] = cm.s.t_contact;
    }
    for (i = 0; i < 2; i++) {
        double p_eps = log2(fabs(eps[i] - eps[i + 1]) / fabs(eps[i + 1] - eps[i + 2]));
        double p_x2 = log2(fabs(x2[i] - x2[i + 1]) / fabs(x2[i + 1] - x2[i + 2]));
        double p_tc = log2(fabs(tc[i] - tc[i + 1]) / fabs(tc[i + 1] - tc[i + 2]));
        CHECK(fabs(p_eps - 2.0) < 0.1, "observed order of eps %.3f", p_eps);
        CHECK(fabs(p_x2 - 2.0) < 0.1, "observed order of x2 %.3f", p_x2);
        CHECK(fabs(p_tc - 2.0) < 0.1, "observed order of the contact time %.3f", p_tc);
    }
}

/* The elastic limit (c -> infinity): Hertz impact, docs/model.md §2. The
 * fixed step keeps the energy, so the striker stops where the spring holds
 * what the dashpot left of the impact energy, E0 - E_diss: F_max low by
 * 3/5 of E_diss/E0 (F ~ E^(3/5)), to rounding, at any step; and eps is
 * sqrt(1 - E_diss/E0), to rounding. The contact time's error is the
 * scheme's, measured +1.02 h^2 at dt = 1e-7 (h = dt/t_c = 8.1e-5, against
 * the exact constant); allowed 2.1 h^2. */
static void test_elastic_limit(void)
{
    contact_model cm = drop(CONTACT_LAW_HERTZ, 1e15, 1e-7, 0.05);
    double k = cm.k, E0 = 0.5 * M * V0 * V0, loss = cm.s.E_diss / E0, rnd = rounding(cm.s.steps);
    double x_max = pow(5.0 * M * V0 * V0 / (4.0 * k), 0.4), t_c = hertz_contact_time(k), h = 1e-7 / t_c;
    CHECK_REL(cm.s.F_peak, k * pow(x_max, 1.5) * (1.0 - 0.6 * loss), rnd, "Hertz F_max");
    CHECK_REL(cm.s.t_contact, t_c, 2.1 * h * h, "Hertz contact time");
    CHECK(cm.s.eps <= 1.0 + rnd && fabs(cm.s.eps - sqrt(1.0 - loss)) <= rnd, "eps = %.17g, not sqrt(1 - %.3g)",
          cm.s.eps, loss);
}

/* However stiff the dashpot split and however long the step: finite, no
 * tension, the momentum invariant, eps in [0, 1], no energy created (what
 * is left, kinetic and at least 2/5 k x1^(5/2) elastic, the G1 laws'
 * stiffness being never below k, plus what was dissipated, never exceeds
 * the impact energy) and no force above (n + 1) c v0 (the fixed step's
 * bound, docs/model.md §11; the model's own force never exceeds c v0),
 * each to rounding only: no allowance grows with the step. */
static void test_stability(void)
{
    static const double cs[] = {1e-2, 1.0, 1e2, 6080.0, 1e6, 1e9};
    static const double dts[] = {1e-9, 1e-7, 1e-5, 1e-4, 1e-3, 1e-1};
    int law, i, j;
    for (law = 1; law <= 2; law++)
        for (i = 0; i < 6; i++)
            for (j = 0; j < 6; j++) {
                double c = cs[i], dt = dts[j], t_end = dt > 1e-4 ? 50 * dt : 2e-3, rnd, x1, E0 = 0.5 * M * V0 * V0;
                double E_left, p_scale;
                contact_model cm;
                if (dt < 1e-8 && c < 1.0)
                    continue; /* 2 ms at 1 ns is covered by the stiffer cases; keep the test fast */
                cm = drop(law, c, dt, t_end);
                rnd = rounding(cm.s.steps);
                CHECK(isfinite(cm.s.x1) && isfinite(cm.s.v) && isfinite(cm.s.x2) && isfinite(cm.s.E_diss),
                      "law %d c %g dt %g: non-finite state", law, c, dt);
                CHECK(cm.s.F >= 0.0 && cm.s.F_peak >= 0.0, "law %d c %g dt %g: tension", law, c, dt);
                CHECK(cm.s.eps >= 0.0, "law %d c %g dt %g: eps %.17g", law, c, dt, cm.s.eps);
                CHECK(cm.s.eps <= 1.0 + rnd, "law %d c %g dt %g: eps - 1 = %.3g above rounding", law, c, dt,
                      cm.s.eps - 1.0);
                p_scale = M * V0 + M * fabs(cm.s.v) + c * fabs(cm.s.x2);
                CHECK(fabs(M * (V0 - cm.s.v) - c * cm.s.x2) <= rnd * p_scale,
                      "law %d c %g dt %g: momentum m (v0 - v) = %.17g vs c x2 = %.17g", law, c, dt,
                      M * (V0 - cm.s.v), c * cm.s.x2);
                x1 = contact_elastic_indentation(&cm);
                E_left = 0.5 * M * cm.s.v * cm.s.v + 0.4 * cm.k * x1 * x1 * sqrt(x1) + cm.s.E_diss;
                CHECK(E_left - E0 <= rnd * (E_left + E0), "law %d c %g dt %g: energy created, %.3g of the impact energy",
                      law, c, dt, (E_left - E0) / E0);
                CHECK(cm.s.F_peak <= 2.5 * c * V0 * (1.0 + rnd), "law %d c %g dt %g: F_peak %.3g of (n + 1) c v0", law,
                      c, dt, cm.s.F_peak / (2.5 * c * V0));
            }
}

/* The G1 law's stiffness: Hertz times Gamma(N+3/2)/(Gamma(N) N^(3/2)). */
static void test_spring_stiffness(void)
{
    contact_params p;
    contact_model cm;
    contact_default_params(&p);
    contact_start(&cm, &p, V0, M);
    CHECK_REL(contact_spring_stiffness(&cm, 1), p.k * 0.75 * sqrt(4.0 * atan(1.0)), 1e-15, "N = 1: Gamma(5/2) k");
    CHECK_REL(contact_spring_stiffness(&cm, 2), p.k * tgamma(3.5) / pow(2.0, 1.5), 1e-14, "N = 2");
    p.g1_nodes = 1000;
    contact_start(&cm, &p, V0, M);
    CHECK_REL(contact_spring_stiffness(&cm, 7), p.k * exp(lgamma(1001.5) - lgamma(1000.0) - 1.5 * log(1000.0)),
              1e-12, "fixed N = 1000 ignores the step count");
    p.law = CONTACT_LAW_HERTZ;
    contact_start(&cm, &p, V0, M);
    CHECK(contact_spring_stiffness(&cm, 1) == p.k, "Hertz law: k itself");
}

/* A gap and gravity: free flight is a parabola, so contact begins at
 * t = (sqrt(v0^2 + 2 g gap) - v0) / g with velocity sqrt(v0^2 + 2 g gap). */
static void test_gap_and_gravity(void)
{
    contact_params p;
    contact_model cm;
    double g = 9.81, gap = 1e-3, v_on = sqrt(V0 * V0 + 2 * g * gap);
    contact_default_params(&p);
    p.g = g;
    p.gap0 = gap;
    p.dt_max = 1e-6;
    contact_start(&cm, &p, V0, M);
    while (!cm.s.in_contact)
        contact_advance(&cm, 1e-5);
    /* Rounding only: measured 14 and 11 ulp (with the onset time written
     * without the cancellation of (v_on - v0) / g); allowed 64 ulp. */
    CHECK_REL(cm.s.t_onset, 2.0 * gap / (V0 + v_on), 64 * DBL_EPSILON, "onset time");
    CHECK_REL(cm.s.v_onset, v_on, 64 * DBL_EPSILON, "onset velocity");
    /* It bounces and lands again: repeated impacts under gravity. */
    while (cm.s.impacts < 3 && cm.s.t < 1.0)
        contact_advance(&cm, 1e-5);
    CHECK(cm.s.impacts == 3, "3 impacts by t = %g s, got %" PRId64, cm.s.t, cm.s.impacts);
}

/* An advance that would take more than max_steps internal steps stops,
 * returns NaN, says so, and leaves the state as it was; the same advance
 * without the limit goes through (the h20 contact from t = 0: 13 161 steps
 * of 1e-7 s, then one flight step). */
static void test_step_limit(void)
{
    contact_params p;
    contact_model cm;
    double v0, m;
    contact_default_params(&p);
    contact_default_striker(&v0, &m);
    contact_start(&cm, &p, v0, m);
    cm.max_steps = 1000;
    CHECK(isnan(contact_advance(&cm, 1.0)) && cm.exceeded, "an advance past max_steps fails and says why");
    CHECK(cm.s.t == 0.0 && cm.s.steps == 0 && cm.s.x1 == 0.0 && cm.s.v == v0, "and changes nothing");
    cm.max_steps = 13162;
    CHECK(!isnan(contact_advance(&cm, 1.0)) && cm.s.impacts == 1 && cm.s.steps == 13162,
          "within the limit it goes through: %lld steps", (long long)cm.s.steps);
}

/* The springpot's first error-controlled step of a contact is accepted at
 * its first trial (a rejection wastes a trial of 67 modes): its length from
 * the springpot's own time scale, not the dashpot's c. */
static void test_springpot_onset_step(void)
{
    static const double alphas[] = {0.2, 0.5, 0.8}, tolerances[] = {1e-6, 1e-8, 1e-10};
    size_t i, j;
    for (i = 0; i < sizeof alphas / sizeof alphas[0]; i++)
        for (j = 0; j < sizeof tolerances / sizeof tolerances[0]; j++) {
            contact_params p;
            contact_model cm;
            contact_state trial;
            double v0, m, h;
            contact_default_params(&p);
            contact_default_striker(&v0, &m);
            p.law = CONTACT_LAW_HERTZ;
            p.damper = CONTACT_DAMPER_SPRINGPOT;
            p.damper_order = alphas[i];
            p.tolerance = tolerances[j];
            contact_start(&cm, &p, v0, m);
            contact_advance_until(&cm, 1.0, CONTACT_ONSET);
            h = onset_step(&cm);
            radau_step(&cm, &cm.s, h, spring_stiffness(&cm, cm.s.n + 1), &trial);
            CHECK(cm.s.in_contact && trial.error <= 1.0, "alpha %g, tolerance %g: the onset step %.3g errs %.3g",
                  alphas[i], tolerances[j], h, trial.error);
            contact_release(&cm);
        }
}

/* Radau IIA with five stages, built here from its definition alone,
 * independent of radau_iia.c's tables: its nodes are the roots of
 * P_5(2x - 1) - P_4(2x - 1) (Legendre polynomials; Hairer and Wanner II,
 * IV.5), each found by Newton's method from the table's value and checked
 * to have moved by rounding only, and A_ij the integral of the j-th
 * Lagrange polynomial on them from 0 to c_i, integrated exactly from its
 * coefficients. */
static double radau_polynomial(double x, double *slope)
{
    double p0 = 1.0, p1 = 2.0 * x - 1.0, d0 = 0.0, d1 = 2.0, p4 = 0.0, d4 = 0.0;
    int n;
    for (n = 1; n < 5; n++) { /* (n+1) P_(n+1) = (2n+1) y P_n - n P_(n-1), y = 2x - 1 */
        const double y = 2.0 * x - 1.0;
        const double p2 = ((2 * n + 1) * y * p1 - n * p0) / (n + 1);
        const double d2 = ((2 * n + 1) * (2.0 * p1 + y * d1) - n * d0) / (n + 1);
        p0 = p1, p1 = p2, d0 = d1, d1 = d2;
        if (n == 3)
            p4 = p1, d4 = d1;
    }
    *slope = d1 - d4;
    return p1 - p4;
}

static void radau_tableau(double c[5], double A[5][5])
{
    static const double table[5] = {0.057104196114517683, 0.2768430136381238, 0.58359043236891683,
                                    0.86024013565621948, 1.0};
    int i, j, k, it;
    for (i = 0; i < 5; i++) {
        double x = table[i], slope;
        for (it = 0; it < 5; it++)
            x -= radau_polynomial(x, &slope) / slope;
        CHECK(fabs(x - table[i]) <= 4.0 * DBL_EPSILON, "Radau node %d: %.17g is a root (%.17g)", i, table[i], x);
        c[i] = x;
    }
    for (j = 0; j < 5; j++) {
        double poly[5] = {1.0, 0.0, 0.0, 0.0, 0.0}; /* l_j's coefficients, lowest first */
        int degree = 0;
        for (k = 0; k < 5; k++) {
            int m;
            if (k == j)
                continue;
            for (m = ++degree; m >= 0; m--) /* times (t - c_k) / (c_j - c_k) */
                poly[m] = ((m > 0 ? poly[m - 1] : 0.0) - c[k] * poly[m]) / (c[j] - c[k]);
        }
        for (i = 0; i < 5; i++) {
            double integral = 0.0, power = c[i];
            int m;
            for (m = 0; m < 5; m++, power *= c[i])
                integral += poly[m] * power / (m + 1);
            A[i][j] = integral;
        }
    }
}

/* x := M^-1 x, Gaussian elimination with partial pivoting (n <= 5). */
static void gauss(int n, double M[5][5], double x[5])
{
    int i, j, k;
    for (k = 0; k < n; k++) {
        int p = k;
        for (i = k + 1; i < n; i++)
            if (fabs(M[i][k]) > fabs(M[p][k]))
                p = i;
        for (j = 0; j < n; j++) {
            const double t = M[k][j];
            M[k][j] = M[p][j], M[p][j] = t;
        }
        {
            const double t = x[k];
            x[k] = x[p], x[p] = t;
        }
        for (i = k + 1; i < n; i++) {
            const double f = M[i][k] / M[k][k];
            for (j = k; j < n; j++)
                M[i][j] -= f * M[k][j];
            x[i] -= f * x[k];
        }
    }
    for (k = n - 1; k >= 0; k--) {
        for (j = k + 1; j < n; j++)
            x[k] -= M[k][j] * x[j];
        x[k] /= M[k][k];
    }
}

/* The default springpot on the Hertz spring at this tolerance, started on
 * the h20 drop test. */
static void start_springpot(contact_model *cm, double tolerance)
{
    contact_params p;
    double v0, m;
    contact_default_params(&p);
    contact_default_striker(&v0, &m);
    p.law = CONTACT_LAW_HERTZ;
    p.damper = CONTACT_DAMPER_SPRINGPOT;
    p.tolerance = tolerance;
    contact_start(cm, &p, v0, m);
}

/* The same 3e-4 s into the h20 impact: in contact, its memory's modes
 * stirred. */
static void start_springpot_in_contact(contact_model *cm, double tolerance)
{
    start_springpot(cm, tolerance);
    contact_advance(cm, 3e-4);
}

/* After an accepted error-controlled springpot step each mode is the last
 * stage's: Phi solves (I + h b A) Phi = phi_n 1 + h A Z with the trial's
 * stage rates Z, which radau_advance_modes takes through A's eigenbasis;
 * solved here mode by mode from the tableau built above, from the slowest
 * mode to the stiffest and from a step of a ns to one of 0.1 ms. Both
 * round sums of terms up to about 50 times the mode's scale (|phi_n| and
 * the travel h sum |Z|: the eigenbasis's last row reaches 50), some 1e-14
 * of it: 1e-13 of that scale (measured: within 2.5e-14 of it). And the
 * stages' elimination of the modes is consistent: the memory's force at
 * the step's end from the advanced modes, c_alpha (eta z + sum a phi), is
 * the spring's force there, to the rounding of those terms: 1e-13 of the
 * memory's scale c_alpha sum |a phi| (measured: within 2.2e-14 of it). */
static void test_radau_modes_are_the_last_stage(void)
{
    static const double steps[] = {1e-9, 1e-6, 1e-5, 1e-4};
    contact_model cm, after;
    double c[5], A[5][5];
    size_t i, j;
    radau_tableau(c, A);
    start_springpot_in_contact(&cm, 1e-8);
    CHECK(cm.s.in_contact && cm.modes.modes > 0, "in contact at 3e-4 s with %zu modes", cm.modes.modes);
    memset(&after, 0, sizeof after);
    CHECK(contact_copy_room(&after, &cm) == 0, "room for a copy of %zu modes", cm.modes.modes);
    for (i = 0; i < sizeof steps / sizeof steps[0]; i++) {
        const double h = steps[i];
        contact_state trial;
        double Z[5], travel = 0.0, memory = 0.0, scale = 0.0, worst = 0.0;
        int k, s;
        radau_step(&cm, &cm.s, h, spring_stiffness(&cm, cm.s.n + 1), &trial);
        Z[0] = trial.x2_rate1;
        for (k = 0; k < 3; k++)
            Z[k + 1] = trial.x2_rate_inner[k];
        Z[4] = trial.x2_rate;
        for (k = 0; k < 5; k++)
            travel += h * fabs(Z[k]);
        contact_copy(&after, &cm);
        radau_advance_modes(&after, &trial);
        for (j = 0; j < cm.modes.modes; j++) {
            const double b = cm.modes.b[j], phi_n = cm.modes.phi[j];
            double M5[5][5], Phi[5];
            for (s = 0; s < 5; s++) {
                Phi[s] = phi_n;
                for (k = 0; k < 5; k++) {
                    M5[s][k] = (s == k) + h * b * A[s][k];
                    Phi[s] += h * A[s][k] * Z[k];
                }
            }
            gauss(5, M5, Phi);
            worst = fmax(worst, fabs(after.modes.phi[j] - Phi[4]) / (fabs(phi_n) + travel));
            memory += cm.modes.a[j] * after.modes.phi[j];
            scale += fabs(cm.modes.a[j] * after.modes.phi[j]);
        }
        CHECK(worst <= 1e-13, "h = %g: the modes are the last stage's within %.2g of their scale", h, worst);
        CHECK(fabs(cm.p.c_alpha * (cm.modes.eta * trial.x2_rate + memory) - trial.F) <= 1e-13 * cm.p.c_alpha * scale,
              "h = %g: the memory's force %.17g is the spring's %.17g", h,
              cm.p.c_alpha * (cm.modes.eta * trial.x2_rate + memory), trial.F);
    }
    contact_release_modes(&after);
    contact_release(&cm);
}

/* Radau IIA's dense output is the polynomial through x1 at the step's
 * start and its five stages: given the values of a quintic at 0 and at the
 * nodes built above, it returns the quintic's coefficients. Its table's
 * entries reach 544 and the values here 1.5: each coefficient is a sum of
 * six terms up to 820, rounded by at most 6 x 820 x 1.1e-16 = 5.4e-13:
 * 1e-12 (measured: within 1.3e-14). */
static void test_radau_dense_output_interpolates(void)
{
    static const double quintic[6] = {0.25, -1.0, 2.0, 0.5, -3.0, 1.75};
    contact_state start, trial;
    double c[5], A[5][5], y[5], p[6], worst = 0.0;
    int i, k;
    radau_tableau(c, A);
    for (i = 0; i < 5; i++) {
        y[i] = 0.0;
        for (k = 5; k >= 0; k--)
            y[i] = y[i] * c[i] + quintic[k];
    }
    memset(&start, 0, sizeof start);
    memset(&trial, 0, sizeof trial);
    start.x1 = quintic[0];
    for (i = 0; i < 4; i++)
        trial.x1_inner[i] = y[i];
    trial.x1 = y[4];
    radau_indentation_polynomial(&start, &trial, p);
    for (k = 0; k < 6; k++)
        worst = fmax(worst, fabs(p[k] - quintic[k]));
    CHECK(worst <= 1e-12, "the dense output's coefficients are the quintic's within %.2g", worst);
}

/* A copied model steps as its original, to the bit, whatever the memory
 * it was copied into held before: here every byte of the struct but its
 * block's pointers, and of the block, 0xff (NaN), which the
 * springpot's passes would sum in the modes padded to whole lanes were
 * they not zeroed in the copy too. */
static void test_a_copy_steps_as_its_original(void)
{
    contact_model cm, copy;
    contact_state original, copied;
    double h, K;
    start_springpot_in_contact(&cm, 1e-6);
    memset(&copy, 0, sizeof copy);
    CHECK(contact_copy_room(&copy, &cm) == 0, "room for a copy of %zu modes", cm.modes.modes);
    memset(&copy, 0xff, offsetof(contact_model, modes));
    memset(copy.modes.a, 0xff, contact_model_bytes(&copy) - sizeof copy);
    contact_copy(&copy, &cm);
    h = cm.s.h_next, K = spring_stiffness(&cm, cm.s.n + 1);
    memset(&original, 0, sizeof original);
    memset(&copied, 0, sizeof copied);
    radau_step(&cm, &cm.s, h, K, &original);
    radau_step(&copy, &copy.s, h, K, &copied);
    CHECK(cm.modes.modes % CONTACT_MODE_LANES != 0 && memcmp(&original, &copied, sizeof original) == 0,
          "a copy's step (%zu modes) is its original's: x1 %.17g and %.17g", cm.modes.modes, copied.x1, original.x1);
    contact_release_modes(&copy);
    contact_release(&cm);
}

/* A model started on memory that held anything (here every byte 0xff,
 * NaN) runs as one started on zeros, to the bit: contact_start clears the
 * struct and gives the springpot's arrays a zeroed block, and the flight of a striker
 * that touches at once is a step of length 0, which reads the coefficients
 * of no step length as they are. Both the fixed and the error-controlled
 * springpot, the whole impact. */
static void test_a_start_on_any_memory_runs_as_on_zeros(void)
{
    static contact_model dirty, clean;
    double tolerances[] = {0.0, 1e-8};
    int i;
    for (i = 0; i < 2; i++) {
        memset(&dirty, 0xff, sizeof dirty);
        memset(&clean, 0, sizeof clean);
        start_springpot(&dirty, tolerances[i]);
        start_springpot(&clean, tolerances[i]);
        while (clean.s.impacts == 0 && clean.s.t < 3e-3) {
            contact_advance(&clean, 1e-5);
            contact_advance(&dirty, 1e-5);
        }
        CHECK(clean.s.impacts == 1 && memcmp(&dirty.s, &clean.s, offsetof(contact_state, step)) == 0
                  && memcmp(dirty.modes.phi, clean.modes.phi, clean.modes.modes * sizeof clean.modes.phi[0]) == 0,
              "tolerance %g: a start on 0xff bytes runs as on zeros (F_peak %.17g and %.17g)", tolerances[i],
              dirty.s.F_peak, clean.s.F_peak);
        contact_release(&dirty);
        contact_release(&clean);
    }
}

/* contact_check_params counts a springpot's modes only below
 * CONTACT_MEMORY_FLOOR: at the floor every alpha and memory_tolerance fits
 * CONTACT_MAX_MODES (and a higher floor needs fewer). Checked here over
 * alpha from 0.0005 to 0.9995 and memory_tolerance from 1e-2 to 1e-12,
 * 12 a decade. */
static void test_kernels_above_the_floor_fit(void)
{
    double a[CONTACT_MAX_MODES + 1], b[CONTACT_MAX_MODES + 1], eta;
    size_t most = 0;
    int i, j;
    for (i = 0; i < 1000; i++)
        for (j = 0; j <= 120; j++) {
            const double alpha = (i + 0.5) / 1000.0, tolerance = 1e-2 * pow(10.0, -j / 12.0);
            const size_t n = soe_kernel(alpha, tolerance, CONTACT_MEMORY_FLOOR, CONTACT_MEMORY_SPAN,
                                        CONTACT_MAX_MODES, a, b, &eta);
            most = n > most ? n : most;
        }
    CHECK(most <= CONTACT_MAX_MODES, "at the floor a kernel needs up to %zu modes", most);
}

/* radau_iia.c built for the narrowest vectors (CMakeLists.txt). */
double radau_step_narrow(contact_model *cm, const contact_state *in, double h, double K, contact_state *out);
void radau_advance_modes_narrow(contact_model *cm, const contact_state *trial);

/* The springpot's passes over its modes run in the CPU's widest vectors,
 * chosen at run time, yet sum in fixed lanes: a step and the modes'
 * advance give the same bits as the narrowest build's, at every step of a
 * springpot's impact (here with this CPU's widest: AVX-512, AVX or SSE2), so
 * that a sweep's results do not depend on the machine that ran them. */
static void test_radau_same_bits_at_every_vector_width(void)
{
    static const double alphas[] = {0.2, 0.5, 0.9};
    size_t i;
    for (i = 0; i < sizeof alphas / sizeof alphas[0]; i++) {
        contact_params p;
        contact_model cm, wide, narrow;
        double v0, m;
        int steps = 0, differ = 0;
        contact_default_params(&p);
        contact_default_striker(&v0, &m);
        p.law = CONTACT_LAW_HERTZ;
        p.damper = CONTACT_DAMPER_SPRINGPOT;
        p.damper_order = alphas[i];
        p.tolerance = 1e-8;
        contact_start(&cm, &p, v0, m);
        memset(&wide, 0, sizeof wide);
        memset(&narrow, 0, sizeof narrow);
        CHECK(contact_copy_room(&wide, &cm) == 0 && contact_copy_room(&narrow, &cm) == 0, "room for copies of %zu modes",
              cm.modes.modes);
        contact_advance_until(&cm, 1.0, CONTACT_ONSET);
        while (cm.s.in_contact && steps < 1000) {
            const double K = spring_stiffness(&cm, cm.s.n + 1), h = cm.s.n == 0 ? onset_step(&cm) : cm.s.h_next;
            contact_state wide_trial, narrow_trial;
            double J_wide, J_narrow;
            memset(&wide_trial, 0, sizeof wide_trial);
            memset(&narrow_trial, 0, sizeof narrow_trial);
            J_wide = radau_step(&cm, &cm.s, h, K, &wide_trial);
            J_narrow = radau_step_narrow(&cm, &cm.s, h, K, &narrow_trial);
            differ += memcmp(&wide_trial, &narrow_trial, sizeof wide_trial) != 0 || J_wide != J_narrow;
            contact_copy(&wide, &cm);
            contact_copy(&narrow, &cm);
            radau_advance_modes(&wide, &wide_trial);
            radau_advance_modes_narrow(&narrow, &wide_trial);
            differ += memcmp(wide.modes.phi, narrow.modes.phi, cm.modes.modes * sizeof cm.modes.phi[0]) != 0;
            contact_advance(&cm, h); /* on along the impact */
            steps++;
        }
        CHECK(steps > 10 && differ == 0, "alpha %g: %d of %d steps differ from the narrowest build's", alphas[i],
              differ, steps);
        contact_release_modes(&wide);
        contact_release_modes(&narrow);
        contact_release(&cm);
    }
}

/* Model Exchange (rates.c) takes the closed-form force, the compressed
 * memory and scheme 1, and refuses the rest naming the parameter. */
static void test_model_exchange_takes_the_continuous_methods(void)
{
    contact_params p;
    char msg[512];
    contact_default_params(&p); /* law 1, the G1 history sum */
    CHECK(contact_me_check(&p, msg, sizeof msg) != 0 && strstr(msg, "law = 1") && strstr(msg, "co-simulation"),
          "law 1: %s", msg);
    p.law = CONTACT_LAW_HERTZ;
    CHECK(contact_me_check(&p, msg, sizeof msg) == 0, "law 2 with the dashpot runs");
    p.scheme = CONTACT_SCHEME_CENTRAL;
    CHECK(contact_me_check(&p, msg, sizeof msg) != 0 && strstr(msg, "scheme = 2"), "the central scheme: %s", msg);
    p.scheme = CONTACT_SCHEME_GRADIENT;
    p.damper = CONTACT_DAMPER_SPRINGPOT;
    p.memory = CONTACT_MEMORY_G1;
    CHECK(contact_me_check(&p, msg, sizeof msg) != 0 && strstr(msg, "memory = 1"), "the full memory: %s", msg);
    p.memory = CONTACT_MEMORY_COMPRESSED;
    CHECK(contact_me_check(&p, msg, sizeof msg) == 0, "the compressed springpot runs");
}

/* Model Exchange's rates at states the co-simulation's steps reach in
 * contact: x' - x2' is contact_rates's x1' and v' its v'; the springpot's
 * x2' from its modes is the rate the fixed step ends with (the
 * springpot's force balance at the step's end), to rounding. */
static void test_model_exchange_rates_are_the_cosimulations(void)
{
    int damper;
    for (damper = CONTACT_DAMPER_DASHPOT; damper <= CONTACT_DAMPER_SPRINGPOT; damper++) {
        contact_params p;
        contact_model cm;
        double v0, m, x[CONTACT_ME_STATES], dx[CONTACT_ME_STATES], x1_rate, v_rate, F_rate, x2_rate;
        int step;
        contact_default_params(&p);
        contact_default_striker(&v0, &m);
        p.law = CONTACT_LAW_HERTZ;
        p.damper = damper;
        contact_start(&cm, &p, v0, m);
        for (step = 0; step < 3000; step++)
            contact_advance(&cm, 1e-7); /* into the contact: 0.3 ms, before the peak */
        contact_rates(&cm, &x1_rate, &v_rate, &F_rate);
        x2_rate = contact_damper_rate(&cm);
        contact_me_get_states(&cm, x);
        CHECK(contact_me_set_states(&cm, x) == 0, "damper %d: the states taken", damper);
        contact_me_derivatives(&cm, dx);
        CHECK(cm.s.in_contact && fabs(dx[CONTACT_ME_X] - dx[CONTACT_ME_X2] - x1_rate) <= 1e-12 * fabs(cm.s.v),
              "damper %d: x' - x2' = %.17g, contact_rates' x1' %.17g", damper, dx[CONTACT_ME_X] - dx[CONTACT_ME_X2],
              x1_rate);
        CHECK(fabs(dx[CONTACT_ME_V] - v_rate) <= 1e-13 * fabs(v_rate), "damper %d: v' = %.17g, contact_rates' %.17g",
              damper, dx[CONTACT_ME_V], v_rate);
        CHECK(fabs(dx[CONTACT_ME_X2] - x2_rate) <= 1e-12 * fabs(x2_rate), "damper %d: x2' = %.17g, the step's %.17g",
              damper, dx[CONTACT_ME_X2], x2_rate);
        contact_release(&cm);
    }
}

int main(void)
{
    test_hertz_constant();
    test_spring_stiffness();
    test_momentum_identity();
    test_energy_balance();
    test_second_order();
    test_elastic_limit();
    test_stability();
    test_gap_and_gravity();
    test_step_limit();
    test_springpot_onset_step();
    test_radau_modes_are_the_last_stage();
    test_radau_dense_output_interpolates();
    test_a_copy_steps_as_its_original();
    test_a_start_on_any_memory_runs_as_on_zeros();
    test_radau_same_bits_at_every_vector_width();
    test_kernels_above_the_floor_fit();
    test_model_exchange_takes_the_continuous_methods();
    test_model_exchange_rates_are_the_cosimulations();
    return check_summary("test_contact");
}
