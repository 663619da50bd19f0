/*
 * A minimal native co-simulation master in C for two FMI 2.0 co-simulation FMUs, as a tool with no Python
 * would run a closed loop: LoadLibrary/dlopen each binary, fixed-step Jacobi coupling with the project's
 * master's semantics (experiments/cosim.py: the connections carried through initialisation twice, the
 * first step sees each FMU's initial outputs), fmi2Terminate, fmi2FreeInstance. Built for linux64 and for
 * win64 (run under wine), so the shipped loops can be run with no Python on either.
 *
 *   loop_host A_BINARY A_GUID B_BINARY B_GUID STOP H ITEM...
 *
 * ITEM is "pA:VR=VALUE" / "pB:VR=VALUE" (a Real parameter) or "wA:VR>B:VR" / "wB:VR>A:VR" (a connection
 * from an output of one FMU to an input of the other). Prints one line per communication point: the time
 * and every connection's value, each %.17g; then "status OK" or the first failing call.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#ifdef _WIN32
#include <windows.h>
#define LIBRARY HMODULE
#define OPEN(path) LoadLibraryA(path)
#define SYMBOL(lib, name) ((void *)GetProcAddress(lib, name))
#define CLOSE(lib) FreeLibrary(lib)
#else
#include <dlfcn.h>
#define LIBRARY void *
#define OPEN(path) dlopen(path, RTLD_NOW | RTLD_LOCAL)
#define SYMBOL(lib, name) dlsym(lib, name)
#define CLOSE(lib) dlclose(lib)
#endif

#include "fmi2FunctionTypes.h"

#define MAX_ITEMS 64

typedef struct {
    LIBRARY lib;
    fmi2Component c;
    fmi2InstantiateTYPE *instantiate;
    fmi2FreeInstanceTYPE *free_instance;
    fmi2SetupExperimentTYPE *setup;
    fmi2EnterInitializationModeTYPE *enter;
    fmi2ExitInitializationModeTYPE *exit_init;
    fmi2TerminateTYPE *terminate;
    fmi2GetRealTYPE *get_real;
    fmi2SetRealTYPE *set_real;
    fmi2DoStepTYPE *do_step;
} Fmu;

typedef struct {
    int from, to;                 /* 0: A, 1: B */
    fmi2ValueReference out, in;
} Wire;

static void logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status, fmi2String category,
                   fmi2String message, ...)
{
    (void)env;
    fprintf(stderr, "[%s] %d %s: %s\n", name ? name : "?", (int)status, category ? category : "", message);
}

static int fail(const char *what)
{
    printf("status failed: %s\n", what);
    return 1;
}

static int load(Fmu *f, const char *path, const char *guid, const char *name, const fmi2CallbackFunctions *cb)
{
    f->lib = OPEN(path);
    if (!f->lib)
        return 0;
    f->instantiate = (fmi2InstantiateTYPE *)SYMBOL(f->lib, "fmi2Instantiate");
    f->free_instance = (fmi2FreeInstanceTYPE *)SYMBOL(f->lib, "fmi2FreeInstance");
    f->setup = (fmi2SetupExperimentTYPE *)SYMBOL(f->lib, "fmi2SetupExperiment");
    f->enter = (fmi2EnterInitializationModeTYPE *)SYMBOL(f->lib, "fmi2EnterInitializationMode");
    f->exit_init = (fmi2ExitInitializationModeTYPE *)SYMBOL(f->lib, "fmi2ExitInitializationMode");
    f->terminate = (fmi2TerminateTYPE *)SYMBOL(f->lib, "fmi2Terminate");
    f->get_real = (fmi2GetRealTYPE *)SYMBOL(f->lib, "fmi2GetReal");
    f->set_real = (fmi2SetRealTYPE *)SYMBOL(f->lib, "fmi2SetReal");
    f->do_step = (fmi2DoStepTYPE *)SYMBOL(f->lib, "fmi2DoStep");
    if (!f->instantiate || !f->free_instance || !f->setup || !f->enter || !f->exit_init || !f->terminate
        || !f->get_real || !f->set_real || !f->do_step)
        return 0;
    f->c = f->instantiate(name, fmi2CoSimulation, guid, "", cb, fmi2False, fmi2False);
    return f->c != NULL;
}

int main(int argc, char **argv)
{
    fmi2CallbackFunctions cb = {logger, calloc, free, NULL, NULL};
    Fmu fmu[2];
    Wire wires[MAX_ITEMS];
    double values[MAX_ITEMS], stop, h, t;
    int n_wires = 0, k, w, pass;
    long n, step;
    if (argc < 7) {
        fprintf(stderr, "usage: loop_host A_BINARY A_GUID B_BINARY B_GUID STOP H ITEM...\n");
        return 2;
    }
    memset(fmu, 0, sizeof fmu);
    if (!load(&fmu[0], argv[1], argv[2], "a", &cb) || !load(&fmu[1], argv[3], argv[4], "b", &cb))
        return fail("load or instantiate");
    stop = atof(argv[5]);
    h = atof(argv[6]);
    for (k = 0; k < 2; k++)
        if (fmu[k].setup(fmu[k].c, fmi2False, 0.0, 0.0, fmi2True, stop) != fmi2OK)
            return fail("fmi2SetupExperiment");
    for (k = 7; k < argc && n_wires < MAX_ITEMS; k++) {
        const char *item = argv[k];
        int who = item[1] == 'A' ? 0 : 1;
        if (item[0] == 'p') {
            unsigned vr;
            double value;
            if (sscanf(item + 3, "%u=%lf", &vr, &value) != 2)
                return fail(item);
            if (fmu[who].set_real(fmu[who].c, &vr, 1, &value) != fmi2OK)
                return fail(item);
        } else if (item[0] == 'w') {
            unsigned out, in;
            if (sscanf(item + 3, "%u>%*c:%u", &out, &in) != 2)
                return fail(item);
            wires[n_wires].from = who;
            wires[n_wires].to = 1 - who;
            wires[n_wires].out = out;
            wires[n_wires].in = in;
            n_wires++;
        } else {
            return fail(item);
        }
    }
    for (k = 0; k < 2; k++)
        if (fmu[k].enter(fmu[k].c) != fmi2OK)
            return fail("fmi2EnterInitializationMode");
    for (pass = 0; pass < 2; pass++)   /* initial values through the connections, once per FMU */
        for (w = 0; w < n_wires; w++) {
            double v;
            if (fmu[wires[w].from].get_real(fmu[wires[w].from].c, &wires[w].out, 1, &v) != fmi2OK
                || fmu[wires[w].to].set_real(fmu[wires[w].to].c, &wires[w].in, 1, &v) != fmi2OK)
                return fail("a connection during initialisation");
        }
    for (k = 0; k < 2; k++)
        if (fmu[k].exit_init(fmu[k].c) != fmi2OK)
            return fail("fmi2ExitInitializationMode");
    n = (long)(stop / h + 0.5);
    for (step = 0; step <= n; step++) {
        for (w = 0; w < n_wires; w++)
            if (fmu[wires[w].from].get_real(fmu[wires[w].from].c, &wires[w].out, 1, &values[w]) != fmi2OK)
                return fail("fmi2GetReal");
        printf("%.17g", step * h);
        for (w = 0; w < n_wires; w++)
            printf(" %.17g", values[w]);
        printf("\n");
        if (step == n)
            break;
        t = step * h;
        for (w = 0; w < n_wires; w++)
            if (fmu[wires[w].to].set_real(fmu[wires[w].to].c, &wires[w].in, 1, &values[w]) != fmi2OK)
                return fail("fmi2SetReal");
        for (k = 0; k < 2; k++)
            if (fmu[k].do_step(fmu[k].c, t, h, fmi2True) != fmi2OK)
                return fail("fmi2DoStep");
    }
    for (k = 0; k < 2; k++) {
        fmu[k].terminate(fmu[k].c);
        fmu[k].free_instance(fmu[k].c);
        CLOSE(fmu[k].lib);
    }
    printf("status OK\n");
    return 0;
}
