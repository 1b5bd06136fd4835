/* The hooks of fmu_interface.h that bindings would write alike, so that a
 * binding writes only what its model has (as Reference-FMUs' cosimulation.c
 * supplies a default for each function a model's config.h does not claim).
 *
 * A binding includes this file once, at its end. Before it, it defines
 * - struct fmu_model, with the members log (its fmu_reporter), started
 *   (set when initialization ends) and t (its time), the table `variables`
 *   and start_values;
 * - the macro of each hook it wrote itself: FM_SET_REAL, FM_GET_REAL,
 *   FM_SET_INTEGER, FM_GET_INTEGER, FM_SET_BOOLEAN, FM_GET_BOOLEAN,
 *   FM_SET_INPUT_DERIVATIVE, FM_GET_OUTPUT_DERIVATIVE, FM_LEAVE_OUT, FM_START,
 *   FM_TIME, FM_STATE (the three of the FMU state);
 * - what the defaults it takes call: start_state (FM_SET_REAL's, FM_START's),
 *   rule_broken (FM_SET_REAL's), rate and the string FM_RATES
 *   (FM_GET_OUTPUT_DERIVATIVE's), state_fields and state_accepted (FM_STATE's);
 * - FM_RELEASE(fm) where its model holds memory beyond the struct, and
 *   FM_OUTPUTS(fm) where it has outputs derived from its state and inputs
 *   (derived again after a start, a value set and a state read).
 * A default stores a value where the table says, with no rule but the Real
 * values' rule_broken: a model with other rules for a type writes its
 * setter; for a type of which the model has no variable, the table reports
 * every reference. */
#ifndef FRACCONTACT_FMU_DEFAULTS_H
#define FRACCONTACT_FMU_DEFAULTS_H

#include <stdlib.h>
#include <string.h>

#include "fmu_interface.h"
#include "fmu_vars.h"
#include "guid.h"

#ifndef FM_RELEASE
#define FM_RELEASE(fm) ((void)(fm))
#endif

/* The model's start values, on a struct that is zero but for its log. */
static void start_values(fmu_model *fm);

fmu_model *fm_new(fm_report report, void *env)
{
    fmu_model *fm = calloc(1, sizeof *fm);
    if (!fm)
        return NULL;
    fm->log.report = report;
    fm->log.env = env;
    fm_reset(fm);
    return fm;
}

void fm_free(fmu_model *fm)
{
    FM_RELEASE(fm);
    free(fm);
}

void fm_reset(fmu_model *fm)
{
    fmu_reporter log = fm->log;
    FM_RELEASE(fm);
    memset(fm, 0, sizeof *fm);
    fm->log = log;
    start_values(fm);
}

const fmu_variables *fm_variables(void)
{
    return &variables;
}

/* The value stored for the variable `vr` of that type, set or read. */
static fm_status set_stored(fmu_model *fm, unsigned vr, var_type type, const void *value, size_t size)
{
    const fmu_variable *var = fmu_settable(&variables, vr, type, fm->started, &fm->log);
    if (!var)
        return FM_ERROR;
    memcpy((char *)fm + var->offset, value, size);
    return FM_OK;
}

static fm_status get_stored(fmu_model *fm, unsigned vr, var_type type, void *value, size_t size)
{
    const fmu_variable *var = fmu_find(&variables, vr, type, &fm->log);
    if (!var)
        return FM_ERROR;
    memcpy(value, (const char *)fm + var->offset, size);
    return FM_OK;
}

#ifndef FM_OUTPUTS
#define FM_OUTPUTS(fm) ((void)(fm))
#endif

#if !defined(FM_SET_REAL) || !defined(FM_START)
/* The state at the start, from the parameters. */
static void start_state(fmu_model *fm);
#endif

#ifndef FM_SET_REAL
/* The value's rule, or NULL if it is fine. */
static const char *rule_broken(unsigned vr, double value);

fm_status fm_set_real(fmu_model *fm, unsigned vr, double value)
{
    const fmu_variable *var = fmu_settable(&variables, vr, VAR_REAL, fm->started, &fm->log);
    const char *why;
    if (!var)
        return FM_ERROR;
    why = rule_broken(vr, value);
    if (why)
        return fmu_say(&fm->log, FM_ERROR, "logStatusError", "%s = %g is invalid: %s", var->name, value, why);
    memcpy((char *)fm + var->offset, &value, sizeof value);
    if (!fm->started) /* before initialization the outputs show the start */
        start_state(fm);
    FM_OUTPUTS(fm);
    return FM_OK;
}
#endif

#ifndef FM_GET_REAL
fm_status fm_get_real(fmu_model *fm, unsigned vr, double *value)
{
    return get_stored(fm, vr, VAR_REAL, value, sizeof *value);
}
#endif

#ifndef FM_SET_INTEGER
fm_status fm_set_integer(fmu_model *fm, unsigned vr, int value)
{
    return set_stored(fm, vr, VAR_INTEGER, &value, sizeof value);
}
#endif

#ifndef FM_GET_INTEGER
fm_status fm_get_integer(fmu_model *fm, unsigned vr, int *value)
{
    return get_stored(fm, vr, VAR_INTEGER, value, sizeof *value);
}
#endif

#ifndef FM_SET_BOOLEAN
fm_status fm_set_boolean(fmu_model *fm, unsigned vr, int value)
{
    return set_stored(fm, vr, VAR_BOOLEAN, &value, sizeof value);
}
#endif

#ifndef FM_GET_BOOLEAN
fm_status fm_get_boolean(fmu_model *fm, unsigned vr, int *value)
{
    return get_stored(fm, vr, VAR_BOOLEAN, value, sizeof *value);
}
#endif

#ifndef FM_SET_INPUT_DERIVATIVE
/* The inputs are held over a step. */
fm_status fm_set_input_derivative(fmu_model *fm, unsigned vr, int order, double value)
{
    (void)value;
    return fmu_say(&fm->log, FM_ERROR, "logStatusError",
                   "fmi2SetRealInputDerivatives: value reference %u, order %d: the " FMU_MODEL_IDENTIFIER
                   " holds its inputs", vr, order);
}
#endif

#ifndef FM_GET_OUTPUT_DERIVATIVE
/* The output vr's first derivative into *value, where it has one (0
 * where not); FM_RATES names the outputs that have one. */
static int rate(const fmu_model *fm, unsigned vr, double *value);

fm_status fm_get_output_derivative(fmu_model *fm, unsigned vr, int order, double *value)
{
    if (order == 1 && rate(fm, vr, value))
        return FM_OK;
    return fmu_say(&fm->log, FM_ERROR, "logStatusError",
                   "fmi2GetRealOutputDerivatives: value reference %u, order %d: only " FM_RATES ", order 1", vr,
                   order);
}
#endif

#ifndef FM_LEAVE_OUT
/* Every output costs the same work offered or not. */
void fm_leave_out(fmu_model *fm, unsigned vr)
{
    (void)fm;
    (void)vr;
}
#endif

#ifndef FM_START
fm_status fm_start(fmu_model *fm, double t0, double t_stop)
{
    (void)t_stop;
    fm->t = t0;
    start_state(fm);
    fm->started = 1;
    FM_OUTPUTS(fm);
    return FM_OK;
}
#endif

#ifndef FM_TIME
double fm_time(const fmu_model *fm)
{
    return fm->t;
}
#endif

#ifndef FM_STATE
/* The FMU state is the table state_fields; a state read from bytes is
 * taken where its values are finite and state_accepted (the model's rules)
 * takes it. */
#define N_STATE_FIELDS (sizeof state_fields / sizeof state_fields[0])

static int state_accepted(const fmu_model *trial);

size_t fm_state_size(const fmu_model *fm)
{
    (void)fm;
    return fmu_fields_size(state_fields, N_STATE_FIELDS);
}

void fm_state_write(const fmu_model *fm, unsigned char *bytes)
{
    fmu_fields_write(fm, state_fields, N_STATE_FIELDS, bytes);
}

fm_status fm_state_read(fmu_model *fm, const unsigned char *bytes, size_t size)
{
    fmu_model trial = *fm;
    if (size != fm_state_size(fm))
        return fmu_say(&fm->log, FM_ERROR, "logStatusError", "the FMU state has the wrong length");
    fmu_fields_read(&trial, state_fields, N_STATE_FIELDS, bytes);
    if (!fmu_fields_finite(&trial, state_fields, N_STATE_FIELDS) || (trial.started != 0 && trial.started != 1)
        || !state_accepted(&trial))
        return fmu_say(&fm->log, FM_ERROR, "logStatusError", "the FMU state holds an invalid value");
    *fm = trial;
    FM_OUTPUTS(fm);
    return FM_OK;
}
#endif

#endif
