/* FMI 2.0 co-simulation glue: instances, the call-sequence state machine,
 * logging, communication times, the FMU state, and the translation of FMI
 * calls onto a model (fmu_interface.h). It knows the standard, not the
 * physics; the FMU it serves names itself in guid.h. Where that FMU has
 * Model Exchange too (FMU_MODEL_EXCHANGE), the instances, variables and
 * FMU state here serve it as well, and fmi2_me.c has its own functions. */
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"
#include "fixed_values.h"
#include "fmi2_states.h"
#include "fmu_instance.h"
#include "fmu_vars.h"
#include "guid.h"
#ifdef FMU_MODEL_EXCHANGE
#include "fmu_me.h"
#endif

/* As FMI 2.0 §3.2.3 and §4.2.4 name them (fmi2_states.h). */
const char *const fi_state_names[FI_STATE_BITS] = {"Instantiated", "Initialization Mode", "Step Complete", NULL,
                                                   "Terminated", "Event Mode", "Continuous-Time Mode"};
const char *const fmu_type_names[3] = {"a Real", "an Integer", "a Boolean"};

/* The states after initialization of the instance `in` at hand: Model
 * Exchange's event and continuous-time modes, or co-simulation's step. */
#define RUNNING (in && in->base.model_exchange ? ME_RUNNING : STEP_COMPLETE)
#define ANY_STATE (INSTANTIATED | INITIALIZATION_MODE | RUNNING | TERMINATED)
#define AFTER_INIT_ENTERED (INITIALIZATION_MODE | RUNNING | TERMINATED)
#define SETTABLE (INSTANTIATED | INITIALIZATION_MODE | RUNNING)
#define STEPPING (STEP_COMPLETE | TERMINATED)

typedef struct {
    fmu_instance base; /* first: the common part */
    fmi2CallbackFunctions callbacks;
} instance;

/* FMI 2.0's logger formats its message like printf: protect any '%' we pass on. */
static void send_log(const fmu_instance *base, fi_status status, const char *category, const char *message)
{
    const instance *in = (const instance *)base;
    char escaped[1024];
    size_t i = 0;
    for (; *message && i + 2 < sizeof escaped; message++) {
        if (*message == '%')
            escaped[i++] = '%';
        escaped[i++] = *message;
    }
    escaped[i] = '\0';
    if (in->callbacks.logger)
        in->callbacks.logger(in->callbacks.componentEnvironment, base->name, (fmi2Status)status, category, escaped);
}

#define REQUIRE(states, name) \
    if (!in || !fi_allowed(&in->base, (states), (name))) \
        return fmi2Error

#define fail(in, ...) ((fmi2Status)fi_fail(&(in)->base, __VA_ARGS__))

/* A co-simulation function called on a Model Exchange instance. */
#define CO_SIMULATION_ONLY(name) \
    if (in && in->base.model_exchange) \
        return fail(in, "%s is a function of co-simulation: this instance was made for fmi2ModelExchange, the " \
                        "host's solver integrates it (fmi2SetTime, fmi2SetContinuousStates, fmi2GetDerivatives)", \
                    (name))

/* ---------------------------------------------------------------- instances */

const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation, const fmi2CallbackFunctions *functions,
                              fmi2Boolean visible, fmi2Boolean loggingOn)
{
    instance probe, *in;
    (void)visible;
    if (!functions)
        return NULL;
    probe.callbacks = *functions;
    fi_probe(&probe.base, instanceName, send_log);
    if (!instanceName || !*instanceName) {
        fail(&probe, "fmi2Instantiate: instanceName must be a non-empty string");
        return NULL;
    }
#ifdef FMU_MODEL_EXCHANGE
    if (fmuType != fmi2CoSimulation && fmuType != fmi2ModelExchange) {
        fail(&probe, "fmi2Instantiate: fmuType = %d: this FMU supports fmi2ModelExchange (0) and fmi2CoSimulation (1)",
             (int)fmuType);
        return NULL;
    }
#else
    if (fmuType != fmi2CoSimulation) {
        fail(&probe, "fmi2Instantiate: this FMU supports co-simulation only");
        return NULL;
    }
#endif
    if (!fmuGUID) {
        fail(&probe, "fmi2Instantiate: fmuGUID does not match modelDescription.xml (" FMU_GUID ")");
        return NULL;
    }
    in = calloc(1, sizeof *in);
    if (!in) {
        fail(&probe, "fmi2Instantiate: out of memory");
        return NULL;
    }
    in->callbacks = *functions;
    if (!fi_init(&in->base, instanceName, send_log, loggingOn != fmi2False, INSTANTIATED)) {
        free(in);
        return NULL;
    }
    if (!fv_load(&in->base, fmuResourceLocation, 1, "fmi2Instantiate", fmuGUID, "fmi2Instantiate: fmuGUID")) {
        fi_release(&in->base);
        free(in);
        return NULL;
    }
    in->base.model_exchange = fmuType == fmi2ModelExchange;
#ifdef FMU_MODEL_EXCHANGE
    if (in->base.model_exchange)
        fm_me_instantiated(in->base.fm);
#endif
    return in;
}

void fmi2FreeInstance(fmi2Component c)
{
    instance *in = c;
    if (!in)
        return;
    fi_release(&in->base);
    free(in);
}

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean loggingOn, size_t nCategories,
                               const fmi2String categories[])
{
    instance *in = c;
    REQUIRE(ANY_STATE, "fmi2SetDebugLogging");
    return (fmi2Status)fi_set_debug_logging(&in->base, loggingOn != fmi2False, nCategories, categories,
                                            "fmi2SetDebugLogging");
}

/* ------------------------------------------------------------ initialization */

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined, fmi2Real tolerance,
                               fmi2Real startTime, fmi2Boolean stopTimeDefined, fmi2Real stopTime)
{
    instance *in = c;
    (void)toleranceDefined;
    (void)tolerance;
    REQUIRE(INSTANTIATED, "fmi2SetupExperiment");
    if (!isfinite(startTime))
        return fail(in, "fmi2SetupExperiment: startTime = %g must be finite", startTime);
    if (stopTimeDefined && !(stopTime >= startTime))
        return fail(in, "fmi2SetupExperiment: stopTime = %g must not lie before startTime = %g", stopTime, startTime);
    in->base.start_time = startTime;
    in->base.stop_time = stopTimeDefined ? stopTime : INFINITY;
    return fmi2OK;
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c)
{
    instance *in = c;
    REQUIRE(INSTANTIATED, "fmi2EnterInitializationMode");
    in->base.state = INITIALIZATION_MODE;
    return fmi2OK;
}

/* A rejected start leaves the instance in initialization mode, so that the
 * master can correct the value and try again; a start with a warning (a
 * value that has no effect) goes ahead. */
fmi2Status fmi2ExitInitializationMode(fmi2Component c)
{
    instance *in = c;
    fm_status status;
    REQUIRE(INITIALIZATION_MODE, "fmi2ExitInitializationMode");
#ifdef FMU_MODEL_EXCHANGE
    if (in->base.model_exchange)
        status = fm_me_start(in->base.fm, in->base.start_time, in->base.stop_time);
    else
#endif
        status = fm_start(in->base.fm, in->base.start_time, in->base.stop_time);
    if (status == FM_ERROR)
        return fmi2Error;
    in->base.state = in->base.model_exchange ? EVENT_MODE : STEP_COMPLETE;
    return (fmi2Status)status;
}

fmi2Status fmi2Terminate(fmi2Component c)
{
    instance *in = c;
    REQUIRE(RUNNING, "fmi2Terminate");
    in->base.state = TERMINATED;
    return fmi2OK;
}

fmi2Status fmi2Reset(fmi2Component c)
{
    instance *in = c;
    REQUIRE(ANY_STATE, "fmi2Reset");
    fv_reset(&in->base);
#ifdef FMU_MODEL_EXCHANGE
    if (in->base.model_exchange)
        fm_me_instantiated(in->base.fm);
#endif
    in->base.start_time = 0.0;
    in->base.stop_time = INFINITY;
    in->base.state = INSTANTIATED;
    return fmi2OK;
}

/* ------------------------------------------------------- getters and setters */

#define GET_LOOP(fn, get, T)                                                  \
    fmi2Status fn(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, \
                  T value[])                                                  \
    {                                                                         \
        instance *in = c;                                                     \
        size_t i;                                                             \
        REQUIRE(AFTER_INIT_ENTERED, #fn);                                     \
        if (fi_null_arrays(&in->base, nvr, vr, value, #fn))                             \
            return fmi2Error;                                                 \
        for (i = 0; i < nvr; i++)                                             \
            if (get(in->base.fm, vr[i], &value[i]) != FM_OK)                      \
                return fmi2Error;                                             \
        return fmi2OK;                                                        \
    }

#define SET_LOOP(fn, set, T)                                                  \
    fmi2Status fn(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, \
                  const T value[])                                            \
    {                                                                         \
        instance *in = c;                                                     \
        size_t i;                                                             \
        REQUIRE(SETTABLE, #fn);                                               \
        if (fi_null_arrays(&in->base, nvr, vr, value, #fn))                             \
            return fmi2Error;                                                 \
        for (i = 0; i < nvr; i++)                                             \
            if (set(in->base.fm, vr[i], value[i]) != FM_OK)                       \
                return fmi2Error;                                             \
        return fmi2OK;                                                        \
    }

static fm_status get_boolean(fmu_model *fm, unsigned vr, fmi2Boolean *value)
{
    int b;
    fm_status status = fm_get_boolean(fm, vr, &b);
    *value = b ? fmi2True : fmi2False;
    return status;
}

static fm_status set_boolean(fmu_model *fm, unsigned vr, fmi2Boolean value)
{
    return fm_set_boolean(fm, vr, value != fmi2False);
}

GET_LOOP(fmi2GetReal, fm_get_real, fmi2Real)
GET_LOOP(fmi2GetInteger, fm_get_integer, fmi2Integer)
GET_LOOP(fmi2GetBoolean, get_boolean, fmi2Boolean)
SET_LOOP(fmi2SetReal, fm_set_real, fmi2Real)
SET_LOOP(fmi2SetInteger, fm_set_integer, fmi2Integer)
SET_LOOP(fmi2SetBoolean, set_boolean, fmi2Boolean)

/* No FMU of this project has a String variable: every reference is an error. */
static fmi2Status no_string(instance *in, const char *name, size_t nvr, const fmi2ValueReference vr[])
{
    if (nvr == 0)
        return fmi2OK;
    return fail(in, "%s: value reference %u is not a String variable of this FMU (it has none)", name,
                vr ? vr[0] : 0u);
}

fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2String value[])
{
    instance *in = c;
    (void)value;
    REQUIRE(AFTER_INIT_ENTERED, "fmi2GetString");
    return no_string(in, "fmi2GetString", nvr, vr);
}

fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2String value[])
{
    instance *in = c;
    (void)value;
    REQUIRE(SETTABLE, "fmi2SetString");
    return no_string(in, "fmi2SetString", nvr, vr);
}

/* --------------------------------------------------------------- stepping */

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint,
                      fmi2Real communicationStepSize, fmi2Boolean noSetFMUStatePriorToCurrentPoint)
{
    instance *in = c;
    const double t = currentCommunicationPoint, H = communicationStepSize;
    (void)noSetFMUStatePriorToCurrentPoint;
    CO_SIMULATION_ONLY("fmi2DoStep");
    REQUIRE(STEP_COMPLETE, "fmi2DoStep");
    if (fi_check_step(&in->base, t, H, 1, "fmi2DoStep") != FI_OK)
        return fmi2Error;
    return fm_do_step(in->base.fm, t, fi_advance(t, H)) == FM_OK ? fmi2OK : fmi2Error;
}

fmi2Status fmi2CancelStep(fmi2Component c)
{
    instance *in = c;
    CO_SIMULATION_ONLY("fmi2CancelStep");
    REQUIRE(0, "fmi2CancelStep"); /* steps are synchronous: never in progress */
    return fmi2Error;
}

fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *value)
{
    instance *in = c;
    (void)s;
    (void)value;
    CO_SIMULATION_ONLY("fmi2GetStatus");
    REQUIRE(STEPPING, "fmi2GetStatus");
    return fmi2Discard; /* no asynchronous step, so no pending status */
}

fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *value)
{
    instance *in = c;
    CO_SIMULATION_ONLY("fmi2GetRealStatus");
    REQUIRE(STEPPING, "fmi2GetRealStatus");
    if (s != fmi2LastSuccessfulTime || !value)
        return fmi2Discard;
    *value = fm_time(in->base.fm);
    return fmi2OK;
}

fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *value)
{
    instance *in = c;
    (void)s;
    (void)value;
    CO_SIMULATION_ONLY("fmi2GetIntegerStatus");
    REQUIRE(STEPPING, "fmi2GetIntegerStatus");
    return fmi2Discard;
}

fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *value)
{
    instance *in = c;
    CO_SIMULATION_ONLY("fmi2GetBooleanStatus");
    REQUIRE(STEPPING, "fmi2GetBooleanStatus");
    if (s != fmi2Terminated || !value)
        return fmi2Discard;
    *value = fmi2False; /* the slave never asks to end the simulation */
    return fmi2OK;
}

fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *value)
{
    instance *in = c;
    (void)s;
    (void)value;
    CO_SIMULATION_ONLY("fmi2GetStringStatus");
    REQUIRE(STEPPING, "fmi2GetStringStatus");
    return fmi2Discard;
}

/* ------------------------------------------------------------ FMU state */

fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *FMUstate)
{
    instance *in = c;
    REQUIRE(ANY_STATE, "fmi2GetFMUstate");
    return (fmi2Status)fi_get_state(&in->base, (fi_state **)FMUstate, "fmi2GetFMUstate");
}

fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate FMUstate)
{
    instance *in = c;
    REQUIRE(ANY_STATE, "fmi2SetFMUstate");
    return (fmi2Status)fi_set_state(&in->base, FMUstate, ANY_STATE, "fmi2SetFMUstate");
}

fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *FMUstate)
{
    instance *in = c;
    REQUIRE(ANY_STATE, "fmi2FreeFMUstate");
    fi_free_state((fi_state **)FMUstate);
    return fmi2OK;
}

fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate FMUstate, size_t *size)
{
    instance *in = c;
    REQUIRE(ANY_STATE, "fmi2SerializedFMUstateSize");
    return (fmi2Status)fi_state_size(&in->base, FMUstate, size, "fmi2SerializedFMUstateSize");
}

fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate FMUstate, fmi2Byte serializedState[], size_t size)
{
    instance *in = c;
    REQUIRE(ANY_STATE, "fmi2SerializeFMUstate");
    return (fmi2Status)fi_serialize(&in->base, FMUstate, (unsigned char *)serializedState, size,
                                    "fmi2SerializeFMUstate");
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte serializedState[], size_t size,
                                   fmi2FMUstate *FMUstate)
{
    instance *in = c;
    REQUIRE(ANY_STATE, "fmi2DeSerializeFMUstate");
    return (fmi2Status)fi_deserialize(&in->base, (const unsigned char *)serializedState, size,
                                      (fi_state **)FMUstate, "fmi2DeSerializeFMUstate");
}

/* ------------------------------------- capabilities this FMU does not declare */

static fmi2Status unsupported(instance *in, int states, const char *name, const char *flag)
{
    REQUIRE(states, name);
    return fail(in, "%s is not supported (modelDescription.xml: %s=\"false\")", name, flag);
}

fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference vUnknown_ref[],
                                        size_t nUnknown, const fmi2ValueReference vKnown_ref[],
                                        size_t nKnown, const fmi2Real dvKnown[], fmi2Real dvUnknown[])
{
    instance *in = c;
#ifdef FMU_MODEL_EXCHANGE
    if (in && in->base.model_exchange) { /* its ModelExchange element provides them */
        REQUIRE(AFTER_INIT_ENTERED, "fmi2GetDirectionalDerivative");
        if (fi_null_arrays(&in->base, nUnknown, vUnknown_ref, dvUnknown, "fmi2GetDirectionalDerivative")
            || fi_null_arrays(&in->base, nKnown, vKnown_ref, dvKnown, "fmi2GetDirectionalDerivative"))
            return fmi2Error;
        return fm_me_directional(in->base.fm, vUnknown_ref, nUnknown, vKnown_ref, nKnown, dvKnown, dvUnknown) == FM_OK
                   ? fmi2OK
                   : fmi2Error;
    }
#endif
    (void)vUnknown_ref;
    (void)nUnknown;
    (void)vKnown_ref;
    (void)nKnown;
    (void)dvKnown;
    (void)dvUnknown;
    return unsupported(in, AFTER_INIT_ENTERED, "fmi2GetDirectionalDerivative", "providesDirectionalDerivative");
}

fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                       const fmi2Integer order[], const fmi2Real value[])
{
    instance *in = c;
    size_t i;
    CO_SIMULATION_ONLY("fmi2SetRealInputDerivatives");
    REQUIRE(SETTABLE, "fmi2SetRealInputDerivatives");
    if (fi_null_arrays(&in->base, nvr, vr, value, "fmi2SetRealInputDerivatives")
        || fi_null_arrays(&in->base, nvr, order, order, "fmi2SetRealInputDerivatives"))
        return fmi2Error;
    for (i = 0; i < nvr; i++)
        if (fm_set_input_derivative(in->base.fm, vr[i], order[i], value[i]) != FM_OK)
            return fmi2Error;
    return fmi2OK;
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                        const fmi2Integer order[], fmi2Real value[])
{
    instance *in = c;
    size_t i;
    CO_SIMULATION_ONLY("fmi2GetRealOutputDerivatives");
    REQUIRE(STEPPING, "fmi2GetRealOutputDerivatives");
    if (fi_null_arrays(&in->base, nvr, vr, value, "fmi2GetRealOutputDerivatives")
        || fi_null_arrays(&in->base, nvr, order, order, "fmi2GetRealOutputDerivatives"))
        return fmi2Error;
    for (i = 0; i < nvr; i++)
        if (fm_get_output_derivative(in->base.fm, vr[i], order[i], &value[i]) != FM_OK)
            return fmi2Error;
    return fmi2OK;
}
