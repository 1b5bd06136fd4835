/* The hooks of fmu_interface.h that every binding would write alike, so that
 * a binding writes only what its model has (as Reference-FMUs' cosimulation.c
 * supplies a default for each function a model's config.h does not claim).
 *
 * A binding includes this file once, at its end, after its struct fmu_model
 * (with the members `log`, its fmu_reporter, and `started`, set once
 * initialization ends), its table `variables` and its function start_values.
 * Before including it, it defines the macro of each hook it wrote itself
 * (FM_GET_REAL, FM_SET_INTEGER, FM_GET_INTEGER, FM_SET_BOOLEAN,
 * FM_GET_BOOLEAN), and FM_RELEASE(fm) where its model holds memory beyond
 * the struct. A default stores a value where the table says, with no rule
 * of its own: a model with rules for a type writes its setter; for a type
 * of which the model has no variable the table reports every reference. */
#ifndef FRACCONTACT_FMU_DEFAULTS_H
#define FRACCONTACT_FMU_DEFAULTS_H

#include <stdlib.h>
#include <string.h>

#include "fmu_interface.h"
#include "fmu_vars.h"

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

#endif
