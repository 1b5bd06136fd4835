/* A master in miniature: loads the contact FMU's binary from an unpacked
 * FMU's binaries/ folder by its path (dlopen, LoadLibrary on Windows), runs
 * the default experiment (the h20 drop test: 3 ms in communication steps of
 * 10 us) and prints the results with every digit. Built for Linux and for
 * Windows, so that the test windows_matches_linux can compare the two
 * binaries through their exported functions alone, as a user's tool sees them.
 *   fmu_importer path/to/binaries/<platform>/fraccontact.{so,dll}  */
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

int main(int argc, char **argv)
{
    const fmi2CallbackFunctions callbacks = {logger, calloc, free, NULL, NULL};
    const double stop = 3e-3, h = 1e-5;
    const fmi2ValueReference vr_F_avg = VR_F_avg, vr_contact = VR_contact;
    const fmi2ValueReference vr_end[] = {VR_F_peak, VR_eps, VR_E_diss, VR_x2, VR_v_striker};
    const char *names[] = {"F_peak", "eps", "E_diss", "x2", "v_striker"};
    const char *binary;
    double end[sizeof vr_end / sizeof vr_end[0]], impulse = 0.0, t_first = -1.0, t_last = -1.0;
    long i, steps = (long)(stop / h + 0.5);
    size_t k;
    fmi2Component c;

    if (argc != 2) {
        fprintf(stderr, "usage: fmu_importer path/to/binaries/<platform>/fraccontact.{so,dll}\n");
        return 2;
    }
    binary = argv[1];
    c = LOAD(fmi2Instantiate)("importer", fmi2CoSimulation, FMU_GUID, "", &callbacks, fmi2False, fmi2False);
    if (!c) {
        fprintf(stderr, "fmu_importer: fmi2Instantiate failed\n");
        return 1;
    }
    ok(LOAD(fmi2SetupExperiment)(c, fmi2False, 0.0, 0.0, fmi2True, stop), "fmi2SetupExperiment");
    ok(LOAD(fmi2EnterInitializationMode)(c), "fmi2EnterInitializationMode");
    ok(LOAD(fmi2ExitInitializationMode)(c), "fmi2ExitInitializationMode");
    for (i = 0; i < steps; i++) {
        double t = (double)i * h, F_avg;
        fmi2Boolean contact;
        ok(LOAD(fmi2DoStep)(c, t, h, fmi2True), "fmi2DoStep");
        ok(LOAD(fmi2GetReal)(c, &vr_F_avg, 1, &F_avg), "fmi2GetReal");
        ok(LOAD(fmi2GetBoolean)(c, &vr_contact, 1, &contact), "fmi2GetBoolean");
        impulse += F_avg * h;
        if (contact) {
            if (t_first < 0.0)
                t_first = t + h;
            t_last = t + h;
        }
    }
    ok(LOAD(fmi2GetReal)(c, vr_end, sizeof vr_end / sizeof vr_end[0], end), "fmi2GetReal");
    ok(LOAD(fmi2Terminate)(c), "fmi2Terminate");
    LOAD(fmi2FreeInstance)(c);

    for (k = 0; k < sizeof end / sizeof end[0]; k++)
        printf("%s %.17g\n", names[k], end[k]);
    printf("impulse %.17g\nt_contact_first %.17g\nt_contact_last %.17g\n", impulse, t_first, t_last);
    return 0;
}
