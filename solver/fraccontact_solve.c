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
#define N_OPTIONS_MAX 40

typedef struct {
    fc_params p;
    double height, output_interval, rtol;
    double interval; /* of the rows: FC_NO_ROWS without --csv */
    int repeat;
    const char *csv;
    int json, reference, quiet;
    const char *typed[N_OPTIONS_MAX]; /* each option's value as typed (NULL: not given) */
} options;

/* ------------------------------------------------------------ options */

typedef enum { REAL, INTEGER, WORD, TEXT, FLAG } option_kind;

/* A rule an option's value must follow: NULL when it does, else the rule. */
typedef const char *(*option_rule)(const void *value);

typedef struct {
    char name[32];
    option_kind kind;
    size_t offset;        /* of its field in options */
    char help[512];
    const char *variable; /* the library's name for it, as in its messages */
    option_rule rule;     /* for the solver's own options (the library checks its own) */
    const char *words;    /* a WORD's words for its codes 1, 2, ..., space-separated (the library's table) */
} option;

typedef struct {
    option list[N_OPTIONS_MAX];
    size_t n;
} option_table;

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

/* The i-th (from 0) of the space-separated words into word; 0 past the last. */
static int nth_word(const char *words, int i, char word[32])
{
    size_t n;
    for (;; words += n) {
        words += strspn(words, " ");
        n = strcspn(words, " ");
        if (n == 0)
            return 0;
        if (i-- == 0)
            break;
    }
    snprintf(word, 32, "%.*s", (int)n, words);
    return 1;
}

static void add_option(option_table *t, const char *name, option_kind kind, size_t offset, const char *variable,
                       option_rule rule, const char *help)
{
    option *o = &t->list[t->n++];
    snprintf(o->name, sizeof o->name, "%s", name);
    o->kind = kind;
    o->offset = offset;
    o->variable = variable;
    o->rule = rule;
    o->words = "";
    snprintf(o->help, sizeof o->help, "%s", help);
}

/* One option per parameter of the library, --NAME with '_' as '-', its help
 * with unit and default from the library; then the solver's own options. */
static void make_options(option_table *t)
{
    fc_params defaults;
    size_t i;
    fc_params_default(&defaults);
    t->n = 0;
    add_option(t, "--height", REAL, offsetof(options, height), NULL, finite_nonnegative,
               "drop height h [m]: v = sqrt(2 * 9.81 * h) (instead of --v)");
    for (i = 0; i < fc_parameter_count(); i++) {
        const fc_parameter *p = fc_parameter_at(i);
        const void *value = (const char *)&defaults + p->offset;
        char name[32], help[512], shown[64], word[32];
        size_t k;
        int w;
        option_kind kind = p->kind == FC_REAL ? REAL : *p->words ? WORD : INTEGER;
        snprintf(name, sizeof name, "--%s", p->name);
        for (k = 2; name[k]; k++)
            name[k] = name[k] == '_' ? '-' : name[k];
        if (p->kind == FC_REAL)
            snprintf(shown, sizeof shown, "%g", *(const double *)value);
        else
            snprintf(shown, sizeof shown, "%d", *(const int *)value);
        snprintf(help, sizeof help, "%s [%s] (default %s)", p->help, p->unit, shown);
        for (w = 0; nth_word(p->words, w, word); w++)
            snprintf(help + strlen(help), sizeof help - strlen(help), "%s%s", w ? ", " : "; or ", word);
        add_option(t, name, kind, offsetof(options, p) + p->offset, p->name, NULL, help);
        t->list[t->n - 1].words = p->words;
    }
    add_option(t, "--output-interval", REAL, offsetof(options, output_interval), "output_interval", finite_nonnegative,
               "time between rows of --csv [s], besides a row at every contact onset and separation; 0 = a row "
               "after every internal step (large). Default: 1/256 of the elastic Hertz contact time at the impact "
               "speed (about 250 rows per contact; 4.8 us at the h20 defaults), or --t-end / 1000 in the driven "
               "scene without mass");
    add_option(t, "--csv", TEXT, offsetof(options, csv), NULL, NULL,
               "write the time series to FILE, columns t [s], F [N], x, x1, x2 [m], v [m/s], E_diss [J]");
    add_option(t, "--json", FLAG, offsetof(options, json), NULL, NULL, "print one JSON object instead of the table");
    add_option(t, "--reference", FLAG, offsetof(options, reference), NULL, NULL,
               "solve with GSL's high-accuracy integrator instead of the model's scheme");
    add_option(t, "--rtol", REAL, offsetof(options, rtol), NULL, between_0_and_1,
               "relative tolerance of --reference (default 1e-12)");
    add_option(t, "--repeat", INTEGER, offsetof(options, repeat), NULL, repeat_count,
               "solve this many times and report the median cpu_seconds (default 1; for timing)");
    add_option(t, "--quiet", FLAG, offsetof(options, quiet), NULL, NULL, "no progress line on a terminal");
}

static void usage(const option_table *t)
{
    size_t i;
    printf("usage: " PROGRAM " [OPTION VALUE]... [--json] [--reference]\n"
           "Simulates an impact on a Hertz spring in series with a dashpot, the spring force\n"
           "computed by the G1 Grunwald-Letnikov semi-integral (docs/model.md). Defaults: the paper's\n"
           "h20 drop test. Options take a value as '--opt VALUE' or '--opt=VALUE'; the model's\n"
           "options are the FMU's variables (--dt-max for dt_max).\n\n");
    for (i = 0; i < t->n; i++)
        printf("  %-18s %s\n", t->list[i].name, t->list[i].help);
    printf("  %-18s %s\n", "--list-options", "print this table as JSON (option, kind, help, choices) and exit");
    printf("  %-18s %s\n\n", "--help", "this text");
    printf("The solve stops at the first of: --impacts impacts ended, --t-end, or the striker out of\n"
           "contact moving away with nothing to bring it back (no gravity, say). A solve that would\n"
           "take more than %.0e internal steps, or a --csv of more than %.0e rows, is refused up\n"
           "front (estimated from the elastic contact time at the impact speed).\n\n", FC_STEPS_MAX,
           (double)FC_ROWS_MAX);
    printf("Output (table, or --json keys):\n"
           "  t_onset [s], v_onset [m/s], F_peak [N], eps, t_contact [s], x2_end [m], E_diss [J]\n"
           "               the first impact's figures (null when none ended): onset time and speed,\n"
           "               largest force, restitution coefficient, contact duration, the permanent\n"
           "               indentation when it ended, the energy it dissipated\n"
           "  per_impact   the same for every finished impact, in order (x2_end: the dent left by all\n"
           "               impacts so far)\n"
           "  end          the FMU's outputs where the solve stopped: t [s], F_peak [N] (the largest\n"
           "               of the solve), eps and t_contact [s] (of the last finished impact), E_diss [J]\n"
           "               (of all impacts), x, x1, x2 [m], v [m/s] (the striker's velocity)\n"
           "  stopped      why the solve stopped: impacts, t_end, receding, or resting (in contact, at rest\n"
           "               for good: an overdamped contact that never separates)\n"
           "  impacts      finished impacts\n"
           "  steps        internal steps (the reference: right-hand-side evaluations)\n"
           "  cpu_seconds  of the solve alone (the median over --repeat)\n"
           "  method, k    gradient, esdirk54 or radau_iia (error-controlled steps, tolerance > 0: the dashpot's,\n"
           "               the springpot's), central, g1_history (a springpot's full G1 history) or\n"
           "               reference; the spring constant used [N/m^n]\n"
           "  params       every parameter of the run, by the FMU's names\n"
           "Exit status: 0 done, 2 bad options, 1 the solve or an output failed, 130 interrupted (Ctrl-C).\n"
           "On a terminal a solve that takes more than a few seconds shows its progress on stderr.\n");
}

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

/* The option table as JSON, for programs that drive the solver. */
static void list_options(const option_table *t)
{
    static const char *const kinds[] = {"real", "integer", "word", "text", "flag"};
    size_t i;
    printf("[");
    for (i = 0; i < t->n; i++) {
        const option *o = &t->list[i];
        char word[32];
        printf("%s\n {\"option\": ", i ? "," : "");
        print_json_string(o->name);
        printf(", \"kind\": \"%s\", \"help\": ", kinds[o->kind]);
        print_json_string(o->help);
        if (o->kind == WORD) {
            int w;
            printf(", \"choices\": [");
            for (w = 0; nth_word(o->words, w, word); w++)
                printf("%s\"%s\"", w ? ", " : "", word);
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

/* "one of WORD, ... or 1, ..., n": what a word option takes. */
static const char *word_rule(const char *words, char *rule, size_t len)
{
    int i, n;
    size_t used;
    char word[32];
    used = (size_t)snprintf(rule, len, "one of");
    for (n = 0; nth_word(words, n, word) && used < len; n++)
        used += (size_t)snprintf(rule + used, len - used, "%s %s", n ? "," : "", word);
    for (i = 1; i <= n && used < len; i++)
        used += (size_t)snprintf(rule + used, len - used, "%s%d", i == 1 ? " or " : ", ", i);
    return rule;
}

static int parse_word(const char *value, const char *words, int *out)
{
    int i;
    char *end, word[32];
    long n = strtol(value, &end, 10);
    for (i = 0; nth_word(words, i, word); i++)
        if (strcmp(value, word) == 0) {
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
    char *at = (char *)o + opt->offset, *end, rule[128];
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
    case WORD:
        return parse_word(value, opt->words, (int *)at)
                   ? bad_option(opt->name, value, word_rule(opt->words, rule, sizeof rule))
                   : 0;
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

/* A message of the library's checks: it names its variable, which names the
 * option and the value as typed. Returns 2. */
static int bad_model(const option_table *t, const options *o, const char *why)
{
    size_t k, n = strcspn(why, " ");
    for (k = 0; k < t->n; k++)
        if (o->typed[k] && t->list[k].variable && strlen(t->list[k].variable) == n
            && strncmp(why, t->list[k].variable, n) == 0)
            return bad_option(t->list[k].name, o->typed[k], why);
    fprintf(stderr, PROGRAM ": %s (see --help)\n", why);
    return 2;
}

static const char *typed_value(const option_table *t, const options *o, const char *name)
{
    size_t k;
    for (k = 0; k < t->n; k++)
        if (strcmp(t->list[k].name, name) == 0)
            return o->typed[k];
    return NULL;
}

/* The options of one method only: --rtol of --reference; what --reference
 * cannot solve (refused), and the model's steps, which it does not take
 * (a warning: they change nothing). */
static int check_method(const option_table *t, options *o)
{
    static const char *const model_steps[] = {"--dt-max", "--tolerance"};
    const char *value;
    size_t i;
    if (!o->reference) {
        value = typed_value(t, o, "--rtol");
        return value ? bad_option("--rtol", value, "the relative tolerance of --reference, which is not given") : 0;
    }
    if (o->p.model.damper != 1)
        return bad_option("--damper", typed_value(t, o, "--damper"),
                          "--reference integrates the dashpot (damper 1) only: a springpot has no ODE for GSL "
                          "(compare --memory 1 with --memory 2 instead)");
    if ((value = typed_value(t, o, "--scheme")))
        return bad_option("--scheme", value, "--reference integrates with GSL, not with a scheme of the model");
    for (i = 0; i < sizeof model_steps / sizeof model_steps[0]; i++)
        if ((value = typed_value(t, o, model_steps[i])))
            fprintf(stderr, PROGRAM ": warning: %s '%s' has no effect with --reference: GSL takes its own steps (to "
                    "--rtol)\n", model_steps[i], value);
    if (o->p.model.law != 2 && o->p.model.g1_nodes == 0) {
        if ((value = typed_value(t, o, "--law")))
            return bad_option("--law", value,
                              "--reference solves the continuous law: hertz, or g1 and g1x with --g1-nodes N > 0 "
                              "(with N the steps since onset the G1 laws tend to hertz as dt_max shrinks)");
        o->p.model.law = 2; /* the default law's limit, which the reference solves */
    }
    return 0;
}

/* The run's size (the library's limits on steps and rows), and the rows'
 * spacing: --output-interval only with --csv. */
static int check_run(const option_table *t, options *o)
{
    char why[FC_MESSAGE_SIZE];
    const char *typed = typed_value(t, o, "--output-interval");
    fc_status status;
    if (!o->csv && typed)
        return bad_option("--output-interval", typed, "the time between the rows of --csv, which is not given");
    o->interval = !o->csv ? FC_NO_ROWS : typed ? o->output_interval : fc_default_output_interval(&o->p);
    status = o->reference ? run_rows_check(&o->p, o->interval, 0.0, why, sizeof why)
                          : fc_run_check(&o->p, o->interval, why, sizeof why);
    return status == FC_OK ? 0 : bad_model(t, o, why);
}

/* Returns 0, 2 for bad options, or -1 after --help or --list-options. */
static int parse(int argc, char **argv, const option_table *t, options *o)
{
    int i;
    size_t k;
    char warning[FC_MESSAGE_SIZE], why[FC_MESSAGE_SIZE];
    for (i = 1; i < argc; i++) {
        char name[64];
        const char *value = NULL, *eq = strchr(argv[i], '=');
        const option *opt = NULL;
        if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
            usage(t);
            return -1;
        }
        if (strcmp(argv[i], "--list-options") == 0) {
            list_options(t);
            return -1;
        }
        snprintf(name, sizeof name, "%.*s", eq ? (int)(eq - argv[i]) : (int)strlen(argv[i]), argv[i]);
        for (k = 0; k < t->n; k++)
            if (strcmp(name, t->list[k].name) == 0)
                opt = &t->list[k];
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
        if (o->typed[opt - t->list]) {
            if (opt->kind == FLAG)
                fprintf(stderr, PROGRAM ": %s given twice: give each option once (see --help)\n", name);
            else
                fprintf(stderr, PROGRAM ": %s given twice ('%s', then '%s'): give each option once (see --help)\n",
                        name, o->typed[opt - t->list], value);
            return 2;
        }
        if (set_option(o, opt, value) != 0)
            return 2;
        o->typed[opt - t->list] = value;
    }
    if (typed_value(t, o, "--height")) {
        if (typed_value(t, o, "--v"))
            return bad_option("--height", typed_value(t, o, "--height"), "give --height or --v, not both");
        o->p.v = fc_drop_velocity(o->height);
    }
    if (fc_params_check(&o->p, why, sizeof why) != FC_OK)
        return bad_model(t, o, why);
    if (check_method(t, o) != 0)
        return 2;
    if (check_run(t, o) != 0)
        return 2;
    if (fc_params_warning(&o->p, warning, sizeof warning))
        fprintf(stderr, PROGRAM ": warning: %s\n", warning);
    return 0;
}

/* ------------------------------------------------------------ results */

/* A row of the reference's time series. */
static void keep(void *ctx, double t, double F, double x, double x1, double x2, double v, double E_diss)
{
    const double row[FC_COLUMNS] = {t, F, x, x1, x2, v, E_diss};
    series_add(ctx, row);
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
    fprintf(f, "t,F,x,x1,x2,v,E_diss\n");
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
    return stop == FC_STOP_IMPACTS ? "impacts" : stop == FC_STOP_T_END ? "t_end" : stop == FC_STOP_RESTING ? "resting"
                                                                                                  : "receding";
}

static const char *method_name(const options *o)
{
    if (o->reference)
        return "reference";
    return fc_method_name(&o->p);
}

/* "name": value for each figure of an impact; null for a missing one. */
static void print_impact_json(const fc_impact *i, int ended)
{
    const double figures[] = {i->t_onset, i->v_onset, i->F_peak, i->eps, i->t_contact, i->x2_end, i->E_diss};
    static const char *const names[] = {"t_onset", "v_onset", "F_peak", "eps", "t_contact", "x2_end", "E_diss"};
    size_t k;
    for (k = 0; k < sizeof names / sizeof names[0]; k++) {
        if (ended)
            printf("%s\"%s\": %.17g", k ? ", " : "", names[k], figures[k]);
        else
            printf("%s\"%s\": null", k ? ", " : "", names[k]);
    }
}

static void print_params_json(const fc_params *p)
{
    size_t i;
    for (i = 0; i < fc_parameter_count(); i++) {
        const fc_parameter *q = fc_parameter_at(i);
        const void *value = (const char *)p + q->offset;
        if (q->kind == FC_REAL)
            printf("%s\"%s\": %.17g", i ? ", " : "", q->name, *(const double *)value);
        else
            printf("%s\"%s\": %d", i ? ", " : "", q->name, *(const int *)value);
    }
}

static void print_json(const options *o, const fc_result *r, double cpu_seconds)
{
    const fc_outcome *f = &r->outcome;
    size_t i;
    printf("{");
    print_impact_json(&f->first, f->impacts > 0);
    printf(", \"per_impact\": [");
    for (i = 0; i < r->n_impacts; i++) {
        printf("%s{", i ? ", " : "");
        print_impact_json(&r->per_impact[i], 1);
        printf("}");
    }
    printf("], \"end\": {\"t\": %.17g, \"F_peak\": %.17g, \"eps\": %.17g, \"t_contact\": %.17g, "
           "\"E_diss\": %.17g, \"x\": %.17g, \"x1\": %.17g, \"x2\": %.17g, \"v\": %.17g}, "
           "\"stopped\": \"%s\", \"impacts\": %" PRId64 ", \"steps\": %" PRId64 ", \"cpu_seconds\": %.9g, "
           "\"method\": \"%s\", \"k\": %.17g, \"params\": {",
           f->t, f->F_peak, f->eps, f->t_contact, f->E_diss, f->x, f->x1, f->x2, f->v, stop_name(f->stop),
           f->impacts, f->steps, cpu_seconds, method_name(o), f->k);
    print_params_json(&o->p);
    printf("}}\n");
}

/* The word of the law's code, from the library's table. */
static const char *law_word(int law, char word[32])
{
    size_t i;
    for (i = 0; i < fc_parameter_count(); i++)
        if (strcmp(fc_parameter_at(i)->name, "law") == 0 && nth_word(fc_parameter_at(i)->words, law - 1, word))
            return word;
    return "?";
}

static void print_table(const options *o, const fc_result *r, double cpu_seconds)
{
    char law[32];
    static const char *const stops[] = {"", "the requested impacts ended", "--t-end reached",
                                        "the striker moves away and nothing brings it back",
                                        "the striker came to rest in contact: the force decayed without a "
                                        "separation"};
    const fc_outcome *f = &r->outcome;
    size_t i;
    printf("%s, law %s, k = %.6g N/m^%g, ", method_name(o), law_word(o->p.model.law, law), f->k, o->p.model.spring_exponent);
    if (o->p.model.damper == 2)
        printf("springpot alpha = %g, c_alpha = %.6g N s^%g/m, memory %s, ", o->p.model.damper_order, o->p.model.c_alpha,
               o->p.model.damper_order, o->p.model.memory == 1 ? "full G1 history" : "compressed");
    else
        printf("c = %.6g N s/m, ", o->p.model.c);
    printf("m = %.6g kg, v = %.6g m/s\n", o->p.m, o->p.v);
    if (r->n_impacts > 0) {
        printf("  impact  t_onset [s]  v_onset [m/s]  F_peak [N]        eps  t_contact [s]  x2_end [m]  E_diss [J]\n");
        for (i = 0; i < r->n_impacts; i++) {
            const fc_impact *p = &r->per_impact[i];
            printf("  %6lu  %11.6g  %13.6g  %10.6g  %9.6g  %13.6g  %10.6g  %10.6g\n", (unsigned long)(i + 1),
                   p->t_onset, p->v_onset, p->F_peak, p->eps, p->t_contact, p->x2_end, p->E_diss);
        }
    } else
        printf("  no impact ended\n");
    printf("  at the end: t = %.6g s, F_peak %.10g N (largest of the solve), x2 %.10g m, E_diss %.10g J,\n"
           "              v %.10g m/s\n", f->t, f->F_peak, f->x2, f->E_diss, f->v);
    printf("  stopped     %s\n", stops[f->stop]);
    printf("  steps       %" PRId64 ", cpu %.6g s\n", f->steps, cpu_seconds);
}

/* ------------------------------------------------------------ the solves */

/* Set by Ctrl-C: the solve stops at its next progress call. */
static volatile sig_atomic_t interrupted;

static void interrupt(int sig)
{
    if (interrupted) { /* a second Ctrl-C: at once */
        signal(sig, SIG_DFL);
        raise(sig);
    }
    interrupted = 1;
}

/* The progress line on a terminal, once the solve has taken a few seconds. */
#define PROGRESS_AFTER 2.0
#define PROGRESS_EVERY 0.5

typedef struct {
    const options *o;
    const series *rows; /* the reference's, which stops when they run out */
    int shown;          /* a line is on the terminal */
    double start, next; /* CPU seconds: the solve's start, the next line (0: no line) */
} progress_line;

static int watch(void *ctx, double t, int64_t steps, int64_t impacts)
{
    progress_line *line = ctx;
    if (line->next > 0.0 && cpu_seconds() >= line->next) {
        line->next = cpu_seconds() + PROGRESS_EVERY;
        line->shown = 1;
        fprintf(stderr, "\r  t = %.6g s of at most %.6g s, %" PRId64 " %s, %" PRId64 " of %d impacts (Ctrl-C stops)   ",
                t, line->o->p.t_end, steps, line->o->reference ? "evaluations" : "steps", impacts,
                line->o->p.impacts);
    }
    return interrupted || (line->rows && line->rows->failed);
}

static void watch_start(progress_line *line, const options *o, const series *rows)
{
    line->o = o;
    line->rows = rows;
    line->shown = 0;
    /* not otherwise: --repeat times the solve, and a clock read would be in the timing */
    line->next = !o->quiet && !o->json && isatty(STDERR_FILENO) ? cpu_seconds() + PROGRESS_AFTER : 0.0;
}

static void watch_end(const progress_line *line)
{
    if (line->shown)
        fprintf(stderr, "\n");
}

/* Reports a solve that did not finish; 130 when Ctrl-C stopped it, else 1. */
static int failed(const fc_outcome *outcome, const char *why)
{
    if (outcome->status == FC_ESTOPPED && interrupted) {
        fprintf(stderr, PROGRAM ": interrupted (Ctrl-C) at t = %.6g s: nothing written\n", outcome->t);
        return 130;
    }
    fprintf(stderr, PROGRAM ": %s\n", why);
    return 1;
}

static int solve_model(const options *o, fc_result *r)
{
    char why[FC_MESSAGE_SIZE];
    progress_line line;
    fc_status status;
    watch_start(&line, o, NULL);
    status = fc_run_with_progress(&o->p, o->interval, watch, &line, r, why, sizeof why);
    watch_end(&line);
    return status == FC_OK ? 0 : failed(&r->outcome, why);
}

static int solve_reference(const options *o, fc_result *r)
{
    reference_result ref;
    impact_list impacts = {NULL, 0, 0};
    series rows = {NULL, 0, 0, 0};
    char why[FC_MESSAGE_SIZE];
    progress_line line;
    int status;
    memset(&ref, 0, sizeof ref);
    watch_start(&line, o, &rows);
    status = reference_solve(&o->p, o->rtol, o->interval, o->interval >= 0.0 ? keep : NULL, &rows, watch, &line,
                             &impacts, &ref, why, sizeof why);
    watch_end(&line);
    memset(r, 0, sizeof *r);
    r->per_impact = impacts.list;
    r->n_impacts = impacts.n;
    r->rows = rows.rows;
    r->n_rows = rows.n;
    r->outcome = ref.outcome;
    if (rows.failed) {
        fprintf(stderr, PROGRAM ": %s\n", rows.n < (size_t)FC_ROWS_MAX ? "out of memory for the --csv series"
                : "--output-interval: the time series reached the rows a run keeps; raise --output-interval, or "
                  "lower --t-end or --impacts");
        return 1;
    }
    return status == 0 ? 0 : failed(&ref.outcome, why);
}

/* One solve, or --repeat of them; *seconds: the median CPU time of the
 * solve alone. The result is the last solve's. Returns 0, or the exit
 * status after a message. */
static int solve(const options *o, fc_result *r, double *seconds)
{
    double *times = malloc((size_t)o->repeat * sizeof *times);
    int i, status = 0;
    struct sigaction on_interrupt, before;
    if (!times) {
        fprintf(stderr, PROGRAM ": out of memory\n");
        return 1;
    }
    memset(&on_interrupt, 0, sizeof on_interrupt);
    on_interrupt.sa_handler = interrupt;
    sigemptyset(&on_interrupt.sa_mask);
    sigaction(SIGINT, &on_interrupt, &before);
    memset(r, 0, sizeof *r);
    for (i = 0; i < o->repeat && status == 0; i++) {
        double t0 = cpu_seconds();
        fc_result_free(r);
        status = o->reference ? solve_reference(o, r) : solve_model(o, r);
        times[i] = cpu_seconds() - t0;
    }
    sigaction(SIGINT, &before, NULL);
    if (status == 0)
        *seconds = median(times, o->repeat);
    free(times);
    return status;
}

int main(int argc, char **argv)
{
    option_table table;
    options o;
    fc_result r;
    double seconds = 0.0;
    int status;
    memset(&o, 0, sizeof o);
    fc_params_default(&o.p);
    o.repeat = 1;
    o.rtol = 1e-12;
    make_options(&table);
    status = parse(argc, argv, &table, &o);
    if (status != 0)
        return status < 0 ? 0 : status;
    status = solve(&o, &r, &seconds);
    if (status == 0 && o.csv && write_csv(o.csv, r.rows, r.n_rows) != 0)
        status = 1;
    if (status == 0) {
        if (o.json)
            print_json(&o, &r, seconds);
        else
            print_table(&o, &r, seconds);
    }
    fc_result_free(&r);
    return status;
}
