/* The FMI 2.0 glue called directly from C, as a master would (and as the
 * sanitizer build can instrument end to end): call sequence, bad input,
 * independent instances, reset. */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "fmi2Functions.h"
#include "fmu_model.h" /* the value references */
#include "guid.h"

static char last_message[1024];
static fmi2Status last_status;
static int messages;

static void logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status,
                   fmi2String category, fmi2String message, ...)
{
    va_list args;
    (void)env;
    (void)name;
    (void)category;
    va_start(args, message);
    vsnprintf(last_message, sizeof last_message, message, args);
    va_end(args);
    last_status = status;
    messages++;
}

static const fmi2CallbackFunctions callbacks = {logger, calloc, free, NULL, NULL};

static fmi2Component instantiate(const char *name)
{
    return fmi2Instantiate(name, fmi2CoSimulation, FMU_GUID, "", &callbacks, fmi2False, fmi2False);
}

static double get(fmi2Component c, fmi2ValueReference vr)
{
    double value = -1.0;
    CHECK(fmi2GetReal(c, &vr, 1, &value) == fmi2OK, "get vr %u: %s", vr, last_message);
    return value;
}

/* The status is an error and the log names what it must. */
static void expect_error(fmi2Status status, const char *a, const char *b, const char *what)
{
    CHECK(status == fmi2Error, "%s: status %d", what, (int)status);
    CHECK(last_status == fmi2Error && strstr(last_message, a) && (!b || strstr(last_message, b)),
          "%s: log \"%s\" should name \"%s\"%s%s", what, last_message, a, b ? " and " : "", b ? b : "");
}

/* The status is an error and the log says exactly `message`. */
static void expect_message(fmi2Status status, const char *message, const char *what)
{
    CHECK(status == fmi2Error && last_status == fmi2Error && strcmp(last_message, message) == 0,
          "%s: status %d, log \"%s\", not \"%s\"", what, (int)status, last_message, message);
}

static fmi2Component started(const char *name)
{
    fmi2Component c = instantiate(name);
    CHECK(fmi2SetupExperiment(c, fmi2False, 0, 0, fmi2False, 0) == fmi2OK && fmi2EnterInitializationMode(c) == fmi2OK
              && fmi2ExitInitializationMode(c) == fmi2OK,
          "start %s: %s", name, last_message);
    return c;
}

static void test_instantiate(void)
{
    fmi2Component c;
    c = fmi2Instantiate("x", fmi2CoSimulation, "{wrong}", "", &callbacks, fmi2False, fmi2False);
    CHECK(c == NULL && strstr(last_message, "fmuGUID"), "a wrong GUID is refused: %s", last_message);
    c = fmi2Instantiate("x", (fmi2Type)7, FMU_GUID, "", &callbacks, fmi2False, fmi2False);
    CHECK(c == NULL && strstr(last_message, "fmuType = 7"), "an unknown fmuType is refused: %s", last_message);
    c = fmi2Instantiate("x", fmi2ModelExchange, FMU_GUID, "", &callbacks, fmi2False, fmi2False);
    CHECK(c != NULL, "model exchange is served beside co-simulation: %s", last_message);
    fmi2FreeInstance(c);
    c = fmi2Instantiate("", fmi2CoSimulation, FMU_GUID, "", &callbacks, fmi2False, fmi2False);
    CHECK(c == NULL && strstr(last_message, "instanceName"), "an empty name is refused: %s", last_message);
    CHECK(fmi2Instantiate("x", fmi2CoSimulation, FMU_GUID, "", NULL, fmi2False, fmi2False) == NULL,
          "no callbacks");
    CHECK(strcmp(fmi2GetVersion(), "2.0") == 0 && strcmp(fmi2GetTypesPlatform(), "default") == 0, "version");
    fmi2FreeInstance(NULL);
}

static void test_call_sequence(void)
{
    fmi2Component c = instantiate("sequence");
    fmi2ValueReference vr = VR_F;
    double value;
    expect_error(fmi2DoStep(c, 0.0, 1e-5, fmi2True), "fmi2DoStep", "illegal call sequence", "doStep before init");
    expect_error(fmi2GetReal(c, &vr, 1, &value), "fmi2GetReal", "illegal call sequence", "getReal before init");
    expect_error(fmi2ExitInitializationMode(c), "fmi2ExitInitializationMode", NULL, "exit before enter");
    expect_error(fmi2Terminate(c), "fmi2Terminate", NULL, "terminate before init");
    CHECK(fmi2EnterInitializationMode(c) == fmi2OK, "enter");
    expect_error(fmi2SetupExperiment(c, fmi2False, 0, 0, fmi2False, 0), "fmi2SetupExperiment", NULL, "setup late");
    expect_error(fmi2DoStep(c, 0.0, 1e-5, fmi2True), "fmi2DoStep", "illegal call sequence", "doStep in initialization");
    CHECK(fmi2ExitInitializationMode(c) == fmi2OK, "exit");
    expect_error(fmi2EnterInitializationMode(c), "fmi2EnterInitializationMode", NULL, "enter twice");
    CHECK(fmi2DoStep(c, 0.0, 1e-5, fmi2True) == fmi2OK, "a step");
    expect_error(fmi2DoStep(c, 0.5, 1e-5, fmi2True), "currentCommunicationPoint", "0.5", "time mismatch");
    expect_error(fmi2DoStep(c, 1e-5, -1.0, fmi2True), "communicationStepSize", "-1", "negative step");
    CHECK(fmi2DoStep(c, 1e-5, 1e-5, fmi2True) == fmi2OK, "the instance is still usable: %s", last_message);
    expect_error(fmi2CancelStep(c), "fmi2CancelStep", NULL, "cancel without a pending step");
    CHECK(fmi2Terminate(c) == fmi2OK, "terminate");
    expect_error(fmi2DoStep(c, 2e-5, 1e-5, fmi2True), "fmi2DoStep", NULL, "step after terminate");
    CHECK(fmi2GetReal(c, &vr, 1, &value) == fmi2OK && value > 0.0, "outputs readable after terminate");
    CHECK(fmi2Reset(c) == fmi2OK, "reset");
    CHECK(fmi2EnterInitializationMode(c) == fmi2OK, "enter after reset");
    fmi2FreeInstance(c);
}

/* A refusal names the variable and the function, in FMI 2.0's words: its
 * types (Real, Integer) and states (Step Complete, Terminated). */
static void test_refusals_name_what_they_refuse(void)
{
    fmi2Component c = started("names");
    fmi2ValueReference c_vr = VR_c, law_vr = VR_law, none = 999, v_vr = VR_v;
    fmi2Integer i;
    fmi2Real r, v = 1.0;
    expect_message(fmi2GetInteger(c, &c_vr, 1, &i),
                   "value reference 9 is not an Integer variable of this FMU: it is c, a Real variable",
                   "an Integer call for a Real");
    expect_message(fmi2GetReal(c, &law_vr, 1, &r),
                   "value reference 30 is not a Real variable of this FMU: it is law, an Integer variable",
                   "a Real call for an Integer");
    expect_message(fmi2GetReal(c, &none, 1, &r),
                   "value reference 999 is not a Real variable of this FMU: it has no variable of that reference",
                   "a reference of no variable");
    CHECK(fmi2DoStep(c, 0.0, 1e-5, fmi2True) == fmi2OK && fmi2Terminate(c) == fmi2OK, "step, terminate");
    expect_message(fmi2DoStep(c, 1e-5, 1e-5, fmi2True),
                   "fmi2DoStep: illegal call sequence: called in state Terminated, allowed only in Step Complete",
                   "a step after terminate");
    expect_message(fmi2SetReal(c, &v_vr, 1, &v),
                   "fmi2SetReal: illegal call sequence: called in state Terminated, allowed only in Instantiated, "
                   "Initialization Mode or Step Complete",
                   "an input after terminate");
    expect_message(fmi2CancelStep(c),
                   "fmi2CancelStep: illegal call sequence: called in state Terminated, allowed in no state of this FMU",
                   "a cancel without a step in progress");
    fmi2FreeInstance(c);
}

/* A communication step that does not advance time (t + H == t) changes
 * nothing: every output of an instance given such steps inside an impact
 * is that of one not given them, there and after the impact. (The G1 law
 * counts internal steps: one more changed eps by about 1e-9.) */
static void test_steps_that_do_not_advance_time(void)
{
    static const fmi2ValueReference outputs[] = {VR_F, VR_F_avg, VR_F_avg_next, VR_F_peak, VR_x, VR_x1, VR_x2,
                                                 VR_v_striker, VR_E_diss, VR_eps, VR_semi_integral};
    const size_t n = sizeof outputs / sizeof outputs[0];
    fmi2Component a = started("slivers"), b = started("plain");
    double t = 0.0, ya[11], yb[11];
    int k;
    for (k = 0; k < 300; k++) {
        if (k == 100)
            CHECK(fmi2DoStep(a, t, 5e-324, fmi2True) == fmi2OK && fmi2DoStep(a, t, 1e-20, fmi2True) == fmi2OK
                      && t + 1e-20 == t,
                  "steps of 5e-324 s and 1e-20 s at t = %g: %s", t, last_message);
        if (k == 100 || k == 299) {
            CHECK(fmi2GetReal(a, outputs, n, ya) == fmi2OK && fmi2GetReal(b, outputs, n, yb) == fmi2OK, "outputs");
            CHECK(memcmp(ya, yb, sizeof ya) == 0, "at t = %g the outputs are those of a run without the slivers "
                  "(eps %.17g, %.17g; x2 %.17g, %.17g)", t, ya[9], yb[9], ya[6], yb[6]);
        }
        CHECK(fmi2DoStep(a, t, 1e-5, fmi2True) == fmi2OK && fmi2DoStep(b, t, 1e-5, fmi2True) == fmi2OK, "step %d", k);
        t += 1e-5;
    }
    CHECK(yb[9] > 0.5, "the impact ended: eps = %g", yb[9]);
    fmi2FreeInstance(a);
    fmi2FreeInstance(b);
}

/* Every real parameter and input rejects NaN and infinities with a message
 * naming it and the value, and keeps its previous value. */
static void test_non_finite_reals(void)
{
    static const fmi2ValueReference vrs[] = {VR_v, VR_m, VR_R, VR_E_i, VR_nu_i, VR_E_s, VR_nu_s, VR_k,
                                             VR_c, VR_dt_max, VR_g, VR_gap0, VR_spring_exponent, VR_damper_order,
                                             VR_c_alpha, VR_memory_tolerance};
    static const char *const names[] = {"v", "m", "R", "E_i", "nu_i", "E_s", "nu_s", "k",
                                        "c", "dt_max", "g", "gap0", "spring_exponent", "damper_order",
                                        "c_alpha", "memory_tolerance"};
    const double bad[] = {NAN, INFINITY, -INFINITY};
    const char *const shown[] = {"nan", "inf", "-inf"};
    fmi2Component c = instantiate("non-finite");
    size_t i, j;
    CHECK(fmi2EnterInitializationMode(c) == fmi2OK, "enter");
    for (i = 0; i < sizeof vrs / sizeof vrs[0]; i++) {
        double before = get(c, vrs[i]);
        for (j = 0; j < 3; j++) {
            char what[64];
            snprintf(what, sizeof what, "%s = %s", names[i], shown[j]);
            expect_error(fmi2SetReal(c, &vrs[i], 1, &bad[j]), names[i], shown[j], what);
        }
        CHECK(get(c, vrs[i]) == before, "%s kept its value", names[i]);
    }
    CHECK(fmi2ExitInitializationMode(c) == fmi2OK, "the defaults still start: %s", last_message);
    fmi2FreeInstance(c);
}

static void test_out_of_range(void)
{
    struct { fmi2ValueReference vr; double value; const char *name; } reals[] = {
        {VR_c, 0.0, "c"}, {VR_c, -1.0, "c"}, {VR_k, -1.0, "k"}, {VR_R, 0.0, "R"}, {VR_R, -1e-3, "R"},
        {VR_dt_max, 5e-324, "dt_max"}, {VR_dt_max, -1e-7, "dt_max"}, {VR_m, -1.0, "m"},
        {VR_E_i, 0.0, "E_i"}, {VR_E_s, -2e9, "E_s"}, {VR_nu_i, 0.6, "nu_i"}, {VR_nu_s, -1.0, "nu_s"},
        {VR_gap0, -1e-3, "gap0"}, {VR_spring_exponent, 0.5, "spring_exponent"},
        {VR_spring_exponent, 11.0, "spring_exponent"}, {VR_damper_order, 0.0, "damper_order"},
        {VR_damper_order, 1.5, "damper_order"}, {VR_c_alpha, 0.0, "c_alpha"}, {VR_c_alpha, -3e5, "c_alpha"},
        {VR_memory_tolerance, 0.0, "memory_tolerance"}, {VR_memory_tolerance, 0.5, "memory_tolerance"}};
    struct { fmi2ValueReference vr; int value; const char *name; } ints[] = {
        {VR_law, 0, "law"}, {VR_law, 4, "law"}, {VR_scene, 0, "scene"}, {VR_scene, 3, "scene"},
        {VR_g1_nodes, -1, "g1_nodes"}, {VR_damper, 0, "damper"}, {VR_damper, 3, "damper"},
        {VR_memory, 0, "memory"}, {VR_memory, 3, "memory"}};
    fmi2Component c = instantiate("range");
    fmi2ValueReference vr;
    size_t i;
    for (i = 0; i < sizeof reals / sizeof reals[0]; i++)
        expect_error(fmi2SetReal(c, &reals[i].vr, 1, &reals[i].value), reals[i].name, " = ", reals[i].name);
    for (i = 0; i < sizeof ints / sizeof ints[0]; i++)
        expect_error(fmi2SetInteger(c, &ints[i].vr, 1, &ints[i].value), ints[i].name, " = ", ints[i].name);

    vr = VR_F;
    expect_error(fmi2SetReal(c, &vr, 1, &reals[0].value), "F is an output", NULL, "set an output");
    vr = 999;
    expect_error(fmi2SetReal(c, &vr, 1, &reals[0].value), "999", "Real", "unknown real reference");
    expect_error(fmi2SetInteger(c, &vr, 1, &ints[0].value), "999", "Integer", "unknown integer reference");
    vr = VR_F; /* a Real's reference is no Integer */
    expect_error(fmi2SetInteger(c, &vr, 1, &ints[0].value), "13", "Integer", "reference of the wrong type");
    expect_error(fmi2SetReal(c, NULL, 1, &reals[0].value), "NULL", NULL, "NULL array");

    /* The drop test needs a mass; the driven scene takes 0 as "no inertia". */
    {
        double zero = 0.0;
        int driven = 2;
        vr = VR_m;
        CHECK(fmi2SetReal(c, &vr, 1, &zero) == fmi2OK, "m = 0 is accepted until the scene is known");
        CHECK(fmi2EnterInitializationMode(c) == fmi2OK, "enter");
        expect_error(fmi2ExitInitializationMode(c), "m = 0", "drop test", "drop test without mass");
        vr = VR_scene;
        CHECK(fmi2SetInteger(c, &vr, 1, &driven) == fmi2OK, "scene = 2: %s", last_message);
        CHECK(fmi2ExitInitializationMode(c) == fmi2OK, "driven with m = 0 starts: %s", last_message);
        vr = VR_c;
        expect_error(fmi2SetReal(c, &vr, 1, &zero), "c is a fixed parameter", NULL, "parameter after init");
    }
    fmi2FreeInstance(c);
}

/* Two instances stepped alternately give, bit for bit, what each gives
 * alone: no shared state. */
/* Free flight is one exact step, so a communication step of 1e9 s holds
 * the impact's steps and one more (docs/numerics.md, "Sub-stepping"). The full G1
 * history steps on a uniform grid of dt_max, so a step that needs more than
 * 1e9 of them is refused at once and changes nothing. */
static void test_long_steps(void)
{
    fmi2ValueReference vr[] = {VR_damper, VR_memory};
    fmi2Integer springpot[] = {2, 1};
    fmi2Component c = instantiate("long");
    CHECK(fmi2SetupExperiment(c, fmi2False, 0, 0, fmi2False, 0) == fmi2OK && fmi2EnterInitializationMode(c) == fmi2OK
              && fmi2ExitInitializationMode(c) == fmi2OK,
          "start: %s", last_message);
    CHECK(fmi2DoStep(c, 0.0, 1e9, fmi2True) == fmi2OK, "a step of 1e9 s: %s", last_message);
    CHECK(get(c, VR_eps) > 0.5 && get(c, VR_eps) < 0.6, "the impact inside it ended: eps %g", get(c, VR_eps));
    fmi2FreeInstance(c);
    c = instantiate("uniform");
    CHECK(fmi2SetupExperiment(c, fmi2False, 0, 0, fmi2False, 0) == fmi2OK && fmi2EnterInitializationMode(c) == fmi2OK
              && fmi2SetInteger(c, vr, 2, springpot) == fmi2OK && fmi2ExitInitializationMode(c) == fmi2OK,
          "start the full G1 history: %s", last_message);
    expect_error(fmi2DoStep(c, 0.0, 1e3, fmi2True), "communicationStepSize", "at most 1048576", "endless step");
    CHECK(get(c, VR_x) == 0.0, "the refused step changed nothing");
    CHECK(fmi2DoStep(c, 0.0, 1e-5, fmi2True) == fmi2OK, "the instance is still usable: %s", last_message);
    fmi2FreeInstance(c);
}

static void test_independent_instances(void)
{
    fmi2ValueReference vr_c = VR_c, out[] = {VR_F, VR_x2, VR_E_diss, VR_F_peak};
    double soft = 2000.0, alone[2][4], together[2][4];
    fmi2Component a, b;
    int i, k;
    for (k = 0; k < 2; k++) {
        fmi2Component c = instantiate("alone");
        if (k == 1)
            fmi2SetReal(c, &vr_c, 1, &soft);
        fmi2EnterInitializationMode(c);
        fmi2ExitInitializationMode(c);
        for (i = 0; i < 60; i++)
            fmi2DoStep(c, i * 1e-5, 1e-5, fmi2True);
        fmi2GetReal(c, out, 4, alone[k]);
        fmi2FreeInstance(c);
    }
    a = instantiate("a");
    b = instantiate("b");
    fmi2SetReal(b, &vr_c, 1, &soft);
    fmi2EnterInitializationMode(a);
    fmi2EnterInitializationMode(b);
    fmi2ExitInitializationMode(a);
    fmi2ExitInitializationMode(b);
    for (i = 0; i < 60; i++) {
        fmi2DoStep(a, i * 1e-5, 1e-5, fmi2True);
        fmi2DoStep(b, i * 1e-5, 1e-5, fmi2True);
    }
    fmi2GetReal(a, out, 4, together[0]);
    fmi2GetReal(b, out, 4, together[1]);
    CHECK(memcmp(alone, together, sizeof alone) == 0, "interleaved instances differ from lone ones");
    CHECK(alone[0][0] != alone[1][0], "the two instances should differ (c = 6080 vs 2000)");
    /* Reset gives the same run again. */
    fmi2Reset(a);
    fmi2EnterInitializationMode(a);
    fmi2ExitInitializationMode(a);
    for (i = 0; i < 60; i++)
        fmi2DoStep(a, i * 1e-5, 1e-5, fmi2True);
    fmi2GetReal(a, out, 4, together[0]);
    CHECK(memcmp(alone[0], together[0], sizeof alone[0]) == 0, "a reset instance repeats its run");
    fmi2FreeInstance(a);
    fmi2FreeInstance(b);
}

static void test_logging(void)
{
    fmi2Component c = instantiate("logging");
    const char *events[] = {"logEvents"}, *unknown[] = {"logEverything"};
    int before;
    expect_error(fmi2SetDebugLogging(c, fmi2True, 1, unknown), "logEverything", NULL, "unknown category");
    CHECK(fmi2SetDebugLogging(c, fmi2True, 1, events) == fmi2OK, "enable logEvents");
    fmi2EnterInitializationMode(c);
    fmi2ExitInitializationMode(c);
    before = messages;
    fmi2DoStep(c, 0.0, 3e-3, fmi2True);
    CHECK(messages > before && strstr(last_message, "impact 1 ended"), "event log: %s", last_message);
    fmi2FreeInstance(c);
}

/* Every exported function: with no instance (an error, no crash), in a
 * state it may not be called in (an error, nothing changes), and in order. */
static void test_every_function(void)
{
    fmi2ValueReference vr_F = VR_F, vr_v = VR_v, vr_law = VR_law, vr_contact = VR_contact;
    fmi2Real r = 0.0;
    fmi2Integer i = 0, order = 1;
    fmi2Boolean b = fmi2False;
    fmi2String str = NULL;
    fmi2Status status;
    fmi2FMUstate state = NULL;
    size_t size = 0;
    fmi2Byte bytes[4096];
    fmi2Component c;

    /* No instance. */
    CHECK(fmi2SetDebugLogging(NULL, fmi2True, 0, NULL) == fmi2Error, "NULL component");
    CHECK(fmi2SetupExperiment(NULL, fmi2False, 0, 0, fmi2False, 0) == fmi2Error, "NULL component");
    CHECK(fmi2EnterInitializationMode(NULL) == fmi2Error && fmi2ExitInitializationMode(NULL) == fmi2Error,
          "NULL component");
    CHECK(fmi2Terminate(NULL) == fmi2Error && fmi2Reset(NULL) == fmi2Error, "NULL component");
    CHECK(fmi2GetReal(NULL, &vr_F, 1, &r) == fmi2Error && fmi2SetReal(NULL, &vr_v, 1, &r) == fmi2Error,
          "NULL component");
    CHECK(fmi2GetInteger(NULL, &vr_law, 1, &i) == fmi2Error && fmi2SetInteger(NULL, &vr_law, 1, &i) == fmi2Error,
          "NULL component");
    CHECK(fmi2GetBoolean(NULL, &vr_contact, 1, &b) == fmi2Error
              && fmi2SetBoolean(NULL, &vr_contact, 1, &b) == fmi2Error, "NULL component");
    CHECK(fmi2GetString(NULL, &vr_F, 1, &str) == fmi2Error && fmi2SetString(NULL, &vr_F, 1, &str) == fmi2Error,
          "NULL component");
    CHECK(fmi2GetFMUstate(NULL, &state) == fmi2Error && fmi2SetFMUstate(NULL, state) == fmi2Error
              && fmi2FreeFMUstate(NULL, &state) == fmi2Error, "NULL component");
    CHECK(fmi2SerializedFMUstateSize(NULL, state, &size) == fmi2Error
              && fmi2SerializeFMUstate(NULL, state, bytes, sizeof bytes) == fmi2Error
              && fmi2DeSerializeFMUstate(NULL, bytes, sizeof bytes, &state) == fmi2Error, "NULL component");
    CHECK(fmi2GetDirectionalDerivative(NULL, &vr_F, 1, &vr_v, 1, &r, &r) == fmi2Error, "NULL component");
    CHECK(fmi2SetRealInputDerivatives(NULL, &vr_v, 1, &order, &r) == fmi2Error
              && fmi2GetRealOutputDerivatives(NULL, &vr_F, 1, &order, &r) == fmi2Error, "NULL component");
    CHECK(fmi2DoStep(NULL, 0, 1e-5, fmi2True) == fmi2Error && fmi2CancelStep(NULL) == fmi2Error, "NULL component");
    CHECK(fmi2GetStatus(NULL, fmi2DoStepStatus, &status) == fmi2Error
              && fmi2GetRealStatus(NULL, fmi2LastSuccessfulTime, &r) == fmi2Error
              && fmi2GetIntegerStatus(NULL, fmi2DoStepStatus, &i) == fmi2Error
              && fmi2GetBooleanStatus(NULL, fmi2Terminated, &b) == fmi2Error
              && fmi2GetStringStatus(NULL, fmi2PendingStatus, &str) == fmi2Error, "NULL component");
    fmi2FreeInstance(NULL);

    /* Instantiated: no outputs, no steps, no statuses yet. */
    c = instantiate("every");
    CHECK(fmi2GetReal(c, &vr_F, 1, &r) == fmi2Error && fmi2GetInteger(c, &vr_law, 1, &i) == fmi2Error
              && fmi2GetBoolean(c, &vr_contact, 1, &b) == fmi2Error && fmi2GetString(c, &vr_F, 1, &str) == fmi2Error,
          "getters before initialization");
    CHECK(fmi2GetRealOutputDerivatives(c, &vr_F, 1, &order, &r) == fmi2Error, "output derivative too early");
    CHECK(fmi2GetDirectionalDerivative(c, &vr_F, 1, &vr_v, 1, &r, &r) == fmi2Error, "directional derivative");
    CHECK(fmi2GetStatus(c, fmi2DoStepStatus, &status) == fmi2Error
              && fmi2GetRealStatus(c, fmi2LastSuccessfulTime, &r) == fmi2Error
              && fmi2GetIntegerStatus(c, fmi2DoStepStatus, &i) == fmi2Error
              && fmi2GetBooleanStatus(c, fmi2Terminated, &b) == fmi2Error
              && fmi2GetStringStatus(c, fmi2PendingStatus, &str) == fmi2Error, "statuses before stepping");
    CHECK(fmi2ExitInitializationMode(c) == fmi2Error && fmi2Terminate(c) == fmi2Error, "exit, terminate early");

    /* In order. */
    CHECK(fmi2SetDebugLogging(c, fmi2False, 0, NULL) == fmi2OK, "logging");
    CHECK(fmi2SetupExperiment(c, fmi2True, 1e-6, 0.0, fmi2True, 3e-3) == fmi2OK, "setup");
    i = 2;
    CHECK(fmi2SetInteger(c, &vr_law, 1, &i) == fmi2OK, "law");
    CHECK(fmi2SetBoolean(c, &vr_contact, 1, &b) == fmi2Error, "a Boolean output cannot be set");
    CHECK(fmi2SetString(c, NULL, 0, NULL) == fmi2OK && fmi2SetString(c, &vr_F, 1, &str) == fmi2Error,
          "no strings");
    CHECK(fmi2SetRealInputDerivatives(c, &vr_v, 1, &order, &r) == fmi2OK, "input derivative");
    CHECK(fmi2EnterInitializationMode(c) == fmi2OK, "enter");
    CHECK(fmi2GetReal(c, &vr_v, 1, &r) == fmi2OK && fmi2GetInteger(c, &vr_law, 1, &i) == fmi2OK && i == 2
              && fmi2GetBoolean(c, &vr_contact, 1, &b) == fmi2OK && b == fmi2False, "getters in initialization");
    CHECK(fmi2ExitInitializationMode(c) == fmi2OK, "exit");
    CHECK(fmi2SetupExperiment(c, fmi2False, 0, 0, fmi2False, 0) == fmi2Error
              && fmi2EnterInitializationMode(c) == fmi2Error && fmi2ExitInitializationMode(c) == fmi2Error,
          "initialization calls after initialization");
    CHECK(fmi2DoStep(c, 0.0, 1e-4, fmi2False) == fmi2OK, "step");
    CHECK(fmi2GetRealOutputDerivatives(c, &vr_F, 1, &order, &r) == fmi2OK && r > 0.0, "dF/dt while loading");
    CHECK(fmi2GetRealStatus(c, fmi2LastSuccessfulTime, &r) == fmi2OK && r == 1e-4, "last successful time");
    CHECK(fmi2GetBooleanStatus(c, fmi2Terminated, &b) == fmi2OK && b == fmi2False, "terminated status");
    CHECK(fmi2GetStatus(c, fmi2DoStepStatus, &status) == fmi2Discard
              && fmi2GetIntegerStatus(c, fmi2DoStepStatus, &i) == fmi2Discard
              && fmi2GetStringStatus(c, fmi2PendingStatus, &str) == fmi2Discard, "no asynchronous status");
    CHECK(fmi2CancelStep(c) == fmi2Error, "nothing to cancel");
    CHECK(fmi2GetFMUstate(c, &state) == fmi2OK, "get state");
    CHECK(fmi2SerializedFMUstateSize(c, state, &size) == fmi2OK && size > 0 && size <= sizeof bytes, "state size");
    CHECK(fmi2SerializeFMUstate(c, state, bytes, size - 1) == fmi2Error, "too small a buffer");
    CHECK(fmi2SerializeFMUstate(c, state, bytes, size) == fmi2OK, "serialize");
    CHECK(fmi2FreeFMUstate(c, &state) == fmi2OK && state == NULL, "free state");
    CHECK(fmi2DeSerializeFMUstate(c, bytes, size, &state) == fmi2OK, "deserialize");
    CHECK(fmi2DoStep(c, 1e-4, 1e-4, fmi2True) == fmi2OK && fmi2SetFMUstate(c, state) == fmi2OK
              && fmi2GetRealStatus(c, fmi2LastSuccessfulTime, &r) == fmi2OK && r == 1e-4, "roll back");
    CHECK(fmi2FreeFMUstate(c, &state) == fmi2OK, "free state");
    CHECK(fmi2Terminate(c) == fmi2OK, "terminate");
    CHECK(fmi2DoStep(c, 1e-4, 1e-4, fmi2True) == fmi2Error && fmi2SetReal(c, &vr_v, 1, &r) == fmi2Error
              && fmi2SetRealInputDerivatives(c, &vr_v, 1, &order, &r) == fmi2Error && fmi2Terminate(c) == fmi2Error,
          "after terminate");
    CHECK(fmi2GetReal(c, &vr_F, 1, &r) == fmi2OK, "outputs after terminate");
    CHECK(fmi2Reset(c) == fmi2OK && fmi2GetReal(c, &vr_F, 1, &r) == fmi2Error, "reset: instantiated again");
    fmi2FreeInstance(c);
}

int main(void)
{
    test_instantiate();
    test_call_sequence();
    test_refusals_name_what_they_refuse();
    test_steps_that_do_not_advance_time();
    test_non_finite_reals();
    test_out_of_range();
    test_long_steps();
    test_independent_instances();
    test_logging();
    test_every_function();
    return check_summary("test_fmi2");
}
