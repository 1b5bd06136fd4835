/* G1 test functions for the C tests (test_g1.c, test_g1_grid.c): functions
 * with known fractional integrals and derivatives, and G1's predicted error. */
#ifndef FRACCONTACT_G1_CASES_H
#define FRACCONTACT_G1_CASES_H

#include <math.h>
#include <stddef.h>

/* Test functions with known fractional integrals and derivatives, and the
 * leading terms of G1's error at t, derived from its generating function
 * (1 - z)^alpha = (h s)^alpha (1 - alpha h s / 2 + ...) and the singularity
 * analysis of sum_k k^p z^k near z = 1 (Lubich, SIAM J. Math. Anal. 17
 * (1986) 704):
 *     G1 - D^alpha f = C1(t) h + Cb(t) h^(p+1) + O(h^2),
 *     C1 = -(alpha/2) D^(alpha+1) f   (the smooth part: for f = t,
 *          alpha = -1/2 it is the 3/(8N) of docs/model.md §4),
 *     Cb = (zeta(-p) + [p = 0]) t^(-alpha-1) / Gamma(-alpha)   (the start:
 *          for alpha = -1 the rectangle rule's Euler-Maclaurin/zeta term).
 * f = t^p: D^alpha t^p = Gamma(p+1)/Gamma(p+1-alpha) t^(p-alpha); C1 vanishes
 * where p - alpha is 0 (p = alpha = 1/2: D^(3/2) t^(1/2) = 0), and then the
 * error is the h^(3/2) start term alone. f = e^(at), a > 0: with
 * D^(-1/2) e^(at) = (1/sqrt(pi)) int_0^t u^(-1/2) e^(a(t-u)) du and u = w^2/a,
 *     D^(-1/2) e^(at) = e^(at) a^(-1/2) erf(sqrt(a t)),
 * D^(1/2) e^(at) = d/dt of it = 1/sqrt(pi t) + sqrt(a) e^(at) erf(sqrt(a t)),
 * D^(3/2) e^(at) = -t^(-3/2)/(2 sqrt(pi)) + a^(3/2) e^(at) erf(sqrt(a t)) + a/sqrt(pi t),
 * D^(-1) e^(at) = (e^(at) - 1)/a; its f(0) = 1 is a p = 0 start, the rest
 * (e^(at) - 1 = sum of t^k, k >= 1) starts at O(h^2). */
static const double ZETA_MINUS_HALF = -0.20788622497735456602; /* zeta(-1/2) */
static const double PI = 3.14159265358979323846;

typedef struct {
    double alpha;
    double p; /* f = t^p, or ... */
    double a; /* ... f = e^(a t) when a > 0 */
} g1_case;

static double g1_case_f(const g1_case *c, double t)
{
    return c->a > 0.0 ? exp(c->a * t) : pow(t, c->p);
}

static double zeta_at_minus(double p)
{
    return p == 0.5 ? ZETA_MINUS_HALF : p == 1.0 ? -1.0 / 12.0 : p == 2.0 ? 0.0 : p == 3.0 ? 1.0 / 120.0 : NAN;
}

/* D^alpha f(t), exact. */
static double g1_case_exact(const g1_case *c, double t)
{
    double a = c->a, e, s;
    if (a == 0.0)
        return tgamma(c->p + 1.0) / tgamma(c->p + 1.0 - c->alpha) * pow(t, c->p - c->alpha);
    e = exp(a * t);
    s = erf(sqrt(a * t));
    if (c->alpha == -0.5)
        return e * s / sqrt(a);
    if (c->alpha == -1.0)
        return (e - 1.0) / a;
    return 1.0 / sqrt(PI * t) + sqrt(a) * e * s; /* alpha = 1/2 */
}

/* The coefficient of h in G1's error at t (the start term included when it
 * is of the same order: p = 0, and e^(at)'s f(0) = 1). */
static double g1_case_c1(const g1_case *c, double t)
{
    double al = c->alpha, a = c->a, start = (1.0 - al) / (2.0 * tgamma(-al)) * pow(t, -al - 1.0), d, e, s;
    if (a == 0.0) {
        if (c->p == 0.0)
            return start;
        if (c->p - al == 0.0)
            return 0.0;
        return -0.5 * al * tgamma(c->p + 1.0) / tgamma(c->p - al) * pow(t, c->p - al - 1.0);
    }
    e = exp(a * t);
    s = erf(sqrt(a * t));
    d = al == -0.5 ? sqrt(a) * e * s                                  /* D^(1/2) (e^(at) - 1) */
        : al == -1.0 ? e - 1.0                                        /* D^0 */
                     : a * sqrt(a) * e * s + a / sqrt(PI * t);      /* D^(3/2) */
    return start - 0.5 * al * d;
}

/* The coefficient of h^(p+1), the start term of t^p, p > 0. */
static double g1_case_cb(const g1_case *c, double t)
{
    if (c->a > 0.0 || c->p == 0.0)
        return 0.0;
    return zeta_at_minus(c->p) / tgamma(-c->alpha) * pow(t, -c->alpha - 1.0);
}

static void g1_case_name(const g1_case *c, char *name, size_t len)
{
    if (c->a > 0.0)
        snprintf(name, len, "D^%g e^(%g t)", c->alpha, c->a);
    else
        snprintf(name, len, "D^%g t^%g", c->alpha, c->p);
}

/* Every test function: t^p for p = 0, 1/2, 1, 2, 3 and e^t, e^(4t), each
 * for alpha = -1/2 (the contact law's semi-integral), -1 and 1/2. */
static size_t g1_cases(g1_case *out)
{
    static const double alphas[] = {-0.5, -1.0, 0.5}, ps[] = {0.0, 0.5, 1.0, 2.0, 3.0}, as[] = {1.0, 4.0};
    size_t n = 0, i, j;
    for (i = 0; i < 3; i++) {
        for (j = 0; j < 5; j++) {
            g1_case c = {alphas[i], ps[j], 0.0};
            out[n++] = c;
        }
        for (j = 0; j < 2; j++) {
            g1_case c = {alphas[i], 0.0, as[j]};
            out[n++] = c;
        }
    }
    return n;
}


#endif
