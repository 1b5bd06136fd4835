/* FMI 2.0 Model Exchange glue (§3): the functions of the host's solver
 * loop, time, continuous states, derivatives, nominals, event indicators
 * and the event and continuous-time modes, on a model's fmu_me.h hooks.
 * The instance's life cycle, variables and FMU state are fmi2_cosim.c's,
 * which serves both interfaces of an FMU whose guid.h defines
 * FMU_MODEL_EXCHANGE. */
#include <math.h>
#include <stddef.h>

#include "fmi2Functions.h"
#include "fmi2_states.h"
#include "fmu_instance.h"
#include "fmu_me.h"

/* The instance of fmi2_cosim.c, whose common part comes first. */
#define REQUIRE(states, name) \
    if (!in || !in->model_exchange || !fi_allowed(in, (states), (name))) \
        return refused(in, (name))

#define AFTER_INIT_ENTERED (INITIALIZATION_MODE | ME_RUNNING | TERMINATED)

/* A call the instance refuses: logged by fi_allowed, or here where it is
 * not a Model Exchange instance. */
static fmi2Status refused(fmu_instance *in, const char *name)
{
    if (in && !in->model_exchange)
        fi_fail(in, "%s is not supported by an instance for co-simulation: instantiate the FMU as fmi2ModelExchange",
                name);
    return fmi2Error;
}

fmi2Status fmi2SetTime(fmi2Component c, fmi2Real time)
{
    fmu_instance *in = c;
    REQUIRE(ME_RUNNING, "fmi2SetTime");
    if (!isfinite(time))
        return (fmi2Status)fi_fail(in, "fmi2SetTime: time = %g must be finite", time);
    fm_me_set_time(in->fm, time);
    return fmi2OK;
}

fmi2Status fmi2SetContinuousStates(fmi2Component c, const fmi2Real x[], size_t nx)
{
    fmu_instance *in = c;
    REQUIRE(CONTINUOUS_TIME_MODE, "fmi2SetContinuousStates");
    if (fi_wrong_count(in, x, nx, fm_me_states, "nx", "fmi2SetContinuousStates"))
        return fmi2Error;
    return fm_me_set_states(in->fm, x) == FM_OK ? fmi2OK : fmi2Error;
}

fmi2Status fmi2GetContinuousStates(fmi2Component c, fmi2Real x[], size_t nx)
{
    fmu_instance *in = c;
    REQUIRE(AFTER_INIT_ENTERED, "fmi2GetContinuousStates");
    if (fi_wrong_count(in, x, nx, fm_me_states, "nx", "fmi2GetContinuousStates"))
        return fmi2Error;
    fm_me_get_states(in->fm, x);
    return fmi2OK;
}

fmi2Status fmi2GetDerivatives(fmi2Component c, fmi2Real derivatives[], size_t nx)
{
    fmu_instance *in = c;
    REQUIRE(AFTER_INIT_ENTERED, "fmi2GetDerivatives");
    if (fi_wrong_count(in, derivatives, nx, fm_me_states, "nx", "fmi2GetDerivatives"))
        return fmi2Error;
    return fm_me_derivatives(in->fm, derivatives) == FM_OK ? fmi2OK : fmi2Error;
}

fmi2Status fmi2GetNominalsOfContinuousStates(fmi2Component c, fmi2Real x_nominal[], size_t nx)
{
    fmu_instance *in = c;
    REQUIRE(INSTANTIATED | AFTER_INIT_ENTERED, "fmi2GetNominalsOfContinuousStates");
    if (fi_wrong_count(in, x_nominal, nx, fm_me_states, "nx", "fmi2GetNominalsOfContinuousStates"))
        return fmi2Error;
    fm_me_nominals(in->fm, x_nominal);
    return fmi2OK;
}

fmi2Status fmi2GetEventIndicators(fmi2Component c, fmi2Real eventIndicators[], size_t ni)
{
    fmu_instance *in = c;
    REQUIRE(AFTER_INIT_ENTERED, "fmi2GetEventIndicators");
    if (fi_wrong_count(in, eventIndicators, ni, fm_me_indicators, "ni", "fmi2GetEventIndicators"))
        return fmi2Error;
    fm_me_event_indicators(in->fm, eventIndicators);
    return fmi2OK;
}

fmi2Status fmi2EnterEventMode(fmi2Component c)
{
    fmu_instance *in = c;
    REQUIRE(ME_RUNNING, "fmi2EnterEventMode");
    in->state = EVENT_MODE;
    return fmi2OK;
}

/* The event at the model's time: the model's discrete outputs follow its
 * state; no state jumps, no time event, nothing more to iterate. */
fmi2Status fmi2NewDiscreteStates(fmi2Component c, fmi2EventInfo *eventInfo)
{
    fmu_instance *in = c;
    REQUIRE(EVENT_MODE, "fmi2NewDiscreteStates");
    if (!eventInfo)
        return (fmi2Status)fi_fail(in, "fmi2NewDiscreteStates: eventInfo is NULL");
    fm_me_event(in->fm);
    eventInfo->newDiscreteStatesNeeded = fmi2False;
    eventInfo->terminateSimulation = fmi2False;
    eventInfo->nominalsOfContinuousStatesChanged = fmi2False;
    eventInfo->valuesOfContinuousStatesChanged = fmi2False;
    eventInfo->nextEventTimeDefined = fmi2False;
    eventInfo->nextEventTime = 0.0;
    return fmi2OK;
}

fmi2Status fmi2EnterContinuousTimeMode(fmi2Component c)
{
    fmu_instance *in = c;
    REQUIRE(EVENT_MODE, "fmi2EnterContinuousTimeMode");
    in->state = CONTINUOUS_TIME_MODE;
    return fmi2OK;
}

fmi2Status fmi2CompletedIntegratorStep(fmi2Component c, fmi2Boolean noSetFMUStatePriorToCurrentPoint,
                                       fmi2Boolean *enterEventMode, fmi2Boolean *terminateSimulation)
{
    fmu_instance *in = c;
    (void)noSetFMUStatePriorToCurrentPoint;
    REQUIRE(CONTINUOUS_TIME_MODE, "fmi2CompletedIntegratorStep");
    if (!enterEventMode || !terminateSimulation)
        return (fmi2Status)fi_fail(in, "fmi2CompletedIntegratorStep: enterEventMode or terminateSimulation is NULL");
    fm_me_step_completed(in->fm);
    *enterEventMode = fmi2False;
    *terminateSimulation = fmi2False;
    return fmi2OK;
}
