/* The energy account of a proxy striker's coupling and the correction that
 * keeps the coupling from creating energy (docs/model.md §17a): once per
 * communication step, from the inputs at its ends and the proxy's motion
 * over it; nothing in the internal steps. */
#include <math.h>

#include "contact.h"

/* The bodies' displacement over an interval of length H: Hermite's
 * quadrature of their approach speed, whose rate a - F/m is known at both
 * ends with the held force F the same there (so it cancels). */
static double displacement(double H, double u_start, double u_end, double a_start, double a_end)
{
    return 0.5 * H * (u_start + u_end) + H * H * (a_start - a_end) / 12.0;
}

/* The energy one interval of length H creates that does not return: the
 * proxy's kinetic energy given up, plus the work its held acceleration a_start
 * does on the bodies' real path less that acceleration's own change, less
 * the work the bodies do on the contact (F held over their displacement),
 * less the work the change of a does against the force the contact holds
 * at the end. With a constant a, and the proxy's velocities those the held
 * force gives the bodies, the terms cancel exactly. */
double coupling_energy_created(double m, double H, double u0, double u1, double F_end, double u_start,
                               double u_end, double a_start, double a_end, double F)
{
    const double dx = displacement(H, u_start, u_end, a_start, a_end);
    const double da = a_end - a_start;
    return m * (0.5 * (u0 - u1) * (u0 + u1) + a_start * (dx - da * H * H / 6.0)) - F * dx
           - F_end * da * H * H / 12.0;
}

double coupling_energy_end_velocity(const coupling_energy *e, double m, double H, double F)
{
    return e->u + H * (e->a + e->a_unseen + 0.5 * H * e->a_rate - F / m);
}

/* What the open interval of length H creates with the force F held on the
 * bodies, their end predicted. */
static double predicted_created(const coupling_energy *e, double m, double H, double F)
{
    return coupling_energy_created(m, H, e->u0, e->u1, e->F_end, e->u, coupling_energy_end_velocity(e, m, H, F), e->a,
                                   e->a + H * e->a_rate, F);
}

void coupling_energy_open(coupling_energy *e, double t, double u, double a, double F)
{
    e->t = t;
    e->u = u;
    e->a = a;
    e->F = F;
    e->open = 1;
}

void coupling_energy_close(coupling_energy *e, double m, double t, double u, double a)
{
    const double H = t - e->t;
    if (e->open && H > 0.0) {
        e->created += coupling_energy_created(m, H, e->u0, e->u1, e->F_end, e->u, u, e->a, a, e->F);
        e->a_rate = (a - e->a) / H;
        e->a_unseen = (u - e->u) / H + e->F / m - 0.5 * (e->a + a);
    }
    e->open = 0;
}

double coupling_energy_predicted(const coupling_energy *e, double m, double H)
{
    return e->created + predicted_created(e, m, H, e->F);
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

/* c = H^2/(2m): the held force's work over the displacement it shortens;
 * X: the bodies' displacement without it. */
double coupling_energy_correction(const coupling_energy *e, double m, double H, double created, double F0)
{
    const double c = 0.5 * H * H / m;
    const double X = H * e->u + 0.5 * H * H * (e->a + e->a_unseen) + H * H * H * e->a_rate / 6.0;
    const double d = smallest_change(created + predicted_created(e, m, H, F0), X + m * e->a * c - 2.0 * c * F0, c);
    return fabs(d) > fabs(F0) ? copysign(fabs(F0), d) : d;
}
