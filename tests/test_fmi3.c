/* The FMI 3.0 co-simulation glue called directly from C, as an importer
 * would: every one of the 75 functions of fmi3Functions.h in and out of
 * order, bad input, event mode, early return, the intermediate update
 * callback, the FMU state and logging. The facts it compares against are
 * independent of the glue: the FMI 2.0 FMU of the same model (loaded beside
 * it with dlopen, as an importer loads an FMU), the exact onset time of
 * free flight, and the momentum identity of a striker without gravity.
 *
 * Usage: test_fmi3 <path of the FMI 2.0 FMU's shared library> */
#define _POSIX_C_SOURCE 200809L

#ifdef _WIN32
#include <windows.h>
#else
#include <dlfcn.h>
#endif
#include <float.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "fmi2FunctionTypes.h"
#include "fmi3Functions.h"
#include "fmu_model.h" /* the value references */

/* Both FMUs' generated headers define FMU_GUID (no include guard). */
#include "fraccontact/guid.h"
static const char fmi2_guid[] = FMU_GUID;
#undef FMU_GUID
#undef FMU_MODEL_IDENTIFIER
#include "fraccontact-fmi3/guid.h"

#define H20_STEP 1e-5 /* the default experiment: 3 ms in steps of 10 us */
#define H20_STEPS 300
#define N_OUT 11
#define GAP0 1e-4   /* a gap before the contact, to see its onset inside a step */
#define V0 0.626418 /* the default striker: sqrt(2 g 0.020), */
#define M0 0.7437   /* 0.7437 kg */

static const fmi3ValueReference outputs[N_OUT] = {VR_F, VR_F_avg, VR_F_peak, VR_x, VR_x1,
                                                  VR_x2, VR_v_striker, VR_E_diss, VR_eps, VR_semi_integral,
                                                  VR_F_avg_next};

/* ------------------------------------------------------- what the FMU tells */

typedef struct {
    char message[1024];
    char category[64];
    fmi3Status status;
    int count, calls; /* messages, and those of category logCalls */
    int updates;      /* intermediate updates */
    double update_time[4];
    fmi3Boolean update_finished[4], update_early[4], update_set[4], update_get[4];
    int wrong_environment;
} recorder;

static recorder rec;

static void logger(fmi3InstanceEnvironment env, fmi3Status status, fmi3String category, fmi3String message)
{
    rec.wrong_environment += env != &rec;
    snprintf(rec.message, sizeof rec.message, "%s", message);
    snprintf(rec.category, sizeof rec.category, "%s", category);
    rec.status = status;
    rec.count++;
    rec.calls += strcmp(category, "logCalls") == 0;
}

static void intermediate_update(fmi3InstanceEnvironment env, fmi3Float64 time, fmi3Boolean set_requested,
                                fmi3Boolean get_allowed, fmi3Boolean step_finished, fmi3Boolean can_return_early,
                                fmi3Boolean *early_return_requested, fmi3Float64 *early_return_time)
{
    int k = rec.updates++;
    rec.wrong_environment += env != &rec;
    if (k < 4) {
        rec.update_time[k] = time;
        rec.update_set[k] = set_requested;
        rec.update_get[k] = get_allowed;
        rec.update_finished[k] = step_finished;
        rec.update_early[k] = can_return_early;
    }
    /* What an importer may write: the FMU must not care. */
    *early_return_requested = fmi3True;
    *early_return_time = -1.0;
}

static fmi3Instance instantiate(const char *name, fmi3Boolean event_mode, fmi3Boolean early_return,
                                fmi3IntermediateUpdateCallback update)
{
    return fmi3InstantiateCoSimulation(name, FMU_GUID, NULL, fmi3False, fmi3False, event_mode, early_return, NULL, 0,
                                       &rec, logger, update);
}

static fmi3Instance plain(const char *name)
{
    return instantiate(name, fmi3False, fmi3False, NULL);
}

static void start(fmi3Instance c)
{
    CHECK(fmi3EnterInitializationMode(c, fmi3False, 0.0, 0.0, fmi3False, 0.0) == fmi3OK, "enter: %s", rec.message);
    CHECK(fmi3ExitInitializationMode(c) == fmi3OK, "exit: %s", rec.message);
}

static double get(fmi3Instance c, fmi3ValueReference vr)
{
    double value = -1.0;
    CHECK(fmi3GetFloat64(c, &vr, 1, &value, 1) == fmi3OK, "get vr %u: %s", vr, rec.message);
    return value;
}

static int in_contact(fmi3Instance c)
{
    fmi3ValueReference vr = VR_contact;
    fmi3Boolean b = fmi3False;
    CHECK(fmi3GetBoolean(c, &vr, 1, &b, 1) == fmi3OK, "get contact: %s", rec.message);
    return b;
}

static fmi3Status set(fmi3Instance c, fmi3ValueReference vr, double value)
{
    return fmi3SetFloat64(c, &vr, 1, &value, 1);
}

/* The status is an error and the log names what it must. */
static void expect_error(fmi3Status status, const char *a, const char *b, const char *what)
{
    CHECK(status == fmi3Error, "%s: status %d", what, (int)status);
    CHECK(rec.status == fmi3Error && strstr(rec.message, a) && (!b || strstr(rec.message, b)),
          "%s: log \"%s\" should name \"%s\"%s%s", what, rec.message, a, b ? " and " : "", b ? b : "");
}

/* The status is an error and the log says exactly `message`. */
static void expect_message(fmi3Status status, const char *message, const char *what)
{
    CHECK(status == fmi3Error && rec.status == fmi3Error && strcmp(rec.message, message) == 0,
          "%s: status %d, log \"%s\", not \"%s\"", what, (int)status, rec.message, message);
}

/* The results of a DoStep. */
typedef struct {
    fmi3Status status;
    fmi3Boolean event, terminate, early;
    double last;
} step_result;

static step_result step(fmi3Instance c, double t, double H)
{
    step_result r = {fmi3Error, fmi3True, fmi3True, fmi3True, -1.0};
    r.status = fmi3DoStep(c, t, H, fmi3False, &r.event, &r.terminate, &r.early, &r.last);
    return r;
}

/* In event mode: the update, which has nothing more to do or schedule. */
static void update_discrete(fmi3Instance c)
{
    fmi3Boolean need = fmi3True, terminate = fmi3True, nominals = fmi3True, values = fmi3True, next = fmi3True;
    fmi3Float64 when = -1.0;
    CHECK(fmi3UpdateDiscreteStates(c, &need, &terminate, &nominals, &values, &next, &when) == fmi3OK,
          "update: %s", rec.message);
    CHECK(!need && !terminate && !nominals && !values && !next, "nothing more to update, nothing scheduled");
}

static void event_mode(fmi3Instance c)
{
    CHECK(fmi3EnterEventMode(c) == fmi3OK, "enter event mode: %s", rec.message);
    update_discrete(c);
}

/* A refusal names the variable and the function, in FMI 3.0's words: its
 * types (Float64, Int32) and states (Step Mode, Terminated). */
static void test_refusals_name_what_they_refuse(void)
{
    fmi3Instance c = plain("names");
    fmi3ValueReference c_vr = VR_c, law_vr = VR_law, none = 999, time_vr = 0;
    fmi3Int32 i;
    fmi3Float64 r;
    start(c);
    expect_message(fmi3GetInt32(c, &c_vr, 1, &i, 1),
                   "value reference 9 is not an Int32 variable of this FMU: it is c, a Float64 variable",
                   "an Int32 call for a Float64");
    expect_message(fmi3GetFloat64(c, &law_vr, 1, &r, 1),
                   "value reference 30 is not a Float64 variable of this FMU: it is law, an Int32 variable",
                   "a Float64 call for an Int32");
    expect_message(fmi3GetFloat64(c, &none, 1, &r, 1),
                   "value reference 999 is not a Float64 variable of this FMU: it has no variable of that reference",
                   "a reference of no variable");
    expect_message(fmi3GetInt32(c, &time_vr, 1, &i, 1),
                   "value reference 0 is not an Int32 variable of this FMU: it is time, a Float64 variable",
                   "an Int32 call for the independent variable");
    CHECK(step(c, 0.0, 1e-5).status == fmi3OK && fmi3Terminate(c) == fmi3OK, "step, terminate: %s", rec.message);
    expect_message(step(c, 1e-5, 1e-5).status,
                   "fmi3DoStep: illegal call sequence: called in state Terminated, allowed only in Step Mode",
                   "a step after terminate");
    expect_message(set(c, VR_v, 1.0),
                   "fmi3SetFloat64: illegal call sequence: called in state Terminated, allowed only in Instantiated, "
                   "Initialization Mode, Event Mode or Step Mode",
                   "an input after terminate");
    fmi3FreeInstance(c);
}

/* A communication step that does not advance time (t + H == t) changes
 * nothing: every output of an instance given such steps inside an impact
 * is that of one not given them, there and after the impact. (The G1 law
 * counts internal steps: one more changed eps by about 1e-9.) */
static void test_steps_that_do_not_advance_time(void)
{
    fmi3Instance a = plain("slivers"), b = plain("plain");
    double t = 0.0, ya[N_OUT], yb[N_OUT];
    step_result s;
    int k;
    start(a);
    start(b);
    for (k = 0; k < H20_STEPS; k++) {
        if (k == 100) {
            s = step(a, t, 5e-324);
            CHECK(s.status == fmi3OK && s.last == t && !s.early, "a step of 5e-324 s at t = %g: %s", t, rec.message);
            s = step(a, t, 1e-20);
            CHECK(s.status == fmi3OK && s.last == t && t + 1e-20 == t, "a step of 1e-20 s: %s", rec.message);
        }
        if (k == 100 || k == H20_STEPS - 1) {
            CHECK(fmi3GetFloat64(a, outputs, N_OUT, ya, N_OUT) == fmi3OK
                      && fmi3GetFloat64(b, outputs, N_OUT, yb, N_OUT) == fmi3OK,
                  "outputs");
            CHECK(memcmp(ya, yb, sizeof ya) == 0, "at t = %g the outputs are those of a run without the slivers "
                  "(eps %.17g, %.17g; x2 %.17g, %.17g)", t, ya[8], yb[8], ya[5], yb[5]);
        }
        CHECK(step(a, t, H20_STEP).status == fmi3OK && step(b, t, H20_STEP).status == fmi3OK, "step %d", k);
        t += H20_STEP;
    }
    CHECK(yb[8] > 0.5, "the impact ended: eps = %g", yb[8]);
    fmi3FreeInstance(a);
    fmi3FreeInstance(b);
}

/* ------------------------------------------------------------ instantiation */

static void test_instantiate(void)
{
    fmi3Instance c;
    fmi3ValueReference vr = VR_F;
    c = fmi3InstantiateCoSimulation("x", "{wrong}", NULL, fmi3False, fmi3False, fmi3False, fmi3False, NULL, 0, &rec,
                                    logger, NULL);
    CHECK(c == NULL && strstr(rec.message, "instantiationToken") && strstr(rec.message, FMU_GUID),
          "a wrong token is refused: %s", rec.message);
    c = fmi3InstantiateCoSimulation("x", NULL, NULL, fmi3False, fmi3False, fmi3False, fmi3False, NULL, 0, &rec,
                                    logger, NULL);
    CHECK(c == NULL && strstr(rec.message, "instantiationToken"), "no token is refused: %s", rec.message);
    c = fmi3InstantiateCoSimulation("x", fmi2_guid, NULL, fmi3False, fmi3False, fmi3False, fmi3False, NULL, 0, &rec,
                                    logger, NULL);
    CHECK(c == NULL && strstr(rec.message, "instantiationToken"), "the FMI 2.0 GUID is refused: %s", rec.message);
    c = fmi3InstantiateCoSimulation("", FMU_GUID, NULL, fmi3False, fmi3False, fmi3False, fmi3False, NULL, 0, &rec,
                                    logger, NULL);
    CHECK(c == NULL && strstr(rec.message, "instanceName"), "an empty name is refused: %s", rec.message);
    c = fmi3InstantiateCoSimulation(NULL, FMU_GUID, NULL, fmi3False, fmi3False, fmi3False, fmi3False, NULL, 0, &rec,
                                    logger, NULL);
    CHECK(c == NULL && strstr(rec.message, "instanceName"), "no name is refused: %s", rec.message);
    c = fmi3InstantiateCoSimulation("x", FMU_GUID, NULL, fmi3False, fmi3False, fmi3False, fmi3False, &vr, 1, &rec,
                                    logger, NULL);
    CHECK(c == NULL && strstr(rec.message, "nRequiredIntermediateVariables = 1"),
          "required intermediate variables are refused: %s", rec.message);
    c = fmi3InstantiateModelExchange("x", FMU_GUID, NULL, fmi3False, fmi3False, &rec, logger);
    CHECK(c != NULL, "model exchange is served beside co-simulation: %s", rec.message);
    fmi3FreeInstance(c);
    c = fmi3InstantiateScheduledExecution("x", FMU_GUID, NULL, fmi3False, fmi3False, &rec, logger, NULL, NULL, NULL);
    CHECK(c == NULL && strstr(rec.message, "fmi3InstantiateScheduledExecution"),
          "scheduled execution is refused: %s", rec.message);
    /* Without a logger nothing can be told, but nothing may crash either. */
    CHECK(fmi3InstantiateCoSimulation("x", "{wrong}", NULL, fmi3False, fmi3False, fmi3False, fmi3False, NULL, 0,
                                      NULL, NULL, NULL) == NULL, "refused without a logger");
    c = fmi3InstantiateCoSimulation("quiet", FMU_GUID, NULL, fmi3False, fmi3False, fmi3False, fmi3False, NULL, 0,
                                    NULL, NULL, NULL);
    CHECK(c != NULL && fmi3DoStep(c, 0, 1, fmi3False, NULL, NULL, NULL, NULL) == fmi3Error,
          "an instance without a logger still refuses");
    fmi3FreeInstance(c);
    CHECK(strcmp(fmi3GetVersion(), "3.0") == 0, "version %s", fmi3GetVersion());
    fmi3FreeInstance(NULL);
    CHECK(rec.wrong_environment == 0, "the logger gets the instance environment");
}

/* ------------------------------------------------------------ state machine */

/* A refused call in each state changes nothing: the next legal call works. */
static void test_state_machine(void)
{
    fmi3Instance c = instantiate("states", fmi3True, fmi3False, NULL);
    fmi3Boolean b[5];
    fmi3Float64 r = 0.0;
    fmi3ValueReference vr = VR_F;
    step_result s;

    /* Instantiated */
    s = step(c, 0.0, 1e-5);
    expect_error(s.status, "fmi3DoStep", "illegal call sequence", "step before initialization");
    expect_error(fmi3EnterEventMode(c), "fmi3EnterEventMode", "illegal call sequence", "event mode too early");
    expect_error(fmi3UpdateDiscreteStates(c, &b[0], &b[1], &b[2], &b[3], &b[4], &r), "fmi3UpdateDiscreteStates",
                 "illegal call sequence", "update too early");
    expect_error(fmi3EnterStepMode(c), "fmi3EnterStepMode", "illegal call sequence", "step mode too early");
    expect_error(fmi3ExitInitializationMode(c), "fmi3ExitInitializationMode", NULL, "exit before enter");
    expect_error(fmi3Terminate(c), "fmi3Terminate", NULL, "terminate before initialization");
    expect_error(fmi3GetFloat64(c, &vr, 1, &r, 1), "fmi3GetFloat64", "illegal call sequence", "get too early");
    expect_error(fmi3EnterInitializationMode(c, fmi3False, 0, NAN, fmi3False, 0), "startTime", "nan",
                 "a NaN start time");
    expect_error(fmi3EnterInitializationMode(c, fmi3False, 0, 1.0, fmi3True, 0.5), "stopTime = 0.5",
                 "startTime = 1", "stop before start");

    /* Initialization mode */
    CHECK(fmi3EnterInitializationMode(c, fmi3True, 1e-6, 0.0, fmi3True, 3e-3) == fmi3OK, "enter: %s", rec.message);
    expect_error(fmi3EnterInitializationMode(c, fmi3False, 0, 0, fmi3False, 0), "fmi3EnterInitializationMode",
                 "illegal call sequence", "enter twice");
    s = step(c, 0.0, 1e-5);
    expect_error(s.status, "fmi3DoStep", "illegal call sequence", "step in initialization mode");
    expect_error(fmi3EnterEventMode(c), "fmi3EnterEventMode", NULL, "event mode in initialization");
    expect_error(fmi3EnterStepMode(c), "fmi3EnterStepMode", NULL, "step mode in initialization");
    CHECK(fmi3GetFloat64(c, &vr, 1, &r, 1) == fmi3OK && r == 0.0, "outputs readable in initialization");
    CHECK(fmi3ExitInitializationMode(c) == fmi3OK, "exit: %s", rec.message);

    /* Event mode (eventModeUsed): the first mode after initialization */
    s = step(c, 0.0, 1e-5);
    expect_error(s.status, "fmi3DoStep", "illegal call sequence", "step in event mode");
    expect_error(fmi3EnterEventMode(c), "fmi3EnterEventMode", "illegal call sequence", "event mode twice");
    expect_error(fmi3ExitInitializationMode(c), "fmi3ExitInitializationMode", NULL, "exit twice");
    expect_error(fmi3UpdateDiscreteStates(c, NULL, &b[1], &b[2], &b[3], &b[4], &r), "fmi3UpdateDiscreteStates",
                 "NULL", "update with a NULL argument");
    CHECK(fmi3UpdateDiscreteStates(c, &b[0], &b[1], &b[2], &b[3], &b[4], &r) == fmi3OK, "update in event mode");
    CHECK(fmi3EnterStepMode(c) == fmi3OK, "step mode: %s", rec.message);

    /* Step mode */
    expect_error(fmi3UpdateDiscreteStates(c, &b[0], &b[1], &b[2], &b[3], &b[4], &r), "fmi3UpdateDiscreteStates",
                 "illegal call sequence", "update in step mode");
    expect_error(fmi3EnterStepMode(c), "fmi3EnterStepMode", "illegal call sequence", "step mode twice");
    s = step(c, 0.0, 1e-5);
    CHECK(s.status == fmi3OK && !s.event && !s.terminate && !s.early && s.last == 1e-5, "a step: %s", rec.message);
    CHECK(fmi3EnterEventMode(c) == fmi3OK && fmi3EnterStepMode(c) == fmi3OK, "event mode and back");
    s = step(c, 1e-5, 1e-5);
    CHECK(s.status == fmi3OK && s.last == 2e-5, "the instance steps on after event mode: %s", rec.message);
    CHECK(fmi3EnterEventMode(c) == fmi3OK && fmi3Terminate(c) == fmi3OK, "terminate from event mode");

    /* Terminated */
    s = step(c, 2e-5, 1e-5);
    expect_error(s.status, "fmi3DoStep", "illegal call sequence", "step after terminate");
    expect_error(fmi3EnterEventMode(c), "fmi3EnterEventMode", NULL, "event mode after terminate");
    expect_error(fmi3Terminate(c), "fmi3Terminate", NULL, "terminate twice");
    expect_error(set(c, VR_v, 1.0), "fmi3SetFloat64", "illegal call sequence", "an input after terminate");
    CHECK(fmi3GetFloat64(c, &vr, 1, &r, 1) == fmi3OK && r > 0.0, "outputs readable after terminate");

    /* Reset from every state, back to instantiated */
    CHECK(fmi3Reset(c) == fmi3OK, "reset after terminate");
    expect_error(fmi3GetFloat64(c, &vr, 1, &r, 1), "fmi3GetFloat64", NULL, "reset: instantiated again");
    CHECK(fmi3Reset(c) == fmi3OK, "reset when instantiated");
    CHECK(fmi3EnterInitializationMode(c, fmi3False, 0, 0, fmi3False, 0) == fmi3OK && fmi3Reset(c) == fmi3OK,
          "reset in initialization mode");
    start(c);
    CHECK(fmi3Reset(c) == fmi3OK, "reset in event mode");
    start(c);
    CHECK(fmi3EnterStepMode(c) == fmi3OK && fmi3Reset(c) == fmi3OK, "reset in step mode");
    start(c);
    CHECK(fmi3EnterStepMode(c) == fmi3OK && step(c, 0.0, 1e-5).status == fmi3OK, "a new run after resets");
    fmi3FreeInstance(c);

    /* Without event mode the instance goes straight to step mode. */
    c = plain("no events");
    start(c);
    expect_error(fmi3EnterStepMode(c), "fmi3EnterStepMode", NULL, "no event mode to leave");
    expect_error(fmi3EnterEventMode(c), "fmi3EnterEventMode", "eventModeUsed = false",
                 "event mode without eventModeUsed");
    s = step(c, 0.0, 1e-5);
    CHECK(s.status == fmi3OK && s.last == 1e-5, "steps right after initialization: %s", rec.message);
    fmi3FreeInstance(c);
}

/* ------------------------------------------------------------------ bad input */

/* Every Float64 parameter and input rejects NaN and infinities with a message
 * naming it and the value, and keeps its previous value. */
static void test_non_finite(void)
{
    static const fmi3ValueReference vrs[] = {VR_v, VR_m, VR_R, VR_E_i, VR_nu_i, VR_E_s, VR_nu_s, VR_k,
                                             VR_c, VR_dt_max, VR_g, VR_gap0, VR_spring_exponent, VR_damper_order,
                                             VR_c_alpha, VR_memory_tolerance};
    static const char *const names[] = {"v", "m", "R", "E_i", "nu_i", "E_s", "nu_s", "k",
                                        "c", "dt_max", "g", "gap0", "spring_exponent", "damper_order",
                                        "c_alpha", "memory_tolerance"};
    const double bad[] = {NAN, INFINITY, -INFINITY};
    const char *const shown[] = {"nan", "inf", "-inf"};
    fmi3Instance c = plain("non-finite");
    size_t i, j;
    CHECK(fmi3EnterInitializationMode(c, fmi3False, 0, 0, fmi3False, 0) == fmi3OK, "enter");
    for (i = 0; i < sizeof vrs / sizeof vrs[0]; i++) {
        double before = get(c, vrs[i]);
        for (j = 0; j < 3; j++) {
            char what[64];
            snprintf(what, sizeof what, "%s = %s", names[i], shown[j]);
            expect_error(set(c, vrs[i], bad[j]), names[i], shown[j], what);
        }
        CHECK(get(c, vrs[i]) == before, "%s kept its value", names[i]);
    }
    CHECK(fmi3ExitInitializationMode(c) == fmi3OK, "the defaults still start: %s", rec.message);
    fmi3FreeInstance(c);
}

static void test_out_of_range(void)
{
    struct { fmi3ValueReference vr; double value; const char *name; } reals[] = {
        {VR_c, 0.0, "c"}, {VR_c, -1.0, "c"}, {VR_k, -1.0, "k"}, {VR_R, 0.0, "R"}, {VR_R, -1e-3, "R"},
        {VR_dt_max, 5e-324, "dt_max"}, {VR_dt_max, -1e-7, "dt_max"}, {VR_m, -1.0, "m"},
        {VR_E_i, 0.0, "E_i"}, {VR_E_s, -2e9, "E_s"}, {VR_nu_i, 0.6, "nu_i"}, {VR_nu_s, -1.0, "nu_s"},
        {VR_gap0, -1e-3, "gap0"}, {VR_spring_exponent, 0.5, "spring_exponent"},
        {VR_damper_order, 1.5, "damper_order"}, {VR_c_alpha, -3e5, "c_alpha"},
        {VR_memory_tolerance, 0.5, "memory_tolerance"}};
    struct { fmi3ValueReference vr; fmi3Int32 value; const char *name; } ints[] = {
        {VR_law, 0, "law"}, {VR_law, 4, "law"}, {VR_scene, 3, "scene"}, {VR_g1_nodes, -1, "g1_nodes"},
        {VR_damper, 3, "damper"}, {VR_memory, 0, "memory"}};
    fmi3Instance c = plain("range");
    fmi3ValueReference vr, two[2] = {VR_v, VR_m};
    double value = 1.0, pair[2] = {0.5, 0.5};
    fmi3Int32 n = 1;
    fmi3Boolean b = fmi3True;
    size_t i;
    for (i = 0; i < sizeof reals / sizeof reals[0]; i++)
        expect_error(set(c, reals[i].vr, reals[i].value), reals[i].name, " = ", reals[i].name);
    for (i = 0; i < sizeof ints / sizeof ints[0]; i++)
        expect_error(fmi3SetInt32(c, &ints[i].vr, 1, &ints[i].value, 1), ints[i].name, " = ", ints[i].name);

    expect_error(set(c, VR_F, 1.0), "F is an output", NULL, "set an output");
    vr = VR_contact;
    expect_error(fmi3SetBoolean(c, &vr, 1, &b, 1), "contact is an output", NULL, "set a Boolean output");
    expect_error(set(c, 0, 1.0), "value reference 0", "independent variable", "set time");
    expect_error(set(c, 999, 1.0), "999", NULL, "unknown Float64 reference");
    vr = 999;
    expect_error(fmi3SetInt32(c, &vr, 1, &n, 1), "999", NULL, "unknown Int32 reference");
    expect_error(fmi3SetBoolean(c, &vr, 1, &b, 1), "999", NULL, "unknown Boolean reference");
    vr = VR_F; /* a Float64's reference is no Int32 */
    expect_error(fmi3SetInt32(c, &vr, 1, &n, 1), "13", NULL, "reference of the wrong type");
    expect_error(fmi3SetFloat64(c, NULL, 1, &value, 1), "fmi3SetFloat64", "NULL", "NULL references");
    vr = VR_v;
    expect_error(fmi3SetFloat64(c, &vr, 1, NULL, 1), "fmi3SetFloat64", "NULL", "NULL values");
    expect_error(fmi3SetFloat64(c, &vr, 1, &value, 2), "fmi3SetFloat64", "nValues = 2", "nValues != nvr");
    expect_error(fmi3SetFloat64(c, two, 2, pair, 1), "fmi3SetFloat64", "nValues = 1", "too few values");
    CHECK(fmi3SetFloat64(c, two, 0, NULL, 0) == fmi3OK, "no values to set");

    CHECK(fmi3EnterInitializationMode(c, fmi3False, 0, 0, fmi3False, 0) == fmi3OK, "enter");
    CHECK(get(c, VR_v) == V0, "v kept its start value through the refusals");
    CHECK(fmi3ExitInitializationMode(c) == fmi3OK, "exit");
    expect_error(set(c, VR_c, 2000.0), "c is a fixed parameter", NULL, "parameter after initialization");
    vr = VR_law;
    expect_error(fmi3SetInt32(c, &vr, 1, &n, 1), "law is a fixed parameter", NULL, "Int32 parameter after init");
    CHECK(get(c, VR_c) == 6080.0, "c unchanged");
    CHECK(set(c, VR_v, 0.5) == fmi3OK, "an input in step mode");
    fmi3FreeInstance(c);
}

/* DoStep's arguments: a refused step changes nothing. */
static void test_bad_steps(void)
{
    fmi3Instance c = plain("bad steps");
    fmi3Boolean b = fmi3False;
    fmi3Float64 last = 0.0;
    step_result s;
    double F;
    start(c);
    s = step(c, 0.0, 1e-4);
    CHECK(s.status == fmi3OK, "a step: %s", rec.message);
    F = get(c, VR_F);
    expect_error(step(c, 1e-4, 0.0).status, "communicationStepSize = 0", "> 0", "H = 0 (FMI 3.0 refuses it)");
    expect_error(step(c, 1e-4, -1e-5).status, "communicationStepSize = -1", NULL, "negative step");
    expect_error(step(c, 1e-4, NAN).status, "communicationStepSize = nan", NULL, "NaN step");
    expect_error(step(c, 1e-4, INFINITY).status, "communicationStepSize = inf", NULL, "infinite step");
    expect_error(step(c, NAN, 1e-5).status, "currentCommunicationPoint = nan", NULL, "NaN time");
    expect_error(step(c, 0.5, 1e-5).status, "currentCommunicationPoint = 0.5", "does not match", "time mismatch");
    expect_error(fmi3DoStep(c, 1e-4, 1e-5, fmi3False, NULL, &b, &b, &last), "fmi3DoStep", "NULL",
                 "NULL eventHandlingNeeded");
    expect_error(fmi3DoStep(c, 1e-4, 1e-5, fmi3False, &b, &b, &b, NULL), "fmi3DoStep", "NULL",
                 "NULL lastSuccessfulTime");
    CHECK(get(c, VR_F) == F && get(c, 0) == 1e-4, "refused steps changed nothing");
    s = step(c, 1e-4, 1e-4);
    CHECK(s.status == fmi3OK && s.last == 2e-4, "the instance is still usable: %s", rec.message);
    fmi3FreeInstance(c);
    /* The full G1 history steps on a uniform grid of dt_max: a step that
     * needs more than 1e9 of them is refused at once. */
    c = plain("uniform grid");
    {
        fmi3ValueReference vrs[] = {VR_damper, VR_memory};
        fmi3Int32 values[] = {2, 1};
        CHECK(fmi3SetInt32(c, vrs, 2, values, 2) == fmi3OK, "the full G1 history: %s", rec.message);
    }
    start(c);
    expect_error(step(c, 0.0, 1e3).status, "communicationStepSize = 1000", "at most 1048576", "endless step");
    CHECK(get(c, VR_x) == 0.0 && get(c, 0) == 0.0, "the refused step changed nothing");
    fmi3FreeInstance(c);
}

/* ----------------------------------------- the FMI 2.0 FMU, as an importer */

typedef struct {
    void *library;
    fmi2InstantiateTYPE *instantiate;
    fmi2SetupExperimentTYPE *setup;
    fmi2EnterInitializationModeTYPE *enter;
    fmi2ExitInitializationModeTYPE *exit;
    fmi2DoStepTYPE *step;
    fmi2GetRealTYPE *get_real;
    fmi2GetBooleanTYPE *get_boolean;
    fmi2GetFMUstateTYPE *get_state;
    fmi2SerializedFMUstateSizeTYPE *state_size;
    fmi2SerializeFMUstateTYPE *serialize;
    fmi2FreeFMUstateTYPE *free_state;
    fmi2FreeInstanceTYPE *free_instance;
} fmi2_fmu;

static fmi2_fmu fmi2;

/* The loader's calls, on POSIX and on Windows (where the test runs under Wine). */
#ifdef _WIN32
static void *open_library(const char *path) { return (void *)LoadLibraryA(path); }
static void *library_symbol(void *library, const char *name)
{
    FARPROC f = GetProcAddress((HMODULE)library, name);
    void *symbol;
    memcpy(&symbol, &f, sizeof symbol);
    return symbol;
}
static const char *library_error(void) { return "LoadLibrary failed"; }
static void close_library(void *library) { FreeLibrary((HMODULE)library); }
#else
static void *open_library(const char *path) { return dlopen(path, RTLD_NOW | RTLD_LOCAL); }
static void *library_symbol(void *library, const char *name) { return dlsym(library, name); }
static const char *library_error(void) { return dlerror(); }
static void close_library(void *library) { dlclose(library); }
#endif

/* The symbol's object pointer into a function pointer, without the cast that
 * ISO C does not define (POSIX and Windows guarantee the representations agree). */
static int load(void *fn, const char *name)
{
    void *symbol = library_symbol(fmi2.library, name);
    memcpy(fn, &symbol, sizeof symbol);
    CHECK(symbol != NULL, "the FMI 2.0 FMU exports %s", name);
    return symbol != NULL;
}

static int load_fmi2(const char *path)
{
    int ok = 1;
    fmi2.library = path ? open_library(path) : NULL;
    CHECK(fmi2.library != NULL, "load the FMI 2.0 FMU %s: %s", path ? path : "(no path given)",
          path ? library_error() : "usage: test_fmi3 <fraccontact.so of the FMI 2.0 FMU>");
    if (!fmi2.library)
        return 0;
    ok &= load(&fmi2.instantiate, "fmi2Instantiate");
    ok &= load(&fmi2.setup, "fmi2SetupExperiment");
    ok &= load(&fmi2.enter, "fmi2EnterInitializationMode");
    ok &= load(&fmi2.exit, "fmi2ExitInitializationMode");
    ok &= load(&fmi2.step, "fmi2DoStep");
    ok &= load(&fmi2.get_real, "fmi2GetReal");
    ok &= load(&fmi2.get_boolean, "fmi2GetBoolean");
    ok &= load(&fmi2.get_state, "fmi2GetFMUstate");
    ok &= load(&fmi2.state_size, "fmi2SerializedFMUstateSize");
    ok &= load(&fmi2.serialize, "fmi2SerializeFMUstate");
    ok &= load(&fmi2.free_state, "fmi2FreeFMUstate");
    ok &= load(&fmi2.free_instance, "fmi2FreeInstance");
    /* The two libraries keep their models apart (hidden symbols): the 2.0
     * one does not answer to fmi3 calls. */
    CHECK(library_symbol(fmi2.library, "fmi3DoStep") == NULL, "the FMI 2.0 FMU exports no fmi3 function");
    return ok;
}

static void fmi2_logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status, fmi2String category,
                        fmi2String message, ...)
{
    (void)env;
    (void)name;
    (void)status;
    (void)category;
    (void)message;
}

static const fmi2CallbackFunctions fmi2_callbacks = {fmi2_logger, calloc, free, NULL, NULL};

static fmi2Component fmi2_started(void)
{
    fmi2Component c = fmi2.instantiate("fmi2", fmi2CoSimulation, fmi2_guid, "", &fmi2_callbacks, fmi2False,
                                       fmi2False);
    CHECK(c && fmi2.setup(c, fmi2False, 0, 0, fmi2False, 0) == fmi2OK && fmi2.enter(c) == fmi2OK
              && fmi2.exit(c) == fmi2OK, "the FMI 2.0 FMU starts");
    return c;
}

/* (a) Without early return the FMI 3.0 FMU is the FMI 2.0 FMU: the same
 * model and binding under another glue, so every output at every
 * communication point of the h20 drop test agrees bit for bit. */
static void test_same_as_fmi2(void)
{
    fmi3Instance c3 = plain("h20");
    fmi2Component c2;
    double y2[N_OUT], y3[N_OUT], F_peak = 0.0;
    int i, differing = 0, contact_differs = 0, time_differs = 0;
    if (!fmi2.library)
        return;
    c2 = fmi2_started();
    start(c3);
    for (i = 0; i < H20_STEPS; i++) {
        fmi2Boolean b2 = fmi2False;
        step_result s = step(c3, i * H20_STEP, H20_STEP);
        CHECK(fmi2.step(c2, i * H20_STEP, H20_STEP, fmi2True) == fmi2OK && s.status == fmi3OK, "step %d", i);
        CHECK(fmi2.get_real(c2, outputs, N_OUT, y2) == fmi2OK, "FMI 2.0 outputs");
        CHECK(fmi3GetFloat64(c3, outputs, N_OUT, y3, N_OUT) == fmi3OK, "FMI 3.0 outputs");
        differing += memcmp(y2, y3, sizeof y2) != 0;
        fmi2.get_boolean(c2, (const fmi2ValueReference[]){VR_contact}, 1, &b2);
        contact_differs += (b2 != 0) != in_contact(c3);
        /* the model takes the master's time and adds the step */
        time_differs += s.last != get(c3, 0) || s.last != i * H20_STEP + H20_STEP;
    }
    F_peak = y3[2];
    CHECK(differing == 0 && contact_differs == 0, "%d of %d communication points differ from FMI 2.0 (contact %d)",
          differing, H20_STEPS, contact_differs);
    CHECK(time_differs == 0, "time (VR 0) is the communication point at %d points", time_differs);
    /* Not a vacuous agreement: an impact happened and ended. */
    CHECK(F_peak > 500.0 && y3[8] > 0.3 && y3[8] < 1.0 && !in_contact(c3), "h20: F_peak %g N, eps %g", F_peak,
          y3[8]);
    fmi2.free_instance(c2);
    fmi3FreeInstance(c3);
}

/* ----------------------------------------------------------- early return */


typedef struct {
    double t_onset, t_separation; /* the events' times (lastSuccessfulTime) */
    double F_peak, eps, v_end, impulse; /* impulse: sum of F_avg H over the communication steps */
    int early_returns, steps;
} run_result;

/* The drop test from a gap GAP0 over 3 ms on the 10 us grid: a master that,
 * after an early return, finishes the communication step it had asked for
 * (event mode first when the instance uses it), checking the discrete
 * outputs around each event. */
static run_result drop_from_gap(fmi3Boolean event_mode_used, fmi3Boolean early_return,
                                fmi3IntermediateUpdateCallback update)
{
    fmi3Instance c = instantiate("gap", event_mode_used, early_return, update);
    run_result r = {-1.0, -1.0, 0.0, 0.0, 0.0, 0.0, 0, 0};
    double t = 0.0;
    int i;
    CHECK(set(c, VR_gap0, GAP0) == fmi3OK, "gap0: %s", rec.message);
    start(c);
    if (event_mode_used)
        CHECK(fmi3EnterStepMode(c) == fmi3OK, "step mode");
    for (i = 0; i < H20_STEPS; i++) {
        const double end = (i + 1) * H20_STEP;
        while (t < end) {
            const int contact_before = in_contact(c);
            const double eps_before = get(c, VR_eps), H = end - t;
            step_result s = step(c, t, H);
            r.steps++;
            CHECK(s.status == fmi3OK && !s.terminate, "step at %.17g: %s", t, rec.message);
            if (s.status != fmi3OK)
                break;
            r.impulse += get(c, VR_F_avg) * (s.last - t);
            CHECK(s.early == (s.last < end), "earlyReturn %d, but lastSuccessfulTime %.17g, end %.17g", s.early,
                  s.last, end);
            CHECK(!s.early || early_return, "an early return that was not allowed");
            if (s.early)
                r.early_returns++;
            if (s.early && !event_mode_used)
                CHECK(in_contact(c) != contact_before, "(c) the discrete outputs change at once without event mode");
            if (in_contact(c) != contact_before || get(c, VR_eps) != eps_before || s.event) {
                /* an event in this step, seen now or in event mode */
                if (contact_before == 0 && r.t_onset < 0.0)
                    r.t_onset = s.last;
                else if (contact_before == 1 && r.t_separation < 0.0)
                    r.t_separation = s.last;
            }
            if (s.event) {
                CHECK(event_mode_used, "eventHandlingNeeded without eventModeUsed");
                CHECK(in_contact(c) == contact_before && get(c, VR_eps) == eps_before,
                      "the discrete outputs keep their values until event mode");
                event_mode(c);
                CHECK(in_contact(c) != contact_before, "contact changes in event mode at %.17g", s.last);
                CHECK(fmi3EnterStepMode(c) == fmi3OK, "step mode");
            }
            t = s.last;
        }
        t = end; /* the grid point, as masters count */
    }
    r.F_peak = get(c, VR_F_peak);
    r.eps = get(c, VR_eps);
    r.v_end = get(c, VR_v_striker);
    fmi3FreeInstance(c);
    return r;
}

/* A relative tolerance for quantities after `steps` internal steps that two
 * runs took with lengths differing by rounding only: each step's rounding
 * is a few ulp (4 allowed) and can be carried on by every later step. */
static double rounding_tolerance(double steps)
{
    return 4.0 * DBL_EPSILON * steps;
}

/* (b) event mode and early return; (c) early return without event mode. */
static void test_early_return(void)
{
    const double t_onset = GAP0 / V0; /* free flight without gravity */
    run_result plain_run, events, no_events;
    double internal_steps, tol;
    memset(&rec, 0, sizeof rec);
    plain_run = drop_from_gap(fmi3False, fmi3False, NULL);
    events = drop_from_gap(fmi3True, fmi3True, NULL);
    no_events = drop_from_gap(fmi3False, fmi3True, NULL);

    CHECK(plain_run.early_returns == 0 && plain_run.steps == H20_STEPS, "no early return unless allowed");
    CHECK(events.early_returns == 2 && no_events.early_returns == 2, "early returns at onset and separation: %d, %d",
          events.early_returns, no_events.early_returns);
    /* The flight to the onset is the same in all runs: x1 = -gap0 + v t over
     * 16 grid steps, each rounding x1 by an ulp of gap0 (1.4e-20 m, i.e.
     * 2.2e-20 s at V0): 64 ulp of t_onset bound it. */
    CHECK_REL(events.t_onset, t_onset, 64 * DBL_EPSILON, "onset time with event mode");
    CHECK(no_events.t_onset == events.t_onset, "onset time without event mode %.17g vs %.17g", no_events.t_onset,
          events.t_onset);
    CHECK(events.t_onset > 15 * H20_STEP && events.t_onset < 16 * H20_STEP, "the onset is inside a step");
    CHECK(events.t_separation > events.t_onset + 1e-4 && events.t_separation < 3e-3, "separation at %.17g",
          events.t_separation);
    CHECK(no_events.t_separation == events.t_separation, "the same separation with and without event mode");
    /* Splitting the communication steps at the events changes the internal
     * steps' lengths by rounding only: over the contact's internal steps of
     * dt_max = 1e-7 s, the tolerance of rounding_tolerance. */
    internal_steps = (events.t_separation - events.t_onset) / 1e-7;
    tol = rounding_tolerance(internal_steps);
    /* far below the scheme's own error at dt_max (~1e-5 relative in F_peak) */
    CHECK(tol < 1e-10, "a meaningful tolerance: %g", tol);
    printf("early return: F_peak %.3g, eps %.3g relative to the plain run; tolerance %.3g (%.0f steps)\n",
           fabs(events.F_peak / plain_run.F_peak - 1.0), fabs(events.eps / plain_run.eps - 1.0), tol,
           internal_steps);
    CHECK_REL(events.F_peak, plain_run.F_peak, tol, "F_peak with early return");
    CHECK_REL(events.eps, plain_run.eps, tol, "eps with early return");
    CHECK(events.eps > 0.3 && events.eps < 1.0, "a restitution coefficient: %g", events.eps);
    /* eps is the rebound over the impact velocity; v_striker is towards the
     * specimen, so it is negative after the rebound. */
    CHECK_REL(-events.v_end, events.eps * V0, 4 * DBL_EPSILON, "v_striker after the rebound");
    CHECK(no_events.F_peak == events.F_peak && no_events.eps == events.eps,
          "event mode only delays the discrete outputs");
}

/* The onset seen step by step: where the early return stops, what the
 * outputs show before and after event mode; then the separation. */
static void test_event_details(void)
{
    fmi3Instance c = instantiate("event details", fmi3True, fmi3True, NULL);
    step_result s;
    double t = 0.0, t_event;
    int i;
    set(c, VR_gap0, GAP0);
    start(c);
    fmi3EnterStepMode(c);
    for (i = 0; i < 15; i++) {
        s = step(c, t, H20_STEP);
        t = s.last;
        CHECK(s.status == fmi3OK && !s.early && !s.event, "free flight step %d", i);
    }
    s = step(c, t, H20_STEP);
    CHECK(s.status == fmi3OK && s.early && s.event && !s.terminate, "an early return at the onset");
    CHECK(s.last > t && s.last < t + H20_STEP, "lastSuccessfulTime %.17g inside the step", s.last);
    CHECK(get(c, 0) == s.last, "time is lastSuccessfulTime");
    CHECK(get(c, VR_x) == 0.0 && get(c, VR_F) == 0.0, "at the onset: x = %g, F = %g", get(c, VR_x), get(c, VR_F));
    CHECK_REL(get(c, VR_v_striker), V0, 0.0, "the striker arrives with v");
    CHECK(!in_contact(c) && get(c, VR_eps) == 0.0, "contact still false before event mode");
    CHECK(fmi3EnterEventMode(c) == fmi3OK && !in_contact(c), "entering event mode alone changes nothing");
    update_discrete(c);
    CHECK(in_contact(c), "contact true after the update");
    fmi3EnterStepMode(c);
    /* the rest of the communication step, then on to the separation */
    t_event = s.last;
    s = step(c, t_event, 16 * H20_STEP - t_event);
    CHECK(s.status == fmi3OK && !s.early && !s.event && s.last == 16 * H20_STEP, "the rest of the step");
    t = s.last;
    for (i = 0; i < 300 && !s.early; i++) {
        s = step(c, t, H20_STEP);
        t = s.last;
    }
    CHECK(s.early && s.event && in_contact(c) && get(c, VR_eps) == 0.0,
          "at the separation: early return, contact and eps held (eps %g)", get(c, VR_eps));
    CHECK(get(c, VR_F) == 0.0 && get(c, VR_x1) == 0.0, "the force is 0 at the separation: %g", get(c, VR_F));
    event_mode(c);
    CHECK(!in_contact(c) && get(c, VR_eps) > 0.3 && get(c, VR_eps) < 1.0, "eps after the update: %g",
          get(c, VR_eps));
    fmi3FreeInstance(c);
}

/* (d) The intermediate update callback, with and without early return. */
static void test_intermediate_update(void)
{
    run_result events, called, called_early;
    double internal_steps, tol;
    int k;
    events = drop_from_gap(fmi3True, fmi3True, NULL);

    memset(&rec, 0, sizeof rec);
    called = drop_from_gap(fmi3False, fmi3False, intermediate_update);
    CHECK(rec.updates == 2, "one update at the onset, one at the separation: %d", rec.updates);
    CHECK(called.early_returns == 0 && called.steps == H20_STEPS, "the steps went on to their ends");
    CHECK(rec.update_time[0] == events.t_onset, "update at the onset %.17g vs %.17g", rec.update_time[0],
          events.t_onset);
    internal_steps = (events.t_separation - events.t_onset) / 1e-7;
    tol = rounding_tolerance(internal_steps);
    CHECK_REL(rec.update_time[1], events.t_separation, tol, "update at the separation");
    for (k = 0; k < 2; k++)
        CHECK(rec.update_finished[k] && !rec.update_early[k] && !rec.update_set[k] && !rec.update_get[k],
              "update %d: intermediateStepFinished, canReturnEarly = earlyReturnAllowed = false", k);
    CHECK_REL(called.F_peak, events.F_peak, tol, "F_peak with the callback");
    CHECK_REL(called.eps, events.eps, tol, "eps with the callback");
    /* F_avg covers the whole communication step, both sides of an event:
     * the impulses add up to the striker's change of momentum (g = 0).
     * Rounding: the model's own steps (velocity and impulse each rounded)
     * and the master's sum of 300 terms. */
    CHECK_REL(called.impulse, M0 * (V0 - called.v_end), rounding_tolerance(internal_steps + H20_STEPS),
              "sum of F_avg H against m (v0 - v)");
    CHECK(called.impulse > M0 * V0, "a rebound: more than the impact's momentum");

    memset(&rec, 0, sizeof rec);
    called_early = drop_from_gap(fmi3False, fmi3True, intermediate_update);
    CHECK(rec.updates == 2 && rec.update_early[0] && rec.update_early[1] && rec.update_finished[0],
          "with early return allowed canReturnEarly is true (%d updates)", rec.updates);
    CHECK(called_early.early_returns == 2 && rec.update_time[0] == called_early.t_onset
              && rec.update_time[1] == called_early.t_separation, "the callback's times are the early returns'");
    CHECK_REL(called_early.impulse, M0 * (V0 - called_early.v_end), rounding_tolerance(internal_steps + H20_STEPS),
              "momentum with early returns");

    /* Event mode with the callback but no early return: the events are
     * handled inside the step, no event mode needed. */
    memset(&rec, 0, sizeof rec);
    called = drop_from_gap(fmi3True, fmi3False, intermediate_update);
    CHECK(rec.updates == 2 && called.early_returns == 0 && called.eps == events.eps,
          "event mode, callback, no early return: %d updates", rec.updates);
    CHECK(rec.wrong_environment == 0, "the callback gets the instance environment");
}

/* ------------------------------------------------- the Jacobi coupling */

/* The drop test from GAP0 in the driven scene under a Jacobi master with
 * the coupling for it (coupling = 2): the master's striker (integrated here,
 * the force held over each step, exact) receives F_avg_next, read before
 * the step, over the part of the step the FMU took; with early return it
 * goes on from lastSuccessfulTime. r.impulse: what the striker received. */
static run_result jacobi_from_gap(fmi3Boolean early_return, fmi3IntermediateUpdateCallback update)
{
    fmi3Instance c = instantiate("jacobi", fmi3False, early_return, update);
    const fmi3ValueReference ints[2] = {VR_scene, VR_coupling};
    const fmi3Int32 values[2] = {2, 2};
    run_result r = {-1.0, -1.0, 0.0, 0.0, 0.0, 0.0, 0, 0};
    double t = 0.0, v = V0;
    int i;
    CHECK(set(c, VR_gap0, GAP0) == fmi3OK && fmi3SetInt32(c, ints, 2, values, 2) == fmi3OK, "driven, coupling 2: %s",
          rec.message);
    start(c);
    for (i = 0; i < H20_STEPS; i++) {
        const double end = (i + 1) * H20_STEP;
        while (t < end) {
            const double F_next = get(c, VR_F_avg_next);
            step_result s;
            set(c, VR_v, v);
            s = step(c, t, end - t);
            r.steps++;
            CHECK(s.status == fmi3OK, "step at %.17g: %s", t, rec.message);
            if (s.status != fmi3OK)
                break;
            r.early_returns += s.early;
            v -= F_next * (s.last - t) / M0;
            r.impulse += F_next * (s.last - t);
            t = s.last;
        }
        t = end;
    }
    r.F_peak = get(c, VR_F_peak);
    r.eps = get(c, VR_eps);
    r.v_end = v;
    CHECK_REL(v, get(c, VR_v_striker), rounding_tolerance(1e4), "the master's striker ends as the proxy");
    fmi3FreeInstance(c);
    return r;
}

/* F_avg_next under every way FMI 3.0 steps: whole steps, the intermediate
 * update at both events inside a step that goes on (the force the master
 * applies over the step is the one read before it), and early return at
 * both (the master applies it up to lastSuccessfulTime): each is the FMU's
 * own drop test, to the rounding of splitting steps at the events. */
static void test_jacobi_coupling(void)
{
    run_result own = drop_from_gap(fmi3False, fmi3False, NULL), runs[3];
    const char *names[3] = {"whole steps", "intermediate update", "early return"};
    double tol = rounding_tolerance(1.4e-3 / 1e-7);
    int k;
    memset(&rec, 0, sizeof rec);
    runs[0] = jacobi_from_gap(fmi3False, NULL);
    runs[1] = jacobi_from_gap(fmi3False, intermediate_update);
    CHECK(rec.updates == 2, "the intermediate update at onset and separation: %d", rec.updates);
    runs[2] = jacobi_from_gap(fmi3True, NULL);
    CHECK(runs[0].early_returns == 0 && runs[1].early_returns == 0 && runs[2].early_returns == 2,
          "early returns: %d, %d, %d", runs[0].early_returns, runs[1].early_returns, runs[2].early_returns);
    for (k = 0; k < 3; k++) {
        char what[4][96];
        snprintf(what[0], sizeof what[0], "Jacobi, %s: F_peak", names[k]);
        snprintf(what[1], sizeof what[1], "Jacobi, %s: eps", names[k]);
        snprintf(what[2], sizeof what[2], "Jacobi, %s: the master's striker rebounds", names[k]);
        snprintf(what[3], sizeof what[3], "Jacobi, %s: the impulse received is the momentum", names[k]);
        CHECK_REL(runs[k].F_peak, own.F_peak, tol, what[0]);
        CHECK_REL(runs[k].eps, own.eps, tol, what[1]);
        CHECK_REL(-runs[k].v_end, own.eps * V0, tol, what[2]);
        CHECK_REL(runs[k].impulse, M0 * (V0 - runs[k].v_end), rounding_tolerance(H20_STEPS), what[3]);
    }
}

/* ------------------------------------------------------------- FMU state */

static size_t state_bytes(fmi3Instance c, fmi3FMUState state, fmi3Byte *bytes, size_t capacity)
{
    size_t size = 0;
    CHECK(fmi3SerializedFMUStateSize(c, state, &size) == fmi3OK && size > 0 && size <= capacity, "state size %lu",
          (unsigned long)size);
    if (size > capacity)
        return 0;
    CHECK(fmi3SerializeFMUState(c, state, bytes, size) == fmi3OK, "serialize: %s", rec.message);
    return size;
}

/* From event mode (entered): the update, step mode, and n steps on the
 * grid; the outputs then, and the time reached. */
static double continue_run(fmi3Instance c, double t, int n, double y[N_OUT])
{
    int i;
    update_discrete(c);
    CHECK(fmi3EnterStepMode(c) == fmi3OK, "leave event mode: %s", rec.message);
    for (i = 0; i < n; i++) {
        step_result s = step(c, t, H20_STEP);
        CHECK(s.status == fmi3OK, "step at %g: %s", t, rec.message);
        t = s.last;
    }
    fmi3GetFloat64(c, outputs, N_OUT, y, N_OUT);
    return t;
}

static void test_fmu_state(void)
{
    fmi3Instance c = instantiate("state", fmi3True, fmi3True, NULL);
    fmi3Instance other = instantiate("other", fmi3True, fmi3True, NULL);
    fmi3FMUState state = NULL, copy = NULL, foreign = NULL;
    static fmi3Byte bytes[8192], again[8192], bad[8192];
    double y1[N_OUT], y2[N_OUT], held[N_OUT], t = 0.0, t_after;
    size_t size, size2;
    int i;
    step_result s = {fmi3OK, 0, 0, 0, 0.0};
    set(c, VR_gap0, GAP0);
    start(c);
    fmi3EnterStepMode(c);
    /* Past the onset and 2 steps into the contact, then to the peak's
     * neighbourhood with early returns at the events. */
    for (i = 0; i < 30; i++) {
        s = step(c, t, (i + 1) * H20_STEP - t);
        if (s.event) {
            event_mode(c);
            fmi3EnterStepMode(c);
        }
        t = s.last;
    }
    CHECK(in_contact(c) && get(c, VR_F) > 0.0, "mid-contact at %g s", t);

    /* Mid-contact in step mode: a round trip through bytes, bit for bit. */
    CHECK(fmi3GetFMUState(c, &state) == fmi3OK, "get state: %s", rec.message);
    size = state_bytes(c, state, bytes, sizeof bytes);
    CHECK(fmi3SerializeFMUState(c, state, again, size - 1) == fmi3Error, "too small a buffer");
    fmi3GetFloat64(c, outputs, N_OUT, y1, N_OUT);
    for (i = 0; i < 5; i++)
        step(c, t + i * H20_STEP, H20_STEP);
    CHECK(fmi3FreeFMUState(c, &state) == fmi3OK && state == NULL, "free state");
    CHECK(fmi3DeserializeFMUState(c, bytes, size, &state) == fmi3OK, "deserialize: %s", rec.message);
    CHECK(fmi3SetFMUState(c, state) == fmi3OK, "set state: %s", rec.message);
    fmi3GetFloat64(c, outputs, N_OUT, y2, N_OUT);
    CHECK(memcmp(y1, y2, sizeof y1) == 0 && get(c, 0) == t, "the outputs at the state, bit for bit");
    CHECK(fmi3GetFMUState(c, &copy) == fmi3OK && state_bytes(c, copy, again, sizeof again) == size
              && memcmp(bytes, again, size) == 0, "the state of a restored instance is the state, byte for byte");
    fmi3FreeFMUState(c, &copy);
    fmi3FreeFMUState(c, &state);

    /* In event mode at the separation: the held outputs and the mode return. */
    for (i = 0; i < 300 && !s.event; i++) {
        s = step(c, t, H20_STEP);
        t = s.last;
    }
    CHECK(s.event && in_contact(c) && get(c, VR_eps) == 0.0, "separation reached with held outputs");
    CHECK(fmi3EnterEventMode(c) == fmi3OK && fmi3GetFMUState(c, &state) == fmi3OK, "a state in event mode");
    size = state_bytes(c, state, bytes, sizeof bytes);
    fmi3GetFloat64(c, outputs, N_OUT, held, N_OUT);
    continue_run(c, t, 10, y1);
    CHECK(fmi3DeserializeFMUState(c, bytes, size, &copy) == fmi3OK && fmi3SetFMUState(c, copy) == fmi3OK,
          "back to event mode: %s", rec.message);
    fmi3GetFloat64(c, outputs, N_OUT, y2, N_OUT);
    CHECK(memcmp(held, y2, sizeof y2) == 0 && in_contact(c), "the held outputs are back");
    expect_error(step(c, t, H20_STEP).status, "fmi3DoStep", "illegal call sequence", "the state's mode is back");
    t_after = continue_run(c, t, 10, y2);
    CHECK(memcmp(y1, y2, sizeof y1) == 0, "the run from a restored event mode repeats, bit for bit");
    fmi3FreeFMUState(c, &copy);

    /* Another instance takes it, and continues the same way. */
    start(other); /* in event mode, with the defaults */
    CHECK(fmi3SetFMUState(other, state) == fmi3OK, "another instance takes the state: %s", rec.message);
    continue_run(other, t, 10, y2);
    CHECK(memcmp(y1, y2, sizeof y1) == 0, "... and continues bit for bit");

    /* Damaged and foreign states are refused, and change nothing. */
    fmi3GetFloat64(c, outputs, N_OUT, y1, N_OUT);
    memcpy(bad, bytes, size);
    bad[size - 3] ^= 0x10;
    expect_error(fmi3DeserializeFMUState(c, bad, size, &copy), "fmi3DeserializeFMUState", "checksum",
                 "a corrupted state");
    expect_error(fmi3DeserializeFMUState(c, bytes, size - 8, &copy), "fmi3DeserializeFMUState", "length",
                 "a truncated state");
    expect_error(fmi3DeserializeFMUState(c, bytes, 10, &copy), "fmi3DeserializeFMUState", "not a", "a stub");
    memcpy(bad, bytes, size);
    bad[0] = 'X';
    expect_error(fmi3DeserializeFMUState(c, bad, size, &copy), "fmi3DeserializeFMUState", "not a",
                 "a wrong magic");
    expect_error(fmi3DeserializeFMUState(c, NULL, size, &copy), "fmi3DeserializeFMUState", "NULL", "NULL bytes");
    expect_error(fmi3SetFMUState(c, NULL), "fmi3SetFMUState", "NULL", "a NULL state");
    expect_error(fmi3GetFMUState(c, NULL), "fmi3GetFMUState", "NULL", "a NULL state pointer");
    expect_error(fmi3SerializedFMUStateSize(c, state, NULL), "fmi3SerializedFMUStateSize", "NULL", "NULL size");
    if (fmi2.library) {
        fmi2Component c2 = fmi2_started();
        fmi2FMUstate s2 = NULL;
        size2 = 0;
        CHECK(fmi2.step(c2, 0.0, 2e-4, fmi2True) == fmi2OK && fmi2.get_state(c2, &s2) == fmi2OK
                  && fmi2.state_size(c2, s2, &size2) == fmi2OK && size2 <= sizeof bad
                  && fmi2.serialize(c2, s2, (fmi2Byte *)bad, size2) == fmi2OK, "an FMI 2.0 state");
        expect_error(fmi3DeserializeFMUState(c, bad, size2, &foreign), "fmi3DeserializeFMUState", "another FMU",
                     "the FMI 2.0 FMU's state");
        /* The same bytes as an fmi3FMUState object: the checks are the
         * setter's too. */
        CHECK(foreign == NULL, "no state made from foreign bytes");
        fmi2.free_state(c2, &s2);
        fmi2.free_instance(c2);
    }
    fmi3GetFloat64(c, outputs, N_OUT, y2, N_OUT);
    CHECK(memcmp(y1, y2, sizeof y1) == 0, "refused states changed nothing");
    CHECK(fmi3FreeFMUState(c, &state) == fmi3OK && fmi3FreeFMUState(c, &state) == fmi3OK, "free twice is harmless");
    CHECK(step(c, t_after, H20_STEP).status == fmi3OK, "still usable: %s", rec.message);
    fmi3FreeInstance(c);
    fmi3FreeInstance(other);
}

/* ---------------------------------------------------------------- logging */

static void test_logging(void)
{
    fmi3Instance c = plain("logging");
    const fmi3String calls[] = {"logCalls"}, events[] = {"logEvents"}, unknown[] = {"logEverything"};
    fmi3ValueReference vr = VR_F;
    double F;
    int before;
    memset(&rec, 0, sizeof rec);
    expect_error(fmi3SetDebugLogging(c, fmi3True, 1, unknown), "fmi3SetDebugLogging", "logEverything",
                 "an unknown category");
    expect_error(fmi3SetDebugLogging(c, fmi3True, 1, NULL), "fmi3SetDebugLogging", "NULL", "NULL categories");
    start(c);
    fmi3GetFloat64(c, &vr, 1, &F, 1);
    CHECK(rec.calls == 0, "no logCalls while logging is off (%d)", rec.calls);

    CHECK(fmi3SetDebugLogging(c, fmi3True, 1, calls) == fmi3OK, "logCalls on");
    before = rec.calls;
    fmi3GetFloat64(c, &vr, 1, &F, 1);
    CHECK(rec.calls == before + 1 && strcmp(rec.message, "fmi3GetFloat64") == 0, "a call is logged: %s",
          rec.message);
    before = rec.count;
    step(c, 0.0, 3e-3);
    CHECK(rec.count == before + 1 && strcmp(rec.category, "logCalls") == 0,
          "only logCalls: no logEvents message (%d messages, last %s)", rec.count - before, rec.message);
    expect_error(fmi3EnterEventMode(c), "fmi3EnterEventMode", NULL, "errors are logged in logStatusError");
    CHECK(strcmp(rec.category, "logStatusError") == 0, "category %s", rec.category);

    CHECK(fmi3SetDebugLogging(c, fmi3True, 1, events) == fmi3OK, "logEvents only");
    before = rec.calls;
    fmi3Reset(c);
    start(c);
    step(c, 0.0, 3e-3);
    CHECK(rec.calls == before && strstr(rec.message, "impact 1 ended"), "event log: %s", rec.message);

    CHECK(fmi3SetDebugLogging(c, fmi3False, 0, NULL) == fmi3OK, "logging off");
    before = rec.count;
    fmi3GetFloat64(c, &vr, 1, &F, 1);
    CHECK(rec.count == before, "nothing logged when off");
    expect_error(set(c, VR_c, 1.0), "c is a fixed parameter", NULL, "errors are logged when off");
    fmi3FreeInstance(c);

    /* loggingOn at instantiation switches every category on. */
    c = fmi3InstantiateCoSimulation("loud", FMU_GUID, NULL, fmi3False, fmi3True, fmi3False, fmi3False, NULL, 0, &rec,
                                    logger, NULL);
    before = rec.calls;
    start(c);
    CHECK(rec.calls == before + 2, "loggingOn logs the calls (%d)", rec.calls - before);
    fmi3FreeInstance(c);
}

/* ---------------------------------------------------- every other function */

/* The functions of capabilities this FMU does not declare (each refused with
 * a message naming it), the getters and setters of types it has no variable
 * of, and every function without an instance. */
static void test_unsupported(void)
{
    fmi3Instance c = plain("unsupported");
    fmi3ValueReference vr = VR_F, vr_v = VR_v;
    fmi3Float64 r[2] = {0.0, 0.0};
    fmi3UInt64 u[2] = {0, 0};
    fmi3IntervalQualifier q = fmi3IntervalNotYetKnown;
    fmi3Boolean b = fmi3False;
    size_t n = 0, idx = 0;
    fmi3DependencyKind kind;
    fmi3Int8 i8 = 0;
    fmi3UInt8 u8 = 0;
    fmi3Int16 i16 = 0;
    fmi3UInt16 u16 = 0;
    fmi3Int32 i32 = 0, order = 1;
    fmi3UInt32 u32 = 0;
    fmi3Int64 i64 = 0;
    fmi3UInt64 u64 = 0;
    fmi3Float32 f32 = 0.0f;
    fmi3String str = "x";
    fmi3Binary bin = NULL;
    fmi3Clock clk = fmi3ClockInactive;
    size_t bin_size = 0;
    fmi3FMUState state = NULL;
    fmi3Byte bytes[16];
    start(c);
#define REFUSED(call, name) expect_error((call), name, "not supported", name)
    REFUSED(fmi3EnterConfigurationMode(c), "fmi3EnterConfigurationMode");
    REFUSED(fmi3ExitConfigurationMode(c), "fmi3ExitConfigurationMode");
    REFUSED(fmi3GetNumberOfVariableDependencies(c, vr, &n), "fmi3GetNumberOfVariableDependencies");
    REFUSED(fmi3GetVariableDependencies(c, vr, &idx, &vr_v, &idx, &kind, 1), "fmi3GetVariableDependencies");
    REFUSED(fmi3GetDirectionalDerivative(c, &vr, 1, &vr_v, 1, r, 1, r + 1, 1), "fmi3GetDirectionalDerivative");
    REFUSED(fmi3GetAdjointDerivative(c, &vr, 1, &vr_v, 1, r, 1, r + 1, 1), "fmi3GetAdjointDerivative");
    REFUSED(fmi3GetIntervalDecimal(c, &vr, 1, r, &q), "fmi3GetIntervalDecimal");
    REFUSED(fmi3GetIntervalFraction(c, &vr, 1, u, u + 1, &q), "fmi3GetIntervalFraction");
    REFUSED(fmi3GetShiftDecimal(c, &vr, 1, r), "fmi3GetShiftDecimal");
    REFUSED(fmi3GetShiftFraction(c, &vr, 1, u, u + 1), "fmi3GetShiftFraction");
    REFUSED(fmi3SetIntervalDecimal(c, &vr, 1, r), "fmi3SetIntervalDecimal");
    REFUSED(fmi3SetIntervalFraction(c, &vr, 1, u, u + 1), "fmi3SetIntervalFraction");
    REFUSED(fmi3SetShiftDecimal(c, &vr, 1, r), "fmi3SetShiftDecimal");
    REFUSED(fmi3SetShiftFraction(c, &vr, 1, u, u + 1), "fmi3SetShiftFraction");
    REFUSED(fmi3EvaluateDiscreteStates(c), "fmi3EvaluateDiscreteStates");
    REFUSED(fmi3ActivateModelPartition(c, vr, 0.0), "fmi3ActivateModelPartition");
    REFUSED(fmi3EnterContinuousTimeMode(c), "fmi3EnterContinuousTimeMode");
    REFUSED(fmi3CompletedIntegratorStep(c, fmi3True, &b, &b), "fmi3CompletedIntegratorStep");
    REFUSED(fmi3SetTime(c, 0.0), "fmi3SetTime");
    REFUSED(fmi3SetContinuousStates(c, r, 1), "fmi3SetContinuousStates");
    REFUSED(fmi3GetContinuousStateDerivatives(c, r, 1), "fmi3GetContinuousStateDerivatives");
    REFUSED(fmi3GetEventIndicators(c, r, 1), "fmi3GetEventIndicators");
    REFUSED(fmi3GetContinuousStates(c, r, 1), "fmi3GetContinuousStates");
    REFUSED(fmi3GetNominalsOfContinuousStates(c, r, 1), "fmi3GetNominalsOfContinuousStates");
    REFUSED(fmi3GetNumberOfEventIndicators(c, &n), "fmi3GetNumberOfEventIndicators");
    REFUSED(fmi3GetNumberOfContinuousStates(c, &n), "fmi3GetNumberOfContinuousStates");
#undef REFUSED

#define NO_TYPE(call, name)                                                                              \
    expect_error((call), name, "no variable of that type", name)
    NO_TYPE(fmi3GetFloat32(c, &vr, 1, &f32, 1), "fmi3GetFloat32");
    NO_TYPE(fmi3GetInt8(c, &vr, 1, &i8, 1), "fmi3GetInt8");
    NO_TYPE(fmi3GetUInt8(c, &vr, 1, &u8, 1), "fmi3GetUInt8");
    NO_TYPE(fmi3GetInt16(c, &vr, 1, &i16, 1), "fmi3GetInt16");
    NO_TYPE(fmi3GetUInt16(c, &vr, 1, &u16, 1), "fmi3GetUInt16");
    NO_TYPE(fmi3GetUInt32(c, &vr, 1, &u32, 1), "fmi3GetUInt32");
    NO_TYPE(fmi3GetInt64(c, &vr, 1, &i64, 1), "fmi3GetInt64");
    NO_TYPE(fmi3GetUInt64(c, &vr, 1, &u64, 1), "fmi3GetUInt64");
    NO_TYPE(fmi3GetString(c, &vr, 1, &str, 1), "fmi3GetString");
    NO_TYPE(fmi3GetBinary(c, &vr, 1, &bin_size, &bin, 1), "fmi3GetBinary");
    NO_TYPE(fmi3GetClock(c, &vr, 1, &clk), "fmi3GetClock");
    NO_TYPE(fmi3SetFloat32(c, &vr_v, 1, &f32, 1), "fmi3SetFloat32");
    NO_TYPE(fmi3SetInt8(c, &vr_v, 1, &i8, 1), "fmi3SetInt8");
    NO_TYPE(fmi3SetUInt8(c, &vr_v, 1, &u8, 1), "fmi3SetUInt8");
    NO_TYPE(fmi3SetInt16(c, &vr_v, 1, &i16, 1), "fmi3SetInt16");
    NO_TYPE(fmi3SetUInt16(c, &vr_v, 1, &u16, 1), "fmi3SetUInt16");
    NO_TYPE(fmi3SetUInt32(c, &vr_v, 1, &u32, 1), "fmi3SetUInt32");
    NO_TYPE(fmi3SetInt64(c, &vr_v, 1, &i64, 1), "fmi3SetInt64");
    NO_TYPE(fmi3SetUInt64(c, &vr_v, 1, &u64, 1), "fmi3SetUInt64");
    NO_TYPE(fmi3SetString(c, &vr_v, 1, &str, 1), "fmi3SetString");
    NO_TYPE(fmi3SetBinary(c, &vr_v, 1, &bin_size, (const fmi3Binary *)&bin, 1), "fmi3SetBinary");
    NO_TYPE(fmi3SetClock(c, &vr_v, 1, &clk), "fmi3SetClock");
#undef NO_TYPE
    CHECK(fmi3GetInt8(c, NULL, 0, NULL, 0) == fmi3OK && fmi3SetString(c, NULL, 0, NULL, 0) == fmi3OK,
          "no values of a missing type: nothing to do");
    CHECK(fmi3GetInt32(c, (const fmi3ValueReference[]){VR_law}, 1, &i32, 1) == fmi3OK && i32 == 1, "law = 1");

    /* Output derivatives (maxOutputDerivativeOrder = 1) */
    CHECK(step(c, 0.0, 1e-5).status == fmi3OK, "a step into the contact");
    CHECK(fmi3GetOutputDerivatives(c, &vr, 1, &order, r, 1) == fmi3OK && r[0] > 0.0, "dF/dt while loading: %g",
          r[0]);
    order = 2;
    expect_error(fmi3GetOutputDerivatives(c, &vr, 1, &order, r, 1), "order 2", NULL, "second derivative");
    expect_error(fmi3GetOutputDerivatives(c, &vr, 1, NULL, r, 1), "fmi3GetOutputDerivatives", "NULL",
                 "NULL orders");
    vr = VR_eps;
    order = 1;
    expect_error(fmi3GetOutputDerivatives(c, &vr, 1, &order, r, 1), "value reference 21", NULL,
                 "eps has no derivative");
    fmi3FreeInstance(c);

    /* No instance: an error, no crash. */
    c = NULL;
    CHECK(fmi3SetDebugLogging(c, fmi3True, 0, NULL) == fmi3Error
              && fmi3EnterInitializationMode(c, fmi3False, 0, 0, fmi3False, 0) == fmi3Error
              && fmi3ExitInitializationMode(c) == fmi3Error && fmi3EnterEventMode(c) == fmi3Error
              && fmi3UpdateDiscreteStates(c, &b, &b, &b, &b, &b, r) == fmi3Error
              && fmi3EnterStepMode(c) == fmi3Error && fmi3Terminate(c) == fmi3Error && fmi3Reset(c) == fmi3Error,
          "NULL instance: the life cycle");
    CHECK(fmi3GetFloat64(c, &vr, 1, r, 1) == fmi3Error && fmi3SetFloat64(c, &vr_v, 1, r, 1) == fmi3Error
              && fmi3GetInt32(c, &vr, 1, &i32, 1) == fmi3Error && fmi3SetInt32(c, &vr, 1, &i32, 1) == fmi3Error
              && fmi3GetBoolean(c, &vr, 1, &b, 1) == fmi3Error && fmi3SetBoolean(c, &vr, 1, &b, 1) == fmi3Error
              && fmi3GetString(c, &vr, 1, &str, 1) == fmi3Error && fmi3GetClock(c, &vr, 1, &clk) == fmi3Error
              && fmi3SetBinary(c, &vr, 1, &bin_size, (const fmi3Binary *)&bin, 1) == fmi3Error,
          "NULL instance: getters and setters");
    CHECK(fmi3DoStep(c, 0, 1e-5, fmi3False, &b, &b, &b, r) == fmi3Error
              && fmi3GetOutputDerivatives(c, &vr, 1, &order, r, 1) == fmi3Error
              && fmi3GetFMUState(c, &state) == fmi3Error && fmi3SetFMUState(c, state) == fmi3Error
              && fmi3FreeFMUState(c, &state) == fmi3Error && fmi3SerializedFMUStateSize(c, state, &n) == fmi3Error
              && fmi3SerializeFMUState(c, state, bytes, sizeof bytes) == fmi3Error
              && fmi3DeserializeFMUState(c, bytes, sizeof bytes, &state) == fmi3Error,
          "NULL instance: stepping and states");
    CHECK(fmi3EnterConfigurationMode(c) == fmi3Error && fmi3SetTime(c, 0.0) == fmi3Error
              && fmi3GetDirectionalDerivative(c, &vr, 1, &vr_v, 1, r, 1, r, 1) == fmi3Error
              && fmi3EvaluateDiscreteStates(c) == fmi3Error && fmi3GetNumberOfContinuousStates(c, &n) == fmi3Error,
          "NULL instance: the unsupported");

    /* Before initialization the getters are refused as out of sequence. */
    c = plain("early");
    expect_error(fmi3GetInt32(c, &vr, 1, &i32, 1), "fmi3GetInt32", "illegal call sequence", "Int32 too early");
    expect_error(fmi3GetFloat32(c, &vr, 1, &f32, 1), "fmi3GetFloat32", "illegal call sequence", "Float32 early");
    expect_error(fmi3GetDirectionalDerivative(c, &vr, 1, &vr_v, 1, r, 1, r, 1), "fmi3GetDirectionalDerivative",
                 "illegal call sequence", "derivative too early");
    expect_error(fmi3GetOutputDerivatives(c, &vr, 1, &order, r, 1), "fmi3GetOutputDerivatives",
                 "illegal call sequence", "output derivative too early");
    CHECK(fmi3GetFMUState(c, &state) == fmi3OK && fmi3SetFMUState(c, state) == fmi3OK
              && fmi3FreeFMUState(c, &state) == fmi3OK, "a state when just instantiated");
    fmi3FreeInstance(c);
}

/* Two instances stepped alternately give, bit for bit, what each gives
 * alone, and a reset instance repeats its run. */
static void test_independent_instances(void)
{
    double alone[2][N_OUT], together[2][N_OUT];
    fmi3Instance a, b;
    int i, k;
    for (k = 0; k < 2; k++) {
        fmi3Instance c = plain("alone");
        if (k == 1)
            set(c, VR_c, 2000.0);
        start(c);
        for (i = 0; i < 60; i++)
            step(c, i * H20_STEP, H20_STEP);
        fmi3GetFloat64(c, outputs, N_OUT, alone[k], N_OUT);
        fmi3FreeInstance(c);
    }
    a = plain("a");
    b = plain("b");
    set(b, VR_c, 2000.0);
    start(a);
    start(b);
    for (i = 0; i < 60; i++) {
        step(a, i * H20_STEP, H20_STEP);
        step(b, i * H20_STEP, H20_STEP);
    }
    fmi3GetFloat64(a, outputs, N_OUT, together[0], N_OUT);
    fmi3GetFloat64(b, outputs, N_OUT, together[1], N_OUT);
    CHECK(memcmp(alone, together, sizeof alone) == 0, "interleaved instances differ from lone ones");
    CHECK(alone[0][0] != alone[1][0], "the two instances should differ (c = 6080 vs 2000)");
    fmi3Reset(a);
    start(a);
    for (i = 0; i < 60; i++)
        step(a, i * H20_STEP, H20_STEP);
    fmi3GetFloat64(a, outputs, N_OUT, together[0], N_OUT);
    CHECK(memcmp(alone[0], together[0], sizeof alone[0]) == 0, "a reset instance repeats its run");
    fmi3FreeInstance(a);
    fmi3FreeInstance(b);
}

int main(int argc, char **argv)
{
    load_fmi2(argc > 1 ? argv[1] : NULL);
    test_instantiate();
    test_state_machine();
    test_refusals_name_what_they_refuse();
    test_steps_that_do_not_advance_time();
    test_non_finite();
    test_out_of_range();
    test_bad_steps();
    test_same_as_fmi2();
    test_early_return();
    test_event_details();
    test_intermediate_update();
    test_jacobi_coupling();
    test_fmu_state();
    test_logging();
    test_unsupported();
    test_independent_instances();
    if (fmi2.library)
        close_library(fmi2.library);
    return check_summary("test_fmi3");
}
