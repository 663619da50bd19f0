/* An FMI 3.0 co-simulation host for cam3.fmu's binary, in C (tests/fmi3/test_fmi3.py runs it under valgrind on
 * x86_64-linux, and cross-compiled by zig, under wine on x86_64-windows and qemu on aarch64-linux): instance cycles with a
 * parameter, initialisation, steps, FMU states (get, serialise, deserialise, restore) and refused calls (a NaN
 * input, a step at the wrong time, a call on NULL); one line per result.
 *
 *     host3 BINARY TOKEN THETA_VR U_VR C_VR CYCLES
 */
#include <stdio.h>
#include <stdlib.h>
#ifdef _WIN32
#include <windows.h>
#define LIBRARY HMODULE
#define OPEN(path) LoadLibraryA(path)
#define CLOSE(lib) FreeLibrary(lib)
/* a function pointer from GetProcAddress through an object pointer's bytes, as below */
#define SYMBOL(lib, name) ((void *)GetProcAddress(lib, name))
#else
#include <dlfcn.h>
#define LIBRARY void *
#define OPEN(path) dlopen(path, RTLD_NOW | RTLD_LOCAL)
#define CLOSE(lib) dlclose(lib)
#define SYMBOL(lib, name) dlsym(lib, name)
#endif

#include "fmi3Functions.h"

/* POSIX: a function pointer from dlsym through an object pointer's bytes */
#define LOAD(name)          \
    name##TYPE *name;       \
    *(void **)(&name) = SYMBOL(lib, #name)

static void logger(fmi3InstanceEnvironment env, fmi3Status status, fmi3String category, fmi3String message) {
    (void)env;
    printf("log %d %s %.120s\n", (int)status, category, message);
}

int main(int argc, char **argv) {
    LIBRARY lib;
    fmi3ValueReference theta_vr, u_vr, c_vr;
    int cycles, k, n;
    if (argc != 7) {
        fprintf(stderr, "usage: host3 BINARY TOKEN THETA_VR U_VR C_VR CYCLES\n");
        return 2;
    }
    lib = OPEN(argv[1]);
    if (!lib) {
        fprintf(stderr, "cannot load %s\n", argv[1]);
        return 2;
    }
    theta_vr = (fmi3ValueReference)atoi(argv[3]);
    u_vr = (fmi3ValueReference)atoi(argv[4]);
    c_vr = (fmi3ValueReference)atoi(argv[5]);
    cycles = atoi(argv[6]);
    {
        LOAD(fmi3InstantiateCoSimulation);
        LOAD(fmi3FreeInstance);
        LOAD(fmi3EnterInitializationMode);
        LOAD(fmi3ExitInitializationMode);
        LOAD(fmi3SetFloat64);
        LOAD(fmi3GetFloat64);
        LOAD(fmi3DoStep);
        LOAD(fmi3GetFMUState);
        LOAD(fmi3SetFMUState);
        LOAD(fmi3FreeFMUState);
        LOAD(fmi3SerializedFMUStateSize);
        LOAD(fmi3SerializeFMUState);
        LOAD(fmi3DeserializeFMUState);
        LOAD(fmi3Terminate);
        LOAD(fmi3Reset);
        if (!fmi3InstantiateCoSimulation || !fmi3DoStep || !fmi3DeserializeFMUState) {
            fprintf(stderr, "missing FMI 3.0 functions\n");
            return 2;
        }
        for (n = 0; n < cycles; n++) {
            fmi3Instance c = fmi3InstantiateCoSimulation("cam3", argv[2], NULL, fmi3False, fmi3False, fmi3False,
                                                         fmi3False, NULL, 0, NULL, logger, NULL);
            fmi3FMUState state = NULL, copy = NULL;
            fmi3Boolean event, terminate, early;
            fmi3Float64 last, theta_a, theta_b, clearance = 5e-4, nan_value = 0.0 / 0.0;
            fmi3Byte *bytes;
            size_t size = 0;
            fmi3Status s;
            if (!c) {
                printf("instantiate failed\n");
                return 1;
            }
            s = fmi3SetFloat64(c, &c_vr, 1, &clearance, 1);
            printf("set-c %d\n", (int)s);
            fmi3EnterInitializationMode(c, fmi3False, 0.0, 0.0, fmi3False, 0.0);
            printf("init %d\n", (int)fmi3ExitInitializationMode(c));
            for (k = 0; k < 100; k++)
                fmi3DoStep(c, k * 1e-3, 1e-3, fmi3True, &event, &terminate, &early, &last);
            fmi3GetFMUState(c, &state);
            fmi3SerializedFMUStateSize(c, state, &size);
            bytes = malloc(size);
            printf("serialize %d\n", (int)fmi3SerializeFMUState(c, state, bytes, size));
            printf("deserialize %d\n", (int)fmi3DeserializeFMUState(c, bytes, size, &copy));
            free(bytes);
            for (k = 100; k < 200; k++)
                fmi3DoStep(c, k * 1e-3, 1e-3, fmi3True, &event, &terminate, &early, &last);
            fmi3GetFloat64(c, &theta_vr, 1, &theta_a, 1);
            fmi3SetFMUState(c, copy);
            for (k = 100; k < 200; k++)
                fmi3DoStep(c, k * 1e-3, 1e-3, fmi3True, &event, &terminate, &early, &last);
            fmi3GetFloat64(c, &theta_vr, 1, &theta_b, 1);
            printf("restored %s %a\n", theta_a == theta_b ? "same" : "DIFFERENT", theta_a);
            printf("nan-input %d\n", (int)fmi3SetFloat64(c, &u_vr, 1, &nan_value, 1));
            printf("wrong-time %d\n", (int)fmi3DoStep(c, 5.0, 1e-3, fmi3True, &event, &terminate, &early, &last));
            printf("null-get %d\n", (int)fmi3GetFloat64(NULL, &theta_vr, 1, &theta_a, 1));
            fmi3FreeFMUState(c, &state);
            fmi3FreeFMUState(c, &copy);
            s = fmi3Terminate(c);
            printf("terminate %d", (int)s);
            printf(" reset %d\n", (int)fmi3Reset(c));
            fmi3FreeInstance(c);
        }
    }
    CLOSE(lib);
    return 0;
}
