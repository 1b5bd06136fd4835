#include "fraccontact.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "contact.h"
#include "run.h"

#define AT(name) offsetof(fc_params, name)

static const fc_parameter parameters[] = {
    {"v", FC_REAL, AT(v), "m/s", "striker velocity towards the specimen; driven scene: the indentation rate"},
    {"m", FC_REAL, AT(m), "kg", "striker mass; driven scene: 0 = no inertia"},
    {"R", FC_REAL, AT(R), "m", "striker tip radius (used only with k = 0)"},
    {"E_i", FC_REAL, AT(E_i), "Pa", "indenter Young's modulus (used only with k = 0)"},
    {"nu_i", FC_REAL, AT(nu_i), "1", "indenter Poisson ratio (used only with k = 0)"},
    {"E_s", FC_REAL, AT(E_s), "Pa", "specimen Young's modulus (used only with k = 0)"},
    {"nu_s", FC_REAL, AT(nu_s), "1", "specimen Poisson ratio (used only with k = 0)"},
    {"k", FC_REAL, AT(k), "N/m1.5",
     "spring constant [N/m^n]; 0 derives the Hertz constant from R, E_i, nu_i, E_s, nu_s (n = 1.5 only); any "
     "other value wins over them"},
    {"spring_exponent", FC_REAL, AT(spring_exponent), "1",
     "n in F = k x1^n: 1.5 Hertz sphere, 1 linear spring (flat punch), 2 cone-like tip"},
    {"c", FC_REAL, AT(c), "N.s/m", "dashpot constant (damper 1)"},
    {"damper_order", FC_REAL, AT(damper_order), "1", "the springpot's order alpha in (0, 1]; 1 is a dashpot (damper 2)"},
    {"c_alpha", FC_REAL, AT(c_alpha), "N.s^alpha/m", "springpot constant: F = c_alpha D^alpha x2 (damper 2)"},
    {"memory_tolerance", FC_REAL, AT(memory_tolerance), "1",
     "relative error of the compressed memory's kernel, from the fixed step (error-controlled steps: from min(dt_max, "
     "1e-9 s)) to 1000 s (memory 2)"},
    {"tolerance", FC_REAL, AT(tolerance), "1",
     "relative error per internal step (error-controlled ESDIRK steps, capped by dt_max only when dt_max > 0); 0 = "
     "fixed steps of dt_max"},
    {"dt_max", FC_REAL, AT(dt_max), "s",
     "largest internal step; 0 = fixed steps of 1e-7 s and no cap on error-controlled steps; in contact, where fewer "
     "than 6 fixed steps would fit in the time the spring takes to stop the striker, they are 4000 in that time"},
    {"g", FC_REAL, AT(g), "m/s2", "acceleration of the striker towards the specimen (9.81 for gravity)"},
    {"gap0", FC_REAL, AT(gap0), "m", "gap between striker and specimen at t = 0"},
    {"t_end", FC_REAL, AT(t_end), "s", "stop at this time if the run has not stopped before"},
    {"law", FC_INTEGER, AT(law), "1", "spring law: 1 G1 history sum, 2 closed-form Hertz, 3 G1 with Richardson extrapolation"},
    {"g1_nodes", FC_INTEGER, AT(g1_nodes), "1", "G1 intervals N; 0: internal steps since contact onset"},
    {"scene", FC_INTEGER, AT(scene), "1", "1 drop test (a free striker), 2 driven (the rate v prescribed)"},
    {"scheme", FC_INTEGER, AT(scheme), "1", "1 SDIRK2 (implicit, L-stable), 2 the paper's explicit central differences"},
    {"damper", FC_INTEGER, AT(damper), "1", "1 dashpot F = c x2', 2 springpot F = c_alpha D^alpha x2 (fractional memory)"},
    {"memory", FC_INTEGER, AT(memory), "1",
     "the springpot's memory: 1 full G1 history (steps of dt_max, O(N) each), 2 compressed (sum of exponentials)"},
    {"impacts", FC_INTEGER, AT(impacts), "1", "stop right after this many impacts have ended"},
};

#define N_PARAMETERS (sizeof parameters / sizeof parameters[0])

size_t fc_parameter_count(void) { return N_PARAMETERS; }

const fc_parameter *fc_parameter_at(size_t i) { return i < N_PARAMETERS ? &parameters[i] : NULL; }

size_t fc_params_size(void) { return sizeof(fc_params); }

size_t fc_outcome_size(void) { return sizeof(fc_outcome); }

void fc_model_params(const fc_params *p, contact_params *q)
{
    q->R = p->R;
    q->E_i = p->E_i;
    q->nu_i = p->nu_i;
    q->E_s = p->E_s;
    q->nu_s = p->nu_s;
    q->k = p->k;
    q->spring_exponent = p->spring_exponent;
    q->c = p->c;
    q->damper_order = p->damper_order;
    q->c_alpha = p->c_alpha;
    q->memory_tolerance = p->memory_tolerance;
    q->tolerance = p->tolerance;
    q->dt_max = p->dt_max;
    q->g = p->g;
    q->gap0 = p->gap0;
    q->law = p->law;
    q->g1_nodes = p->g1_nodes;
    q->scene = p->scene;
    q->scheme = p->scheme;
    q->damper = p->damper;
    q->memory = p->memory;
}

void fc_params_default(fc_params *p)
{
    contact_params q;
    memset(p, 0, sizeof *p);
    contact_default_params(&q);
    contact_default_striker(&p->v, &p->m);
    p->R = q.R;
    p->E_i = q.E_i;
    p->nu_i = q.nu_i;
    p->E_s = q.E_s;
    p->nu_s = q.nu_s;
    p->k = q.k;
    p->spring_exponent = q.spring_exponent;
    p->c = q.c;
    p->damper_order = q.damper_order;
    p->c_alpha = q.c_alpha;
    p->memory_tolerance = q.memory_tolerance;
    p->tolerance = q.tolerance;
    p->dt_max = q.dt_max;
    p->g = q.g;
    p->gap0 = q.gap0;
    p->law = q.law;
    p->g1_nodes = q.g1_nodes;
    p->scene = q.scene;
    p->scheme = q.scheme;
    p->damper = q.damper;
    p->memory = q.memory;
    p->t_end = 1.0;
    p->impacts = 1;
}

fc_status fc_params_check(const fc_params *p, char *msg, size_t len)
{
    contact_params q;
    fc_model_params(p, &q);
    if (contact_check_params(&q, msg, len) != 0 || contact_check_striker(&q, q.scene, p->v, p->m, msg, len) != 0
        || contact_check_resolution(&q, p->v, p->m, msg, len) != 0)
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
    if (contact_check_history_span(&q, p->v, p->m, p->t_end, p->impacts == 1 || !(p->g > 0.0), "t_end", msg, len)
        != 0)
        return FC_EINVAL;
    return FC_OK;
}

size_t fc_memory_kernel(const fc_params *p, size_t max, double *a, double *b, double *eta, char *msg, size_t len)
{
    contact_params q;
    contact_model cm;
    size_t i;
    if (fc_params_check(p, msg, len) != FC_OK)
        return 0;
    fc_model_params(p, &q);
    q.damper = CONTACT_DAMPER_SPRINGPOT;
    q.memory = CONTACT_MEMORY_COMPRESSED;
    memset(&cm, 0, sizeof cm);
    contact_configure(&cm, &q);
    if (cm.modes.modes <= max)
        for (i = 0; i < cm.modes.modes; i++) {
            a[i] = cm.modes.a[i];
            b[i] = cm.modes.b[i];
        }
    *eta = cm.modes.eta;
    return cm.modes.modes;
}

double fc_step_limit(const fc_params *p)
{
    contact_params q;
    fc_model_params(p, &q);
    return contact_step_limit(&q);
}

double fc_drop_velocity(double height)
{
    return sqrt(2.0 * 9.81 * height);
}

int fc_params_warning(const fc_params *p, char *msg, size_t len)
{
    contact_params q;
    fc_model_params(p, &q);
    return contact_unused_value(&q, msg, len) || contact_step_warning(&q, p->v, p->m, msg, len);
}

int fc_error_controlled(const fc_params *p)
{
    contact_params q;
    fc_model_params(p, &q);
    return contact_error_controlled(&q);
}

/* t_c v / x_max of an elastic impact on the spring k x1^n (MODEL.md §2):
 * 2 integral_0^1 (1 - u^(n+1))^(-1/2) du = 2/(n+1) B(1/(n+1), 1/2). */
static double elastic_contact_time(double n)
{
    const double e = 1.0 / (n + 1.0);
    return 2.0 * e * tgamma(e) * tgamma(0.5) / tgamma(e + 0.5);
}

double fc_default_output_interval(const fc_params *p)
{
    contact_params q;
    contact_model cm;
    double x_ref, t_ref, x_small;
    if (p->scene == CONTACT_SCENE_DRIVEN && !(p->m > 0.0)) /* one contact, as long as the run */
        return p->t_end / 1000.0;
    fc_model_params(p, &q);
    contact_start(&cm, &q, p->v, p->m);
    contact_scales(&q, contact_spring_stiffness(&cm, 0), p->v, p->m, &x_ref, &t_ref, &x_small);
    return t_ref > 0.0 ? elastic_contact_time(p->spring_exponent) * t_ref / 256.0 : p->t_end / 1000.0;
}

/* ------------------------------------------------------------ a run */

/* The model's state as a row of the time series. */
static void keep(series *s, const contact_model *cm)
{
    const double row[FC_COLUMNS] = {cm->s.t, cm->s.F, contact_total_indentation(cm), contact_elastic_indentation(cm),
                                    cm->s.x2, cm->s.v, cm->s.E_diss};
    series_add(s, row);
}

/* Rows at the output times k * interval in (before->s.t, t], each the model
 * advanced from `before` to that time: what the rows show never changes the
 * steps the run takes. */
static void keep_rows_until(series *out, const contact_model *before, double t, double interval, int64_t *k)
{
    for (; interval > 0.0 && (double)*k * interval <= t; ++*k) {
        contact_model at = *before;
        double tau = (double)*k * interval - before->s.t;
        if (tau > 0.0 && isnan(contact_advance(&at, tau)))
            return;
        keep(out, &at);
    }
}

/* The full G1 history lives on its grid and cannot be copied cheaply: its
 * rows are the grid points at or just after the output times. */
static int rows_on_grid(const contact_params *q)
{
    return q->damper == CONTACT_DAMPER_SPRINGPOT && q->memory == CONTACT_MEMORY_G1;
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

/* The impact that has just ended, its dissipation counted from its onset;
 * the dent where it ended (the full G1 history ends a contact on its grid,
 * a fraction of a step later: x2 there, less its rate over that fraction). */
static fc_impact finished_impact(const contact_model *cm, double E_diss_onset)
{
    const contact_state *s = &cm->s;
    fc_impact done;
    done.t_onset = s->t_onset;
    done.v_onset = s->v_onset;
    done.F_peak = s->F_peak_contact;
    done.eps = s->eps;
    done.t_contact = s->t_contact;
    done.x2_end = s->x2 - contact_damper_rate(cm) * (s->t - (s->t_onset + s->t_contact));
    done.E_diss = s->E_diss - E_diss_onset;
    return done;
}

/* Ends a run where cm is (with a message already written if it failed). */
static fc_status finish(contact_model *cm, fc_outcome *o, fc_status status)
{
    summarize(cm, o);
    contact_release(cm);
    return o->status = status;
}

/* The run behind fc_run and fc_run_batch: out may be NULL (no rows), and
 * impacts NULL (only the first is kept, in r->outcome.first). */
static fc_status run(const fc_params *p, double interval, series *out, impact_list *impacts,
                     fc_progress progress, void *ctx, fc_outcome *o, char *msg, size_t len)
{
    contact_params q;
    contact_model cm, snapshot;
    double E_diss_onset = 0.0;
    int64_t k = 1, reported = 0;
    int uniform, grid;
    double dt;
    memset(o, 0, sizeof *o);
    if (fc_params_check(p, msg, len) != FC_OK)
        return o->status = FC_EINVAL;
    fc_model_params(p, &q);
    dt = contact_step_limit(&q);
    contact_start(&cm, &q, p->v, p->m);
    uniform = contact_steps_uniformly(&cm);
    grid = rows_on_grid(&q);
    if (out)
        keep(out, &cm);
    while (!(o->stop = why_stop(p, &cm, uniform ? 1e-6 * dt : 0.0))) {
        const contact_state before = cm.s;
        double H = p->t_end - cm.s.t;
        int rows_inside;
        if (grid) {
            H = dt;
            if (contact_check_advance(&cm, H, msg, len) != 0)
                return finish(&cm, o, FC_EFAIL);
        } else if (cm.s.in_contact || uniform)
            H = fmin(H, dt);
        rows_inside = out && interval > 0.0 && !grid && (double)k * interval <= cm.s.t + H;
        if (rows_inside)
            snapshot = cm; /* no G1 history in it: a plain copy */
        if (isnan(contact_advance_until(&cm, H, CONTACT_ONSET | CONTACT_SEPARATION))) {
            contact_reject(msg, len, "t", cm.s.t, "the state became non-finite in the step from here [s]");
            return finish(&cm, o, FC_EFAIL);
        }
        if (cm.s.in_contact && !before.in_contact)
            E_diss_onset = before.E_diss;
        if (cm.s.impacts > before.impacts) {
            fc_impact done = finished_impact(&cm, E_diss_onset);
            if (cm.s.impacts == 1)
                o->first = done;
            if (impacts && impact_list_add(impacts, &done) != 0) {
                contact_reject(msg, len, "impacts", (double)cm.s.impacts, "out of memory for the per-impact figures");
                return finish(&cm, o, FC_ENOMEM);
            }
        }
        if (out) {
            if (grid)
                keep_grid_rows_until(out, &cm, interval, &k);
            else if (rows_inside)
                keep_rows_until(out, &snapshot, cm.s.t, interval, &k);
            if (interval == 0.0 || cm.s.in_contact != before.in_contact)
                keep(out, &cm);
        }
        if (progress && cm.s.steps - reported >= 65536) {
            reported = cm.s.steps;
            progress(ctx, cm.s.t, cm.s.steps, cm.s.impacts);
        }
    }
    if (out) {
        keep(out, &cm);
        if (out->failed) {
            contact_reject(msg, len, "rows", (double)out->n, "out of memory for the time series");
            return finish(&cm, o, FC_ENOMEM);
        }
    }
    return finish(&cm, o, FC_OK);
}

fc_status fc_run_with_progress(const fc_params *p, double output_interval, fc_progress progress, void *ctx,
                               fc_result *r, char *msg, size_t len)
{
    series rows = {NULL, 0, 0, 0};
    impact_list impacts = {NULL, 0, 0};
    fc_status status;
    double interval = output_interval == FC_DEFAULT_ROWS ? fc_default_output_interval(p) : output_interval;
    memset(r, 0, sizeof *r);
    status = run(p, interval, interval >= 0.0 ? &rows : NULL, &impacts, progress, ctx, &r->outcome, msg, len);
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

fc_status fc_run_batch(size_t n, const fc_params *params, fc_outcome *out)
{
    char why[FC_MESSAGE_SIZE];
    fc_status first = FC_OK;
    size_t i;
    for (i = 0; i < n; i++) {
        fc_status status = run(&params[i], FC_NO_ROWS, NULL, NULL, NULL, NULL, &out[i], why, sizeof why);
        if (first == FC_OK)
            first = status;
    }
    return first;
}
