/* fraccontact-bench: timings for docs/benchmarks.md
 * (reports/benchmarks.py runs it; not a test). Prints one JSON object.
 *   fraccontact-bench step           ns per internal step of each law, and of
 *                                     the literal O(N) G1 sum per step
 *   fraccontact-bench g1 N ALPHA      the bare G1 history sum of f(x) = x on
 *                                     N intervals of [0, 1]: newest point and
 *                                     full grid, timed and checked at every point
 *   fraccontact-bench batch N LAW DT_MAX
 *                                     the library's own CPU for N h20 impacts in
 *                                     one fc_run_batch call (the C core's cost of
 *                                     what fraccontact.impacts does from Python)
 *   fraccontact-bench springpot [LARGEST_N]
 *                                     ns per internal step over the h20 impact of
 *                                     the dashpot and the springpot's compressed
 *                                     memory (runs alternated), and of its full
 *                                     G1 history; then a
 *                                     springpot impact by both memories on N =
 *                                     1e3, 1e4, ... LARGEST_N (default 1e6)
 *                                     steps of one span: CPU, F_peak, eps, the
 *                                     memory's values and the history's heap
 *   fraccontact-bench controlled TOLERANCE
 *                                     the error-controlled h20 impact (law 2)
 *                                     of the dashpot and of the springpot's
 *                                     compressed memory side by side: CPU per
 *                                     impact (batches alternated, medians),
 *                                     steps and the impact's figures
 *   fraccontact-bench anchor K C M V T_END RTOL [REPEATS]
 *                                     the speed anchor (anchor.h):
 *                                     one impact by GSL's rk8pd as a user would
 *                                     script it, its figures, right-hand sides,
 *                                     steps and CPU per impact (median of
 *                                     REPEATS runs; default as many as fit in
 *                                     2 s, at most 2001) */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "anchor.h"
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
            contact_advance(&cm, 100 * contact_step_limit(&p));
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

/* The G1 value of D^alpha x at grid point n (docs/model.md §4 closed form), and
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
        p[i].model.law = law;
        p[i].model.dt_max = dt_max;
        p[i].model.c = 4000.0 + 4000.0 * (double)i / (double)N;
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

/* ------------------------------------------------------------ springpot */

/* The springpot of the benchmarks: alpha 0.5, c_alpha 3e5 (the
 * defaults: as damping as the h20 dashpot at the impact's frequency). */
static void springpot_params(contact_params *p, int memory, double dt_max)
{
    contact_default_params(p);
    p->damper = CONTACT_DAMPER_SPRINGPOT;
    p->damper_order = 0.5;
    p->c_alpha = 3e5;
    p->memory = memory;
    p->dt_max = dt_max;
}

typedef struct {
    double seconds;        /* CPU of the run */
    int64_t steps;         /* internal steps taken */
    int64_t impacts;
    double F_peak, eps, t;
    size_t memory_values;  /* contact_memory_count at the end: the FMU state's share */
    size_t history_bytes;  /* the full history's heap (x2 and weights) */
    size_t modes;          /* the compressed memory's M */
} impact_run;

/* One h20 impact from t = 0 in calls of 100 internal steps (of dt_max, or the
 * default step where dt_max is 0), as an
 * FMU takes them: until the first impact ends (span 0), or over exactly
 * `span` (a whole number of calls). 0, or -1 when a call fails. */
static int run_impact(const contact_params *p, double span, impact_run *out)
{
    contact_model cm;
    double v0, m, H = 100.0 * contact_step_limit(p), t0;
    long calls = span > 0.0 ? lround(span / H) : 0, i;
    char why[512];
    int failed = 0;
    contact_default_striker(&v0, &m);
    if (contact_start(&cm, p, v0, m) != 0) {
        fprintf(stderr, "fraccontact-bench: no memory for the springpot's modes\n");
        contact_release(&cm);
        return -1;
    }
    if (contact_check_advance(&cm, span > 0.0 ? calls * H : H, why, sizeof why) != 0) {
        fprintf(stderr, "fraccontact-bench: %s\n", why);
        contact_release(&cm);
        return -1;
    }
    t0 = cpu_seconds();
    if (span > 0.0) {
        for (i = 0; i < calls && !failed; i++)
            failed = isnan(contact_advance(&cm, H));
    } else {
        while (cm.s.impacts == 0 && !failed)
            failed = isnan(contact_advance(&cm, H));
    }
    out->seconds = cpu_seconds() - t0;
    out->steps = cm.s.steps;
    out->impacts = cm.s.impacts;
    out->F_peak = cm.s.F_peak;
    out->eps = cm.s.eps;
    out->t = cm.s.t;
    out->memory_values = contact_memory_count(&cm);
    out->history_bytes = cm.history.capacity * 2 * sizeof(double);
    out->modes = cm.modes.modes;
    contact_release(&cm);
    if (failed)
        fprintf(stderr, "fraccontact-bench: the model failed at t = %g s\n", cm.s.t);
    return failed ? -1 : 0;
}

/* The median over repeats of ns per step and of the run's seconds: as many
 * repeats as fit in about `budget` seconds (at least 3, at most `most`), a
 * single run when the first takes over a minute. *repeats says how many. */
static int timed_impacts(const contact_params *p, double span, double budget, int most, impact_run *out,
                         double *ns, int *repeats)
{
    double per_step[15], seconds[15];
    int r, n;
    if (run_impact(p, span, out) != 0)
        return -1;
    n = out->seconds > 60.0 ? 1 : (int)fmin((double)most, fmax(3.0, ceil(budget / fmax(out->seconds, 1e-9))));
    for (r = 0; r < n; r++) {
        if (r > 0 && run_impact(p, span, out) != 0)
            return -1;
        per_step[r] = out->seconds / (double)out->steps * 1e9;
        seconds[r] = out->seconds;
    }
    *ns = median(per_step, n);
    out->seconds = median(seconds, n);
    *repeats = n;
    return 0;
}

static void print_run(const char *name, const impact_run *r, double ns, int repeats)
{
    printf("\"%s\": {\"ns_per_step\": %.2f, \"seconds\": %.6g, \"repeats\": %d, \"steps\": %lld, \"impacts\": %lld, "
           "\"F_peak\": %.17g, \"eps\": %.17g, \"t\": %.17g, \"memory_values\": %lu, \"history_bytes\": %lu, "
           "\"modes\": %lu}",
           name, ns, r->seconds, repeats, (long long)r->steps, (long long)r->impacts, r->F_peak, r->eps, r->t,
           (unsigned long)r->memory_values, (unsigned long)r->history_bytes, (unsigned long)r->modes);
}

/* The span of the ladder: the springpot's h20 impact lasts 1.42 ms. */
#define SPRINGPOT_SPAN 1.5e-3

/* The h20 impact's ns per step of the dashpot and the compressed memory:
 * ROUNDS rounds alternating them, REPEATS runs each a round (a run is a few
 * ms: alternating spreads both over the same second, so that a burst of
 * other work slows both alike), the median of all. */
#define H20_ROUNDS 5
#define H20_REPEATS 21

static int h20_side_by_side(impact_run *dash, double *ns_dash, impact_run *comp, double *ns_comp)
{
    contact_params pd, pc;
    double per_dash[H20_ROUNDS * H20_REPEATS], per_comp[H20_ROUNDS * H20_REPEATS];
    double sec_dash[H20_ROUNDS * H20_REPEATS], sec_comp[H20_ROUNDS * H20_REPEATS];
    int r, k, n = 0;
    contact_default_params(&pd);
    springpot_params(&pc, CONTACT_MEMORY_COMPRESSED, 1e-7);
    for (r = 0; r < H20_ROUNDS; r++)
        for (k = 0; k < H20_REPEATS; k++, n++) {
            if (run_impact(&pd, 0.0, dash) != 0 || run_impact(&pc, 0.0, comp) != 0)
                return -1;
            per_dash[n] = dash->seconds / (double)dash->steps * 1e9;
            sec_dash[n] = dash->seconds;
            per_comp[n] = comp->seconds / (double)comp->steps * 1e9;
            sec_comp[n] = comp->seconds;
        }
    *ns_dash = median(per_dash, n);
    dash->seconds = median(sec_dash, n);
    *ns_comp = median(per_comp, n);
    comp->seconds = median(sec_comp, n);
    return 0;
}

static int bench_springpot(double largest)
{
    contact_params p;
    impact_run r, comp;
    double ns, ns_comp, N;
    int repeats, first = 1;
    printf("{\"sizeof_contact_model\": %lu, \"h20\": {\"dt_max\": %g, ", (unsigned long)sizeof(contact_model), 1e-7);
    if (h20_side_by_side(&r, &ns, &comp, &ns_comp) != 0)
        return 1;
    print_run("dashpot", &r, ns, H20_ROUNDS * H20_REPEATS);
    printf(", ");
    print_run("compressed", &comp, ns_comp, H20_ROUNDS * H20_REPEATS);
    springpot_params(&p, CONTACT_MEMORY_G1, 1e-7);
    if (timed_impacts(&p, 0.0, 1.0, 9, &r, &ns, &repeats) != 0)
        return 1;
    printf(", ");
    print_run("full", &r, ns, repeats);
    printf("}, \"span\": %g, \"ladder\": [", SPRINGPOT_SPAN);
    fflush(stdout);
    for (N = 1e3; N <= largest * (1.0 + 1e-9); N *= 10.0) {
        double dt = SPRINGPOT_SPAN / N;
        printf("%s{\"N\": %.0f, \"dt_max\": %.17g, ", first ? "" : ", ", N, dt);
        first = 0;
        springpot_params(&p, CONTACT_MEMORY_COMPRESSED, dt);
        if (timed_impacts(&p, SPRINGPOT_SPAN, 2.0, 15, &r, &ns, &repeats) != 0)
            return 1;
        print_run("compressed", &r, ns, repeats);
        printf(", ");
        springpot_params(&p, CONTACT_MEMORY_G1, dt);
        if (timed_impacts(&p, SPRINGPOT_SPAN, 2.0, 9, &r, &ns, &repeats) != 0)
            return 1;
        print_run("full", &r, ns, repeats);
        printf("}");
        fflush(stdout);
    }
    printf("]}\n");
    return 0;
}

/* ------------------------------------------------ error-controlled h20 */

/* Batches of this many impacts, alternated between the two dampers for
 * this many rounds: a batch takes a few ms, so that a burst of other work
 * slows both alike. */
#define CONTROLLED_BATCH 50
#define CONTROLLED_ROUNDS 41

static void controlled_params(fc_params *p, int damper, double tolerance)
{
    fc_params_default(p);
    p->model.law = CONTACT_LAW_HERTZ;
    p->model.tolerance = tolerance;
    p->model.damper = damper;
}

static void print_controlled(const char *name, const fc_outcome *o, double seconds)
{
    printf("\"%s\": {\"seconds_per_impact\": %.6g, \"steps\": %lld, \"F_peak\": %.17g, \"eps\": %.17g, "
           "\"t_contact\": %.17g, \"x2_end\": %.17g, \"E_diss\": %.17g}",
           name, seconds, (long long)o->steps, o->first.F_peak, o->first.eps, o->first.t_contact, o->first.x2_end,
           o->first.E_diss);
}

static int bench_controlled(double tolerance)
{
    fc_params p[2][CONTROLLED_BATCH];
    fc_outcome out[2][CONTROLLED_BATCH];
    double runs[2][CONTROLLED_ROUNDS];
    int r, d, i;
    for (d = 0; d < 2; d++)
        for (i = 0; i < CONTROLLED_BATCH; i++)
            controlled_params(&p[d][i], d == 0 ? CONTACT_DAMPER_DASHPOT : CONTACT_DAMPER_SPRINGPOT, tolerance);
    for (r = 0; r < CONTROLLED_ROUNDS; r++)
        for (d = 0; d < 2; d++) {
            double t0 = cpu_seconds();
            if (fc_run_batch(CONTROLLED_BATCH, p[d], out[d]) != FC_OK)
                return 1;
            runs[d][r] = (cpu_seconds() - t0) / CONTROLLED_BATCH;
        }
    printf("{\"tolerance\": %g, \"batch\": %d, \"rounds\": %d, ", tolerance, CONTROLLED_BATCH, CONTROLLED_ROUNDS);
    print_controlled("dashpot", &out[0][0], median(runs[0], CONTROLLED_ROUNDS));
    printf(", ");
    print_controlled("springpot", &out[1][0], median(runs[1], CONTROLLED_ROUNDS));
    printf("}\n");
    return 0;
}

/* ------------------------------------------------------------ anchor */

/* A figure, or null when the run did not get there. */
static void print_figure(const char *name, int known, double value)
{
    if (known)
        printf("\"%s\": %.17g, ", name, value);
    else
        printf("\"%s\": null, ", name);
}

static int bench_anchor(const anchor_problem *p, int repeats)
{
    anchor_result r, again;
    double *runs, t0;
    int i;
    t0 = cpu_seconds();
    if (anchor_impact(p, &r) != 0) {
        fprintf(stderr, "fraccontact-bench: GSL failed at t = %g s\n", r.t);
        return 1;
    }
    if (repeats <= 0)
        repeats = (int)fmin(2001.0, fmax(1.0, floor(2.0 / fmax(cpu_seconds() - t0, 1e-9))));
    runs = malloc((size_t)repeats * sizeof *runs);
    if (!runs)
        return 1;
    for (i = 0; i < repeats; i++) {
        t0 = cpu_seconds();
        anchor_impact(p, &again);
        runs[i] = cpu_seconds() - t0;
        if (again.F_peak != r.F_peak || again.t != r.t || again.v != r.v || again.x2 != r.x2 ||
            again.evaluations != r.evaluations) {
            fprintf(stderr, "fraccontact-bench: run %d of the anchor differs from the first\n", i);
            free(runs);
            return 1;
        }
    }
    printf("{\"k\": %.17g, \"c\": %.17g, \"m\": %.17g, \"v\": %.17g, \"t_end\": %.17g, \"rtol\": %.17g, "
           "\"separated\": %s, \"F_peak\": %.17g, ",
           p->k, p->c, p->m, p->v0, p->t_end, p->rtol, r.separated ? "true" : "false", r.F_peak);
    print_figure("eps", r.separated, r.eps);
    print_figure("t_contact", r.separated, r.t_contact);
    print_figure("x2_end", r.separated, r.x2_end);
    printf("\"end\": {\"t\": %.17g, \"x1\": %.17g, \"x2\": %.17g, \"v\": %.17g, \"F\": %.17g}, "
           "\"rhs_evaluations\": %ld, \"steps\": %ld, \"rejected_steps\": %ld, \"us_per_impact\": %.4g, "
           "\"repeats\": %d}\n",
           r.t, r.x1, r.x2, r.v, r.F, r.evaluations, r.steps, r.rejected, median(runs, repeats) * 1e6, repeats);
    free(runs);
    return 0;
}

/* The anchor's arguments K C M V T_END RTOL, all positive; 0 when they are. */
static int anchor_arguments(char **argv, anchor_problem *p)
{
    double *fields[6];
    int i;
    fields[0] = &p->k;
    fields[1] = &p->c;
    fields[2] = &p->m;
    fields[3] = &p->v0;
    fields[4] = &p->t_end;
    fields[5] = &p->rtol;
    for (i = 0; i < 6; i++) {
        char *end;
        *fields[i] = strtod(argv[i], &end);
        if (end == argv[i] || *end != '\0' || !(*fields[i] > 0.0) || !isfinite(*fields[i])) {
            fprintf(stderr, "fraccontact-bench anchor: '%s' is not a positive number\n", argv[i]);
            return -1;
        }
    }
    return 0;
}

int main(int argc, char **argv)
{
    anchor_problem anchor;
    if (argc == 5 && strcmp(argv[1], "batch") == 0 && atol(argv[2]) > 0)
        return bench_batch((size_t)atol(argv[2]), atoi(argv[3]), atof(argv[4]));
    if (argc == 2 && strcmp(argv[1], "step") == 0)
        return bench_step();
    if (argc == 4 && strcmp(argv[1], "g1") == 0 && atol(argv[2]) > 0)
        return bench_g1((size_t)atol(argv[2]), atof(argv[3]));
    if ((argc == 2 || (argc == 3 && atof(argv[2]) >= 1e3)) && strcmp(argv[1], "springpot") == 0)
        return bench_springpot(argc == 3 ? atof(argv[2]) : 1e6);
    if (argc == 3 && strcmp(argv[1], "controlled") == 0 && atof(argv[2]) > 0.0)
        return bench_controlled(atof(argv[2]));
    if ((argc == 8 || argc == 9) && strcmp(argv[1], "anchor") == 0)
        return anchor_arguments(argv + 2, &anchor) != 0 ? 2 : bench_anchor(&anchor, argc == 9 ? atoi(argv[8]) : 0);
    fprintf(stderr, "usage: fraccontact-bench step | g1 N ALPHA | batch N LAW DT_MAX | springpot [LARGEST_N] | "
                    "controlled TOLERANCE | anchor K C M V T_END RTOL [REPEATS]\n");
    return 2;
}
