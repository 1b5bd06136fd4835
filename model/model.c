/* The model's life cycle (configure, start, drive, release, copy), its
 * outputs, and the springpot's memory as values for saving a state. */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "contact_internal.h"
#include "soe.h"

/* Gamma(5/2) = 3 sqrt(pi) / 4: x1^(3/2) = Gamma(5/2) D^(-1/2) x1 (docs/model.md §3). */
#define GAMMA_5_2 1.329340388179137

/* Zero modes up to a whole number of the lanes the springpot's passes sum
 * in (the arrays' room): they add exact zeros. */
static void pad_modes(contact_modes *m)
{
    size_t j;
    for (j = m->modes; j < m->room; j++)
        m->a[j] = m->b[j] = m->phi[j] = 0.0;
}

static int kernel_fits(const contact_kernel *k, const contact_params *p)
{
    return k->floor == memory_kernel_floor(p) && k->damper_order == p->damper_order
           && k->memory_tolerance == p->memory_tolerance;
}

/* The arrays of the compressed memory's block, one after another. */
#define MODE_ARRAYS 12

/* The block's arrays for `modes` modes, padded to whole lanes: the block
 * kept where it holds them, a new one replacing it otherwise, its values
 * unset (whoever takes it sets what a step reads: modes_at_rest,
 * pad_modes, contact_copy). 0, or -1 when memory runs out (the block as it
 * was). */
static int reserve_modes(contact_modes *m, size_t modes)
{
    const size_t room = (modes + CONTACT_MODE_LANES - 1) / CONTACT_MODE_LANES * CONTACT_MODE_LANES;
    double *block;
    if (room <= m->room)
        return 0;
    block = malloc(MODE_ARRAYS * room * sizeof *block);
    if (!block)
        return -1;
    free(m->a);
    m->room = room;
    m->a = block;
    m->b = block + room;
    m->phi = block + 2 * room;
    m->p = block + 3 * room;
    m->q = block + 4 * room;
    m->keep = block + 5 * room;
    m->rate = block + 6 * room;
    m->radau_d = block + 7 * room;
    return 0;
}

/* The compressed memory's kernel (docs/model.md §6), from *kept when it
 * fits p, and kept there otherwise (kept may be NULL); -1 when memory for
 * its modes runs out. */
static int memory_kernel(contact_modes *m, const contact_params *p, contact_kernel *kept)
{
    contact_kernel built;
    const contact_kernel *k = kept && kernel_fits(kept, p) ? kept : &built; /* only a kernel that fits is kept */
    if (k == &built) {
        built.modes = soe_kernel(p->damper_order, p->memory_tolerance, memory_kernel_floor(p), CONTACT_MEMORY_SPAN,
                                 CONTACT_MAX_MODES, built.a, built.b, &built.eta);
        if (built.modes > CONTACT_MAX_MODES) /* contact_check_params refuses such parameters */
            built.modes = CONTACT_MAX_MODES;
        built.damper_order = p->damper_order;
        built.memory_tolerance = p->memory_tolerance;
        built.floor = memory_kernel_floor(p);
        if (kept)
            *kept = built;
    }
    if (reserve_modes(m, k->modes) != 0)
        return -1;
    m->modes = k->modes;
    m->eta = k->eta;
    if (!k->modes) /* a kernel of no modes (alpha = 1) has no block to fill */
        return 0;
    memcpy(m->a, k->a, k->modes * sizeof m->a[0]);
    memcpy(m->b, k->b, k->modes * sizeof m->b[0]);
    return 0;
}

static int configure(contact_model *cm, const contact_params *p, contact_kernel *kept)
{
    const double n = p->spring_exponent;
    if (p->damper == CONTACT_DAMPER_SPRINGPOT && p->memory == CONTACT_MEMORY_COMPRESSED
        && memory_kernel(&cm->modes, p, kept) != 0)
        return -1;
    cm->p = *p;
    cm->k = spring_constant(p);
    cm->n_gamma = n == 1.5 ? GAMMA_5_2 : tgamma(n + 1.0);
    cm->inv_c = 1.0 / p->c;
    cm->k_fixed = p->law == CONTACT_LAW_HERTZ ? cm->k
                  : p->g1_nodes > 0 ? cm->k * g1_ratio(p->law, n, (double)p->g1_nodes) : 0.0;
    cm->method = method_record(p);
    cm->h_max = contact_step_limit(p);
    resolve_contact(cm);
    /* An error-controlled step needs its stages' roots well inside its
     * tolerance, not to rounding. */
    cm->series_limit = error_controlled(cm) ? pow(1e-3 * p->tolerance / 20.0, 2.0 / 7.0) : 0.0;
    cm->peak_force_seen = -1.0;
    cm->peak_length = 0.0;
    if (!compressed_memory(cm))
        cm->modes.modes = 0;
    cm->modes.h = 0.0;
    cm->modes.radau_h = 0.0;
    pad_modes(&cm->modes);
    return 0;
}

/* The memory at rest (pad_modes zeroed the padding), and the coefficients
 * of no step length zero as in a model cleared whole: modes.h = 0 names
 * none, but a step of length 0 (a flight that touches at once) reads them
 * as they are. */
static void modes_at_rest(contact_modes *m)
{
    const size_t bytes = m->modes * sizeof m->phi[0];
    if (!m->modes)
        return;
    memset(m->phi, 0, bytes);
    memset(m->p, 0, bytes);
    memset(m->q, 0, bytes);
    memset(m->keep, 0, bytes);
    memset(m->rate, 0, bytes);
}

int contact_configure(contact_model *cm, const contact_params *p)
{
    const double *block = cm->modes.a;
    if (configure(cm, p, NULL) != 0)
        return -1;
    if (cm->modes.a != block) /* a new block: the coefficients too at rest */
        modes_at_rest(&cm->modes);
    return 0;
}

void contact_release_modes(contact_model *cm)
{
    free(cm->modes.a);
    memset(&cm->modes, 0, sizeof cm->modes);
}

void contact_release(contact_model *cm)
{
    contact_release_modes(cm);
    free(cm->history.x2);
    free(cm->history.w);
    memset(&cm->history, 0, sizeof cm->history);
}

int contact_start(contact_model *cm, const contact_params *p, double v0, double m)
{
    return contact_start_with(cm, p, v0, m, NULL);
}

/* Clears a model, its memory none (configure allocates the compressed
 * memory's block): the fields before the modes as one, the modes' and the
 * history's one by one. */
static void clear_model(contact_model *cm)
{
    static const contact_modes no_modes;
    memset(cm, 0, offsetof(contact_model, modes));
    cm->modes = no_modes;
    memset(&cm->history, 0, sizeof cm->history);
}

int contact_start_with(contact_model *cm, const contact_params *p, double v0, double m, contact_kernel *kernel)
{
    clear_model(cm);
    if (configure(cm, p, kernel) != 0)
        return -1;
    modes_at_rest(&cm->modes);
    cm->s.x1 = -p->gap0;
    cm->s.v = v0;
    if (p->scene == CONTACT_SCENE_DROP) {
        cm->inv_m = 1.0 / m;
        cm->accel = p->g;
        resolve_contact(cm);
    } else {
        contact_drive(cm, v0, m, 0.0);
    }
    return 0;
}

void contact_drive(contact_model *cm, double v, double m, double accel)
{
    if (cm->p.scene != CONTACT_SCENE_DRIVEN)
        return;
    if (v != cm->s.v)
        cm->s.h_prev = 0.0; /* a multistep scheme's past no longer leads here: restart it */
    cm->s.v = v;
    cm->inv_m = m > 0.0 ? 1.0 / m : 0.0;
    cm->accel = m > 0.0 ? cm->p.g + accel : accel;
    resolve_contact(cm);
}

double contact_damper_rate(const contact_model *cm)
{
    return springpot(cm) ? cm->s.x2_rate : cm->s.F * cm->inv_c;
}

double contact_x2_end(const contact_model *cm)
{
    const contact_state *s = &cm->s;
    if (full_history(cm))
        return g1_history_x2_end(cm);
    return s->x2 - contact_damper_rate(cm) * (s->t - (s->t_onset + s->t_contact));
}

void contact_rates(const contact_model *cm, double *x1_rate, double *v_rate, double *F_rate)
{
    const contact_state *s = &cm->s;
    const double n = cm->p.spring_exponent;
    double x1 = contact_elastic_indentation(cm);
    *x1_rate = s->in_contact ? s->v - contact_damper_rate(cm) : 0.0;
    *v_rate = cm->accel - cm->inv_m * s->F;
    *F_rate = x1 > 0.0 ? n * contact_spring_stiffness(cm, s->n) * pow(x1, n - 1.0) * *x1_rate : 0.0;
}

double contact_spring_stiffness(const contact_model *cm, long n_steps)
{
    return spring_stiffness(cm, n_steps);
}

/* Whether the springpot holds no memory: before its first contact. */
int memory_at_rest(const contact_model *cm)
{
    size_t i;
    if (!springpot(cm))
        return 1;
    if (cm->s.x2 != 0.0 || cm->s.x2_rate != 0.0)
        return 0;
    for (i = 0; i < cm->modes.modes; i++)
        if (cm->modes.phi[i] != 0.0)
            return 0;
    return 1;
}

int contact_never_returns(const contact_model *cm)
{
    const contact_state *s = &cm->s;
    const double a = cm->accel;
    if (s->in_contact || a > 0.0)
        return 0;
    /* A recovering dent (x2 falls towards 0, never below) may still meet a
     * striker that has not cleared the undeformed surface. */
    if (!memory_at_rest(cm) && !(s->v <= 0.0 && s->x1 + s->x2 <= 0.0))
        return 0;
    return !contact_flight_arrives(s->x1, s->v, a);
}

int contact_flight_arrives(double x1, double v, double a)
{
    if (a > 0.0)
        return 1;
    if (v > 0.0) /* heading in: it arrives unless a deceleration turns it in the gap first */
        return !(a < 0.0) || x1 + 0.5 * v * v / -a > 0.0;
    return 0;
}

int contact_rests(const contact_model *cm)
{
    const contact_state *s = &cm->s;
    /* the force's test first: every step in contact asks, and it fails while the force lasts */
    return s->in_contact && s->F <= DBL_EPSILON * s->F_peak_contact && !springpot(cm) && cm->accel == 0.0
           && fabs(s->v) <= DBL_EPSILON * fabs(s->v_onset);
}

double contact_elastic_indentation(const contact_model *cm)
{
    return cm->s.x1 > 0.0 ? cm->s.x1 : 0.0;
}

double contact_total_indentation(const contact_model *cm)
{
    return cm->s.x1 + cm->s.x2;
}

double contact_semi_integral_per_force(const contact_model *cm)
{
    return 1.0 / (cm->n_gamma * cm->k);
}

double contact_semi_integral(const contact_model *cm)
{
    return cm->s.F * contact_semi_integral_per_force(cm);
}

size_t contact_memory_count(const contact_model *cm)
{
    if (compressed_memory(cm))
        return 1 + cm->modes.modes;
    return full_history(cm) ? 4 + (size_t)cm->s.steps : 0;
}

double contact_memory_get(const contact_model *cm, size_t i)
{
    if (i == 0)
        return cm->s.x2_rate;
    if (compressed_memory(cm))
        return cm->modes.phi[i - 1];
    if (i < 3)
        return i == 1 ? cm->history.v_prev : cm->history.G_prev;
    return i - 3 < cm->history.capacity ? cm->history.x2[i - 3] : 0.0; /* x2(0) = 0 before the first step */
}

int contact_memory_accepts(const contact_model *cm, size_t count, char *msg, size_t len)
{
    size_t expected = contact_memory_count(cm);
    if (full_history(cm) && cm->s.steps > CONTACT_G1_HISTORY_MAX) {
        snprintf(msg, len, "a G1 history of %lld steps exceeds the limit of %d",
                 (long long)cm->s.steps, CONTACT_G1_HISTORY_MAX);
        return -1;
    }
    if (count != expected) {
        snprintf(msg, len, "the damper's memory holds %zu values where these parameters and %lld steps need %zu",
                 count, (long long)cm->s.steps, expected);
        return -1;
    }
    return 0;
}

int contact_memory_resize(contact_model *cm, size_t count)
{
    return full_history(cm) && count > 3 ? history_reserve(&cm->history, count - 3) : 0;
}

void contact_memory_set(contact_model *cm, size_t i, double value)
{
    if (i == 0)
        cm->s.x2_rate = value;
    else if (compressed_memory(cm))
        cm->modes.phi[i - 1] = value;
    else if (i < 3)
        *(i == 1 ? &cm->history.v_prev : &cm->history.G_prev) = value;
    else
        cm->history.x2[i - 3] = value;
}

int contact_copy_room(contact_model *to, const contact_model *from)
{
    return from->modes.modes ? reserve_modes(&to->modes, from->modes.modes) : 0;
}

void contact_copy(contact_model *to, const contact_model *from)
{
    const contact_modes *f = &from->modes;
    contact_modes *t = &to->modes;
    const size_t bytes = f->modes * sizeof f->a[0];
    /* all but the modes, then the modes' scalars and the used part of each
     * array into to's block, padded as the original's */
    memcpy(to, from, offsetof(contact_model, modes));
    to->history = from->history;
    t->modes = f->modes;
    t->eta = f->eta;
    t->h = f->h;
    t->radau_h = 0.0; /* radau_d is not copied */
    t->sum_q = f->sum_q;
    t->sum_rate = f->sum_rate;
    if (!f->modes)
        return;
    memcpy(t->a, f->a, bytes);
    memcpy(t->b, f->b, bytes);
    memcpy(t->phi, f->phi, bytes);
    memcpy(t->p, f->p, bytes);
    memcpy(t->q, f->q, bytes);
    memcpy(t->keep, f->keep, bytes);
    memcpy(t->rate, f->rate, bytes);
    pad_modes(t);
}

size_t contact_model_bytes(const contact_model *cm)
{
    return sizeof *cm + MODE_ARRAYS * cm->modes.room * sizeof(double)
           + 2 * cm->history.capacity * sizeof(double);
}
