#include "fraccontact.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "contact.h"
#include "run.h"

/* The library's rows of parameters.def, in its order. */
#define ROW(name, type, at, unit, words, description) \
    {#name, FC_KIND_##type, offsetof(fc_params, at), unit, description, words},
#define FC_KIND_Real FC_REAL
#define FC_KIND_Integer FC_INTEGER
#define LIBRARY_ROW(name, type, unit, value, min, max, vr, index, variability, words, rule, description) \
    ROW(name, type, name, unit, words, description)
#define MODEL_ROW(name, type, unit, value, min, max, vr, index, variability, words, rule, description) \
    ROW(name, type, model.name, unit, words, description)

static const fc_parameter parameters[] = {
#define INPUT_FMU_LIBRARY LIBRARY_ROW
#define PARAMETER_MODEL_FMU_LIBRARY MODEL_ROW
#define PARAMETER_MODEL_LIBRARY MODEL_ROW
#define STOP_LIBRARY LIBRARY_ROW
#include "parameters.def"
};

#define N_PARAMETERS (sizeof parameters / sizeof parameters[0])

size_t fc_parameter_count(void) { return N_PARAMETERS; }

const fc_parameter *fc_parameter_at(size_t i) { return i < N_PARAMETERS ? &parameters[i] : NULL; }

size_t fc_params_size(void) { return sizeof(fc_params); }

size_t fc_outcome_size(void) { return sizeof(fc_outcome); }

void fc_striker(const fc_params *p, double *v, double *m)
{
    *v = p->v - p->v2;
    *m = contact_reduced_mass(p->m, p->m2);
}

void fc_params_default(fc_params *p)
{
    memset(p, 0, sizeof *p);
#define INPUT_FMU_LIBRARY(name, type, unit, value, ...) p->name = value;
#define STOP_LIBRARY(name, type, unit, value, ...) p->name = value;
#include "parameters.def"
    contact_default_params(&p->model);
}

fc_status fc_params_check(const fc_params *p, char *msg, size_t len)
{
    const contact_params *q = &p->model;
    double v, m;
    fc_striker(p, &v, &m);
    if (contact_check_params(q, msg, len) != 0
        || contact_check_bodies(q, q->scene, p->v, p->m, p->v2, p->m2, msg, len) != 0
        || contact_check_resolution(q, v, m, msg, len) != 0)
        return FC_EINVAL;
    if (!(p->t_end > 0.0) || !isfinite(p->t_end)) {
        contact_reject(msg, len, "t_end", p->t_end, "the time limit must be positive and finite [s]");
        return FC_EINVAL;
    }
    if (p->impacts < 1) {
        contact_reject(msg, len, "impacts", p->impacts, "the number of impacts to stop after must be >= 1");
        return FC_EINVAL;
    }
    /* A run stops at its first separation after one impact, or where
     * nothing brings the striker back. */
    if (contact_check_history_span(q, v, m, p->t_end, p->impacts == 1 || !(q->g > 0.0), "t_end", msg, len)
        != 0)
        return FC_EINVAL;
    return FC_OK;
}

size_t fc_memory_kernel(const fc_params *p, size_t max, double *a, double *b, double *eta, char *msg, size_t len)
{
    contact_params q = p->model;
    contact_model cm;
    size_t i;
    if (fc_params_check(p, msg, len) != FC_OK)
        return 0;
    q.damper = CONTACT_DAMPER_SPRINGPOT;
    q.memory = CONTACT_MEMORY_COMPRESSED;
    memset(&cm, 0, sizeof cm);
    if (contact_configure(&cm, &q) != 0) {
        contact_reject(msg, len, "memory", (double)q.memory, "out of memory for the springpot's modes");
        return 0;
    }
    if (cm.modes.modes <= max)
        for (i = 0; i < cm.modes.modes; i++) {
            a[i] = cm.modes.a[i];
            b[i] = cm.modes.b[i];
        }
    *eta = cm.modes.eta;
    i = cm.modes.modes;
    contact_release(&cm);
    return i;
}

double fc_step_limit(const fc_params *p)
{
    return contact_step_limit(&p->model);
}

double fc_drop_velocity(double height)
{
    return sqrt(2.0 * 9.81 * height);
}

int fc_params_warning(const fc_params *p, char *msg, size_t len)
{
    double v, m;
    fc_striker(p, &v, &m);
    return contact_unused_value(&p->model, msg, len) || contact_step_warning(&p->model, v, m, msg, len)
           || contact_arrival_warning(&p->model, v, msg, len);
}

int fc_error_controlled(const fc_params *p)
{
    return contact_error_controlled(&p->model);
}

const char *fc_method_name(const fc_params *p)
{
    return contact_method_name(contact_method(&p->model));
}

/* t_c v / x_max of an elastic impact on the spring k x1^n (docs/model.md §2):
 * 2 integral_0^1 (1 - u^(n+1))^(-1/2) du = 2/(n+1) B(1/(n+1), 1/2). */
static double elastic_contact_time(double n)
{
    const double e = 1.0 / (n + 1.0);
    return 2.0 * e * tgamma(e) * tgamma(0.5) / tgamma(e + 0.5);
}

/* The elastic Hertz contact time at the impact speed [s], 0 when the
 * striker never meets the specimen. */
static double contact_time(const fc_params *p)
{
    contact_params q = p->model;
    contact_model cm;
    double x_ref, t_ref, x_small, v, m;
    fc_striker(p, &v, &m);
    q.damper = CONTACT_DAMPER_DASHPOT; /* the spring's alone: no springpot's memory to build */
    contact_start(&cm, &q, v, m);
    contact_scales(&q, contact_spring_stiffness(&cm, 0), v, m, &x_ref, &t_ref, &x_small);
    return t_ref > 0.0 ? elastic_contact_time(p->model.spring_exponent) * t_ref : 0.0;
}

/* Whether the run is one contact as long as the run: the driven scene without mass. */
static int driven_rate(const fc_params *p)
{
    return p->model.scene == CONTACT_SCENE_DRIVEN && !(p->m > 0.0);
}

double fc_default_output_interval(const fc_params *p)
{
    double t_c;
    if (driven_rate(p)) /* one contact, as long as the run */
        return p->t_end / 1000.0;
    t_c = contact_time(p);
    return t_c > 0.0 ? t_c / 256.0 : p->t_end / 1000.0;
}

/* ------------------------------------------------------------ a run's size */

/* When the striker first meets the specimen (it falls through gap0 from v
 * under g: gap0 = v t + g t^2 / 2), or infinity when it never does. */
static double onset_time(const fc_params *p)
{
    double g = driven_rate(p) ? 0.0 : p->model.g, v, m, root, speed;
    fc_striker(p, &v, &m);
    root = v * v + 2.0 * g * p->model.gap0;
    if (p->model.gap0 == 0.0 && (v > 0.0 || (v == 0.0 && g > 0.0)))
        return 0.0;
    speed = root >= 0.0 ? v + sqrt(root) : 0.0;
    return speed > 0.0 ? 2.0 * p->model.gap0 / speed : INFINITY;
}

/* The least a run must cover before it may stop, short of t_end [s]: none
 * when the striker never arrives, else to its first onset, then its contacts, each at least the elastic contact time at
 * the first impact's speed (later ones are slower, and longer), all
 * `impacts` of them when an acceleration brings the striker back; the
 * driven scene without mass is in contact until t_end. Of that, *in_contact
 * is the contacts' part. */
static double least_span(const fc_params *p, double *in_contact)
{
    double onset = onset_time(p), end = p->t_end, contacts;
    *in_contact = 0.0;
    if (isinf(onset)) /* it recedes from the start: the run stops at once */
        return 0.0;
    if (!(onset < end))
        return end;
    contacts = driven_rate(p) ? end : contact_time(p) * (p->model.g > 0.0 ? (double)p->impacts : 1.0);
    *in_contact = fmin(contacts, end - onset);
    return onset + *in_contact;
}

/* The least number of internal steps of the run: steps of at most the
 * step limit (dt_max, its default, or none under error control) over its
 * contacts, or over the whole span on a uniform grid. */
static double least_steps(const fc_params *p)
{
    double in_contact, span = least_span(p, &in_contact);
    return contact_least_steps(&p->model, span, in_contact);
}

static fc_status reject_steps(const fc_params *p, double steps, char *msg, size_t len)
{
    char rule[256];
    snprintf(rule, sizeof rule,
             "the run would take at least %.3g internal steps of at most %.3g s, more than %.0e; raise dt_max, or "
             "lower t_end or impacts",
             steps, fc_step_limit(p), FC_STEPS_MAX);
    contact_reject(msg, len, "dt_max", p->model.dt_max, rule);
    return FC_EINVAL;
}

fc_status run_rows_check(const fc_params *p, double interval, double steps, char *msg, size_t len)
{
    char rule[256];
    double in_contact, span = least_span(p, &in_contact), rows = interval > 0.0 ? span / interval : steps;
    if (interval == FC_NO_ROWS || interval == FC_DEFAULT_ROWS)
        return FC_OK;
    if (!(interval >= 0.0) || isinf(interval)) {
        contact_reject(msg, len, "output_interval", interval,
                       "the time between rows must be finite and >= 0 [s] (0: a row every internal step)");
        return FC_EINVAL;
    }
    if (!(rows > FC_ROWS_MAX))
        return FC_OK;
    snprintf(rule, sizeof rule,
             "the time series would hold at least %.3g rows (%s over %.3g s), more than the %.0e a run keeps; "
             "raise output_interval, or lower t_end or impacts",
             rows, interval > 0.0 ? "one every output_interval" : "one every internal step", span, (double)FC_ROWS_MAX);
    contact_reject(msg, len, "output_interval", interval, rule);
    return FC_EINVAL;
}

fc_status fc_run_check(const fc_params *p, double output_interval, char *msg, size_t len)
{
    double steps, interval;
    if (fc_params_check(p, msg, len) != FC_OK)
        return FC_EINVAL;
    steps = least_steps(p);
    if (steps > FC_STEPS_MAX)
        return reject_steps(p, steps, msg, len);
    interval = output_interval == FC_DEFAULT_ROWS ? fc_default_output_interval(p) : output_interval;
    return run_rows_check(p, interval, steps, msg, len);
}

/* ------------------------------------------------------------ a run */

/* The progress callback comes after about this much work, in units of one
 * internal step of the compressed memory (the dearest step but the full G1
 * history's): well within a tenth of a second of CPU. */
#define PROGRESS_WORK 8192

/* An error-controlled step costs about this many units: the dashpot's
 * ESDIRK (seven stages) fewer, the springpot's Radau IIA (five coupled
 * stages and two passes over the modes) more. */
#define CONTROLLED_STEP_UNITS 4

typedef struct {
    fc_progress report; /* NULL: none */
    void *ctx;
    const contact_model *cm; /* the run's model, and the steps of it counted so far */
    int64_t counted;
    int64_t unit;       /* the work of one of its steps, and */
    int history;        /* whether they sum over the full G1 history */
    int64_t work, next; /* work done so far, and where the next call falls */
    int stopped;        /* the callback asked to stop */
    int64_t poll_at;    /* the model's step count at which the run asks again */
} watch;

static int stop_asked(watch *w, int64_t extra);

/* The model's poll inside a long advance. */
static int poll_run(void *ctx)
{
    return stop_asked(ctx, 0);
}

/* Watches the run of the model cm from its start. */
static void watch_run(watch *w, contact_model *cm)
{
    w->cm = cm;
    w->counted = 0;
    w->poll_at = 0;
    w->unit = contact_error_controlled(&cm->p) ? CONTROLLED_STEP_UNITS : 1;
    w->history = contact_method(&cm->p) == CONTACT_METHOD_G1_HISTORY;
    if (w->report) {
        cm->poll = poll_run;
        cm->poll_ctx = w;
    }
}

/* The work of the run's steps from `before` to `after`. */
static int64_t work_of(const watch *w, int64_t before, int64_t after)
{
    return w->history ? (int64_t)contact_history_work((double)before, (double)after) : (after - before) * w->unit;
}

/* Counts the model's steps since the last count and `extra` work, and calls
 * the callback when it is due: 1 when it asks to stop. */
static int stop_asked(watch *w, int64_t extra)
{
    const contact_model *cm = w->cm;
    if (!w->report)
        return 0;
    w->work += work_of(w, w->counted, cm->s.steps) + extra;
    w->counted = cm->s.steps;
    if (w->work >= w->next) {
        w->next = w->work + PROGRESS_WORK;
        w->stopped = w->stopped || w->report(w->ctx, cm->s.t, cm->s.steps, cm->s.impacts) != 0;
    }
    /* the steps whose work reaches the next call; the full G1 history's
     * grow dearer, so it asks after each */
    w->poll_at = cm->s.steps + (w->history ? 1 : (w->next - w->work + w->unit - 1) / w->unit);
    return w->stopped;
}

/* Whether the run's loop asks stop_asked after a step: only where its
 * callback may be due, not at every step. */
static int stop_due(const watch *w)
{
    return w->report && (w->stopped || w->cm->s.steps >= w->poll_at);
}

/* The model's state as a row of the time series. */
static void keep(series *s, const contact_model *cm)
{
    const double row[FC_COLUMNS] = {cm->s.t, cm->s.F, contact_total_indentation(cm), contact_elastic_indentation(cm),
                                    cm->s.x2, cm->s.v, cm->s.E_diss};
    series_add(s, row);
}

/* The copies of the model a run's rows are computed from (keep_rows_until),
 * each with its own compressed memory's block, allocated when the run
 * starts. */
typedef struct {
    contact_model snapshot, cursor, at;
} row_copies;

/* Room in the copies for the modes of *cm: 0, or -1 when memory runs out. */
static int row_copies_room(row_copies *c, const contact_model *cm)
{
    if (contact_copy_room(&c->snapshot, cm) != 0 || contact_copy_room(&c->cursor, cm) != 0)
        return -1;
    return contact_copy_room(&c->at, cm);
}

/* Rows at the output times k * interval in (from->s.t, t], each the model
 * advanced to that time from a copy of the state, so that what the rows
 * show never changes the steps the run takes. The copy is the last state
 * of the run's own steps before the row: out of contact a recovering
 * springpot's flight is one advance of many steps, which the rows retrace
 * once, step by step, not once a row. Their work counts towards w's. */
static void keep_rows_until(series *out, const contact_model *from, double t, double interval, int64_t *k, watch *w,
                            row_copies *c)
{
    contact_model *const cursor = &c->cursor, *const at = &c->at;
    int64_t steps = 0;
    contact_copy(cursor, from);
    cursor->poll = NULL; /* the run's: not the rows' steps */
    for (; interval > 0.0 && (double)*k * interval <= t && !out->failed; ++*k) {
        const double t_row = (double)*k * interval;
        for (;;) {
            contact_copy(at, cursor);
            if (!(t_row > at->s.t))
                break;
            if (isnan(contact_advance_until(at, t_row - at->s.t, CONTACT_FLIGHT_STEP)))
                return;
            steps += 1 + at->s.steps - cursor->s.steps;
            if (steps >= PROGRESS_WORK) {
                if (stop_asked(w, steps))
                    return;
                steps = 0;
            }
            if (!(at->s.t < t_row))
                break;
            contact_copy(cursor, at); /* a whole step of the run's short of the row */
        }
        keep(out, at);
    }
    stop_asked(w, steps);
}

/* The full G1 history lives on its grid and cannot be copied cheaply: its
 * rows are the grid points at or just after the output times. */
static int rows_on_grid(const contact_params *q)
{
    return contact_method(q) == CONTACT_METHOD_G1_HISTORY;
}

static void keep_grid_rows_until(series *out, const contact_model *cm, double interval, int64_t *k)
{
    if (!(interval > 0.0 && (double)*k * interval <= cm->s.t))
        return;
    keep(out, cm);
    *k = (int64_t)floor(cm->s.t / interval) + 1;
}

/* Why the run stops here, if it does; `slack`: how far short of t_end the
 * run may stop (on a grid of dt_max, the steps' summed times fall short of
 * it by rounding). */
static int why_stop(const fc_params *p, const contact_model *cm, double slack)
{
    if (cm->s.impacts >= p->impacts)
        return FC_STOP_IMPACTS;
    if (cm->s.t >= p->t_end - slack)
        return FC_STOP_T_END;
    if (cm->s.in_contact)
        return contact_rests(cm) ? FC_STOP_RESTING : 0;
    return contact_never_returns(cm) ? FC_STOP_RECEDING : 0;
}

static void summarize(const contact_model *cm, fc_outcome *o)
{
    o->impacts = cm->s.impacts;
    o->steps = cm->s.steps;
    o->F_peak = cm->s.F_peak;
    o->eps = cm->s.eps;
    o->t_contact = cm->s.t_contact;
    o->E_diss = cm->s.E_diss;
    o->t = cm->s.t;
    o->x = contact_total_indentation(cm);
    o->x1 = contact_elastic_indentation(cm);
    o->x2 = cm->s.x2;
    o->v = cm->s.v;
    o->k = cm->k;
}

/* The impact that has just ended, its dissipation counted from its onset,
 * and the dent where it ended. */
static fc_impact finished_impact(const contact_model *cm, double E_diss_onset)
{
    const contact_state *s = &cm->s;
    fc_impact done;
    done.t_onset = s->t_onset;
    done.v_onset = s->v_onset;
    done.F_peak = s->F_peak_contact;
    done.eps = s->eps;
    done.t_contact = s->t_contact;
    done.x2_end = contact_x2_end(cm);
    done.E_diss = s->E_diss - E_diss_onset;
    return done;
}

/* Why the time series stopped growing. */
static fc_status rows_failed(const series *out, double interval, double t, char *msg, size_t len)
{
    char rule[256];
    if (out->n < (size_t)FC_ROWS_MAX) {
        contact_reject(msg, len, "rows", (double)out->n, "out of memory for the time series");
        return FC_ENOMEM;
    }
    snprintf(rule, sizeof rule, "the time series reached the %.0e rows a run keeps at t = %.6g s; raise output_interval, "
             "or lower t_end or impacts", (double)FC_ROWS_MAX, t);
    contact_reject(msg, len, "output_interval", interval, rule);
    return FC_ENOMEM;
}

/* Ends a run where cm is (with a message already written if it failed). */
static fc_status finish(contact_model *cm, row_copies *c, fc_outcome *o, fc_status status)
{
    summarize(cm, o);
    contact_release(cm);
    contact_release_modes(&c->snapshot);
    contact_release_modes(&c->cursor);
    contact_release_modes(&c->at);
    return o->status = status;
}

/* The run behind fc_run and fc_run_batch: out may be NULL (no rows), and
 * impacts NULL (only the first is kept, in r->outcome.first). */
static fc_status run(const fc_params *p, double interval, series *out, impact_list *impacts, watch *w,
                     contact_kernel *kernel, fc_outcome *o, char *msg, size_t len)
{
    const contact_params *q = &p->model;
    static const contact_modes no_modes;
    contact_model cm;
    row_copies copies;
    double E_diss_onset = 0.0;
    int64_t k = 1;
    int uniform, grid;
    double dt, v, m;
    memset(o, 0, sizeof *o);
    if (fc_run_check(p, out ? interval : FC_NO_ROWS, msg, len) != FC_OK)
        return o->status = FC_EINVAL;
    fc_striker(p, &v, &m);
    dt = contact_step_limit(q);
    copies.snapshot.modes = copies.cursor.modes = copies.at.modes = no_modes;
    uniform = contact_steps_uniformly(q);
    grid = rows_on_grid(q);
    if (contact_start_with(&cm, q, v, m, kernel) != 0
        || (out && interval > 0.0 && !grid && row_copies_room(&copies, &cm) != 0)) {
        contact_reject(msg, len, "memory", (double)q->memory, "out of memory for the springpot's modes");
        return finish(&cm, &copies, o, FC_ENOMEM);
    }
    watch_run(w, &cm);
    if (out)
        keep(out, &cm);
    while (!(o->stop = why_stop(p, &cm, uniform ? 1e-6 * dt : 0.0))) {
        const contact_state before = cm.s;
        double H = p->t_end - cm.s.t;
        int rows_inside;
        if (grid) {
            H = dt;
            if (contact_check_advance(&cm, H, msg, len) != 0)
                return finish(&cm, &copies, o, FC_EFAIL);
        } else if (cm.s.in_contact || uniform)
            H = fmin(H, dt);
        rows_inside = out && interval > 0.0 && !grid && (double)k * interval <= cm.s.t + H;
        if (rows_inside)
            contact_copy(&copies.snapshot, &cm); /* no G1 history in it */
        if (isnan(contact_advance_until(&cm, H, CONTACT_ONSET | CONTACT_SEPARATION))) {
            contact_reject(msg, len, "t", cm.s.t, "the state became non-finite in the step from here [s]");
            return finish(&cm, &copies, o, FC_EFAIL);
        }
        if (cm.s.in_contact && !before.in_contact)
            E_diss_onset = before.E_diss;
        if (cm.s.impacts > before.impacts) {
            fc_impact done = finished_impact(&cm, E_diss_onset);
            if (cm.s.impacts == 1)
                o->first = done;
            if (impacts && impact_list_add(impacts, &done) != 0) {
                contact_reject(msg, len, "impacts", (double)cm.s.impacts, "out of memory for the per-impact figures");
                return finish(&cm, &copies, o, FC_ENOMEM);
            }
        }
        if (out) {
            if (grid)
                keep_grid_rows_until(out, &cm, interval, &k);
            else if (rows_inside)
                keep_rows_until(out, &copies.snapshot, cm.s.t, interval, &k, w, &copies);
            if (interval == 0.0 || cm.s.in_contact != before.in_contact)
                keep(out, &cm);
            if (out->failed)
                break;
        }
        if (stop_due(w) && stop_asked(w, 0)) {
            snprintf(msg, len, "stopped at t = %.17g s: the progress callback asked to stop", cm.s.t);
            return finish(&cm, &copies, o, FC_ESTOPPED);
        }
    }
    if (out) {
        keep(out, &cm);
        if (out->failed)
            return finish(&cm, &copies, o, rows_failed(out, interval, cm.s.t, msg, len));
    }
    return finish(&cm, &copies, o, FC_OK);
}

fc_status fc_run_with_progress(const fc_params *p, double output_interval, fc_progress progress, void *ctx,
                               fc_result *r, char *msg, size_t len)
{
    series rows = {NULL, 0, 0, 0};
    impact_list impacts = {NULL, 0, 0};
    watch w = {progress, ctx, NULL, 0, 1, 0, 0, PROGRESS_WORK, 0, 0};
    fc_status status;
    double interval = output_interval == FC_DEFAULT_ROWS ? fc_default_output_interval(p) : output_interval;
    memset(r, 0, sizeof *r);
    status = run(p, interval, interval == FC_NO_ROWS ? NULL : &rows, &impacts, &w, NULL, &r->outcome, msg, len);
    if (rows.failed) { /* no half of a time series */
        free(rows.rows);
        rows.rows = NULL;
        rows.n = 0;
    }
    r->per_impact = impacts.list;
    r->n_impacts = impacts.n;
    r->rows = rows.rows;
    r->n_rows = rows.n;
    return status;
}

fc_status fc_run(const fc_params *p, double output_interval, fc_result *r, char *msg, size_t len)
{
    return fc_run_with_progress(p, output_interval, NULL, NULL, r, msg, len);
}

void fc_result_free(fc_result *r)
{
    free(r->per_impact);
    free(r->rows);
    memset(r, 0, sizeof *r);
}

/* A batch's callback as a run's: the cases finished so far, of n. */
typedef struct {
    fc_batch_progress report;
    void *ctx;
    size_t done, n;
} batch_watch;

static int batch_progress(void *ctx, double t, int64_t steps, int64_t impacts)
{
    batch_watch *b = ctx;
    (void)t, (void)steps, (void)impacts;
    return b->report(b->ctx, b->done, b->n);
}

fc_status fc_run_batch_with_progress(size_t n, const fc_params *params, fc_outcome *out, fc_batch_progress progress,
                                     void *ctx)
{
    char why[FC_MESSAGE_SIZE];
    batch_watch b = {progress, ctx, 0, n};
    watch w = {progress ? batch_progress : NULL, &b, NULL, 0, 1, 0, 0, PROGRESS_WORK, 0, 0};
    fc_status first = FC_OK, status = FC_OK;
    contact_kernel kernel; /* runs alike share their springpot's kernel */
    size_t i;
    kernel.floor = 0.0;
    for (i = 0; i < n && status != FC_ESTOPPED; i++) {
        b.done = i;
        status = run(&params[i], FC_NO_ROWS, NULL, NULL, &w, &kernel, &out[i], why, sizeof why);
        if (first == FC_OK)
            first = status;
        if (status != FC_ESTOPPED && progress && progress(ctx, i + 1, n) != 0 && i + 1 < n)
            status = FC_ESTOPPED;
    }
    for (; i < n; i++) { /* not run */
        memset(&out[i], 0, sizeof out[i]);
        out[i].status = FC_ESTOPPED;
    }
    return status == FC_ESTOPPED ? FC_ESTOPPED : first;
}

fc_status fc_run_batch(size_t n, const fc_params *params, fc_outcome *out)
{
    return fc_run_batch_with_progress(n, params, out, NULL, NULL);
}
