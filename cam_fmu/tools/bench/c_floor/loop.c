/* The bench's C host: per-step cost of an FMU's fmi2DoStep plus fmi2GetReal of two outputs, in a tight loop.
 *
 *   loop BINARY.so RESOURCES_DIR GUID STEPS H VR1 VR2 ROUNDS
 *
 * dlopen the binary, instantiate, initialise, then ROUNDS times: STEPS steps of H s each followed by one
 * fmi2GetReal of VR1 and VR2, timed with CLOCK_MONOTONIC; a fresh instance per round. Prints one JSON
 * line: the best round's ns per step and the last values read. C99 with POSIX dlopen/clock_gettime. */
#define _POSIX_C_SOURCE 200809L
#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "fmi2Functions.h"

static void logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status, fmi2String category,
                   fmi2String message, ...)
{
    (void)env;
    (void)name;
    if (status >= fmi2Warning)
        fprintf(stderr, "[%s] %s\n", category ? category : "", message ? message : "");
}

#define LOAD(name) fmi2##name##TYPE *name = (fmi2##name##TYPE *)dlsym(lib, "fmi2" #name)

int main(int argc, char **argv)
{
    void *lib;
    long steps, rounds, k, r;
    double h, best = -1.0, values[2] = {0.0, 0.0};
    fmi2ValueReference vrs[2];
    fmi2CallbackFunctions callbacks = {logger, calloc, free, NULL, NULL};
    char uri[4096];
    if (argc != 9) {
        fprintf(stderr, "usage: loop BINARY RESOURCES GUID STEPS H VR1 VR2 ROUNDS\n");
        return 2;
    }
    lib = dlopen(argv[1], RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
        fprintf(stderr, "%s\n", dlerror());
        return 1;
    }
    steps = atol(argv[4]);
    h = strtod(argv[5], NULL);
    vrs[0] = (fmi2ValueReference)atol(argv[6]);
    vrs[1] = (fmi2ValueReference)atol(argv[7]);
    rounds = atol(argv[8]);
    snprintf(uri, sizeof uri, "file://%s", argv[2]);
    {
        LOAD(Instantiate);
        LOAD(SetupExperiment);
        LOAD(EnterInitializationMode);
        LOAD(ExitInitializationMode);
        LOAD(DoStep);
        LOAD(GetReal);
        LOAD(FreeInstance);
        if (!Instantiate || !SetupExperiment || !EnterInitializationMode || !ExitInitializationMode || !DoStep
            || !GetReal || !FreeInstance) {
            fprintf(stderr, "an FMI function is missing\n");
            return 1;
        }
        for (r = 0; r < rounds; r++) {
            struct timespec a, b;
            double t = 0.0, ns;
            fmi2Component c = Instantiate("loop", fmi2CoSimulation, argv[3], uri, &callbacks, fmi2False, fmi2False);
            if (!c || SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0) != fmi2OK
                || EnterInitializationMode(c) != fmi2OK || ExitInitializationMode(c) != fmi2OK) {
                fprintf(stderr, "instantiation or initialisation failed\n");
                return 1;
            }
            clock_gettime(CLOCK_MONOTONIC, &a);
            for (k = 0; k < steps; k++) {
                if (DoStep(c, t, h, fmi2True) != fmi2OK || GetReal(c, vrs, 2, values) != fmi2OK) {
                    fprintf(stderr, "step %ld failed\n", k);
                    return 1;
                }
                t = (double)(k + 1) * h;
            }
            clock_gettime(CLOCK_MONOTONIC, &b);
            ns = ((double)(b.tv_sec - a.tv_sec) * 1e9 + (double)(b.tv_nsec - a.tv_nsec)) / (double)steps;
            if (best < 0.0 || ns < best)
                best = ns;
            FreeInstance(c);
        }
    }
    printf("{\"ns_per_step\": %.3f, \"values\": [%.17g, %.17g]}\n", best, values[0], values[1]);
    dlclose(lib);
    return 0;
}
