/* ESDIRK 5(4), the error-controlled steps (docs/model.md §12): Kvaerno's
 * method (A. Kvaerno, Singly diagonally implicit Runge-Kutta methods with an
 * explicit first stage, BIT 44 (2004) 489-502), SUNDIALS ARKODE's
 * ARKODE_KVAERNO_7_4_5, its tableau below. The dashpot's: the springpot's
 * error-controlled steps are Radau IIA's (radau_iia.c). */
#include <math.h>

#include "stage.h"

/* Kvaerno's ESDIRK of order 5 with an embedded solution of order 4: an
 * explicit first stage, then six implicit stages of one diagonal gamma. Both solutions are L-stable and
 * stiffly accurate: the step's end is its last stage, the embedded
 * solution its sixth, so that their difference estimates the step's error
 * at no extra cost, and a step far too long for the motion damps it rather
 * than reflecting it. Its order keeps the steps of a tight tolerance few
 * (docs/model.md §12). */
#define ESDIRK_STAGES 7
#define ESDIRK_EMBEDDED 5
#define ESDIRK_GAMMA 0.26
static const double esdirk_a[ESDIRK_STAGES][ESDIRK_STAGES] = {
    {0.0},
    {ESDIRK_GAMMA, ESDIRK_GAMMA},
    {0.13, 0.8403332099679080963, ESDIRK_GAMMA},
    {0.2237196147832050559, 0.4767553231979969983, -0.06470895363112615134, ESDIRK_GAMMA},
    {0.1664856432324832153, 0.1045001884159172041, 0.03631482272098715162, -0.1309070445107399857, ESDIRK_GAMMA},
    {0.1385564023126822495, 0.0, -0.04245337201752043099, 0.02446657898003141966, 0.6194303907248067618,
     ESDIRK_GAMMA},
    {0.1365975117764029144, 0.0, -0.05496908796538376712, -0.04118626728321046868, 0.6299330489901640319,
     0.06962479448202728949, ESDIRK_GAMMA}};

/* One ESDIRK step of length h from *in with spring stiffness K (the
 * contract of sdirk_step), the damper a dashpot. out->error is the
 * embedded estimate of its error over the tolerance: x1's relative to
 * error_length, x2's to error_travel, v's to error_speed. E_diss is the order-5
 * quadrature of F^2/c (SDIRK2's mean force times the travel is of order 2
 * only). */
static double esdirk_step(contact_model *cm, const contact_state *in, double h, double K, contact_state *out)
{
    const int last = ESDIRK_STAGES - 1;
    damper_stage damper = {0.0, cm->inv_c};
    double F[ESDIRK_STAGES], rise[ESDIRK_STAGES];
    double X = in->x1, V = in->v, X_embedded = 0.0, V_embedded = 0.0, x2_embedded = 0.0;
    double impulse = 0.0, work = 0.0, length, error;
    int i, j;
    F[0] = in->F;
    for (i = 0; i <= last; i++) {
        if (i > 0) {
            /* each stage waits on the one before: the sums are ordered so
             * that its rise and force come in last, at one multiply-add */
            double xh = in->x1, vh = in->v;
            for (j = 0; j < i; j++) {
                xh += esdirk_a[i][j] * rise[j];
                vh += h * esdirk_a[i][j] * cm->accel;
                vh -= h * esdirk_a[i][j] * cm->inv_m * F[j];
            }
            F[i] = implicit_stage(cm, K, ESDIRK_GAMMA * h, xh, vh, damper, &X, &V);
            /* h x1' from the stage's equation X = xh + gamma h x1': a
             * shorter chain than h (V - z) */
            rise[i] = (X - xh) * (1.0 / ESDIRK_GAMMA);
        } else {
            rise[0] = h * (V - F[0] * cm->inv_c);
        }
        if (i == ESDIRK_EMBEDDED) {
            X_embedded = X;
            V_embedded = V;
            for (j = 0; j <= i; j++)
                x2_embedded += h * esdirk_a[i][j] * F[j];
        }
    }
    for (j = 0; j <= last; j++) {
        impulse += h * esdirk_a[last][j] * F[j];
        work += h * esdirk_a[last][j] * F[j] * F[j];
    }
    carry_state(out, in);
    out->t = in->t + h;
    out->x1 = X;
    out->v = V;
    out->F = F[last];
    out->step = h;
    out->x2 = in->x2 + impulse * cm->inv_c;
    out->E_diss = in->E_diss + work * cm->inv_c;
    length = error_length(cm, in, K, out);
    error = larger(fabs(X - X_embedded) / length,
                   fabs(impulse - x2_embedded) * cm->inv_c / error_travel(length, in, out));
    out->error = larger(error, fabs(V - V_embedded) / error_speed(in, out)) / cm->p.tolerance;
    return impulse;
}

const contact_method_record esdirk54_method = {
    .method = CONTACT_METHOD_ESDIRK54,
    .name = "esdirk54",
    .controls_error = 1,
    .dashpot_step = esdirk_step,
};
