/* The implicit stage (docs/model.md §10): each stage of ESDIRK 5(4) and
 * each BDF2 step of the full G1 history reduces to one scalar root
 * X + beta X^n = r, taken inline on the hot path. The fixed steps'
 * discrete gradient solves a root of its own (gradient.c), which starts
 * from stage_root where its own start is no good one. */
#ifndef FRACCONTACT_STAGE_H
#define FRACCONTACT_STAGE_H

#include "contact_internal.h"

double other_stage_force(const contact_model *cm, double K, double r, double beta, double *X);

/* The root s > 0 of s^2 + beta s^3 = r (r > 0, beta >= 0): s^2 is the elastic
 * indentation of an implicit stage with n = 3/2. With u = beta sqrt(r) the root is
 *     sqrt(r) (1 - u/2 + 5u^2/8 - u^3 + 231u^4/128 - 7u^5/2 + 7293u^6/1024 - 15u^7 + ...),
 * so for u < 1e-4 (a dashpot's stage of 1e-7 s at the paper's parameters)
 * the series to u^4 is exact to 4e-20, below rounding; to u^6 it is as
 * accurate as a stage needs while its error, below 20u^7, is: while
 * u^2 < series_limit (an error-controlled step's u is about 0.01 at the
 * paper's parameters; series_limit 0: never). The even powers of u are
 * powers of w = u^2 = beta^2 r and sqrt(r) u = beta r, so the series is
 * sqrt(r) E(w) + beta r O(w): the two polynomials need no square root and
 * are ready when it is, a shorter chain on every implicit stage.
 * Otherwise Newton's method, which converges from any start at or above the
 * root and from a close one below it because the cubic increases and is
 * convex for s > 0: from that series (off by < 20u^7, 1.6e-8 at most)
 * while u < 0.05, from sqrt(r) / (1 + u/2) (off by < u^2/2) while u <= 1,
 * and from cbrt(r / beta), above the root, when the split is stiff (u > 1). */
static inline double stage_root(double r, double beta, double series_limit)
{
    const double w = beta * beta * r, odd = beta * r;
    double s = sqrt(r), ds;
    int i;
    if (w < 1e-8) /* u < 1e-4, short stages: to u^4, exact to 4e-20 */
        return s * (1.0 + w * (0.625 + w * (231.0 / 128.0))) - odd * (0.5 + w);
    if (w < 0.0025) { /* u < 0.05 */
        s = s * (1.0 + w * (0.625 + w * (231.0 / 128.0 + w * (7293.0 / 1024.0)))) - odd * (0.5 + w * (1.0 + 3.5 * w));
        if (w < series_limit)
            return s;
    } else {
        s = w > 1.0 ? cbrt(r / beta) : s / (1.0 + 0.5 * beta * s);
    }
    for (i = 0; i < 200; i++) {
        ds = (s * s * (1.0 + beta * s) - r) / (s * (2.0 + 3.0 * beta * s));
        s -= ds;
        /* Newton leaves a relative error of about half the square of the
         * last relative correction: after one of 1e-8 the iterate is exact
         * to rounding. */
        if (!(fabs(ds) > 1e-8 * s))
            break;
    }
    return s;
}

static inline double stage_force(const contact_model *cm, double K, double r, double beta, double *X)
{
    double s;
    if (cm->p.spring_exponent != 1.5)
        return other_stage_force(cm, K, r, beta, X);
    s = stage_root(r, beta, cm->series_limit);
    *X = s * s;
    return K * s * *X;
}

/* What the damper makes of an implicit stage: its rate x2' = (F - A) inv_B,
 * linear in the force (the dashpot: A = 0, inv_B = 1/c; a springpot: its
 * memory's pull A and its stiffness over the stage as a viscosity 1/inv_B). */
typedef struct {
    double A, inv_B;
} damper_stage;

/* One implicit stage of x1' = v - x2', v' = accel - inv_m F with
 * F = K max(x1, 0)^n, x2' = (F - A) inv_B:
 *     X = xh + hg (V - x2'),  V = vh + hg (accel - inv_m F).
 * Eliminating V and x2' leaves X + beta X^n = r, one scalar root. Returns F. */
static inline double implicit_stage(const contact_model *cm, double K, double hg, double xh, double vh,
                                    damper_stage d, double *X, double *V)
{
    /* vh last: in an ESDIRK step it is the latest of the three to be known */
    double r = (xh + hg * (hg * cm->accel + d.A * d.inv_B)) + hg * vh;
    double F = 0.0;
    if (r > 0.0 && K > 0.0)
        F = stage_force(cm, K, r, K * hg * (d.inv_B + hg * cm->inv_m), X);
    else
        *X = r; /* out of contact the striker moves freely */
    *V = vh + hg * (cm->accel - cm->inv_m * F);
    return F;
}

#endif
