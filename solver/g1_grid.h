/* The G1 value of D^alpha f at every point of a uniform grid at once: the
 * history sums of g1.h for all n, a discrete convolution. A tool of the
 * solver and the benchmarks (GSL's FFT), not of the FMU. */
#ifndef FRACCONTACT_G1_GRID_H
#define FRACCONTACT_G1_GRID_H

#include <stddef.h>

/* out[n] = delta^(-alpha) sum_{j=0..n} w_j f[n-j] for n = 0..n_samples-1.
 * The first `head` points (all, if head >= n_samples) are summed directly
 * as g1_history_sum does; the rest come from a zero-padded FFT convolution,
 * O(n log n), accurate to a few ulp of the largest terms. Relative to a
 * point's own value that error is larger where the values are small (the
 * first points of a semi-integral of a line: like (n_samples/n)^1.5 ulp), so
 * the caller sums those directly; the benchmark's head of n_samples/128
 * keeps every point of a 1e6 grid within 1e-12. Returns 0, or -1 when memory
 * runs out. */
int g1_full_grid(double alpha, const double *f, size_t n_samples, double delta, size_t head, double *out);

#endif
