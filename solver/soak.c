/* fraccontact-soak: scale and endurance of the FMU (reports/reliability.py
 * runs it for docs/reliability.md, and
 * tests/test_reliability_claims.py checks its memory per instance). Prints one JSON object.
 *   fraccontact-soak instances N      N instances alive at once, each through an impact (and the
 *                                     size of the contact model an instance holds)
 *   fraccontact-soak threads T        T threads stepping their own instances at once,
 *                                     compared bit for bit with one thread
 *   fraccontact-soak steps S          S internal steps of bouncing under gravity
 *                                     (the model), resident memory sampled
 *   fraccontact-soak fmu-seconds S    S simulated seconds of bouncing, then resting on
 *                                     the specimen, through the FMU (dt_max = 1e-6 s)
 *   fraccontact-soak memory           the heap bytes an initialized instance holds and
 *                                     its serialized FMU state's, per configuration
 *   fraccontact-soak memory URI GUID  the same for an exported FMU: its resources folder's
 *                                     file: URI and its GUID (docs/export.md) */
#define _POSIX_C_SOURCE 200809L

#include <inttypes.h>
#include <malloc.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "contact.h"
#include "fmi2Functions.h"
#include "fmu_model.h" /* the value references, from parameters.def */
#include "guid.h"

static void quiet(fmi2ComponentEnvironment e, fmi2String n, fmi2Status s, fmi2String c, fmi2String m, ...)
{
    (void)e;
    (void)n;
    (void)s;
    (void)c;
    (void)m;
}

static const fmi2CallbackFunctions callbacks = {quiet, calloc, free, NULL, NULL};

static double wall_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Resident memory of this process [MiB]. */
static double resident_mib(void)
{
    long pages = 0, resident = 0;
    FILE *f = fopen("/proc/self/statm", "r");
    if (f) {
        if (fscanf(f, "%ld %ld", &pages, &resident) != 2)
            resident = 0;
        fclose(f);
    }
    return (double)resident * (double)sysconf(_SC_PAGESIZE) / 1048576.0;
}

/* An instance of the h20 drop test with dashpot c and dt_max, initialized. */
static fmi2Component drop(double c, double dt_max)
{
    fmi2ValueReference vr[] = {VR_c, VR_dt_max};
    fmi2Real v[] = {c, dt_max};
    fmi2Component x = fmi2Instantiate("soak", fmi2CoSimulation, FMU_GUID, "", &callbacks, fmi2False, fmi2False);
    if (!x || fmi2SetReal(x, vr, 2, v) != fmi2OK || fmi2EnterInitializationMode(x) != fmi2OK
        || fmi2ExitInitializationMode(x) != fmi2OK) {
        fprintf(stderr, "fraccontact-soak: an instance did not start\n");
        exit(1);
    }
    return x;
}

/* Steps an instance through its impact (2 ms) and reads F_peak, eps, x2, E_diss. */
static void impact(fmi2Component x, double out[4])
{
    fmi2ValueReference vr[] = {VR_F_peak, VR_eps, VR_x2, VR_E_diss};
    int i;
    for (i = 0; i < 200; i++)
        if (fmi2DoStep(x, i * 1e-5, 1e-5, fmi2True) != fmi2OK) {
            fprintf(stderr, "fraccontact-soak: a step failed\n");
            exit(1);
        }
    fmi2GetReal(x, vr, 4, out);
}

static int instances(long n)
{
    fmi2Component *x = malloc((size_t)n * sizeof *x);
    double before = resident_mib(), alive, t0, out[4], lone[4], worst = 0.0;
    long i;
    for (i = 0; i < n; i++)
        x[i] = drop(6080.0 * (1.0 + (double)(i % 100) / 100.0), 1e-6);
    alive = resident_mib();
    t0 = wall_now();
    for (i = 0; i < n; i++) {
        impact(x[i], out);
        if (i % 997 == 0) { /* a sample against the same instance alone */
            fmi2Component y = drop(6080.0 * (1.0 + (double)(i % 100) / 100.0), 1e-6);
            impact(y, lone);
            fmi2FreeInstance(y);
            if (memcmp(out, lone, sizeof out) != 0)
                worst = 1.0;
        }
    }
    printf("{\"instances\": %ld, \"rss_before_mib\": %.1f, \"rss_alive_mib\": %.1f, \"kib_per_instance\": %.2f, "
           "\"seconds_for_all_impacts\": %.2f, \"sampled_differ_from_alone\": %s, \"bytes_contact_model\": %zu, "
           "\"max_modes\": %d}\n",
           n, before, alive, (alive - before) * 1024.0 / (double)n, wall_now() - t0, worst > 0 ? "true" : "false",
           contact_model_bytes(&(contact_model){0}), CONTACT_MAX_MODES);
    for (i = 0; i < n; i++)
        fmi2FreeInstance(x[i]);
    free(x);
    return 0;
}

enum { PER_THREAD = 16 };

typedef struct {
    int first;
    double results[PER_THREAD][4];
} work;

static void *run_work(void *arg)
{
    work *w = arg;
    int i;
    for (i = 0; i < PER_THREAD; i++) {
        fmi2Component x = drop(2000.0 + 500.0 * (w->first + i), 1e-7);
        impact(x, w->results[i]);
        fmi2FreeInstance(x);
    }
    return NULL;
}

static int threads(int t)
{
    work *together = calloc((size_t)t, sizeof *together), *alone = calloc((size_t)t, sizeof *alone);
    pthread_t *id = malloc((size_t)t * sizeof *id);
    double t0, t_alone, t_together;
    int i, same;
    for (i = 0; i < t; i++)
        together[i].first = alone[i].first = i * PER_THREAD;
    t0 = wall_now();
    for (i = 0; i < t; i++)
        run_work(&alone[i]);
    t_alone = wall_now() - t0;
    t0 = wall_now();
    for (i = 0; i < t; i++)
        pthread_create(&id[i], NULL, run_work, &together[i]);
    for (i = 0; i < t; i++)
        pthread_join(id[i], NULL);
    t_together = wall_now() - t0;
    same = 1;
    for (i = 0; i < t; i++)
        same &= memcmp(together[i].results, alone[i].results, sizeof alone[i].results) == 0;
    printf("{\"threads\": %d, \"instances\": %d, \"identical_to_one_thread\": %s, \"seconds_one_thread\": %.2f, "
           "\"seconds_threaded\": %.2f, \"cores\": %ld}\n",
           t, t * PER_THREAD, same ? "true" : "false", t_alone, t_together, sysconf(_SC_NPROCESSORS_ONLN));
    free(together);
    free(alone);
    free(id);
    return same ? 0 : 1;
}

/* Bouncing under gravity through the model, S internal steps, the resident
 * memory sampled every tenth of the run. */
static int steps(double target)
{
    contact_params p;
    contact_model cm;
    double t0 = wall_now(), rss[11], max_rss = 0.0, v0, m;
    int k = 0, i;
    contact_default_params(&p);
    p.g = 9.81;
    p.c = 1e5; /* a stiffer dashpot rebounds more: many impacts before the striker rests */
    contact_default_striker(&v0, &m);
    contact_start(&cm, &p, v0, m);
    rss[k++] = resident_mib();
    while ((double)cm.s.steps < target) {
        if (isnan(contact_advance(&cm, 1e-3))) {
            fprintf(stderr, "fraccontact-soak: the state became non-finite\n");
            return 1;
        }
        if (k < 11 && (double)cm.s.steps >= target * k / 10.0)
            rss[k++] = resident_mib();
    }
    for (i = 0; i < k; i++)
        if (rss[i] > max_rss)
            max_rss = rss[i];
    printf("{\"internal_steps\": %" PRId64 ", \"impacts\": %" PRId64 ", \"simulated_seconds\": %.3f, \"wall_seconds\": %.1f, "
           "\"rss_mib_samples\": [", cm.s.steps, cm.s.impacts, cm.s.t, wall_now() - t0);
    for (i = 0; i < k; i++)
        printf("%s%.2f", i ? ", " : "", rss[i]);
    printf("], \"rss_mib_max\": %.2f, \"state_bytes\": %lu}\n", max_rss, (unsigned long)contact_model_bytes(&cm));
    return 0;
}

/* Bouncing under gravity through the FMU, then resting in contact (the
 * dashpot creeping) for the rest of the simulated time. */
static int fmu_seconds(double seconds)
{
    fmi2ValueReference vr_in[] = {VR_g, VR_dt_max}, vr[] = {VR_eps, VR_E_diss};
    fmi2Real in[] = {9.81, 1e-6}, out[2];
    fmi2Component x = fmi2Instantiate("soak", fmi2CoSimulation, FMU_GUID, "", &callbacks, fmi2False, fmi2False);
    double t = 0.0, H = 1e-3, end = seconds, t0 = wall_now(), rss0, rss_max = 0.0;
    long n = 0;
    fmi2SetReal(x, vr_in, 2, in);
    fmi2EnterInitializationMode(x);
    fmi2ExitInitializationMode(x);
    rss0 = resident_mib();
    while (t < end) {
        if (fmi2DoStep(x, t, H, fmi2True) != fmi2OK) {
            fprintf(stderr, "fraccontact-soak: a step failed at t = %g s\n", t);
            return 1;
        }
        t = (double)++n * H;
        if (n % 1000 == 0 && resident_mib() > rss_max)
            rss_max = resident_mib();
    }
    fmi2GetReal(x, vr, 2, out);
    printf("{\"simulated_seconds\": %.1f, \"communication_steps\": %ld, \"wall_seconds\": %.1f, \"rss_mib_start\": %.2f, "
           "\"rss_mib_max\": %.2f, \"E_diss\": %.6g}\n", seconds, n, wall_now() - t0, rss0, rss_max, out[1]);
    fmi2FreeInstance(x);
    return 0;
}

/* The heap's bytes in use (malloc's own overhead of each block included). */
static size_t heap_bytes(void)
{
    return mallinfo2().uordblks;
}

/* Instances alive at once for a heap measure: malloc keeps a few freed
 * blocks of each size cached, which count as in use; spread over this many
 * instances they count for less than a byte each. */
#define MEASURED 1000

/* An instance of the FMU of `guid` (its resources folder's URI; "" for
 * none), given `ints` for damper and memory and `reals` for
 * memory_tolerance unless NULL, initialized (a warning of a value without
 * effect allowed); NULL after a message. */
static fmi2Component started(const char *guid, const char *resources, const fmi2Integer *ints,
                             const fmi2Real *reals)
{
    const fmi2ValueReference vr_int[] = {VR_damper, VR_memory}, vr_real[] = {VR_memory_tolerance};
    fmi2Component x = fmi2Instantiate("soak", fmi2CoSimulation, guid, resources, &callbacks, fmi2False, fmi2False);
    if (!x || (ints && (fmi2SetInteger(x, vr_int, 2, ints) != fmi2OK || fmi2SetReal(x, vr_real, 1, reals) != fmi2OK))
        || fmi2EnterInitializationMode(x) != fmi2OK || fmi2ExitInitializationMode(x) > fmi2Warning) {
        fprintf(stderr, "fraccontact-soak: an instance did not start\n");
        return NULL;
    }
    return x;
}

/* The heap bytes an initialized instance holds (started's arguments), with
 * MEASURED alive, and its serialized FMU state's size: 0, or 1 after a message. */
static int instance_memory(const char *guid, const char *resources, const fmi2Integer *ints, const fmi2Real *reals,
                           size_t *held, size_t *state_bytes)
{
    static fmi2Component x[MEASURED];
    fmi2FMUstate state = NULL;
    size_t before = heap_bytes(), i, n;
    for (n = 0; n < MEASURED && (x[n] = started(guid, resources, ints, reals)); n++)
        ;
    *held = (heap_bytes() - before + MEASURED / 2) / MEASURED;
    if (n == MEASURED
        && (fmi2GetFMUstate(x[0], &state) != fmi2OK || fmi2SerializedFMUstateSize(x[0], state, state_bytes) != fmi2OK))
        fprintf(stderr, "fraccontact-soak: no FMU state\n");
    fmi2FreeFMUstate(x[0], &state);
    for (i = 0; i < n; i++)
        fmi2FreeInstance(x[i]);
    return n < MEASURED || !*state_bytes;
}

/* One configuration's instance, initialized: the heap bytes it holds and
 * its serialized FMU state's size, printed with the compressed memory's
 * mode count (the model's kernel for the same parameters). */
static int configuration_memory(int damper, int memory, double memory_tolerance, const char *comma)
{
    fmi2Integer ints[] = {damper, memory};
    fmi2Real reals[] = {memory_tolerance};
    contact_params p;
    contact_model cm;
    size_t held, state_bytes = 0, modes;
    double v0, m;
    if (instance_memory(FMU_GUID, "", ints, reals, &held, &state_bytes) != 0) {
        fprintf(stderr, "fraccontact-soak: an instance (damper = %d, memory = %d) did not start\n", damper, memory);
        return 1;
    }
    contact_default_params(&p);
    p.damper = damper;
    p.memory = memory;
    p.memory_tolerance = memory_tolerance;
    contact_default_striker(&v0, &m);
    if (contact_start(&cm, &p, v0, m) != 0)
        return 1;
    modes = cm.modes.modes;
    contact_release(&cm);
    printf("{\"damper\": %d, \"memory\": %d, \"memory_tolerance\": %g, \"modes\": %zu, \"instance_bytes\": %zu, "
           "\"state_bytes\": %zu}%s", damper, memory, memory_tolerance, modes, held, state_bytes, comma);
    return 0;
}

/* An exported FMU's instance at its fixed values, initialized: the heap
 * bytes it holds and its serialized FMU state's size. */
static int exported_memory(const char *resources, const char *guid)
{
    size_t held, state_bytes = 0;
    fmi2Component first = started(guid, resources, NULL, NULL);
    if (!first)
        return 1;
    fmi2FreeInstance(first); /* the first instance's one-time allocations apart */
    if (instance_memory(guid, resources, NULL, NULL, &held, &state_bytes) != 0)
        return 1;
    printf("{\"instance_bytes\": %zu, \"state_bytes\": %zu}\n", held, state_bytes);
    return 0;
}

/* The dashpot, the springpot's full G1 history before its first step, and
 * its compressed memory at the default memory_tolerance and two others. */
static int memory_per_configuration(void)
{
    int failed;
    fmi2FreeInstance(drop(6080.0, 1e-6)); /* the first instance's one-time allocations apart */
    printf("{\"bytes_contact_model\": %zu, \"configurations\": [", sizeof(contact_model));
    failed = configuration_memory(CONTACT_DAMPER_DASHPOT, CONTACT_MEMORY_COMPRESSED, 1e-6, ", ")
             || configuration_memory(CONTACT_DAMPER_SPRINGPOT, CONTACT_MEMORY_G1, 1e-6, ", ")
             || configuration_memory(CONTACT_DAMPER_SPRINGPOT, CONTACT_MEMORY_COMPRESSED, 1e-3, ", ")
             || configuration_memory(CONTACT_DAMPER_SPRINGPOT, CONTACT_MEMORY_COMPRESSED, 1e-6, ", ")
             || configuration_memory(CONTACT_DAMPER_SPRINGPOT, CONTACT_MEMORY_COMPRESSED, 1e-10, "");
    printf("]}\n");
    return failed;
}

int main(int argc, char **argv)
{
    if (argc == 2 && strcmp(argv[1], "memory") == 0)
        return memory_per_configuration();
    if (argc == 4 && strcmp(argv[1], "memory") == 0)
        return exported_memory(argv[2], argv[3]);
    if (argc == 3 && strcmp(argv[1], "instances") == 0)
        return instances(atol(argv[2]));
    if (argc == 3 && strcmp(argv[1], "threads") == 0)
        return threads(atoi(argv[2]));
    if (argc == 3 && strcmp(argv[1], "steps") == 0)
        return steps(atof(argv[2]));
    if (argc == 3 && strcmp(argv[1], "fmu-seconds") == 0)
        return fmu_seconds(atof(argv[2]));
    fprintf(stderr, "usage: fraccontact-soak instances N | threads T | steps S | fmu-seconds S | memory [URI GUID]\n");
    return 2;
}
