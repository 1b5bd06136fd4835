/* The energy account of a proxy striker's coupling and the correction that
 * keeps the coupling from creating energy (docs/model.md §17): once per
 * communication step, from the inputs at its ends and the proxy's motion
 * over it; nothing in the internal steps. */
#include <float.h>
#include <math.h>

#include "contact.h"

/* The bodies' displacement over an interval of length H: Hermite's
 * quadrature of their approach speed, whose rate a - F/m is known at both
 * ends with the held force F the same there (so it cancels). */
static double displacement(double H, double u_start, double u_end, double a_start, double a_end)
{
    return 0.5 * H * (u_start + u_end) + H * H * (a_start - a_end) / 12.0;
}

/* The energy the open interval creates and does not return, the bodies
 * ending it at (u_end, a_end): the proxy's kinetic energy given up, plus
 * the work its held acceleration does on the bodies' path less that
 * acceleration's own change, less the work the bodies do on the contact,
 * less the work the change of a does against the force the contact holds
 * at the end. With a constant a, and the proxy's velocities those the held
 * force gives the bodies, the terms cancel exactly. */
static double secular(const coupling_energy *e, double m, double u_end, double a_end)
{
    const double H = e->H, dx = displacement(H, e->u, u_end, e->a, a_end), da = a_end - e->a;
    return m * (0.5 * (e->u0 - e->u1) * (e->u0 + e->u1) + e->a * (dx - da * H * H / 6.0)) - e->F * dx
           - e->F_end * da * H * H / 12.0;
}

void coupling_energy_open(coupling_energy *e, double H, double u, double a, double F)
{
    e->H = H;
    e->u = u;
    e->a = a;
    e->F = F;
    e->open = 1;
}

void coupling_energy_proxy(coupling_energy *e, const contact_model *cm, const contact_state *from,
                           const contact_state *to, double J, double w0, double w1)
{
    /* the end velocity the impulse gives (a multistep scheme's own may
     * differ from it by its truncation error, which is no energy the
     * bodies see) */
    const double v1 = from->v + e->H * cm->accel - J * cm->inv_m;
    e->u0 = from->v + w0;
    e->u1 = v1 + w1;
    e->F_end = to->F;
    e->dx = (to->x1 + to->x2) - (from->x1 + from->x2);
    e->ends_free = !to->in_contact;
    e->scale = 0.5 * (e->u0 * e->u0 + e->u1 * e->u1) / cm->inv_m;
}

/* The proxy's own work on the contact over the open interval, by its
 * equation of motion (m v' = m a - F, a held), less what secular() counts
 * of it: the held acceleration's work on the proxy's own path instead of
 * the bodies' (the two paths part while the force changes within a step,
 * and meet again only where it is smooth); 0 with a constant a and no
 * force. The owed impulse's share is counted where the proxy restarts. */
static double lag(const coupling_energy *e, double m, double dx_bodies, double da)
{
    return m * e->a * (e->dx - dx_bodies + da * e->H * e->H / 6.0) + e->F_end * da * e->H * e->H / 12.0;
}

/* Adds the open interval's share of the lag and, where the contact is
 * over at its end, the whole lag to what was created: the proxy's work
 * is then all the contact has taken, less what the bodies gave it. */
static void add_lag(coupling_energy *e, double m, double dx_bodies, double da)
{
    const double share = lag(e, m, dx_bodies, da);
    e->lag += share;
    e->rounding += fabs(m * e->a * e->dx) + fabs(share);
    if (e->ends_free) {
        e->created += e->lag;
        e->lag = 0.0;
    }
}

void coupling_energy_close(coupling_energy *e, double m, double u, double a)
{
    double dx;
    if (!e->open)
        return;
    dx = displacement(e->H, e->u, u, e->a, a);
    e->created += secular(e, m, u, a);
    e->rounding += e->scale + fabs(e->F * dx);
    add_lag(e, m, dx, a - e->a);
    e->a_rate = (a - e->a) / e->H;
    e->a_unseen = (u - e->u) / e->H + e->F / m - 0.5 * (e->a + a);
    e->open = 0;
}

void coupling_energy_restart(coupling_energy *e, double owed, double dv)
{
    /* the secular terms count the owed impulse as taken at the bodies'
     * velocity, which the restart moves by dv against the proxy's */
    e->created -= owed * dv;
    e->rounding += fabs(owed * dv);
}

/* The bodies' acceleration apart from the contact at the open interval's
 * end, a's rate over the last closed interval carried on. */
static double end_accel(const coupling_energy *e)
{
    return e->a + e->H * e->a_rate;
}

/* The bodies' approach speed at the end of the open interval under the
 * force F: from its start, a, a's rate and the unseen acceleration. */
static double end_velocity(const coupling_energy *e, double m, double F)
{
    return e->u + e->H * (e->a + e->a_unseen + 0.5 * e->H * e->a_rate - F / m);
}

coupling_energy coupling_energy_predicted(const coupling_energy *e, double m)
{
    coupling_energy next = *e;
    const double u_end = end_velocity(e, m, e->F), a_end = end_accel(e);
    coupling_energy_close(&next, m, u_end, a_end); /* the rates it takes are e's again */
    next.u = u_end;
    next.a = a_end;
    return next;
}

/* The smallest change d of the force, in the sign of g (the direction in
 * which more force takes more work from the bodies), that brings an energy
 * E(d) = E - d g + c d^2 to 0 where E > 0; where no d does, the one that
 * comes closest. */
static double smallest_change(double E, double g, double c)
{
    const double disc = g * g - 4.0 * c * E;
    if (!(E > 0.0) || g == 0.0)
        return 0.0;
    return disc < 0.0 ? g / (2.0 * c) : 2.0 * E / (g + copysign(sqrt(disc), g));
}

/* A change d of the force F0 that never turns it round, but for a pull on
 * a proxy that ends the interval out of contact: the contact is over, and
 * a push could only give the separating bodies more energy. */
static double limited(double d, double F0, int ends_free)
{
    if (fabs(d) <= fabs(F0) || (ends_free && d < 0.0))
        return d;
    return copysign(fabs(F0), d);
}

/* The account adds terms of the size of the kinetic energies and works of
 * each interval (`rounding` sums them), each rounded to a few ulps, and
 * the bodies' velocities drift from the proxy's by an ulp a step: an
 * energy within ACCOUNT_ROUNDING of that sum cannot be told from 0 (two
 * free bodies, a constant acceleration), and is left alone. */
#define ACCOUNT_ROUNDING (16.0 * DBL_EPSILON)

/* The energy is quadratic in the force: with F = F0 + d the bodies'
 * displacement X - c F shortens by c d (c = H^2/(2m)); where the contact
 * ends within the interval, the lag's share takes back the held
 * acceleration's work on that displacement. */
double coupling_energy_correction(const coupling_energy *e, double m)
{
    const double F0 = e->F, H = e->H, c = 0.5 * H * H / m, a_end = end_accel(e);
    const double X = displacement(H, e->u, end_velocity(e, m, 0.0), e->a, a_end);
    const double noise = ACCOUNT_ROUNDING * (e->rounding + e->scale + fabs(F0 * (X - c * F0)));
    const double a_work = e->ends_free ? 0.0 : m * e->a * c;
    double created = e->created + secular(e, m, end_velocity(e, m, F0), a_end);
    if (e->ends_free)
        created += e->lag + lag(e, m, X - c * F0, a_end - e->a);
    return limited(smallest_change(created - noise, X + a_work - 2.0 * c * F0, c), F0, e->ends_free);
}
