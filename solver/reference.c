#include "reference.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>
#include <gsl/gsl_roots.h>

/* y = (x1, v, x2, E_diss): x1' = v - F/c, v' = accel - F/m, x2' = F/c,
 * E_diss' = F^2/c with F = K max(x1, 0)^n. */
typedef struct {
    double K, n, inv_c, inv_m, accel;
    long evaluations;
} ode;

static double force(const ode *o, double x1)
{
    if (!(x1 > 0.0))
        return 0.0;
    return o->n == 1.5 ? o->K * x1 * sqrt(x1) : o->K * pow(x1, o->n);
}

static int rhs(double t, const double y[], double f[], void *params)
{
    ode *o = params;
    double F = force(o, y[0]);
    (void)t;
    o->evaluations++;
    f[0] = y[1] - F * o->inv_c;
    f[1] = o->accel - o->inv_m * F;
    f[2] = F * o->inv_c;
    f[3] = F * F * o->inv_c;
    return GSL_SUCCESS;
}

static int jacobian(double t, const double y[], double *dfdy, double dfdt[], void *params)
{
    const ode *o = params;
    double x1 = y[0] > 0.0 ? y[0] : 0.0, F = force(o, y[0]), dF = o->n * o->K * pow(x1, o->n - 1.0);
    (void)t;
    memset(dfdy, 0, 16 * sizeof *dfdy);
    dfdy[0] = -dF * o->inv_c;
    dfdy[1] = 1.0;
    dfdy[4] = -o->inv_m * dF;
    dfdy[8] = dF * o->inv_c;
    dfdy[12] = 2.0 * F * dF * o->inv_c;
    memset(dfdt, 0, 4 * sizeof *dfdt);
    return GSL_SUCCESS;
}

/* x1 (which = 0) or its rate x1' (which = 1) at the state y. */
static double event_value(const ode *o, int which, const double y[4])
{
    return which == 0 ? y[0] : y[1] - force(o, y[0]) * o->inv_c;
}

typedef struct {
    gsl_odeiv2_driver *driver;
    ode *o;
    int status;
} integrator;

/* y1 = y(t1) from y0 = y(t0), from a fresh start so that the result depends
 * on t1 alone (root finding needs a function, not a history). */
static void integrate(integrator *in, double t0, const double y0[4], double t1, double y1[4])
{
    double t = t0;
    memcpy(y1, y0, 4 * sizeof *y1);
    if (t1 <= t0)
        return;
    gsl_odeiv2_driver_reset_hstart(in->driver, 1e-3 * (t1 - t0));
    if (in->status == GSL_SUCCESS)
        in->status = gsl_odeiv2_driver_apply(in->driver, &t, t1, y1);
}

typedef struct {
    integrator *in;
    double t0;
    const double *y0;
    int which;
} event_at;

static double event_function(double t1, void *params)
{
    const event_at *e = params;
    double y[4];
    integrate(e->in, e->t0, e->y0, t1, y);
    return event_value(e->in->o, e->which, y);
}

/* The time in (t0, t1] at which event `which` changes sign, given that it
 * does; Brent's method to within a few ulp of the time. */
static double event_time(integrator *in, double t0, const double y0[4], double t1, int which)
{
    event_at e = {in, t0, y0, which};
    gsl_function fn = {event_function, &e};
    gsl_root_fsolver *solver = gsl_root_fsolver_alloc(gsl_root_fsolver_brent);
    double lo = t0, hi = t1, root = t1;
    int i, status = GSL_CONTINUE;
    if (!solver || gsl_root_fsolver_set(solver, &fn, lo, hi) != GSL_SUCCESS) {
        gsl_root_fsolver_free(solver);
        return t1;
    }
    for (i = 0; i < 200 && status == GSL_CONTINUE; i++) {
        gsl_root_fsolver_iterate(solver);
        root = gsl_root_fsolver_root(solver);
        lo = gsl_root_fsolver_x_lower(solver);
        hi = gsl_root_fsolver_x_upper(solver);
        status = gsl_root_test_interval(lo, hi, 0.0, 4e-16);
    }
    gsl_root_fsolver_free(solver);
    return root;
}

/* Whether the dashpot's relaxation rate n (K/c) x1^(n-1), at the Hertz
 * indentation scale, is fast against the contact time scale. */
static int is_stiff(const ode *o, double v0, double x_ref)
{
    double lambda = o->n * o->K * o->inv_c * pow(x_ref, o->n - 1.0);
    return !(v0 > 0.0 && lambda * x_ref / v0 < 100.0);
}

/* Whether the striker, out of contact at y, never comes back (the model's
 * own test, on the reference's state). */
static int never_returns(contact_model *cm, const double y[4])
{
    cm->s.x1 = y[0];
    cm->s.v = y[1];
    cm->s.in_contact = 0;
    return contact_never_returns(cm);
}

/* Whether the striker, in contact at y, has come to rest for good (the
 * model's own test, on the reference's state). */
static int rests(contact_model *cm, const ode *o, const double y[4], double v_onset, double F_peak_contact)
{
    cm->s.in_contact = 1;
    cm->s.F = force(o, y[0]);
    cm->s.F_peak_contact = F_peak_contact;
    cm->s.v = y[1];
    cm->s.v_onset = v_onset;
    return contact_rests(cm);
}

/* Samples at k out_dt in (t, t1], integrated from the bracket's start; their
 * right-hand-side evaluations are not the solve's. */
static void sample_until(integrator *in, double t, const double y[4], double t1, double out_dt, long *k,
                         reference_sample sample, void *ctx)
{
    long evaluations = in->o->evaluations;
    for (; out_dt > 0.0 && (double)*k * out_dt <= t1; ++*k) {
        double tk = (double)*k * out_dt, yk[4];
        integrate(in, t, y, tk, yk);
        sample(ctx, tk, force(in->o, yk[0]), yk[0] + yk[2], yk[0] > 0.0 ? yk[0] : 0.0, yk[2], yk[1], yk[3]);
    }
    in->o->evaluations = evaluations;
}

static void sample_state(const ode *o, double t, const double y[4], reference_sample sample, void *ctx)
{
    sample(ctx, t, force(o, y[0]), y[0] + y[2], y[0] > 0.0 ? y[0] : 0.0, y[2], y[1], y[3]);
}

/* The brackets between two calls of the progress callback: a few
 * milliseconds of work at most. */
#define BRACKETS_PER_PROGRESS 64

int reference_solve(const fc_params *params, double rtol, double out_dt, reference_sample sample, void *ctx,
                    fc_progress progress, void *progress_ctx, impact_list *per_impact, reference_result *result,
                    char *msg, size_t len)
{
    fc_outcome *r = &result->outcome;
    const contact_params *p = &params->model;
    const double t_end = params->t_end;
    double v0, m;
    contact_model cm;
    ode o;
    integrator in;
    gsl_odeiv2_system sys;
    double scale[4], x_ref, t_ref, x_small, bracket, y[4], y1[4], t = 0.0;
    double v_onset, t_onset = 0.0, E_diss_onset = 0.0, F_peak_contact = 0.0;
    long k = 1, brackets = 0;
    int in_contact, out_of_memory = 0, stopped = 0;
    gsl_error_handler_t *previous = gsl_set_error_handler_off();

    fc_striker(params, &v0, &m);
    v_onset = v0;
    if (p->damper != CONTACT_DAMPER_DASHPOT) {
        snprintf(msg, len,
                 "--reference integrates the dashpot (damper = 1) only; a springpot has no ODE for GSL: compare "
                 "memory = 1 (the full G1 history) with memory = 2 instead");
        gsl_set_error_handler(previous);
        return -1;
    }
    contact_start(&cm, p, v0, m);
    o.K = contact_spring_stiffness(&cm, 0); /* the continuous law (N fixed, or N -> infinity) */
    o.n = p->spring_exponent;
    o.inv_c = cm.inv_c;
    o.inv_m = cm.inv_m;
    o.accel = cm.accel;
    o.evaluations = 0;
    memset(result, 0, sizeof *result);
    r->k = cm.k;

    /* Tolerance scales: the indentation where the contact first changes
     * character (elastic peak or dashpot take-over), its speed and energy;
     * never below 1e-280, so that the absolute tolerances stay above the
     * denormals when the striker barely moves (v0 = 5e-324). */
    contact_scales(p, o.K, v0, m, &x_ref, &t_ref, &x_small);
    if (!(x_small > 0.0) || !isfinite(x_small))
        x_small = p->gap0 > 0.0 ? p->gap0 : 1e-6;
    scale[0] = scale[2] = fmax(1e-3 * x_small, 1e-280);
    scale[1] = fmax(1e-3 * (fabs(v0) > 0.0 ? fabs(v0) : sqrt(fabs(p->g) * x_small) + 1e-9), 1e-280);
    scale[3] = fmax(1e-3 * o.K * pow(x_small, o.n + 1.0), 1e-280);
    result->stiff = is_stiff(&o, t_ref > 0.0 ? x_ref / t_ref : fabs(v0), t_ref > 0.0 ? x_ref : x_small);
    bracket = t_ref > 0.0 ? t_ref / 64.0 : 1e-6;

    sys.function = rhs;
    sys.jacobian = jacobian;
    sys.dimension = 4;
    sys.params = &o;
    in.o = &o;
    in.status = GSL_SUCCESS;
    in.driver = gsl_odeiv2_driver_alloc_scaled_new(&sys, result->stiff ? gsl_odeiv2_step_msbdf : gsl_odeiv2_step_rk8pd,
                                                   1e-12, rtol, rtol, 1.0, 0.0, scale);
    if (!in.driver) {
        snprintf(msg, len, "reference: GSL could not allocate its driver");
        gsl_set_error_handler(previous);
        return -1;
    }
    gsl_odeiv2_driver_set_nmax(in.driver, 0);

    y[0] = -p->gap0;
    y[1] = v0;
    y[2] = y[3] = 0.0;
    in_contact = y[0] >= 0.0 && (v0 > 0.0 || (v0 == 0.0 && o.accel > 0.0));
    if (sample)
        sample_state(&o, t, y, sample, ctx);
    while (in.status == GSL_SUCCESS && !out_of_memory && !stopped) {
        double t1;
        int event = 0;
        r->stop = r->impacts >= params->impacts ? FC_STOP_IMPACTS
                  : t >= t_end          ? FC_STOP_T_END
                  : !in_contact && never_returns(&cm, y) ? FC_STOP_RECEDING
                  : in_contact && rests(&cm, &o, y, v_onset, F_peak_contact) ? FC_STOP_RESTING
                                                                            : 0;
        if (r->stop)
            break;
        t1 = fmin(t + bracket, t_end);
        integrate(&in, t, y, t1, y1);
        if (!in_contact && y1[0] > 0.0) {           /* onset inside (t, t1] */
            t1 = event_time(&in, t, y, t1, 0);
            integrate(&in, t, y, t1, y1);
            y1[0] = 0.0;
            in_contact = event = 1;
            v_onset = y1[1];
            t_onset = t1;
            E_diss_onset = y1[3];
            F_peak_contact = 0.0;
        } else if (in_contact) {
            if (event_value(&o, 1, y) > 0.0 && event_value(&o, 1, y1) <= 0.0) { /* the force peaks */
                double tp = event_time(&in, t, y, t1, 1), yp[4];
                integrate(&in, t, y, tp, yp);
                F_peak_contact = fmax(F_peak_contact, force(&o, yp[0]));
            }
            /* separation inside (t, t1]: x1 falls to 0 on the way out (an
             * indentation that underflows on the way in is none) */
            if (y1[0] <= 0.0 && !(event_value(&o, 1, y1) > 0.0)) {
                fc_impact done;
                t1 = event_time(&in, t, y, t1, 0);
                integrate(&in, t, y, t1, y1);
                y1[0] = 0.0;
                in_contact = 0;
                event = 1;
                r->impacts++;
                r->eps = v_onset > 0.0 ? -y1[1] / v_onset : 0.0;
                r->t_contact = t1 - t_onset;
                done.t_onset = t_onset;
                done.v_onset = v_onset;
                done.F_peak = F_peak_contact;
                done.eps = r->eps;
                done.t_contact = r->t_contact;
                done.x2_end = y1[2];
                done.E_diss = y1[3] - E_diss_onset;
                if (r->impacts == 1)
                    r->first = done;
                out_of_memory = impact_list_add(per_impact, &done) != 0;
            }
            F_peak_contact = fmax(F_peak_contact, force(&o, y1[0]));
        }
        r->F_peak = fmax(r->F_peak, F_peak_contact);
        if (sample) {
            sample_until(&in, t, y, t1, out_dt, &k, sample, ctx);
            if (event || out_dt == 0.0)
                sample_state(&o, t1, y1, sample, ctx);
        }
        t = t1;
        memcpy(y, y1, sizeof y);
        stopped = progress && ++brackets % BRACKETS_PER_PROGRESS == 0
                  && progress(progress_ctx, t, o.evaluations, r->impacts) != 0;
    }
    if (sample)
        sample_state(&o, t, y, sample, ctx);
    r->t = t;
    r->v = y[1];
    r->x1 = y[0] > 0.0 ? y[0] : 0.0;
    r->x = y[0] + y[2];
    r->x2 = y[2];
    r->E_diss = y[3];
    r->steps = o.evaluations;
    r->status = stopped ? FC_ESTOPPED : in.status == GSL_SUCCESS && !out_of_memory ? FC_OK : FC_EFAIL;
    gsl_odeiv2_driver_free(in.driver);
    gsl_set_error_handler(previous);
    if (out_of_memory) {
        snprintf(msg, len, "reference: out of memory for the per-impact figures");
        return -1;
    }
    if (stopped) {
        snprintf(msg, len, "stopped at t = %.17g s: the progress callback asked to stop", t);
        return -1;
    }
    if (in.status != GSL_SUCCESS) {
        snprintf(msg, len, "reference: GSL's integrator failed at t = %.9g s (%s)", t, gsl_strerror(in.status));
        return -1;
    }
    return 0;
}
