/* SDIRK2, the fixed steps (docs/model.md §11): Alexander's two-stage
 * singly diagonally implicit Runge-Kutta method (R. Alexander, SIAM J.
 * Numer. Anal. 14 (1977) 1006-1021), gamma = 1 - 1/sqrt(2),
 *     gamma      | gamma
 *     1          | 1 - gamma   gamma
 *     -----------+-------------------
 *                | 1 - gamma   gamma
 * and the springpot's compressed memory in its stages (§6). */
#include <stddef.h>

#include "stage.h"

/* Alexander's two-stage SDIRK: L-stable, second order, stiffly accurate.
 * L-stability keeps the step stable however fast the dashpot relaxes, and
 * damps rather than reflects what a long step cannot resolve. */
#define SDIRK_GAMMA 0.29289321881345248 /* 1 - 1/sqrt(2) */

/* The springpot F = c_alpha (eta x2' + sum_i a_i phi_i), phi_i' = -b_i phi_i
 * + x2' (docs/model.md §6), in the SDIRK stages of a step of length h: with
 * d_i = 1/(1 + gamma h b_i) each stage's modes are d_i (their explicit part
 * + gamma h x2'), so the force is linear in x2' with the coefficients below,
 * which depend on h alone and are kept for the step length last used. */
static const contact_modes *modes_for_step(contact_model *cm, double h)
{
    contact_modes *m = &cm->modes;
    const double hg = SDIRK_GAMMA * h, hb = (1.0 - SDIRK_GAMMA) * h;
    size_t i;
    if (m->h == h)
        return m;
    m->sum_p = m->sum_q = 0.0;
    for (i = 0; i < m->modes; i++) {
        double d = 1.0 / (1.0 + hg * m->b[i]);
        m->p[i] = m->a[i] * d;
        m->q[i] = m->p[i] * d * m->b[i];
        m->sum_p += m->p[i];
        m->sum_q += m->q[i];
        /* phi_new = keep phi + rate1 x2'_1 + rate2 x2'_2 over the step */
        m->keep[i] = d * (1.0 - hb * m->b[i] * d);
        m->rate1[i] = d * d * hb;
        m->rate2[i] = d * hg;
    }
    m->h = h;
    return m;
}

/* The two stages' damper terms of a springpot step from the modes phi:
 * stage 1 from sum p phi; stage 2, after the first stage's rate z1, from the
 * modes advanced explicitly by (1 - gamma) h. */
static void springpot_stages(contact_model *cm, double h, damper_stage *d1, double *S2)
{
    const contact_modes *m = modes_for_step(cm, h);
    const double c = cm->p.c_alpha;
    double S1 = 0.0, Sq = 0.0;
    size_t i;
    for (i = 0; i < m->modes; i++) {
        S1 += m->p[i] * m->phi[i];
        Sq += m->q[i] * m->phi[i];
    }
    d1->A = c * S1;
    d1->inv_B = 1.0 / (c * (m->eta + SDIRK_GAMMA * h * m->sum_p));
    *S2 = Sq;
}

static void springpot_second_stage(const contact_model *cm, double h, const damper_stage *d1, double Sq, double z1,
                                   damper_stage *d2)
{
    const contact_modes *m = &cm->modes;
    const double hg = SDIRK_GAMMA * h, hb = (1.0 - SDIRK_GAMMA) * h;
    d2->A = d1->A + cm->p.c_alpha * hb * (z1 * m->sum_p - (Sq + hg * z1 * m->sum_q));
    d2->inv_B = d1->inv_B;
}

/* The modes after an accepted step of length h with stage rates z1, z2. */
void advance_modes(contact_model *cm, double h, double z1, double z2)
{
    const contact_modes *m = modes_for_step(cm, h);
    size_t i;
    for (i = 0; i < m->modes; i++)
        cm->modes.phi[i] = m->keep[i] * m->phi[i] + m->rate1[i] * z1 + m->rate2[i] * z2;
}

/* One SDIRK step of length h from *in with spring stiffness K (0: no
 * contact: free flight, exact while the damper rests). Writes t, x1, x2, v,
 * F, E_diss and what accepting the step needs (its length and the damper's
 * stage rates) of *out; returns the impulse of the contact force. Inlined
 * in the dashpot's and the springpot's steps below, so that the dashpot's
 * carries none of the springpot's work: `springpot` is a constant in each. */
static inline double sdirk_step_of(contact_model *cm, const contact_state *in, double h, double K, contact_state *out,
                                   const int springpot, const int compressed)
{
    const double hg = SDIRK_GAMMA * h, hb = (1.0 - SDIRK_GAMMA) * h;
    damper_stage d1 = {0.0, cm->inv_c}, d2 = {0.0, cm->inv_c};
    double X1, V1, X2, V2, F1, F2, z1, z2, impulse, Sq = 0.0;

    if (compressed)
        springpot_stages(cm, h, &d1, &Sq);
    F1 = implicit_stage(cm, K, hg, in->x1, in->v, d1, &X1, &V1);
    z1 = (F1 - d1.A) * d1.inv_B;
    if (compressed)
        springpot_second_stage(cm, h, &d1, Sq, z1, &d2);
    F2 = implicit_stage(cm, K, hg, in->x1 + hb * (V1 - z1), in->v + hb * (cm->accel - cm->inv_m * F1), d2, &X2,
                        &V2);
    z2 = (F2 - d2.A) * d2.inv_B;
    impulse = hb * F1 + hg * F2;

    carry_state(out, in);
    out->t = in->t + h;
    out->x1 = X2;
    out->v = V2;
    out->F = F2;
    out->step = h;
    out->x2_rate1 = z1;
    out->x2_rate = z2;
    if (springpot) {
        /* The mean force J/h times the travel, as the dashpot below counts
         * (within O(h^3) of the integral of F x2'; at alpha = 1 the same). */
        out->x2 = in->x2 + hb * z1 + hg * z2;
        out->E_diss = in->E_diss + (h > 0.0 ? impulse * (out->x2 - in->x2) / h : 0.0);
        return impulse;
    }
    /* The dashpot carries the spring's force: x2' = F/c, dissipating F^2/c.
     * A step counts J^2/(c h), the dissipation of its mean force J/h: within
     * O(h^3) of the integral (which exceeds it by h Var(F)/c), and unlike a
     * quadrature of the stage forces it does not overshoot the energy there
     * is when a step is far too long to resolve the motion. */
    out->x2 = in->x2 + impulse * cm->inv_c;
    out->E_diss = in->E_diss + (h > 0.0 ? impulse * impulse * cm->inv_c / h : 0.0);
    return impulse;
}

double sdirk_dashpot_step(contact_model *cm, const contact_state *in, double h, double K, contact_state *out)
{
    return sdirk_step_of(cm, in, h, K, out, 0, 0);
}

double sdirk_springpot_step(contact_model *cm, const contact_state *in, double h, double K, contact_state *out)
{
    return sdirk_step_of(cm, in, h, K, out, 1, compressed_memory(cm));
}

const contact_method_record sdirk2_method = {
    .method = CONTACT_METHOD_SDIRK2,
    .name = "sdirk2",
    .dashpot_step = sdirk_dashpot_step,
    .springpot_step = sdirk_springpot_step,
    .accept = sdirk2_accept,
};
