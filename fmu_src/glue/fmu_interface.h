/* What the FMI glue (fmi2_cosim.c, fmi3_cosim.c) asks of a model: the hook interface each
 * FMU's binding implements (fmu_src/binding/fmu_model.c for the contact
 * element, striker/striker_model.c for the striker, bodies/body_model.c for
 * the body), taking from fmu_defaults.h the hooks it does not write. No FMI
 * types: plain C values and statuses numerically equal to the FMI ones. */
#ifndef FRACCONTACT_FMU_INTERFACE_H
#define FRACCONTACT_FMU_INTERFACE_H

#include <stddef.h>

typedef enum { FM_OK = 0, FM_WARNING = 1, FM_ERROR = 3 } fm_status;

/* Where a model reports: status, log category, message. */
typedef void (*fm_report)(void *env, fm_status status, const char *category, const char *message);

typedef struct fmu_model fmu_model; /* each model defines its own */

/* A model with its start values, reporting through report(env, ...); NULL
 * when memory runs out. */
fmu_model *fm_new(fm_report report, void *env);
void fm_free(fmu_model *fm);

/* Start values; forgets any simulation. */
void fm_reset(fmu_model *fm);

fm_status fm_set_real(fmu_model *fm, unsigned vr, double value);
fm_status fm_get_real(fmu_model *fm, unsigned vr, double *value);
fm_status fm_set_integer(fmu_model *fm, unsigned vr, int value);
fm_status fm_get_integer(fmu_model *fm, unsigned vr, int *value);
fm_status fm_set_boolean(fmu_model *fm, unsigned vr, int value);
fm_status fm_get_boolean(fmu_model *fm, unsigned vr, int *value);

/* Derivatives of real inputs and outputs (fmi2SetRealInputDerivatives,
 * fmi2GetRealOutputDerivatives). */
fm_status fm_set_input_derivative(fmu_model *fm, unsigned vr, int order, double value);
fm_status fm_get_output_derivative(fmu_model *fm, unsigned vr, int order, double *value);

/* End of initialization: checks what the model needs, starts it at t0 for
 * a run that the master means to end at t_stop (INFINITY: not said).
 * FM_WARNING: started, with a reported warning (a value without effect). */
fm_status fm_start(fmu_model *fm, double t0, double t_stop);

/* One communication step [t, t + H], and the model's time. The glue has
 * checked that H is finite and >= 0 and that t is the model's time up to
 * the master's rounding: the model takes t as its time. H is 0 where the
 * master's step does not advance time (t + H == t, fi_advance). */
fm_status fm_do_step(fmu_model *fm, double t, double H);
double fm_time(const fmu_model *fm);

/* For FMI 3.0's early return and event mode (a model served by the FMI 2.0
 * glue alone need not define these). fm_do_step with options:
 * FM_STOP_AT_EVENT ends the step right after the model's first event inside
 * it (*event = 1, and fm_time tells when); FM_CONTINUE continues the
 * communication step that the last call ended at an event, so that averages
 * over the step cover both parts. After a stop at an event the discrete
 * outputs keep their values from before it until fm_update_discrete (FMI
 * 3.0's event mode) or the next step. */
enum { FM_STOP_AT_EVENT = 1, FM_CONTINUE = 2 };
fm_status fm_do_step_until(fmu_model *fm, double t, double H, unsigned options, int *event);
void fm_update_discrete(fmu_model *fm);

/* An output the FMU does not offer (an exported FMU's modelDescription.xml
 * leaves it out: fixed_values.h), told before initialization: the model may
 * skip the work that only this output needs. */
void fm_leave_out(fmu_model *fm, unsigned vr);

/* The model's part of the FMU state, as fm_state_size(fm) bytes in the
 * platform-independent layout of serial.h (a model with a growing memory
 * needs more as it runs). fm_state_read takes `size` bytes back only if they
 * describe a valid model (else FM_ERROR, a report, nothing changed). */
size_t fm_state_size(const fmu_model *fm);
void fm_state_write(const fmu_model *fm, unsigned char *bytes);
fm_status fm_state_read(fmu_model *fm, const unsigned char *bytes, size_t size);

#endif
