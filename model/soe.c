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
 * Newton's method, the third in closed form: a kernel is built for every
 * model configured (and checked), so a few evaluations, not a bisection's
 * hundred. */

/* ln f and its slope d ln f / d ln x of a bound f decreasing in x. */
typedef void (*log_bound)(double alpha, double lg_alpha, double x, double *value, double *slope);

/* The trapezoidal rule's relative error at aliasing frequency y = 2 pi/du,
 * 2 |Gamma(alpha + i y)| / Gamma(alpha), with ln |Gamma(alpha + i y)| by
 * Stirling's series to its 1/(12 z) term, which at |z| >= 1 errs by less
 * than 1/(360 |z|^3): ample for a bound. */
static void aliasing_error(double alpha, double lg_alpha, double y, double *value, double *slope)
{
    const double r2 = alpha * alpha + y * y, angle = atan2(y, alpha);
    *value = log(2.0) + (alpha - 0.5) * 0.5 * log(r2) - y * angle - alpha + 0.5 * log(2.0 * PI) + alpha / (12.0 * r2)
             - lg_alpha;
    *slope = y * (-0.5 * y / r2 - angle - alpha * y / (6.0 * r2 * r2));
}

/* The kernel's fraction carried by rates above x / delta at tau = delta. */
static void fast_tail(double alpha, double lg_alpha, double x, double *value, double *slope)
{
    *value = (alpha - 1.0) * log(x) - x - lg_alpha;
    *slope = (alpha - 1.0) - x;
}

/* The smallest x in [lo, hi] with f(x) <= target for a decreasing f: lo if
 * f(lo) is already below, hi if f(hi) is not. Newton's method on ln f as a
 * function of x, in which both bounds are nearly straight lines (a few
 * steps from hi, where in ln x they are exponentials), kept inside the
 * bracket in ln x (a step leaving it bisects it), to rounding. */
static double decreasing_below(log_bound f, double alpha, double lg_alpha, double target, double lo, double hi)
{
    const double goal = log(target);
    double a = log(lo), b = log(hi), s, value, slope;
    int i;
    f(alpha, lg_alpha, lo, &value, &slope);
    if (value <= goal)
        return lo;
    f(alpha, lg_alpha, hi, &value, &slope);
    if (value > goal)
        return hi;
    s = b;
    for (i = 0; i < 100; i++) {
        /* x (1 - (ln f - goal) / (d ln f / d ln x)), in ln x; a step
         * to x <= 0 lands on the bracket's end and bisects it */
        const double ratio = 1.0 - (value - goal) / slope;
        double next = ratio > 0.0 ? s + log(ratio) : a;
        /* quadratic convergence: after a step of 1e-13 the iterate is
         * exact to rounding (an absolute step in ln x, which is >= 0) */
        if (fabs(next - s) <= 1e-13)
            return exp(next);
        if (b - a <= 1e-13)
            return exp(b);
        if (!(next > a && next < b))
            next = 0.5 * (a + b);
        s = next;
        f(alpha, lg_alpha, exp(s), &value, &slope);
        if (value <= goal)
            b = s;
        else
            a = s;
    }
    return exp(b);
}

size_t soe_kernel(double alpha, double tolerance, double delta, double span, size_t max, double *a, double *b,
                  double *eta)
{
    const double part = tolerance / 4.0;
    double lg_alpha, du, weight, u_max, u_min, u, ratio, step_a, step_b;
    size_t n = 0;
    if (alpha >= 1.0) { /* the dashpot: a delta function */
        *eta = 1.0;
        return 0;
    }
    /* ln Gamma(alpha) from Gamma(alpha) = Gamma(1 + alpha) / alpha: lgamma
     * would write the global signgam, a data race between threads building
     * kernels at once, and tgamma(alpha) itself overflows for alpha below
     * 1 / DBL_MAX, where Gamma(1 + alpha) is still near 1. */
    lg_alpha = log(tgamma(1.0 + alpha)) - log(alpha);
    /* y >= 1 (du <= 2 pi) and x >= 1 even where a tiny alpha's huge
     * Gamma(alpha) would allow less: the rule still needs a few points a
     * decade, and the fast cut must lie above 1/delta. */
    du = 2.0 * PI / decreasing_below(aliasing_error, alpha, lg_alpha, part, 1.0, 1e4);
    weight = sin(PI * alpha) / PI * du;
    u_max = log(decreasing_below(fast_tail, alpha, lg_alpha, part, 1.0, 1e4) / delta);
    u_min = log(pow(part * (1.0 + alpha) * tgamma(alpha), 1.0 / (1.0 + alpha)) / span);
    /* The lumped dashpot: the rule's terms above u_max, sum_j a_j / b_j. */
    ratio = exp((alpha - 1.0) * du);
    *eta = weight * exp((alpha - 1.0) * u_max) * ratio / (1.0 - ratio);
    /* the terms' geometric progressions by products: within rounding of
     * the exponentials over the largest number of terms */
    step_a = exp(-alpha * du);
    step_b = exp(-du);
    for (u = u_max; u > u_min; u -= du) {
        if (n == max)
            return max + 1;
        a[n] = n == 0 ? weight * exp(alpha * u) : a[n - 1] * step_a;
        b[n] = n == 0 ? exp(u) : b[n - 1] * step_b;
        n++;
    }
    /* The lumped spring: the rule's terms below the slowest one kept. */
    if (n == max)
        return max + 1;
    a[n] = weight * exp(alpha * (u + du)) * step_a / (1.0 - step_a);
    b[n] = 0.0;
    return n + 1;
}
