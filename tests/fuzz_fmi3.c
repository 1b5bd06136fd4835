/* Fuzzing the FMI 3.0 API as fuzz_fmi2.c fuzzes FMI 2.0: a byte string read
 * as a program of FMI 3.0 calls with their values, on two instances at
 * once, each made with or without event mode, early return and the
 * intermediate update callback. After every call: the status is one the
 * standard allows; readable outputs are finite with F >= 0; a DoStep that
 * succeeds reports a lastSuccessfulTime inside its step, early return only
 * when allowed and exactly when it stopped short, event handling only with
 * event mode; a refused DoStep changes nothing; an FMU state that is taken
 * back reads out as the same bytes. A broken invariant aborts, which the
 * fuzzer (libFuzzer, or the replay driver fuzz_replay.c in every build)
 * reports as a crash.
 *
 * The program: each call takes an opcode byte (its top bit picks the
 * instance) and then the bytes its arguments need; a value byte picks from
 * a table of interesting numbers or, with its top bit set, reads the next 8
 * bytes as a raw double. Running out of bytes ends the program. Both
 * interfaces: an instance for Model Exchange takes the solver's calls
 * (states, time, derivatives, event indicators, nominals, the modes), and
 * the derivatives, indicators and nominals it gives must be finite. The
 * seeds, tests/fuzz_corpus/fmi3_*.bin, are written by tests/fuzz_seeds.py. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi3Functions.h"
#include "fuzz_program.h"
#include "guid.h"
#include "serial.h"

/* ------------------------------------------------------------- invariants */

static void require(int ok, const char *what)
{
    if (!ok) {
        fprintf(stderr, "fuzz invariant broken: %s\n", what);
        abort();
    }
}

static fmi3Status checked(fmi3Status s)
{
    require(s == fmi3OK || s == fmi3Warning || s == fmi3Discard || s == fmi3Error, "status outside the standard's");
    return s;
}

/* What an instance was made with, and the step in progress (for the
 * intermediate update callback's checks). */
typedef struct {
    fmi3Boolean event_mode_used, early_return_allowed;
    double step_start, step_end;
    int in_step, model_exchange;
} instance_info;

static void logger(fmi3InstanceEnvironment env, fmi3Status status, fmi3String category, fmi3String message)
{
    (void)env;
    require(status == fmi3OK || status == fmi3Warning || status == fmi3Error, "a log status outside the FMU's");
    require(category && message && strlen(message) < 4096, "a log message without category or text");
}

static void intermediate_update(fmi3InstanceEnvironment env, fmi3Float64 time, fmi3Boolean set_requested,
                                fmi3Boolean get_allowed, fmi3Boolean step_finished, fmi3Boolean can_return_early,
                                fmi3Boolean *early_return_requested, fmi3Float64 *early_return_time)
{
    const instance_info *info = env;
    require(info->in_step, "an intermediate update outside DoStep");
    require(time >= info->step_start && time <= info->step_end, "an intermediate update outside the step");
    require(!set_requested && !get_allowed && step_finished, "an intermediate update this FMU does not offer");
    require(can_return_early == info->early_return_allowed, "canReturnEarly is not earlyReturnAllowed");
    *early_return_requested = fmi3True; /* what a master may write; the FMU must not care */
    *early_return_time = time;
}

#define N_OUT 11
static const fmi3ValueReference outputs[N_OUT] = {13, 14, 15, 16, 17, 18, 19, 20, 21, 22, 28};

/* Every real output, when readable, is finite and the force is not tension. */
static void check_outputs(fmi3Instance c)
{
    fmi3Float64 v[N_OUT];
    fmi3ValueReference contact = 40;
    fmi3Boolean b = fmi3False;
    size_t i;
    if (checked(fmi3GetFloat64(c, outputs, N_OUT, v, N_OUT)) != fmi3OK)
        return;
    for (i = 0; i < N_OUT; i++)
        require(v[i] - v[i] == 0.0, "a non-finite output");
    require(v[0] >= 0.0 && v[2] >= 0.0, "a negative contact force");
    if (checked(fmi3GetBoolean(c, &contact, 1, &b, 1)) == fmi3OK)
        require(b == fmi3True || b == fmi3False, "a Boolean neither true nor false");
}

/* Time and every output, as bytes (0 when they cannot be read). */
typedef struct {
    int readable;
    fmi3Float64 values[N_OUT + 1];
    fmi3Boolean contact;
} snapshot;

static int same(const snapshot *a, const snapshot *b)
{
    return a->readable == b->readable && a->contact == b->contact
           && memcmp(a->values, b->values, sizeof a->values) == 0;
}

static snapshot take(fmi3Instance c)
{
    static const fmi3ValueReference time = 0, contact = 40;
    snapshot s;
    memset(&s, 0, sizeof s);
    s.readable = fmi3GetFloat64(c, outputs, N_OUT, s.values, N_OUT) == fmi3OK
                 && fmi3GetFloat64(c, &time, 1, &s.values[N_OUT], 1) == fmi3OK
                 && fmi3GetBoolean(c, &contact, 1, &s.contact, 1) == fmi3OK;
    return s;
}

/* ------------------------------------------------------------------ steps */

/* Whether the instance keeps a springpot's full G1 history (damper 2,
 * memory 1), whose steps cost O(N) each. */
static int full_history(fmi3Instance x)
{
    const fmi3ValueReference damper = 33, memory = 34;
    fmi3Int32 d = 0, m = 0;
    return fmi3GetInt32(x, &damper, 1, &d, 1) == fmi3OK && fmi3GetInt32(x, &memory, 1, &m, 1) == fmi3OK && d == 2
           && m == 1;
}

static double model_time(fmi3Instance x)
{
    const fmi3ValueReference time = 0;
    fmi3Float64 t = 0.0;
    return fmi3GetFloat64(x, &time, 1, &t, 1) == fmi3OK ? t : 0.0;
}

/* A step of H from the model's time, or from anywhere, as the input's
 * budget allows (fuzz_program.h), then checked. */
static void do_step(fmi3Instance x, instance_info *info, budget *spent, program *p)
{
    const fmi3ValueReference dt_vr = 10;
    fmi3Float64 H = value(p), dt = 0.0, now = model_time(x), t = now, last = -1.0;
    fmi3Boolean event = fmi3True, terminate = fmi3True, early = fmi3True;
    fmi3Status s;
    snapshot before;
    if (checked(fmi3GetFloat64(x, &dt_vr, 1, &dt, 1)) != fmi3OK)
        dt = 0.0;
    dt = internal_step(dt);
    H = affordable(spent, H, dt);
    if (byte(p) & 1)
        t = value(p);
    if (!pay(spent, H, dt, now / dt, full_history(x)))
        return;
    before = take(x);
    info->step_start = t;
    info->step_end = t + H;
    info->in_step = 1;
    s = checked(fmi3DoStep(x, t, H, byte(p) & 1, &event, &terminate, &early, &last));
    info->in_step = 0;
    if (s == fmi3OK || s == fmi3Warning) {
        require(!terminate, "terminateSimulation from a contact element");
        require(last >= t && last <= t + H, "lastSuccessfulTime outside the step");
        require(early == (last < t + H), "earlyReturn and lastSuccessfulTime disagree");
        require(!early || info->early_return_allowed, "an early return that was not allowed");
        require(!event || info->event_mode_used, "eventHandlingNeeded without event mode");
        require(model_time(x) == last, "the model's time is not lastSuccessfulTime");
        check_outputs(x);
    } else if (s == fmi3Error) {
        snapshot after = take(x);
        require(same(&before, &after), "a refused DoStep changed the outputs or time");
    }
}

/* ------------------------------------------------------------- FMU states */

/* A state's bytes mangled: a byte flipped or 8 bytes overwritten by a value,
 * maybe cut short, and maybe its checksum made right again (the layout of
 * fmu_instance.c: the payload's CRC-32 at 16, the payload from 20), so that
 * the model's own checks of a state are reached too. */
static size_t mangle(program *p, uint8_t *bytes, size_t size)
{
    const uint8_t how = byte(p);
    size_t at = byte(p);
    at = (at | (size_t)byte(p) << 8) % size;
    if (how & 1)
        bytes[at] ^= byte(p);
    else if (at + 8 <= size) {
        double d = value(p);
        memcpy(bytes + at, &d, 8);
    }
    if (how & 2)
        size = at;
    if ((how & 4) && size >= 20) {
        uint32_t crc = serial_crc32(bytes + 20, size - 20);
        size_t i;
        for (i = 0; i < 4; i++)
            bytes[16 + i] = (uint8_t)(crc >> (8 * i));
    }
    return size;
}

/* The instance's state as bytes into `bytes` (capacity 1 << 16); its size,
 * or 0 when it cannot be had. */
static size_t read_out(fmi3Instance x, uint8_t *bytes)
{
    fmi3FMUState state = NULL;
    size_t size = 0;
    if (checked(fmi3GetFMUState(x, &state)) != fmi3OK)
        return 0;
    if (checked(fmi3SerializedFMUStateSize(x, state, &size)) != fmi3OK || size > (1u << 16)
        || checked(fmi3SerializeFMUState(x, state, bytes, size)) != fmi3OK)
        size = 0;
    fmi3FreeFMUState(x, &state);
    return size;
}

/* A state taken back reads out as a state that, taken back, reads out the
 * same again; and as the bytes it came from if they are the FMU's own, of a
 * mode past initialization. (Before initialization ends the outputs are a
 * preview the model recomputes from the parameters, and a damaged state's
 * derived values, such as 1/m, are derived again.) */
static void check_round_trip(fmi3Instance x, const uint8_t *bytes, size_t n, int exact)
{
    static uint8_t first[1 << 16], second[1 << 16];
    fmi3FMUState state = NULL;
    size_t size = read_out(x, first), size2;
    if (size == 0)
        return;
    if (exact) /* the FMU's own state, past initialization: bit for bit */
        require(size == n && memcmp(first, bytes, n) == 0, "a state of the FMU reads out differently");
    require(checked(fmi3DeserializeFMUState(x, first, size, &state)) == fmi3OK, "a state read out is refused");
    require(checked(fmi3SetFMUState(x, state)) == fmi3OK, "a state read out cannot be set");
    fmi3FreeFMUState(x, &state);
    check_outputs(x);
    size2 = read_out(x, second);
    require(size2 == size && memcmp(first, second, size) == 0, "a state taken back reads out differently");
}

/* ------------------------------------------------------ calls that must fail */

/* A function this FMU does not support, or a getter or setter of a type it
 * has no variable of, or a good function with bad arrays: always fmi3Error. */
static void refused(fmi3Instance x, program *p)
{
    fmi3ValueReference vr = reference(p), two[2] = {1, 2};
    fmi3Float64 r[2] = {0.0, 0.0};
    fmi3UInt64 u[2] = {0, 0};
    fmi3Int32 n = 0;
    fmi3Boolean b = fmi3False;
    fmi3IntervalQualifier q;
    size_t count = 0;
    fmi3String str = "x";
    fmi3Clock clk = fmi3ClockInactive;
    fmi3Status s;
    switch (byte(p) % 24) {
    case 0: s = fmi3EnterConfigurationMode(x); break;
    case 1: s = fmi3ExitConfigurationMode(x); break;
    case 2: s = fmi3GetNumberOfVariableDependencies(x, vr, &count); break;
    case 3: s = fmi3GetDirectionalDerivative(x, &vr, 1, &vr, 1, r, 1, r + 1, 1); break;
    case 4: s = fmi3GetAdjointDerivative(x, &vr, 1, &vr, 1, r, 1, r + 1, 1); break;
    case 5: s = fmi3GetIntervalDecimal(x, &vr, 1, r, &q); break;
    case 6: s = fmi3SetShiftFraction(x, &vr, 1, u, u + 1); break;
    case 7: s = fmi3EvaluateDiscreteStates(x); break;
    case 8: s = fmi3ActivateModelPartition(x, vr, value(p)); break;
    case 9: s = fmi3EnterContinuousTimeMode(x); break;
    case 10: s = fmi3CompletedIntegratorStep(x, fmi3True, &b, &b); break;
    case 11: s = fmi3SetTime(x, value(p)); break;
    case 12: s = fmi3GetContinuousStates(x, r, 1); break;
    case 13: s = fmi3GetNumberOfEventIndicators(x, &count); break;
    case 14: s = fmi3GetString(x, &vr, 1, &str, 1); break;
    case 15: s = fmi3SetString(x, &vr, 1, &str, 1); break;
    case 16: s = fmi3GetClock(x, &vr, 1, &clk); break;
    case 17: s = fmi3SetUInt64(x, &vr, 1, u, 1); break;
    case 18: s = fmi3GetFloat64(x, two, 2, r, 1); break;         /* nValues != nvr */
    case 19: s = fmi3SetFloat64(x, two, 2, r, 3); break;
    case 20: s = fmi3SetFloat64(x, two, 2, NULL, 2); break;      /* NULL arrays */
    case 21: s = fmi3GetInt32(x, NULL, 1, &n, 1); break;
    case 22: s = fmi3SetFloat64(x, (const fmi3ValueReference[]){0}, 1, r, 1); break; /* time */
    default: s = fmi3InstantiateModelExchange("me", "{wrong}", NULL, fmi3False, fmi3False, NULL, logger) ? fmi3OK
                                                                                                        : fmi3Error;
    }
    require(checked(s) == fmi3Error, "a call that must be refused was not");
}

/* -------------------------------------------------------- Model Exchange */

/* The continuous states and event indicators of modelDescription.xml, at most. */
enum { MAX_STATES = 256, MAX_INDICATORS = 8 };

static void require_finite(const fmi3Float64 *v, size_t n, const char *what)
{
    size_t i;
    for (i = 0; i < n; i++)
        if (!(v[i] - v[i] == 0.0)) {
            fprintf(stderr, "fuzz invariant broken: a non-finite value among the %s\n", what);
            abort();
        }
}

/* A solver's evaluation: one state moved, the time set, what it reads. */
static void evaluate(fmi3Instance x, program *p)
{
    fmi3Float64 xs[MAX_STATES], z[MAX_INDICATORS];
    size_t n = 0, m = 0, at = byte(p);
    const fmi3Float64 dx = value(p), t = value(p);
    if (checked(fmi3GetNumberOfContinuousStates(x, &n)) != fmi3OK || checked(fmi3GetNumberOfEventIndicators(x, &m))
        != fmi3OK)
        return;
    require(n <= MAX_STATES && m <= MAX_INDICATORS, "more states or event indicators than the harness holds");
    if (n > 0 && checked(fmi3GetContinuousStates(x, xs, n)) == fmi3OK) {
        xs[at % n] += dx;
        checked(fmi3SetContinuousStates(x, xs, n));
    }
    checked(fmi3SetTime(x, t));
    if (checked(fmi3GetContinuousStateDerivatives(x, xs, n)) == fmi3OK)
        require_finite(xs, n, "derivatives");
    if (checked(fmi3GetEventIndicators(x, z, m)) == fmi3OK)
        require_finite(z, m, "event indicators");
    if (checked(fmi3GetNominalsOfContinuousStates(x, xs, n)) == fmi3OK)
        require_finite(xs, n, "nominals");
    check_outputs(x);
}

/* The modes of Model Exchange beside the event mode (ops 4 and 5). */
static void me_mode(fmi3Instance x, program *p)
{
    fmi3Boolean enter = fmi3False, terminate = fmi3False;
    if (byte(p) & 1)
        checked(fmi3EnterContinuousTimeMode(x));
    else
        checked(fmi3CompletedIntegratorStep(x, fmi3True, &enter, &terminate));
    check_outputs(x);
}

/* ------------------------------------------------------------------ driver */

typedef struct {
    fmi3Instance c[2];
    instance_info info[2];
    fmi3FMUState state[2];
    uint8_t blob[1 << 16];
    size_t blob_size;
    budget spent;
} world;

static void instantiate(world *w, int k, program *p)
{
    static const fmi3ValueReference one = 13;
    const uint8_t flags = byte(p);
    instance_info *info = &w->info[k];
    const char *token = flags & 0x10 ? "{wrong}" : FMU_GUID;
    if (w->c[k])
        return;
    info->model_exchange = 0;
    info->event_mode_used = (flags >> 1) & 1;
    info->early_return_allowed = (flags >> 2) & 1;
    info->in_step = 0;
    w->c[k] = fmi3InstantiateCoSimulation(flags & 0x20 ? "" : k ? "b" : "a", token, NULL, fmi3False, flags & 1,
                                          info->event_mode_used, info->early_return_allowed, &one,
                                          (flags >> 6) & 1, info, logger,
                                          flags & 8 ? intermediate_update : NULL);
    require(!w->c[k] == ((flags & 0x70) != 0), "instantiation refused or accepted wrongly");
}

static void deserialize(world *w, fmi3Instance x, program *p)
{
    static uint8_t mangled[1 << 16];
    size_t size;
    int own;
    fmi3Status s;
    if (!x || w->blob_size == 0 || w->state[1])
        return;
    memcpy(mangled, w->blob, w->blob_size);
    own = !(byte(p) & 1);
    size = own ? w->blob_size : mangle(p, mangled, w->blob_size);
    s = checked(fmi3DeserializeFMUState(x, mangled, size, &w->state[1]));
    if (s != fmi3OK)
        return;
    if (checked(fmi3SetFMUState(x, w->state[1])) == fmi3OK) {
        /* the mode (u32 at 20): 1 instantiated, 2 initialization mode */
        check_outputs(x);
        check_round_trip(x, mangled, size, own && mangled[20] > 2);
    }
}

static void run(world *w, program *p)
{
    int steps = 0;
    while (more(p, 1) && steps < 64) {
        const uint8_t op = byte(p);
        const int k = op >> 7;
        fmi3Instance x = w->c[k];
        fmi3ValueReference vr = 0;
        fmi3Float64 r = 0.0, t = 0.0;
        fmi3Int32 n = 0, order = 1;
        fmi3Boolean b[5] = {0, 0, 0, 0, 0};
        switch (op & 0x1F) {
        case 0: instantiate(w, k, p); break;
        case 1:
            fmi3FreeInstance(x);
            w->c[k] = NULL;
            break;
        case 2:
            r = value(p);
            n = byte(p) & 1;
            t = value(p);
            checked(fmi3EnterInitializationMode(x, fmi3False, 0.0, r, n, t));
            break;
        case 3: checked(fmi3ExitInitializationMode(x)); break;
        case 4: checked(fmi3EnterEventMode(x)); break;
        case 5:
            if (checked(fmi3UpdateDiscreteStates(x, &b[0], &b[1], &b[2], &b[3], &b[4], &r)) == fmi3OK) {
                require(!b[0] && !b[1] && !b[2] && !b[3] && !b[4], "an update with more to do");
                check_outputs(x);
            }
            break;
        case 6: checked(fmi3EnterStepMode(x)); break;
        case 7: checked(fmi3Terminate(x)); break;
        case 8: checked(fmi3Reset(x)); break;
        case 9:
            vr = reference(p);
            r = value(p);
            checked(fmi3SetFloat64(x, &vr, 1, &r, 1));
            break;
        case 10:
            vr = reference(p);
            n = (fmi3Int32)(int8_t)byte(p);
            checked(fmi3SetInt32(x, &vr, 1, &n, 1));
            break;
        case 11:
            vr = reference(p);
            b[0] = byte(p) & 1;
            checked(fmi3SetBoolean(x, &vr, 1, b, 1));
            break;
        case 12:
            if (x)
                check_outputs(x);
            break;
        case 13:
            if (x) {
                steps++;
                do_step(x, &w->info[k], &w->spent, p);
            }
            break;
        case 14:
            if (x && !w->state[k])
                checked(fmi3GetFMUState(x, &w->state[k]));
            break;
        case 15: {
            const int j = byte(p) & 1;
            if (x && w->state[j] && checked(fmi3SetFMUState(x, w->state[j])) == fmi3OK)
                check_outputs(x);
            break;
        }
        case 16:
            if (x)
                checked(fmi3FreeFMUState(x, &w->state[byte(p) & 1]));
            break;
        case 17: { /* serialize, if it fits the blob (a full G1 history may not) */
            size_t size = 0;
            if (x && w->state[k] && checked(fmi3SerializedFMUStateSize(x, w->state[k], &size)) == fmi3OK
                && size <= sizeof w->blob && checked(fmi3SerializeFMUState(x, w->state[k], w->blob, size)) == fmi3OK)
                w->blob_size = size;
            break;
        }
        case 18: deserialize(w, x, p); break;
        case 19:
            vr = reference(p);
            order = (fmi3Int32)(byte(p) % 3);
            if (checked(fmi3GetOutputDerivatives(x, &vr, 1, &order, &r, 1)) == fmi3OK)
                require(r - r == 0.0, "a non-finite output derivative");
            break;
        case 20: {
            const fmi3String categories[] = {"logEvents", "logCalls", "logStatusError", "no such category"};
            const fmi3Boolean on = byte(p) & 1;
            checked(fmi3SetDebugLogging(x, on, byte(p) % 5, categories));
            break;
        }
        case 21: /* the Model Exchange calls among them succeed on an instance for it */
            if (x && !w->info[k].model_exchange)
                refused(x, p);
            break;
        case 22:
            vr = reference(p);
            if (checked(fmi3GetInt32(x, &vr, 1, &n, 1)) == fmi3OK && vr == 30)
                require(n >= 1 && n <= 3, "law out of its range");
            if (checked(fmi3GetBoolean(x, &vr, 1, b, 1)) == fmi3OK)
                require(b[0] == fmi3True || b[0] == fmi3False, "a Boolean neither true nor false");
            break;
        case 23:
            if (!x) {
                w->info[k].model_exchange = 1;
                w->c[k] = fmi3InstantiateModelExchange(k ? "b" : "a", FMU_GUID, NULL, fmi3False, byte(p) & 1,
                                                       &w->info[k], logger);
                require(w->c[k] != NULL, "Model Exchange's instantiation refused");
            }
            break;
        case 24:
            if (x)
                evaluate(x, p);
            break;
        case 25:
            if (x)
                me_mode(x, p);
            break;
        default:
            checked(fmi3GetDirectionalDerivative(x, &vr, 1, &vr, 1, &r, 1, &t, 1));
            break;
        }
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static world w;
    program p = {data, data + size};
    int k;
    memset(&w, 0, sizeof w);
    run(&w, &p);
    for (k = 0; k < 2; k++)
        if (w.c[k]) {
            fmi3FreeFMUState(w.c[k], &w.state[0]);
            fmi3FreeFMUState(w.c[k], &w.state[1]);
        }
    free(w.state[0]); /* states outlive an instance freed before them */
    free(w.state[1]);
    fmi3FreeInstance(w.c[0]);
    fmi3FreeInstance(w.c[1]);
    return 0;
}
