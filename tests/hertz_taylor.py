"""The drop test's Hertz–dashpot ODE (docs/model.md §2) by mpmath's Taylor
series solver at 25 digits: a reference whose own error is far below a
double's, to measure the double-precision references (scipy, GSL) against.

    x1' = v - F/c,  v' = -F/m,  x2' = F/c,  E_diss' = F^2/c,  F = k x1^(3/2)

x1^(3/2) has a branch point at x1 = 0, where a Taylor series' radius of
convergence shrinks to nothing: the solve starts a picosecond after contact
(as scipy_contact's does, x1 = v0 t there) and runs in t past the peak; from
x1 = x1_peak / 4 to the separation the variable is s = sqrt(x1) instead, in
which F = k s^3 and dt/ds = 2 s / x1' are analytic (x1' = v < 0 at the
separation)."""

import mpmath

from fraccontact.hertz import contact_time
from fraccontact.scipy_contact import T0

DIGITS = 25
TOL = 1e-22


def _crossing(f, t, dt):
    """The first root of f after t (f(t) > 0), bracketed by steps of dt."""
    while f(t + dt) > 0:
        t += dt
    return mpmath.findroot(f, (t, t + dt), solver="anderson")


def drop(k, c, m, v0):
    """F_peak, eps, t_contact, x2, E_diss of the first impact, as floats."""
    with mpmath.workdps(DIGITS):
        k, c, m, v0, tol = (mpmath.mpf(a) for a in (k, c, m, v0, TOL))
        in_t = mpmath.odefun(lambda t, y: [y[1] - k * y[0] ** 1.5 / c, -k * y[0] ** 1.5 / m,
                                           k * y[0] ** 1.5 / c, (k * y[0] ** 1.5) ** 2 / c],
                             mpmath.mpf(T0), [v0 * T0, v0, 0, 0], tol=tol)
        dt = mpmath.mpf(contact_time(float(k), float(m), float(v0))) / 256
        t_peak = _crossing(lambda t: in_t(t)[1] - k * in_t(t)[0] ** 1.5 / c, mpmath.mpf(T0), dt)
        x1_peak = in_t(t_peak)[0]
        t1 = _crossing(lambda t: in_t(t)[0] - x1_peak / 4, t_peak, dt)
        y1 = in_t(t1)
        s1 = mpmath.sqrt(y1[0])

        def in_sigma(sigma, z):  # z = (t, v, x2, E_diss) at s = s1 - sigma, so d/dsigma = -d/ds
            s = s1 - sigma
            F, t_per_s = k * s ** 3, 2 * s / (z[1] - k * s ** 3 / c)
            return [-t_per_s, F / m * t_per_s, -F / c * t_per_s, -F * F / c * t_per_s]
        end = mpmath.odefun(in_sigma, 0, [t1, y1[1], y1[2], y1[3]], tol=tol)(s1)
        return dict(F_peak=float(k * x1_peak ** 1.5), eps=float(-end[1] / v0), t_contact=float(end[0]),
                    x2=float(end[2]), E_diss=float(end[3]))
