/* The striker FMU: a rigid body of mass m under gravity g, a spring k_s
 * holding it at x0 and the contact force F (input, pushing against its
 * motion towards the specimen). Its position x (towards the specimen, the
 * contact element's indentation coordinate) and velocity v are the outputs.
 * With F held over a step the motion is a parabola, or with the spring a
 * harmonic oscillation, integrated exactly. */
#include <math.h>
#include <stddef.h>

#include "fmu_interface.h"
#include "fmu_vars.h"

enum { VR_F = 1, VR_m = 2, VR_g = 3, VR_x0 = 4, VR_v0 = 5, VR_x = 6, VR_v = 7, VR_k_s = 8 };

struct fmu_model {
    double F;              /* input: contact force on the striker [N] */
    double m, g, x0, v0, k_s; /* parameters */
    double t, x, v;        /* state */
    int started;
    fmu_reporter log;
};

static const fmu_variable variable_list[] = {
    {VR_F, "F", VAR_REAL, VAR_INPUT, offsetof(fmu_model, F)},
    {VR_m, "m", VAR_REAL, VAR_PARAMETER, offsetof(fmu_model, m)},
    {VR_g, "g", VAR_REAL, VAR_PARAMETER, offsetof(fmu_model, g)},
    {VR_x0, "x0", VAR_REAL, VAR_PARAMETER, offsetof(fmu_model, x0)},
    {VR_v0, "v0", VAR_REAL, VAR_PARAMETER, offsetof(fmu_model, v0)},
    {VR_x, "x", VAR_REAL, VAR_OUTPUT, offsetof(fmu_model, x)},
    {VR_v, "v", VAR_REAL, VAR_OUTPUT, offsetof(fmu_model, v)},
    {VR_k_s, "k_s", VAR_REAL, VAR_PARAMETER, offsetof(fmu_model, k_s)},
};

static const fmu_variables variables = {variable_list, sizeof variable_list / sizeof variable_list[0]};

/* The start values that are not 0. */
static void start_values(fmu_model *fm)
{
    fm->m = 0.7437;
    fm->v0 = 0.626418;
    fm->v = fm->v0;
}

/* The value's rule, or NULL if it is fine. */
static const char *rule_broken(unsigned vr, double value)
{
    if (!isfinite(value))
        return "must be finite";
    if (vr == VR_m && !(value > 0.0))
        return "the striker mass must be positive [kg]";
    if (vr == VR_k_s && value < 0.0)
        return "the spring's stiffness must not be negative [N/m]";
    return NULL;
}

/* The state at the start: at rest at x0 but for the speed v0. */
static void start_state(fmu_model *fm)
{
    fm->x = fm->x0;
    fm->v = fm->v0;
}

/* v' at the step's start: gravity, the held force and the spring. */
static double acceleration(const fmu_model *fm)
{
    return fm->g - fm->F / fm->m - fm->k_s / fm->m * (fm->x - fm->x0);
}

#define FM_RATES "x and v"

static int rate(const fmu_model *fm, unsigned vr, double *value)
{
    if (vr == VR_x)
        *value = fm->v;
    else if (vr == VR_v)
        *value = acceleration(fm);
    else
        return 0;
    return 1;
}

/* With F held over a step: x'' = a - w^2 (x - x0), a = g - F/m,
 * w^2 = k_s/m. Without the spring a parabola; with it an oscillation
 * about x0 + a/w^2. */
fm_status fm_do_step(fmu_model *fm, double t, double H)
{
    const double a = fm->g - fm->F / fm->m;
    if (fm->k_s > 0.0) {
        const double w = sqrt(fm->k_s / fm->m), c = cos(w * H), s = sin(w * H);
        const double rest = fm->x0 + a / (w * w), d = fm->x - rest, v = fm->v;
        fm->x = rest + d * c + v / w * s;
        fm->v = v * c - d * w * s;
    } else {
        fm->x += H * (fm->v + 0.5 * H * a);
        fm->v += H * a;
    }
    fm->t = t + H;
    return FM_OK;
}

#define F(field) {offsetof(fmu_model, field), FIELD_F64}

static const state_field state_fields[] = {F(F), F(m), F(g), F(x0), F(v0), F(k_s), F(t), F(x), F(v),
                                           {offsetof(fmu_model, started), FIELD_I32}};

/* Whether a state read is one the striker can hold. */
static int state_accepted(const fmu_model *trial)
{
    return !rule_broken(VR_m, trial->m) && !rule_broken(VR_k_s, trial->k_s);
}

#include "fmu_defaults.h" /* the hooks not written above */
