/* FMI 3.0 co-simulation glue: the same model and binding as FMI 2.0
 * (fmu_interface.h), with FMI 3.0's state machine, event mode, early return
 * at the model's events and the intermediate update callback. Instances,
 * logging and the FMU state are fmu_instance.c's, shared with fmi2_cosim.c.
 * It knows the standard, not the physics. Where the FMU has Model Exchange
 * too (FMU_MODEL_EXCHANGE), the instances, event mode, variables and FMU
 * state here serve it as well, and fmi3_me.c has its own functions. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi3Functions.h"
#include "fixed_values.h"
#include "fmi3_states.h"
#include "fmu_instance.h"
#include "fmu_vars.h"
#include "guid.h"
#ifdef FMU_MODEL_EXCHANGE
#include "fmu_me.h"
#endif

/* As FMI 3.0 §3.2 and §4.2 name them (fmi3_states.h). */
const char *const fi_state_names[FI_STATE_BITS] = {"Instantiated", "Initialization Mode", "Continuous-Time Mode", NULL,
                                                   NULL, "Event Mode", "Step Mode", "Terminated"};
const char *const fmu_type_names[3] = {"a Float64", "an Int32", "a Boolean"};

/* The states after initialization of the instance `in` at hand: Model
 * Exchange's event and continuous-time modes, or co-simulation's. */
#define SIMULATING (in && in->base.model_exchange ? ME_RUNNING : EVENT_MODE | STEP_MODE)
#define ANY_STATE (INSTANTIATED | INITIALIZATION_MODE | ME_RUNNING | STEP_MODE | TERMINATED)
#define AFTER_INIT_ENTERED (INITIALIZATION_MODE | SIMULATING | TERMINATED)
#define SETTABLE (INSTANTIATED | INITIALIZATION_MODE | SIMULATING)

#define VR_TIME 0u /* the independent variable */

typedef struct {
    fmu_instance base; /* first: the common part */
    fmi3InstanceEnvironment environment;
    fmi3LogMessageCallback log_message;
    fmi3IntermediateUpdateCallback intermediate_update;
    int event_mode_used;
    int early_return_allowed;
    fi_state *step_start; /* before a step that goes on after an event inside it (fmi3DoStep) */
} instance;

static void send_log(const fmu_instance *base, fi_status status, const char *category, const char *message)
{
    const instance *in = (const instance *)base;
    if (in->log_message)
        in->log_message(in->environment, (fmi3Status)status, category, message);
}

#define REQUIRE(states, name) \
    if (!in || !fi_allowed(&in->base, (states), (name))) \
        return fmi3Error

#define fail(in, ...) ((fmi3Status)fi_fail(&(in)->base, __VA_ARGS__))

/* A co-simulation function called on a Model Exchange instance. */
#define CO_SIMULATION_ONLY(name) \
    if (in && in->base.model_exchange) \
        return fail(in, "%s is a function of co-simulation: this instance was made by fmi3InstantiateModelExchange, " \
                        "the host's solver integrates it (fmi3SetTime, fmi3SetContinuousStates, " \
                        "fmi3GetContinuousStateDerivatives)", (name))

/* ---------------------------------------------------------------- instances */

const char *fmi3GetVersion(void) { return fmi3Version; }

/* An instance, its messages naming `name`, the function that makes it
 * (fmi3InstantiateCoSimulation, or fmi3InstantiateModelExchange with
 * event mode used and no intermediate update), or NULL and a message. */
static instance *instantiate(const char *name, fmi3String instanceName, fmi3String instantiationToken,
                             fmi3String resourcePath, fmi3Boolean loggingOn, fmi3Boolean eventModeUsed,
                             fmi3Boolean earlyReturnAllowed, size_t nRequiredIntermediateVariables,
                             fmi3InstanceEnvironment instanceEnvironment, fmi3LogMessageCallback logMessage,
                             fmi3IntermediateUpdateCallback intermediateUpdate)
{
    instance probe, *in;
    char token[64];
    probe.environment = instanceEnvironment;
    probe.log_message = logMessage;
    fi_probe(&probe.base, instanceName, send_log);
    if (!instanceName || !*instanceName) {
        fail(&probe, "%s: instanceName must be a non-empty string", name);
        return NULL;
    }
    if (!instantiationToken) {
        fail(&probe, "%s: instantiationToken does not match modelDescription.xml (" FMU_GUID ")", name);
        return NULL;
    }
    if (nRequiredIntermediateVariables > 0) {
        fail(&probe, "%s: nRequiredIntermediateVariables = %lu, but no variable of this FMU can be read or set "
                     "during an intermediate update", name, (unsigned long)nRequiredIntermediateVariables);
        return NULL;
    }
    in = calloc(1, sizeof *in);
    if (!in) {
        fail(&probe, "%s: out of memory", name);
        return NULL;
    }
    *in = probe;
    in->step_start = NULL;
    in->intermediate_update = intermediateUpdate;
    in->event_mode_used = eventModeUsed;
    in->early_return_allowed = earlyReturnAllowed;
    if (!fi_init(&in->base, instanceName, send_log, loggingOn, INSTANTIATED)) {
        free(in);
        return NULL;
    }
    snprintf(token, sizeof token, "%s: instantiationToken", name);
    if (!fv_load(&in->base, resourcePath, 0, name, instantiationToken, token)) {
        fi_release(&in->base);
        free(in);
        return NULL;
    }
    return in;
}

fmi3Instance fmi3InstantiateCoSimulation(fmi3String instanceName, fmi3String instantiationToken,
                                         fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                         fmi3Boolean eventModeUsed, fmi3Boolean earlyReturnAllowed,
                                         const fmi3ValueReference requiredIntermediateVariables[],
                                         size_t nRequiredIntermediateVariables,
                                         fmi3InstanceEnvironment instanceEnvironment,
                                         fmi3LogMessageCallback logMessage,
                                         fmi3IntermediateUpdateCallback intermediateUpdate)
{
    (void)visible;
    (void)requiredIntermediateVariables;
    return instantiate("fmi3InstantiateCoSimulation", instanceName, instantiationToken, resourcePath, loggingOn,
                       eventModeUsed, earlyReturnAllowed, nRequiredIntermediateVariables, instanceEnvironment,
                       logMessage, intermediateUpdate);
}

static fmi3Instance other_interface(fmi3String instanceName, fmi3InstanceEnvironment environment,
                                    fmi3LogMessageCallback logMessage, const char *name)
{
    instance probe;
    probe.environment = environment;
    probe.log_message = logMessage;
    fi_probe(&probe.base, instanceName, send_log);
#ifdef FMU_MODEL_EXCHANGE
    fail(&probe, "%s: this FMU supports model exchange and co-simulation only", name);
#else
    fail(&probe, "%s: this FMU supports co-simulation only", name);
#endif
    return NULL;
}

#ifdef FMU_MODEL_EXCHANGE
/* Model Exchange (fmi3_me.c): the co-simulation's instance, its event mode
 * used, no intermediate update. */
fmi3Instance fmi3InstantiateModelExchange(fmi3String instanceName, fmi3String instantiationToken,
                                          fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                          fmi3InstanceEnvironment instanceEnvironment,
                                          fmi3LogMessageCallback logMessage)
{
    instance *in = instantiate("fmi3InstantiateModelExchange", instanceName, instantiationToken, resourcePath,
                               loggingOn, fmi3True, fmi3False, 0, instanceEnvironment, logMessage, NULL);
    (void)visible;
    if (in) {
        in->base.model_exchange = 1;
        fm_me_instantiated(in->base.fm);
    }
    return in;
}
#else
fmi3Instance fmi3InstantiateModelExchange(fmi3String instanceName, fmi3String instantiationToken,
                                          fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                          fmi3InstanceEnvironment instanceEnvironment,
                                          fmi3LogMessageCallback logMessage)
{
    (void)instantiationToken;
    (void)resourcePath;
    (void)visible;
    (void)loggingOn;
    return other_interface(instanceName, instanceEnvironment, logMessage, "fmi3InstantiateModelExchange");
}
#endif

fmi3Instance fmi3InstantiateScheduledExecution(fmi3String instanceName, fmi3String instantiationToken,
                                               fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                               fmi3InstanceEnvironment instanceEnvironment,
                                               fmi3LogMessageCallback logMessage, fmi3ClockUpdateCallback clockUpdate,
                                               fmi3LockPreemptionCallback lockPreemption,
                                               fmi3UnlockPreemptionCallback unlockPreemption)
{
    (void)instantiationToken;
    (void)resourcePath;
    (void)visible;
    (void)loggingOn;
    (void)clockUpdate;
    (void)lockPreemption;
    (void)unlockPreemption;
    return other_interface(instanceName, instanceEnvironment, logMessage, "fmi3InstantiateScheduledExecution");
}

void fmi3FreeInstance(fmi3Instance c)
{
    instance *in = c;
    if (!in)
        return;
    fi_release(&in->base);
    fi_free_state(&in->step_start);
    free(in);
}

fmi3Status fmi3SetDebugLogging(fmi3Instance c, fmi3Boolean loggingOn, size_t nCategories,
                               const fmi3String categories[])
{
    instance *in = c;
    REQUIRE(ANY_STATE, "fmi3SetDebugLogging");
    return (fmi3Status)fi_set_debug_logging(&in->base, loggingOn, nCategories, categories, "fmi3SetDebugLogging");
}

/* ------------------------------------------------------------ initialization */

fmi3Status fmi3EnterInitializationMode(fmi3Instance c, fmi3Boolean toleranceDefined, fmi3Float64 tolerance,
                                       fmi3Float64 startTime, fmi3Boolean stopTimeDefined, fmi3Float64 stopTime)
{
    instance *in = c;
    (void)toleranceDefined;
    (void)tolerance;
    REQUIRE(INSTANTIATED, "fmi3EnterInitializationMode");
    if (!isfinite(startTime))
        return fail(in, "fmi3EnterInitializationMode: startTime = %g must be finite", startTime);
    if (stopTimeDefined && !(stopTime >= startTime))
        return fail(in, "fmi3EnterInitializationMode: stopTime = %g must not lie before startTime = %g", stopTime,
                    startTime);
    in->base.start_time = startTime;
    in->base.stop_time = stopTimeDefined ? stopTime : INFINITY;
    in->base.state = INITIALIZATION_MODE;
    return fmi3OK;
}

/* A rejected start leaves the instance in initialization mode, so that the
 * master can correct the value and try again. */
fmi3Status fmi3ExitInitializationMode(fmi3Instance c)
{
    instance *in = c;
    fm_status status;
    REQUIRE(INITIALIZATION_MODE, "fmi3ExitInitializationMode");
#ifdef FMU_MODEL_EXCHANGE
    if (in->base.model_exchange)
        status = fm_me_start(in->base.fm, in->base.start_time, in->base.stop_time);
    else
#endif
        status = fm_start(in->base.fm, in->base.start_time, in->base.stop_time);
    if (status == FM_ERROR)
        return fmi3Error;
    in->base.state = in->event_mode_used ? EVENT_MODE : STEP_MODE;
    return (fmi3Status)status;
}

fmi3Status fmi3EnterEventMode(fmi3Instance c)
{
    instance *in = c;
    REQUIRE(SIMULATING & ~EVENT_MODE, "fmi3EnterEventMode");
    if (!in->event_mode_used)
        return fail(in, "fmi3EnterEventMode: the instance was made with eventModeUsed = false");
    in->base.state = EVENT_MODE;
    return fmi3OK;
}

/* The contact's discrete outputs (contact, eps) take their values after the
 * event; nothing else is discrete, and nothing is scheduled. */
fmi3Status fmi3UpdateDiscreteStates(fmi3Instance c, fmi3Boolean *discreteStatesNeedUpdate,
                                    fmi3Boolean *terminateSimulation, fmi3Boolean *nominalsOfContinuousStatesChanged,
                                    fmi3Boolean *valuesOfContinuousStatesChanged, fmi3Boolean *nextEventTimeDefined,
                                    fmi3Float64 *nextEventTime)
{
    instance *in = c;
    REQUIRE(EVENT_MODE, "fmi3UpdateDiscreteStates");
    if (!discreteStatesNeedUpdate || !terminateSimulation || !nominalsOfContinuousStatesChanged
        || !valuesOfContinuousStatesChanged || !nextEventTimeDefined || !nextEventTime)
        return fail(in, "fmi3UpdateDiscreteStates: an output argument is NULL");
#ifdef FMU_MODEL_EXCHANGE
    if (in->base.model_exchange)
        fm_me_event(in->base.fm);
    else
#endif
        fm_update_discrete(in->base.fm);
    *discreteStatesNeedUpdate = fmi3False;
    *terminateSimulation = fmi3False;
    *nominalsOfContinuousStatesChanged = fmi3False;
    *valuesOfContinuousStatesChanged = fmi3False;
    *nextEventTimeDefined = fmi3False;
    *nextEventTime = 0.0;
    return fmi3OK;
}

fmi3Status fmi3EnterStepMode(fmi3Instance c)
{
    instance *in = c;
    CO_SIMULATION_ONLY("fmi3EnterStepMode");
    REQUIRE(EVENT_MODE, "fmi3EnterStepMode");
    in->base.state = STEP_MODE;
    return fmi3OK;
}

fmi3Status fmi3Terminate(fmi3Instance c)
{
    instance *in = c;
    REQUIRE(SIMULATING, "fmi3Terminate");
    in->base.state = TERMINATED;
    return fmi3OK;
}

fmi3Status fmi3Reset(fmi3Instance c)
{
    instance *in = c;
    REQUIRE(ANY_STATE, "fmi3Reset");
    fv_reset(&in->base);
#ifdef FMU_MODEL_EXCHANGE
    if (in->base.model_exchange)
        fm_me_instantiated(in->base.fm);
#endif
    in->base.start_time = 0.0;
    in->base.stop_time = INFINITY;
    in->base.state = INSTANTIATED;
    return fmi3OK;
}

/* ------------------------------------------------------- getters and setters */

/* Every variable is a scalar: as many values as references. */
static int scalars(instance *in, size_t nvr, const void *vr, const void *values, size_t n_values, const char *name)
{
    if (fi_null_arrays(&in->base, nvr, vr, values, name))
        return 0;
    if (n_values != nvr) {
        fi_fail(&in->base, "%s: nValues = %lu for %lu scalar variables", name, (unsigned long)n_values,
                (unsigned long)nvr);
        return 0;
    }
    return 1;
}

static fm_status get_float64(instance *in, fmi3ValueReference vr, fmi3Float64 *value)
{
    if (vr != VR_TIME)
        return fm_get_real(in->base.fm, vr, value);
    *value = fm_time(in->base.fm);
    return FM_OK;
}

static fm_status set_float64(instance *in, fmi3ValueReference vr, fmi3Float64 value)
{
    if (vr != VR_TIME)
        return fm_set_real(in->base.fm, vr, value);
    fi_fail(&in->base, "value reference %u is the independent variable time: it cannot be set", vr);
    return FM_ERROR;
}

/* The independent variable is the glue's, not the model's: a call of
 * another type for it is refused here, as the model refuses its own. */
static int is_time(instance *in, fmi3ValueReference vr, var_type type)
{
    if (vr != VR_TIME)
        return 0;
    fi_fail(&in->base, "value reference %u is not %s variable of this FMU: it is time, %s variable", vr,
            fmu_type_names[type], fmu_type_names[VAR_REAL]);
    return 1;
}

static fm_status get_int32(instance *in, fmi3ValueReference vr, fmi3Int32 *value)
{
    int i;
    fm_status status;
    if (is_time(in, vr, VAR_INTEGER))
        return FM_ERROR;
    status = fm_get_integer(in->base.fm, vr, &i);
    *value = i;
    return status;
}

static fm_status set_int32(instance *in, fmi3ValueReference vr, fmi3Int32 value)
{
    if (is_time(in, vr, VAR_INTEGER))
        return FM_ERROR;
    return fm_set_integer(in->base.fm, vr, value);
}

static fm_status get_boolean(instance *in, fmi3ValueReference vr, fmi3Boolean *value)
{
    int b = 0;
    fm_status status;
    if (is_time(in, vr, VAR_BOOLEAN))
        return FM_ERROR;
    status = fm_get_boolean(in->base.fm, vr, &b);
    *value = b != 0;
    return status;
}

static fm_status set_boolean(instance *in, fmi3ValueReference vr, fmi3Boolean value)
{
    if (is_time(in, vr, VAR_BOOLEAN))
        return FM_ERROR;
    return fm_set_boolean(in->base.fm, vr, value);
}

#define GET_LOOP(fn, get, T)                                                                           \
    fmi3Status fn(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, T values[], size_t nValues) \
    {                                                                                                  \
        instance *in = c;                                                                              \
        size_t i;                                                                                      \
        REQUIRE(AFTER_INIT_ENTERED, #fn);                                                              \
        if (!scalars(in, nvr, vr, values, nValues, #fn))                                               \
            return fmi3Error;                                                                          \
        for (i = 0; i < nvr; i++)                                                                      \
            if (get(in, vr[i], &values[i]) != FM_OK)                                                   \
                return fmi3Error;                                                                      \
        return fmi3OK;                                                                                 \
    }

#define SET_LOOP(fn, set, T)                                                                                 \
    fmi3Status fn(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, const T values[], size_t nValues) \
    {                                                                                                        \
        instance *in = c;                                                                                    \
        size_t i;                                                                                            \
        REQUIRE(SETTABLE, #fn);                                                                              \
        if (!scalars(in, nvr, vr, values, nValues, #fn))                                                     \
            return fmi3Error;                                                                                \
        for (i = 0; i < nvr; i++)                                                                            \
            if (set(in, vr[i], values[i]) != FM_OK)                                                          \
                return fmi3Error;                                                                            \
        return fmi3OK;                                                                                       \
    }

GET_LOOP(fmi3GetFloat64, get_float64, fmi3Float64)
GET_LOOP(fmi3GetInt32, get_int32, fmi3Int32)
GET_LOOP(fmi3GetBoolean, get_boolean, fmi3Boolean)
SET_LOOP(fmi3SetFloat64, set_float64, fmi3Float64)
SET_LOOP(fmi3SetInt32, set_int32, fmi3Int32)
SET_LOOP(fmi3SetBoolean, set_boolean, fmi3Boolean)

/* The types this FMU has no variable of: every reference is an error. */
static fmi3Status no_variable(instance *in, const char *name, size_t nvr, const fmi3ValueReference vr[])
{
    if (nvr == 0)
        return fmi3OK;
    return fail(in, "%s: value reference %u: this FMU has no variable of that type", name, vr ? vr[0] : 0u);
}

#define NO_GETTER(fn, T)                                                                                 \
    fmi3Status fn(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, T values[], size_t nValues) \
    {                                                                                                    \
        instance *in = c;                                                                                \
        (void)values;                                                                                    \
        (void)nValues;                                                                                   \
        REQUIRE(AFTER_INIT_ENTERED, #fn);                                                                \
        return no_variable(in, #fn, nvr, vr);                                                            \
    }

#define NO_SETTER(fn, T)                                                                                       \
    fmi3Status fn(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, const T values[], size_t nValues) \
    {                                                                                                          \
        instance *in = c;                                                                                      \
        (void)values;                                                                                          \
        (void)nValues;                                                                                         \
        REQUIRE(SETTABLE, #fn);                                                                                \
        return no_variable(in, #fn, nvr, vr);                                                                  \
    }

NO_GETTER(fmi3GetFloat32, fmi3Float32)
NO_GETTER(fmi3GetInt8, fmi3Int8)
NO_GETTER(fmi3GetUInt8, fmi3UInt8)
NO_GETTER(fmi3GetInt16, fmi3Int16)
NO_GETTER(fmi3GetUInt16, fmi3UInt16)
NO_GETTER(fmi3GetUInt32, fmi3UInt32)
NO_GETTER(fmi3GetInt64, fmi3Int64)
NO_GETTER(fmi3GetUInt64, fmi3UInt64)
NO_GETTER(fmi3GetString, fmi3String)
NO_SETTER(fmi3SetFloat32, fmi3Float32)
NO_SETTER(fmi3SetInt8, fmi3Int8)
NO_SETTER(fmi3SetUInt8, fmi3UInt8)
NO_SETTER(fmi3SetInt16, fmi3Int16)
NO_SETTER(fmi3SetUInt16, fmi3UInt16)
NO_SETTER(fmi3SetUInt32, fmi3UInt32)
NO_SETTER(fmi3SetInt64, fmi3Int64)
NO_SETTER(fmi3SetUInt64, fmi3UInt64)
NO_SETTER(fmi3SetString, fmi3String)

fmi3Status fmi3GetBinary(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, size_t valueSizes[],
                         fmi3Binary values[], size_t nValues)
{
    instance *in = c;
    (void)valueSizes;
    (void)values;
    (void)nValues;
    REQUIRE(AFTER_INIT_ENTERED, "fmi3GetBinary");
    return no_variable(in, "fmi3GetBinary", nvr, vr);
}

fmi3Status fmi3SetBinary(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, const size_t valueSizes[],
                         const fmi3Binary values[], size_t nValues)
{
    instance *in = c;
    (void)valueSizes;
    (void)values;
    (void)nValues;
    REQUIRE(SETTABLE, "fmi3SetBinary");
    return no_variable(in, "fmi3SetBinary", nvr, vr);
}

fmi3Status fmi3GetClock(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, fmi3Clock values[])
{
    instance *in = c;
    (void)values;
    REQUIRE(AFTER_INIT_ENTERED, "fmi3GetClock");
    return no_variable(in, "fmi3GetClock", nvr, vr);
}

fmi3Status fmi3SetClock(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, const fmi3Clock values[])
{
    instance *in = c;
    (void)values;
    REQUIRE(SETTABLE, "fmi3SetClock");
    return no_variable(in, "fmi3SetClock", nvr, vr);
}

/* --------------------------------------------------------------- stepping */

/* Until the end of the step, or the first of the model's events when the
 * master may hear of it: by an early return, or by the intermediate update
 * callback (after which the step goes on when it may not return early). */
fmi3Status fmi3DoStep(fmi3Instance c, fmi3Float64 currentCommunicationPoint, fmi3Float64 communicationStepSize,
                      fmi3Boolean noSetFMUStatePriorToCurrentPoint, fmi3Boolean *eventHandlingNeeded,
                      fmi3Boolean *terminateSimulation, fmi3Boolean *earlyReturn, fmi3Float64 *lastSuccessfulTime)
{
    instance *in = c;
    const double t = currentCommunicationPoint, end = t + communicationStepSize;
    unsigned stop, options;
    double now = t;
    int event = 0;
    (void)noSetFMUStatePriorToCurrentPoint;
    CO_SIMULATION_ONLY("fmi3DoStep");
    REQUIRE(STEP_MODE, "fmi3DoStep");
    stop = in->early_return_allowed || in->intermediate_update ? FM_STOP_AT_EVENT : 0u;
    options = stop;
    if (!eventHandlingNeeded || !terminateSimulation || !earlyReturn || !lastSuccessfulTime)
        return fail(in, "fmi3DoStep: an output argument is NULL");
    *eventHandlingNeeded = *terminateSimulation = *earlyReturn = fmi3False;
    *lastSuccessfulTime = t;
    if (fi_check_step(&in->base, t, communicationStepSize, 0, "fmi3DoStep") != FI_OK)
        return fmi3Error;
    /* A step that goes on after an event inside it keeps its start: a
     * refusal of the rest takes the whole step back, as a refused step
     * changes nothing. */
    if (in->intermediate_update && !in->early_return_allowed
        && fi_get_state(&in->base, &in->step_start, "fmi3DoStep") != FI_OK)
        return fmi3Error;
    for (;;) {
        if (fm_do_step_until(in->base.fm, now, options & FM_CONTINUE ? end - now : fi_advance(t, communicationStepSize),
                             options, &event) != FM_OK) {
            if (options & FM_CONTINUE)
                fi_set_state(&in->base, in->step_start, STEP_MODE, "fmi3DoStep");
            return fmi3Error;
        }
        now = fm_time(in->base.fm);
        *lastSuccessfulTime = now;
        if (!event)
            return fmi3OK;
        if (in->intermediate_update) {
            fmi3Boolean requested = fmi3False;
            fmi3Float64 requested_time = now;
            in->intermediate_update(in->environment, now, fmi3False, fmi3False, fmi3True,
                                    in->early_return_allowed, &requested, &requested_time);
        }
        if (in->early_return_allowed || !(now < end))
            break;
        fm_update_discrete(in->base.fm); /* handled inside the step, as FMI 2.0 does */
        options = stop | FM_CONTINUE;
    }
    *earlyReturn = now < end;
    if (in->event_mode_used)
        *eventHandlingNeeded = fmi3True; /* the discrete outputs change in event mode */
    else
        fm_update_discrete(in->base.fm);
    return fmi3OK;
}

fmi3Status fmi3GetOutputDerivatives(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr,
                                    const fmi3Int32 orders[], fmi3Float64 values[], size_t nValues)
{
    instance *in = c;
    size_t i;
    CO_SIMULATION_ONLY("fmi3GetOutputDerivatives");
    REQUIRE(STEP_MODE | TERMINATED, "fmi3GetOutputDerivatives");
    if (!scalars(in, nvr, vr, values, nValues, "fmi3GetOutputDerivatives")
        || fi_null_arrays(&in->base, nvr, orders, orders, "fmi3GetOutputDerivatives"))
        return fmi3Error;
    for (i = 0; i < nvr; i++)
        if (fm_get_output_derivative(in->base.fm, vr[i], orders[i], &values[i]) != FM_OK)
            return fmi3Error;
    return fmi3OK;
}

/* ------------------------------------------------------------ FMU state */

/* the states of the instance's own interface */
#define STATE_MODES (INSTANTIATED | INITIALIZATION_MODE | SIMULATING | TERMINATED)

fmi3Status fmi3GetFMUState(fmi3Instance c, fmi3FMUState *FMUState)
{
    instance *in = c;
    REQUIRE(ANY_STATE, "fmi3GetFMUState");
    return (fmi3Status)fi_get_state(&in->base, (fi_state **)FMUState, "fmi3GetFMUState");
}

fmi3Status fmi3SetFMUState(fmi3Instance c, fmi3FMUState FMUState)
{
    instance *in = c;
    REQUIRE(ANY_STATE, "fmi3SetFMUState");
    return (fmi3Status)fi_set_state(&in->base, FMUState, STATE_MODES, "fmi3SetFMUState");
}

fmi3Status fmi3FreeFMUState(fmi3Instance c, fmi3FMUState *FMUState)
{
    instance *in = c;
    REQUIRE(ANY_STATE, "fmi3FreeFMUState");
    fi_free_state((fi_state **)FMUState);
    return fmi3OK;
}

fmi3Status fmi3SerializedFMUStateSize(fmi3Instance c, fmi3FMUState FMUState, size_t *size)
{
    instance *in = c;
    REQUIRE(ANY_STATE, "fmi3SerializedFMUStateSize");
    return (fmi3Status)fi_state_size(&in->base, FMUState, size, "fmi3SerializedFMUStateSize");
}

fmi3Status fmi3SerializeFMUState(fmi3Instance c, fmi3FMUState FMUState, fmi3Byte serializedState[], size_t size)
{
    instance *in = c;
    REQUIRE(ANY_STATE, "fmi3SerializeFMUState");
    return (fmi3Status)fi_serialize(&in->base, FMUState, serializedState, size, "fmi3SerializeFMUState");
}

fmi3Status fmi3DeserializeFMUState(fmi3Instance c, const fmi3Byte serializedState[], size_t size,
                                   fmi3FMUState *FMUState)
{
    instance *in = c;
    REQUIRE(ANY_STATE, "fmi3DeserializeFMUState");
    return (fmi3Status)fi_deserialize(&in->base, serializedState, size, (fi_state **)FMUState,
                                      "fmi3DeserializeFMUState");
}

/* ------------------------------------- capabilities this FMU does not declare */

static fmi3Status unsupported(instance *in, int states, const char *name, const char *why)
{
    REQUIRE(states, name);
    return fail(in, "%s is not supported (%s)", name, why);
}

#define NOT_DECLARED(flag) "modelDescription.xml: " flag "=\"false\""
#define NO_CLOCKS "this FMU has no clocks"
#define NOT_CO_SIMULATION "a function of model exchange or scheduled execution; this FMU is co-simulation only"

fmi3Status fmi3GetNumberOfVariableDependencies(fmi3Instance c, fmi3ValueReference valueReference,
                                               size_t *nDependencies)
{
    (void)valueReference;
    (void)nDependencies;
    return unsupported(c, ANY_STATE, "fmi3GetNumberOfVariableDependencies", NOT_DECLARED("providesPerElementDependencies"));
}

fmi3Status fmi3GetVariableDependencies(fmi3Instance c, fmi3ValueReference dependent, size_t elementIndicesOfDependent[],
                                       fmi3ValueReference independents[], size_t elementIndicesOfIndependents[],
                                       fmi3DependencyKind dependencyKinds[], size_t nDependencies)
{
    (void)dependent;
    (void)elementIndicesOfDependent;
    (void)independents;
    (void)elementIndicesOfIndependents;
    (void)dependencyKinds;
    (void)nDependencies;
    return unsupported(c, ANY_STATE, "fmi3GetVariableDependencies", NOT_DECLARED("providesPerElementDependencies"));
}

fmi3Status fmi3GetDirectionalDerivative(fmi3Instance c, const fmi3ValueReference unknowns[], size_t nUnknowns,
                                        const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[],
                                        size_t nSeed, fmi3Float64 sensitivity[], size_t nSensitivity)
{
    instance *in = c;
#ifdef FMU_MODEL_EXCHANGE
    if (in && in->base.model_exchange) { /* its ModelExchange element provides them */
        REQUIRE(AFTER_INIT_ENTERED, "fmi3GetDirectionalDerivative");
        if (fi_null_arrays(&in->base, nUnknowns, unknowns, sensitivity, "fmi3GetDirectionalDerivative")
            || fi_null_arrays(&in->base, nKnowns, knowns, seed, "fmi3GetDirectionalDerivative"))
            return fmi3Error;
        if (nSeed != nKnowns || nSensitivity != nUnknowns)
            return fail(in, "fmi3GetDirectionalDerivative: nSeed = %lu and nSensitivity = %lu must be nKnowns = %lu "
                            "and nUnknowns = %lu (every variable of this FMU is a scalar)", (unsigned long)nSeed,
                        (unsigned long)nSensitivity, (unsigned long)nKnowns, (unsigned long)nUnknowns);
        return fm_me_directional(in->base.fm, unknowns, nUnknowns, knowns, nKnowns, seed, sensitivity) == FM_OK
                   ? fmi3OK
                   : fmi3Error;
    }
#endif
    (void)unknowns;
    (void)nUnknowns;
    (void)knowns;
    (void)nKnowns;
    (void)seed;
    (void)nSeed;
    (void)sensitivity;
    (void)nSensitivity;
    return unsupported(in, AFTER_INIT_ENTERED, "fmi3GetDirectionalDerivative",
                       NOT_DECLARED("providesDirectionalDerivatives"));
}

fmi3Status fmi3GetAdjointDerivative(fmi3Instance c, const fmi3ValueReference unknowns[], size_t nUnknowns,
                                    const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[],
                                    size_t nSeed, fmi3Float64 sensitivity[], size_t nSensitivity)
{
    instance *in = c;
    (void)unknowns;
    (void)nUnknowns;
    (void)knowns;
    (void)nKnowns;
    (void)seed;
    (void)nSeed;
    (void)sensitivity;
    (void)nSensitivity;
    return unsupported(in, AFTER_INIT_ENTERED, "fmi3GetAdjointDerivative", NOT_DECLARED("providesAdjointDerivatives"));
}

fmi3Status fmi3EnterConfigurationMode(fmi3Instance c)
{
    return unsupported(c, ANY_STATE, "fmi3EnterConfigurationMode", "this FMU has no structural parameters");
}

fmi3Status fmi3ExitConfigurationMode(fmi3Instance c)
{
    return unsupported(c, ANY_STATE, "fmi3ExitConfigurationMode", "this FMU has no structural parameters");
}

fmi3Status fmi3GetIntervalDecimal(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, fmi3Float64 intervals[],
                                  fmi3IntervalQualifier qualifiers[])
{
    (void)vr;
    (void)nvr;
    (void)intervals;
    (void)qualifiers;
    return unsupported(c, ANY_STATE, "fmi3GetIntervalDecimal", NO_CLOCKS);
}

fmi3Status fmi3GetIntervalFraction(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, fmi3UInt64 counters[],
                                   fmi3UInt64 resolutions[], fmi3IntervalQualifier qualifiers[])
{
    (void)vr;
    (void)nvr;
    (void)counters;
    (void)resolutions;
    (void)qualifiers;
    return unsupported(c, ANY_STATE, "fmi3GetIntervalFraction", NO_CLOCKS);
}

fmi3Status fmi3GetShiftDecimal(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, fmi3Float64 shifts[])
{
    (void)vr;
    (void)nvr;
    (void)shifts;
    return unsupported(c, ANY_STATE, "fmi3GetShiftDecimal", NO_CLOCKS);
}

fmi3Status fmi3GetShiftFraction(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, fmi3UInt64 counters[],
                                fmi3UInt64 resolutions[])
{
    (void)vr;
    (void)nvr;
    (void)counters;
    (void)resolutions;
    return unsupported(c, ANY_STATE, "fmi3GetShiftFraction", NO_CLOCKS);
}

fmi3Status fmi3SetIntervalDecimal(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr,
                                  const fmi3Float64 intervals[])
{
    (void)vr;
    (void)nvr;
    (void)intervals;
    return unsupported(c, ANY_STATE, "fmi3SetIntervalDecimal", NO_CLOCKS);
}

fmi3Status fmi3SetIntervalFraction(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr,
                                   const fmi3UInt64 counters[], const fmi3UInt64 resolutions[])
{
    (void)vr;
    (void)nvr;
    (void)counters;
    (void)resolutions;
    return unsupported(c, ANY_STATE, "fmi3SetIntervalFraction", NO_CLOCKS);
}

fmi3Status fmi3SetShiftDecimal(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, const fmi3Float64 shifts[])
{
    (void)vr;
    (void)nvr;
    (void)shifts;
    return unsupported(c, ANY_STATE, "fmi3SetShiftDecimal", NO_CLOCKS);
}

fmi3Status fmi3SetShiftFraction(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr,
                                const fmi3UInt64 counters[], const fmi3UInt64 resolutions[])
{
    (void)vr;
    (void)nvr;
    (void)counters;
    (void)resolutions;
    return unsupported(c, ANY_STATE, "fmi3SetShiftFraction", NO_CLOCKS);
}

fmi3Status fmi3EvaluateDiscreteStates(fmi3Instance c)
{
    return unsupported(c, ANY_STATE, "fmi3EvaluateDiscreteStates", NOT_DECLARED("providesEvaluateDiscreteStates"));
}

fmi3Status fmi3ActivateModelPartition(fmi3Instance c, fmi3ValueReference clockReference, fmi3Float64 activationTime)
{
    (void)clockReference;
    (void)activationTime;
    return unsupported(c, ANY_STATE, "fmi3ActivateModelPartition", NOT_CO_SIMULATION);
}

#ifndef FMU_MODEL_EXCHANGE /* else fmi3_me.c */
fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance c)
{
    return unsupported(c, ANY_STATE, "fmi3EnterContinuousTimeMode", NOT_CO_SIMULATION);
}

fmi3Status fmi3CompletedIntegratorStep(fmi3Instance c, fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                                       fmi3Boolean *enterEventMode, fmi3Boolean *terminateSimulation)
{
    (void)noSetFMUStatePriorToCurrentPoint;
    (void)enterEventMode;
    (void)terminateSimulation;
    return unsupported(c, ANY_STATE, "fmi3CompletedIntegratorStep", NOT_CO_SIMULATION);
}

fmi3Status fmi3SetTime(fmi3Instance c, fmi3Float64 time)
{
    (void)time;
    return unsupported(c, ANY_STATE, "fmi3SetTime", NOT_CO_SIMULATION);
}

fmi3Status fmi3SetContinuousStates(fmi3Instance c, const fmi3Float64 continuousStates[], size_t nContinuousStates)
{
    (void)continuousStates;
    (void)nContinuousStates;
    return unsupported(c, ANY_STATE, "fmi3SetContinuousStates", NOT_CO_SIMULATION);
}

fmi3Status fmi3GetContinuousStateDerivatives(fmi3Instance c, fmi3Float64 derivatives[], size_t nContinuousStates)
{
    (void)derivatives;
    (void)nContinuousStates;
    return unsupported(c, ANY_STATE, "fmi3GetContinuousStateDerivatives", NOT_CO_SIMULATION);
}

fmi3Status fmi3GetEventIndicators(fmi3Instance c, fmi3Float64 eventIndicators[], size_t nEventIndicators)
{
    (void)eventIndicators;
    (void)nEventIndicators;
    return unsupported(c, ANY_STATE, "fmi3GetEventIndicators", NOT_CO_SIMULATION);
}

fmi3Status fmi3GetContinuousStates(fmi3Instance c, fmi3Float64 continuousStates[], size_t nContinuousStates)
{
    (void)continuousStates;
    (void)nContinuousStates;
    return unsupported(c, ANY_STATE, "fmi3GetContinuousStates", NOT_CO_SIMULATION);
}

fmi3Status fmi3GetNominalsOfContinuousStates(fmi3Instance c, fmi3Float64 nominals[], size_t nContinuousStates)
{
    (void)nominals;
    (void)nContinuousStates;
    return unsupported(c, ANY_STATE, "fmi3GetNominalsOfContinuousStates", NOT_CO_SIMULATION);
}

fmi3Status fmi3GetNumberOfEventIndicators(fmi3Instance c, size_t *nEventIndicators)
{
    (void)nEventIndicators;
    return unsupported(c, ANY_STATE, "fmi3GetNumberOfEventIndicators", NOT_CO_SIMULATION);
}

fmi3Status fmi3GetNumberOfContinuousStates(fmi3Instance c, size_t *nContinuousStates)
{
    (void)nContinuousStates;
    return unsupported(c, ANY_STATE, "fmi3GetNumberOfContinuousStates", NOT_CO_SIMULATION);
}
#endif
