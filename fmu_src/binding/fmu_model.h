/* The contact FMU's variables (docs/variables.md) on top of the
 * contact model: value references, start values, who may set what and when,
 * and the mapping of a communication step onto the model. It implements
 * fmu_interface.h for the FMI glue. */
#ifndef FRACCONTACT_FMU_MODEL_H
#define FRACCONTACT_FMU_MODEL_H

#include <stddef.h>

#include "contact.h"
#include "fmu_interface.h"

/* Value references; they must match modelDescription.xml. */
enum fmu_vr {
    VR_v = 1, VR_m = 2,
    VR_R = 3, VR_E_i = 4, VR_nu_i = 5, VR_E_s = 6, VR_nu_s = 7,
    VR_k = 8, VR_c = 9, VR_dt_max = 10, VR_g = 11, VR_gap0 = 12,
    VR_F = 13, VR_F_avg = 14, VR_F_peak = 15, VR_x = 16, VR_x1 = 17, VR_x2 = 18,
    VR_v_striker = 19, VR_E_diss = 20, VR_eps = 21, VR_semi_integral = 22,
    VR_spring_exponent = 23, VR_damper_order = 24, VR_c_alpha = 25, VR_memory_tolerance = 26,
    VR_tolerance = 27, VR_F_avg_next = 28,
    VR_v2 = 36, VR_m2 = 37, VR_a = 38, VR_a2 = 39,
    VR_law = 30, VR_g1_nodes = 31, VR_scene = 32, VR_damper = 33, VR_memory = 34, VR_coupling = 35,
    VR_contact = 40
};

/* What the master feeds to the striker (the parameter `coupling`): F_avg
 * after this FMU's step (Gauss-Seidel), or F_avg_next, read before the step
 * (Jacobi); with the latter a proxy striker starts from the master's v less
 * the impulse it exerted but F_avg_next has not yet announced. */
enum fmu_coupling { COUPLING_GAUSS_SEIDEL = 1, COUPLING_JACOBI = 2 };

#endif
