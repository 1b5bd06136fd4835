/* fraccontact-solve: the contact model without Modelica or an FMI master.
 * Runs a drop test or a driven scene with the same model code as the FMU
 * (or, with --reference, with GSL's high-accuracy integrator) and prints
 * the impact's figures; --csv writes the time series, --json one object. */
#define _POSIX_C_SOURCE 200809L

#include <inttypes.h>
#include <math.h>
#include <signal.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "fraccontact.h"
#include "reference.h"
#include "run.h"
#include "timing.h"

#define PROGRAM "fraccontact-solve"
#define N_OPTIONS_MAX 32

typedef struct {
    fc_params p;
    double height, output_interval, rtol;
    int repeat;
    const char *csv;
    int json, reference, quiet;
    const char *typed[N_OPTIONS_MAX]; /* each option's value as typed (NULL: not given) */
} options;

/* ------------------------------------------------------------ options */

typedef enum { REAL, INTEGER, LAW, SCHEME, SCENE, TEXT, FLAG } option_kind;

/* A rule an option's value must follow: NULL when it does, else the rule. */
typedef const char *(*option_rule)(const void *value);

typedef struct {
    const char *name;
    option_kind kind;
    size_t offset;
    const char *help;
    const char *variable; /* the model's name for it, as in its messages */
    option_rule rule;     /* for the solver's own options (the model checks its own) */
} option;

#define AT(field) offsetof(options, field)

static const char *finite_nonnegative(const void *value)
{
    double x = *(const double *)value;
    return isfinite(x) && x >= 0.0 ? NULL : "must be finite and >= 0";
}

static const char *between_0_and_1(const void *value)
{
    double x = *(const double *)value;
    return x > 0.0 && x < 1.0 ? NULL : "must lie in (0, 1)";
}

static const char *repeat_count(const void *value)
{
    int n = *(const int *)value;
    return n >= 1 && n <= 100000 ? NULL : "must lie in 1..100000";
}

static const option table[] = {
    {"--height", REAL, AT(height), "drop height h [m]: v0 = sqrt(2 * 9.81 * h) (overrides --v0)", NULL,
     finite_nonnegative},
    {"--v0", REAL, AT(p.v), "impact velocity towards the specimen [m/s] (default 0.626418, the paper's 20 mm); driven scene: the constant indentation rate", "v", NULL},
    {"--m", REAL, AT(p.m), "striker mass [kg] (default 0.7437); driven scene: 0 = no inertia", "m", NULL},
    {"--k", REAL, AT(p.k), "Hertz constant [N/m^1.5] (default 3.299e8); 0 derives it from --R, --E-i, --nu-i, --E-s, --nu-s; a k other than 0 wins over them (a warning says so when one of them is set)", "k", NULL},
    {"--c", REAL, AT(p.c), "dashpot constant [N s/m] (default 6080)", "c", NULL},
    {"--R", REAL, AT(p.R), "striker tip radius [m] (default 6.35e-3; used only with --k 0)", "R", NULL},
    {"--E-i", REAL, AT(p.E_i), "indenter Young's modulus [Pa] (default 210e9; used only with --k 0)", "E_i", NULL},
    {"--nu-i", REAL, AT(p.nu_i), "indenter Poisson ratio (default 0.3; used only with --k 0)", "nu_i", NULL},
    {"--E-s", REAL, AT(p.E_s), "specimen Young's modulus [Pa] (default 2.64e9; used only with --k 0)", "E_s", NULL},
    {"--nu-s", REAL, AT(p.nu_s), "specimen Poisson ratio (default 0.4; used only with --k 0)", "nu_s", NULL},
    {"--law", LAW, AT(p.law), "spring law: g1 (G1 history sum, default), hertz (closed form), g1x (G1 with Richardson extrapolation)", "law", NULL},
    {"--g1-nodes", INTEGER, AT(p.g1_nodes), "G1 intervals N (default 0: internal steps since contact onset)", "g1_nodes", NULL},
    {"--dt", REAL, AT(p.dt_max), "internal time step [s] (default 1e-7)", "dt_max", NULL},
    {"--scheme", SCHEME, AT(p.scheme), "time scheme: sdirk2 (implicit, L-stable, second order; default) or central (the paper's explicit central differences)", "scheme", NULL},
    {"--scene", SCENE, AT(p.scene), "drop (default: a free striker) or driven (constant indentation rate --v0)", "scene", NULL},
    {"--g", REAL, AT(p.g), "acceleration of the striker towards the specimen [m/s^2] (default 0; 9.81 for gravity)", "g", NULL},
    {"--gap0", REAL, AT(p.gap0), "gap between striker and specimen at t = 0 [m] (default 0)", "gap0", NULL},
    {"--t-end", REAL, AT(p.t_end), "stop at this time if the solve has not stopped before [s] (default 1)", "t_end",
     NULL},
    {"--impacts", INTEGER, AT(p.impacts), "stop right after this many impacts have ended (default 1)", "impacts",
     NULL},
    {"--output-interval", REAL, AT(output_interval), "time between rows of --csv [s], besides a row at every contact onset and separation; 0 = a row after every internal step (large). Default: 1/256 of the elastic Hertz contact time at the impact speed (about 250 rows per contact; 4.8 us at the h20 defaults), or --t-end / 1000 in the driven scene without mass", NULL, finite_nonnegative},
    {"--csv", TEXT, AT(csv), "write the time series to FILE: t, F, x, x1, x2, v, E_diss (SI units)", NULL, NULL},
    {"--json", FLAG, AT(json), "print one JSON object instead of the table", NULL, NULL},
    {"--reference", FLAG, AT(reference), "solve with GSL's high-accuracy integrator instead of the model's scheme", NULL, NULL},
    {"--rtol", REAL, AT(rtol), "relative tolerance of --reference (default 1e-12)", NULL, between_0_and_1},
    {"--repeat", INTEGER, AT(repeat), "solve this many times and report the median cpu_seconds (default 1; for timing)", NULL, repeat_count},
    {"--quiet", FLAG, AT(quiet), "no progress line on a terminal", NULL, NULL},
};
#define N_OPTIONS (sizeof table / sizeof table[0])
typedef char options_fit_in_typed[N_OPTIONS <= N_OPTIONS_MAX ? 1 : -1];

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
            "The solve stops at the first of: --impacts impacts ended, --t-end, or the striker out of\n"
            "contact moving away with nothing to bring it back (no gravity, say).\n\n"
            "Output (table, or --json keys):\n"
            "  per_impact   one entry for every finished impact, in order: t_onset [s], v_onset [m/s],\n"
            "               F_peak [N], eps, t_contact [s], x2_end [m] (the permanent indentation when it\n"
            "               ended, left by all impacts so far), E_diss [J] (dissipated during it)\n"
            "  F_peak [N]   the largest force of the whole solve (all impacts, and a contact still going)\n"
            "  eps, t_contact [s]   of the last finished impact (0 when none ended)\n"
            "  x_perm [m], E_diss [J]   permanent indentation and energy dissipated where the solve\n"
            "               stopped, summed over every impact\n"
            "  v_end [m/s], x_end [m], x1_end [m]   striker velocity, total and elastic indentation there\n"
            "  impacts      finished impacts; separated: whether any impact ended\n"
            "  stopped      why the solve stopped: impacts, t_end or receding\n"
            "  t_end [s]    where it stopped\n"
            "  steps        internal steps (the reference: right-hand-side evaluations)\n"
            "  cpu_seconds  of the solve alone (the median over --repeat)\n"
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

/* Names the option and its value exactly as typed. */
static int bad_option(const char *name, const char *value, const char *why)
{
    fprintf(stderr, PROGRAM ": %s '%s'%s: %s (see --help)\n", name, value, *value ? "" : " (empty)", why);
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

/* Reads the value into its field; 0, or 2 after a message. */
static int set_option(options *o, const option *opt, const char *value)
{
    char *at = (char *)o + opt->offset, *end;
    const char *broken;
    switch (opt->kind) {
    case REAL:
        *(double *)at = strtod(value, &end);
        if (!*value || *end)
            return bad_option(opt->name, value, "not a number");
        break;
    case INTEGER: {
        long n = strtol(value, &end, 10);
        if (!*value || *end)
            return bad_option(opt->name, value, "not a whole number");
        if (n < -2147483647L || n > 2147483647L)
            return bad_option(opt->name, value, "out of range");
        *(int *)at = (int)n;
        break;
    }
    case LAW:
        return parse_word(value, law_words, (int *)at) ? bad_option(opt->name, value, "one of g1, hertz, g1x") : 0;
    case SCHEME:
        return parse_word(value, scheme_words, (int *)at) ? bad_option(opt->name, value, "one of sdirk2, central") : 0;
    case SCENE:
        return parse_word(value, scene_words, (int *)at) ? bad_option(opt->name, value, "one of drop, driven") : 0;
    case TEXT:
        *(const char **)at = value;
        break;
    case FLAG:
        *(int *)at = 1;
        break;
    }
    broken = opt->rule ? opt->rule(at) : NULL;
    return broken ? bad_option(opt->name, value, broken) : 0;
}

/* The model's own checks; its message names its variable, which names the
 * option and the value as typed. */
static int check_model(const options *o)
{
    char why[FC_MESSAGE_SIZE];
    size_t k, n;
    if (fc_params_check(&o->p, why, sizeof why) == FC_OK)
        return 0;
    n = strcspn(why, " ");
    for (k = 0; k < N_OPTIONS; k++)
        if (o->typed[k] && table[k].variable && strlen(table[k].variable) == n
            && strncmp(why, table[k].variable, n) == 0)
            return bad_option(table[k].name, o->typed[k], why);
    fprintf(stderr, PROGRAM ": %s (see --help)\n", why);
    return 2;
}

static const char *typed_value(const options *o, const char *name)
{
    size_t k;
    for (k = 0; k < N_OPTIONS; k++)
        if (strcmp(table[k].name, name) == 0)
            return o->typed[k];
    return NULL;
}

/* Returns 0, 2 for bad options, or -1 after --help or --list-options. */
static int parse(int argc, char **argv, options *o)
{
    int i;
    size_t k;
    char warning[FC_MESSAGE_SIZE];
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
            value = "";
        } else if (eq)
            value = eq + 1;
        else if (i + 1 < argc)
            value = argv[++i];
        else
            return bad_option(name, "", "needs a value");
        if (set_option(o, opt, value) != 0)
            return 2;
        o->typed[opt - table] = value;
    }
    if (typed_value(o, "--height"))
        o->p.v = fc_drop_velocity(o->height);
    if (check_model(o) != 0)
        return 2;
    if (fc_params_warning(&o->p, warning, sizeof warning))
        fprintf(stderr, PROGRAM ": warning: %s\n", warning);
    return 0;
}

/* ------------------------------------------------------------ results */

/* The reference's rows, in the library's layout. */
typedef struct {
    double *rows;
    size_t n, cap;
    int failed;
} series;

/* A row, unless it repeats the last one's time (an event on an output time). */
static void keep(void *ctx, double t, double F, double x, double x1, double x2, double v, double E_diss)
{
    series *s = ctx;
    double *r;
    if (s->failed || (s->n > 0 && !(t > s->rows[(s->n - 1) * FC_COLUMNS + FC_T])))
        return;
    if (s->n == s->cap) {
        size_t cap = s->cap ? 2 * s->cap : 1024;
        double *grown = realloc(s->rows, cap * FC_COLUMNS * sizeof *grown);
        if (!grown) {
            s->failed = 1;
            return;
        }
        s->rows = grown;
        s->cap = cap;
    }
    r = s->rows + s->n++ * FC_COLUMNS;
    r[FC_T] = t;
    r[FC_F] = F;
    r[FC_X] = x;
    r[FC_X1] = x1;
    r[FC_X2] = x2;
    r[FC_V] = v;
    r[FC_E_DISS] = E_diss;
}

static int write_csv_rows(const char *tmp, const char *path, const double *rows, size_t n);

/* The temporary file being written, removed if a signal ends the run. */
static char csv_tmp[4096];

static void remove_csv_tmp(int sig)
{
    unlink(csv_tmp); /* async-signal-safe, as are the two calls below */
    signal(sig, SIG_DFL);
    raise(sig);
}

static void on_signals(void (*handler)(int))
{
    static const int signals[] = {SIGINT, SIGTERM, SIGHUP};
    size_t i;
    for (i = 0; i < sizeof signals / sizeof signals[0]; i++)
        signal(signals[i], handler);
}

/* Written to FILE.tmp and renamed, so that an interrupted run never leaves a
 * complete-looking file, nor (when a signal interrupts it) the temporary one. */
static int write_csv(const char *path, const double *rows, size_t n)
{
    int ok;
    snprintf(csv_tmp, sizeof csv_tmp, "%s.tmp", path);
    on_signals(remove_csv_tmp);
    ok = write_csv_rows(csv_tmp, path, rows, n);
    on_signals(SIG_DFL);
    return ok;
}

static int write_csv_rows(const char *tmp, const char *path, const double *rows, size_t n)
{
    FILE *f;
    size_t i;
    int ok;
    f = fopen(tmp, "w");
    if (!f) {
        fprintf(stderr, PROGRAM ": --csv '%s': cannot write: ", path);
        perror(NULL);
        return -1;
    }
    fprintf(f, "t_s,F_N,x_m,x1_m,x2_m,v_m_per_s,E_diss_J\n");
    for (i = 0; i < n; i++) {
        const double *r = rows + i * FC_COLUMNS;
        fprintf(f, "%.12g,%.12g,%.12g,%.12g,%.12g,%.12g,%.12g\n", r[FC_T], r[FC_F], r[FC_X], r[FC_X1], r[FC_X2],
                r[FC_V], r[FC_E_DISS]);
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

static const char *stop_name(int stop)
{
    return stop == FC_STOP_IMPACTS ? "impacts" : stop == FC_STOP_T_END ? "t_end" : "receding";
}

static void print_json(const options *o, const fc_result *r, double cpu_seconds)
{
    static const char *const laws[] = {"", "g1", "hertz", "g1x"};
    static const char *const schemes[] = {"", "sdirk2", "central"};
    const fc_outcome *f = &r->outcome;
    size_t i;
    printf("{\"F_peak\": %.17g, \"eps\": %.17g, \"t_contact\": %.17g, \"x_perm\": %.17g, "
           "\"E_diss\": %.17g, \"v_end\": %.17g, \"x_end\": %.17g, \"x1_end\": %.17g, "
           "\"steps\": %" PRId64 ", \"cpu_seconds\": %.9g, \"impacts\": %" PRId64 ", \"separated\": %s, "
           "\"stopped\": \"%s\", \"t_end\": %.17g, \"law\": \"%s\", \"method\": \"%s\", \"dt\": %.17g, "
           "\"k\": %.17g, \"c\": %.17g, \"m\": %.17g, \"v0\": %.17g, \"per_impact\": [",
           f->F_peak, f->eps, f->t_contact, f->x2, f->E_diss, f->v, f->x, f->x1, f->steps, cpu_seconds,
           f->impacts, f->impacts > 0 ? "true" : "false", stop_name(f->stop), f->t, laws[o->p.law],
           o->reference ? "reference" : schemes[o->p.scheme], o->p.dt_max, f->k, o->p.c, o->p.m, o->p.v);
    for (i = 0; i < r->n_impacts; i++) {
        const fc_impact *p = &r->per_impact[i];
        printf("%s{\"t_onset\": %.17g, \"v_onset\": %.17g, \"F_peak\": %.17g, \"eps\": %.17g, "
               "\"t_contact\": %.17g, \"x2_end\": %.17g, \"E_diss\": %.17g}",
               i ? ", " : "", p->t_onset, p->v_onset, p->F_peak, p->eps, p->t_contact, p->x2_end, p->E_diss);
    }
    printf("]}\n");
}

static void print_table(const options *o, const fc_result *r, double cpu_seconds)
{
    static const char *const laws[] = {"", "g1", "hertz", "g1x"};
    static const char *const schemes[] = {"", "sdirk2", "central"};
    static const char *const stops[] = {"", "the requested impacts ended", "--t-end reached",
                                        "the striker moves away and nothing brings it back"};
    const fc_outcome *f = &r->outcome;
    size_t i;
    printf("%s, law %s, k = %.6g N/m^1.5, c = %.6g N s/m, m = %.6g kg, v0 = %.6g m/s\n",
           o->reference ? "reference" : schemes[o->p.scheme], laws[o->p.law], f->k, o->p.c, o->p.m, o->p.v);
    if (r->n_impacts > 0) {
        printf("  impact  t_onset [s]  v_onset [m/s]  F_peak [N]        eps  t_contact [s]  x2_end [m]  E_diss [J]\n");
        for (i = 0; i < r->n_impacts; i++) {
            const fc_impact *p = &r->per_impact[i];
            printf("  %6lu  %11.6g  %13.6g  %10.6g  %9.6g  %13.6g  %10.6g  %10.6g\n", (unsigned long)(i + 1),
                   p->t_onset, p->v_onset, p->F_peak, p->eps, p->t_contact, p->x2_end, p->E_diss);
        }
    }
    printf("  F_peak     %.10g N (largest of the solve)\n", f->F_peak);
    printf("  eps        %.10g (last finished impact)\n", f->eps);
    printf("  t_contact  %.10g s (last finished impact)\n", f->t_contact);
    printf("  x_perm     %.10g m (where the solve stopped)\n", f->x2);
    printf("  E_diss     %.10g J (all impacts)\n", f->E_diss);
    printf("  v_end      %.10g m/s\n", f->v);
    printf("  impacts    %" PRId64 "\n", f->impacts);
    printf("  stopped    at t = %.6g s: %s\n", f->t, stops[f->stop]);
    printf("  steps      %" PRId64 "\n", f->steps);
    printf("  cpu        %.6g s\n", cpu_seconds);
}

/* ------------------------------------------------------------ the solves */

typedef struct {
    double t_end, shown;
    int impacts;
} progress_line;

static void show_progress(void *ctx, double t, int64_t steps, int64_t impacts)
{
    progress_line *line = ctx;
    if (cpu_seconds() - line->shown < 0.5)
        return;
    line->shown = cpu_seconds();
    fprintf(stderr, "\r  t = %.6g s of at most %.6g s, %" PRId64 " steps, %" PRId64 " of %d impacts   ", t,
            line->t_end, steps, impacts, line->impacts);
}

static int solve_model(const options *o, double interval, fc_result *r)
{
    char why[FC_MESSAGE_SIZE];
    progress_line line = {o->p.t_end, 0.0, o->p.impacts};
    int progress = !o->quiet && !o->json && isatty(STDERR_FILENO);
    line.shown = cpu_seconds();
    if (fc_run_with_progress(&o->p, interval, progress ? show_progress : NULL, &line, r, why, sizeof why) != FC_OK) {
        fprintf(stderr, PROGRAM ": %s\n", why);
        return -1;
    }
    if (progress && r->outcome.steps >= 65536)
        fprintf(stderr, "\n");
    return 0;
}

static int solve_reference(const options *o, double interval, fc_result *r)
{
    reference_result ref;
    impact_list impacts = {NULL, 0, 0};
    series rows = {NULL, 0, 0, 0};
    char why[FC_MESSAGE_SIZE];
    int status = reference_solve(&o->p, o->rtol, interval, interval >= 0.0 ? keep : NULL, &rows, &impacts, &ref,
                                 why, sizeof why);
    memset(r, 0, sizeof *r);
    r->per_impact = impacts.list;
    r->n_impacts = impacts.n;
    r->rows = rows.rows;
    r->n_rows = rows.n;
    if (status != 0 || rows.failed) {
        fprintf(stderr, PROGRAM ": %s\n", status != 0 ? why : "out of memory for the --csv series");
        return -1;
    }
    r->outcome = ref.outcome;
    return 0;
}

/* One solve, or --repeat of them; returns the median CPU time of the solve
 * alone, or -1. The result is the last solve's. */
static double solve(const options *o, double interval, fc_result *r)
{
    double *times = malloc((size_t)o->repeat * sizeof *times), seconds = -1.0;
    int i, status = times ? 0 : -1;
    for (i = 0; i < o->repeat && status == 0; i++) {
        double t0 = cpu_seconds();
        if (i > 0)
            fc_result_free(r);
        status = o->reference ? solve_reference(o, interval, r) : solve_model(o, interval, r);
        times[i] = cpu_seconds() - t0;
    }
    if (status == 0)
        seconds = median(times, o->repeat);
    free(times);
    return seconds;
}

int main(int argc, char **argv)
{
    options o;
    fc_result r;
    double interval, seconds;
    int status;
    memset(&o, 0, sizeof o);
    fc_params_default(&o.p);
    o.repeat = 1;
    o.rtol = 1e-12;
    status = parse(argc, argv, &o);
    if (status != 0)
        return status < 0 ? 0 : status;
    interval = !o.csv ? FC_NO_ROWS : typed_value(&o, "--output-interval") ? o.output_interval
                                                                            : fc_default_output_interval(&o.p);
    seconds = solve(&o, interval, &r);
    status = seconds < 0.0 || (o.csv && write_csv(o.csv, r.rows, r.n_rows) != 0);
    if (!status) {
        if (o.json)
            print_json(&o, &r, seconds);
        else
            print_table(&o, &r, seconds);
    }
    fc_result_free(&r);
    return status;
}
