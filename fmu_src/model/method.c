/* Which method a configuration runs, decided here alone (docs/model.md
 * §16): the springpot's full G1 history steps by its own BDF2 scheme, the
 * central scheme by the paper's central differences, error-controlled steps
 * by ESDIRK 5(4) (the dashpot) or Radau IIA (the compressed springpot),
 * fixed ones by SDIRK2. */
#include <math.h>
#include <stddef.h>

#include "contact_internal.h"

/* Whether the force depends on the number of steps: the G1 laws with
 * g1_nodes = 0 count the internal steps since onset as their intervals. */
static int law_counts_steps(const contact_params *p)
{
    return p->law != CONTACT_LAW_HERTZ && p->g1_nodes == 0;
}

enum contact_method contact_method(const contact_params *p)
{
    if (p->damper == CONTACT_DAMPER_SPRINGPOT && p->memory == CONTACT_MEMORY_G1)
        return CONTACT_METHOD_G1_HISTORY;
    if (p->scheme == CONTACT_SCHEME_CENTRAL)
        return CONTACT_METHOD_CENTRAL;
    if (p->tolerance > 0.0 && !law_counts_steps(p))
        return p->damper == CONTACT_DAMPER_SPRINGPOT ? CONTACT_METHOD_RADAU_IIA : CONTACT_METHOD_ESDIRK54;
    return CONTACT_METHOD_SDIRK2;
}

const char *contact_method_name(enum contact_method method)
{
    switch (method) {
    case CONTACT_METHOD_SDIRK2:
        return "sdirk2";
    case CONTACT_METHOD_ESDIRK54:
        return "esdirk54";
    case CONTACT_METHOD_RADAU_IIA:
        return "radau_iia";
    case CONTACT_METHOD_G1_HISTORY:
        return "g1_history";
    case CONTACT_METHOD_CENTRAL:
        return "central";
    }
    return "unknown";
}

/* Why error-controlled steps do not apply with these parameters, or NULL:
 * they need a force that does not depend on the step count, the implicit
 * scheme, and a memory that takes any step (not the full G1 history's
 * uniform grid). */
const char *fixed_steps_only(const contact_params *p)
{
    const enum contact_method method = contact_method(p);
    if (law_counts_steps(p))
        return "with g1_nodes = 0 the G1 laws count internal steps, whose number defines their error, so they "
               "take fixed steps of dt_max (set g1_nodes > 0 or law = 2 for error-controlled steps)";
    if (method == CONTACT_METHOD_CENTRAL)
        return "the central differences (scheme = 2) take fixed steps of dt_max";
    if (method == CONTACT_METHOD_G1_HISTORY)
        return "the springpot's full G1 history (memory = 1) steps on a uniform grid of dt_max (memory = 2, "
               "the compressed memory, takes error-controlled steps)";
    return NULL;
}

int contact_error_controlled(const contact_params *p)
{
    const enum contact_method method = contact_method(p);
    return method == CONTACT_METHOD_ESDIRK54 || method == CONTACT_METHOD_RADAU_IIA;
}

double contact_step_limit(const contact_params *p)
{
    if (p->dt_max > 0.0)
        return p->dt_max;
    return contact_error_controlled(p) ? INFINITY : CONTACT_DEFAULT_STEP;
}

double contact_least_steps(const contact_params *p, double span, double in_contact)
{
    return (uniform_grid(p) ? span : in_contact) / contact_step_limit(p);
}

double contact_history_work(double before, double after)
{
    return (after - before) * (1.0 + floor(after / CONTACT_HISTORY_PER_UNIT));
}

int contact_steps_uniformly(const contact_params *p) { return uniform_grid(p); }
