/* A sum of exponentials for the springpot's kernel (docs/model.md §6):
 *     tau^(-alpha) / Gamma(1 - alpha)  ~  eta delta(tau) + sum_i a_i exp(-b_i tau),
 * relative error at most `tolerance` for every tau in [delta, span]. The
 * terms are a generalised Maxwell (Prony) series: the fastest part of the
 * kernel, below delta, is lumped into a dashpot eta (its integral), the
 * slowest, beyond the span, into a spring (b = 0). C99, libc and libm only. */
#ifndef FRACCONTACT_SOE_H
#define FRACCONTACT_SOE_H

#include <stddef.h>

/* Writes the terms into a[], b[] (at most `max`) and the lumped dashpot into
 * *eta; returns their number, or max + 1 when more would be needed (then a,
 * b are unspecified). 0 < alpha <= 1 (alpha = 1: no terms, eta = 1),
 * 0 < tolerance < 1, 0 < delta < span. */
size_t soe_kernel(double alpha, double tolerance, double delta, double span, size_t max, double *a, double *b,
                  double *eta);

#endif
