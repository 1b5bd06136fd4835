/* ESDIRK 5(4), the error-controlled steps (docs/model.md §12): Kvaerno's
 * method (A. Kvaerno, Singly diagonally implicit Runge-Kutta methods with an
 * explicit first stage, BIT 44 (2004) 489-502), SUNDIALS ARKODE's
 * ARKODE_KVAERNO_7_4_5, its tableau below; and the springpot's compressed
 * memory in its stages (§6). */
#include <float.h>
#include <math.h>
#include <string.h>

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

/* The elastic indentation at the contact's peak force so far, kept for the
 * force it was derived from. */
static double peak_indentation(contact_model *cm, double K, double F_peak)
{
    if (F_peak != cm->peak_force_seen) {
        cm->peak_force_seen = F_peak;
        cm->peak_length = K > 0.0 ? pow(F_peak / K, 1.0 / cm->p.spring_exponent) : 0.0;
    }
    return cm->peak_length;
}

/* The springpot's compressed memory in the ESDIRK stages of a step of
 * length h, as in the SDIRK steps: with z_k the damper's rate x2' at stage
 * k, each implicit stage i has the modes
 *     phi_i = d (E_i + gamma h z_i),   d = 1/(1 + gamma h b),
 *     E_i = phi_n + h sum_{k<i} a_ik (z_k - b phi_k),
 * so its force c_alpha (eta z_i + sum a phi_i) is A_i + z_i / inv_B: the
 * memory's pull A_i = c_alpha sum a d E_i and the viscosity
 * 1/inv_B = c_alpha (eta + gamma h sum a d), one scalar root per stage
 * still. Stage 0 is the step's start. */
/* A trial step needs the modes only through the force's sums c sum a phi,
 * and each stage's modes are linear in the start's and in the rates: with
 * u = gamma h b d = 1 - d, stage i's modes are
 *     phi_i = d phi_n - (u / gamma) sum_{k<i} a_ik phi_k + d h (Z_i + gamma z_i),
 *     Z_i = sum_{k<i} a_ik z_k   (phi_0 = phi_n),
 * polynomials of degree i in u. Their sums mu_i[m] = sum a u^m phi_i then
 * follow from the sums of the start's modes by the same recursion, one
 * degree down a stage:
 *     mu_i[m] = D[m] - (1/gamma) sum_{k<i} a_ik mu_k[m + 1] + h (Z_i + gamma z_i) W[m],
 *     D[m] = sum a d u^m phi_n,  W[m] = sum a d u^m,  mu_0[m] = S[m] = sum a u^m phi_n,
 * and stage i's pull A_i is c_alpha times mu_i[0] without its z_i term: one
 * pass over the modes a trial (esdirk_moments_begin), the stages scalar. */
#define ESDIRK_DEGREES (ESDIRK_STAGES - 1)
typedef struct {
    double S[ESDIRK_STAGES], D[ESDIRK_DEGREES], W[ESDIRK_DEGREES];
    double mu[ESDIRK_STAGES][ESDIRK_STAGES]; /* mu_i[m] for m <= 6 - i, all the later stages need */
} esdirk_moments;

/* The start's sums S, D, W for a step of length h; returns inv_B. The
 * sums in local variables: the compiler keeps them in registers. Per mode
 * only D and W, whose terms a d u^m keep their precision however stiff the
 * mode (d small, u near 1); S follows from them, S[m + 1] = S[m] - D[m]
 * (u = 1 - d), each difference exact to rounding of the memory's force S[0]. */
static double esdirk_moments_begin(const contact_model *cm, double h, esdirk_moments *mom)
{
    const contact_modes *m = &cm->modes;
    const double hg = ESDIRK_GAMMA * h;
    double S0 = 0.0, D[ESDIRK_DEGREES] = {0.0}, W[ESDIRK_DEGREES] = {0.0};
    size_t j;
    int k;
    for (j = 0; j < m->modes; j++) {
        const double hb = hg * m->b[j], d = 1.0 / (1.0 + hb), u = hb * d;
        double x = m->a[j] * m->phi[j], y = m->a[j] * d;
        S0 += x;
        x *= d;
        for (k = 0; k < ESDIRK_DEGREES; k++) {
            D[k] += x;
            W[k] += y;
            x *= u;
            y *= u;
        }
    }
    mom->S[0] = S0;
    for (k = 0; k < ESDIRK_DEGREES; k++)
        mom->S[k + 1] = mom->S[k] - D[k];
    memcpy(mom->D, D, sizeof D);
    memcpy(mom->W, W, sizeof W);
    for (k = 1; k < ESDIRK_STAGES; k++)
        mom->mu[0][k] = mom->S[k];
    return 1.0 / (cm->p.c_alpha * (m->eta + hg * W[0]));
}

/* sum_{k<i} a_ik mu_k[m] */
static double esdirk_moments_past(int i, int m, const esdirk_moments *mom)
{
    double past = 0.0;
    int k;
    for (k = 0; k < i; k++)
        past += esdirk_a[i][k] * mom->mu[k][m];
    return past;
}

/* Stage i's pull A_i from the rates z[0..i-1]. */
static double esdirk_moments_pull(const contact_model *cm, double h, int i, const double *z, const esdirk_moments *mom)
{
    double Z = 0.0;
    int k;
    for (k = 0; k < i; k++)
        Z += esdirk_a[i][k] * z[k];
    return cm->p.c_alpha * (mom->D[0] - esdirk_moments_past(i, 1, mom) * (1.0 / ESDIRK_GAMMA) + h * Z * mom->W[0]);
}

/* Stage i's sums once its rate z[i] is known. */
static void esdirk_moments_settle(double h, int i, const double *z, esdirk_moments *mom)
{
    double Z = ESDIRK_GAMMA * z[i];
    int k, m;
    for (k = 0; k < i; k++)
        Z += esdirk_a[i][k] * z[k];
    for (m = 0; m + i < ESDIRK_STAGES; m++)
        mom->mu[i][m] = mom->D[m] - esdirk_moments_past(i, m + 1, mom) * (1.0 / ESDIRK_GAMMA) + h * Z * mom->W[m];
}

/* The memory force's embedded error estimate: c_alpha sum a (phi_6 - phi_5),
 * the last stage's (the step's end) less the embedded solution's. */
static double esdirk_moments_error(const contact_model *cm, const esdirk_moments *mom)
{
    return cm->p.c_alpha * fabs(mom->mu[ESDIRK_STAGES - 1][0] - mom->mu[ESDIRK_EMBEDDED][0]);
}

/* The rates z_0..z_6 of an ESDIRK trial step from the model's state. */
static void esdirk_trial_rates(const contact_model *cm, const contact_state *trial, double z[ESDIRK_STAGES])
{
    z[0] = cm->s.x2_rate;
    z[1] = trial->x2_rate1;
    memcpy(z + 2, trial->x2_rate_inner, sizeof trial->x2_rate_inner);
    z[ESDIRK_STAGES - 1] = trial->x2_rate;
}

/* The last stage's modes as a polynomial in u: by the recursion of
 * esdirk_moments each stage's modes are phi_i = sum_m u^m q_i[m],
 *     q_0[0] = phi_n,
 *     q_i[m] = ([m = 0] - [m = 1]) (phi_n + h Zt_i) - (1/gamma) sum_{k<i} a_ik q_k[m - 1],
 *     Zt_i = sum_{k<i} a_ik z_k + gamma z_i,
 * linear in phi_n and the h Zt_l, so that the last stage's coefficients are
 *     q_6[m] = ESDIRK_LAST_STAGE[m][0] phi_n + sum_{l>=1} ESDIRK_LAST_STAGE[m][l] h Zt_l,
 * the table below that recursion's from each unit (phi_n = 1 or one h Zt_l =
 * 1), to 17 digits: constants of the tableau, where the recursion on every
 * accepted step would cost more than the modes' own update
 * (tests/test_contact.c checks them against the stages taken one by one). */
static const double ESDIRK_LAST_STAGE[ESDIRK_STAGES][ESDIRK_STAGES] = {
    {1, 0, 0, 0, 0, 0, 1},
    {-3.8461538461538458, 0, 0.21141956909762985, 0.15840872032004025, -2.4228194191929382, -0.26778767108472029, -1},
    {3.5502958579881638, 0, 0.12268131785870509, -1.3530713408788944, 3.0608033489286859, 0.26778767108472029, 0},
    {1.4641177363070845, 0.85437020047787537, -0.72053796936316161, 1.5158802770475246, -0.63798392973574747, 0, 0},
    {-0.98677684021334378, -0.19439448404171211, 0.46638192255768962, -0.32121765648867029, 0, 0, 0},
    {-1.6982544782691826, -0.91836150160672481, -0.079944840150862978, 0, 0, 0, 0},
    {0.51677157034112287, 0.25838578517056143, 0, 0, 0, 0, 0}};

/* The modes after an accepted ESDIRK step from the model's state: the last
 * stage's (stiffly accurate), so that whichever of an event search's trials
 * is accepted brings its own; each mode's end two independent Horner
 * evaluations in its u. */
void esdirk_advance_modes(contact_model *cm, const contact_state *trial)
{
    const int last = ESDIRK_STAGES - 1;
    contact_modes *m = &cm->modes;
    const double h = trial->step, hg = ESDIRK_GAMMA * h;
    double z[ESDIRK_STAGES], rate[ESDIRK_STAGES], add[ESDIRK_STAGES];
    size_t j;
    int i, k, n;
    esdirk_trial_rates(cm, trial, z);
    for (i = 1; i < ESDIRK_STAGES; i++) {
        double Z = ESDIRK_GAMMA * z[i];
        for (k = 0; k < i; k++)
            Z += esdirk_a[i][k] * z[k];
        rate[i] = h * Z;
    }
    for (n = 0; n < ESDIRK_STAGES; n++) {
        add[n] = 0.0;
        for (i = 1; i < ESDIRK_STAGES; i++)
            add[n] += ESDIRK_LAST_STAGE[n][i] * rate[i];
    }
    for (j = 0; j < m->modes; j++) {
        const double u = hg * m->b[j] / (1.0 + hg * m->b[j]);
        double keep = ESDIRK_LAST_STAGE[last][0], more = add[last];
        for (n = last - 1; n >= 0; n--) {
            keep = keep * u + ESDIRK_LAST_STAGE[n][0];
            more = more * u + add[n];
        }
        m->phi[j] = keep * m->phi[j] + more;
    }
}

/* One ESDIRK step of length h from *in with spring stiffness K (the
 * contract of sdirk_step), the damper a dashpot (mem NULL) or the
 * compressed springpot (mem its stages' scratch, its explicit stage 0 at
 * the start's rate in->x2_rate); inlined twice below, so that the
 * dashpot's copy carries none of the springpot's work. out->error is the
 * embedded estimate of its error over the tolerance: x1's and x2's
 * relative to the larger of the elastic indentation at the step's ends and
 * at the contact's peak force so far (relative in the force at onset, where
 * x1^n is not smooth, grading the first steps), v's relative to the speed
 * at onset or now; a springpot's modes are state too, and their force's
 * error counts as the travel it would drive over the step through the
 * stage's viscosity. The springpot's E_diss is the order-5 quadrature of
 * F x2', as the dashpot's of F^2/c (SDIRK2's mean force times the travel
 * is of order 2 only). */
static inline double esdirk_step_of(contact_model *cm, const contact_state *in, double h, double K, contact_state *out,
                                    esdirk_moments *mem)
{
    const int last = ESDIRK_STAGES - 1;
    damper_stage damper = {0.0, cm->inv_c};
    double F[ESDIRK_STAGES], z[ESDIRK_STAGES], rise[ESDIRK_STAGES];
    double X = in->x1, V = in->v, X_embedded = 0.0, V_embedded = 0.0, x2_embedded = 0.0;
    double impulse = 0.0, work = 0.0, travel = 0.0, length, speed, error;
    int i, j;
    F[0] = in->F;
    z[0] = mem ? in->x2_rate : F[0] * cm->inv_c;
    if (mem)
        damper.inv_B = esdirk_moments_begin(cm, h, mem);
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
            if (mem)
                damper.A = esdirk_moments_pull(cm, h, i, z, mem);
            F[i] = implicit_stage(cm, K, ESDIRK_GAMMA * h, xh, vh, damper, &X, &V);
            z[i] = (F[i] - damper.A) * damper.inv_B;
            if (mem)
                esdirk_moments_settle(h, i, z, mem);
            /* h x1' from the stage's equation X = xh + gamma h x1': a
             * shorter chain than h (V - z) */
            rise[i] = (X - xh) * (1.0 / ESDIRK_GAMMA);
        } else {
            rise[0] = h * (V - z[0]);
        }
        if (i == ESDIRK_EMBEDDED) {
            X_embedded = X;
            V_embedded = V;
            for (j = 0; j <= i; j++)
                x2_embedded += h * esdirk_a[i][j] * (mem ? z[j] : F[j]);
        }
    }
    for (j = 0; j <= last; j++) {
        impulse += h * esdirk_a[last][j] * F[j];
        if (mem) {
            travel += h * esdirk_a[last][j] * z[j];
            work += h * esdirk_a[last][j] * F[j] * z[j];
        } else
            work += h * esdirk_a[last][j] * F[j] * F[j];
    }
    length = larger(larger(fabs(in->x1), fabs(X)), DBL_MIN);
    if (in->F_peak_contact > larger(in->F, F[last])) /* past the peak: its indentation is the larger */
        length = larger(length, peak_indentation(cm, K, in->F_peak_contact));
    speed = larger(larger(fabs(in->v), fabs(V)), larger(fabs(in->v_onset), DBL_MIN));
    *out = *in;
    out->t = in->t + h;
    out->x1 = X;
    out->v = V;
    out->F = F[last];
    out->step = h;
    out->x2_rate1 = z[1];
    out->x2_rate = z[last];
    if (mem) {
        out->x2 = in->x2 + travel;
        out->E_diss = in->E_diss + work;
        memcpy(out->x2_rate_inner, z + 2, sizeof out->x2_rate_inner);
        error = larger(larger(fabs(X - X_embedded), fabs(travel - x2_embedded)),
                       esdirk_moments_error(cm, mem) * damper.inv_B * h) / length;
    } else {
        out->x2 = in->x2 + impulse * cm->inv_c;
        out->E_diss = in->E_diss + work * cm->inv_c;
        error = larger(fabs(X - X_embedded), fabs(impulse - x2_embedded) * cm->inv_c) / length;
    }
    out->error = larger(error, fabs(V - V_embedded) / speed) / cm->p.tolerance;
    return impulse;
}

static double springpot_esdirk_step(contact_model *cm, const contact_state *in, double h, double K, contact_state *out)
{
    esdirk_moments mem;
    return esdirk_step_of(cm, in, h, K, out, &mem);
}

/* An error-controlled step: the dashpot's, or the compressed springpot's
 * (out of contact a recovering springpot's SDIRK2 step: esdirk_steps). */
double esdirk_step(contact_model *cm, const contact_state *in, double h, double K, contact_state *out)
{
    if (!springpot(cm))
        return esdirk_step_of(cm, in, h, K, out, NULL);
    if (!esdirk_steps(cm, in))
        return sdirk_step(cm, in, h, K, out);
    return springpot_esdirk_step(cm, in, h, K, out);
}
