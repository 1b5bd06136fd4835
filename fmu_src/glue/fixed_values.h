/* The values an exported FMU fixes (fraccontact export, docs/export.md):
 * resources/fixed_values.txt, one "name value" a line, '#' comments, ended
 * by a line "end"; a line "guid TOKEN" gives the exported FMU's own GUID or
 * instantiation token, a line "omit NAME" an output that the exported FMU
 * does not offer (fm_leave_out: the model may skip what only it needs). Read at instantiation and set through the model's own
 * setters, as if the importer had set them; set again at every reset. A
 * FMU without the file is the full FMU. */
#ifndef FRACCONTACT_FIXED_VALUES_H
#define FRACCONTACT_FIXED_VALUES_H

#include "fmu_instance.h"

#define FV_FILE "fixed_values.txt"
#define FV_MAX_BYTES 16384 /* the file's largest size: a value a line for every variable, with comments */

/* Sets the values of the file in `resources` (FMI 2.0's file URI of the
 * resources folder where `uri`, else FMI 3.0's path, ending in a separator;
 * NULL: none), and checks the importer's `token` (its GUID or instantiation
 * token, named `what` in an error) against the file's "guid" line, which an
 * exported modelDescription.xml carries, or the full FMU's (guid.h). 0 after
 * an error naming `caller`, the file, its line, the variable, the value and
 * the rule; the values are then half set and the instance is to be released. */
int fv_load(fmu_instance *in, const char *resources, int uri, const char *caller, const char *token,
            const char *what);

/* fm_reset, then the fixed values and the outputs left out again: the instance as instantiated. */
void fv_reset(fmu_instance *in);

void fv_free(fmu_instance *in);

#endif
