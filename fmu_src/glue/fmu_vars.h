/* What every FMU model of this project does the same way: a table of its
 * variables (value reference, name, type, causality, where the value lives),
 * lookups that report a wrong reference or a forbidden set, formatted
 * reports, and its FMU state as a table of fields. */
#ifndef FRACCONTACT_FMU_VARS_H
#define FRACCONTACT_FMU_VARS_H

#include <stddef.h>

#include "fmu_interface.h"

typedef enum { VAR_REAL, VAR_INTEGER, VAR_BOOLEAN } var_type;
typedef enum { VAR_PARAMETER, VAR_INPUT, VAR_OUTPUT } var_causality;

typedef struct {
    unsigned vr;
    const char *name;
    var_type type;
    var_causality causality;
    size_t offset; /* of the stored value in the model's struct (parameters, inputs) */
} fmu_variable;

typedef struct {
    const fmu_variable *list;
    size_t count;
} fmu_variables;

typedef struct {
    fm_report report;
    void *env;
} fmu_reporter;

#if defined(__GNUC__)
__attribute__((format(printf, 4, 5)))
#endif
fm_status fmu_say(const fmu_reporter *r, fm_status status, const char *category, const char *fmt, ...);

/* The types as the FMU's FMI version names them, with their article ("a Real",
 * "a Float64"), indexed by var_type: defined by its glue (fmi2_cosim.c,
 * fmi3_cosim.c). */
extern const char *const fmu_type_names[3];

/* The model's table, `variables` (defined by fmu_defaults.h). */
const fmu_variables *fm_variables(void);

/* The variable of that reference and type, or NULL after an error report
 * naming the variable that reference has, if any, and its type. */
const fmu_variable *fmu_find(const fmu_variables *vars, unsigned vr, var_type type, const fmu_reporter *r);

/* The same, and NULL after a report if it may not be set now: outputs never,
 * parameters (all fixed) only before initialization ends. */
const fmu_variable *fmu_settable(const fmu_variables *vars, unsigned vr, var_type type, int started,
                                 const fmu_reporter *r);

/* A model's FMU state as a table of fields (offsets into its struct), in the
 * layout of serial.h: doubles bit for bit, 32- and 64-bit integers (int, int64_t) little-endian. */
typedef enum { FIELD_F64, FIELD_I32, FIELD_I64 } field_kind;

typedef struct {
    size_t offset;
    field_kind kind;
} state_field;

size_t fmu_fields_size(const state_field *fields, size_t n);
void fmu_fields_write(const void *base, const state_field *fields, size_t n, unsigned char *bytes);
void fmu_fields_read(void *base, const state_field *fields, size_t n, const unsigned char *bytes);

/* Whether every double among the fields is finite: a state read from bytes
 * may hold anything. */
int fmu_fields_finite(const void *base, const state_field *fields, size_t n);

#endif
