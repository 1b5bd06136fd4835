#include "soe.h"

#include <math.h>

#define PI 3.14159265358979323846

/* The kernel is a Laplace transform over the relaxation rate s = e^u:
 *     tau^(-alpha) / Gamma(1 - alpha) = sin(pi alpha)/pi  integral e^(alpha u) e^(-e^u tau) du,
 * and the trapezoidal rule in u, step du, turns it into exponentials. Three
 * errors share the tolerance, a third each (all relative, for every tau):
 * the rule's, 2 |Gamma(alpha + 2 pi i/du)| / Gamma(alpha) whatever tau
 * (the integrand's Fourier transform at the rule's aliasing frequency); the
 * fast rates cut at u_max, where e^(-e^u delta) has fallen below it; and the
 * slow rates lumped into one spring, whose e^(-b tau) ~ 1 holds while
 * (e^u_min span)^(1 + alpha) stays below it. Each bound is solved by a
 * fixed-point iteration of its logarithm. */

/* y with 2 sqrt(2 pi) y^(alpha - 1/2) e^(-pi y / 2) / Gamma(alpha) = target,
 * the asymptotic |Gamma(alpha + i y)| for y >> 1. */
static double aliasing_frequency(double alpha, double target)
{
    double y = 10.0;
    int i;
    for (i = 0; i < 60; i++)
        y = 2.0 / PI * log(2.0 * sqrt(2.0 * PI) * pow(y, alpha - 0.5) / (tgamma(alpha) * target));
    return y;
}

/* x = e^u_max delta with x^(alpha - 1) e^(-x) / Gamma(alpha) = target: the
 * rates cut above u_max carry that fraction of the kernel at tau = delta. */
static double fast_cut(double alpha, double target)
{
    double x = 10.0;
    int i;
    for (i = 0; i < 60; i++)
        x = log(pow(x, alpha - 1.0) / (tgamma(alpha) * target));
    return x;
}

size_t soe_kernel(double alpha, double tolerance, double delta, double span, size_t max, double *a, double *b,
                  double *eta)
{
    const double part = tolerance / 3.0;
    double du, weight, u_max, u_min, u, ratio;
    size_t n = 0;
    if (alpha >= 1.0) { /* the dashpot: a delta function */
        *eta = 1.0;
        return 0;
    }
    du = 2.0 * PI / aliasing_frequency(alpha, part);
    weight = sin(PI * alpha) / PI * du;
    u_max = log(fast_cut(alpha, part) / delta);
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
