#include "anchor.h"

#include <math.h>
#include <string.h>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

/* Events are located to 1e-7 of the time since onset: t_contact then errs
 * by at most 1e-7, ten times below the 1e-6 asked of the figures. The other
 * figures need far less: at separation F = 0, so v and x2 stand still to
 * first order (x2' = F/c, v' = -F/m), and at the peak F' = 0, so F errs by
 * (F''/2) dt^2: about 1e-14 of F_peak in the h20 impact. */
#define EVENT_TIME_TOLERANCE 1e-7

typedef struct {
    double k, inv_c, inv_m;
    long evaluations;
} anchor_ode;

static double hertz_force(const anchor_ode *o, double x1)
{
    return x1 > 0.0 ? o->k * x1 * sqrt(x1) : 0.0;
}

/* y = (x1, x2, v): x1' = v - F/c, x2' = F/c, v' = -F/m. The elastic
 * indentation is a state of its own, not x - x2: under a soft dashpot x1 is
 * a thousandth of x, and the difference would lose three digits of it. */
static int anchor_rhs(double t, const double y[], double f[], void *params)
{
    anchor_ode *o = params;
    double F = hertz_force(o, y[0]);
    (void)t;
    o->evaluations++;
    f[0] = y[2] - F * o->inv_c;
    f[1] = F * o->inv_c;
    f[2] = -F * o->inv_m;
    return GSL_SUCCESS;
}

/* The force peaks where the indentation rate x1' falls through 0 (which =
 * 1); the striker separates where x1 does (which = 0). */
static double event_value(const anchor_ode *o, int which, const double y[3])
{
    return which == 0 ? y[0] : y[2] - hertz_force(o, y[0]) * o->inv_c;
}

/* The zero of event `which` inside the step (t0, t0 + h], from y0 = y(t0)
 * with g0 and g1 its values at both ends: secant iterations, each one rk8pd
 * step of length tau from y0 (the derivative there computed once). y is
 * y(t0 + h) on entry and y(t0 + tau) on return; returns tau. */
static double locate_event(gsl_odeiv2_step *step, const gsl_odeiv2_system *sys, double t0, const double y0[3],
                           double h, double g0, double g1, int which, double y[3])
{
    double a = 0.0, b = h, ga = g0, gb = g1, dydt0[3], yerr[3];
    double tol = EVENT_TIME_TOLERANCE * (t0 + h);
    int i;
    anchor_rhs(t0, y0, dydt0, sys->params);
    for (i = 0; i < 60 && fabs(b - a) > tol && gb != 0.0 && gb != ga; i++) {
        double tau = fmin(fmax(b - gb * (b - a) / (gb - ga), 0.0), h);
        memcpy(y, y0, 3 * sizeof *y);
        gsl_odeiv2_step_apply(step, t0, tau, y, yerr, dydt0, NULL, sys);
        a = b;
        ga = gb;
        b = tau;
        gb = event_value(sys->params, which, y);
    }
    return b;
}

int anchor_impact(const anchor_problem *p, anchor_result *r)
{
    anchor_ode o = {p->k, 1.0 / p->c, 1.0 / p->m, 0};
    gsl_odeiv2_system sys = {anchor_rhs, NULL, 3, &o};
    /* The elastic Hertz impact's largest indentation (docs/model.md §2) and its
     * time scale: the contact lasts 2.94 of them without the dashpot. */
    double x_hertz = pow(5.0 * p->m * p->v0 * p->v0 / (4.0 * p->k), 0.4), t_scale = x_hertz / p->v0;
    /* An absolute error per component, rtol times its scale (x_hertz for the
     * indentations, v0 for the velocity), on top of rtol times its value: a
     * test relative alone would ask for exact x1 and v where they pass through
     * zero (onset, separation, the striker turning back). */
    const double scale[3] = {x_hertz, x_hertz, p->v0};
    gsl_odeiv2_step *step = gsl_odeiv2_step_alloc(gsl_odeiv2_step_rk8pd, 3);
    gsl_odeiv2_control *control = gsl_odeiv2_control_scaled_new(p->rtol, p->rtol, 1.0, 0.0, scale, 3);
    gsl_odeiv2_evolve *evolve = gsl_odeiv2_evolve_alloc(3);
    /* A first guess of the step, a hundredth of the time scale: the control
     * shrinks it or grows it (up to fivefold a step) from there. */
    double y[3] = {0.0, 0.0, p->v0}, t = 0.0, h = 1e-2 * t_scale;
    int status = step && control && evolve ? GSL_SUCCESS : GSL_ENOMEM;
    gsl_error_handler_t *previous = gsl_set_error_handler_off(); /* a status, not an abort */

    memset(r, 0, sizeof *r);
    while (status == GSL_SUCCESS && t < p->t_end) {
        double t0 = t, y0[3], rate0 = event_value(&o, 1, y);
        memcpy(y0, y, sizeof y0);
        status = gsl_odeiv2_evolve_apply(evolve, control, step, &sys, &t, p->t_end, &h, y);
        if (status != GSL_SUCCESS)
            break;
        r->steps++;
        r->F_peak = fmax(r->F_peak, hertz_force(&o, y[0]));
        if (rate0 > 0.0 && !(event_value(&o, 1, y) > 0.0)) {
            double yp[3];
            memcpy(yp, y, sizeof yp);
            locate_event(step, &sys, t0, y0, t - t0, rate0, event_value(&o, 1, y), 1, yp);
            r->F_peak = fmax(r->F_peak, hertz_force(&o, yp[0]));
        }
        if (y[0] <= 0.0 && event_value(&o, 1, y) < 0.0) {
            t = t0 + locate_event(step, &sys, t0, y0, t - t0, y0[0], y[0], 0, y);
            r->separated = 1;
            r->t_contact = t;
            r->eps = -y[2] / p->v0;
            r->x2_end = y[1];
            break;
        }
    }
    r->t = t;
    r->x1 = r->separated ? 0.0 : y[0];
    r->x2 = y[1];
    r->v = y[2];
    r->F = hertz_force(&o, r->x1);
    r->evaluations = o.evaluations;
    r->rejected = evolve ? (long)evolve->failed_steps : 0;
    gsl_odeiv2_evolve_free(evolve);
    gsl_odeiv2_control_free(control);
    gsl_odeiv2_step_free(step);
    gsl_set_error_handler(previous);
    return status;
}
