#include "fmu_model.h"

#include "fmu_me.h"
#include "fmu_vars.h"
#include "serial.h"

#include <float.h>
#include <inttypes.h>
#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The model advanced by one more communication step from the end of the
 * last, computed with F_avg_next: the next step itself when its inputs come
 * as assumed (a memo of a deterministic computation, so that dropping it
 * changes no result; not part of the FMU state). A full G1 history's buffer
 * is shared with the model, room for the step reserved first. */
typedef struct {
    int valid;
    int event;            /* an onset or a separation inside it */
    double H;             /* the step's length */
    double impulse;       /* the contact force's impulse over it */
    contact_model model;  /* the state at its end */
} prediction;

/* The inputs: the striker's velocity and mass, the second body's, and the
 * accelerations the forces other than this contact give each of them
 * (docs/two_bodies.md). The model's striker is their relative motion. */
typedef struct {
#define INPUT_FMU_LIBRARY(name, type, ...) CONTACT_TYPE(type) name;
#define INPUT_FMU(name, type, ...) CONTACT_TYPE(type) name;
#include "parameters.def"
} bodies;

/* The communication step's side of the coupling: the force outputs, the
 * impulse owed and the energy account, which a refused step puts back as
 * they were. */
typedef struct {
    double F_avg;         /* impulse of the last communication step / its length */
    double span;          /* that length: where an early return cut it, so far */
    double F_avg_next;    /* (predicted impulse of the next step + owed) / H; F before the first step */
    double owed;          /* the contact's impulse so far less what F_avg_next announced over it [N s] */
    double announced;     /* F_avg_next as the communication step began: what the master applies over it */
    double start;         /* where the communication step began, */
    double H;             /* the step size requested then (FM_CONTINUE goes on with both), and
                             the length of the step F_avg_next predicts */
    coupling_energy energy; /* a proxy striker's energy account (docs/model.md §17) */
    double correction;    /* what the account adds to the force output for the bodies' next interval */
} step_account;

struct fmu_model {
    contact_params params;
    int coupling;         /* enum fmu_coupling */
    bodies in;            /* the inputs as last set */
    double v_slope;       /* dv/dt given by the master for the next step (0: v held) */
    step_account step;
    int64_t predicted;    /* communication steps taken from the prediction, */
    int64_t computed;     /* and computed afresh */
    int started;          /* past initialization: fixed parameters are frozen */
    int held;             /* a step stopped at an event: the discrete outputs show */
    int held_contact;     /* their values from before it until fm_update_discrete */
    int coupling_warned;  /* the master was seen feeding the other coupling's force, and told */
    double held_eps;
    int model_exchange;   /* serves a Model Exchange instance (fm_me_instantiated) */
    double me_speed, me_mass; /* Model Exchange: the approach speed and mass its nominal values are of */
    int no_prediction;    /* the FMU does not offer F_avg_next (fm_leave_out): nothing predicts */
    contact_model model;
    prediction *next;     /* allocated at the start where F_avg_next is offered, else NULL */
    fmu_reporter log;
};

#define PARAM(field) offsetof(fmu_model, params.field)

/* The most internal steps one communication step may take: about a minute
 * of CPU; beyond that a step is a mistake, not a wish. The fuzzers build the
 * FMU with a lower limit (CMakeLists.txt), so that no input runs long. */
#ifndef MAX_STEPS
#define MAX_STEPS 1000000000
#endif

/* The FMU's rows of parameters.def: an input is a member of in, a
 * model's parameter of params, the binding's own parameter (coupling) of
 * fmu_model, and an output is computed (real_output). */
#define VARIABLE(name, type, causality, offset) {VR_##name, #name, VAR_TYPE_##type, causality, offset},
#define VAR_TYPE_Real VAR_REAL
#define VAR_TYPE_Integer VAR_INTEGER
#define VAR_TYPE_Boolean VAR_BOOLEAN
#define INPUT(name, type, ...) VARIABLE(name, type, VAR_INPUT, offsetof(fmu_model, in.name))
#define MODEL_PARAMETER(name, type, ...) VARIABLE(name, type, VAR_PARAMETER, PARAM(name))
#define OWN_PARAMETER(name, type, ...) VARIABLE(name, type, VAR_PARAMETER, offsetof(fmu_model, name))
#define OUTPUT(name, type, ...) VARIABLE(name, type, VAR_OUTPUT, 0)
static const fmu_variable variable_list[] = {
#define INPUT_FMU_LIBRARY INPUT
#define INPUT_FMU INPUT
#define PARAMETER_MODEL_FMU_LIBRARY MODEL_PARAMETER
#define PARAMETER_FMU OWN_PARAMETER
#define OUTPUT_FMU OUTPUT
#include "parameters.def"
};
#undef VARIABLE
#undef INPUT
#undef MODEL_PARAMETER
#undef OWN_PARAMETER
#undef OUTPUT

static const fmu_variables variables = {variable_list, sizeof variable_list / sizeof variable_list[0]};

#define report(fm, ...) fmu_say(&(fm)->log, __VA_ARGS__)

/* 0 when the binding's own parameter is usable, else -1 and why. */
static int check_coupling(const fmu_model *fm, int coupling, char *why, size_t len)
{
    if (coupling == COUPLING_JACOBI && fm->no_prediction)
        return contact_reject(why, len, "coupling", coupling,
                              "this FMU does not offer F_avg_next, which the master feeds with coupling = 2 "
                              "(Jacobi): 1 = the master feeds F_avg after this step (Gauss-Seidel)");
    if (coupling == COUPLING_GAUSS_SEIDEL || coupling == COUPLING_JACOBI)
        return 0;
    return contact_reject(why, len, "coupling", coupling,
                          "1 = the master feeds F_avg to the striker after this step (Gauss-Seidel), "
                          "2 = F_avg_next before it (Jacobi)");
}

/* The approach speed of the two bodies: the model's striker velocity. */
static double approach(const bodies *b)
{
    return b->v - b->v2;
}

/* The mass of the model's striker: the reduced mass m m2/(m + m2) of two
 * free bodies, m where the second is held (m2 = 0), 0 where the rate is
 * prescribed (m = 0). */
static double proxy_mass(const bodies *b)
{
    return contact_reduced_mass(b->m, b->m2);
}

/* What the other forces add to the approach's acceleration. */
static double other_accel(const bodies *b)
{
    return b->a - b->a2;
}

/* 0 when the inputs are usable in `scene` with the parameters *p (which
 * passed their check), else -1 and why: the striker's own rules, and the
 * same for the model's striker, the relative motion (the approach speed
 * and the reduced mass). */
static int check_bodies(const contact_params *p, int scene, const bodies *b, char *why, size_t len)
{
    const double mass = proxy_mass(b), accel = p->g + other_accel(b);
    if (contact_check_bodies(p, scene, b->v, b->m, b->v2, b->m2, why, len) != 0)
        return -1;
    if (!isfinite(b->a))
        return contact_reject(why, len, "a", b->a,
                              "the striker's acceleration from its other forces must be finite [m/s^2]");
    if (!isfinite(b->a2))
        return contact_reject(why, len, "a2", b->a2,
                              "the second body's acceleration from its other forces must be finite [m/s^2]");
    if (!isfinite(accel) || (p->damper == CONTACT_DAMPER_DASHPOT && !isfinite(mass * accel * (mass * accel) / p->c)))
        return contact_reject(why, len, "a", b->a,
                              "the approach's acceleration g + a - a2 must be finite, and so must the power "
                              "(m_r (g + a - a2))^2 / c it can dissipate (m_r the reduced mass m m2/(m + m2))");
    return 0;
}

/* Applies a parameter change only if the parameters stay valid. */
static fm_status set_parameter(fmu_model *fm, const fmu_variable *var, const void *value, size_t size)
{
    contact_params params = fm->params;
    int coupling = fm->coupling;
    char why[256];
    if (var->offset == offsetof(fmu_model, coupling))
        memcpy(&coupling, value, size);
    else
        memcpy((char *)&params + (var->offset - offsetof(fmu_model, params)), value, size);
    if (contact_check_params(&params, why, sizeof why) != 0 || check_coupling(fm, coupling, why, sizeof why) != 0)
        return report(fm, FM_ERROR, "logStatusError", "%s", why);
    memcpy((char *)fm + var->offset, value, size);
    return FM_OK;
}

/* Before initialization ends the outputs show the state the model would
 * start from with the values set so far. */
static void preview_start(fmu_model *fm)
{
    char why[256];
    if (fm->started)
        return;
    if (contact_check_params(&fm->params, why, sizeof why) == 0
        && check_bodies(&fm->params, CONTACT_SCENE_DRIVEN, &fm->in, why, sizeof why) == 0) {
        /* The mass only scales the dynamics, which a preview does not run. */
        contact_release(&fm->model);
        contact_start(&fm->model, &fm->params, approach(&fm->in), fm->in.m > 0.0 ? proxy_mass(&fm->in) : 1.0);
    }
}

double fm_time(const fmu_model *fm)
{
    return fm->model.s.t;
}

/* The start values that are not 0, and the outputs they give. */
static void start_values(fmu_model *fm)
{
    contact_default_params(&fm->params);
#define INPUT_FMU_LIBRARY(name, type, unit, value, ...) fm->in.name = value;
#define INPUT_FMU(name, type, unit, value, ...) fm->in.name = value;
#define PARAMETER_FMU(name, type, unit, value, ...) fm->name = value;
#include "parameters.def"
    preview_start(fm);
}

fm_status fm_set_real(fmu_model *fm, unsigned vr, double value)
{
    const fmu_variable *var = fmu_settable(&variables, vr, VAR_REAL, fm->started, &fm->log);
    bodies trial;
    char why[256];
    if (!var)
        return FM_ERROR;
    if (var->causality == VAR_PARAMETER)
        return set_parameter(fm, var, &value, sizeof value);
    /* Inputs: the rules that depend on the scene (m > 0 in the drop test)
     * or on other parameters (a uniform grid's resolution) wait for
     * fm_start, since those may still change. */
    trial = fm->in;
    *(double *)((char *)&trial + (var->offset - offsetof(fmu_model, in))) = value;
    if (check_bodies(&fm->params, CONTACT_SCENE_DRIVEN, &trial, why, sizeof why) != 0
        || (fm->started
            && contact_check_resolution(&fm->params, approach(&trial), proxy_mass(&trial), why, sizeof why) != 0))
        return report(fm, FM_ERROR, "logStatusError", "%s", why);
    fm->in = trial;
    if (vr == VR_v)
        fm->v_slope = 0.0; /* a new value: the old slope no longer describes it */
    return FM_OK;
}

static double real_output(const fmu_model *fm, unsigned vr)
{
    const contact_model *cm = &fm->model;
    switch (vr) {
    case VR_F: return cm->s.F;
    case VR_F_avg: return fm->step.F_avg + (fm->coupling == COUPLING_GAUSS_SEIDEL ? fm->step.correction : 0.0);
    case VR_F_avg_next:
        return fm->started ? fm->step.F_avg_next + (fm->coupling == COUPLING_JACOBI ? fm->step.correction : 0.0)
                           : cm->s.F;
    case VR_F_peak: return cm->s.F_peak;
    case VR_x: return contact_total_indentation(cm);
    case VR_x1: return contact_elastic_indentation(cm);
    case VR_x2: return cm->s.x2;
    case VR_v_striker: return cm->s.v;
    case VR_E_diss: return cm->s.E_diss;
    case VR_eps: return fm->held ? fm->held_eps : cm->s.eps;
    case VR_semi_integral: return contact_semi_integral(cm);
    default: return 0.0;
    }
}

/* The first real output whose value is not finite (a finite state can
 * still overflow a derived output, such as x1 + x2), or NULL. */
static const fmu_variable *nonfinite_output(const fmu_model *fm)
{
    size_t i;
    for (i = 0; i < variables.count; i++)
        if (variables.list[i].type == VAR_REAL && variables.list[i].causality == VAR_OUTPUT
            && !isfinite(real_output(fm, variables.list[i].vr)))
            return &variables.list[i];
    return NULL;
}

static int model_exchange_variable(fmu_model *fm, unsigned vr, double *value);
static void me_follow_inputs(fmu_model *fm);

fm_status fm_get_real(fmu_model *fm, unsigned vr, double *value)
{
    const fmu_variable *var;
    if (fm->model_exchange)
        me_follow_inputs(fm); /* the driven scene's rate is the inputs as set, not as last integrated */
    if (model_exchange_variable(fm, vr, value))
        return FM_OK;
    var = fmu_find(&variables, vr, VAR_REAL, &fm->log);
    if (!var)
        return FM_ERROR;
    if (vr == VR_F_avg_next && fm->no_prediction)
        return report(fm, FM_ERROR, "logStatusError",
                      "F_avg_next (value reference %u): this exported FMU does not offer it (its "
                      "resources/fixed_values.txt: omit F_avg_next); the Gauss-Seidel coupling reads F_avg", vr);
    preview_start(fm);
    *value = var->causality == VAR_OUTPUT ? real_output(fm, vr) : *(const double *)((const char *)fm + var->offset);
    return FM_OK;
}

fm_status fm_set_integer(fmu_model *fm, unsigned vr, int value)
{
    const fmu_variable *var = fmu_settable(&variables, vr, VAR_INTEGER, fm->started, &fm->log);
    return var ? set_parameter(fm, var, &value, sizeof value) : FM_ERROR;
}

fm_status fm_get_boolean(fmu_model *fm, unsigned vr, int *value)
{
    if (!fmu_find(&variables, vr, VAR_BOOLEAN, &fm->log))
        return FM_ERROR;
    preview_start(fm);
    *value = fm->held ? fm->held_contact : fm->model.s.in_contact;
    return FM_OK;
}

static fm_status order_one(fmu_model *fm, const char *what, unsigned vr, int order)
{
    if (order == 1)
        return FM_OK;
    return report(fm, FM_ERROR, "logStatusError", "%s: order %d for value reference %u: only order 1 is provided",
                  what, order, vr);
}

fm_status fm_set_input_derivative(fmu_model *fm, unsigned vr, int order, double value)
{
    if (order_one(fm, "SetRealInputDerivatives", vr, order) != FM_OK)
        return FM_ERROR;
    if (vr != VR_v)
        return report(fm, FM_ERROR, "logStatusError",
                      "SetRealInputDerivatives: value reference %u: only v (%d) takes a derivative", vr, VR_v);
    if (!isfinite(value))
        return report(fm, FM_ERROR, "logStatusError", "SetRealInputDerivatives: dv/dt = %g must be finite",
                      value);
    fm->v_slope = value;
    return FM_OK;
}

fm_status fm_get_output_derivative(fmu_model *fm, unsigned vr, int order, double *value)
{
    const contact_model *cm = &fm->model;
    double x1_rate, v_rate, F_rate;
    if (order_one(fm, "GetOutputDerivatives", vr, order) != FM_OK)
        return FM_ERROR;
    contact_rates(cm, &x1_rate, &v_rate, &F_rate);
    switch (vr) {
    case VR_F: *value = F_rate; break;
    case VR_x: *value = cm->s.v; break;
    case VR_x1: *value = x1_rate; break;
    case VR_x2: *value = contact_damper_rate(cm); break;
    case VR_v_striker: *value = v_rate; break;
    case VR_E_diss: *value = cm->s.F * contact_damper_rate(cm); break;
    case VR_semi_integral: *value = F_rate * contact_semi_integral_per_force(cm); break;
    default:
        return report(fm, FM_ERROR, "logStatusError",
                      "GetOutputDerivatives: value reference %u has no time derivative here "
                      "(F, x, x1, x2, v_striker, E_diss, semi_integral have)", vr);
    }
    /* Extreme but valid states (k near DBL_MAX, say) can overflow a rate
     * that the state itself does not. */
    if (!isfinite(*value))
        return report(fm, FM_ERROR, "logStatusError",
                      "GetOutputDerivatives: the time derivative of value reference %u overflows (%g)", vr,
                      *value);
    return FM_OK;
}

void fm_leave_out(fmu_model *fm, unsigned vr)
{
    if (vr == VR_F_avg_next)
        fm->no_prediction = 1; /* the prediction is what gives F_avg_next */
}

/* The prediction's storage where the FMU offers F_avg_next, with room for
 * the model's modes: 0, or -1 when memory runs out. */
static int prediction_room(fmu_model *fm)
{
    if (fm->no_prediction)
        return 0;
    if (!fm->next)
        fm->next = calloc(1, sizeof *fm->next);
    return fm->next ? contact_copy_room(&fm->next->model, &fm->model) : -1;
}

static void forget_prediction(fmu_model *fm)
{
    if (fm->next)
        fm->next->valid = 0;
}

static void release_prediction(fmu_model *fm)
{
    if (!fm->next)
        return;
    contact_release_modes(&fm->next->model);
    free(fm->next);
    fm->next = NULL;
}

fm_status fm_start(fmu_model *fm, double t0, double t_stop)
{
    char why[512];
    if (contact_check_params(&fm->params, why, sizeof why) != 0
        || check_coupling(fm, fm->coupling, why, sizeof why) != 0
        || check_bodies(&fm->params, fm->params.scene, &fm->in, why, sizeof why) != 0
        || contact_check_resolution(&fm->params, approach(&fm->in), proxy_mass(&fm->in), why, sizeof why) != 0
        || (isfinite(t_stop)
            && contact_check_history_span(&fm->params, approach(&fm->in), proxy_mass(&fm->in), t_stop - t0, 0,
                                          "stopTime - startTime", why, sizeof why) != 0))
        return report(fm, FM_ERROR, "logStatusError", "%s", why);
    contact_release(&fm->model);
    if (contact_start(&fm->model, &fm->params, approach(&fm->in), proxy_mass(&fm->in)) != 0
        || prediction_room(fm) != 0)
        return report(fm, FM_ERROR, "logStatusError", "out of memory for the springpot's %lu modes (memory = 2)",
                      (unsigned long)fm->model.modes.modes);
    fm->model.max_steps = MAX_STEPS;
    fm->model.s.t = t0;
    memset(&fm->step, 0, sizeof fm->step);
    /* No step length yet to predict over: the force now, the limit of a
     * vanishing step (0 at the start, where the striker has not touched). */
    fm->step.F_avg_next = fm->model.s.F;
    fm->predicted = fm->computed = 0;
    forget_prediction(fm);
    fm->held = 0;
    fm->started = 1;
    if (contact_unused_value(&fm->params, why, sizeof why)
        || (!fm->model_exchange /* the host's solver takes the steps */
            && contact_step_warning(&fm->params, approach(&fm->in), proxy_mass(&fm->in), why, sizeof why))
        || contact_arrival_warning(&fm->params, approach(&fm->in), why, sizeof why))
        return report(fm, FM_WARNING, "logStatusWarning", "%s", why);
    if (other_accel(&fm->in) != 0.0 && fm->params.scene == CONTACT_SCENE_DROP)
        return report(fm, FM_WARNING, "logStatusWarning",
                      "a = %g and a2 = %g have no effect in the drop test (scene = 1): its striker's only other "
                      "force is g", fm->in.a, fm->in.a2);
    if (fm->coupling != COUPLING_GAUSS_SEIDEL && fm->params.scene == CONTACT_SCENE_DROP)
        return report(fm, FM_WARNING, "logStatusWarning",
                      "coupling = %d has no effect in the drop test (scene = 1): the FMU's striker is its own",
                      fm->coupling);
    return FM_OK;
}

/* What a refused step puts back beside the state: the damper's rate and a
 * compressed memory's modes (a full G1 history keeps its past; the state's
 * step count says how much of it counts). */
typedef struct {
    size_t count;
    double values[CONTACT_MAX_MODES + 1];
} memory_copy;

static void save_memory(const contact_model *cm, memory_copy *copy)
{
    size_t i, count = contact_memory_count(cm);
    copy->count = count < CONTACT_MAX_MODES + 1 ? count : 1;
    for (i = 0; i < copy->count; i++)
        copy->values[i] = contact_memory_get(cm, i);
}

static void restore_memory(contact_model *cm, const memory_copy *copy)
{
    size_t i;
    for (i = 0; i < copy->count; i++)
        contact_memory_set(cm, i, copy->values[i]);
}

static void report_events(fmu_model *fm, const contact_state *before)
{
    const contact_state *s = &fm->model.s;
    if (s->impacts != before->impacts && fm->model_exchange) /* no communication steps to count */
        report(fm, FM_OK, "logEvents", "impact %" PRId64 " ended at t = %.9g s: eps = %.6g, x2 = %.6g m, "
               "F_peak = %.6g N", s->impacts, s->t, s->eps, s->x2, s->F_peak);
    else if (s->impacts != before->impacts)
        report(fm, FM_OK, "logEvents",
               "impact %" PRId64 " ended by t = %.9g s: eps = %.6g, x2 = %.6g m, F_peak = %.6g N; "
               "communication steps so far: %" PRId64 " taken from the prediction, %" PRId64 " computed",
               s->impacts, s->t, s->eps, s->x2, s->F_peak, fm->predicted, fm->computed);
    if (s->in_contact && (!before->in_contact || s->impacts != before->impacts))
        report(fm, FM_OK, "logEvents", "contact began in (%.9g, %.9g] s at %.6g m/s",
               before->t, s->t, s->v_onset);
}

void fm_update_discrete(fmu_model *fm)
{
    fm->held = 0;
}

/* Whether the contact began or an impact ended since `before`. */
static int event_since(const contact_state *before, const contact_state *now)
{
    return now->in_contact != before->in_contact || now->impacts != before->impacts;
}

fm_status fm_do_step(fmu_model *fm, double t, double H)
{
    int event;
    return fm_do_step_until(fm, t, H, 0u, &event);
}

/* A proxy striker's velocity from the master's before a step follows the
 * proxy's own end velocity from the last step when the two differ by no
 * more than this fraction of the velocities at hand: two integrations of
 * the same motion (the proxy's internal steps, the master's striker) differ
 * by rounding, which grows with the steps taken. Any larger difference is
 * a force on the striker the proxy did not know (gravity the FMU's g lacks,
 * a spring), and the master's velocity wins. Since the comparison is made
 * afresh each step against the master's velocity, the velocity the proxy
 * ignores never exceeds this fraction. */
#define SAME_MOTION 1e-12

/* Whether the master's velocity v, read as the coupling it names, is the
 * proxy's own motion ending at v_end (SAME_MOTION). */
static int same_motion(const fmu_model *fm, double v, double v_end)
{
    return fabs(v - v_end) <= SAME_MOTION * fmax(fmax(fabs(v), fabs(v_end)), fabs(fm->model.s.v_onset));
}

/* The velocity the step starts from. The master's v, except for a proxy
 * striker (driven scene, m > 0): with the Jacobi coupling less the impulse
 * owed (the striker has not yet received it), and its own end velocity
 * v_end when the master's agrees with it to rounding (SAME_MOTION). A
 * master that feeds the other force than `coupling` says (F_avg_next with
 * coupling = 1, F_avg with 2) shows it where its v is the proxy's motion
 * read as the other coupling: the proxy then follows its own motion too,
 * and *other says so. A deterministic function of the state and the
 * inputs, so that a memo of the step (the prediction) may be dropped
 * without changing a result. */
static double start_velocity(const fmu_model *fm, double v_end, int *other)
{
    double jacobi, gauss_seidel, v;
    *other = 0;
    if (fm->params.scene != CONTACT_SCENE_DRIVEN || !(fm->in.m > 0.0))
        return approach(&fm->in);
    /* the impulse owed acts on both bodies: on their approach through the reduced mass */
    jacobi = approach(&fm->in) - fm->step.owed / proxy_mass(&fm->in);
    gauss_seidel = approach(&fm->in);
    v = fm->coupling == COUPLING_JACOBI ? jacobi : gauss_seidel;
    if (same_motion(fm, v, v_end))
        return v_end;
    /* (no master feeds F_avg_next where the FMU does not offer it) */
    *other = !fm->no_prediction && same_motion(fm, fm->coupling == COUPLING_JACOBI ? gauss_seidel : jacobi, v_end);
    return *other ? v_end : v;
}

/* The next step, of length H from the model's state as the last step left
 * it, into fm->next (valid = 0 where it cannot be taken: the full G1
 * history's grid or its limit, memory for it, or a non-finite state). */
static void predict(fmu_model *fm, double H)
{
    prediction *p = fm->next;
    contact_model *cm = &fm->model;
    char why[512];
    p->valid = 0;
    /* The full G1 history's struct copy shares its buffer: room for the
     * predicted steps first, so that the copy never reallocates it. */
    if (contact_check_advance(cm, H, why, sizeof why) != 0 || contact_check_work(cm, H, MAX_STEPS, why, sizeof why) != 0
        || (contact_steps_uniformly(&cm->p)
            && contact_memory_resize(cm, contact_memory_count(cm) + (size_t)floor(H / cm->h_max + 0.5)) != 0))
        return;
    contact_copy(&p->model, cm);
    p->impulse = contact_advance(&p->model, H);
    if (isnan(p->impulse))
        return;
    p->H = H;
    p->event = event_since(&cm->s, &p->model.s);
    p->valid = 1;
}

/* Whether the step of length H (stopping at the events of stop_at), its
 * inputs applied to the model, is the one predicted: the same velocity,
 * drive and length, and no event inside when it must stop at one. */
static int predicted_step(const fmu_model *fm, double H, unsigned stop_at, double v_end)
{
    const prediction *p = fm->next;
    const contact_model *cm = &fm->model;
    return p && p->valid && H == p->H && cm->s.v == v_end && cm->inv_m == p->model.inv_m && cm->accel == p->model.accel
           && !(stop_at && p->event);
}

/* Whether the model's striker is a proxy the master's bodies follow. */
static int proxy_striker(const fmu_model *fm)
{
    return fm->params.scene == CONTACT_SCENE_DRIVEN && fm->in.m > 0.0;
}

/* The bodies' approach acceleration apart from the contact. */
static double bodies_accel(const fmu_model *fm)
{
    return fm->params.g + other_accel(&fm->in);
}

/* A whole communication step of length H taken from the proxy state
 * *start with the impulse J, the impulse owed before it `owed`: its
 * interval in the energy account, and the correction to the force output
 * for the bodies' interval that has not yet begun to take it (this one
 * under Gauss-Seidel, the next under Jacobi). */
static void account_step(fmu_model *fm, double H, const contact_state *start, double J, double owed)
{
    coupling_energy *e = &fm->step.energy, next;
    const contact_model *cm = &fm->model;
    const prediction *p = fm->next; /* there under Jacobi (check_coupling) */
    const double m = proxy_mass(&fm->in);
    if (fm->coupling == COUPLING_GAUSS_SEIDEL) {
        coupling_energy_open(e, H, approach(&fm->in), bodies_accel(fm), fm->step.F_avg);
        coupling_energy_proxy(e, cm, start, &cm->s, J, 0.0, 0.0);
        fm->step.correction = coupling_energy_correction(e, m);
        e->F += fm->step.correction;
        return;
    }
    coupling_energy_open(e, H, approach(&fm->in), bodies_accel(fm), fm->step.announced + fm->step.correction);
    coupling_energy_proxy(e, cm, start, &cm->s, J, owed / m, fm->step.owed / m);
    /* the next interval: the bodies' start predicted from this one's, the
     * proxy's motion from its own end (owing nothing then), moved to it */
    next = coupling_energy_predicted(e, m);
    coupling_energy_open(&next, fm->step.H, next.u, next.a, fm->step.F_avg_next);
    coupling_energy_proxy(&next, cm, &cm->s, p->valid ? &p->model.s : &cm->s,
                          fm->step.F_avg_next * fm->step.H - fm->step.owed, fm->step.owed / m, 0.0);
    next.u1 += next.u - next.u0;
    next.u0 = next.u;
    fm->step.correction = coupling_energy_correction(&next, m);
}

/* The model driven by the inputs for a step of length H > 0 from the
 * velocity v (contact_drive), or FM_ERROR, reported, and the model as it
 * was where the step cannot be taken: off the full G1 history's grid, or
 * in more than MAX_STEPS internal steps, known before the first
 * (contact_check_work; the model's max_steps stops the others). */
static fm_status drive(fmu_model *fm, double H, double v)
{
    contact_model *cm = &fm->model;
    const contact_state s = cm->s;
    const double inv_m = cm->inv_m, accel = cm->accel, contact_step = cm->contact_step;
    char why[512];
    contact_drive(cm, v, proxy_mass(&fm->in), fm->in.m > 0.0 ? other_accel(&fm->in) : fm->v_slope);
    if (contact_check_advance(cm, H, why, sizeof why) == 0
        && contact_check_work(cm, H, MAX_STEPS, why, sizeof why) == 0)
        return FM_OK;
    cm->s = s;
    cm->inv_m = inv_m;
    cm->accel = accel;
    cm->contact_step = contact_step;
    return report(fm, FM_ERROR, "logStatusError", "DoStep: communicationStepSize = %.17g: %s", H, why);
}

fm_status fm_do_step_until(fmu_model *fm, double t, double H, unsigned options, int *event)
{
    contact_model *cm = &fm->model;
    contact_state before;
    memory_copy memory;
    double impulse, part, t_start, end, v_end;
    const fmu_variable *overflow;
    const step_account saved = fm->step; /* as it was, for a refusal */
    const int held = fm->held;             /* the discrete outputs a refusal keeps showing */
    const int stop = (options & FM_STOP_AT_EVENT) != 0, resume = (options & FM_CONTINUE) != 0;
    const unsigned stop_at = stop ? CONTACT_ONSET | CONTACT_SEPARATION : 0u;
    /* a step of the energy account: the master's whole step (an early
     * return's part is one), not the rest of a step cut inside the FMU */
    const int accounted = !resume && proxy_striker(fm);
    int from_prediction, other_coupling;
    *event = 0;
    if (H == 0.0) {
        fm_update_discrete(fm); /* a new step: the master has seen the last event */
        cm->s.t = t; /* the master's: the glue let it differ from ours by rounding only */
        return FM_OK;
    }
    t_start = cm->s.t;
    v_end = cm->s.v;
    /* A refused step changes nothing, so the checks come first */
    if (drive(fm, H, start_velocity(fm, v_end, &other_coupling)) != FM_OK)
        return FM_ERROR;
    fm_update_discrete(fm);
    if (!resume) { /* a new communication step: what a Jacobi master applies over it, where and how long */
        fm->step.announced = fm->step.F_avg_next;
        fm->step.start = t;
        fm->step.H = H;
    }
    if (accounted) /* the inputs end the bodies' last interval */
        coupling_energy_close(&fm->step.energy, proxy_mass(&fm->in), approach(&fm->in), bodies_accel(fm));
    if (accounted)
        coupling_energy_restart(&fm->step.energy, fm->coupling == COUPLING_JACOBI ? fm->step.owed : 0.0,
                                cm->s.v - v_end);
    before = cm->s;
    save_memory(cm, &memory);
    from_prediction = predicted_step(fm, H, stop_at, v_end);
    if (from_prediction) {
        contact_copy(cm, &fm->next->model); /* the step F_avg_next announced */
        impulse = fm->next->impulse;
    } else {
        impulse = contact_advance_until(cm, H, stop_at);
    }
    if (isnan(impulse)) {
        fm->step = saved;
        fm->held = held;
        forget_prediction(fm);
        if (cm->exceeded)
            return report(fm, FM_ERROR, "logStatusError",
                          "DoStep: communicationStepSize = %g from t = %.17g s took more than %.0e internal steps "
                          "and was stopped; the state is kept at the start of the step "
                          "(take shorter communication steps, a larger dt_max or tolerance > 0)", H, t,
                          (double)MAX_STEPS);
        return report(fm, FM_ERROR, "logStatusError",
                      "DoStep: the state became non-finite in [%.17g, %.17g] s; "
                      "it is kept at the start of the step", t, t + H);
    }
    *event = stop && event_since(&before, &cm->s);
    /* The step ran on the FMU's clock, from where the last step ended; the
     * master's, which the glue let differ from it by rounding only, sets
     * the clock at the communication point (where the step went on after
     * an event too), or carries the time to an event over to it, never
     * past that point. So the master's rounding of its time changes no
     * result, and the predicted step is the step. */
    end = resume ? fm->step.start + fm->step.H : t + H; /* as the master adds them */
    if (!*event)
        cm->s.t = end;
    else
        cm->s.t = fmin(t == t_start ? cm->s.t : t + (cm->s.t - t_start), end);
    part = *event ? cm->s.t - t : H;
    /* The impulse the contact exerted beyond what F_avg_next announced for
     * this part of the communication step: owed to the striker. */
    fm->step.owed += impulse - fm->step.announced * part;
    if (resume) { /* the average over the whole communication step so far */
        impulse += fm->step.F_avg * fm->step.span;
        part += fm->step.span;
    }
    fm->step.F_avg = part > 0.0 ? impulse / part : cm->s.F;
    fm->step.span = part;
    /* The next communication step, as long as this one was requested, from
     * wherever this one ended; without a prediction the average force of
     * this step, held. */
    if (fm->next)
        predict(fm, fm->step.H);
    fm->step.F_avg_next =
        (fm->next && fm->next->valid ? fm->next->impulse / fm->step.H : fm->step.F_avg) + fm->step.owed / fm->step.H;
    if (accounted)
        account_step(fm, part, &before, impulse, saved.owed);
    else { /* no proxy, or the rest of a step cut at an event inside the FMU: left out of the account */
        fm->step.energy.open = 0;
        fm->step.correction = 0.0;
    }
    overflow = nonfinite_output(fm);
    if (overflow) {
        double value = real_output(fm, overflow->vr);
        cm->s = before;
        restore_memory(cm, &memory);
        fm->step = saved;
        forget_prediction(fm); /* a memo: dropping it changes no result */
        *event = 0;
        return report(fm, FM_ERROR, "logStatusError",
                      "DoStep: the output %s would be %g after [%.17g, %.17g] s (beyond double precision); "
                      "the state is kept at the start of the step", overflow->name, value, t, t + H);
    }
    if (from_prediction)
        fm->predicted++;
    else
        fm->computed++;
    if (*event) {
        fm->held = 1;
        fm->held_contact = before.in_contact;
        fm->held_eps = before.eps;
    }
    report_events(fm, &before);
    /* logged as a warning; the step itself went as it should */
    if (other_coupling && !fm->coupling_warned) {
        fm->coupling_warned = 1;
        report(fm, FM_WARNING, "logStatusWarning",
                      "coupling = %d, but the master's v at t = %.9g s follows %s: the proxy striker follows its "
                      "own motion; set coupling = %d (with a force on the striker the FMU does not know, such as "
                      "gravity in the master's striker, only the right coupling gives the right force)",
                      fm->coupling, t,
                      fm->coupling == COUPLING_JACOBI ? "F_avg fed after this FMU's step (Gauss-Seidel)"
                                                      : "F_avg_next fed before it (Jacobi)",
                      fm->coupling == COUPLING_JACOBI ? COUPLING_GAUSS_SEIDEL : COUPLING_JACOBI);
    }
    return FM_OK;
}

/* ------------------------------------------------------- Model Exchange */

const size_t fm_me_states = CONTACT_ME_STATES, fm_me_indicators = CONTACT_ME_INDICATORS;

/* The driven scene's indentation rate is its input, read wherever the
 * model's rates are. */
static void me_follow_inputs(fmu_model *fm)
{
    preview_start(fm); /* before initialization ends: the state it would start from */
    if (fm->params.scene == CONTACT_SCENE_DRIVEN)
        fm->model.s.v = approach(&fm->in);
}

void fm_me_instantiated(fmu_model *fm)
{
    fm->model_exchange = 1;
}

fm_status fm_me_start(fmu_model *fm, double t0, double t_stop)
{
    char why[512];
    fm_status status;
    if (contact_me_check(&fm->params, why, sizeof why) != 0)
        return report(fm, FM_ERROR, "logStatusError", "%s", why);
    status = fm_start(fm, t0, t_stop);
    if (status == FM_ERROR)
        return status;
    /* the host's solver moves the bodies: no proxy striker in the driven scene */
    if (fm->params.scene == CONTACT_SCENE_DRIVEN)
        contact_drive(&fm->model, approach(&fm->in), 0.0, 0.0);
    fm->me_speed = approach(&fm->in);
    fm->me_mass = fm->params.scene == CONTACT_SCENE_DROP ? proxy_mass(&fm->in) : 0.0;
    if (status == FM_OK && fm->params.scene == CONTACT_SCENE_DRIVEN
        && (fm->in.m != 0.0 || other_accel(&fm->in) != 0.0 || fm->coupling != COUPLING_GAUSS_SEIDEL))
        return report(fm, FM_WARNING, "logStatusWarning",
                      "m = %g, a = %g, a2 = %g and coupling = %d have no effect in Model Exchange's driven scene "
                      "(scene = 2): the host moves the bodies, and the indentation's rate is v - v2 as given",
                      fm->in.m, fm->in.a, fm->in.a2, fm->coupling);
    return status;
}

void fm_me_set_time(fmu_model *fm, double t)
{
    fm->model.s.t = t;
}

fm_status fm_me_set_states(fmu_model *fm, const double *x)
{
    size_t i;
    for (i = 0; i < CONTACT_ME_STATES; i++)
        if (!isfinite(x[i]))
            return report(fm, FM_ERROR, "logStatusError",
                          "SetContinuousStates: the state %lu is %g: it must be finite", (unsigned long)i, x[i]);
    if (contact_me_set_states(&fm->model, x) != 0)
        return report(fm, FM_ERROR, "logStatusError",
                      "SetContinuousStates: x = %g m, x2 = %g m and the modes give a force or a damper rate beyond "
                      "double precision; the states are kept as they were", x[CONTACT_ME_X], x[CONTACT_ME_X2]);
    me_follow_inputs(fm);
    return FM_OK;
}

void fm_me_get_states(fmu_model *fm, double *x)
{
    me_follow_inputs(fm);
    contact_me_get_states(&fm->model, x);
}

fm_status fm_me_derivatives(fmu_model *fm, double *dx)
{
    size_t i;
    me_follow_inputs(fm);
    contact_me_derivatives(&fm->model, dx);
    /* extreme but finite states (an indentation of metres on a steel
     * spring) can overflow a rate */
    for (i = 0; i < CONTACT_ME_STATES; i++)
        if (!isfinite(dx[i]))
            return report(fm, FM_ERROR, "logStatusError",
                          "GetDerivatives: the derivative of the state %lu overflows (%g) at x = %g m, x2 = %g m",
                          (unsigned long)i, dx[i], contact_total_indentation(&fm->model), fm->model.s.x2);
    return FM_OK;
}

void fm_me_nominals(fmu_model *fm, double *nominal)
{
    me_follow_inputs(fm);
    if (!fm->started) /* before the start: of the inputs so far */
        contact_me_nominals(&fm->model, approach(&fm->in),
                            fm->params.scene == CONTACT_SCENE_DROP ? proxy_mass(&fm->in) : 0.0, nominal);
    else
        contact_me_nominals(&fm->model, fm->me_speed, fm->me_mass, nominal);
}

void fm_me_event_indicators(fmu_model *fm, double *z)
{
    me_follow_inputs(fm);
    contact_me_indicators(&fm->model, z);
}

void fm_me_event(fmu_model *fm)
{
    const contact_state before = fm->model.s;
    me_follow_inputs(fm);
    contact_me_event(&fm->model);
    report_events(fm, &before);
}

void fm_me_step_completed(fmu_model *fm)
{
    contact_me_accept(&fm->model);
}

/* The state of value reference vr (its place among the states), or -1. */
static long me_state_of(unsigned vr)
{
    switch (vr) {
    case VR_x: return CONTACT_ME_X;
    case VR_v_striker: return CONTACT_ME_V;
    case VR_x2: return CONTACT_ME_X2;
    case VR_E_diss: return CONTACT_ME_E_DISS;
    default: return vr >= VR_phi && vr - VR_phi < CONTACT_MAX_MODES ? CONTACT_ME_MODES + (long)(vr - VR_phi) : -1;
    }
}

/* The derivative of value reference vr (the place of its state), or -1. */
static long me_derivative_of(unsigned vr)
{
    switch (vr) {
    case VR_der_x: return CONTACT_ME_X;
    case VR_der_v_striker: return CONTACT_ME_V;
    case VR_der_x2: return CONTACT_ME_X2;
    case VR_der_E_diss: return CONTACT_ME_E_DISS;
    default: return vr >= VR_phi + VR_DERIVATIVE_OFFSET ? me_state_of(vr - VR_DERIVATIVE_OFFSET) : -1;
    }
}

fm_status fm_me_directional(fmu_model *fm, const unsigned *unknowns, size_t n_unknowns, const unsigned *knowns,
                            size_t n_knowns, const double *seed, double *sensitivity)
{
    double dx[CONTACT_ME_STATES] = {0.0}, df[CONTACT_ME_STATES], dv = 0.0;
    size_t i;
    me_follow_inputs(fm);
    for (i = 0; i < n_knowns; i++) {
        const long state = me_state_of(knowns[i]);
        if (state >= 0)
            dx[state] += seed[i];
        else if (knowns[i] == VR_v || knowns[i] == VR_v2) /* the driven scene's rate v - v2 */
            dv += knowns[i] == VR_v ? seed[i] : -seed[i];
        else
            return report(fm, FM_ERROR, "logStatusError",
                          "GetDirectionalDerivative: value reference %u is not a continuous state or the input v "
                          "or v2: the derivatives are differentiated with respect to those", knowns[i]);
    }
    for (i = 0; i < n_unknowns; i++)
        if (me_derivative_of(unknowns[i]) < 0)
            return report(fm, FM_ERROR, "logStatusError",
                          "GetDirectionalDerivative: value reference %u is not a state derivative (der(x), "
                          "der(v_striker), der(x2), der(E_diss), der(phi[i]))", unknowns[i]);
    contact_me_directional(&fm->model, dx, dv, df);
    for (i = 0; i < n_unknowns; i++)
        sensitivity[i] = df[me_derivative_of(unknowns[i])];
    return FM_OK;
}

/* The derivatives and the modes by value reference (parameters.def's
 * DERIVATIVE and STATE rows) at the model's state: 1 and *value, or 0 for
 * another reference. */
static int model_exchange_variable(fmu_model *fm, unsigned vr, double *value)
{
    double x[CONTACT_ME_STATES];
    int derivative = vr >= VR_phi + VR_DERIVATIVE_OFFSET;
    unsigned mode = vr - (derivative ? VR_phi + VR_DERIVATIVE_OFFSET : VR_phi);
    if (!(vr >= VR_der_x && vr <= VR_event_x1_rate) && !(vr >= VR_phi && mode < CONTACT_MAX_MODES))
        return 0;
    preview_start(fm); /* and nothing else changes the model: a co-simulation master reads these too */
    if (vr == VR_event_x1 || vr == VR_event_x1_rate) {
        contact_me_indicators(&fm->model, x);
        *value = x[vr - VR_event_x1];
        return 1;
    }
    if (vr >= VR_phi && !derivative) {
        contact_me_get_states(&fm->model, x);
        *value = x[CONTACT_ME_MODES + mode];
        return 1;
    }
    contact_me_derivatives(&fm->model, x);
    switch (vr) {
    case VR_der_x: *value = x[CONTACT_ME_X]; break;
    case VR_der_v_striker: *value = x[CONTACT_ME_V]; break;
    case VR_der_x2: *value = x[CONTACT_ME_X2]; break;
    case VR_der_E_diss: *value = x[CONTACT_ME_E_DISS]; break;
    default: *value = x[CONTACT_ME_MODES + mode]; break;
    }
    return 1;
}

/* ------------------------------------------------------------ FMU state */

/* Every value a simulation depends on, field by field: a raw copy of the
 * struct would carry the logger's pointers and the compiler's padding into
 * another process. The rest (k, 1/c, ...) is derived again on reading. */
#define F(field) {offsetof(fmu_model, field), FIELD_F64}
#define I(field) {offsetof(fmu_model, field), FIELD_I32}
#define L(field) {offsetof(fmu_model, field), FIELD_I64}
#define STATE_F(field) F(model.s.field),
#define STATE_L(field) L(model.s.field),
#define STATE_I(field) I(model.s.field),
#define ENERGY_F(field) F(step.energy.field)

static const state_field state_fields[] = {
    F(params.R), F(params.E_i), F(params.nu_i), F(params.E_s), F(params.nu_s), F(params.k), F(params.c),
    F(params.dt_max), F(params.tolerance), F(params.g), F(params.gap0), I(params.law), I(params.g1_nodes), I(params.scene),
    I(params.scheme), F(params.spring_exponent), I(params.damper), F(in.v), F(in.m), F(in.v2), F(in.m2), F(in.a),
    F(in.a2), F(v_slope), F(step.F_avg), F(step.span),
    I(coupling), F(step.F_avg_next), F(step.owed), F(step.announced), F(step.start), F(step.H), L(predicted),
    L(computed), I(started), I(held), I(held_contact), F(held_eps), ENERGY_F(created), ENERGY_F(rounding),
    ENERGY_F(H), ENERGY_F(u), ENERGY_F(a), ENERGY_F(a_rate), ENERGY_F(a_unseen), ENERGY_F(F), ENERGY_F(u0),
    ENERGY_F(u1), ENERGY_F(F_end), ENERGY_F(dx), ENERGY_F(scale), ENERGY_F(lag), I(step.energy.open),
    I(step.energy.ends_free), F(step.correction),
    F(model.inv_m), F(model.accel), CONTACT_STATE_FIELDS(STATE_F, STATE_L, STATE_I)};

/* A springpot's parameters follow, then its memory: the count of values
 * (u64) and the values (contact_memory_get). A dashpot's state ends above. */
static const state_field springpot_fields[] = {F(params.damper_order), F(params.c_alpha), F(params.memory_tolerance),
                                               I(params.memory)};

#define N_STATE_FIELDS (sizeof state_fields / sizeof state_fields[0])
#define N_SPRINGPOT_FIELDS (sizeof springpot_fields / sizeof springpot_fields[0])

static int has_springpot(const contact_params *p) { return p->damper == CONTACT_DAMPER_SPRINGPOT; }

size_t fm_state_size(const fmu_model *fm)
{
    size_t size = fmu_fields_size(state_fields, N_STATE_FIELDS);
    if (has_springpot(&fm->params))
        size += fmu_fields_size(springpot_fields, N_SPRINGPOT_FIELDS) + 8 + 8 * contact_memory_count(&fm->model);
    return size;
}

void fm_state_write(const fmu_model *fm, unsigned char *bytes)
{
    size_t i, count;
    fmu_fields_write(fm, state_fields, N_STATE_FIELDS, bytes);
    if (!has_springpot(&fm->params))
        return;
    bytes += fmu_fields_size(state_fields, N_STATE_FIELDS);
    fmu_fields_write(fm, springpot_fields, N_SPRINGPOT_FIELDS, bytes);
    bytes += fmu_fields_size(springpot_fields, N_SPRINGPOT_FIELDS);
    count = contact_memory_count(&fm->model);
    serial_put_u64(bytes, count);
    for (i = 0; i < count; i++)
        serial_put_double(bytes + 8 + 8 * i, contact_memory_get(&fm->model, i));
}

/* The parameters and the state of `bytes` into *trial, and the count of the
 * memory's values that follow at *memory; NULL, or what is wrong. */
static const char *read_fields(fmu_model *trial, const unsigned char *bytes, size_t size, const unsigned char **memory,
                               size_t *count)
{
    const size_t fixed = fmu_fields_size(state_fields, N_STATE_FIELDS);
    const size_t springpot = fmu_fields_size(springpot_fields, N_SPRINGPOT_FIELDS);
    *count = 0;
    if (size < fixed)
        return "the FMU state is too short";
    fmu_fields_read(trial, state_fields, N_STATE_FIELDS, bytes);
    if (!has_springpot(&trial->params))
        return size == fixed ? NULL : "the FMU state has the wrong length";
    if (size < fixed + springpot + 8)
        return "the FMU state is too short";
    fmu_fields_read(trial, springpot_fields, N_SPRINGPOT_FIELDS, bytes + fixed);
    *memory = bytes + fixed + springpot + 8;
    *count = (size_t)serial_get_u64(bytes + fixed + springpot);
    if (*count > (size - fixed - springpot - 8) / 8 || size != fixed + springpot + 8 + 8 * *count)
        return "the FMU state has the wrong length";
    return NULL;
}

/* A state read refused after trial took blocks of its own: frees them, and
 * reports the error. */
static fm_status refuse_state(fmu_model *fm, fmu_model *trial, const char *fmt, ...)
{
    char why[512];
    va_list args;
    contact_release_modes(&trial->model);
    if (trial->next)
        contact_release_modes(&trial->next->model);
    va_start(args, fmt);
    vsnprintf(why, sizeof why, fmt, args);
    va_end(args);
    return report(fm, FM_ERROR, "logStatusError", "%s", why);
}

fm_status fm_state_read(fmu_model *fm, const unsigned char *bytes, size_t size)
{
    fmu_model trial = *fm;
    prediction fresh; /* trial's, its modes in a block of its own: fm's storage takes it once the state is read */
    const unsigned char *memory = NULL;
    const char *problem;
    char why[256];
    size_t i, count;
    problem = read_fields(&trial, bytes, size, &memory, &count);
    if (problem)
        return report(fm, FM_ERROR, "logStatusError", "%s", problem);
    if (contact_check_params(&trial.params, why, sizeof why) != 0
        || check_bodies(&trial.params, CONTACT_SCENE_DRIVEN, &trial.in, why, sizeof why) != 0
        || check_coupling(&trial, trial.coupling, why, sizeof why) != 0)
        return report(fm, FM_ERROR, "logStatusError", "the FMU state holds an invalid value: %s", why);
    if (!fmu_fields_finite(&trial, state_fields, N_STATE_FIELDS)
        || !fmu_fields_finite(&trial, springpot_fields, N_SPRINGPOT_FIELDS) || (trial.started != 0 && trial.started != 1)
        || (trial.held != 0 && trial.held != 1) || (trial.held_contact != 0 && trial.held_contact != 1)
        /* (Model Exchange takes the peak at accepted states: a state the host set may exceed it) */
        || !(trial.model.s.F >= 0.0 && (trial.model.s.F <= trial.model.s.F_peak || trial.model_exchange))
        || (trial.model.s.in_contact != 0 && trial.model.s.in_contact != 1) || trial.model.s.steps < 0
        || trial.step.H < 0.0 || trial.step.span < 0.0 || trial.predicted < 0 || trial.computed < 0)
        return report(fm, FM_ERROR, "logStatusError", "the FMU state holds a non-finite or impossible value");
    for (i = 0; i < count; i++)
        if (!isfinite(serial_get_double(memory + 8 * i)))
            return report(fm, FM_ERROR, "logStatusError", "the FMU state's damper memory holds a non-finite value");
    /* the compressed memory's modes in blocks of trial's own, fm's kept
     * until the state is read */
    memset(&trial.model.modes, 0, sizeof trial.model.modes);
    memset(&fresh, 0, sizeof fresh);
    trial.next = fm->no_prediction ? NULL : &fresh;
    if (contact_configure(&trial.model, &trial.params) != 0
        || (trial.next && !fm->next && !(fm->next = calloc(1, sizeof *fm->next)))
        || (trial.next && contact_copy_room(&fresh.model, &trial.model) != 0))
        return refuse_state(fm, &trial, "out of memory for the FMU state's springpot modes (memory = 2)");
    trial.model.max_steps = MAX_STEPS;
    if (nonfinite_output(&trial))
        return refuse_state(fm, &trial, "the FMU state gives the output %s a non-finite value",
                            nonfinite_output(&trial)->name);
    if (contact_memory_accepts(&trial.model, count, why, sizeof why) != 0)
        return refuse_state(fm, &trial, "the FMU state does not fit its parameters: %s", why);
    /* trial shares fm's G1 history buffer: growing it is the last thing
     * that can fail, and leaves fm as it was if it does. */
    if (contact_memory_resize(&trial.model, count) != 0)
        return refuse_state(fm, &trial, "out of memory for the FMU state's G1 history (%lu values)",
                            (unsigned long)count);
    for (i = 0; i < count; i++)
        contact_memory_set(&trial.model, i, serial_get_double(memory + 8 * i));
    contact_release_modes(&fm->model);
    if (trial.next) { /* empty: a memo of the next step, which the next step computes again, to the bit */
        contact_release_modes(&fm->next->model);
        *fm->next = fresh;
        trial.next = fm->next;
    }
    *fm = trial;
    return FM_OK;
}

/* The hooks written above in place of the glue's defaults, which supply the rest. */
#define FM_SET_REAL
#define FM_GET_REAL
#define FM_SET_INTEGER
#define FM_GET_BOOLEAN
#define FM_SET_INPUT_DERIVATIVE
#define FM_GET_OUTPUT_DERIVATIVE
#define FM_START
#define FM_TIME
#define FM_STATE
#define FM_LEAVE_OUT
#define FM_RELEASE(fm) (contact_release(&(fm)->model), release_prediction(fm))
#include "fmu_defaults.h"
