/* A Model Exchange host in C for cam.fmu's FMI functions, linked with them (tests/fmu_me/test_engine_fmu_me_host.py):
 * a fixed-step explicit Euler with event handling (a sign change of an indicator, or the FMU's request at
 * fmi2CompletedIntegratorStep, enters event mode and iterates fmi2NewDiscreteStates), then the refusals.
 *
 *   me_host GUID STEP STOP [vr=value ...]     parameters by value reference (Real; true/false for Booleans)
 *   (environment CAM_FORMULATION_VR: the value reference of 'formulation', for the paper's refusal)
 *
 * Prints "events N", "final t theta omega i", the refusals' statuses; exit 0 unless a call the
 * host expects to pass fails. Built with -fsanitize=address,undefined or run under valgrind.
 *
 * Linked with the FMI functions (the engine's sources), or, built with -DME_HOST_DYNAMIC, loading them
 * from an FMU's binary as an importer does: the library's path in the environment variable
 * CAM_FMU_LIBRARY, dlopen on linux and LoadLibrary on Windows (cam.dll under wine). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"

#ifdef ME_HOST_DYNAMIC
#ifdef _WIN32
#include <windows.h>
#define OPEN(path) ((void *)LoadLibraryA(path))
#define SYMBOL(lib, name) ((void *)GetProcAddress((HMODULE)(lib), name))
#else
#include <dlfcn.h>
#define OPEN(path) dlopen(path, RTLD_NOW | RTLD_LOCAL)
#define SYMBOL(lib, name) dlsym(lib, name)
#endif
/* The functions this host calls, looked up by their standard names. */
#define FMI_CALLS(X) X(Instantiate) X(FreeInstance) X(SetupExperiment) X(EnterInitializationMode) \
    X(ExitInitializationMode) X(Terminate) X(SetReal) X(SetBoolean) X(SetString) X(DoStep) X(EnterEventMode) \
    X(NewDiscreteStates) X(EnterContinuousTimeMode) X(CompletedIntegratorStep) X(SetTime) X(SetContinuousStates) \
    X(GetContinuousStates) X(GetDerivatives) X(GetEventIndicators) X(GetFMUstate) X(SetFMUstate) X(FreeFMUstate) \
    X(SerializedFMUstateSize) X(SerializeFMUstate) X(DeSerializeFMUstate)
#define POINTER(name) fmi2##name##TYPE *name;
static struct { FMI_CALLS(POINTER) } fmi;   /* a test host's one table, filled once by load() */
#define LOOKUP(name) ok = ok && (*(void **)&fmi.name = SYMBOL(lib, "fmi2" #name)) != NULL;

static int load(void)
{
    const char *path = getenv("CAM_FMU_LIBRARY");
    void *lib = path ? OPEN(path) : NULL;
    int ok = lib != NULL;
    FMI_CALLS(LOOKUP)
    if (!ok)
        fprintf(stderr, "cannot load the FMI functions from CAM_FMU_LIBRARY = %s\n", path ? path : "(unset)");
    return ok;
}

#undef fmi2Instantiate
#define fmi2Instantiate fmi.Instantiate
#undef fmi2FreeInstance
#define fmi2FreeInstance fmi.FreeInstance
#undef fmi2SetupExperiment
#define fmi2SetupExperiment fmi.SetupExperiment
#undef fmi2EnterInitializationMode
#define fmi2EnterInitializationMode fmi.EnterInitializationMode
#undef fmi2ExitInitializationMode
#define fmi2ExitInitializationMode fmi.ExitInitializationMode
#undef fmi2Terminate
#define fmi2Terminate fmi.Terminate
#undef fmi2SetReal
#define fmi2SetReal fmi.SetReal
#undef fmi2SetBoolean
#define fmi2SetBoolean fmi.SetBoolean
#undef fmi2SetString
#define fmi2SetString fmi.SetString
#undef fmi2DoStep
#define fmi2DoStep fmi.DoStep
#undef fmi2EnterEventMode
#define fmi2EnterEventMode fmi.EnterEventMode
#undef fmi2NewDiscreteStates
#define fmi2NewDiscreteStates fmi.NewDiscreteStates
#undef fmi2EnterContinuousTimeMode
#define fmi2EnterContinuousTimeMode fmi.EnterContinuousTimeMode
#undef fmi2CompletedIntegratorStep
#define fmi2CompletedIntegratorStep fmi.CompletedIntegratorStep
#undef fmi2SetTime
#define fmi2SetTime fmi.SetTime
#undef fmi2SetContinuousStates
#define fmi2SetContinuousStates fmi.SetContinuousStates
#undef fmi2GetContinuousStates
#define fmi2GetContinuousStates fmi.GetContinuousStates
#undef fmi2GetDerivatives
#define fmi2GetDerivatives fmi.GetDerivatives
#undef fmi2GetEventIndicators
#define fmi2GetEventIndicators fmi.GetEventIndicators
#undef fmi2GetFMUstate
#define fmi2GetFMUstate fmi.GetFMUstate
#undef fmi2SetFMUstate
#define fmi2SetFMUstate fmi.SetFMUstate
#undef fmi2FreeFMUstate
#define fmi2FreeFMUstate fmi.FreeFMUstate
#undef fmi2SerializedFMUstateSize
#define fmi2SerializedFMUstateSize fmi.SerializedFMUstateSize
#undef fmi2SerializeFMUstate
#define fmi2SerializeFMUstate fmi.SerializeFMUstate
#undef fmi2DeSerializeFMUstate
#define fmi2DeSerializeFMUstate fmi.DeSerializeFMUstate
#else
static int load(void)
{
    return 1;
}
#endif

#define NX 9   /* the engine's seven slots, a free follower's gap and rate; a drive holds the slots it does not carry */
#define NZ 4
#define MAX_VARS 200

static void logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status, fmi2String category,
                   fmi2String message, ...)
{
    (void)env;
    (void)name;
    if (status >= fmi2Error)
        printf("log %d %s: %s\n", (int)status, category, message);
}

static const fmi2CallbackFunctions CALLBACKS = {logger, calloc, free, NULL, NULL};

static int check(fmi2Status status, const char *what)
{
    if (status != fmi2OK) {
        printf("failed %s (%d)\n", what, (int)status);
        return 0;
    }
    return 1;
}

/* A parameter by value reference: vr=value, vr=true|false, or vr=text (a string such as a closure; vr=s:text
 * sets a string that reads as a number). */
static int set_parameter(fmi2Component c, const char *arg)
{
    fmi2ValueReference vr = (fmi2ValueReference)strtoul(arg, NULL, 10);
    const char *value = strchr(arg, '=');
    if (!value)
        return 0;
    value++;
    if (strncmp(value, "s:", 2) == 0) {
        fmi2String text = value + 2;
        return fmi2SetString(c, &vr, 1, &text) == fmi2OK;
    }
    if (strcmp(value, "true") == 0 || strcmp(value, "false") == 0) {
        fmi2Boolean b = value[0] == 't';
        return fmi2SetBoolean(c, &vr, 1, &b) == fmi2OK;
    }
    {
        char *end;
        fmi2Real r = strtod(value, &end);
        if (end == value || *end != '\0')
            return fmi2SetString(c, &vr, 1, &value) == fmi2OK;
        return fmi2SetReal(c, &vr, 1, &r) == fmi2OK;
    }
}

static int event_iteration(fmi2Component c, long *events)
{
    fmi2EventInfo info;
    int k = 0;
    if (!check(fmi2EnterEventMode(c), "fmi2EnterEventMode"))
        return 0;
    do {
        if (!check(fmi2NewDiscreteStates(c, &info), "fmi2NewDiscreteStates") || ++k > 100)
            return 0;
    } while (info.newDiscreteStatesNeeded);
    *events += 1;
    return check(fmi2EnterContinuousTimeMode(c), "fmi2EnterContinuousTimeMode");
}

static int run(const char *guid, double h, double stop, int argc, char **argv)
{
    fmi2Component c = fmi2Instantiate("me", fmi2ModelExchange, guid, "", &CALLBACKS, fmi2False, fmi2False);
    double x[NX], dx[NX], z[NZ], pre[NZ], t = 0.0;
    long events = 0, steps, k;
    int i, ok = 1;
    fmi2Boolean enter, terminate;
    if (!c)
        return 0;
    ok = check(fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2True, stop), "fmi2SetupExperiment")
         && check(fmi2EnterInitializationMode(c), "fmi2EnterInitializationMode");
    for (i = 0; ok && i < argc; i++)
        ok = set_parameter(c, argv[i]);
    ok = ok && check(fmi2ExitInitializationMode(c), "fmi2ExitInitializationMode");
    if (ok) { /* the initial event iteration (fmi2ExitInitializationMode enters event mode) */
        fmi2EventInfo info;
        do
            ok = check(fmi2NewDiscreteStates(c, &info), "fmi2NewDiscreteStates");
        while (ok && info.newDiscreteStatesNeeded);
        ok = ok && check(fmi2EnterContinuousTimeMode(c), "fmi2EnterContinuousTimeMode");
    }
    ok = ok && check(fmi2GetEventIndicators(c, pre, NZ), "fmi2GetEventIndicators");
    steps = (long)floor(stop / h + 0.5);
    for (k = 1; ok && k <= steps; k++) {
        int crossed = 0;
        ok = check(fmi2GetContinuousStates(c, x, NX), "fmi2GetContinuousStates")
             && check(fmi2GetDerivatives(c, dx, NX), "fmi2GetDerivatives");
        for (i = 0; i < NX; i++)
            x[i] += h * dx[i];
        t = k * h;
        ok = ok && check(fmi2SetTime(c, t), "fmi2SetTime") && check(fmi2SetContinuousStates(c, x, NX), "fmi2SetContinuousStates")
             && check(fmi2CompletedIntegratorStep(c, fmi2True, &enter, &terminate), "fmi2CompletedIntegratorStep")
             && check(fmi2GetEventIndicators(c, z, NZ), "fmi2GetEventIndicators");
        for (i = 0; ok && i < NZ; i++)
            crossed |= (pre[i] > 0.0) != (z[i] > 0.0);
        if (ok && (crossed || enter)) {
            ok = event_iteration(c, &events) && check(fmi2GetEventIndicators(c, z, NZ), "fmi2GetEventIndicators");
        }
        memcpy(pre, z, sizeof z);
    }
    ok = ok && check(fmi2GetContinuousStates(c, x, NX), "fmi2GetContinuousStates");
    if (ok)
        printf("events %ld\nfinal %.17g %.17g %.17g %.17g\n", events, t, x[0], x[1], x[2]);
    {   /* a saved state, serialised and back, restores */
        fmi2FMUstate state = NULL, back = NULL;
        size_t size = 0;
        fmi2Byte *bytes;
        ok = ok && check(fmi2GetFMUstate(c, &state), "fmi2GetFMUstate")
             && check(fmi2SerializedFMUstateSize(c, state, &size), "fmi2SerializedFMUstateSize");
        bytes = malloc(size ? size : 1);
        ok = ok && bytes && check(fmi2SerializeFMUstate(c, state, bytes, size), "fmi2SerializeFMUstate")
             && check(fmi2DeSerializeFMUstate(c, bytes, size, &back), "fmi2DeSerializeFMUstate")
             && check(fmi2SetFMUstate(c, back), "fmi2SetFMUstate");
        free(bytes);
        fmi2FreeFMUstate(c, &state);
        fmi2FreeFMUstate(c, &back);
    }
    /* refusals: wrong counts, a call out of order, a non-finite state; the instance goes on */
    printf("refused %d %d %d %d\n", (int)fmi2GetDerivatives(c, dx, 2), (int)fmi2NewDiscreteStates(c, NULL),
           (int)fmi2DoStep(c, t, h, fmi2True), (int)fmi2SetTime(c, NAN));
    ok = ok && check(fmi2Terminate(c), "fmi2Terminate");
    fmi2FreeInstance(c);
    return ok;
}

int main(int argc, char **argv)
{
    fmi2Component c;
    if (argc < 4) {
        fprintf(stderr, "usage: me_host GUID STEP STOP [vr=value ...]\n");
        return 2;
    }
    if (!load())
        return 2;
    if (!run(argv[1], strtod(argv[2], NULL), strtod(argv[3], NULL), argc - 4, argv + 4))
        return 1;
    /* the paper formulation: refused at initialisation, the instance in the error state */
    c = fmi2Instantiate("paper", fmi2ModelExchange, argv[1], "", &CALLBACKS, fmi2False, fmi2False);
    if (!c)
        return 1;
    {
        const char *formulation = getenv("CAM_FORMULATION_VR");
        fmi2ValueReference vr = (fmi2ValueReference)strtoul(formulation ? formulation : "0", NULL, 10);
        fmi2String paper = "paper";
        fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0);
        fmi2EnterInitializationMode(c);
        if (fmi2SetString(c, &vr, 1, &paper) != fmi2OK)
            return 1;
        printf("paper %d\n", (int)fmi2ExitInitializationMode(c));
    }
    fmi2FreeInstance(c);
    return 0;
}
