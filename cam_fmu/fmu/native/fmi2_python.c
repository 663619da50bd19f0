/*
 * The project's own linux64 binary of a Python FMU (pi_speed.fmu): an FMI 2.0 co-simulation wrapper that hosts
 * the Python slave (a pythonfmu Fmi2Slave subclass).
 *
 * Written for this project (not derived from pythonfmu's C++).  Design:
 *
 * - No link-time dependency on libpython.  Python.h is included for types and
 *   struct layouts only; every API function is called through a pointer found
 *   with dlsym, so the library loads in any host, and `nm -D --undefined-only`
 *   lists no Py* symbol (a test checks it).
 * - Python host (fmpy, libcosimpy): the running interpreter is detected with
 *   dlsym(RTLD_DEFAULT, "Py_IsInitialized"); it is never initialised or
 *   finalised here, only PyGILState_Ensure/Release around every call.
 * - Native host (ecos, C tools): libpython is dlopen'ed with RTLD_NOW |
 *   RTLD_GLOBAL (this also promotes an already loaded private copy to global,
 *   so extension modules such as math or numpy resolve their symbols), found
 *   through $CAM_FMU_PYTHON (a python executable or a libpython) or else
 *   resources/python.txt (recorded at build time).  It is started with an
 *   isolated PyConfig (home, executable, no signal handlers; environment
 *   variables such as PYTHONHOME/PYTHONPATH do not apply) and the recorded
 *   site-packages folders are added with site.addsitedir.
 * - The interpreter is NEVER finalised: Py_Finalize at unload is where
 *   pythonfmu's binary and numpy/scipy crash native hosts.  The interpreter
 *   stays alive and idle; Python holds no pointer into this library (no C
 *   callbacks, no atexit hooks), so the host may dlclose it at any time.
 * - All Python-side work happens in the bridge module (bridge.py, bundled as
 *   <package>._fmi_bridge): every call returns (status, payload, messages).
 *   A Python exception in a slave method is fmi2Error (or fmi2Discard when the
 *   exception says fmi_status == "discard"); an exception escaping the bridge
 *   or a failing C-API call is fmi2Fatal.
 * - After the last instance is freed, the bridge removes the FMU's private
 *   module names from sys.modules (sys.path is never touched).
 * - The exchange (bridge.Exchange, a bytearray the bridge keeps current):
 *   fmi2GetReal of the slave's outputs and inputs, and fmi2SetReal of inputs
 *   within their ranges, are answered here without the GIL; per step only
 *   fmi2DoStep enters Python.
 */
#include <Python.h>

#include <dlfcn.h>
#include <errno.h>
#include <limits.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* ------------------------------------------------------------------ FMI 2.0 types */
typedef void *fmi2Component;
typedef void *fmi2ComponentEnvironment;
typedef void *fmi2FMUstate;
typedef unsigned int fmi2ValueReference;
typedef double fmi2Real;
typedef int fmi2Integer;
typedef int fmi2Boolean;
typedef char fmi2Char;
typedef const fmi2Char *fmi2String;
typedef char fmi2Byte;
#define fmi2True 1
#define fmi2False 0

typedef enum { fmi2OK, fmi2Warning, fmi2Discard, fmi2Error, fmi2Fatal, fmi2Pending } fmi2Status;
typedef enum { fmi2ModelExchange, fmi2CoSimulation } fmi2Type;
typedef enum { fmi2DoStepStatus, fmi2PendingStatus, fmi2LastSuccessfulTime, fmi2Terminated } fmi2StatusKind;

typedef void (*fmi2CallbackLogger)(fmi2ComponentEnvironment, fmi2String, fmi2Status, fmi2String, fmi2String, ...);
typedef void *(*fmi2CallbackAllocateMemory)(size_t, size_t);
typedef void (*fmi2CallbackFreeMemory)(void *);
typedef void (*fmi2StepFinished)(fmi2ComponentEnvironment, fmi2Status);
typedef struct {
    const fmi2CallbackLogger logger;
    const fmi2CallbackAllocateMemory allocateMemory;
    const fmi2CallbackFreeMemory freeMemory;
    const fmi2StepFinished stepFinished;
    const fmi2ComponentEnvironment componentEnvironment;
} fmi2CallbackFunctions;

#define EXPORT __attribute__((visibility("default")))

/* ------------------------------------------------------------------ Python API by pointer */
#define PY_FUNCTIONS(X)                                                                    \
    X(Py_IsInitialized) X(Py_GetVersion) X(PyGILState_Ensure) X(PyGILState_Release)      \
    X(PyEval_SaveThread) X(PyPreConfig_InitIsolatedConfig) X(Py_PreInitialize)           \
    X(PyConfig_InitIsolatedConfig) X(PyConfig_SetBytesString) X(PyConfig_Clear)          \
    X(Py_InitializeFromConfig) X(PyStatus_Exception) X(PyRun_StringFlags) X(PyDict_New)  \
    X(PyDict_GetItemString) X(PyDict_SetItemString) X(PyEval_GetBuiltins)                \
    X(PyObject_GetAttrString) X(PyObject_CallObject) X(PyObject_Str) X(Py_VaBuildValue)  \
    X(PyUnicode_AsUTF8) X(PyUnicode_FromString) X(PyErr_Occurred) X(PyErr_Fetch)        \
    X(PyErr_NormalizeException) X(PyErr_Clear) X(Py_IncRef) X(Py_DecRef)                 \
    X(PyBytes_FromStringAndSize) X(PyBytes_AsStringAndSize) X(PyTuple_Size)              \
    X(PyTuple_GetItem) X(PyList_Size) X(PyList_GetItem) X(PyLong_AsLong) X(PyFloat_FromDouble)  \
    X(PyByteArray_AsString) X(PyByteArray_Size)

#define DECLARE_PTR(name) static __typeof__(&name) p_##name;
PY_FUNCTIONS(DECLARE_PTR)
#undef DECLARE_PTR

/* ------------------------------------------------------------------ global state */
static pthread_mutex_t g_lock = PTHREAD_MUTEX_INITIALIZER;
static int g_python_ready = 0;      /* API pointers loaded and an interpreter running */
static int g_python_owned = 0;      /* we started the interpreter (native host) */
static PyObject *g_bridge = NULL;   /* <package>._fmi_bridge */
static PyObject *g_class = NULL;    /* the slave class */
static int g_live = 0;              /* live instances (guarded by the GIL) */
static int (*p_is_finalizing)(void) = NULL;  /* Py_IsFinalizing (3.13+) or _Py_IsFinalizing, if exported */
static PyObject *p_none = NULL;     /* Python's None (_Py_NoneStruct): a payload that means "nothing" */
static char g_package[128];
static char g_slave[128];

#define INSTANCE_MAGIC 0xCA3F3001u
#define STATE_MAGIC 0xCA3F5701u

/* The exchange: a bytearray of the bridge (bridge.Exchange) holding the per-step variables, so that
 * fmi2GetReal of them and fmi2SetReal of inputs within range are answered here, without the GIL.
 * Header of int32 (positions as bridge._HEAD lists them), then uint32 value references, double
 * lower and upper input bounds and double values at the offsets the header gives. */
enum { X_MAGIC, X_N_OUT, X_N_IN, X_OFF_VR, X_OFF_LO, X_OFF_HI, X_OFF_VALUE, X_READY, X_DIRTY, X_HEAD };
#define EXCHANGE_MAGIC 0x58434D43
typedef struct {
    PyObject *buffer;     /* the bytearray (a reference held); NULL: every call goes to Python */
    int *head;
    const fmi2ValueReference *vr;
    const double *lo, *hi;
    double *value;
    int n_out, n;         /* slots [0, n_out) are outputs, [n_out, n) inputs */
} Exchange;

typedef struct {
    unsigned magic;
    char *name;
    fmi2CallbackLogger logger;
    fmi2ComponentEnvironment env;
    int logging_on;
    PyObject *inst;     /* bridge.Instance */
    int in_error;       /* after fmi2Error: only get/set state, get*, reset, terminate, free */
    int fatal;          /* after fmi2Fatal: only free */
    int terminated;     /* a step was discarded: fmi2Terminated status */
    double time;        /* end of the last successful step */
    Exchange x;
    char last_error[1024];
} Instance;

typedef struct {
    unsigned magic;
    PyObject *obj;
} State;

/* ------------------------------------------------------------------ logging */
static void emit(fmi2CallbackLogger logger, fmi2ComponentEnvironment env, const char *name, fmi2Status status,
                 const char *category, const char *text)
{
    if (logger) {
        logger(env, name ? name : "cam", status, category, "%s", text);
    } else {
        fprintf(stderr, "[%s] %s: %s\n", name ? name : "", category, text);
    }
}

static void logf_(Instance *c, fmi2Status status, const char *category, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
static void logf_(Instance *c, fmi2Status status, const char *category, const char *fmt, ...)
{
    char text[2048];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(text, sizeof text, fmt, ap);
    va_end(ap);
    if (status == fmi2OK && !c->logging_on) return;
    emit(c->logger, c->env, c->name, status, category, text);
}

/* ------------------------------------------------------------------ small helpers */
static void strip(char *s)
{
    size_t n = strlen(s);
    while (n && (s[n - 1] == '\n' || s[n - 1] == '\r' || s[n - 1] == ' ' || s[n - 1] == '\t')) s[--n] = 0;
}

static int is_file(const char *path)
{
    struct stat st;
    return path && *path && stat(path, &st) == 0 && S_ISREG(st.st_mode);
}

static int hexval(int ch)
{
    if (ch >= '0' && ch <= '9') return ch - '0';
    if (ch >= 'a' && ch <= 'f') return ch - 'a' + 10;
    if (ch >= 'A' && ch <= 'F') return ch - 'A' + 10;
    return -1;
}

/* file:///a/b, file:/a/b, file://localhost/a/b (percent-decoded) or a plain path -> /a/b */
static int uri_to_path(const char *uri, char *out, size_t size)
{
    const char *p = uri;
    size_t n = 0;
    if (!uri || !*uri) return -1;
    if (strncmp(p, "file:", 5) == 0) {
        p += 5;
        if (strncmp(p, "//", 2) == 0) {
            p += 2;
            if (strncmp(p, "localhost", 9) == 0) p += 9;
        }
    }
    if (*p != '/') return -1;
    for (; *p && n + 1 < size; p++) {
        if (*p == '%' && hexval(p[1]) >= 0 && hexval(p[2]) >= 0) {
            out[n++] = (char)(hexval(p[1]) * 16 + hexval(p[2]));
            p += 2;
        } else {
            out[n++] = *p;
        }
    }
    out[n] = 0;
    while (n > 1 && out[n - 1] == '/') out[--n] = 0;
    return 0;
}

/* <fmu>/binaries/linux64/cam.so -> <fmu>/resources */
static int resources_from_library(char *out, size_t size)
{
    Dl_info info;
    char *slash;
    if (!dladdr((void *)&resources_from_library, &info) || !info.dli_fname) return -1;
    if (!realpath(info.dli_fname, out)) snprintf(out, size, "%s", info.dli_fname);
    for (int k = 0; k < 3; k++) {
        slash = strrchr(out, '/');
        if (!slash) return -1;
        *slash = 0;
    }
    if (strlen(out) + 11 >= size) return -1;
    strcat(out, "/resources");
    return 0;
}

/* Reads "key=value" lines of resources/<file>; calls back for each. */
static int read_keyvalues(const char *path, void (*cb)(const char *, const char *, void *), void *data)
{
    char line[PATH_MAX + 64];
    FILE *f = fopen(path, "r");
    if (!f) return -1;
    while (fgets(line, sizeof line, f)) {
        char *eq;
        strip(line);
        if (!line[0] || line[0] == '#') continue;
        eq = strchr(line, '=');
        if (!eq) continue;
        *eq = 0;
        cb(line, eq + 1, data);
    }
    fclose(f);
    return 0;
}

/* ------------------------------------------------------------------ where Python is */
typedef struct {
    char executable[PATH_MAX];
    char libpython[PATH_MAX];
    char home[PATH_MAX];
    char sites[8][PATH_MAX];
    int nsites;
    char version[32];
    char source[PATH_MAX + 32];
} PyLocation;

static void location_kv(const char *key, const char *value, void *data)
{
    PyLocation *loc = data;
    if (!strcmp(key, "executable")) snprintf(loc->executable, PATH_MAX, "%s", value);
    else if (!strcmp(key, "libpython")) snprintf(loc->libpython, PATH_MAX, "%s", value);
    else if (!strcmp(key, "home")) snprintf(loc->home, PATH_MAX, "%s", value);
    else if (!strcmp(key, "version")) snprintf(loc->version, sizeof loc->version, "%s", value);
    else if (!strcmp(key, "site") && loc->nsites < 8) snprintf(loc->sites[loc->nsites++], PATH_MAX, "%s", value);
}

static const char QUERY[] =
    "import sys, sysconfig, os, site\n"
    "v = sysconfig.get_config_var\n"
    "print('executable=' + sys.executable)\n"
    "print('libpython=' + os.path.join(v('LIBDIR') or '', v('INSTSONAME') or v('LDLIBRARY') or ''))\n"
    "print('home=' + sys.base_prefix)\n"
    "print('version=%d.%d' % sys.version_info[:2])\n"
    "[print('site=' + p) for p in dict.fromkeys(site.getsitepackages())]\n";

/* Ask a python executable where its libpython, home and site-packages are. */
static int query_executable(const char *exe, PyLocation *loc, char *err, size_t errsize)
{
    char cmd[PATH_MAX + sizeof QUERY + 64], line[PATH_MAX + 64];
    FILE *p;
    if (strchr(exe, '\'') || !is_file(exe)) {
        snprintf(err, errsize, "'%s' is not a python executable", exe);
        return -1;
    }
    snprintf(cmd, sizeof cmd, "'%s' -I -c \"$CAM_FMU_QUERY\" 2>&1", exe);
    setenv("CAM_FMU_QUERY", QUERY, 1);
    p = popen(cmd, "r");
    unsetenv("CAM_FMU_QUERY");
    if (!p) {
        snprintf(err, errsize, "cannot run '%s': %s", exe, strerror(errno));
        return -1;
    }
    while (fgets(line, sizeof line, p)) {
        char *eq;
        strip(line);
        eq = strchr(line, '=');
        if (!eq) continue;
        *eq = 0;
        location_kv(line, eq + 1, loc);
    }
    if (pclose(p) != 0 || !loc->libpython[0]) {
        snprintf(err, errsize, "'%s' did not report its libpython", exe);
        return -1;
    }
    return 0;
}

static int find_python(const char *resources, PyLocation *loc, char *err, size_t errsize)
{
    const char *env = getenv("CAM_FMU_PYTHON");
    memset(loc, 0, sizeof *loc);
    if (env && *env) {
        const char *base = strrchr(env, '/');
        base = base ? base + 1 : env;
        snprintf(loc->source, sizeof loc->source, "CAM_FMU_PYTHON=%s", env);
        if (strncmp(base, "libpython", 9) == 0) {
            char *slash;
            snprintf(loc->libpython, PATH_MAX, "%s", env);
            snprintf(loc->home, PATH_MAX, "%s", env);           /* <home>/lib/libpython3.X.so */
            for (int k = 0; k < 2 && (slash = strrchr(loc->home, '/')); k++) *slash = 0;
            return 0;
        }
        return query_executable(env, loc, err, errsize);
    }
    {
        char path[PATH_MAX + 16];
        snprintf(path, sizeof path, "%s/python.txt", resources);
        snprintf(loc->source, sizeof loc->source, "%s", path);
        if (read_keyvalues(path, location_kv, loc) != 0) {
            snprintf(err, errsize, "no CAM_FMU_PYTHON and cannot read %s", path);
            return -1;
        }
        if (!loc->libpython[0]) {
            snprintf(err, errsize, "%s names no libpython", path);
            return -1;
        }
    }
    return 0;
}

/* ------------------------------------------------------------------ starting Python */
static int load_api(void *handle, char *err, size_t errsize)
{
#define LOAD_PTR(name)                                                                     \
    if (!p_##name) {                                                                       \
        p_##name = (__typeof__(p_##name))dlsym(handle, #name);                             \
        if (!p_##name) {                                                                   \
            snprintf(err, errsize, "libpython lacks %s", #name);                           \
            return -1;                                                                     \
        }                                                                                  \
    }
    PY_FUNCTIONS(LOAD_PTR)
#undef LOAD_PTR
    p_none = (PyObject *)dlsym(handle, "_Py_NoneStruct");
    if (!p_none) {
        snprintf(err, errsize, "libpython lacks _Py_NoneStruct");
        return -1;
    }
    p_is_finalizing = (int (*)(void))dlsym(handle, "Py_IsFinalizing");
    if (!p_is_finalizing) p_is_finalizing = (int (*)(void))dlsym(handle, "_Py_IsFinalizing");
    return 0;
}

/* The interpreter runs and is not shutting down: Python may be called (from any thread). */
static int python_usable(void)
{
    return g_python_ready && p_Py_IsInitialized() && !(p_is_finalizing && p_is_finalizing());
}

static void reset_api(void)
{
    p_is_finalizing = NULL;
    p_none = NULL;
#define CLEAR_PTR(name) p_##name = NULL;
    PY_FUNCTIONS(CLEAR_PTR)
#undef CLEAR_PTR
}

static int version_ok(char *err, size_t errsize)
{
    char want[16];
    const char *have = p_Py_GetVersion();
    snprintf(want, sizeof want, "%d.%d.", PY_MAJOR_VERSION, PY_MINOR_VERSION);
    if (strncmp(have, want, strlen(want)) != 0) {
        snprintf(err, errsize, "this FMU was built for Python %d.%d, the Python found is %.20s",
                 PY_MAJOR_VERSION, PY_MINOR_VERSION, have);
        return -1;
    }
    return 0;
}

/* callable(*Py_BuildValue(fmt, ...)); fmt must describe a tuple, e.g. "(dd)" */
static PyObject *call(PyObject *callable, const char *fmt, ...)
{
    PyObject *args, *result;
    va_list ap;
    va_start(ap, fmt);
    args = p_Py_VaBuildValue(fmt, ap);
    va_end(ap);
    if (!args) return NULL;
    result = p_PyObject_CallObject(callable, args);
    p_Py_DecRef(args);
    return result;
}

static const char ADD_SITES[] =
    "def _cam_fmu_add_sites(paths):\n"
    "    import os, site, sys\n"
    "    for p in paths.split('\\n'):\n"
    "        if p and os.path.isdir(p) and p not in sys.path:\n"
    "            site.addsitedir(p)\n";

static int start_interpreter(const PyLocation *loc, char *err, size_t errsize)
{
    PyPreConfig pre;
    PyConfig config;
    PyStatus status;
    const char *alloc = getenv("PYTHONMALLOC");

    p_PyPreConfig_InitIsolatedConfig(&pre);
    if (alloc && !strcmp(alloc, "malloc")) pre.allocator = PYMEM_ALLOCATOR_MALLOC;   /* for valgrind */
    else if (alloc && !strcmp(alloc, "malloc_debug")) pre.allocator = PYMEM_ALLOCATOR_MALLOC_DEBUG;
    pre.utf8_mode = 1;
    status = p_Py_PreInitialize(&pre);
    if (p_PyStatus_Exception(status)) {
        snprintf(err, errsize, "Py_PreInitialize failed: %s", status.err_msg ? status.err_msg : "?");
        return -1;
    }
    p_PyConfig_InitIsolatedConfig(&config);
    config.install_signal_handlers = 0;
    config.site_import = 1;
    config.parse_argv = 0;
    config.write_bytecode = 0;   /* never write __pycache__ into the host's FMU folder */
    if (loc->home[0]) {
        status = p_PyConfig_SetBytesString(&config, &config.home, loc->home);
        if (p_PyStatus_Exception(status)) goto fail;
    }
    if (loc->executable[0]) {
        status = p_PyConfig_SetBytesString(&config, &config.executable, loc->executable);
        if (p_PyStatus_Exception(status)) goto fail;
        status = p_PyConfig_SetBytesString(&config, &config.program_name, loc->executable);
        if (p_PyStatus_Exception(status)) goto fail;
    }
    status = p_Py_InitializeFromConfig(&config);
    if (p_PyStatus_Exception(status)) goto fail;
    p_PyConfig_Clear(&config);

    /* site-packages recorded at build time (a venv's, for example) */
    {
        char joined[8 * (PATH_MAX + 1)] = "";
        PyObject *globals = p_PyDict_New(), *res, *fn;
        for (int k = 0; k < loc->nsites; k++) {
            strcat(joined, loc->sites[k]);
            strcat(joined, "\n");
        }
        p_PyDict_SetItemString(globals, "__builtins__", p_PyEval_GetBuiltins());
        res = p_PyRun_StringFlags(ADD_SITES, Py_file_input, globals, globals, NULL);
        fn = res ? p_PyDict_GetItemString(globals, "_cam_fmu_add_sites") : NULL;
        if (res) p_Py_DecRef(res);
        if (fn) {
            PyObject *r = call(fn, "(s)", joined);
            if (r) p_Py_DecRef(r);
        }
        if (p_PyErr_Occurred()) p_PyErr_Clear();   /* a missing site folder is not fatal */
        p_Py_DecRef(globals);
    }
    p_PyEval_SaveThread();   /* release the GIL: every call takes it with PyGILState_Ensure */
    return 0;
fail:
    snprintf(err, errsize, "starting Python (home %s) failed: %s%s%s", loc->home[0] ? loc->home : "?",
             status.func ? status.func : "", status.func ? ": " : "", status.err_msg ? status.err_msg : "?");
    p_PyConfig_Clear(&config);
    return -1;
}

/* Makes sure an interpreter runs and the API pointers are set.  0 on success. */
static int ensure_python(const char *resources, char *err, size_t errsize, const char **mode)
{
    int rc = 0;
    pthread_mutex_lock(&g_lock);
    if (g_python_ready) {
        *mode = g_python_owned ? "started by this FMU" : "the host's";
        goto done;
    }
    {
        /* A Python host (fmpy, libcosimpy): its interpreter is already running. */
        int (*is_init)(void) = (int (*)(void))dlsym(RTLD_DEFAULT, "Py_IsInitialized");
        if (is_init && is_init()) {
            if (load_api(RTLD_DEFAULT, err, errsize) != 0) { reset_api(); rc = -1; goto done; }
            g_python_ready = 1;
            g_python_owned = 0;
            *mode = "the host's";
            goto done;
        }
    }
    {
        PyLocation loc;
        void *handle;
        char where[PATH_MAX + 64];
        if (find_python(resources, &loc, err, errsize) != 0) { rc = -1; goto done; }
        snprintf(where, sizeof where, " (from %s)", loc.source);
        handle = dlopen(loc.libpython, RTLD_NOW | RTLD_GLOBAL);   /* never dlclose'd */
        if (!handle) {
            snprintf(err, errsize, "cannot load libpython %s%s: %s", loc.libpython, where, dlerror());
            rc = -1;
            goto done;
        }
        if (load_api(handle, err, errsize) != 0 || version_ok(err, errsize) != 0) {
            strncat(err, where, errsize - strlen(err) - 1);
            reset_api();
            rc = -1;
            goto done;
        }
        if (p_Py_IsInitialized()) {          /* e.g. preloaded and started by another library */
            g_python_owned = 0;
            *mode = "already running";
        } else {
            if (start_interpreter(&loc, err, errsize) != 0) {
                strncat(err, where, errsize - strlen(err) - 1);
                rc = -1;
                goto done;
            }
            g_python_owned = 1;
            *mode = "started by this FMU";
        }
        g_python_ready = 1;
    }
done:
    pthread_mutex_unlock(&g_lock);
    return rc;
}

/* Text of the pending Python exception (cleared). GIL held. */
static void fetch_error(char *buf, size_t size)
{
    PyObject *type = NULL, *value = NULL, *tb = NULL;
    const char *tname = "error", *text = "";
    PyObject *name = NULL, *str = NULL;
    if (!p_PyErr_Occurred()) {
        snprintf(buf, size, "Python call failed without an exception");
        return;
    }
    p_PyErr_Fetch(&type, &value, &tb);
    p_PyErr_NormalizeException(&type, &value, &tb);
    if (type) name = p_PyObject_GetAttrString(type, "__name__");
    if (name) tname = p_PyUnicode_AsUTF8(name);
    if (value) str = p_PyObject_Str(value);
    if (str) text = p_PyUnicode_AsUTF8(str);
    p_PyErr_Clear();
    snprintf(buf, size, "%s: %s", tname ? tname : "error", text ? text : "");
    if (name) p_Py_DecRef(name);
    if (str) p_Py_DecRef(str);
    if (type) p_Py_DecRef(type);
    if (value) p_Py_DecRef(value);
    if (tb) p_Py_DecRef(tb);
}

static void native_kv(const char *key, const char *value, void *data)
{
    (void)data;
    if (!strcmp(key, "package")) snprintf(g_package, sizeof g_package, "%s", value);
    else if (!strcmp(key, "slave_module")) snprintf(g_slave, sizeof g_slave, "%s", value);
}

static const char LOADER[] =
    "def _cam_fmu_load(package, slave, resources):\n"
    "    import importlib, importlib.util, os, sys\n"
    "    if package not in sys.modules:\n"
    "        folder = os.path.join(resources, package)\n"
    "        spec = importlib.util.spec_from_file_location(\n"
    "            package, os.path.join(folder, '__init__.py'), submodule_search_locations=[folder])\n"
    "        module = importlib.util.module_from_spec(spec)\n"
    "        sys.modules[package] = module\n"
    "        try:\n"
    "            spec.loader.exec_module(module)\n"
    "        except BaseException:\n"
    "            sys.modules.pop(package, None)\n"
    "            raise\n"
    "    bridge = importlib.import_module(package + '._fmi_bridge')\n"
    "    return bridge, bridge.load(package, slave, resources)\n";

/* Imports the bridge and the slave class (GIL held).  0 on success. */
static int load_bridge(const char *resources, char *err, size_t errsize)
{
    char path[PATH_MAX + 16];
    PyObject *globals, *res, *fn, *pair = NULL;
    if (g_bridge) {   /* imported before, detached after the last instance: re-register the names */
        PyObject *attach = p_PyObject_GetAttrString(g_bridge, "attach");
        PyObject *r = attach ? p_PyObject_CallObject(attach, NULL) : NULL;
        if (attach) p_Py_DecRef(attach);
        if (!r) {
            fetch_error(err, errsize);
            return -1;
        }
        p_Py_DecRef(r);
        return 0;
    }
    g_package[0] = g_slave[0] = 0;
    snprintf(path, sizeof path, "%s/native.txt", resources);
    if (read_keyvalues(path, native_kv, NULL) != 0 || !g_package[0] || !g_slave[0]) {
        snprintf(err, errsize, "cannot read package and slave_module from %s", path);
        return -1;
    }
    globals = p_PyDict_New();
    if (!globals) { fetch_error(err, errsize); return -1; }
    p_PyDict_SetItemString(globals, "__builtins__", p_PyEval_GetBuiltins());
    res = p_PyRun_StringFlags(LOADER, Py_file_input, globals, globals, NULL);
    fn = res ? p_PyDict_GetItemString(globals, "_cam_fmu_load") : NULL;
    if (res) p_Py_DecRef(res);
    if (fn) pair = call(fn, "(sss)", g_package, g_slave, resources);
    if (!pair || p_PyTuple_Size(pair) != 2) {
        char why[1500];
        fetch_error(why, sizeof why);
        snprintf(err, errsize, "cannot import the FMU's Python code %s/%s from %s: %s", g_package, g_slave,
                 resources, why);
        if (pair) p_Py_DecRef(pair);
        p_Py_DecRef(globals);
        return -1;
    }
    g_bridge = p_PyTuple_GetItem(pair, 0);
    g_class = p_PyTuple_GetItem(pair, 1);
    p_Py_IncRef(g_bridge);
    p_Py_IncRef(g_class);
    p_Py_DecRef(pair);
    p_Py_DecRef(globals);
    return 0;
}

/* After the last instance: take the FMU's names out of sys.modules (GIL held).  The bridge and the
 * class stay referenced here, so the next fmi2Instantiate re-attaches them instead of importing. */
static void detach_bridge(void)
{
    if (g_bridge) {
        PyObject *fn = p_PyObject_GetAttrString(g_bridge, "detach");
        PyObject *r = fn ? call(fn, "(ss)", g_package, g_slave) : NULL;
        if (r) p_Py_DecRef(r);
        if (fn) p_Py_DecRef(fn);
        if (p_PyErr_Occurred()) p_PyErr_Clear();
    }
}

/* Library unload (dlclose by the host, or process exit).  Only in a Python host whose interpreter still
 * runs (fmpy's freeLibrary): drop our references so the FMU's modules can be collected.  After
 * Py_Finalize (process exit of a Python host) and in native hosts (our interpreter is never finalised)
 * nothing is done: no Python code runs from the ELF destructor. */
__attribute__((destructor)) static void on_library_unload(void)
{
    if (g_python_owned || !g_bridge || !python_usable()) return;
    {
        PyGILState_STATE gil = p_PyGILState_Ensure();
        p_Py_DecRef(g_class);
        p_Py_DecRef(g_bridge);
        g_class = g_bridge = NULL;
        p_PyGILState_Release(gil);
    }
}

/* ------------------------------------------------------------------ calling the bridge */
/* c->inst.method(*args) -> (status, payload, messages).  GIL held.  *payload gets a new reference. */
static fmi2Status invoke(Instance *c, const char *method, PyObject **payload, const char *fmt, ...)
{
    PyObject *fn, *args = NULL, *res, *st, *pl, *msgs;
    long status;
    va_list ap;
    if (payload) *payload = NULL;
    fn = p_PyObject_GetAttrString(c->inst, method);
    if (fn && fmt) {
        va_start(ap, fmt);
        args = p_Py_VaBuildValue(fmt, ap);
        va_end(ap);
    }
    res = (fn && (args || !fmt)) ? p_PyObject_CallObject(fn, args) : NULL;
    if (args) p_Py_DecRef(args);
    if (fn) p_Py_DecRef(fn);
    st = res ? p_PyTuple_GetItem(res, 0) : NULL;
    pl = st ? p_PyTuple_GetItem(res, 1) : NULL;
    msgs = pl ? p_PyTuple_GetItem(res, 2) : NULL;
    status = st ? p_PyLong_AsLong(st) : -1;
    if (!msgs || status < 0 || status > fmi2Fatal) {
        char why[1500];
        fetch_error(why, sizeof why);
        if (res) p_Py_DecRef(res);
        c->fatal = 1;
        snprintf(c->last_error, sizeof c->last_error, "%s", why);
        logf_(c, fmi2Fatal, "logStatusFatal", "%s: the Python interpreter failed: %s", method, why);
        return fmi2Fatal;
    }
    {
        Py_ssize_t n = p_PyList_Size(msgs);   /* -1 (with an exception) for None */
        if (n < 0) p_PyErr_Clear();
        for (Py_ssize_t i = 0; i < n; i++) {
            PyObject *m = p_PyList_GetItem(msgs, i);
            PyObject *ms = m ? p_PyTuple_GetItem(m, 0) : NULL;
            PyObject *mc = ms ? p_PyTuple_GetItem(m, 1) : NULL;
            PyObject *mt = mc ? p_PyTuple_GetItem(m, 2) : NULL;
            const char *cat = mc ? p_PyUnicode_AsUTF8(mc) : NULL;
            const char *text = mt ? p_PyUnicode_AsUTF8(mt) : NULL;
            long s = ms ? p_PyLong_AsLong(ms) : 0;
            if (!text || !cat) { p_PyErr_Clear(); continue; }
            if (s < 0 || s > fmi2Fatal) s = fmi2OK;
            if (s >= fmi2Discard && status >= fmi2Discard) snprintf(c->last_error, sizeof c->last_error, "%s", text);
            logf_(c, (fmi2Status)s, cat, "%s", text);
        }
    }
    if (payload) {
        *payload = pl;
        p_Py_IncRef(pl);
    }
    p_Py_DecRef(res);
    if (status == fmi2Error) c->in_error = 1;
    if (status == fmi2Discard) c->terminated = 1;
    return (fmi2Status)status;
}

/* ------------------------------------------------------------------ entry checks */
static Instance *checked(fmi2Component comp, const char *fname, int allowed_after_error, fmi2Status *st)
{
    Instance *c = comp;
    if (!c || c->magic != INSTANCE_MAGIC) {
        fprintf(stderr, "[FMU] %s: invalid fmi2Component %p\n", fname, comp);
        *st = fmi2Error;
        return NULL;
    }
    if (c->fatal) {
        logf_(c, fmi2Fatal, "logStatusFatal", "%s: not possible after fmi2Fatal (only fmi2FreeInstance is)", fname);
        *st = fmi2Fatal;
        return NULL;
    }
    if (c->in_error && !allowed_after_error) {
        logf_(c, fmi2Error, "logStatusError",
              "%s: not allowed after fmi2Error (last error: %s); call fmi2SetFMUstate or fmi2Reset first",
              fname, c->last_error);
        *st = fmi2Error;
        return NULL;
    }
    return c;
}

#define ENTER(fname, after_error)                                         \
    fmi2Status st_;                                                       \
    Instance *c = checked(comp, fname, after_error, &st_);                \
    if (!c) return st_;                                                   \
    PyGILState_STATE gil_ = p_PyGILState_Ensure();

#define LEAVE(value)                                                      \
    do {                                                                  \
        fmi2Status result_ = (value); /* evaluated with the GIL held */   \
        p_PyGILState_Release(gil_);                                       \
        return result_;                                                   \
    } while (0)

static PyObject *packed(const void *data, size_t bytes)
{
    return p_PyBytes_FromStringAndSize(data ? (const char *)data : "", (Py_ssize_t)bytes);
}

/* ------------------------------------------------------------------ the exchange */
/* Ask the bridge for the exchange and check its layout (GIL held).  Without one (another slave: the
 * bridge answers None, quietly; or a layout that does not fit: a warning) every value call goes to
 * Python, as before.  None is checked before PyByteArray_AsString, which is undefined for it. */
static void share_exchange(Instance *c)
{
    PyObject *buffer = NULL;
    char *data;
    Py_ssize_t size;
    int *h;
    fmi2Status s = invoke(c, "share", &buffer, NULL);
    if (s == fmi2Error || s == fmi2Discard) {   /* logged; the instance works without the exchange */
        c->in_error = c->terminated = 0;
        logf_(c, fmi2Warning, "logStatusWarning", "the exchange could not be set up: every value call goes to Python");
    }
    if (s != fmi2OK || !buffer || buffer == p_none) {
        if (buffer) p_Py_DecRef(buffer);
        return;
    }
    data = p_PyByteArray_AsString(buffer);
    size = data ? p_PyByteArray_Size(buffer) : -1;
    h = (int *)data;
    if (!data || size < (Py_ssize_t)(X_HEAD * sizeof(int)) || h[X_MAGIC] != EXCHANGE_MAGIC || h[X_N_OUT] < 0 ||
        h[X_N_IN] < 0 || h[X_N_OUT] + h[X_N_IN] > 1024 || h[X_OFF_VR] < (int)(X_HEAD * sizeof(int)) ||
        h[X_OFF_LO] % 8 || h[X_OFF_HI] % 8 || h[X_OFF_VALUE] % 8 ||
        h[X_OFF_VR] + 4L * (h[X_N_OUT] + h[X_N_IN]) > size || h[X_OFF_LO] + 8L * (h[X_N_OUT] + h[X_N_IN]) > size ||
        h[X_OFF_HI] + 8L * (h[X_N_OUT] + h[X_N_IN]) > size || h[X_OFF_VALUE] + 8L * (h[X_N_OUT] + h[X_N_IN]) > size) {
        if (!data) p_PyErr_Clear();
        logf_(c, fmi2Warning, "logStatusWarning", "the bridge's exchange has an unexpected layout: not used");
        p_Py_DecRef(buffer);
        return;
    }
    c->x.buffer = buffer;
    c->x.head = h;
    c->x.vr = (const fmi2ValueReference *)(data + h[X_OFF_VR]);
    c->x.lo = (const double *)(data + h[X_OFF_LO]);
    c->x.hi = (const double *)(data + h[X_OFF_HI]);
    c->x.value = (double *)(data + h[X_OFF_VALUE]);
    c->x.n_out = h[X_N_OUT];
    c->x.n = h[X_N_OUT] + h[X_N_IN];
}

static int slot_of(const Exchange *x, fmi2ValueReference vr)
{
    for (int k = 0; k < x->n; k++)
        if (x->vr[k] == vr) return k;
    return -1;
}

/* fmi2GetReal answered from the exchange: 1, or 0 when Python must answer (a variable not in it, or
 * outputs not yet calculated).  No GIL: only this instance's calls touch its exchange, one at a time. */
static int exchange_get(const Exchange *x, const fmi2ValueReference vr[], size_t nvr, fmi2Real value[])
{
    if (!x->buffer || !x->head[X_READY]) return 0;
    for (size_t i = 0; i < nvr; i++) {
        int k = slot_of(x, vr[i]);
        if (k < 0) return 0;
        value[i] = x->value[k];
    }
    return 1;
}

/* fmi2SetReal of inputs, each within its range, into the exchange: 1, or 0 when Python must answer
 * (another variable, or a value out of range or NaN: Python's message names it).  Nothing is written
 * unless every value passes. */
static int exchange_set(Exchange *x, const fmi2ValueReference vr[], size_t nvr, const fmi2Real value[])
{
    if (!x->buffer) return 0;
    for (size_t i = 0; i < nvr; i++) {
        int k = slot_of(x, vr[i]);
        if (k < x->n_out || !(x->lo[k] <= value[i] && value[i] <= x->hi[k])) return 0;
    }
    for (size_t i = 0; i < nvr; i++) x->value[slot_of(x, vr[i])] = value[i];
    x->head[X_DIRTY] = 1;
    return 1;
}

/* ------------------------------------------------------------------ FMI 2.0 API */
EXPORT const char *fmi2GetTypesPlatform(void) { return "default"; }
EXPORT const char *fmi2GetVersion(void) { return "2.0"; }

EXPORT fmi2Status fmi2SetDebugLogging(fmi2Component comp, fmi2Boolean loggingOn, size_t n, const fmi2String cats[])
{
    Instance *c = comp;
    (void)n;
    (void)cats;
    if (!c || c->magic != INSTANCE_MAGIC) return fmi2Error;
    c->logging_on = loggingOn ? 1 : 0;
    return fmi2OK;
}

EXPORT fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid, fmi2String resourceLocation,
                                     const fmi2CallbackFunctions *functions, fmi2Boolean visible,
                                     fmi2Boolean loggingOn)
{
    char resources[PATH_MAX], err[2048];
    const char *mode = "";
    fmi2CallbackLogger logger = functions ? functions->logger : NULL;
    fmi2ComponentEnvironment env = functions ? functions->componentEnvironment : NULL;
    Instance *c;
    PyGILState_STATE gil;
    PyObject *cls_fn;
    fmi2Status status;
    (void)guid;

    if (type != fmi2CoSimulation) {
        emit(logger, env, name, fmi2Error, "logStatusError", "this FMU supports co-simulation only");
        return NULL;
    }
    if (uri_to_path(resourceLocation, resources, sizeof resources) != 0 &&
        resources_from_library(resources, sizeof resources) != 0) {
        emit(logger, env, name, fmi2Error, "logStatusError", "this FMU cannot locate its resources folder");
        return NULL;
    }
    if (ensure_python(resources, err, sizeof err, &mode) != 0) {
        char text[2600];
        snprintf(text, sizeof text,
                 "this FMU needs Python %d.%d with numpy and found none usable: %s. Point the environment "
                 "variable CAM_FMU_PYTHON at a python%d.%d executable (or its libpython%d.%d.so), or edit "
                 "resources/python.txt in the FMU.",
                 PY_MAJOR_VERSION, PY_MINOR_VERSION, err, PY_MAJOR_VERSION, PY_MINOR_VERSION, PY_MAJOR_VERSION,
                 PY_MINOR_VERSION);
        emit(logger, env, name, fmi2Error, "logStatusError", text);
        return NULL;
    }
    c = calloc(1, sizeof *c);
    if (!c) return NULL;
    c->magic = INSTANCE_MAGIC;
    c->name = strdup(name ? name : "cam");
    c->logger = logger;
    c->env = env;
    c->logging_on = loggingOn ? 1 : 0;

    gil = p_PyGILState_Ensure();
    if (load_bridge(resources, err, sizeof err) != 0) {
        logf_(c, fmi2Error, "logStatusError", "%s", err);
        goto fail;
    }
    cls_fn = p_PyObject_GetAttrString(g_bridge, "Instance");
    c->inst = cls_fn ? call(cls_fn, "(Ossi)", g_class, c->name, resources, visible ? 1 : 0) : NULL;
    if (cls_fn) p_Py_DecRef(cls_fn);
    if (!c->inst) {
        fetch_error(err, sizeof err);
        logf_(c, fmi2Error, "logStatusError", "cannot create the instance: %s", err);
        goto fail;
    }
    g_live++;
    status = invoke(c, "create", NULL, NULL);
    if (status != fmi2OK) {
        logf_(c, fmi2Error, "logStatusError", "the slave could not be created (status %d)", (int)status);
        p_Py_DecRef(c->inst);
        c->inst = NULL;
        g_live--;
        goto fail;
    }
    share_exchange(c);
    logf_(c, fmi2OK, "logAll", "Python %.*s (%s), module %s", (int)strcspn(p_Py_GetVersion(), " "),
          p_Py_GetVersion(), mode, g_slave);
    p_PyGILState_Release(gil);
    return c;
fail:
    if (g_live == 0) detach_bridge();
    p_PyGILState_Release(gil);
    free(c->name);
    c->magic = 0;
    free(c);
    return NULL;
}

EXPORT void fmi2FreeInstance(fmi2Component comp)
{
    Instance *c = comp;
    if (!c || c->magic != INSTANCE_MAGIC) return;
    c->magic = 0;
    if (python_usable()) {   /* during a Python host's shutdown, leave its objects to it */
        PyGILState_STATE gil = p_PyGILState_Ensure();
        if (c->x.buffer) p_Py_DecRef(c->x.buffer);
        if (c->inst) {
            p_Py_DecRef(c->inst);
            g_live--;
        }
        if (g_live <= 0) {
            g_live = 0;
            detach_bridge();
        }
        p_PyGILState_Release(gil);
    }
    free(c->name);
    free(c);
}

EXPORT fmi2Status fmi2SetupExperiment(fmi2Component comp, fmi2Boolean toleranceDefined, fmi2Real tolerance,
                                      fmi2Real startTime, fmi2Boolean stopTimeDefined, fmi2Real stopTime)
{
    ENTER("fmi2SetupExperiment", 0)
    c->time = startTime;
    LEAVE(invoke(c, "setup_experiment", NULL, "(didid)", startTime, stopTimeDefined ? 1 : 0, stopTime,
                 toleranceDefined ? 1 : 0, tolerance));
}

EXPORT fmi2Status fmi2EnterInitializationMode(fmi2Component comp)
{
    ENTER("fmi2EnterInitializationMode", 0)
    LEAVE(invoke(c, "enter_initialization_mode", NULL, NULL));
}

EXPORT fmi2Status fmi2ExitInitializationMode(fmi2Component comp)
{
    ENTER("fmi2ExitInitializationMode", 0)
    LEAVE(invoke(c, "exit_initialization_mode", NULL, NULL));
}

EXPORT fmi2Status fmi2Terminate(fmi2Component comp)
{
    ENTER("fmi2Terminate", 1)
    LEAVE(invoke(c, "terminate", NULL, NULL));
}

EXPORT fmi2Status fmi2Reset(fmi2Component comp)
{
    fmi2Status s;
    ENTER("fmi2Reset", 1)
    s = invoke(c, "reset", NULL, NULL);
    if (s == fmi2OK) {
        c->in_error = 0;
        c->terminated = 0;
        c->time = 0.0;
    }
    LEAVE(s);
}

/* ---- values */
/* Every output array gets safe values (0, false, "") before a call is checked, so a host that reads it
 * after a refused call (an invalid instance, an unknown value reference, fmi2Error) reads no garbage. */
static void zero_out(void *out, size_t n, size_t item)
{
    if (out && n) memset(out, 0, n * item);
}

static void empty_strings(fmi2String value[], size_t n)
{
    if (value)
        for (size_t i = 0; i < n; i++) value[i] = "";
}

static fmi2Status get_values(fmi2Component comp, const char *fname, const char *method,
                             const fmi2ValueReference vr[], size_t nvr, void *out, size_t item)
{
    PyObject *vrs, *payload = NULL;
    fmi2Status s;
    char *data;
    Py_ssize_t size;
    zero_out(out, nvr, item);
    ENTER(fname, 1)
    if (nvr == 0) LEAVE(fmi2OK);
    if (!vr || !out) {
        logf_(c, fmi2Error, "logStatusError", "%s: NULL array", fname);
        LEAVE(fmi2Error);
    }
    vrs = packed(vr, nvr * sizeof *vr);
    s = vrs ? invoke(c, method, &payload, "(O)", vrs) : fmi2Fatal;
    if (vrs) p_Py_DecRef(vrs);
    if (s == fmi2OK) {
        if (p_PyBytes_AsStringAndSize(payload, &data, &size) != 0 || (size_t)size != nvr * item) {
            p_PyErr_Clear();
            logf_(c, fmi2Error, "logStatusError", "%s: the slave returned %ld bytes, expected %zu", fname,
                  (long)size, nvr * item);
            s = fmi2Error;
        } else {
            memcpy(out, data, nvr * item);
        }
    }
    if (payload) p_Py_DecRef(payload);
    LEAVE(s);
}

static fmi2Status set_values(fmi2Component comp, const char *fname, const char *method,
                             const fmi2ValueReference vr[], size_t nvr, const void *in, size_t item)
{
    PyObject *vrs, *vals;
    fmi2Status s = fmi2Fatal;
    ENTER(fname, 0)
    if (nvr == 0) LEAVE(fmi2OK);
    if (!vr || !in) {
        logf_(c, fmi2Error, "logStatusError", "%s: NULL array", fname);
        LEAVE(fmi2Error);
    }
    vrs = packed(vr, nvr * sizeof *vr);
    vals = packed(in, nvr * item);
    if (vrs && vals) s = invoke(c, method, NULL, "(OO)", vrs, vals);
    if (vrs) p_Py_DecRef(vrs);
    if (vals) p_Py_DecRef(vals);
    LEAVE(s);
}

/* The instance, when a value call may be answered from its exchange (otherwise the full path reports). */
static Instance *exchange_instance(fmi2Component comp, int allowed_after_error)
{
    Instance *c = comp;
    return c && c->magic == INSTANCE_MAGIC && !c->fatal && (allowed_after_error || !c->in_error) ? c : NULL;
}

EXPORT fmi2Status fmi2GetReal(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr, fmi2Real value[])
{
    Instance *c = exchange_instance(comp, 1);
    if (c && vr && value && exchange_get(&c->x, vr, nvr, value)) return fmi2OK;
    return get_values(comp, "fmi2GetReal", "get_real", vr, nvr, value, sizeof(fmi2Real));
}

EXPORT fmi2Status fmi2GetInteger(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr,
                                 fmi2Integer value[])
{
    return get_values(comp, "fmi2GetInteger", "get_integer", vr, nvr, value, sizeof(fmi2Integer));
}

EXPORT fmi2Status fmi2GetBoolean(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr,
                                 fmi2Boolean value[])
{
    return get_values(comp, "fmi2GetBoolean", "get_boolean", vr, nvr, value, sizeof(fmi2Boolean));
}

EXPORT fmi2Status fmi2SetReal(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr,
                              const fmi2Real value[])
{
    Instance *c = exchange_instance(comp, 0);
    if (c && vr && value && exchange_set(&c->x, vr, nvr, value)) return fmi2OK;
    return set_values(comp, "fmi2SetReal", "set_real", vr, nvr, value, sizeof(fmi2Real));
}

EXPORT fmi2Status fmi2SetInteger(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr,
                                 const fmi2Integer value[])
{
    return set_values(comp, "fmi2SetInteger", "set_integer", vr, nvr, value, sizeof(fmi2Integer));
}

EXPORT fmi2Status fmi2SetBoolean(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr,
                                 const fmi2Boolean value[])
{
    return set_values(comp, "fmi2SetBoolean", "set_boolean", vr, nvr, value, sizeof(fmi2Boolean));
}

EXPORT fmi2Status fmi2GetString(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr,
                                fmi2String value[])
{
    PyObject *vrs, *payload = NULL;
    fmi2Status s;
    empty_strings(value, nvr);
    ENTER("fmi2GetString", 1)
    if (nvr == 0) LEAVE(fmi2OK);
    if (!vr || !value) {
        logf_(c, fmi2Error, "logStatusError", "fmi2GetString: NULL array");
        LEAVE(fmi2Error);
    }
    vrs = packed(vr, nvr * sizeof *vr);
    s = vrs ? invoke(c, "get_string", &payload, "(O)", vrs) : fmi2Fatal;
    if (vrs) p_Py_DecRef(vrs);
    if (s == fmi2OK) {
        if (p_PyTuple_Size(payload) != (Py_ssize_t)nvr) {
            p_PyErr_Clear();
            logf_(c, fmi2Error, "logStatusError", "fmi2GetString: wrong number of values from the slave");
            s = fmi2Error;
        } else {
            /* the bytes stay alive in the bridge instance until the next fmi2GetString */
            for (size_t i = 0; i < nvr; i++) {
                char *data = NULL;
                Py_ssize_t size;
                if (p_PyBytes_AsStringAndSize(p_PyTuple_GetItem(payload, (Py_ssize_t)i), &data, &size) != 0) {
                    p_PyErr_Clear();
                    data = "";
                }
                value[i] = data;
            }
        }
    }
    if (payload) p_Py_DecRef(payload);
    LEAVE(s);
}

EXPORT fmi2Status fmi2SetString(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr,
                                const fmi2String value[])
{
    PyObject *vrs, *vals;
    fmi2Status s = fmi2Fatal;
    size_t total = 0, at = 0;
    char *joined;
    ENTER("fmi2SetString", 0)
    if (nvr == 0) LEAVE(fmi2OK);
    if (!vr || !value) {
        logf_(c, fmi2Error, "logStatusError", "fmi2SetString: NULL array");
        LEAVE(fmi2Error);
    }
    for (size_t i = 0; i < nvr; i++) total += strlen(value[i] ? value[i] : "") + 1;
    joined = malloc(total);
    if (!joined) LEAVE(fmi2Error);
    for (size_t i = 0; i < nvr; i++) {
        size_t len = strlen(value[i] ? value[i] : "");
        memcpy(joined + at, value[i] ? value[i] : "", len);
        at += len;
        joined[at++] = 0;
    }
    vrs = packed(vr, nvr * sizeof *vr);
    vals = packed(joined, total);
    free(joined);
    if (vrs && vals) s = invoke(c, "set_string", NULL, "(OO)", vrs, vals);
    if (vrs) p_Py_DecRef(vrs);
    if (vals) p_Py_DecRef(vals);
    LEAVE(s);
}

/* ---- stepping */
EXPORT fmi2Status fmi2DoStep(fmi2Component comp, fmi2Real currentCommunicationPoint,
                             fmi2Real communicationStepSize, fmi2Boolean noSetFMUStatePriorToCurrentPoint)
{
    fmi2Status s;
    (void)noSetFMUStatePriorToCurrentPoint;
    ENTER("fmi2DoStep", 0)
    s = invoke(c, "do_step", NULL, "(dd)", currentCommunicationPoint, communicationStepSize);
    if (s == fmi2OK) {
        c->time = currentCommunicationPoint + communicationStepSize;
        c->terminated = 0;
    }
    LEAVE(s);
}

EXPORT fmi2Status fmi2CancelStep(fmi2Component comp)
{
    ENTER("fmi2CancelStep", 1)
    logf_(c, fmi2Error, "logStatusError", "fmi2CancelStep: this FMU does not step asynchronously");
    LEAVE(fmi2Error);
}

EXPORT fmi2Status fmi2GetStatus(fmi2Component comp, const fmi2StatusKind s, fmi2Status *value)
{
    if (value) *value = fmi2OK;
    ENTER("fmi2GetStatus", 1)
    if (s == fmi2DoStepStatus && value) {
        *value = c->terminated ? fmi2Discard : fmi2OK;
        LEAVE(fmi2OK);
    }
    LEAVE(fmi2Discard);
}

EXPORT fmi2Status fmi2GetRealStatus(fmi2Component comp, const fmi2StatusKind s, fmi2Real *value)
{
    if (value) *value = 0.0;
    ENTER("fmi2GetRealStatus", 1)
    if (s == fmi2LastSuccessfulTime && value) {
        *value = c->time;
        LEAVE(fmi2OK);
    }
    LEAVE(fmi2Discard);
}

EXPORT fmi2Status fmi2GetIntegerStatus(fmi2Component comp, const fmi2StatusKind s, fmi2Integer *value)
{
    (void)s;
    if (value) *value = 0;
    ENTER("fmi2GetIntegerStatus", 1)
    LEAVE(fmi2Discard);
}

/* fmi2Terminated is true after a discarded step: fmpy then ends the run at fmi2LastSuccessfulTime. */
EXPORT fmi2Status fmi2GetBooleanStatus(fmi2Component comp, const fmi2StatusKind s, fmi2Boolean *value)
{
    if (value) *value = fmi2False;
    ENTER("fmi2GetBooleanStatus", 1)
    if (s == fmi2Terminated && value) {
        *value = c->terminated ? fmi2True : fmi2False;
        LEAVE(fmi2OK);
    }
    LEAVE(fmi2Discard);
}

EXPORT fmi2Status fmi2GetStringStatus(fmi2Component comp, const fmi2StatusKind s, fmi2String *value)
{
    (void)s;
    if (value) *value = "";
    ENTER("fmi2GetStringStatus", 1)
    LEAVE(fmi2Discard);
}

/* ---- FMU state */
static State *valid_state(fmi2FMUstate s)
{
    State *state = s;
    return (state && state->magic == STATE_MAGIC) ? state : NULL;
}

EXPORT fmi2Status fmi2GetFMUstate(fmi2Component comp, fmi2FMUstate *FMUstate)
{
    PyObject *obj = NULL;
    fmi2Status s;
    ENTER("fmi2GetFMUstate", 1)
    if (!FMUstate) LEAVE(fmi2Error);
    s = invoke(c, "get_state", &obj, NULL);
    if (s == fmi2OK) {
        State *state = valid_state(*FMUstate);
        if (state) {   /* overwrite the given state */
            p_Py_DecRef(state->obj);
        } else {
            state = calloc(1, sizeof *state);
            if (!state) { p_Py_DecRef(obj); LEAVE(fmi2Error); }
            state->magic = STATE_MAGIC;
            *FMUstate = state;
        }
        state->obj = obj;
    } else if (obj) {
        p_Py_DecRef(obj);
    }
    LEAVE(s);
}

EXPORT fmi2Status fmi2SetFMUstate(fmi2Component comp, fmi2FMUstate FMUstate)
{
    State *state = valid_state(FMUstate);
    fmi2Status s;
    ENTER("fmi2SetFMUstate", 1)
    if (!state) {
        logf_(c, fmi2Error, "logStatusError", "fmi2SetFMUstate: invalid state");
        LEAVE(fmi2Error);
    }
    c->in_error = 0;   /* the state decides; a failing _set_fmu_state sets it again */
    s = invoke(c, "set_state", NULL, "(O)", state->obj);
    if (s == fmi2OK) c->terminated = 0;
    LEAVE(s);
}

EXPORT fmi2Status fmi2FreeFMUstate(fmi2Component comp, fmi2FMUstate *FMUstate)
{
    State *state;
    ENTER("fmi2FreeFMUstate", 1)
    state = FMUstate ? valid_state(*FMUstate) : NULL;
    if (state) {
        p_Py_DecRef(state->obj);
        state->magic = 0;
        free(state);
        *FMUstate = NULL;
    }
    LEAVE(fmi2OK);
}

static fmi2Status serialized(Instance *c, State *state, PyObject **bytes)
{
    return invoke(c, "state_to_bytes", bytes, "(O)", state->obj);
}

EXPORT fmi2Status fmi2SerializedFMUstateSize(fmi2Component comp, fmi2FMUstate FMUstate, size_t *size)
{
    State *state = valid_state(FMUstate);
    PyObject *bytes = NULL;
    char *data;
    Py_ssize_t n = 0;
    fmi2Status s;
    if (size) *size = 0;
    ENTER("fmi2SerializedFMUstateSize", 1)
    if (!state || !size) LEAVE(fmi2Error);
    s = serialized(c, state, &bytes);
    if (s == fmi2OK && p_PyBytes_AsStringAndSize(bytes, &data, &n) == 0) *size = (size_t)n;
    else if (s == fmi2OK) { p_PyErr_Clear(); s = fmi2Error; }
    if (bytes) p_Py_DecRef(bytes);
    LEAVE(s);
}

EXPORT fmi2Status fmi2SerializeFMUstate(fmi2Component comp, fmi2FMUstate FMUstate, fmi2Byte out[], size_t size)
{
    State *state = valid_state(FMUstate);
    PyObject *bytes = NULL;
    char *data;
    Py_ssize_t n = 0;
    fmi2Status s;
    zero_out(out, size, 1);
    ENTER("fmi2SerializeFMUstate", 1)
    if (!state || !out) LEAVE(fmi2Error);
    s = serialized(c, state, &bytes);
    if (s == fmi2OK && p_PyBytes_AsStringAndSize(bytes, &data, &n) == 0 && (size_t)n <= size) {
        memcpy(out, data, (size_t)n);
    } else if (s == fmi2OK) {
        p_PyErr_Clear();
        logf_(c, fmi2Error, "logStatusError", "fmi2SerializeFMUstate: buffer of %zu bytes, need %ld", size, (long)n);
        s = fmi2Error;
    }
    if (bytes) p_Py_DecRef(bytes);
    LEAVE(s);
}

EXPORT fmi2Status fmi2DeSerializeFMUstate(fmi2Component comp, const fmi2Byte in[], size_t size,
                                          fmi2FMUstate *FMUstate)
{
    PyObject *bytes, *obj = NULL;
    fmi2Status s = fmi2Fatal;
    ENTER("fmi2DeSerializeFMUstate", 1)
    if (!in || !FMUstate) LEAVE(fmi2Error);
    bytes = packed(in, size);
    if (bytes) {
        s = invoke(c, "state_from_bytes", &obj, "(O)", bytes);
        p_Py_DecRef(bytes);
    }
    if (s == fmi2OK) {
        State *state = valid_state(*FMUstate);
        if (state) {
            p_Py_DecRef(state->obj);
        } else {
            state = calloc(1, sizeof *state);
            if (!state) { p_Py_DecRef(obj); LEAVE(fmi2Error); }
            state->magic = STATE_MAGIC;
            *FMUstate = state;
        }
        state->obj = obj;
    } else if (obj) {
        p_Py_DecRef(obj);
    }
    LEAVE(s);
}

/* ---- not supported (the model description does not declare them) */
EXPORT fmi2Status fmi2GetDirectionalDerivative(fmi2Component comp, const fmi2ValueReference u[], size_t nu,
                                               const fmi2ValueReference z[], size_t nz, const fmi2Real dv[],
                                               fmi2Real dz[])
{
    (void)u; (void)z; (void)nz; (void)dv;
    zero_out(dz, nu, sizeof *dz);   /* dvUnknown holds nUnknown values */
    ENTER("fmi2GetDirectionalDerivative", 1)
    logf_(c, fmi2Error, "logStatusError", "fmi2GetDirectionalDerivative is not supported");
    LEAVE(fmi2Error);
}

EXPORT fmi2Status fmi2SetRealInputDerivatives(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr,
                                              const fmi2Integer order[], const fmi2Real value[])
{
    (void)vr; (void)nvr; (void)order; (void)value;
    ENTER("fmi2SetRealInputDerivatives", 0)
    logf_(c, fmi2Error, "logStatusError", "fmi2SetRealInputDerivatives is not supported (canInterpolateInputs=false)");
    LEAVE(fmi2Error);
}

EXPORT fmi2Status fmi2GetRealOutputDerivatives(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr,
                                               const fmi2Integer order[], fmi2Real value[])
{
    (void)vr; (void)order;
    zero_out(value, nvr, sizeof *value);
    ENTER("fmi2GetRealOutputDerivatives", 1)
    logf_(c, fmi2Error, "logStatusError", "fmi2GetRealOutputDerivatives is not supported");
    LEAVE(fmi2Error);
}
