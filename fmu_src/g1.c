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

double g1_history_sum(double alpha, const double *w, const double *f,
                      size_t n_samples, double delta)
{
    /* Neumaier's compensated sum: the weights of a fractional integral decay
     * only like j^(alpha-1), so a million terms of one sign would otherwise
     * lose about sqrt(n) ulp, which is what the 1e-12 reference check sees. */
    double sum = 0.0, carry = 0.0;
    size_t j, n = n_samples - 1;
    if (n_samples == 0)
        return 0.0;
    for (j = 0; j <= n; j++) {
        double term = w[j] * f[n - j];
        double t = sum + term;
        carry += fabs(sum) >= fabs(term) ? (sum - t) + term : (term - t) + sum;
        sum = t;
    }
    return pow(delta, -alpha) * (sum + carry);
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
