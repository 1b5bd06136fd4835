/* Thread safety, as FMI promises it (instances share nothing) and the
 * library's batch relies on: both FMUs and libfraccontact, loaded as an
 * importer loads them, run in parallel threads, each thread its own
 * instances and batches, in the configurations whose code differs (the
 * dashpot's G1 and Hertz laws, error-controlled steps, the springpot's
 * compressed memory, built when an instance leaves initialization, and its
 * full G1 history). Every run's results must be the same run's alone, bit
 * for bit. CMake builds the FMUs and the library again with
 * ThreadSanitizer for this test, and runs it with halt_on_error=1: a data
 * race between the threads (such as one in a libm function with global
 * state) fails it, however the threads happened to interleave.
 *   test_threads FMI2.so FMI3.so LIBRARY.so */
#define _POSIX_C_SOURCE 200809L

#include <dlfcn.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "fmi2FunctionTypes.h"
#include "fmi3FunctionTypes.h"
#include "fmu_model.h" /* the value references */
#include "fraccontact.h"

/* Both FMUs' generated headers define FMU_GUID (no include guard). */
#include "fraccontact/guid.h"
static const char fmi2_guid[] = FMU_GUID;
#undef FMU_GUID
#include "fraccontact-fmi3/guid.h"

enum { THREADS = 8, CONFIGURATIONS = 6, STEPS = 100, OUTPUTS = 7, BATCH = CONFIGURATIONS };
#define H 2e-5 /* the communication step [s]: 100 of them take the impact past its end */

/* A configuration: parameters beyond the defaults; and the damper's
 * constant (c or c_alpha) scaled by the run's variant, so that no two runs
 * are alike. */
typedef struct {
    const char *name;
    fmi2Integer law, damper, memory;
    fmi2Real dt_max, tolerance;
} configuration;

static const configuration configurations[CONFIGURATIONS] = {
    {"dashpot, G1 law", 1, 1, 2, 1e-6, 0.0},
    {"dashpot, Hertz law", 2, 1, 2, 1e-6, 0.0},
    {"dashpot, error-controlled", 2, 1, 2, 1e-4, 1e-6},
    {"springpot, compressed memory", 1, 2, 2, 1e-6, 0.0},
    {"springpot, compressed memory, error-controlled", 2, 2, 2, 1e-4, 1e-6},
    {"springpot, full G1 history", 1, 2, 1, 1e-6, 0.0},
};

static const fmi2ValueReference integer_vr[3] = {VR_law, VR_damper, VR_memory};
static const fmi2ValueReference dashpot_vr[3] = {VR_dt_max, VR_tolerance, VR_c},
                                 springpot_vr[3] = {VR_dt_max, VR_tolerance, VR_c_alpha};
static const fmi2ValueReference output_vr[OUTPUTS] = {VR_F, VR_F_peak, VR_x1, VR_x2, VR_v_striker, VR_E_diss, VR_eps};

/* An FMU's messages, printed (a run that fails says why). */
static void logger2(fmi2ComponentEnvironment e, fmi2String n, fmi2Status s, fmi2String c, fmi2String m, ...)
{
    (void)e, (void)n, (void)s, (void)c;
    fprintf(stderr, "FMI 2.0: %s\n", m);
}

static void logger3(fmi3InstanceEnvironment e, fmi3Status s, fmi3String c, fmi3String m)
{
    (void)e, (void)s, (void)c;
    fprintf(stderr, "FMI 3.0: %s\n", m);
}

/* The functions a run calls, looked up in the loaded libraries. */
static struct {
    fmi2InstantiateTYPE *instantiate;
    fmi2SetIntegerTYPE *set_integer;
    fmi2SetRealTYPE *set_real;
    fmi2GetRealTYPE *get_real;
    fmi2EnterInitializationModeTYPE *enter;
    fmi2ExitInitializationModeTYPE *exit;
    fmi2DoStepTYPE *step;
    fmi2FreeInstanceTYPE *free;
    /* Model Exchange */
    fmi2NewDiscreteStatesTYPE *new_discrete_states;
    fmi2EnterContinuousTimeModeTYPE *enter_continuous;
    fmi2EnterEventModeTYPE *enter_event;
    fmi2SetTimeTYPE *set_time;
    fmi2GetContinuousStatesTYPE *get_states;
    fmi2SetContinuousStatesTYPE *set_states;
    fmi2GetDerivativesTYPE *get_derivatives;
    fmi2GetEventIndicatorsTYPE *get_indicators;
} fmi2;

static struct {
    fmi3InstantiateCoSimulationTYPE *instantiate;
    fmi3SetInt32TYPE *set_int32;
    fmi3SetFloat64TYPE *set_float64;
    fmi3GetFloat64TYPE *get_float64;
    fmi3EnterInitializationModeTYPE *enter;
    fmi3ExitInitializationModeTYPE *exit;
    fmi3DoStepTYPE *step;
    fmi3FreeInstanceTYPE *free;
    /* Model Exchange */
    fmi3InstantiateModelExchangeTYPE *instantiate_me;
    fmi3UpdateDiscreteStatesTYPE *update_discrete_states;
    fmi3EnterContinuousTimeModeTYPE *enter_continuous;
    fmi3EnterEventModeTYPE *enter_event;
    fmi3SetTimeTYPE *set_time;
    fmi3GetContinuousStatesTYPE *get_states;
    fmi3SetContinuousStatesTYPE *set_states;
    fmi3GetContinuousStateDerivativesTYPE *get_derivatives;
    fmi3GetEventIndicatorsTYPE *get_indicators;
} fmi3;

static struct {
    void (*params_default)(fc_params *p);
    fc_status (*run_batch)(size_t n, const fc_params *params, fc_outcome *out);
} library;

static void *symbol(void *lib, const char *name)
{
    void *f = lib ? dlsym(lib, name) : NULL;
    if (!f) {
        fprintf(stderr, "test_threads: %s not found (%s)\n", name, dlerror());
        exit(1);
    }
    return f;
}

static void load(const char *fmi2_path, const char *fmi3_path, const char *library_path)
{
    void *a = dlopen(fmi2_path, RTLD_NOW | RTLD_LOCAL), *b = dlopen(fmi3_path, RTLD_NOW | RTLD_LOCAL),
         *c = dlopen(library_path, RTLD_NOW | RTLD_LOCAL);
    *(void **)&fmi2.instantiate = symbol(a, "fmi2Instantiate");
    *(void **)&fmi2.set_integer = symbol(a, "fmi2SetInteger");
    *(void **)&fmi2.set_real = symbol(a, "fmi2SetReal");
    *(void **)&fmi2.get_real = symbol(a, "fmi2GetReal");
    *(void **)&fmi2.enter = symbol(a, "fmi2EnterInitializationMode");
    *(void **)&fmi2.exit = symbol(a, "fmi2ExitInitializationMode");
    *(void **)&fmi2.step = symbol(a, "fmi2DoStep");
    *(void **)&fmi2.free = symbol(a, "fmi2FreeInstance");
    *(void **)&fmi2.new_discrete_states = symbol(a, "fmi2NewDiscreteStates");
    *(void **)&fmi2.enter_continuous = symbol(a, "fmi2EnterContinuousTimeMode");
    *(void **)&fmi2.enter_event = symbol(a, "fmi2EnterEventMode");
    *(void **)&fmi2.set_time = symbol(a, "fmi2SetTime");
    *(void **)&fmi2.get_states = symbol(a, "fmi2GetContinuousStates");
    *(void **)&fmi2.set_states = symbol(a, "fmi2SetContinuousStates");
    *(void **)&fmi2.get_derivatives = symbol(a, "fmi2GetDerivatives");
    *(void **)&fmi2.get_indicators = symbol(a, "fmi2GetEventIndicators");
    *(void **)&fmi3.instantiate = symbol(b, "fmi3InstantiateCoSimulation");
    *(void **)&fmi3.set_int32 = symbol(b, "fmi3SetInt32");
    *(void **)&fmi3.set_float64 = symbol(b, "fmi3SetFloat64");
    *(void **)&fmi3.get_float64 = symbol(b, "fmi3GetFloat64");
    *(void **)&fmi3.enter = symbol(b, "fmi3EnterInitializationMode");
    *(void **)&fmi3.exit = symbol(b, "fmi3ExitInitializationMode");
    *(void **)&fmi3.step = symbol(b, "fmi3DoStep");
    *(void **)&fmi3.free = symbol(b, "fmi3FreeInstance");
    *(void **)&fmi3.instantiate_me = symbol(b, "fmi3InstantiateModelExchange");
    *(void **)&fmi3.update_discrete_states = symbol(b, "fmi3UpdateDiscreteStates");
    *(void **)&fmi3.enter_continuous = symbol(b, "fmi3EnterContinuousTimeMode");
    *(void **)&fmi3.enter_event = symbol(b, "fmi3EnterEventMode");
    *(void **)&fmi3.set_time = symbol(b, "fmi3SetTime");
    *(void **)&fmi3.get_states = symbol(b, "fmi3GetContinuousStates");
    *(void **)&fmi3.set_states = symbol(b, "fmi3SetContinuousStates");
    *(void **)&fmi3.get_derivatives = symbol(b, "fmi3GetContinuousStateDerivatives");
    *(void **)&fmi3.get_indicators = symbol(b, "fmi3GetEventIndicators");
    *(void **)&library.params_default = symbol(c, "fc_params_default");
    *(void **)&library.run_batch = symbol(c, "fc_run_batch");
}

/* A run: which interface (2, 3: an FMU; 0: a batch of every configuration
 * through the library), its configuration and variant, and its results
 * (the outputs after each communication step, or the batch's outcomes). */
typedef struct {
    int fmi, config, variant, failed;
    double outputs[STEPS][OUTPUTS];
    fc_outcome outcomes[BATCH];
} run;

/* The scale of the damper's constant in a variant. */
static double scale(int variant)
{
    return 1.0 + 0.1 * variant;
}

/* A run's real parameters, and their value references. */
static const fmi2ValueReference *real_parameters(const run *r, fmi2Real real[3])
{
    const configuration *c = &configurations[r->config];
    real[0] = c->dt_max;
    real[1] = c->tolerance;
    real[2] = (c->damper == 1 ? 6080.0 : 3e5) * scale(r->variant);
    return c->damper == 1 ? dashpot_vr : springpot_vr;
}

static void run_fmi2(run *r)
{
    const configuration *c = &configurations[r->config];
    const fmi2CallbackFunctions callbacks = {logger2, calloc, free, NULL, NULL};
    const fmi2Integer integer[3] = {c->law, c->damper, c->memory};
    fmi2Real real[3];
    const fmi2ValueReference *real_vr = real_parameters(r, real);
    fmi2Component x = fmi2.instantiate("threads", fmi2CoSimulation, fmi2_guid, "", &callbacks, fmi2False, fmi2False);
    int i;
    r->failed = !x || fmi2.set_integer(x, integer_vr, 3, integer) != fmi2OK || fmi2.set_real(x, real_vr, 3, real) != fmi2OK
                || fmi2.enter(x) != fmi2OK || fmi2.exit(x) != fmi2OK;
    for (i = 0; i < STEPS && !r->failed; i++)
        r->failed = fmi2.step(x, i * H, H, fmi2True) != fmi2OK || fmi2.get_real(x, output_vr, OUTPUTS, r->outputs[i]) != fmi2OK;
    if (x)
        fmi2.free(x);
}

/* Model Exchange through FMI 2.0 (the configurations of law 2 with the
 * dashpot): the host's solver here explicit Euler steps of H / ME_STEPS,
 * an event where an indicator changes sign. */
enum { ME_STATES = 164, ME_INDICATORS = 2, ME_STEPS = 200 };

static int me_step(fmi2Component x, double t, double *states, double *z)
{
    double rates[ME_STATES], next[ME_INDICATORS];
    fmi2EventInfo info;
    int i, event = 0;
    if (fmi2.get_derivatives(x, rates, ME_STATES) != fmi2OK)
        return -1;
    for (i = 0; i < ME_STATES; i++)
        states[i] += H / ME_STEPS * rates[i];
    if (fmi2.set_time(x, t) != fmi2OK || fmi2.set_states(x, states, ME_STATES) != fmi2OK
        || fmi2.get_indicators(x, next, ME_INDICATORS) != fmi2OK)
        return -1;
    for (i = 0; i < ME_INDICATORS; i++)
        event |= (next[i] > 0.0) != (z[i] > 0.0);
    if (event && (fmi2.enter_event(x) != fmi2OK || fmi2.new_discrete_states(x, &info) != fmi2OK
                  || fmi2.enter_continuous(x) != fmi2OK || fmi2.get_indicators(x, next, ME_INDICATORS) != fmi2OK))
        return -1;
    memcpy(z, next, sizeof next);
    return 0;
}

static void run_fmi2_me(run *r)
{
    const configuration *c = &configurations[r->config];
    const fmi2CallbackFunctions callbacks = {logger2, calloc, free, NULL, NULL};
    const fmi2Integer integer[3] = {c->law, c->damper, c->memory};
    fmi2Real real[3];
    const fmi2ValueReference *real_vr = real_parameters(r, real);
    fmi2Component x = fmi2.instantiate("threads", fmi2ModelExchange, fmi2_guid, "", &callbacks, fmi2False, fmi2False);
    double states[ME_STATES], z[ME_INDICATORS];
    fmi2EventInfo info;
    int i, j;
    r->failed = !x || fmi2.set_integer(x, integer_vr, 3, integer) != fmi2OK || fmi2.set_real(x, real_vr, 3, real) != fmi2OK
                || fmi2.enter(x) != fmi2OK || fmi2.exit(x) != fmi2OK || fmi2.new_discrete_states(x, &info) != fmi2OK
                || fmi2.enter_continuous(x) != fmi2OK || fmi2.get_states(x, states, ME_STATES) != fmi2OK
                || fmi2.get_indicators(x, z, ME_INDICATORS) != fmi2OK;
    for (i = 0; i < STEPS && !r->failed; i++) {
        for (j = 1; j <= ME_STEPS && !r->failed; j++)
            r->failed = me_step(x, i * H + j * (H / ME_STEPS), states, z) != 0;
        r->failed = r->failed || fmi2.get_real(x, output_vr, OUTPUTS, r->outputs[i]) != fmi2OK;
    }
    if (x)
        fmi2.free(x);
}

static void run_fmi3(run *r)
{
    const configuration *c = &configurations[r->config];
    const fmi3Int32 integer[3] = {c->law, c->damper, c->memory};
    fmi3Float64 real[3], last;
    const fmi3ValueReference *real_vr = real_parameters(r, real);
    fmi3Boolean event, terminate, early;
    fmi3Instance x = fmi3.instantiate("threads", FMU_GUID, NULL, fmi3False, fmi3False, fmi3False, fmi3False, NULL, 0,
                                      NULL, logger3, NULL);
    int i;
    r->failed = !x || fmi3.set_int32(x, integer_vr, 3, integer, 3) != fmi3OK
                || fmi3.set_float64(x, real_vr, 3, real, 3) != fmi3OK
                || fmi3.enter(x, fmi3False, 0.0, 0.0, fmi3False, 0.0) != fmi3OK || fmi3.exit(x) != fmi3OK;
    for (i = 0; i < STEPS && !r->failed; i++)
        r->failed = fmi3.step(x, i * H, H, fmi3True, &event, &terminate, &early, &last) != fmi3OK
                    || fmi3.get_float64(x, output_vr, OUTPUTS, r->outputs[i], OUTPUTS) != fmi3OK;
    if (x)
        fmi3.free(x);
}

/* Model Exchange through FMI 3.0, as me_step and run_fmi2_me do through 2.0. */
static int update_discrete_states3(fmi3Instance x)
{
    fmi3Boolean again = fmi3True, terminate, nominals, values, next_defined;
    fmi3Float64 next;
    int rounds;
    for (rounds = 0; again && rounds < 10; rounds++)
        if (fmi3.update_discrete_states(x, &again, &terminate, &nominals, &values, &next_defined, &next) != fmi3OK)
            return -1;
    return again ? -1 : 0;
}

static int me_step3(fmi3Instance x, double t, double *states, double *z)
{
    double rates[ME_STATES], next[ME_INDICATORS];
    int i, event = 0;
    if (fmi3.get_derivatives(x, rates, ME_STATES) != fmi3OK)
        return -1;
    for (i = 0; i < ME_STATES; i++)
        states[i] += H / ME_STEPS * rates[i];
    if (fmi3.set_time(x, t) != fmi3OK || fmi3.set_states(x, states, ME_STATES) != fmi3OK
        || fmi3.get_indicators(x, next, ME_INDICATORS) != fmi3OK)
        return -1;
    for (i = 0; i < ME_INDICATORS; i++)
        event |= (next[i] > 0.0) != (z[i] > 0.0);
    if (event && (fmi3.enter_event(x) != fmi3OK || update_discrete_states3(x) != 0
                  || fmi3.enter_continuous(x) != fmi3OK || fmi3.get_indicators(x, next, ME_INDICATORS) != fmi3OK))
        return -1;
    memcpy(z, next, sizeof next);
    return 0;
}

static void run_fmi3_me(run *r)
{
    const configuration *c = &configurations[r->config];
    const fmi3Int32 integer[3] = {c->law, c->damper, c->memory};
    fmi3Float64 real[3];
    const fmi3ValueReference *real_vr = real_parameters(r, real);
    fmi3Instance x = fmi3.instantiate_me("threads", FMU_GUID, NULL, fmi3False, fmi3False, NULL, logger3);
    double states[ME_STATES], z[ME_INDICATORS];
    int i, j;
    r->failed = !x || fmi3.set_int32(x, integer_vr, 3, integer, 3) != fmi3OK
                || fmi3.set_float64(x, real_vr, 3, real, 3) != fmi3OK
                || fmi3.enter(x, fmi3False, 0.0, 0.0, fmi3False, 0.0) != fmi3OK || fmi3.exit(x) != fmi3OK
                || update_discrete_states3(x) != 0 || fmi3.enter_continuous(x) != fmi3OK
                || fmi3.get_states(x, states, ME_STATES) != fmi3OK || fmi3.get_indicators(x, z, ME_INDICATORS) != fmi3OK;
    for (i = 0; i < STEPS && !r->failed; i++) {
        for (j = 1; j <= ME_STEPS && !r->failed; j++)
            r->failed = me_step3(x, i * H + j * (H / ME_STEPS), states, z) != 0;
        r->failed = r->failed || fmi3.get_float64(x, output_vr, OUTPUTS, r->outputs[i], OUTPUTS) != fmi3OK;
    }
    if (x)
        fmi3.free(x);
}

static void run_batch(run *r)
{
    fc_params p[BATCH];
    int i;
    for (i = 0; i < BATCH; i++) {
        const configuration *c = &configurations[i];
        library.params_default(&p[i]);
        p[i].model.law = c->law;
        p[i].model.damper = c->damper;
        p[i].model.memory = c->memory;
        p[i].model.dt_max = c->dt_max;
        p[i].model.tolerance = c->tolerance;
        p[i].model.c *= scale(r->variant);
        p[i].model.c_alpha *= scale(r->variant);
    }
    r->failed = library.run_batch(BATCH, p, r->outcomes) != FC_OK;
}

static void perform(run *r)
{
    memset(r->outputs, 0, sizeof r->outputs);
    memset(r->outcomes, 0, sizeof r->outcomes);
    if (r->fmi == 2)
        run_fmi2(r);
    else if (r->fmi == 4)
        run_fmi2_me(r);
    else if (r->fmi == 3)
        run_fmi3(r);
    else if (r->fmi == 5)
        run_fmi3_me(r);
    else
        run_batch(r);
}

/* Every FMU configuration in both versions, batches, and Model Exchange
 * (fmi = 4: FMI 2.0, 5: FMI 3.0) of the two configurations from ME_FIRST
 * on, in two variants: RUNS runs, shared out among the threads. */
enum { ME_FIRST = 1, ME_CONFIGURATIONS = 2, PER_VARIANT = 2 * CONFIGURATIONS + 1 + 2 * ME_CONFIGURATIONS,
       RUNS = 2 * PER_VARIANT };
static run alone[RUNS], threaded[RUNS];

static void describe(run *r, int k)
{
    r->variant = k / PER_VARIANT;
    k %= PER_VARIANT;
    if (k > 2 * CONFIGURATIONS) {
        k -= 2 * CONFIGURATIONS + 1;
        r->fmi = 4 + k / ME_CONFIGURATIONS;
        r->config = ME_FIRST + k % ME_CONFIGURATIONS;
        return;
    }
    r->fmi = k == 2 * CONFIGURATIONS ? 0 : 2 + k / CONFIGURATIONS;
    r->config = k % CONFIGURATIONS;
}

static void *thread_main(void *arg)
{
    const int first = (int)(size_t)arg;
    int k;
    for (k = first; k < RUNS; k += THREADS)
        perform(&threaded[k]);
    return NULL;
}

int main(int argc, char **argv)
{
    pthread_t threads[THREADS];
    int k;
    if (argc != 4) {
        fprintf(stderr, "usage: test_threads FMI2.so FMI3.so LIBRARY.so\n");
        return 2;
    }
    load(argv[1], argv[2], argv[3]);
    for (k = 0; k < RUNS; k++) {
        describe(&alone[k], k);
        describe(&threaded[k], k);
        perform(&alone[k]);
    }
    for (k = 0; k < THREADS; k++)
        CHECK(pthread_create(&threads[k], NULL, thread_main, (void *)(size_t)k) == 0, "thread %d", k);
    for (k = 0; k < THREADS; k++)
        pthread_join(threads[k], NULL);
    for (k = 0; k < RUNS; k++) {
        const run *a = &alone[k], *t = &threaded[k];
        const char *via = a->fmi == 2   ? "FMI 2.0"
                          : a->fmi == 3 ? "FMI 3.0"
                          : a->fmi == 4 ? "FMI 2.0 Model Exchange"
                          : a->fmi == 5 ? "FMI 3.0 Model Exchange"
                                        : "the library",
                   *what = a->fmi ? configurations[a->config].name : "a batch of every configuration";
        CHECK(!a->failed && !t->failed, "%s, %s, variant %d: a run failed", via, what, a->variant);
        CHECK(memcmp(a->outputs, t->outputs, sizeof a->outputs) == 0
                  && memcmp(a->outcomes, t->outcomes, sizeof a->outcomes) == 0,
              "%s, %s, variant %d: in a thread, results not those of the run alone", via, what, a->variant);
        if (a->fmi >= 4) { /* the impact ended, eps within Euler's first-order error (h = 1e-7 s) of co-simulation's */
            const run *cs = &alone[a->variant * PER_VARIANT + a->config];
            const double eps = a->outputs[STEPS - 1][OUTPUTS - 1], cs_eps = cs->outputs[STEPS - 1][OUTPUTS - 1];
            CHECK(eps > 0.0 && fabs(eps / cs_eps - 1.0) < 2e-3, "%s, %s, variant %d: eps %.9g, co-simulation's %.9g",
                  via, what, a->variant, eps, cs_eps);
        }
    }
    return check_summary("test_threads");
}
