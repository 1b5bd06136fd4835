/* FMI 3.0 Model Exchange glue (§3): the functions of the host's solver
 * loop, time, continuous states, derivatives, nominals, event indicators
 * and the continuous-time mode, on a model's fmu_me.h hooks. The instance,
 * its event mode, variables and FMU state are fmi3_cosim.c's, which serves
 * both interfaces of an FMU whose guid.h defines FMU_MODEL_EXCHANGE. */
#include <math.h>
#include <stddef.h>

#include "fmi3Functions.h"
#include "fmi3_states.h"
#include "fmu_instance.h"
#include "fmu_me.h"

/* The instance of fmi3_cosim.c, whose common part comes first. */
#define REQUIRE(states, name) \
    if (!in || !in->model_exchange || !fi_allowed(in, (states), (name))) \
        return refused(in, (name))

#define AFTER_INIT_ENTERED (INITIALIZATION_MODE | ME_RUNNING | TERMINATED)

/* A call the instance refuses: logged by fi_allowed, or here where it is
 * not a Model Exchange instance. */
static fmi3Status refused(fmu_instance *in, const char *name)
{
    if (in && !in->model_exchange)
        fi_fail(in, "%s is not supported by an instance for co-simulation: instantiate the FMU for model exchange",
                name);
    return fmi3Error;
}

fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance c)
{
    fmu_instance *in = c;
    REQUIRE(EVENT_MODE, "fmi3EnterContinuousTimeMode");
    in->state = CONTINUOUS_TIME_MODE;
    return fmi3OK;
}

fmi3Status fmi3CompletedIntegratorStep(fmi3Instance c, fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                                       fmi3Boolean *enterEventMode, fmi3Boolean *terminateSimulation)
{
    fmu_instance *in = c;
    (void)noSetFMUStatePriorToCurrentPoint;
    REQUIRE(CONTINUOUS_TIME_MODE, "fmi3CompletedIntegratorStep");
    if (!enterEventMode || !terminateSimulation)
        return (fmi3Status)fi_fail(in, "fmi3CompletedIntegratorStep: enterEventMode or terminateSimulation is NULL");
    fm_me_step_completed(in->fm);
    *enterEventMode = fmi3False;
    *terminateSimulation = fmi3False;
    return fmi3OK;
}

fmi3Status fmi3SetTime(fmi3Instance c, fmi3Float64 time)
{
    fmu_instance *in = c;
    REQUIRE(ME_RUNNING, "fmi3SetTime");
    if (!isfinite(time))
        return (fmi3Status)fi_fail(in, "fmi3SetTime: time = %g must be finite", time);
    fm_me_set_time(in->fm, time);
    return fmi3OK;
}

fmi3Status fmi3SetContinuousStates(fmi3Instance c, const fmi3Float64 continuousStates[], size_t nContinuousStates)
{
    fmu_instance *in = c;
    REQUIRE(CONTINUOUS_TIME_MODE, "fmi3SetContinuousStates");
    if (fi_wrong_count(in, continuousStates, nContinuousStates, fm_me_states, "nContinuousStates",
                    "fmi3SetContinuousStates"))
        return fmi3Error;
    return fm_me_set_states(in->fm, continuousStates) == FM_OK ? fmi3OK : fmi3Error;
}

fmi3Status fmi3GetContinuousStateDerivatives(fmi3Instance c, fmi3Float64 derivatives[], size_t nContinuousStates)
{
    fmu_instance *in = c;
    REQUIRE(AFTER_INIT_ENTERED, "fmi3GetContinuousStateDerivatives");
    if (fi_wrong_count(in, derivatives, nContinuousStates, fm_me_states, "nContinuousStates",
                    "fmi3GetContinuousStateDerivatives"))
        return fmi3Error;
    return fm_me_derivatives(in->fm, derivatives) == FM_OK ? fmi3OK : fmi3Error;
}

fmi3Status fmi3GetEventIndicators(fmi3Instance c, fmi3Float64 eventIndicators[], size_t nEventIndicators)
{
    fmu_instance *in = c;
    REQUIRE(AFTER_INIT_ENTERED, "fmi3GetEventIndicators");
    if (fi_wrong_count(in, eventIndicators, nEventIndicators, fm_me_indicators, "nEventIndicators",
                    "fmi3GetEventIndicators"))
        return fmi3Error;
    fm_me_event_indicators(in->fm, eventIndicators);
    return fmi3OK;
}

fmi3Status fmi3GetContinuousStates(fmi3Instance c, fmi3Float64 continuousStates[], size_t nContinuousStates)
{
    fmu_instance *in = c;
    REQUIRE(AFTER_INIT_ENTERED, "fmi3GetContinuousStates");
    if (fi_wrong_count(in, continuousStates, nContinuousStates, fm_me_states, "nContinuousStates",
                    "fmi3GetContinuousStates"))
        return fmi3Error;
    fm_me_get_states(in->fm, continuousStates);
    return fmi3OK;
}

fmi3Status fmi3GetNominalsOfContinuousStates(fmi3Instance c, fmi3Float64 nominals[], size_t nContinuousStates)
{
    fmu_instance *in = c;
    REQUIRE(INSTANTIATED | AFTER_INIT_ENTERED, "fmi3GetNominalsOfContinuousStates");
    if (fi_wrong_count(in, nominals, nContinuousStates, fm_me_states, "nContinuousStates",
                    "fmi3GetNominalsOfContinuousStates"))
        return fmi3Error;
    fm_me_nominals(in->fm, nominals);
    return fmi3OK;
}

fmi3Status fmi3GetNumberOfEventIndicators(fmi3Instance c, size_t *nEventIndicators)
{
    fmu_instance *in = c;
    REQUIRE(AFTER_INIT_ENTERED, "fmi3GetNumberOfEventIndicators");
    if (!nEventIndicators)
        return (fmi3Status)fi_fail(in, "fmi3GetNumberOfEventIndicators: nEventIndicators is NULL");
    *nEventIndicators = fm_me_indicators;
    return fmi3OK;
}

fmi3Status fmi3GetNumberOfContinuousStates(fmi3Instance c, size_t *nContinuousStates)
{
    fmu_instance *in = c;
    REQUIRE(AFTER_INIT_ENTERED, "fmi3GetNumberOfContinuousStates");
    if (!nContinuousStates)
        return (fmi3Status)fi_fail(in, "fmi3GetNumberOfContinuousStates: nContinuousStates is NULL");
    *nContinuousStates = fm_me_states;
    return fmi3OK;
}
