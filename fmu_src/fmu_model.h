/* The FMU's variables (DESIGN.md: the interface table) on top of the contact
 * model: value references, start values, who may set what and when, and the
 * mapping of a communication step onto the model. No FMI types here: the
 * FMI glue (fmi2_cosim.c) translates. */
#ifndef FRACCONTACT_FMU_MODEL_H
#define FRACCONTACT_FMU_MODEL_H

#include <stddef.h>

#include "contact.h"

/* Value references; they must match modelDescription.xml. */
enum fmu_vr {
    VR_v = 1, VR_m = 2,
    VR_R = 3, VR_E_i = 4, VR_nu_i = 5, VR_E_s = 6, VR_nu_s = 7,
    VR_k = 8, VR_c = 9, VR_dt_max = 10, VR_g = 11, VR_gap0 = 12,
    VR_F = 13, VR_F_avg = 14, VR_F_peak = 15, VR_x = 16, VR_x1 = 17, VR_x2 = 18,
    VR_v_striker = 19, VR_E_diss = 20, VR_eps = 21, VR_semi_integral = 22,
    VR_law = 30, VR_g1_nodes = 31, VR_scene = 32,
    VR_contact = 40
};

/* Status values, numerically the FMI ones they become. */
typedef enum { FM_OK = 0, FM_WARNING = 1, FM_ERROR = 3 } fm_status;

/* Where the model layer reports: status, log category, message. */
typedef void (*fm_report)(void *env, fm_status status, const char *category, const char *message);

typedef struct {
    contact_params params;
    double v, m;          /* the inputs as last set */
    double v_slope;       /* dv/dt given by the master for the next step (0: v held) */
    double F_avg;         /* impulse of the last communication step / its length */
    int started;          /* past initialization: fixed parameters are frozen */
    contact_model model;
    fm_report report;
    void *report_env;
} fmu_model;

/* Start values; forgets any simulation. */
void fm_reset(fmu_model *fm);

fm_status fm_set_real(fmu_model *fm, unsigned vr, double value);
fm_status fm_get_real(fmu_model *fm, unsigned vr, double *value);
fm_status fm_set_integer(fmu_model *fm, unsigned vr, int value);
fm_status fm_get_integer(fmu_model *fm, unsigned vr, int *value);
fm_status fm_set_boolean(fmu_model *fm, unsigned vr, int value);
fm_status fm_get_boolean(fmu_model *fm, unsigned vr, int *value);

/* Input and output derivatives (order 1): the slope of v over the next
 * step (it lapses when v is set again), and the rates of the outputs that
 * change continuously. */
fm_status fm_set_input_derivative(fmu_model *fm, unsigned vr, int order, double value);
fm_status fm_get_output_derivative(fmu_model *fm, unsigned vr, int order, double *value);

/* End of initialization: checks the inputs against the scene, starts the
 * model at time t0 and freezes the fixed parameters. */
fm_status fm_start(fmu_model *fm, double t0);

/* One communication step [t, t + H]. */
fm_status fm_do_step(fmu_model *fm, double t, double H);

/* The model's part of the FMU state, as fm_state_size() bytes in the
 * platform-independent layout of serial.h. fm_state_read takes it back only
 * if it describes a valid model (else FM_ERROR, a report, nothing changed). */
size_t fm_state_size(void);
void fm_state_write(const fmu_model *fm, unsigned char *bytes);
fm_status fm_state_read(fmu_model *fm, const unsigned char *bytes);

#endif
