/* A master in miniature: loads the contact FMU's binary from an unpacked
 * FMU's binaries/ folder by its path (dlopen, LoadLibrary on Windows), runs
 * the default experiment (the h20 drop test: 3 ms in communication steps of
 * 10 us) and prints the results with every digit. Built for Linux and for
 * Windows, so that the test windows_matches_linux can compare the two
 * binaries through their exported functions alone, as a user's tool sees them.
 * REPEATS runs the experiment that many times, each in a new instance, and
 * prints the last one's results (tests/instruction_counts.py counts a run's
 * instructions as the difference of two such counts). RESOURCES and GUID
 * instantiate an exported FMU: its resources folder's file: URI and its GUID
 * (tests/windows_fmu.py same-exported-results).
 *   fmu_importer path/to/binaries/<platform>/fraccontact.{so,dll} [REPEATS [RESOURCES GUID]]  */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef _WIN32
#include <windows.h>
#else
#include <dlfcn.h>
#endif

#include "fmi2FunctionTypes.h"
#include "fmu_model.h" /* the value references */
#include "guid.h"

/* Every function pointer converts to and from this one without a warning. */
typedef void (*any_function)(void);

static any_function load(const char *binary, const char *name)
{
    static void *library;
    any_function f = NULL;
#ifdef _WIN32
    if (!library)
        library = (void *)LoadLibraryA(binary);
    if (library)
        f = (any_function)GetProcAddress((HMODULE)library, name);
#else
    if (!library)
        library = dlopen(binary, RTLD_NOW | RTLD_LOCAL);
    if (library) {
        void *symbol = dlsym(library, name);
        memcpy(&f, &symbol, sizeof f); /* ISO C has no cast from void * to a function */
    }
#endif
    if (!f) {
        fprintf(stderr, "fmu_importer: %s: cannot load %s\n", binary, library ? name : "the library");
        exit(1);
    }
    return f;
}

static void logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status,
                   fmi2String category, fmi2String message, ...)
{
    va_list args;
    (void)env;
    (void)category;
    va_start(args, message);
    fprintf(stderr, "%s (status %d): ", name, (int)status);
    vfprintf(stderr, message, args);
    fputc('\n', stderr);
    va_end(args);
}

static void ok(fmi2Status status, const char *call)
{
    if (status != fmi2OK) {
        fprintf(stderr, "fmu_importer: %s returned status %d\n", call, (int)status);
        exit(1);
    }
}

#define LOAD(name) ((name##TYPE *)load(binary, #name))

#define STOP 3e-3
#define H 1e-5
#define OUTPUTS 5

/* The default experiment in a new instance: the outputs at its end, the
 * impulse of F_avg, and the first and the last communication point in
 * contact (-1: none). */
static void experiment(const char *binary, const char *resources, const char *guid, double end[OUTPUTS],
                       double *impulse, double *t_first, double *t_last)
{
    const fmi2CallbackFunctions callbacks = {logger, calloc, free, NULL, NULL};
    const fmi2ValueReference vr_F_avg = VR_F_avg, vr_contact = VR_contact;
    const fmi2ValueReference vr_end[OUTPUTS] = {VR_F_peak, VR_eps, VR_E_diss, VR_x2, VR_v_striker};
    long i, steps = (long)(STOP / H + 0.5);
    fmi2Component c = LOAD(fmi2Instantiate)("importer", fmi2CoSimulation, guid, resources, &callbacks, fmi2False,
                                            fmi2False);
    if (!c) {
        fprintf(stderr, "fmu_importer: fmi2Instantiate failed\n");
        exit(1);
    }
    *impulse = 0.0;
    *t_first = *t_last = -1.0;
    ok(LOAD(fmi2SetupExperiment)(c, fmi2False, 0.0, 0.0, fmi2True, STOP), "fmi2SetupExperiment");
    ok(LOAD(fmi2EnterInitializationMode)(c), "fmi2EnterInitializationMode");
    ok(LOAD(fmi2ExitInitializationMode)(c), "fmi2ExitInitializationMode");
    for (i = 0; i < steps; i++) {
        double t = (double)i * H, F_avg;
        fmi2Boolean contact;
        ok(LOAD(fmi2DoStep)(c, t, H, fmi2True), "fmi2DoStep");
        ok(LOAD(fmi2GetReal)(c, &vr_F_avg, 1, &F_avg), "fmi2GetReal");
        ok(LOAD(fmi2GetBoolean)(c, &vr_contact, 1, &contact), "fmi2GetBoolean");
        *impulse += F_avg * H;
        if (contact) {
            if (*t_first < 0.0)
                *t_first = t + H;
            *t_last = t + H;
        }
    }
    ok(LOAD(fmi2GetReal)(c, vr_end, OUTPUTS, end), "fmi2GetReal");
    ok(LOAD(fmi2Terminate)(c), "fmi2Terminate");
    LOAD(fmi2FreeInstance)(c);
}

int main(int argc, char **argv)
{
    const char *names[OUTPUTS] = {"F_peak", "eps", "E_diss", "x2", "v_striker"};
    double end[OUTPUTS], impulse, t_first, t_last;
    long repeats = argc >= 3 ? atol(argv[2]) : 1, r;
    const char *resources = argc == 5 ? argv[3] : "", *guid = argc == 5 ? argv[4] : FMU_GUID;
    size_t k;

    if ((argc != 2 && argc != 3 && argc != 5) || repeats < 1) {
        fprintf(stderr, "usage: fmu_importer path/to/binaries/<platform>/fraccontact.{so,dll} [REPEATS [RESOURCES "
                        "GUID]]\n");
        return 2;
    }
    for (r = 0; r < repeats; r++)
        experiment(argv[1], resources, guid, end, &impulse, &t_first, &t_last);
    for (k = 0; k < OUTPUTS; k++)
        printf("%s %.17g\n", names[k], end[k]);
    printf("impulse %.17g\nt_contact_first %.17g\nt_contact_last %.17g\n", impulse, t_first, t_last);
    return 0;
}
