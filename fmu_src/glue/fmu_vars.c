#include "fmu_vars.h"

#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>

#include "serial.h"


fm_status fmu_say(const fmu_reporter *r, fm_status status, const char *category, const char *fmt, ...)
{
    char message[512];
    va_list args;
    va_start(args, fmt);
    vsnprintf(message, sizeof message, fmt, args);
    va_end(args);
    if (r->report)
        r->report(r->env, status, category, message);
    return status;
}

const fmu_variable *fmu_find(const fmu_variables *vars, unsigned vr, var_type type, const fmu_reporter *r)
{
    const fmu_variable *other = NULL;
    size_t i;
    for (i = 0; i < vars->count; i++) {
        if (vars->list[i].vr != vr)
            continue;
        if (vars->list[i].type == type)
            return &vars->list[i];
        other = &vars->list[i];
    }
    if (other)
        fmu_say(r, FM_ERROR, "logStatusError",
                "value reference %u is not %s variable of this FMU: it is %s, %s variable", vr, fmu_type_names[type],
                other->name, fmu_type_names[other->type]);
    else
        fmu_say(r, FM_ERROR, "logStatusError",
                "value reference %u is not %s variable of this FMU: it has no variable of that reference", vr,
                fmu_type_names[type]);
    return NULL;
}

const fmu_variable *fmu_settable(const fmu_variables *vars, unsigned vr, var_type type, int started,
                                 const fmu_reporter *r)
{
    const fmu_variable *var = fmu_find(vars, vr, type, r);
    if (!var)
        return NULL;
    if (var->causality == VAR_OUTPUT) {
        fmu_say(r, FM_ERROR, "logStatusError", "%s is an output; it cannot be set", var->name);
        return NULL;
    }
    if (var->causality == VAR_PARAMETER && started) {
        fmu_say(r, FM_ERROR, "logStatusError",
                "%s is a fixed parameter; it can be set only before ExitInitializationMode", var->name);
        return NULL;
    }
    return var;
}

static size_t field_size(field_kind kind)
{
    return kind == FIELD_I32 ? 4 : 8;
}

size_t fmu_fields_size(const state_field *fields, size_t n)
{
    size_t i, size = 0;
    for (i = 0; i < n; i++)
        size += field_size(fields[i].kind);
    return size;
}

void fmu_fields_write(const void *base, const state_field *fields, size_t n, unsigned char *bytes)
{
    size_t i;
    for (i = 0; i < n; i++) {
        const char *at = (const char *)base + fields[i].offset;
        if (fields[i].kind == FIELD_F64)
            serial_put_double(bytes, *(const double *)at);
        else if (fields[i].kind == FIELD_I32)
            serial_put_u32(bytes, (uint32_t) * (const int *)at);
        else
            serial_put_u64(bytes, (uint64_t) * (const int64_t *)at);
        bytes += field_size(fields[i].kind);
    }
}

void fmu_fields_read(void *base, const state_field *fields, size_t n, const unsigned char *bytes)
{
    size_t i;
    for (i = 0; i < n; i++) {
        char *at = (char *)base + fields[i].offset;
        if (fields[i].kind == FIELD_F64)
            *(double *)at = serial_get_double(bytes);
        else if (fields[i].kind == FIELD_I32)
            *(int *)at = (int)(int32_t)serial_get_u32(bytes);
        else
            *(int64_t *)at = (int64_t)serial_get_u64(bytes);
        bytes += field_size(fields[i].kind);
    }
}

int fmu_fields_finite(const void *base, const state_field *fields, size_t n)
{
    size_t i;
    for (i = 0; i < n; i++)
        if (fields[i].kind == FIELD_F64 && !isfinite(*(const double *)((const char *)base + fields[i].offset)))
            return 0;
    return 1;
}
