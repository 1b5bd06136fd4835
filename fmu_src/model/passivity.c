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
    e->scale = 0.5 * (e->u0 * e->u0 + e->u1 * e->u1) / cm->inv_m;
}

void coupling_energy_close(coupling_energy *e, double m, double u, double a)
{
    double dx;
    if (!e->open)
        return;
    dx = displacement(e->H, e->u, u, e->a, a);
    e->created += secular(e, m, u, a);
    e->rounding += e->scale + fabs(e->F * dx);
    e->a_rate = (a - e->a) / e->H;
    e->a_unseen = (u - e->u) / e->H + e->F / m - 0.5 * (e->a + a);
    e->open = 0;
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

/* The account adds terms of the size of the kinetic energies and works of
 * each interval (`rounding` sums them), each rounded to a few ulps, and
 * the bodies' velocities drift from the proxy's by an ulp a step: an
 * energy within ACCOUNT_ROUNDING of that sum cannot be told from 0 (two
 * free bodies, a constant acceleration), and is left alone. */
#define ACCOUNT_ROUNDING (16.0 * DBL_EPSILON)

/* The energy is quadratic in the force: with F = F0 + d the bodies'
 * displacement X - c F shortens by c d (c = H^2/(2m)). */
double coupling_energy_correction(const coupling_energy *e, double m)
{
    const double F0 = e->F, H = e->H, c = 0.5 * H * H / m, a_end = end_accel(e);
    const double X = displacement(H, e->u, end_velocity(e, m, 0.0), e->a, a_end);
    const double noise = ACCOUNT_ROUNDING * (e->rounding + e->scale + fabs(F0 * (X - c * F0)));
    const double created = e->created + secular(e, m, end_velocity(e, m, F0), a_end);
    const double d = smallest_change(created - noise, X + m * e->a * c - 2.0 * c * F0, c);
    return fabs(d) > fabs(F0) ? copysign(fabs(F0), d) : d;
}
