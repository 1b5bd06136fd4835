#include "soe.h"

#include <math.h>

#define PI 3.14159265358979323846

/* The kernel is a Laplace transform over the relaxation rate s = e^u:
 *     tau^(-alpha) / Gamma(1 - alpha) = sin(pi alpha)/pi  integral e^(alpha u) e^(-e^u tau) du,
 * and the trapezoidal rule in u, step du, turns it into exponentials. Three
 * errors share the tolerance, a quarter each (all relative, for every tau;
 * the fourth quarter covers what the bounds below leave out, such as the
 * rule's further aliasing terms: measured, the error stays within 0.75 of
 * the tolerance for alpha from 0.001 to 0.9999 and tolerances from 1e-2 to
 * 1e-12):
 * the rule's, 2 |Gamma(alpha + 2 pi i/du)| / Gamma(alpha) whatever tau
 * (the integrand's Fourier transform at the rule's aliasing frequency); the
 * fast rates cut at u_max, where e^(-e^u delta) has fallen below it; and the
 * slow rates lumped into one spring, whose e^(-b tau) ~ 1 holds while
 * (e^u_min span)^(1 + alpha) stays below it. The first two are solved by
 * bisection, the third in closed form. */

/* ln |Gamma(alpha + i y)| by Stirling's series to its 1/(12 z) term, which
 * at |z| >= 1 errs by less than 1/(360 |z|^3): ample for a bound. */
static double log_gamma_modulus(double alpha, double y)
{
    const double r2 = alpha * alpha + y * y;
    return (alpha - 0.5) * 0.5 * log(r2) - y * atan2(y, alpha) - alpha + 0.5 * log(2.0 * PI) + alpha / (12.0 * r2);
}

/* The smallest x in [lo, hi] with f(x) <= target for a decreasing f, by
 * bisection on ln x: lo if f(lo) is already below. */
static double decreasing_below(double (*f)(double, double), double alpha, double target, double lo, double hi)
{
    int i;
    if (f(alpha, lo) <= target)
        return lo;
    for (i = 0; i < 100; i++) {
        double mid = sqrt(lo * hi);
        if (f(alpha, mid) <= target)
            hi = mid;
        else
            lo = mid;
    }
    return hi;
}

/* The trapezoidal rule's relative error at aliasing frequency y = 2 pi/du. */
static double aliasing_error(double alpha, double y)
{
    return 2.0 * exp(log_gamma_modulus(alpha, y) - lgamma(alpha));
}

/* The kernel's fraction carried by rates above x / delta at tau = delta. */
static double fast_tail(double alpha, double x)
{
    return exp((alpha - 1.0) * log(x) - x - lgamma(alpha));
}

size_t soe_kernel(double alpha, double tolerance, double delta, double span, size_t max, double *a, double *b,
                  double *eta)
{
    const double part = tolerance / 4.0;
    double du, weight, u_max, u_min, u, ratio;
    size_t n = 0;
    if (alpha >= 1.0) { /* the dashpot: a delta function */
        *eta = 1.0;
        return 0;
    }
    /* y >= 1 (du <= 2 pi) and x >= 1 even where a tiny alpha's huge
     * Gamma(alpha) would allow less: the rule still needs a few points a
     * decade, and the fast cut must lie above 1/delta. */
    du = 2.0 * PI / decreasing_below(aliasing_error, alpha, part, 1.0, 1e4);
    weight = sin(PI * alpha) / PI * du;
    u_max = log(decreasing_below(fast_tail, alpha, part, 1.0, 1e4) / delta);
    u_min = log(pow(part * (1.0 + alpha) * tgamma(alpha), 1.0 / (1.0 + alpha)) / span);
    /* The lumped dashpot: the rule's terms above u_max, sum_j a_j / b_j. */
    ratio = exp((alpha - 1.0) * du);
    *eta = weight * exp((alpha - 1.0) * u_max) * ratio / (1.0 - ratio);
    for (u = u_max; u > u_min; u -= du) {
        if (n == max)
            return max + 1;
        a[n] = weight * exp(alpha * u);
        b[n] = exp(u);
        n++;
    }
    /* The lumped spring: the rule's terms below the slowest one kept. */
    if (n == max)
        return max + 1;
    ratio = exp(-alpha * du);
    a[n] = weight * exp(alpha * (u + du)) * ratio / (1.0 - ratio);
    b[n] = 0.0;
    return n + 1;
}
