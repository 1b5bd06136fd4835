/* What the Model Exchange glue (fmi2_me.c, fmi3_me.c) asks of a model
 * beyond fmu_interface.h: its continuous states, their derivatives and
 * nominal values, its event indicators, and what it does at an event and
 * after an accepted step. Only a model whose modelDescription.xml has a
 * ModelExchange element writes these (guid.h then defines
 * FMU_MODEL_EXCHANGE). */
#ifndef FRACCONTACT_FMU_ME_H
#define FRACCONTACT_FMU_ME_H

#include <stddef.h>

#include "fmu_interface.h"

/* The numbers modelDescription.xml declares. */
extern const size_t fm_me_states, fm_me_indicators;

/* The model serves a Model Exchange instance: said after the instance is
 * made and after every reset. */
void fm_me_instantiated(fmu_model *fm);

/* End of initialization in Model Exchange: what fm_start checks and does,
 * and whether the model runs there (FM_ERROR and a report naming the
 * variable, its value and what to take instead, the model as it was). */
fm_status fm_me_start(fmu_model *fm, double t0, double t_stop);

void fm_me_set_time(fmu_model *fm, double t);

/* fm_me_states values each. */
fm_status fm_me_set_states(fmu_model *fm, const double *x);
void fm_me_get_states(fmu_model *fm, double *x);
fm_status fm_me_derivatives(fmu_model *fm, double *dx);
void fm_me_nominals(fmu_model *fm, double *nominal);

/* fm_me_indicators values. */
void fm_me_event_indicators(fmu_model *fm, double *z);

/* The event at the model's time handled (discrete outputs updated). */
void fm_me_event(fmu_model *fm);

/* The host accepted the state it set last. */
void fm_me_step_completed(fmu_model *fm);

/* The directional derivative of the state derivatives `unknowns` for the
 * changes `seed` of the states or inputs `knowns` (value references) into
 * sensitivity (n_unknowns values); FM_ERROR and a report for a reference
 * that is neither. */
fm_status fm_me_directional(fmu_model *fm, const unsigned *unknowns, size_t n_unknowns, const unsigned *knowns,
                            size_t n_knowns, const double *seed, double *sensitivity);

#endif
