/* The implicit stage's root for exponents other than the Hertz sphere's
 * n = 3/2, which stage.h takes inline (docs/model.md §10). */
#include <math.h>

#include "stage.h"

/* The root X > 0 of X + beta X^n = r (r > 0, beta >= 0, n >= 1) for any n:
 * Newton's method from the smaller of r and (r/beta)^(1/n), both at or above
 * the root, where the increasing convex function converges monotonically. */
static double power_root(double r, double beta, double n)
{
    double X = beta > 0.0 ? fmin(r, pow(r / beta, 1.0 / n)) : r, dX;
    int i;
    for (i = 0; i < 200; i++) {
        double Xn1 = pow(X, n - 1.0);
        dX = (X + beta * X * Xn1 - r) / (1.0 + n * beta * Xn1);
        X -= dX;
        if (!(fabs(dX) > 1e-9 * X))
            break;
    }
    return X;
}

/* The elastic indentation X of an implicit stage, X + beta X^n = r, and the
 * spring force K X^n there: the Hertz sphere's n = 1.5 inline (the common
 * case, on every step), any other n apart. */
double other_stage_force(const contact_model *cm, double K, double r, double beta, double *X)
{
    const double n = cm->p.spring_exponent;
    *X = n == 1.0 ? r / (1.0 + beta) : power_root(r, beta, n);
    return spring_force(cm, K, *X);
}
