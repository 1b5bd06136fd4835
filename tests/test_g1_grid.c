/* The full-grid G1 (FFT with a direct head) against the newest-point sum it
 * must reproduce at every point, against the straight-line closed form, and
 * against closed forms of powers and exponentials at every point (the
 * predicted error terms, and the slower convergence near the start). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "check.h"
#include "g1.h"
#include "g1_cases.h"
#include "g1_grid.h"

/* Every point of a smooth, sign-changing history against the literal O(n)
 * sum, for an integral and a derivative: the FFT errs by a few ulp of the
 * largest terms, so the check is relative to those (1e-12 of max |out|). */
static void test_against_literal_sums(void)
{
    static const double alphas[] = {-0.5, 0.5, -1.0};
    const size_t n = 3001;
    double *f = malloc(n * sizeof *f), *w = malloc(n * sizeof *w), *out = malloc(n * sizeof *out);
    size_t a, i;
    for (i = 0; i < n; i++)
        f[i] = sin(7.0 * (double)i / (double)n) + 0.3 * cos(23.0 * (double)i / (double)n);
    for (a = 0; a < 3; a++) {
        double worst = 0.0, largest = 0.0;
        CHECK(g1_full_grid(alphas[a], f, n, 1e-3, 100, out) == 0, "allocation");
        g1_weights(alphas[a], n, w);
        for (i = 0; i < n; i++)
            largest = fmax(largest, fabs(out[i]));
        for (i = 0; i < n; i++)
            worst = fmax(worst, fabs(out[i] - g1_history_sum(alphas[a], w, f, i + 1, 1e-3)));
        CHECK(worst <= 1e-12 * largest, "alpha %g: worst difference %.3g of the largest value %.3g",
              alphas[a], worst, largest);
    }
    free(f);
    free(w);
    free(out);
}

/* The line on 1e5 intervals: every point within 1e-12 of its own closed-form
 * value, the direct head taking the points whose values are too small for
 * the FFT's absolute error. */
static void test_line_pointwise(void)
{
    const size_t N = 100000;
    double *f = malloc((N + 1) * sizeof *f), *out = malloc((N + 1) * sizeof *out), delta = 1.0 / (double)N, worst = 0.0;
    size_t i;
    for (i = 0; i <= N; i++)
        f[i] = (double)i * delta;
    CHECK(g1_full_grid(-0.5, f, N + 1, delta, N / 128, out) == 0, "allocation");
    for (i = 1; i <= N; i++) {
        double exact = g1_line_ratio(-0.5, (double)i) * pow((double)i * delta, 1.5) / tgamma(2.5);
        worst = fmax(worst, fabs(out[i] / exact - 1.0));
    }
    CHECK(worst <= 1e-12, "worst relative error %.3g", worst);
    free(f);
    free(out);
}

/* The full grid against the closed forms at t = 1/4, 1/2 and 1 (grid
 * points N/4, N/2, N of N = 400 ... 25600 intervals; the FFT computes all
 * three): the same order and two-term error prediction as the literal sum
 * in test_g1.c, with the same tolerances (order within 0.05; the rest after
 * C1 h + Cb h^(p+1) below 2 K h^2, K measured at N = 400; rounding: the
 * FFT's 1e-12 of the largest value, see test_against_literal_sums). */
static void test_closed_forms_pointwise(void)
{
    static const double ts[] = {0.25, 0.5, 1.0};
    g1_case cases[21];
    size_t n_cases = g1_cases(cases), k, j, n, i;
    const size_t n0 = 400, n_max = 25600;
    double *f = malloc((n_max + 1) * sizeof *f), *out = malloc((n_max + 1) * sizeof *out);
    for (k = 0; k < n_cases; k++) {
        const g1_case *c = &cases[k];
        double previous[3] = {0, 0, 0}, K[3] = {0, 0, 0};
        char name[64];
        g1_case_name(c, name, sizeof name);
        for (n = n0; n <= n_max; n *= 2) {
            double h = 1.0 / (double)n, largest = 0.0;
            for (i = 0; i <= n; i++)
                f[i] = g1_case_f(c, (double)i * h);
            CHECK(g1_full_grid(c->alpha, f, n + 1, h, n / 128, out) == 0, "allocation");
            for (i = 0; i <= n; i++)
                largest = fmax(largest, fabs(out[i]));
            for (j = 0; j < 3; j++) {
                double t = ts[j], c1 = g1_case_c1(c, t), cb = g1_case_cb(c, t);
                double expected = c1 != 0.0 ? 1.0 : c->p + 1.0;
                double err = out[(size_t)(t * (double)n)] - g1_case_exact(c, t);
                double rest = err - c1 * h - cb * pow(h, c->p + 1.0);
                if (n == n0) {
                    K[j] = fabs(rest) / (h * h);
                } else {
                    double order = log2(fabs(previous[j] / err));
                    CHECK(fabs(order - expected) <= 0.05, "grid, %s at t = %g, N %lu: order %.4f, expected %g",
                          name, t, (unsigned long)n, order, expected);
                    CHECK(fabs(rest) <= 2.0 * K[j] * h * h + 1e-12 * largest,
                          "grid, %s at t = %g, N %lu: error %.6g, rest %.3g above 2 K h^2 = %.3g", name, t,
                          (unsigned long)n, err, rest, 2.0 * K[j] * h * h);
                }
                previous[j] = err;
            }
        }
    }
    free(f);
    free(out);
}

/* Near the start G1 converges more slowly. At grid point n the error of
 * t^p is h^(p-alpha) times a function of n alone (the sum is self-similar),
 * so it never shrinks at a fixed index: the largest error over the grid
 * falls like h^min(1, p - alpha). Where p - alpha < 1 it sits at the first
 * point, h^(p-alpha) |1 - Gamma(p+1)/Gamma(p+1-alpha)| (p > 0); p - alpha =
 * 1/2 converges at order 1/2 (t^0 and t^1 under alpha = -1/2 and 1/2), t^(1/2)
 * under D^(1/2) not at all (order 0, 0.114 at t = h), and t^0 under D^(1/2),
 * whose exact value t^(-1/2)/sqrt(pi) is unbounded, diverges at order -1/2.
 * Measured: these orders to 1e-4, and 0.99 ... 1.00 where min = 1 (the
 * h^(p+1) term of p = 1/2); asserted within 0.05. */
static void test_largest_error_near_the_start(void)
{
    g1_case cases[21];
    size_t n_cases = g1_cases(cases), k, n, i;
    const size_t n_max = 25600;
    double *f = malloc((n_max + 1) * sizeof *f), *out = malloc((n_max + 1) * sizeof *out);
    for (k = 0; k < n_cases; k++) {
        const g1_case *c = &cases[k];
        double expected = fmin(1.0, c->p - c->alpha), previous = 0.0;
        char name[64];
        if (c->a > 0.0)
            continue; /* smooth, f(0) = 1: as t^0 */
        g1_case_name(c, name, sizeof name);
        for (n = 400; n <= n_max; n *= 2) {
            double h = 1.0 / (double)n, worst = 0.0;
            for (i = 0; i <= n; i++)
                f[i] = g1_case_f(c, (double)i * h);
            CHECK(g1_full_grid(c->alpha, f, n + 1, h, n / 128, out) == 0, "allocation");
            for (i = 1; i <= n; i++)
                worst = fmax(worst, fabs(out[i] - g1_case_exact(c, (double)i * h)));
            if (n > 400) {
                double order = log2(previous / worst);
                CHECK(fabs(order - expected) <= 0.05, "grid, %s: largest error %.4g at N %lu, order %.4f, expected %g",
                      name, worst, (unsigned long)n, order, expected);
            }
            previous = worst;
        }
    }
    free(f);
    free(out);
}

int main(void)
{
    test_against_literal_sums();
    test_line_pointwise();
    test_closed_forms_pointwise();
    test_largest_error_near_the_start();
    return check_summary("test_g1_grid");
}
