/* FMI 2.0 co-simulation glue: instances, the call-sequence state machine,
 * logging, communication times, the FMU state, and the translation of FMI
 * calls onto a model (fmu_interface.h). It knows the standard, not the
 * physics; the FMU it serves names itself in guid.h. */
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"
#include "fmu_interface.h"
#include "guid.h"
#include "serial.h"

/* The states of FMI 2.0 §4.2.4 that this slave can be in, as bits, so that
 * each function names the set of states it may be called in. There is no
 * stepFailed, error or fatal state: a refused call changes nothing, and a
 * step that fails (fmi2Error) keeps the model at the start of the step, in
 * stepComplete, so the master may retry with a shorter step, restore a
 * state, reset, or terminate. */
enum {
    INSTANTIATED = 1 << 0,
    INITIALIZATION_MODE = 1 << 1,
    STEP_COMPLETE = 1 << 2,
    TERMINATED = 1 << 4
};

#define ANY_STATE (INSTANTIATED | INITIALIZATION_MODE | STEP_COMPLETE | TERMINATED)
#define AFTER_INIT_ENTERED (INITIALIZATION_MODE | STEP_COMPLETE | TERMINATED)
#define SETTABLE (INSTANTIATED | INITIALIZATION_MODE | STEP_COMPLETE)
#define STEPPING (STEP_COMPLETE | TERMINATED)

static const char *const log_categories[] = {"logEvents", "logCalls", "logStatusWarning", "logStatusError"};
#define N_CATEGORIES (sizeof log_categories / sizeof log_categories[0])

typedef struct {
    fmi2CallbackFunctions callbacks;
    char *name;
    int state;
    int logging_on;
    int category_on[N_CATEGORIES];
    double start_time;
    fmu_model *fm;
} instance;

/* The logger formats its message like printf: protect any '%' we pass on. */
static void send_log(const instance *in, fmi2Status status, const char *category, const char *message)
{
    char escaped[1024];
    size_t i = 0;
    for (; *message && i + 2 < sizeof escaped; message++) {
        if (*message == '%')
            escaped[i++] = '%';
        escaped[i++] = *message;
    }
    escaped[i] = '\0';
    if (in->callbacks.logger)
        in->callbacks.logger(in->callbacks.componentEnvironment, in->name, status, category, escaped);
}

static int category_index(const char *category)
{
    size_t i;
    for (i = 0; i < N_CATEGORIES; i++)
        if (strcmp(category, log_categories[i]) == 0)
            return (int)i;
    return -1;
}

/* Errors and warnings always reach the user; the other categories only when
 * the master switched them on. */
static void log_message(instance *in, fmi2Status status, const char *category, const char *message)
{
    int i = category_index(category);
    if (status == fmi2Error || status == fmi2Warning || (in->logging_on && i >= 0 && in->category_on[i]))
        send_log(in, status, category, message);
}

static void report_from_model(void *env, fm_status status, const char *category, const char *message)
{
    log_message((instance *)env, (fmi2Status)status, category, message);
}

static fmi2Status fail(instance *in, const char *message)
{
    log_message(in, fmi2Error, "logStatusError", message);
    return fmi2Error;
}

/* Whether function `name` may be called now; logs the call when asked to. */
static int allowed(instance *in, int states, const char *name)
{
    char message[160];
    if (!in)
        return 0;
    if (!(in->state & states)) {
        snprintf(message, sizeof message, "%s: illegal call sequence (not allowed in the current state)", name);
        fail(in, message);
        return 0;
    }
    log_message(in, fmi2OK, "logCalls", name);
    return 1;
}

#define REQUIRE(states, name) \
    if (!allowed(in, (states), (name))) \
        return fmi2Error

static int null_arrays(instance *in, size_t n, const void *a, const void *b, const char *name)
{
    char message[160];
    if (n > 0 && (!a || !b)) {
        snprintf(message, sizeof message, "%s: a NULL array with nvr = %lu", name, (unsigned long)n);
        fail(in, message);
        return 1;
    }
    return 0;
}

/* ---------------------------------------------------------------- instances */

const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation, const fmi2CallbackFunctions *functions,
                              fmi2Boolean visible, fmi2Boolean loggingOn)
{
    instance probe, *in;
    (void)fmuResourceLocation;
    (void)visible;
    if (!functions)
        return NULL;
    memset(&probe, 0, sizeof probe);
    probe.callbacks = *functions;
    probe.name = (char *)(instanceName ? instanceName : FMU_MODEL_IDENTIFIER);
    if (!instanceName || !*instanceName) {
        fail(&probe, "fmi2Instantiate: instanceName must be a non-empty string");
        return NULL;
    }
    if (fmuType != fmi2CoSimulation) {
        fail(&probe, "fmi2Instantiate: this FMU supports co-simulation only");
        return NULL;
    }
    if (!fmuGUID || strcmp(fmuGUID, FMU_GUID) != 0) {
        fail(&probe, "fmi2Instantiate: fmuGUID does not match modelDescription.xml (" FMU_GUID ")");
        return NULL;
    }
    in = calloc(1, sizeof *in);
    if (in) {
        in->name = malloc(strlen(instanceName) + 1);
        in->fm = fm_new(report_from_model, in);
    }
    if (!in || !in->name || !in->fm) {
        if (in) {
            free(in->name);
            fm_free(in->fm);
        }
        free(in);
        fail(&probe, "fmi2Instantiate: out of memory");
        return NULL;
    }
    strcpy(in->name, instanceName);
    in->callbacks = *functions;
    in->logging_on = loggingOn != fmi2False;
    memset(in->category_on, 1, sizeof in->category_on);
    in->state = INSTANTIATED;
    return in;
}

void fmi2FreeInstance(fmi2Component c)
{
    instance *in = c;
    if (!in)
        return;
    fm_free(in->fm);
    free(in->name);
    free(in);
}

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean loggingOn, size_t nCategories,
                               const fmi2String categories[])
{
    instance *in = c;
    size_t i;
    char message[200];
    REQUIRE(ANY_STATE, "fmi2SetDebugLogging");
    if (null_arrays(in, nCategories, categories, categories, "fmi2SetDebugLogging"))
        return fmi2Error;
    for (i = 0; i < nCategories; i++)
        if (!categories[i] || category_index(categories[i]) < 0) {
            snprintf(message, sizeof message, "fmi2SetDebugLogging: unknown log category \"%.60s\"",
                     categories[i] ? categories[i] : "(null)");
            return fail(in, message);
        }
    in->logging_on = loggingOn != fmi2False;
    if (nCategories == 0)
        memset(in->category_on, 1, sizeof in->category_on);
    else {
        memset(in->category_on, 0, sizeof in->category_on);
        for (i = 0; i < nCategories; i++)
            in->category_on[category_index(categories[i])] = 1;
    }
    return fmi2OK;
}

/* ------------------------------------------------------------ initialization */

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined, fmi2Real tolerance,
                               fmi2Real startTime, fmi2Boolean stopTimeDefined, fmi2Real stopTime)
{
    instance *in = c;
    char message[160];
    (void)toleranceDefined;
    (void)tolerance;
    (void)stopTimeDefined;
    (void)stopTime;
    REQUIRE(INSTANTIATED, "fmi2SetupExperiment");
    if (!isfinite(startTime)) {
        snprintf(message, sizeof message, "fmi2SetupExperiment: startTime = %g must be finite", startTime);
        return fail(in, message);
    }
    in->start_time = startTime;
    return fmi2OK;
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c)
{
    instance *in = c;
    REQUIRE(INSTANTIATED, "fmi2EnterInitializationMode");
    in->state = INITIALIZATION_MODE;
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
    status = fm_start(in->fm, in->start_time);
    if (status == FM_ERROR)
        return fmi2Error;
    in->state = STEP_COMPLETE;
    return (fmi2Status)status;
}

fmi2Status fmi2Terminate(fmi2Component c)
{
    instance *in = c;
    REQUIRE(STEP_COMPLETE, "fmi2Terminate");
    in->state = TERMINATED;
    return fmi2OK;
}

fmi2Status fmi2Reset(fmi2Component c)
{
    instance *in = c;
    REQUIRE(ANY_STATE, "fmi2Reset");
    fm_reset(in->fm);
    in->start_time = 0.0;
    in->state = INSTANTIATED;
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
        if (null_arrays(in, nvr, vr, value, #fn))                             \
            return fmi2Error;                                                 \
        for (i = 0; i < nvr; i++)                                             \
            if (get(in->fm, vr[i], &value[i]) != FM_OK)                      \
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
        if (null_arrays(in, nvr, vr, value, #fn))                             \
            return fmi2Error;                                                 \
        for (i = 0; i < nvr; i++)                                             \
            if (set(in->fm, vr[i], value[i]) != FM_OK)                       \
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
    char message[160];
    if (nvr == 0)
        return fmi2OK;
    snprintf(message, sizeof message, "%s: value reference %u is not a String variable of this FMU (it has none)",
             name, vr ? vr[0] : 0u);
    return fail(in, message);
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
    double now;
    char message[200];
    (void)noSetFMUStatePriorToCurrentPoint;
    REQUIRE(STEP_COMPLETE, "fmi2DoStep");
    if (!isfinite(t) || !isfinite(H) || H < 0.0) {
        snprintf(message, sizeof message,
                 "fmi2DoStep: currentCommunicationPoint = %.17g, communicationStepSize = %.17g: "
                 "both must be finite and the step size >= 0", t, H);
        return fail(in, message);
    }
    /* Masters accumulate time with rounding: a mismatch below a millionth
     * of the step is theirs, and the model takes their time. */
    now = fm_time(in->fm);
    if (fabs(t - now) > 1e-6 * H + 1e-12 * fabs(t)) {
        snprintf(message, sizeof message,
                 "fmi2DoStep: currentCommunicationPoint = %.17g does not match the FMU's time %.17g", t, now);
        return fail(in, message);
    }
    return fm_do_step(in->fm, t, H) == FM_OK ? fmi2OK : fmi2Error;
}

fmi2Status fmi2CancelStep(fmi2Component c)
{
    instance *in = c;
    REQUIRE(0, "fmi2CancelStep"); /* steps are synchronous: never in progress */
    return fmi2Error;
}

fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *value)
{
    instance *in = c;
    (void)s;
    (void)value;
    REQUIRE(STEPPING, "fmi2GetStatus");
    return fmi2Discard; /* no asynchronous step, so no pending status */
}

fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *value)
{
    instance *in = c;
    REQUIRE(STEPPING, "fmi2GetRealStatus");
    if (s != fmi2LastSuccessfulTime || !value)
        return fmi2Discard;
    *value = fm_time(in->fm);
    return fmi2OK;
}

fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *value)
{
    instance *in = c;
    (void)s;
    (void)value;
    REQUIRE(STEPPING, "fmi2GetIntegerStatus");
    return fmi2Discard;
}

fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *value)
{
    instance *in = c;
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
    REQUIRE(STEPPING, "fmi2GetStringStatus");
    return fmi2Discard;
}

/* ------------------------------------------------------------ FMU state */

/* An FMU state is its serialized bytes, so that getting, setting,
 * serializing and deserializing share one format and one set of checks:
 *   "FCST", format, CRC-32 of the GUID, payload length, CRC-32 of the payload,
 *   then the payload: the instance's mode and start time, then the model's
 *   state (fm_state_write). All integers little-endian. */
#define STATE_MAGIC "FCST"
#define STATE_FORMAT 2u
#define STATE_HEADER 20u
#define STATE_INSTANCE 12u /* mode (u32), start time (f64) */

typedef struct {
    size_t size;
    unsigned char bytes[1]; /* size bytes follow */
} fmu_state;

static size_t state_size(const instance *in)
{
    return STATE_HEADER + STATE_INSTANCE + fm_state_size(in->fm);
}

/* A state of `size` bytes: `reuse` if it has that size, else a new one
 * (and `reuse` freed). */
static fmu_state *state_of_size(fmu_state *reuse, size_t size)
{
    fmu_state *state;
    if (reuse && reuse->size == size)
        return reuse;
    state = malloc(offsetof(fmu_state, bytes) + size);
    if (state) {
        state->size = size;
        free(reuse);
    }
    return state;
}

static void write_state(const instance *in, unsigned char *b)
{
    size_t payload = state_size(in) - STATE_HEADER;
    unsigned char *p = b + STATE_HEADER;
    serial_put_u32(p, (uint32_t)in->state);
    serial_put_double(p + 4, in->start_time);
    fm_state_write(in->fm, p + STATE_INSTANCE);
    memcpy(b, STATE_MAGIC, 4);
    serial_put_u32(b + 4, STATE_FORMAT);
    serial_put_u32(b + 8, serial_crc32((const unsigned char *)FMU_GUID, strlen(FMU_GUID)));
    serial_put_u32(b + 12, (uint32_t)payload);
    serial_put_u32(b + 16, serial_crc32(p, payload));
}

/* NULL when the bytes are a whole, undamaged state of this FMU and format;
 * otherwise what is wrong with them. */
static const char *state_problem(const unsigned char *b, size_t size)
{
    size_t payload;
    if (size < STATE_HEADER || memcmp(b, STATE_MAGIC, 4) != 0)
        return "not a " FMU_MODEL_IDENTIFIER " FMU state";
    if (serial_get_u32(b + 4) != STATE_FORMAT)
        return "an FMU state of another format version";
    if (serial_get_u32(b + 8) != serial_crc32((const unsigned char *)FMU_GUID, strlen(FMU_GUID)))
        return "an FMU state of another FMU (its GUID differs)";
    payload = serial_get_u32(b + 12);
    if (payload < STATE_INSTANCE || size != STATE_HEADER + payload)
        return "an FMU state of the wrong length (truncated, or of another version)";
    if (serial_get_u32(b + 16) != serial_crc32(b + STATE_HEADER, payload))
        return "a corrupted FMU state (its checksum does not match)";
    return NULL;
}

static int valid_mode(uint32_t mode)
{
    return mode == INSTANTIATED || mode == INITIALIZATION_MODE || mode == STEP_COMPLETE || mode == TERMINATED;
}

fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *FMUstate)
{
    instance *in = c;
    fmu_state *state;
    REQUIRE(ANY_STATE, "fmi2GetFMUstate");
    if (!FMUstate)
        return fail(in, "fmi2GetFMUstate: FMUstate is NULL");
    state = state_of_size(*FMUstate, state_size(in)); /* a given state is overwritten */
    if (!state)
        return fail(in, "fmi2GetFMUstate: out of memory");
    write_state(in, state->bytes);
    *FMUstate = state;
    return fmi2OK;
}

fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate FMUstate)
{
    instance *in = c;
    const fmu_state *state = FMUstate;
    const char *problem;
    char message[200];
    uint32_t mode;
    REQUIRE(ANY_STATE, "fmi2SetFMUstate");
    if (!state)
        return fail(in, "fmi2SetFMUstate: FMUstate is NULL");
    problem = state_problem(state->bytes, state->size);
    mode = serial_get_u32(state->bytes + STATE_HEADER);
    if (!problem && !valid_mode(mode))
        problem = "an FMU state with an impossible mode";
    if (problem) {
        snprintf(message, sizeof message, "fmi2SetFMUstate: %s", problem);
        return fail(in, message);
    }
    if (fm_state_read(in->fm, state->bytes + STATE_HEADER + STATE_INSTANCE,
                      state->size - STATE_HEADER - STATE_INSTANCE) != FM_OK)
        return fmi2Error;
    in->start_time = serial_get_double(state->bytes + STATE_HEADER + 4);
    in->state = (int)mode;
    return fmi2OK;
}

fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *FMUstate)
{
    instance *in = c;
    REQUIRE(ANY_STATE, "fmi2FreeFMUstate");
    if (FMUstate) {
        free(*FMUstate);
        *FMUstate = NULL;
    }
    return fmi2OK;
}

fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate FMUstate, size_t *size)
{
    instance *in = c;
    REQUIRE(ANY_STATE, "fmi2SerializedFMUstateSize");
    if (!FMUstate || !size)
        return fail(in, "fmi2SerializedFMUstateSize: FMUstate or size is NULL");
    *size = ((const fmu_state *)FMUstate)->size;
    return fmi2OK;
}

fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate FMUstate, fmi2Byte serializedState[], size_t size)
{
    instance *in = c;
    const fmu_state *state = FMUstate;
    char message[200];
    REQUIRE(ANY_STATE, "fmi2SerializeFMUstate");
    if (!state || !serializedState)
        return fail(in, "fmi2SerializeFMUstate: FMUstate or serializedState is NULL");
    if (size < state->size) {
        snprintf(message, sizeof message, "fmi2SerializeFMUstate: size = %lu, but the state takes %lu bytes",
                 (unsigned long)size, (unsigned long)state->size);
        return fail(in, message);
    }
    memcpy(serializedState, state->bytes, state->size);
    return fmi2OK;
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte serializedState[], size_t size,
                                   fmi2FMUstate *FMUstate)
{
    instance *in = c;
    const char *problem;
    fmu_state *state;
    char message[200];
    REQUIRE(ANY_STATE, "fmi2DeSerializeFMUstate");
    if (!serializedState || !FMUstate)
        return fail(in, "fmi2DeSerializeFMUstate: serializedState or FMUstate is NULL");
    problem = state_problem((const unsigned char *)serializedState, size);
    if (problem) {
        snprintf(message, sizeof message, "fmi2DeSerializeFMUstate: %s (%lu bytes)", problem, (unsigned long)size);
        return fail(in, message);
    }
    state = state_of_size(*FMUstate, size);
    if (!state)
        return fail(in, "fmi2DeSerializeFMUstate: out of memory");
    memcpy(state->bytes, serializedState, size);
    *FMUstate = state;
    return fmi2OK;
}

/* ------------------------------------- capabilities this FMU does not declare */

static fmi2Status unsupported(instance *in, int states, const char *name, const char *flag)
{
    char message[200];
    if (!allowed(in, states, name))
        return fmi2Error;
    snprintf(message, sizeof message, "%s is not supported (modelDescription.xml: %s=\"false\")", name, flag);
    return fail(in, message);
}

fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference vUnknown_ref[],
                                        size_t nUnknown, const fmi2ValueReference vKnown_ref[],
                                        size_t nKnown, const fmi2Real dvKnown[], fmi2Real dvUnknown[])
{
    (void)vUnknown_ref;
    (void)nUnknown;
    (void)vKnown_ref;
    (void)nKnown;
    (void)dvKnown;
    (void)dvUnknown;
    return unsupported(c, AFTER_INIT_ENTERED, "fmi2GetDirectionalDerivative", "providesDirectionalDerivative");
}

fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                       const fmi2Integer order[], const fmi2Real value[])
{
    instance *in = c;
    size_t i;
    REQUIRE(SETTABLE, "fmi2SetRealInputDerivatives");
    if (null_arrays(in, nvr, vr, value, "fmi2SetRealInputDerivatives")
        || null_arrays(in, nvr, order, order, "fmi2SetRealInputDerivatives"))
        return fmi2Error;
    for (i = 0; i < nvr; i++)
        if (fm_set_input_derivative(in->fm, vr[i], order[i], value[i]) != FM_OK)
            return fmi2Error;
    return fmi2OK;
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                        const fmi2Integer order[], fmi2Real value[])
{
    instance *in = c;
    size_t i;
    REQUIRE(STEPPING, "fmi2GetRealOutputDerivatives");
    if (null_arrays(in, nvr, vr, value, "fmi2GetRealOutputDerivatives")
        || null_arrays(in, nvr, order, order, "fmi2GetRealOutputDerivatives"))
        return fmi2Error;
    for (i = 0; i < nvr; i++)
        if (fm_get_output_derivative(in->fm, vr[i], order[i], &value[i]) != FM_OK)
            return fmi2Error;
    return fmi2OK;
}
