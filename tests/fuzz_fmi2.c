/* Fuzzing the FMI API: a byte string read as a program of FMI calls with
 * their values, on two instances at once. After every call: the status is
 * one the standard allows (never fmi2Fatal or fmi2Pending from a synchronous
 * slave), and whenever outputs can be read they are finite with F >= 0.
 * A broken invariant aborts, which the fuzzer (libFuzzer, or the replay
 * driver fuzz_replay.c in every other build) reports as a crash.
 *
 * The program: each call takes an opcode byte and then the bytes its
 * arguments need; a value byte picks from a table of interesting numbers or,
 * with its top bit set, reads the next 8 bytes as a raw double (NaN, Inf,
 * denormals and all). Running out of bytes ends the program. Both
 * interfaces: an instance for Model Exchange takes the solver's calls
 * (states, derivatives, event indicators, nominals, the modes), and the
 * derivatives, indicators and nominals it gives must be finite. */
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"
#include "fuzz_program.h"
#include "guid.h"

static void logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status, fmi2String category,
                   fmi2String message, ...)
{
    char text[2048];
    va_list args;
    (void)env;
    (void)name;
    (void)status;
    (void)category;
    va_start(args, message);
    vsnprintf(text, sizeof text, message, args);
    va_end(args);
}

static const fmi2CallbackFunctions callbacks = {logger, calloc, free, NULL, NULL};

/* The continuous states and event indicators of modelDescription.xml. */
enum { STATES = 164, INDICATORS = 2 };

static void require_finite(const fmi2Real *v, size_t n, const char *what)
{
    size_t i;
    for (i = 0; i < n; i++)
        if (!(v[i] - v[i] == 0.0)) {
            fprintf(stderr, "fuzz invariant broken: a non-finite value among the %s\n", what);
            abort();
        }
}

/* Whether the instance keeps a springpot's full G1 history (damper 2,
 * memory 1), whose steps cost O(N) each. */
static int full_history(fmi2Component x)
{
    const fmi2ValueReference damper = 33, memory = 34;
    fmi2Integer d = 0, m = 0;
    return fmi2GetInteger(x, &damper, 1, &d) == fmi2OK && fmi2GetInteger(x, &memory, 1, &m) == fmi2OK && d == 2
           && m == 1;
}

static void require(int ok, const char *what)
{
    if (!ok) {
        fprintf(stderr, "fuzz invariant broken: %s\n", what);
        abort();
    }
}

static fmi2Status checked(fmi2Status s)
{
    require(s == fmi2OK || s == fmi2Warning || s == fmi2Discard || s == fmi2Error, "status outside the standard's");
    return s;
}

/* Every real output, when readable, is finite and the force is not tension. */
static void check_outputs(fmi2Component c)
{
    static const fmi2ValueReference outputs[] = {13, 14, 15, 16, 17, 18, 19, 20, 21, 22, 28};
    fmi2Real v[11];
    size_t i;
    if (checked(fmi2GetReal(c, outputs, 11, v)) != fmi2OK)
        return;
    for (i = 0; i < 11; i++)
        require(v[i] - v[i] == 0.0, "a non-finite output");
    require(v[0] >= 0.0 && v[2] >= 0.0, "a negative contact force");
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    program p = {data, data + size};
    fmi2Component c[2] = {NULL, NULL};
    fmi2FMUstate state[2] = {NULL, NULL};
    fmi2Byte blob[4096];
    size_t blob_size = 0;
    budget spent = {0.0, 0.0};
    int steps = 0;
    while (more(&p, 1) && steps < 64) {
        uint8_t op = byte(&p);
        int k = op >> 7;                       /* which instance */
        fmi2Component x = c[k];
        fmi2ValueReference vr = 0;
        fmi2Real r = 0.0, t = 0.0, now = 0.0, dt = 0.0;
        fmi2Integer n = 0, order = 1;
        fmi2Boolean b = fmi2False;
        fmi2Status s;
        switch (op & 0x1F) {
        case 0:
            if (!x)
                c[k] = fmi2Instantiate(k ? "b" : "a", fmi2CoSimulation, FMU_GUID, "", &callbacks, fmi2False,
                                       byte(&p) & 1);
            break;
        case 1:
            fmi2FreeInstance(x);
            c[k] = NULL;
            break;
        case 2:
            r = value(&p);
            checked(fmi2SetupExperiment(x, fmi2False, 0.0, r, fmi2False, 0.0));
            break;
        case 3:
            checked(fmi2EnterInitializationMode(x));
            break;
        case 4:
            checked(fmi2ExitInitializationMode(x));
            break;
        case 5:
            checked(fmi2Terminate(x));
            break;
        case 6:
            checked(fmi2Reset(x));
            break;
        case 7:
            vr = reference(&p);
            r = value(&p);
            checked(fmi2SetReal(x, &vr, 1, &r));
            break;
        case 8:
            vr = reference(&p);
            n = (fmi2Integer)(int8_t)byte(&p);
            checked(fmi2SetInteger(x, &vr, 1, &n));
            break;
        case 9:
            vr = reference(&p);
            b = byte(&p) & 1;
            checked(fmi2SetBoolean(x, &vr, 1, &b));
            break;
        case 10:
            if (x)
                check_outputs(x);
            break;
        case 11: /* a step from the last successful time, or from anywhere, as the budget allows */
            if (!x)
                break;
            r = value(&p);
            vr = 10;
            if (checked(fmi2GetReal(x, &vr, 1, &dt)) != fmi2OK)
                dt = 0.0;
            dt = internal_step(dt);
            r = affordable(&spent, r, dt);
            if (checked(fmi2GetRealStatus(x, fmi2LastSuccessfulTime, &now)) != fmi2OK)
                now = 0.0;
            t = now;
            if (byte(&p) & 1)
                t = value(&p);
            if (!pay(&spent, r, dt, now / dt, full_history(x)))
                break;
            steps++;
            s = checked(fmi2DoStep(x, t, r, fmi2True));
            if (s == fmi2OK)
                check_outputs(x);
            break;
        case 12:
            if (x && !state[k])
                checked(fmi2GetFMUstate(x, &state[k]));
            break;
        case 13: {
            int j = byte(&p) & 1;
            if (state[j])
                checked(fmi2SetFMUstate(x, state[j]));
            if (x)
                check_outputs(x);
            break;
        }
        case 14:
            if (x) {
                int j = byte(&p) & 1;
                checked(fmi2FreeFMUstate(x, &state[j]));
            }
            break;
        case 15: { /* serialize, if it fits the blob (a full G1 history may not) */
            size_t size = 0;
            if (x && state[k] && checked(fmi2SerializedFMUstateSize(x, state[k], &size)) == fmi2OK
                && size <= sizeof blob && checked(fmi2SerializeFMUstate(x, state[k], blob, size)) == fmi2OK)
                blob_size = size;
            break;
        }
        case 16: /* deserialize the blob, maybe mutated or cut short */
            if (x && blob_size > 0) {
                size_t at = byte(&p) % blob_size, length = blob_size;
                fmi2Byte mutated[4096];
                memcpy(mutated, blob, blob_size);
                mutated[at] ^= byte(&p);
                if (byte(&p) & 1)
                    length = at;
                if (!state[1]) {
                    s = checked(fmi2DeSerializeFMUstate(x, mutated, length, &state[1]));
                    if (s == fmi2OK) {
                        checked(fmi2SetFMUstate(x, state[1]));
                        check_outputs(x);
                    }
                }
            }
            break;
        case 17:
            vr = reference(&p);
            order = (fmi2Integer)(byte(&p) % 4);
            r = value(&p);
            checked(fmi2SetRealInputDerivatives(x, &vr, 1, &order, &r));
            break;
        case 18:
            vr = reference(&p);
            order = (fmi2Integer)(byte(&p) % 3);
            if (checked(fmi2GetRealOutputDerivatives(x, &vr, 1, &order, &r)) == fmi2OK)
                require(r - r == 0.0, "a non-finite output derivative");
            break;
        case 19: {
            const char *categories[] = {"logEvents", "logCalls", "logStatusError", "no such category"};
            checked(fmi2SetDebugLogging(x, byte(&p) & 1, byte(&p) % 5, categories));
            break;
        }
        case 20: {
            fmi2String str = "x";
            vr = reference(&p);
            checked(byte(&p) & 1 ? fmi2SetString(x, &vr, 1, &str) : fmi2GetString(x, &vr, 1, &str));
            break;
        }
        case 21: {
            fmi2Status status;
            fmi2String str;
            checked(fmi2CancelStep(x));
            checked(fmi2GetStatus(x, fmi2DoStepStatus, &status));
            checked(fmi2GetIntegerStatus(x, fmi2DoStepStatus, &n));
            checked(fmi2GetBooleanStatus(x, fmi2Terminated, &b));
            checked(fmi2GetStringStatus(x, fmi2PendingStatus, &str));
            break;
        }
        case 22:
            vr = reference(&p);
            if (checked(fmi2GetInteger(x, &vr, 1, &n)) == fmi2OK && vr == 30)
                require(n >= 1 && n <= 3, "law out of its range");
            if (checked(fmi2GetBoolean(x, &vr, 1, &b)) == fmi2OK)
                require(b == fmi2True || b == fmi2False, "a Boolean neither true nor false");
            break;
        case 23:
            if (!x)
                c[k] = fmi2Instantiate(k ? "b" : "a", fmi2ModelExchange, FMU_GUID, "", &callbacks, fmi2False,
                                       byte(&p) & 1);
            break;
        case 24: { /* a solver's evaluation: one state moved, the time set, what it reads */
            fmi2Real xs[STATES], z[INDICATORS];
            size_t at = byte(&p) % STATES;
            r = value(&p);
            t = value(&p);
            if (checked(fmi2GetContinuousStates(x, xs, STATES)) == fmi2OK) {
                xs[at] += r;
                checked(fmi2SetContinuousStates(x, xs, STATES));
            }
            checked(fmi2SetTime(x, t));
            if (checked(fmi2GetDerivatives(x, xs, STATES)) == fmi2OK)
                require_finite(xs, STATES, "derivatives");
            if (checked(fmi2GetEventIndicators(x, z, INDICATORS)) == fmi2OK)
                require_finite(z, INDICATORS, "event indicators");
            if (checked(fmi2GetNominalsOfContinuousStates(x, xs, STATES)) == fmi2OK)
                require_finite(xs, STATES, "nominals");
            if (x)
                check_outputs(x);
            break;
        }
        case 25: { /* the modes of Model Exchange */
            fmi2EventInfo info;
            switch (byte(&p) % 4) {
            case 0: checked(fmi2EnterEventMode(x)); break;
            case 1: checked(fmi2NewDiscreteStates(x, &info)); break;
            case 2: checked(fmi2EnterContinuousTimeMode(x)); break;
            default: checked(fmi2CompletedIntegratorStep(x, fmi2True, &b, &b)); break;
            }
            if (x)
                check_outputs(x);
            break;
        }
        default:
            checked(fmi2GetDirectionalDerivative(x, &vr, 1, &vr, 1, &r, &t));
            break;
        }
    }
    for (int k = 0; k < 2; k++) {
        if (c[k]) {
            fmi2FreeFMUstate(c[k], &state[0]);
            fmi2FreeFMUstate(c[k], &state[1]);
        }
    }
    free(state[0]); /* states outlive an instance freed before them */
    free(state[1]);
    fmi2FreeInstance(c[0]);
    fmi2FreeInstance(c[1]);
    return 0;
}
