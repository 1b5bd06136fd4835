/* The contact model against identities that hold whatever its step:
 * momentum, energy, closed forms, order of convergence, stability. */
#include <float.h>
#include <inttypes.h>
#include <math.h>
#include <stdio.h>

#include "check.h"
#include "contact.h"

static const double V0 = 0.626418, M = 0.7437; /* the paper's h20 drop */

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

/* Any Runge-Kutta method keeps linear invariants, and m v + c x2 is one:
 * x2_end = m v0 (1 + eps) / c holds to rounding, at any step and any c. */
static void test_momentum_identity(void)
{
    static const double cs[] = {608.0, 6080.0, 60800.0, 6.08e6}; /* below ~600 it never rebounds */
    int law, i;
    for (law = 1; law <= 2; law++)
        for (i = 0; i < 4; i++) {
            contact_model cm = drop(law, cs[i], 1e-7, 0.05);
            CHECK(cm.s.impacts == 1, "law %d, c %g: no separation", law, cs[i]);
            CHECK_REL(cm.s.x2, M * V0 * (1.0 + cm.s.eps) / cs[i], 1e-12, "x2_end vs m v0 (1 + eps) / c");
        }
}

/* Law 2 conserves 1/2 m v^2 + (2/5) k x1^(5/2) + E_diss; the scheme's
 * second-order error is ~ (dt / t_c)^2 ~ 1e-8 at dt = 1e-7, t_c = 1.3 ms. */
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
    CHECK(worst < 1e-7 * E0, "energy balance off by %.3g of the impact energy", worst / E0);
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

/* The elastic limit (c -> infinity): Hertz impact, MODEL.md §2. */
static void test_elastic_limit(void)
{
    contact_model cm = drop(CONTACT_LAW_HERTZ, 1e15, 1e-7, 0.05);
    double k = cm.k, x_max = pow(5.0 * M * V0 * V0 / (4.0 * k), 0.4);
    /* Peak sampling and the scheme both err by ~ (dt / t_c)^2 ~ 1e-8. */
    CHECK_REL(cm.s.F_peak, k * pow(x_max, 1.5), 1e-6, "Hertz F_max");
    CHECK_REL(cm.s.t_contact, 2.94327 * x_max / V0, 1e-5, "Hertz contact time (closed form given to 6 digits)");
    CHECK(fabs(cm.s.eps - 1.0) < 1e-6, "eps = %.12f, not 1", cm.s.eps);
}

/* However stiff the dashpot split and however long the step: finite, no
 * tension, the momentum identity to rounding, and, up to the scheme's
 * second-order error bounded by (dt / t_c)^2 with t_c the Hertz contact time
 * (and the energy's rounding, an ulp a step at worst),
 * eps in [0, 1] and no more energy dissipated and left than came in (nearly
 * elastic cases at dt = t_c / 13 overshoot by 1.4e-4 against the 6e-3
 * allowed). */
static void test_stability(void)
{
    static const double cs[] = {1e-2, 1.0, 1e2, 6080.0, 1e6, 1e9};
    static const double dts[] = {1e-9, 1e-7, 1e-5, 1e-4, 1e-3, 1e-1};
    const double t_c = 1.3e-3;
    int law, i, j;
    for (law = 1; law <= 2; law++)
        for (i = 0; i < 6; i++)
            for (j = 0; j < 6; j++) {
                double dt = dts[j], t_end = dt > 1e-4 ? 50 * dt : 2e-3;
                contact_model cm;
                if (dt < 1e-8 && cs[i] < 1.0)
                    continue; /* 2 ms at 1 ns is covered by the stiffer cases; keep the test fast */
                cm = drop(law, cs[i], dt, t_end);
                CHECK(isfinite(cm.s.x1) && isfinite(cm.s.v) && isfinite(cm.s.x2) && isfinite(cm.s.E_diss),
                      "law %d c %g dt %g: non-finite state", law, cs[i], dt);
                CHECK(cm.s.F >= 0.0 && cm.s.F_peak >= 0.0, "law %d c %g dt %g: tension", law, cs[i], dt);
                CHECK(cm.s.eps >= 0.0 && cm.s.eps <= 1.0 + (dt / t_c) * (dt / t_c),
                      "law %d c %g dt %g: eps %.17g", law, cs[i], dt, cm.s.eps);
                CHECK(fabs(M * (V0 - cm.s.v) - cs[i] * cm.s.x2) <= 1e-12 * M * V0,
                      "law %d c %g dt %g: momentum m (v0 - v) = %.17g vs c x2 = %.17g",
                      law, cs[i], dt, M * (V0 - cm.s.v), cs[i] * cm.s.x2);
                CHECK(cm.s.E_diss + 0.5 * M * cm.s.v * cm.s.v
                          <= 0.5 * M * V0 * V0 * (1.0 + (dt / t_c) * (dt / t_c) + DBL_EPSILON * cm.s.steps),
                      "law %d c %g dt %g: E_diss %.17g + kinetic energy exceed the impact energy",
                      law, cs[i], dt, cm.s.E_diss);
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
    CHECK_REL(cm.s.t_onset, (v_on - V0) / g, 1e-12, "onset time");
    CHECK_REL(cm.s.v_onset, v_on, 1e-12, "onset velocity");
    /* It bounces and lands again: repeated impacts under gravity. */
    while (cm.s.impacts < 3 && cm.s.t < 1.0)
        contact_advance(&cm, 1e-5);
    CHECK(cm.s.impacts == 3, "3 impacts by t = %g s, got %" PRId64, cm.s.t, cm.s.impacts);
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
    return check_summary("test_contact");
}
