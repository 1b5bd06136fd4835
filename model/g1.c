#include "g1.h"

#include <math.h>

void g1_weights(double alpha, size_t n, double *w)
{
    size_t j;
    if (n == 0)
        return;
    w[0] = 1.0;
    for (j = 1; j < n; j++)
        w[j] = w[j - 1] * (1.0 - (alpha + 1.0) / (double)j);
}

/* sum_{j=0..n/stride} w_j f[n - stride j], newest sample last. Neumaier's
 * compensated sum: the weights of a fractional integral decay only like
 * j^(alpha-1), so a million terms of one sign would otherwise lose about
 * sqrt(n) ulp, which is what the 1e-12 reference check sees. */
static double weighted_history(const double *w, const double *f, size_t n, size_t stride)
{
    double sum = 0.0, carry = 0.0;
    size_t j;
    for (j = 0; j <= n / stride; j++) {
        double term = w[j] * f[n - stride * j];
        double t = sum + term;
        carry += fabs(sum) >= fabs(term) ? (sum - t) + term : (term - t) + sum;
        sum = t;
    }
    return sum + carry;
}

double g1_history_sum(double alpha, const double *w, const double *f,
                      size_t n_samples, double delta)
{
    if (n_samples == 0)
        return 0.0;
    return pow(delta, -alpha) * weighted_history(w, f, n_samples - 1, 1);
}

double g1_history_sum_extrapolated(double alpha, const double *w, const double *f,
                                   size_t n_samples, double delta)
{
    size_t n = n_samples - 1;
    if (n_samples == 0)
        return 0.0;
    return 2.0 * pow(delta, -alpha) * weighted_history(w, f, n, 1)
           - pow(2.0 * delta, -alpha) * weighted_history(w, f, n, 2);
}

/* Stirling's series of ln Gamma(z) without its leading terms; at z >= 30 the
 * first omitted term, 1/(1188 z^9), is below 1e-16. */
static double stirling_tail(double z)
{
    double r = 1.0 / z, r2 = r * r;
    return r * (1.0 / 12 - r2 * (1.0 / 360 - r2 * (1.0 / 1260 - r2 / 1680)));
}

double g1_line_ratio(double alpha, double N)
{
    double a = 1.0 - alpha;
    if (N < 30.0)
        return tgamma(N + a) / (tgamma(N) * pow(N, a));
    /* ln Gamma(N+a) - ln Gamma(N) - a ln N, with the O(1) parts cancelled
     * analytically so that the O(1/N) result keeps full relative precision. */
    return exp((N + a - 0.5) * log1p(a / N) - a
               + stirling_tail(N + a) - stirling_tail(N));
}

double g1_line_ratio_extrapolated(double alpha, double N)
{
    double M = floor(0.5 * N);
    if (M < 1.0)
        return g1_line_ratio(alpha, N);
    return (N * g1_line_ratio(alpha, N) - M * g1_line_ratio(alpha, M)) / (N - M);
}
