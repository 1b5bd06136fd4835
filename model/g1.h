/* G1 (Grünwald–Letnikov) quadrature of the fractional operator D^alpha on a
 * uniform grid: a generic operator, any order alpha, any sampled function.
 * docs/model.md §3. C99, libc and libm only. */
#ifndef FRACCONTACT_G1_H
#define FRACCONTACT_G1_H

#include <stddef.h>

/* The first n weights w[0..n-1] of order alpha:
 * w_0 = 1, w_j = w_{j-1} (1 - (alpha + 1) / j). */
void g1_weights(double alpha, size_t n, double *w);

/* The G1 value of D^alpha f at the newest sample of a history
 * f[0..n_samples-1] (oldest first, spacing delta, f[0] at the lower terminal):
 *     delta^(-alpha) * sum_{j=0..n} w_j f[n-j],   n = n_samples - 1,
 * with w from g1_weights(alpha, >= n_samples). O(n_samples). */
double g1_history_sum(double alpha, const double *w, const double *f,
                      size_t n_samples, double delta);

/* Richardson extrapolation of the above over the grids of spacing delta and
 * 2 delta (n_samples - 1 must be even): 2 G1_delta - G1_2delta, which cancels
 * G1's O(delta) error term at O(n) cost. */
double g1_history_sum_extrapolated(double alpha, const double *w, const double *f,
                                   size_t n_samples, double delta);

/* For the identity f(xi) = xi on N >= 1 intervals of [0, x], the ratio of
 * the G1 value of D^alpha f at x to the exact value x^(1-alpha)/Gamma(2-alpha):
 *     Gamma(N + 1 - alpha) / (Gamma(N) N^(1 - alpha)) = 1 + O(1/N).
 * O(1), accurate to a few ulp for every N (no lgamma cancellation). */
double g1_line_ratio(double alpha, double N);

/* The same ratio after Richardson extrapolation over N and M = floor(N/2)
 * intervals, (N r(N) - M r(M)) / (N - M) = 1 + O(1/N^2); r(1) for N = 1,
 * which has no coarser grid. */
double g1_line_ratio_extrapolated(double alpha, double N);

#endif
