/* fraccontact-solve: the contact model without Modelica or an FMI master.
 * Runs a drop test or a driven scene with the same model code as the FMU
 * (or, with --reference, with GSL's high-accuracy integrator) and prints
 * the impact's figures; --csv writes the time series, --json one object. */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "contact.h"
#include "reference.h"
#include "timing.h"

#define PROGRAM "fraccontact-solve"
#define G_EARTH 9.81

typedef struct {
    contact_params p;
    double v0, m, height, t_end, output_interval, rtol;
    int impacts, repeat;
    const char *csv;
    int json, reference, quiet;
} options;

/* ------------------------------------------------------------ options */

typedef enum { REAL, INTEGER, LAW, SCHEME, SCENE, TEXT, FLAG } option_kind;

typedef struct {
    const char *name;
    option_kind kind;
    size_t offset;
    const char *help;
} option;

#define AT(field) offsetof(options, field)

static const option table[] = {
    {"--height", REAL, AT(height), "drop height h [m]: v0 = sqrt(2 * 9.81 * h) (overrides --v0)"},
    {"--v0", REAL, AT(v0), "impact velocity towards the specimen [m/s] (default 0.626418, the paper's 20 mm); driven scene: the constant indentation rate"},
    {"--m", REAL, AT(m), "striker mass [kg] (default 0.7437); driven scene: 0 = no inertia"},
    {"--k", REAL, AT(p.k), "Hertz constant [N/m^1.5] (default 3.299e8); 0 derives it from --R, --E-i, --nu-i, --E-s, --nu-s"},
    {"--c", REAL, AT(p.c), "dashpot constant [N s/m] (default 6080)"},
    {"--R", REAL, AT(p.R), "striker tip radius [m] (default 6.35e-3)"},
    {"--E-i", REAL, AT(p.E_i), "indenter Young's modulus [Pa] (default 210e9)"},
    {"--nu-i", REAL, AT(p.nu_i), "indenter Poisson ratio (default 0.3)"},
    {"--E-s", REAL, AT(p.E_s), "specimen Young's modulus [Pa] (default 2.64e9)"},
    {"--nu-s", REAL, AT(p.nu_s), "specimen Poisson ratio (default 0.4)"},
    {"--law", LAW, AT(p.law), "spring law: g1 (G1 history sum, default), hertz (closed form), g1x (G1 with Richardson extrapolation)"},
    {"--g1-nodes", INTEGER, AT(p.g1_nodes), "G1 intervals N (default 0: internal steps since contact onset)"},
    {"--dt", REAL, AT(p.dt_max), "internal time step [s] (default 1e-7)"},
    {"--scheme", SCHEME, AT(p.scheme), "time scheme: sdirk2 (implicit, L-stable, second order; default) or central (the paper's explicit central differences)"},
    {"--scene", SCENE, AT(p.scene), "drop (default: a free striker) or driven (constant indentation rate --v0)"},
    {"--g", REAL, AT(p.g), "acceleration of the striker towards the specimen [m/s^2] (default 0; 9.81 for gravity)"},
    {"--gap0", REAL, AT(p.gap0), "gap between striker and specimen at t = 0 [m] (default 0)"},
    {"--t-end", REAL, AT(t_end), "stop at this time if the impacts have not ended [s] (default 1)"},
    {"--impacts", INTEGER, AT(impacts), "stop after this many finished impacts (default 1)"},
    {"--output-interval", REAL, AT(output_interval), "time between rows of --csv [s] (default: every internal step; the reference: 1/64 of the contact time scale)"},
    {"--csv", TEXT, AT(csv), "write the time series to FILE: t, F, x, x1, x2, v, E_diss (SI units)"},
    {"--json", FLAG, AT(json), "print one JSON object instead of the table"},
    {"--reference", FLAG, AT(reference), "solve with GSL's high-accuracy integrator instead of the model's scheme"},
    {"--rtol", REAL, AT(rtol), "relative tolerance of --reference (default 1e-12)"},
    {"--repeat", INTEGER, AT(repeat), "solve this many times and report the median cpu_seconds (default 1; for timing)"},
    {"--quiet", FLAG, AT(quiet), "no progress line on a terminal"},
};
#define N_OPTIONS (sizeof table / sizeof table[0])

static void usage(FILE *out)
{
    size_t i;
    fprintf(out,
            "usage: " PROGRAM " [OPTION VALUE]... [--json] [--reference]\n"
            "Simulates an impact on a Hertz spring in series with a dashpot, the spring force\n"
            "computed by the G1 Grunwald-Letnikov semi-integral (MODEL.md). Defaults: the paper's\n"
            "h20 drop test. Options take a value as '--opt VALUE' or '--opt=VALUE'.\n\n");
    for (i = 0; i < N_OPTIONS; i++)
        fprintf(out, "  %-18s %s\n", table[i].name, table[i].help);
    fprintf(out, "  %-18s %s\n", "--list-options", "print this table as JSON (option, kind, help, choices) and exit");
    fprintf(out, "  %-18s %s\n\n", "--help", "this text");
    fprintf(out,
            "Output (table, or --json keys): F_peak [N], eps, t_contact [s], x_perm [m], E_diss [J],\n"
            "v_end [m/s], x_end [m], x1_end [m] (striker velocity, total and elastic indentation where\n"
            "the solve stopped),\n"
            "steps (internal steps; the reference: right-hand-side evaluations), cpu_seconds (of the\n"
            "solve alone), impacts, separated, t_end [s] (where the solve stopped).\n"
            "Exit status: 0 done, 2 bad options, 1 the solve or an output failed.\n");
}

static const char *const law_words[] = {"g1", "hertz", "g1x", NULL};
static const char *const scheme_words[] = {"sdirk2", "central", NULL};
static const char *const scene_words[] = {"drop", "driven", NULL};

static void print_json_string(const char *text)
{
    putchar('"');
    for (; *text; text++) {
        if (*text == '"' || *text == '\\')
            putchar('\\');
        putchar(*text);
    }
    putchar('"');
}

/* The option table as JSON, for programs that drive the solver (the sweep):
 * one table, never a copy of it. */
static void list_options(void)
{
    static const char *const kinds[] = {"real", "integer", "word", "word", "word", "text", "flag"};
    size_t i;
    printf("[");
    for (i = 0; i < N_OPTIONS; i++) {
        const char *const *words = table[i].kind == LAW      ? law_words
                                   : table[i].kind == SCHEME ? scheme_words
                                   : table[i].kind == SCENE  ? scene_words
                                                             : NULL;
        printf("%s\n {\"option\": ", i ? "," : "");
        print_json_string(table[i].name);
        printf(", \"kind\": \"%s\", \"help\": ", kinds[table[i].kind]);
        print_json_string(table[i].help);
        if (words) {
            int w;
            printf(", \"choices\": [");
            for (w = 0; words[w]; w++)
                printf("%s\"%s\"", w ? ", " : "", words[w]);
            printf("]");
        }
        printf("}");
    }
    printf("\n]\n");
}

static int bad_option(const char *name, const char *value, const char *why)
{
    fprintf(stderr, PROGRAM ": %s '%s': %s (see --help)\n", name, value, why);
    return 2;
}

static int parse_word(const char *value, const char *const words[], int *out)
{
    int i;
    char *end;
    long n = strtol(value, &end, 10);
    for (i = 0; words[i]; i++)
        if (strcmp(value, words[i]) == 0) {
            *out = i + 1;
            return 0;
        }
    if (*value && !*end && n >= 1 && n <= i) {
        *out = (int)n;
        return 0;
    }
    return -1;
}

static int set_option(options *o, const option *opt, const char *value)
{
    char *at = (char *)o + opt->offset, *end;
    switch (opt->kind) {
    case REAL:
        *(double *)at = strtod(value, &end);
        if (!*value || *end)
            return bad_option(opt->name, value, "not a number");
        return 0;
    case INTEGER: {
        long n = strtol(value, &end, 10);
        if (!*value || *end)
            return bad_option(opt->name, value, "not a whole number");
        if (n < -2147483647L || n > 2147483647L)
            return bad_option(opt->name, value, "out of range");
        *(int *)at = (int)n;
        return 0;
    }
    case LAW:
        return parse_word(value, law_words, (int *)at) ? bad_option(opt->name, value, "one of g1, hertz, g1x") : 0;
    case SCHEME:
        return parse_word(value, scheme_words, (int *)at) ? bad_option(opt->name, value, "one of sdirk2, central") : 0;
    case SCENE:
        return parse_word(value, scene_words, (int *)at) ? bad_option(opt->name, value, "one of drop, driven") : 0;
    case TEXT:
        *(const char **)at = value;
        return 0;
    case FLAG:
        *(int *)at = 1;
        return 0;
    }
    return 0;
}

/* Returns 0, 2 for bad options, or -1 after --help. */
static int parse(int argc, char **argv, options *o)
{
    int i;
    size_t k;
    char why[300];
    for (i = 1; i < argc; i++) {
        char name[64];
        const char *value = NULL, *eq = strchr(argv[i], '=');
        const option *opt = NULL;
        if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
            usage(stdout);
            return -1;
        }
        if (strcmp(argv[i], "--list-options") == 0) {
            list_options();
            return -1;
        }
        snprintf(name, sizeof name, "%.*s", eq ? (int)(eq - argv[i]) : (int)strlen(argv[i]), argv[i]);
        for (k = 0; k < N_OPTIONS; k++)
            if (strcmp(name, table[k].name) == 0)
                opt = &table[k];
        if (!opt)
            return bad_option("option", argv[i], "unknown");
        if (opt->kind == FLAG) {
            if (eq)
                return bad_option(name, eq + 1, "takes no value");
        } else if (eq)
            value = eq + 1;
        else if (i + 1 < argc)
            value = argv[++i];
        else
            return bad_option(name, "", "needs a value");
        if (set_option(o, opt, value ? value : "") != 0)
            return 2;
    }
    if (o->height != -1.0) { /* -1: not given */
        if (!(o->height >= 0.0) || !isfinite(o->height))
            return bad_option("--height", "", "must be finite and >= 0");
        o->v0 = sqrt(2.0 * G_EARTH * o->height);
    }
    if (contact_check_params(&o->p, why, sizeof why) != 0
        || contact_check_striker(o->p.scene, o->v0, o->m, why, sizeof why) != 0) {
        fprintf(stderr, PROGRAM ": %s (see --help)\n", why);
        return 2;
    }
    if (!(o->t_end > 0.0) || !isfinite(o->t_end))
        return bad_option("--t-end", "", "must be positive and finite");
    if (o->impacts < 1)
        return bad_option("--impacts", "", "must be >= 1");
    if (!(o->output_interval >= 0.0) || !isfinite(o->output_interval))
        return bad_option("--output-interval", "", "must be >= 0 and finite");
    if (o->repeat < 1 || o->repeat > 100000)
        return bad_option("--repeat", "", "must lie in 1..100000");
    if (!(o->rtol > 0.0 && o->rtol < 1.0))
        return bad_option("--rtol", "", "must lie in (0, 1)");
    return 0;
}

/* ------------------------------------------------------------ results */

typedef struct {
    double t, F, x, x1, x2, v, E_diss;
} row;

typedef struct {
    row *rows;
    size_t n, cap;
    int failed;
} series;

static void keep(void *ctx, double t, double F, double x, double x1, double x2, double v, double E_diss)
{
    series *s = ctx;
    if (s->failed)
        return;
    if (s->n == s->cap) {
        size_t cap = s->cap ? 2 * s->cap : 4096;
        row *grown = realloc(s->rows, cap * sizeof *grown);
        if (!grown) {
            s->failed = 1;
            return;
        }
        s->rows = grown;
        s->cap = cap;
    }
    s->rows[s->n].t = t;
    s->rows[s->n].F = F;
    s->rows[s->n].x = x;
    s->rows[s->n].x1 = x1;
    s->rows[s->n].x2 = x2;
    s->rows[s->n].v = v;
    s->rows[s->n].E_diss = E_diss;
    s->n++;
}

static void keep_state(series *s, const contact_model *cm)
{
    keep(s, cm->s.t, cm->s.F, contact_total_indentation(cm), contact_elastic_indentation(cm), cm->s.x2, cm->s.v,
         cm->s.E_diss);
}

/* Written to FILE.tmp and renamed, so that an interrupted run never leaves a
 * complete-looking file. */
static int write_csv(const char *path, const series *s)
{
    char tmp[4096];
    FILE *f;
    size_t i;
    int ok;
    snprintf(tmp, sizeof tmp, "%s.tmp", path);
    f = fopen(tmp, "w");
    if (!f) {
        fprintf(stderr, PROGRAM ": --csv '%s': cannot write: ", path);
        perror(NULL);
        return -1;
    }
    fprintf(f, "t_s,F_N,x_m,x1_m,x2_m,v_m_per_s,E_diss_J\n");
    for (i = 0; i < s->n; i++) {
        const row *r = &s->rows[i];
        fprintf(f, "%.12g,%.12g,%.12g,%.12g,%.12g,%.12g,%.12g\n", r->t, r->F, r->x, r->x1, r->x2,
                r->v, r->E_diss);
    }
    ok = !ferror(f);
    ok = (fclose(f) == 0) && ok;
    if (!ok || rename(tmp, path) != 0) {
        fprintf(stderr, PROGRAM ": --csv '%s': writing failed: ", path);
        perror(NULL);
        remove(tmp);
        return -1;
    }
    return 0;
}

typedef struct {
    double F_peak, eps, t_contact, x_perm, E_diss, v_end, x_end, x1_end, cpu_seconds, t_end;
    long steps, impacts;
} figures;

static void print_results(const options *o, const figures *f, double k)
{
    static const char *const laws[] = {"", "g1", "hertz", "g1x"};
    static const char *const schemes[] = {"", "sdirk2", "central"};
    const char *method = o->reference ? "reference" : schemes[o->p.scheme];
    if (o->json) {
        printf("{\"F_peak\": %.17g, \"eps\": %.17g, \"t_contact\": %.17g, \"x_perm\": %.17g, "
               "\"E_diss\": %.17g, \"v_end\": %.17g, \"x_end\": %.17g, \"x1_end\": %.17g, "
               "\"steps\": %ld, \"cpu_seconds\": %.9g, "
               "\"impacts\": %ld, \"separated\": %s, \"t_end\": %.17g, \"law\": \"%s\", "
               "\"method\": \"%s\", \"dt\": %.17g, \"k\": %.17g, \"c\": %.17g, \"m\": %.17g, \"v0\": %.17g}\n",
               f->F_peak, f->eps, f->t_contact, f->x_perm, f->E_diss, f->v_end, f->x_end, f->x1_end, f->steps,
               f->cpu_seconds,
               f->impacts, f->impacts > 0 ? "true" : "false", f->t_end, laws[o->p.law], method,
               o->p.dt_max, k, o->p.c, o->m, o->v0);
        return;
    }
    printf("%s, law %s, k = %.6g N/m^1.5, c = %.6g N s/m, m = %.6g kg, v0 = %.6g m/s\n", method,
           laws[o->p.law], k, o->p.c, o->m, o->v0);
    printf("  F_peak     %.10g N\n", f->F_peak);
    printf("  eps        %.10g\n", f->eps);
    printf("  t_contact  %.10g s\n", f->t_contact);
    printf("  x_perm     %.10g m\n", f->x_perm);
    printf("  E_diss     %.10g J\n", f->E_diss);
    printf("  v_end      %.10g m/s\n", f->v_end);
    printf("  impacts    %ld%s (t = %.6g s)\n", f->impacts, f->impacts > 0 ? "" : ", no separation by --t-end",
           f->t_end);
    printf("  steps      %ld\n", f->steps);
    printf("  cpu        %.6g s\n", f->cpu_seconds);
}

/* ------------------------------------------------------------ the solves */

static int solve_model(const options *o, series *out, figures *f)
{
    contact_model cm;
    double chunk = o->output_interval > 0.0 ? o->output_interval : o->p.dt_max, t0;
    int progress = !o->quiet && !o->json && isatty(STDERR_FILENO);
    double shown = cpu_seconds();
    contact_start(&cm, &o->p, o->v0, o->m);
    if (out)
        keep_state(out, &cm);
    t0 = cpu_seconds();
    /* Stop short of t_end by rounding only, not by a sliver of a step. */
    while (cm.s.impacts < o->impacts && cm.s.t < o->t_end - 1e-6 * chunk) {
        double H = fmin(chunk, o->t_end - cm.s.t);
        if (isnan(contact_advance(&cm, H))) {
            fprintf(stderr, PROGRAM ": the state became non-finite near t = %.9g s\n", cm.s.t);
            return -1;
        }
        if (out)
            keep_state(out, &cm);
        if (progress && (cm.s.steps & 0xffff) == 0 && cpu_seconds() - shown > 0.5) {
            shown = cpu_seconds();
            fprintf(stderr, "\r  t = %.6g s of at most %.6g s, %ld steps, %ld of %ld impacts   ", cm.s.t, o->t_end,
                    cm.s.steps, cm.s.impacts, (long)o->impacts);
        }
    }
    if (progress && shown > t0)
        fprintf(stderr, "\n");
    f->cpu_seconds = cpu_seconds() - t0;
    f->F_peak = cm.s.F_peak;
    f->eps = cm.s.eps;
    f->t_contact = cm.s.t_contact;
    f->x_perm = cm.s.x2;
    f->E_diss = cm.s.E_diss;
    f->v_end = cm.s.v;
    f->x_end = contact_total_indentation(&cm);
    f->x1_end = contact_elastic_indentation(&cm);
    f->steps = cm.s.steps;
    f->impacts = cm.s.impacts;
    f->t_end = cm.s.t;
    return 0;
}

static int solve_reference(const options *o, series *out, figures *f)
{
    reference_result r;
    char why[300];
    double t0 = cpu_seconds();
    if (reference_solve(&o->p, o->v0, o->m, o->rtol, o->t_end, o->impacts, o->output_interval, out ? keep : NULL, out, &r,
                        why, sizeof why) != 0) {
        fprintf(stderr, PROGRAM ": %s\n", why);
        return -1;
    }
    f->cpu_seconds = cpu_seconds() - t0;
    f->F_peak = r.F_peak;
    f->eps = r.eps;
    f->t_contact = r.t_contact;
    f->x_perm = r.x_perm;
    f->E_diss = r.E_diss;
    f->v_end = r.v;
    f->x_end = r.x;
    f->x1_end = r.x1;
    f->steps = r.rhs_evaluations;
    f->impacts = r.impacts;
    f->t_end = r.t;
    return 0;
}

/* One solve, or --repeat of them with the median CPU time; the series is
 * kept from the first only. */
static int solve(const options *o, series *out, figures *f)
{
    double *times = malloc((size_t)o->repeat * sizeof *times);
    int i, status = times ? 0 : -1;
    for (i = 0; i < o->repeat && status == 0; i++) {
        status = o->reference ? solve_reference(o, i == 0 ? out : NULL, f) : solve_model(o, i == 0 ? out : NULL, f);
        if (times)
            times[i] = f->cpu_seconds;
    }
    if (status == 0) {
        f->cpu_seconds = median(times, o->repeat);
    }
    free(times);
    return status;
}

int main(int argc, char **argv)
{
    options o;
    figures f;
    series s = {NULL, 0, 0, 0};
    contact_model cm;
    int status;
    memset(&o, 0, sizeof o);
    memset(&f, 0, sizeof f);
    contact_default_params(&o.p);
    o.v0 = 0.626418;
    o.m = 0.7437;
    o.height = -1.0;
    o.t_end = 1.0;
    o.impacts = 1;
    o.repeat = 1;
    o.rtol = 1e-12;
    status = parse(argc, argv, &o);
    if (status != 0)
        return status < 0 ? 0 : status;
    status = solve(&o, o.csv ? &s : NULL, &f);
    if (status == 0 && s.failed) {
        fprintf(stderr, PROGRAM ": out of memory for the --csv series\n");
        status = -1;
    }
    if (status == 0 && o.csv && write_csv(o.csv, &s) != 0)
        status = -1;
    free(s.rows);
    if (status != 0)
        return 1;
    contact_start(&cm, &o.p, o.v0, o.m);
    print_results(&o, &f, cm.k);
    return 0;
}
