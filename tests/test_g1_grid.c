/* The full-grid G1 (FFT with a direct head) against the newest-point sum it
 * must reproduce at every point, and against the straight-line closed form. */
#include <math.h>
#include <stdlib.h>

#include "check.h"
#include "g1.h"
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

int main(void)
{
    test_against_literal_sums();
    test_line_pointwise();
    return check_summary("test_g1_grid");
}
