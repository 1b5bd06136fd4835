/* fraccontact-bench: timings for docs/benchmarks.md (scripts/benchmarks.py
 * runs it; not a test). Prints one JSON object.
 *   fraccontact-bench step           ns per internal step of each law, and of
 *                                     the literal O(N) G1 sum per step
 *   fraccontact-bench g1 N ALPHA      the bare G1 history sum of f(x) = x on
 *                                     N intervals of [0, 1]: newest point and
 *                                     full grid, timed and checked at every point
 *   fraccontact-bench batch N LAW DT_MAX
 *                                     the library's own CPU for N h20 impacts in
 *                                     one fc_run_batch call (the C core's cost of
 *                                     what fraccontact.impacts does from Python) */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "contact.h"
#include "fraccontact.h"
#include "g1.h"
#include "g1_grid.h"
#include "timing.h"

/* ns per internal step over the h20 contact: 100 steps per call, as an FMU
 * with a 10 us communication step takes them. */
static double ns_per_step(int law)
{
    double runs[15];
    int r;
    for (r = 0; r < 15; r++) {
        contact_params p;
        contact_model cm;
        double t0, v0, m;
        contact_default_params(&p);
        p.law = law;
        contact_default_striker(&v0, &m);
        contact_start(&cm, &p, v0, m);
        t0 = cpu_seconds();
        while (cm.s.impacts == 0)
            contact_advance(&cm, 100 * p.dt_max);
        runs[r] = (cpu_seconds() - t0) / (double)cm.s.steps * 1e9;
    }
    return median(runs, 15);
}

/* ns for one literal G1 sum over the straight line with N intervals: what a
 * law-1 step would add if it summed instead of using the closed form. */
static double ns_literal_sum(size_t N)
{
    double *w = malloc((N + 1) * sizeof *w), *f = malloc((N + 1) * sizeof *f), runs[9], sink = 0.0;
    size_t i;
    int r, k, reps = (int)(2e6 / (double)N) + 1;
    g1_weights(-0.5, N + 1, w);
    for (i = 0; i <= N; i++)
        f[i] = (double)i / (double)N;
    for (r = 0; r < 9; r++) {
        double t0 = cpu_seconds();
        for (k = 0; k < reps; k++)
            sink += g1_history_sum(-0.5, w, f, N + 1, 1.0 / (double)N);
        runs[r] = (cpu_seconds() - t0) / reps * 1e9;
    }
    free(w);
    free(f);
    return sink > 0.0 ? median(runs, 9) : -1.0;
}

static int bench_step(void)
{
    static const size_t Ns[] = {100, 1000, 10000, 13160};
    size_t i;
    printf("{\"ns_per_step\": {\"g1\": %.2f, \"hertz\": %.2f, \"g1x\": %.2f}, \"ns_literal_sum\": {",
           ns_per_step(CONTACT_LAW_G1), ns_per_step(CONTACT_LAW_HERTZ), ns_per_step(CONTACT_LAW_G1_EXTRAPOLATED));
    for (i = 0; i < sizeof Ns / sizeof Ns[0]; i++)
        printf("%s\"%lu\": %.1f", i ? ", " : "", (unsigned long)Ns[i], ns_literal_sum(Ns[i]));
    printf("}}\n");
    return 0;
}

/* The G1 value of D^alpha x at grid point n (MODEL.md §4 closed form), and
 * the magnitude of the terms it sums (for f >= 0 all weights share a sign
 * when alpha < 0; for 0 < alpha < 1 all but w_0 are negative). */
static double line_value(double alpha, size_t n, double delta)
{
    return n == 0 ? 0.0 : g1_line_ratio(alpha, (double)n) * pow((double)n * delta, 1.0 - alpha) / tgamma(2.0 - alpha);
}

static double terms_magnitude(double alpha, size_t n, double delta, double value)
{
    return alpha > 0.0 ? 2.0 * (double)n * delta * pow(delta, -alpha) - value : value;
}

static int bench_g1(size_t N, double alpha)
{
    double *w = malloc((N + 1) * sizeof *w), *f = malloc((N + 1) * sizeof *f), *out = malloc((N + 1) * sizeof *out);
    double delta = 1.0 / (double)N, newest = 0.0, t_newest[9], t_full[5], worst = 0.0, newest_error;
    /* Relative to a point's own value the FFT errs like eps (N/n)^1.5 here:
     * summing the first N/128 points directly keeps every point within 1e-12. */
    size_t i, worst_at = 0, head = N / 128 > 256 ? N / 128 : 256;
    int r, k, reps = (int)(2e6 / (double)N) + 1;
    if (!w || !f || !out)
        return 1;
    for (i = 0; i <= N; i++)
        f[i] = (double)i * delta;
    for (r = 0; r < 9; r++) {
        double t0 = cpu_seconds();
        for (k = 0; k < reps; k++) {
            g1_weights(alpha, N + 1, w); /* the weights are part of the work, as in any caller */
            newest = g1_history_sum(alpha, w, f, N + 1, delta);
        }
        t_newest[r] = (cpu_seconds() - t0) / reps;
    }
    for (r = 0; r < 5; r++) {
        double t0 = cpu_seconds();
        if (g1_full_grid(alpha, f, N + 1, delta, head, out) != 0)
            return 1;
        t_full[r] = cpu_seconds() - t0;
    }
    for (i = 1; i <= N; i++) {
        double value = line_value(alpha, i, delta);
        double e = fabs(out[i] - value) / terms_magnitude(alpha, i, delta, value);
        if (e > worst) {
            worst = e;
            worst_at = i;
        }
    }
    newest_error = fabs(newest - line_value(alpha, N, delta)) / terms_magnitude(alpha, N, delta, line_value(alpha, N, delta));
    printf("{\"N\": %lu, \"alpha\": %g, \"newest_seconds\": %.6g, \"full_seconds\": %.6g, \"newest_error\": %.3g, "
           "\"full_max_error\": %.3g, \"full_worst_point\": %lu, \"head\": %lu}\n",
           (unsigned long)N, alpha, median(t_newest, 9), median(t_full, 5), newest_error, worst,
           (unsigned long)worst_at, (unsigned long)head);
    free(w);
    free(f);
    free(out);
    return 0;
}

/* CPU per impact of N h20 impacts (dashpots spread over 4000..8000 N s/m,
 * as a sweep would) in one batch call: the median of 5. */
static int bench_batch(size_t N, int law, double dt_max)
{
    fc_params *p = malloc(N * sizeof *p);
    fc_outcome *out = malloc(N * sizeof *out);
    double runs[5];
    size_t i;
    int r;
    if (!p || !out)
        return 1;
    for (i = 0; i < N; i++) {
        fc_params_default(&p[i]);
        p[i].law = law;
        p[i].dt_max = dt_max;
        p[i].c = 4000.0 + 4000.0 * (double)i / (double)N;
    }
    for (r = 0; r < 5; r++) {
        double t0 = cpu_seconds();
        if (fc_run_batch(N, p, out) != FC_OK)
            return 1;
        runs[r] = (cpu_seconds() - t0) / (double)N;
    }
    printf("{\"N\": %lu, \"law\": %d, \"dt_max\": %g, \"seconds_per_impact\": %.6g, \"F_peak_first\": %.17g}\n",
           (unsigned long)N, law, dt_max, median(runs, 5), out[0].first.F_peak);
    free(p);
    free(out);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc == 5 && strcmp(argv[1], "batch") == 0 && atol(argv[2]) > 0)
        return bench_batch((size_t)atol(argv[2]), atoi(argv[3]), atof(argv[4]));
    if (argc == 2 && strcmp(argv[1], "step") == 0)
        return bench_step();
    if (argc == 4 && strcmp(argv[1], "g1") == 0 && atol(argv[2]) > 0)
        return bench_g1((size_t)atol(argv[2]), atof(argv[3]));
    fprintf(stderr, "usage: fraccontact-bench step | g1 N ALPHA | batch N LAW DT_MAX\n");
    return 2;
}
