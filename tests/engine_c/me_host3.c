/* An FMI 3.0 Model Exchange host in C for cam3.fmu's functions, linked with them (tests/fmi3/test_fmi3_me_host.py):
 * the scheme of me_host.c (FMI 2.0) in FMI 3.0's calls: a fixed-step explicit Euler with event handling (a sign
 * change of an indicator, or the FMU's request at fmi3CompletedIntegratorStep, enters event mode and iterates
 * fmi3UpdateDiscreteStates), a saved state serialised and restored, then the refusals.
 *
 *   me_host3 TOKEN STEP STOP [vr=value ...]     parameters by value reference (Float64; true/false; s:text)
 *   (environment CAM_FORMULATION_VR: the value reference of 'formulation', for the paper's refusal)
 *
 * Prints me_host.c's lines ("events N", "final t theta omega i", "refused ...", "paper S"); exit 0 unless a call
 * the host expects to pass fails. Built with -fsanitize=address,undefined. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi3Functions.h"

#define NX 9   /* the engine's seven slots, a free follower's gap and rate */
#define NZ 4

static void logger(fmi3InstanceEnvironment env, fmi3Status status, fmi3String category, fmi3String message)
{
    (void)env;
    if (status >= fmi3Error)
        printf("log %d %s: %s\n", (int)status, category, message);
}

static int check(fmi3Status status, const char *what)
{
    if (status != fmi3OK) {
        printf("failed %s (%d)\n", what, (int)status);
        return 0;
    }
    return 1;
}

static int set_parameter(fmi3Instance c, const char *arg)
{
    fmi3ValueReference vr = (fmi3ValueReference)strtoul(arg, NULL, 10);
    const char *value = strchr(arg, '=');
    char *end;
    fmi3Float64 r;
    if (!value)
        return 0;
    value++;
    if (strncmp(value, "s:", 2) == 0) {
        fmi3String text = value + 2;
        return fmi3SetString(c, &vr, 1, &text, 1) == fmi3OK;
    }
    if (strcmp(value, "true") == 0 || strcmp(value, "false") == 0) {
        fmi3Boolean b = value[0] == 't';
        return fmi3SetBoolean(c, &vr, 1, &b, 1) == fmi3OK;
    }
    r = strtod(value, &end);
    if (end == value || *end != '\0')
        return fmi3SetString(c, &vr, 1, &value, 1) == fmi3OK;
    return fmi3SetFloat64(c, &vr, 1, &r, 1) == fmi3OK;
}

/* fmi3UpdateDiscreteStates until no update is needed (at most 100). */
static int update(fmi3Instance c)
{
    fmi3Boolean needed = fmi3True, terminate, nominals, values, defined;
    fmi3Float64 next;
    int k = 0;
    while (needed)
        if (!check(fmi3UpdateDiscreteStates(c, &needed, &terminate, &nominals, &values, &defined, &next),
                   "fmi3UpdateDiscreteStates") || ++k > 100)
            return 0;
    return 1;
}

static int run(const char *token, double h, double stop, int argc, char **argv)
{
    fmi3Instance c = fmi3InstantiateModelExchange("me3", token, "", fmi3False, fmi3False, NULL, logger);
    double x[NX], dx[NX], z[NZ], pre[NZ], t = 0.0;
    long events = 0, steps, k;
    int i, ok;
    size_t nx = 0, nz = 0;
    fmi3Boolean enter, terminate, b;
    if (!c)
        return 0;
    ok = check(fmi3GetNumberOfContinuousStates(c, &nx), "fmi3GetNumberOfContinuousStates")
         && check(fmi3GetNumberOfEventIndicators(c, &nz), "fmi3GetNumberOfEventIndicators") && nx == NX && nz == NZ
         && check(fmi3EnterInitializationMode(c, fmi3False, 0.0, 0.0, fmi3True, stop), "fmi3EnterInitializationMode");
    for (i = 0; ok && i < argc; i++)
        ok = set_parameter(c, argv[i]);
    ok = ok && check(fmi3ExitInitializationMode(c), "fmi3ExitInitializationMode") && update(c)
         && check(fmi3EnterContinuousTimeMode(c), "fmi3EnterContinuousTimeMode")
         && check(fmi3GetEventIndicators(c, pre, NZ), "fmi3GetEventIndicators");
    steps = (long)floor(stop / h + 0.5);
    for (k = 1; ok && k <= steps; k++) {
        int crossed = 0;
        ok = check(fmi3GetContinuousStates(c, x, NX), "fmi3GetContinuousStates")
             && check(fmi3GetContinuousStateDerivatives(c, dx, NX), "fmi3GetContinuousStateDerivatives");
        for (i = 0; i < NX; i++)
            x[i] += h * dx[i];
        t = k * h;
        ok = ok && check(fmi3SetTime(c, t), "fmi3SetTime") && check(fmi3SetContinuousStates(c, x, NX),
                                                                     "fmi3SetContinuousStates")
             && check(fmi3CompletedIntegratorStep(c, fmi3True, &enter, &terminate), "fmi3CompletedIntegratorStep")
             && check(fmi3GetEventIndicators(c, z, NZ), "fmi3GetEventIndicators");
        for (i = 0; ok && i < NZ; i++)
            crossed |= (pre[i] > 0.0) != (z[i] > 0.0);
        if (ok && (crossed || enter)) {
            ok = check(fmi3EnterEventMode(c), "fmi3EnterEventMode") && update(c)
                 && check(fmi3EnterContinuousTimeMode(c), "fmi3EnterContinuousTimeMode")
                 && check(fmi3GetEventIndicators(c, z, NZ), "fmi3GetEventIndicators");
            events += 1;
        }
        memcpy(pre, z, sizeof z);
    }
    ok = ok && check(fmi3GetContinuousStates(c, x, NX), "fmi3GetContinuousStates");
    if (ok)
        printf("events %ld\nfinal %.17g %.17g %.17g %.17g\n", events, t, x[0], x[1], x[2]);
    {   /* a saved state, serialised and back, restores */
        fmi3FMUState state = NULL, back = NULL;
        size_t size = 0;
        fmi3Byte *bytes;
        ok = ok && check(fmi3GetFMUState(c, &state), "fmi3GetFMUState")
             && check(fmi3SerializedFMUStateSize(c, state, &size), "fmi3SerializedFMUStateSize");
        bytes = malloc(size ? size : 1);
        ok = ok && bytes && check(fmi3SerializeFMUState(c, state, bytes, size), "fmi3SerializeFMUState")
             && check(fmi3DeserializeFMUState(c, bytes, size, &back), "fmi3DeserializeFMUState")
             && check(fmi3SetFMUState(c, back), "fmi3SetFMUState");
        free(bytes);
        fmi3FreeFMUState(c, &state);
        fmi3FreeFMUState(c, &back);
    }
    /* refusals: a wrong count, a NULL out-argument, a co-simulation call, a non-finite time; the instance goes on */
    printf("refused %d %d %d %d\n", (int)fmi3GetContinuousStateDerivatives(c, dx, 2),
           (int)fmi3UpdateDiscreteStates(c, NULL, &b, &b, &b, &b, NULL),
           (int)fmi3DoStep(c, t, h, fmi3True, &b, &b, &b, &x[0]), (int)fmi3SetTime(c, NAN));
    ok = ok && check(fmi3Terminate(c), "fmi3Terminate");
    fmi3FreeInstance(c);
    return ok;
}

int main(int argc, char **argv)
{
    fmi3Instance c;
    if (argc < 4) {
        fprintf(stderr, "usage: me_host3 TOKEN STEP STOP [vr=value ...]\n");
        return 2;
    }
    if (!run(argv[1], strtod(argv[2], NULL), strtod(argv[3], NULL), argc - 4, argv + 4))
        return 1;
    /* the paper formulation: refused at initialisation, the instance in the error state */
    c = fmi3InstantiateModelExchange("paper", argv[1], "", fmi3False, fmi3False, NULL, logger);
    if (!c)
        return 1;
    {
        const char *formulation = getenv("CAM_FORMULATION_VR");
        fmi3ValueReference vr = (fmi3ValueReference)strtoul(formulation ? formulation : "0", NULL, 10);
        fmi3String paper = "paper";
        fmi3EnterInitializationMode(c, fmi3False, 0.0, 0.0, fmi3False, 0.0);
        if (fmi3SetString(c, &vr, 1, &paper, 1) != fmi3OK)
            return 1;
        printf("paper %d\n", (int)fmi3ExitInitializationMode(c));
    }
    fmi3FreeInstance(c);
    return 0;
}
