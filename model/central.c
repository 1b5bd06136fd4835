/* The paper's central differences (docs/model.md §15). */
#include "contact_internal.h"

/* The paper's explicit scheme (docs/model.md §15), kept for comparison: x'' by
 * central differences (Stormer), the dashpot x2' = F/c by forward Euler with
 * the force of the step's start, so it is stable only while the dashpot's
 * relaxation lambda h < 2. Onset and separation are where x1 changes sign,
 * their times interpolated linearly; no step is split. */
static void central_internal_step(contact_model *cm, double h, double *impulse)
{
    contact_state *s = &cm->s;
    const double x = s->x1 + s->x2, x1 = s->x1, t = s->t, F = s->F;
    const double a = cm->accel - cm->inv_m * F;
    double x_next, x1_next;
    if (s->h_prev != h) /* (re)start the two-step recursion from the velocity */
        s->x_prev = x - h * s->v + 0.5 * h * h * a;
    x_next = cm->inv_m > 0.0 ? 2.0 * x - s->x_prev + h * h * a : x + h * s->v;
    s->x2 += h * F * cm->inv_c;
    s->E_diss += h * F * F * cm->inv_c;
    *impulse += h * F;
    x1_next = x_next - s->x2;
    if (!s->in_contact && x1_next > 0.0)
        begin_contact(s, t + h * (x1 < 0.0 ? x1 / (x1 - x1_next) : 0.0), s->v);
    s->x_prev = x;
    s->h_prev = h;
    s->x1 = x1_next;
    s->t = t + h;
    if (s->in_contact) {
        s->n++;
        s->F = x1_next > 0.0 ? spring_force(cm, contact_spring_stiffness(cm, s->n), x1_next) : 0.0;
    }
    if (cm->inv_m > 0.0) /* second-order velocity at the step's end */
        s->v = (x_next - x) / h + 0.5 * h * (cm->accel - cm->inv_m * s->F);
    if (s->F > s->F_peak_contact)
        s->F_peak_contact = s->F;
    if (s->F > s->F_peak)
        s->F_peak = s->F;
    if (s->in_contact && !(x1_next > 0.0))
        end_contact(s, t + h * x1 / (x1 - x1_next), s->v);
}

/* A step, and whether it ended with an event of the mask stop_at. */
static int central_grid_step(contact_model *cm, double h, double *impulse, unsigned stop_at)
{
    const int was_in_contact = cm->s.in_contact;
    central_internal_step(cm, h, impulse);
    return cm->s.in_contact != was_in_contact && (stop_at & (cm->s.in_contact ? CONTACT_ONSET : CONTACT_SEPARATION));
}

const contact_method_record central_method = {
    .method = CONTACT_METHOD_CENTRAL,
    .name = "central",
    .uniform_grid = "central scheme's",
    .fixed_steps = "the central differences (scheme = 2) take fixed steps of dt_max",
    .grid_step = central_grid_step,
};
