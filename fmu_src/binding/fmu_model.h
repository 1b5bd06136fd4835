/* The contact FMU's variables (docs/variables.md) on top of the
 * contact model: value references, start values, who may set what and when,
 * and the mapping of a communication step onto the model. It implements
 * fmu_interface.h for the FMI glue. */
#ifndef FRACCONTACT_FMU_MODEL_H
#define FRACCONTACT_FMU_MODEL_H

#include <stddef.h>

#include "contact.h"
#include "fmu_interface.h"

/* Value references (VR_v, VR_F, ...): the FMU's rows of parameters.def. */
#define FMU_VR(name, type, unit, value, min, max, vr, ...) VR_##name = vr,
enum fmu_vr {
#define INPUT_FMU_LIBRARY FMU_VR
#define INPUT_FMU FMU_VR
#define PARAMETER_MODEL_FMU_LIBRARY FMU_VR
#define PARAMETER_FMU FMU_VR
#define OUTPUT_FMU FMU_VR
#define DERIVATIVE_FMU(name, type, unit, value, min, max, vr, ...) VR_der_##name = vr,
#define STATE_FMU FMU_VR
#define INDICATOR_FMU FMU_VR
#include "parameters.def"
};
#undef FMU_VR

/* Model Exchange's STATE rows: the element i (from 0) at vr + i, its
 * derivative at vr + i + VR_DERIVATIVE_OFFSET (parameters.def). */
#define VR_DERIVATIVE_OFFSET 1000

/* What the master feeds to the striker (the parameter `coupling`): F_avg
 * after this FMU's step (Gauss-Seidel), or F_avg_next, read before the step
 * (Jacobi); with the latter a proxy striker starts from the master's v less
 * the impulse it exerted but F_avg_next has not yet announced. */
enum fmu_coupling { COUPLING_GAUSS_SEIDEL = 1, COUPLING_JACOBI = 2 };

#endif
