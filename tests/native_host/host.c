/*
 * A minimal native FMI 2.0 co-simulation host, as real tools load FMUs:
 * dlopen(RTLD_NOW | RTLD_LOCAL) (LoadLibrary on Windows), fmi2Instantiate, run,
 * fmi2FreeInstance, dlclose, exit.  No libpython is linked or preloaded. The FMI
 * types are the official headers' (fmi2FunctionTypes.h, vendored in cam_fmu/engine/csrc/fmi/headers).
 *
 *   host <binary> <resources-dir> COMMAND...
 *
 * Commands (run in order; each prints one JSON line; the logger prints
 * {"log": status, "category": ..., "msg": ...} lines):
 *   guid TEXT            the GUID the following inst/cycles pass (default "")
 *   inst                 fmi2Instantiate (loggingOn = false: errors must still reach the logger)
 *   init                 fmi2SetupExperiment(0) + Enter/ExitInitializationMode
 *   enter / exit         fmi2EnterInitializationMode / fmi2ExitInitializationMode alone
 *   setr VR VALUE        fmi2SetReal of one variable (VALUE may be nan)
 *   sets VR TEXT         fmi2SetString of one variable
 *   getr VR,VR,...       one fmi2GetReal of all listed variables (the array is filled with -1.5 first)
 *   gets VR,VR,...       one fmi2GetString of all listed variables (the array is filled with "junk" first)
 *   step N H             N x fmi2DoStep of size H (stops at the first non-OK status)
 *   stepat T H           one fmi2DoStep(T, H), whatever the host's time
 *   save / restore       fmi2GetFMUstate / fmi2SetFMUstate (one slot)
 *   serial               serialise the saved state, deserialise it, and make that the saved state
 *   reset / term / free  fmi2Reset / fmi2Terminate / fmi2FreeInstance
 *   laststatus           fmi2GetBooleanStatus(fmi2Terminated) and fmi2GetRealStatus(fmi2LastSuccessfulTime)
 *   cycles N             N x (fmi2Instantiate + fmi2FreeInstance); prints RSS after 20 and after N (Linux)
 *   nullcalls            every getter with a NULL and with a bogus component, outputs filled with junk
 *                        first; prints each status and what the outputs hold afterwards (no instance needed)
 * At the end: fmi2FreeInstance if still instantiated, dlclose, {"exit": 0}, return 0.
 */
#include <math.h>
#include <stdarg.h>
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

/* A copy of text in memory of its own (free() it): what strdup does, which C99 lacks (POSIX declares it, and
 * under -std=c99 neither glibc nor clang does without _POSIX_C_SOURCE; an undeclared strdup returns int). */
static char *copy_text(const char *text)
{
    size_t n = strlen(text) + 1;
    char *copy = malloc(n);
    if (!copy) {
        fprintf(stderr, "host: out of memory\n");
        exit(1);
    }
    return memcpy(copy, text, n);
}

static void json_string(const char *s)
{
    putchar('"');
    for (; s && *s; s++) {
        unsigned char ch = (unsigned char)*s;
        if (ch == '"' || ch == '\\') printf("\\%c", ch);
        else if (ch < 0x20) printf("\\u%04x", ch);
        else putchar(ch);
    }
    putchar('"');
}

static void logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status, fmi2String category,
                   fmi2String message, ...)
{
    char text[8192];
    va_list ap;
    (void)env;
    (void)name;
    va_start(ap, message);
    vsnprintf(text, sizeof text, message, ap);
    va_end(ap);
    printf("{\"log\": %d, \"category\": ", (int)status);
    json_string(category);
    printf(", \"msg\": ");
    json_string(text);
    printf("}\n");
    fflush(stdout);
}

static long rss_kb(void)
{
    long pages = 0, resident = 0;
    FILE *f = fopen("/proc/self/statm", "r"); /* Linux only: 0 elsewhere */
    if (f) {
        if (fscanf(f, "%ld %ld", &pages, &resident) != 2) resident = 0;
        fclose(f);
    }
    return resident * 4;
}

#define SYM(name) fmi2##name##TYPE *fmi2##name = (fmi2##name##TYPE *)SYMBOL(lib, "fmi2" #name)

static void json_strings(const char *const *s, size_t n)
{
    putchar('[');
    for (size_t i = 0; i < n; i++) {
        if (i) printf(", ");
        if (s[i]) json_string(s[i]);
        else printf("null");
    }
    putchar(']');
}

int main(int argc, char **argv)
{
    LIBRARY lib;
    char uri[4200];
    const char *guid = "";
    fmi2CallbackFunctions cb = {logger, calloc, free, NULL, NULL};
    fmi2Component c = NULL;
    fmi2FMUstate saved = NULL;
    double time = 0.0, saved_time = 0.0;   /* s: the host's clock, and the time of the saved state */
    if (argc < 3) {
        fprintf(stderr, "usage: host <binary.so> <resources-dir> COMMAND...\n");
        return 2;
    }
    lib = OPEN(argv[1]);
    if (!lib) {
        printf("{\"dlopen\": ");
#ifdef _WIN32
        json_string("LoadLibrary failed");
#else
        json_string(dlerror());
#endif
        printf("}\n");
        return 3;
    }
    SYM(Instantiate); SYM(FreeInstance); SYM(SetupExperiment); SYM(EnterInitializationMode);
    SYM(ExitInitializationMode); SYM(Terminate); SYM(Reset); SYM(SetReal); SYM(GetReal); SYM(GetString);
    SYM(SetString); SYM(DoStep); SYM(GetFMUstate); SYM(SetFMUstate); SYM(FreeFMUstate);
    SYM(SerializedFMUstateSize); SYM(SerializeFMUstate); SYM(DeSerializeFMUstate);
    SYM(GetBooleanStatus); SYM(GetRealStatus); SYM(GetInteger); SYM(GetBoolean); SYM(GetStatus);
    SYM(GetIntegerStatus); SYM(GetStringStatus); SYM(GetDirectionalDerivative); SYM(GetRealOutputDerivatives);
    if (!fmi2Instantiate || !fmi2DoStep || !fmi2GetBooleanStatus || !fmi2DeSerializeFMUstate || !fmi2GetString) {
        printf("{\"dlsym\": \"missing FMI functions\"}\n");
        return 3;
    }
    snprintf(uri, sizeof uri, "file://%s", argv[2]);

    for (int k = 3; k < argc; k++) {
        const char *cmd = argv[k];
        fmi2Status s = fmi2OK;
        if (!strcmp(cmd, "guid")) {
            guid = argv[++k];
            continue;
        } else if (!strcmp(cmd, "nullcalls")) {
            int bogus[64] = {0};   /* memory that is not an instance: the wrapper must recognise it */
            fmi2Component comps[2] = {NULL, bogus};
            for (int which = 0; which < 2; which++) {
                fmi2Component x = comps[which];
                fmi2ValueReference vrs[3] = {0, 1, 2}, z[2] = {0, 1};
                double r[3] = {-1.5, -1.5, -1.5}, rs = -1.5, dz[2] = {-1.5, -1.5}, od[2] = {-1.5, -1.5}, dv[1] = {1};
                int iv[3] = {-7, -7, -7}, bv[3] = {-7, -7, -7}, is = -7, bs = -7, order[2] = {1, 1};
                const char *sv[3] = {"junk", "junk", "junk"}, *ss = "junk";
                fmi2Status st = fmi2Pending;
                int statuses[11];
                statuses[0] = fmi2GetReal(x, vrs, 3, r);
                statuses[1] = fmi2GetInteger(x, vrs, 3, iv);
                statuses[2] = fmi2GetBoolean(x, vrs, 3, bv);
                statuses[3] = fmi2GetString(x, vrs, 3, sv);
                statuses[4] = fmi2GetStatus(x, 0, &st);
                statuses[5] = fmi2GetRealStatus(x, 2, &rs);
                statuses[6] = fmi2GetIntegerStatus(x, 0, &is);
                statuses[7] = fmi2GetBooleanStatus(x, 3, &bs);
                statuses[8] = fmi2GetStringStatus(x, 0, &ss);
                statuses[9] = fmi2GetDirectionalDerivative(x, vrs, 2, z, 1, dv, dz);   /* 2 unknowns: dz[0..1] */
                statuses[10] = fmi2GetRealOutputDerivatives(x, z, 2, order, od);
                printf("{\"cmd\": \"nullcalls\", \"component\": \"%s\", \"statuses\": [", which ? "bogus" : "null");
                for (int i = 0; i < 11; i++) printf(i ? ", %d" : "%d", statuses[i]);
                printf("], \"real\": [%g, %g, %g], \"integer\": [%d, %d, %d], \"boolean\": [%d, %d, %d], \"string\": ",
                       r[0], r[1], r[2], iv[0], iv[1], iv[2], bv[0], bv[1], bv[2]);
                json_strings(sv, 3);
                printf(", \"status\": %d, \"real_status\": %g, \"integer_status\": %d, \"boolean_status\": %d, "
                       "\"string_status\": ", (int)st, rs, is, bs);
                json_strings(&ss, 1);
                printf(", \"directional\": [%g, %g], \"output_derivatives\": [%g, %g]}\n", dz[0], dz[1], od[0], od[1]);
                fflush(stdout);
            }
            continue;
        } else if (!strcmp(cmd, "inst")) {
            c = fmi2Instantiate("host", fmi2CoSimulation, guid, uri, &cb, fmi2False, fmi2False);
            printf("{\"cmd\": \"inst\", \"ok\": %s}\n", c ? "true" : "false");
            if (!c) break;
            continue;
        } else if (!strcmp(cmd, "cycles")) {
            int n = atoi(argv[++k]);
            long after20 = 0;
            for (int i = 0; i < n; i++) {
                fmi2Component x = fmi2Instantiate("cycle", fmi2CoSimulation, guid, uri, &cb, fmi2False, fmi2False);
                if (!x) { printf("{\"cmd\": \"cycles\", \"failed_at\": %d}\n", i); break; }
                fmi2FreeInstance(x);
                if (i == 19) after20 = rss_kb();
            }
            printf("{\"cmd\": \"cycles\", \"n\": %d, \"rss_after_20_kb\": %ld, \"rss_end_kb\": %ld}\n", n, after20,
                   rss_kb());
            continue;
        } else if (!strcmp(cmd, "free")) {
            if (c && saved) fmi2FreeFMUstate(c, &saved);
            fmi2FreeInstance(c);   /* also after fmi2Error/fmi2Fatal, and with NULL */
            c = NULL;
            saved = NULL;
        } else if (!c) {
            printf("{\"cmd\": \"%s\", \"error\": \"no instance\"}\n", cmd);
            continue;
        } else if (!strcmp(cmd, "init")) {
            s = fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0);
            if (s == fmi2OK) s = fmi2EnterInitializationMode(c);
            if (s == fmi2OK) s = fmi2ExitInitializationMode(c);
            time = 0.0;
        } else if (!strcmp(cmd, "enter")) {
            s = fmi2EnterInitializationMode(c);
        } else if (!strcmp(cmd, "exit")) {
            s = fmi2ExitInitializationMode(c);
        } else if (!strcmp(cmd, "stepat")) {
            double t0 = strtod(argv[++k], NULL);
            double h = strtod(argv[++k], NULL);
            s = fmi2DoStep(c, t0, h, fmi2True);
            if (s == fmi2OK) time = t0 + h;
        } else if (!strcmp(cmd, "gets")) {
            fmi2ValueReference vrs[64];
            const char *values[64];
            size_t n = 0;
            char *list = copy_text(argv[++k]);
            for (int i = 0; i < 64; i++) values[i] = "junk";
            for (char *t = strtok(list, ","); t && n < 64; t = strtok(NULL, ",")) vrs[n++] = (fmi2ValueReference)atoi(t);
            free(list);
            s = fmi2GetString(c, vrs, n, values);
            printf("{\"cmd\": \"gets\", \"status\": %d, \"values\": ", (int)s);
            json_strings(values, n);
            printf("}\n");
            fflush(stdout);
            continue;
        } else if (!strcmp(cmd, "setr")) {
            fmi2ValueReference vr = (fmi2ValueReference)atoi(argv[++k]);
            double v = strtod(argv[++k], NULL);
            s = fmi2SetReal(c, &vr, 1, &v);
        } else if (!strcmp(cmd, "sets")) {
            fmi2ValueReference vr = (fmi2ValueReference)atoi(argv[++k]);
            const char *v = argv[++k];
            s = fmi2SetString(c, &vr, 1, &v);
        } else if (!strcmp(cmd, "getr")) {
            fmi2ValueReference vrs[64];
            double values[64];
            size_t n = 0;
            char *list = copy_text(argv[++k]);
            for (int i = 0; i < 64; i++) values[i] = -1.5;
            for (char *t = strtok(list, ","); t && n < 64; t = strtok(NULL, ",")) vrs[n++] = (fmi2ValueReference)atoi(t);
            free(list);
            s = fmi2GetReal(c, vrs, n, values);
            printf("{\"cmd\": \"getr\", \"status\": %d, \"values\": [", (int)s);
            for (size_t i = 0; i < n; i++) printf(i ? ", %.17g" : "%.17g", isfinite(values[i]) ? values[i] : 1e308);
            printf("]}\n");
            fflush(stdout);
            continue;
        } else if (!strcmp(cmd, "step")) {
            int n = atoi(argv[++k]);
            double h = strtod(argv[++k], NULL);
            int done = 0;
            for (; done < n; done++) {
                s = fmi2DoStep(c, time, h, fmi2True);
                if (s != fmi2OK) break;
                time += h;
            }
            printf("{\"cmd\": \"step\", \"status\": %d, \"steps\": %d, \"time\": %.17g}\n", (int)s, done, time);
            fflush(stdout);
            continue;
        } else if (!strcmp(cmd, "save")) {
            s = fmi2GetFMUstate(c, &saved);
            saved_time = time;
        } else if (!strcmp(cmd, "restore")) {
            s = fmi2SetFMUstate(c, saved);
            if (s == fmi2OK) time = saved_time;   /* the clock goes back with the state */
        } else if (!strcmp(cmd, "serial")) {
            size_t size = 0;
            fmi2Byte *buf;
            fmi2FMUstate copy = NULL;
            s = fmi2SerializedFMUstateSize(c, saved, &size);
            buf = malloc(size ? size : 1);
            if (s == fmi2OK) s = fmi2SerializeFMUstate(c, saved, buf, size);
            if (s == fmi2OK) s = fmi2DeSerializeFMUstate(c, buf, size, &copy);
            free(buf);
            if (s == fmi2OK) {
                fmi2FreeFMUstate(c, &saved);
                saved = copy;
            }
        } else if (!strcmp(cmd, "reset")) {
            s = fmi2Reset(c);
            time = 0.0;
        } else if (!strcmp(cmd, "term")) {
            s = fmi2Terminate(c);
        } else if (!strcmp(cmd, "laststatus")) {
            int terminated = -1;
            double last = -1.0;
            fmi2Status s1 = fmi2GetBooleanStatus(c, fmi2Terminated, &terminated);
            fmi2Status s2 = fmi2GetRealStatus(c, fmi2LastSuccessfulTime, &last);
            printf("{\"cmd\": \"laststatus\", \"status\": %d, \"terminated\": %d, \"last_time\": %.17g}\n",
                   (int)(s1 > s2 ? s1 : s2), terminated, last);
            fflush(stdout);
            continue;
        } else {
            printf("{\"cmd\": \"%s\", \"error\": \"unknown command\"}\n", cmd);
            continue;
        }
        printf("{\"cmd\": \"%s\", \"status\": %d}\n", cmd, (int)s);
        fflush(stdout);
    }
    if (c) {
        if (saved) fmi2FreeFMUstate(c, &saved);
        fmi2FreeInstance(c);
    }
    CLOSE(lib);
    printf("{\"exit\": 0}\n");
    return 0;
}
