/* Which method a configuration runs, decided here alone (docs/model.md
 * §16): the springpot's full G1 history steps by its own BDF2 scheme, the
 * central scheme by the paper's central differences, error-controlled steps
 * by ESDIRK 5(4) (the dashpot) or Radau IIA (the compressed springpot),
 * fixed ones by the discrete gradient (gradient.c); each method's record lies at the end of its file. */
#include <math.h>
#include <stddef.h>

#include "contact_internal.h"

/* Whether the force depends on the number of steps: the G1 laws with
 * g1_nodes = 0 count the internal steps since onset as their intervals. */
static int law_counts_steps(const contact_params *p)
{
    return p->law != CONTACT_LAW_HERTZ && p->g1_nodes == 0;
}

/* The record of the method these parameters run: its choice, here alone. */
const contact_method_record *method_record(const contact_params *p)
{
    if (p->damper == CONTACT_DAMPER_SPRINGPOT && p->memory == CONTACT_MEMORY_G1)
        return &g1_history_method;
    if (p->scheme == CONTACT_SCHEME_CENTRAL)
        return &central_method;
    if (p->tolerance > 0.0 && !law_counts_steps(p))
        return p->damper == CONTACT_DAMPER_SPRINGPOT ? &radau_iia_method : &esdirk54_method;
    return &gradient_method;
}

enum contact_method contact_method(const contact_params *p) { return method_record(p)->method; }

const char *contact_method_name(enum contact_method method)
{
    static const contact_method_record *const records[] = {&gradient_method, &esdirk54_method, &radau_iia_method,
                                                            &g1_history_method, &central_method};
    size_t i;
    for (i = 0; i < sizeof records / sizeof records[0]; i++)
        if (records[i]->method == method)
            return records[i]->name;
    return "unknown";
}

/* Why error-controlled steps do not apply with these parameters, or NULL:
 * they need a force that does not depend on the step count, and a method
 * that takes any step (not a uniform grid's). */
const char *fixed_steps_only(const contact_params *p)
{
    if (law_counts_steps(p))
        return "with g1_nodes = 0 the G1 laws count internal steps, whose number defines their error, so they "
               "take fixed steps of dt_max (set g1_nodes > 0 or law = 2 for error-controlled steps)";
    return method_record(p)->fixed_steps;
}

int contact_error_controlled(const contact_params *p) { return method_record(p)->controls_error; }

double contact_step_limit(const contact_params *p)
{
    if (p->dt_max > 0.0)
        return p->dt_max;
    return contact_error_controlled(p) ? INFINITY : CONTACT_DEFAULT_STEP;
}

double contact_least_steps(const contact_params *p, double span, double in_contact)
{
    return (contact_steps_uniformly(p) ? span : in_contact) / contact_step_limit(p);
}

double contact_history_work(double before, double after)
{
    return (after - before) * (1.0 + floor(after / CONTACT_HISTORY_PER_UNIT));
}

int contact_steps_uniformly(const contact_params *p) { return method_record(p)->uniform_grid != NULL; }
