/* FMI 2.0 co-simulation glue of cam.fmu over the drive's instance API (cam_instance.h).
 *
 * Thin by design: the FMI state machine, argument checks, logging and the FMU state objects.
 * Everything the drive does is behind cam_instance_*; an FMI 3.0 glue would replace only this file.
 * Compiled into the FMU's binary with the engine (csrc/src/ *.c) and the official FMI 2.0 headers
 * (those fmpy ships); CAM_GUID is defined at build time from the model description.
 *
 * Rules kept here (docs/fmu.md, "Errors"):
 * - A call not allowed in the instance's state is fmi2Error naming the call and the state.
 * - A refused request writes nothing: a multi-value set checks every value before writing one.
 * - Output arrays of get calls are filled with safe values (0, false, "") before anything is
 *   checked, so a host that ignores a refusal never reads garbage.
 * - A refused request (a value out of range, an unknown variable, a call out of order) is fmi2Error
 *   and changes nothing: the instance goes on. An error of the model itself (initialisation or a
 *   step that cannot be computed correctly) puts the instance into the error state: then only get
 *   calls, state calls, fmi2Reset, fmi2Terminate and fmi2FreeInstance are allowed, and
 *   fmi2SetFMUstate or fmi2Reset makes it usable again.
 * - fmi2Discard (a step the solver cannot complete at this size) leaves the state as before the
 *   step: fmi2GetBooleanStatus(fmi2Terminated) is true, fmi2LastSuccessfulTime where it stands.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"
#include "cam_instance.h"

#ifndef CAM_GUID
#error "CAM_GUID must be defined by the build (the model description's guid)"
#endif

#define MESSAGE_MAX 1024              /* a log line is cut here (a 20 MB bad value is not echoed whole) */
#define STATE_MAGIC 0x43414d53u       /* 'CAMS': a serialised cam.fmu state */
#define STATE_HEADER 16               /* magic, format, payload size (8 bytes) */
#define STATE_FORMAT 1u
/* |currentCommunicationPoint - the FMU's time| allowed: rounding of a host's summed steps */
#define TIME_SLACK(t) (1e-9 * (fabs(t) > 1.0 ? fabs(t) : 1.0))

typedef enum {
    INSTANTIATED = 1 << 0,
    INITIALIZATION = 1 << 1,
    STEP_COMPLETE = 1 << 2,
    STEP_FAILED = 1 << 3,   /* after fmi2Discard */
    ERROR_STATE = 1 << 4,   /* after fmi2Error */
    TERMINATED = 1 << 5
} InstanceState;

#define ANY_STATE (INSTANTIATED | INITIALIZATION | STEP_COMPLETE | STEP_FAILED | ERROR_STATE | TERMINATED)
#define GET_STATES (INITIALIZATION | STEP_COMPLETE | STEP_FAILED | ERROR_STATE | TERMINATED)

#define INSTANCE_MAGIC 0x63616d32u   /* 'cam2': a pointer a host passes is checked to be an instance */

typedef struct {
    unsigned magic;               /* INSTANCE_MAGIC while alive, 0 once freed */
    CamInstance *drive;
    fmi2CallbackLogger logger;
    fmi2ComponentEnvironment environment;
    char *name;
    int logging_on;
    InstanceState state;
    double start_time;
    double last_successful_time;
} Instance;

typedef struct {
    size_t size;
    unsigned char bytes[];
} SavedState;

/* ------------------------------------------------------------------ logging */

static const char *state_name(InstanceState s) {
    switch (s) {
    case INSTANTIATED: return "instantiated";
    case INITIALIZATION: return "initialization mode";
    case STEP_COMPLETE: return "step mode";
    case STEP_FAILED: return "step mode after fmi2Discard";
    case ERROR_STATE: return "error (after fmi2Error: fmi2Reset or fmi2SetFMUstate to go on)";
    case TERMINATED: return "terminated";
    }
    return "unknown";
}

static void log_message(Instance *S, fmi2Status status, const char *category, const char *format, ...) {
    char text[MESSAGE_MAX], escaped[2 * MESSAGE_MAX];
    size_t k, n = 0;
    va_list args;
    if (!S->logger || (status == fmi2OK && !S->logging_on)) return;
    va_start(args, format);
    vsnprintf(text, sizeof text, format, args);
    va_end(args);
    if (strlen(text) == sizeof text - 1) memcpy(text + sizeof text - 5, "...", 4);
    /* The text is the logger's format with every '%' doubled and no arguments: hosts that format
     * it (printf-style, as the standard says) and hosts that cannot see varargs (ctypes) both
     * show the message itself. */
    for (k = 0; text[k] && n + 2 < sizeof escaped; k++) {
        if (text[k] == '%') escaped[n++] = '%';
        escaped[n++] = text[k];
    }
    escaped[n] = '\0';
    S->logger(S->environment, S->name, status, category, escaped);
}

/* A refused request: fmi2Error with the message; the instance stays as it was (nothing of the
 * request was done), so the host may correct the request and go on. */
static fmi2Status fail(Instance *S, const char *call, const char *text) {
    log_message(S, fmi2Error, "logStatusError", "%s: %s", call, text);
    return fmi2Error;
}

static int allowed(Instance *S, int states, const char *call) {
    char text[256];
    if (S->state & states) return 1;
    snprintf(text, sizeof text, "not allowed in state '%s'", state_name(S->state));
    log_message(S, fmi2Error, "logStatusError", "%s: %s", call, text);
    return 0;
}

/* The drive's verdict on initialisation or a step: a discarded step (the state as before it) or an
 * error of the model (the instance goes to the error state: fmi2Reset or fmi2SetFMUstate). */
static fmi2Status drive_status(Instance *S, int status, const char *call) {
    if (status == CAM_OK) return fmi2OK;
    if (status == CAM_ERR_REJECTED) {
        log_message(S, fmi2Discard, "logStatusDiscard", "%s: %s", call, cam_instance_message(S->drive));
        S->state = STEP_FAILED;
        return fmi2Discard;
    }
    log_message(S, fmi2Error, "logStatusError", "%s: %s", call, cam_instance_message(S->drive));
    S->state = ERROR_STATE;
    return fmi2Error;
}

/* ------------------------------------------------------------------ common functions */

const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation, const fmi2CallbackFunctions *functions,
                              fmi2Boolean visible, fmi2Boolean loggingOn) {
    Instance probe = {0};
    Instance *S;
    (void)fmuResourceLocation;
    (void)visible;
    probe.logger = functions ? functions->logger : NULL;
    probe.environment = functions ? functions->componentEnvironment : NULL;
    probe.name = (char *)(instanceName ? instanceName : "cam");
    if (!instanceName || !instanceName[0]) {
        log_message(&probe, fmi2Error, "logStatusError", "fmi2Instantiate: instanceName must not be empty");
        return NULL;
    }
    if (fmuType != fmi2CoSimulation) {
        log_message(&probe, fmi2Error, "logStatusError",
                    "fmi2Instantiate: cam.fmu is a co-simulation FMU (fmuType fmi2CoSimulation)");
        return NULL;
    }
    if (!fmuGUID || strcmp(fmuGUID, CAM_GUID) != 0) {
        log_message(&probe, fmi2Error, "logStatusError",
                    "fmi2Instantiate: GUID '%.80s' is not this binary's %s: the model description and the "
                    "binary come from different builds", fmuGUID ? fmuGUID : "(null)", CAM_GUID);
        return NULL;
    }
    S = calloc(1, sizeof *S);
    if (!S) return NULL;
    S->name = malloc(strlen(instanceName) + 1);
    S->drive = cam_instance_new();
    if (!S->name || !S->drive) {
        free(S->name);
        cam_instance_free(S->drive);
        free(S);
        log_message(&probe, fmi2Error, "logStatusError", "fmi2Instantiate: out of memory");
        return NULL;
    }
    strcpy(S->name, instanceName);
    S->logger = probe.logger;
    S->environment = probe.environment;
    S->logging_on = loggingOn ? 1 : 0;
    S->state = INSTANTIATED;
    S->magic = INSTANCE_MAGIC;
    return S;
}

/* The instance behind a component a host passes, or NULL (NULL, freed, or not an instance). */
static Instance *instance(fmi2Component c) {
    Instance *S = c;
    return S && S->magic == INSTANCE_MAGIC ? S : NULL;
}

void fmi2FreeInstance(fmi2Component c) {
    Instance *S = instance(c);
    if (!S) return;
    S->magic = 0;
    cam_instance_free(S->drive);
    free(S->name);
    free(S);
}

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean loggingOn, size_t nCategories,
                               const fmi2String categories[]) {
    Instance *S = instance(c);
    (void)nCategories;
    (void)categories;
    if (!S) return fmi2Error;
    S->logging_on = loggingOn ? 1 : 0;
    return fmi2OK;
}

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined, fmi2Real tolerance,
                               fmi2Real startTime, fmi2Boolean stopTimeDefined, fmi2Real stopTime) {
    Instance *S = instance(c);
    char text[200];
    (void)toleranceDefined;
    (void)tolerance;
    if (!S) return fmi2Error;
    if (!allowed(S, INSTANTIATED, "fmi2SetupExperiment")) return fmi2Error;
    if (!isfinite(startTime) || fabs(startTime) > 1e15 ||
        (stopTimeDefined && !(isfinite(stopTime) && stopTime >= startTime))) {
        snprintf(text, sizeof text, "startTime = %.17g s must be finite within [-1e15, 1e15] s and "
                 "stopTime = %.17g s finite and >= startTime", startTime, stopTime);
        return fail(S, "fmi2SetupExperiment", text);
    }
    S->start_time = startTime;
    return fmi2OK;
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c) {
    Instance *S = instance(c);
    if (!S) return fmi2Error;
    if (!allowed(S, INSTANTIATED, "fmi2EnterInitializationMode")) return fmi2Error;
    S->state = INITIALIZATION;
    return fmi2OK;
}

fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
    Instance *S = instance(c);
    fmi2Status status;
    if (!S) return fmi2Error;
    if (!allowed(S, INITIALIZATION, "fmi2ExitInitializationMode")) return fmi2Error;
    status = drive_status(S, cam_instance_initialize(S->drive, S->start_time), "fmi2ExitInitializationMode");
    if (status == fmi2OK) {
        S->state = STEP_COMPLETE;
        S->last_successful_time = S->start_time;
    }
    return status;
}

fmi2Status fmi2Terminate(fmi2Component c) {
    Instance *S = instance(c);
    if (!S) return fmi2Error;
    if (!allowed(S, STEP_COMPLETE | STEP_FAILED | ERROR_STATE, "fmi2Terminate")) return fmi2Error;
    S->state = TERMINATED;
    return fmi2OK;
}

fmi2Status fmi2Reset(fmi2Component c) {
    Instance *S = instance(c);
    if (!S) return fmi2Error;
    cam_instance_reset(S->drive);
    S->state = INSTANTIATED;
    S->start_time = S->last_successful_time = 0.0;
    return fmi2OK;
}

/* ------------------------------------------------------------------ variables */

static int check_references(Instance *S, const fmi2ValueReference vr[], size_t nvr, const void *value,
                            CamKind type, const char *call) {
    char text[300];
    size_t k;
    CamKind kind;
    const char *name;
    if (nvr == 0) return 1;
    if (!vr || !value) {
        fail(S, call, "the value reference and value arrays must not be NULL");
        return 0;
    }
    for (k = 0; k < nvr; k++) {
        if (!cam_instance_variable(vr[k], &kind, &name)) {
            snprintf(text, sizeof text, "value reference %u is not a variable of cam.fmu (0 to %d)", vr[k],
                     CAM_VR_PARAMS + CAM_N_PARAMS - 1);
            fail(S, call, text);
            return 0;
        }
        if (kind != type) {
            snprintf(text, sizeof text, "variable '%s' (value reference %u) is a %s, not a %s", name, vr[k],
                     cam_kind_name(kind), cam_kind_name(type));
            fail(S, call, text);
            return 0;
        }
    }
    return 1;
}

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Real value[]) {
    Instance *S = instance(c);
    size_t k;
    if (value) for (k = 0; k < nvr; k++) value[k] = 0.0;
    if (!S) return fmi2Error;
    if (!allowed(S, GET_STATES, "fmi2GetReal")) return fmi2Error;
    if (!check_references(S, vr, nvr, value, CAM_KIND_REAL, "fmi2GetReal")) return fmi2Error;
    for (k = 0; k < nvr; k++)
        if (cam_instance_get_real(S->drive, vr[k], &value[k]) != CAM_OK)
            return fail(S, "fmi2GetReal", cam_instance_message(S->drive));
    return fmi2OK;
}

fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Integer value[]) {
    Instance *S = instance(c);
    size_t k;
    (void)vr;
    if (value) for (k = 0; k < nvr; k++) value[k] = 0;
    if (!S) return fmi2Error;
    if (nvr == 0) return fmi2OK;
    return fail(S, "fmi2GetInteger", "cam.fmu has no Integer variables");
}

fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Boolean value[]) {
    Instance *S = instance(c);
    size_t k;
    int v;
    if (value) for (k = 0; k < nvr; k++) value[k] = fmi2False;
    if (!S) return fmi2Error;
    if (!allowed(S, GET_STATES, "fmi2GetBoolean")) return fmi2Error;
    if (!check_references(S, vr, nvr, value, CAM_KIND_BOOLEAN, "fmi2GetBoolean")) return fmi2Error;
    for (k = 0; k < nvr; k++) {
        if (cam_instance_get_boolean(S->drive, vr[k], &v) != CAM_OK)
            return fail(S, "fmi2GetBoolean", cam_instance_message(S->drive));
        value[k] = v ? fmi2True : fmi2False;
    }
    return fmi2OK;
}

fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2String value[]) {
    Instance *S = instance(c);
    size_t k;
    if (value) for (k = 0; k < nvr; k++) value[k] = "";
    if (!S) return fmi2Error;
    if (!allowed(S, GET_STATES, "fmi2GetString")) return fmi2Error;
    if (!check_references(S, vr, nvr, value, CAM_KIND_STRING, "fmi2GetString")) return fmi2Error;
    for (k = 0; k < nvr; k++)
        if (cam_instance_get_string(S->drive, vr[k], &value[k]) != CAM_OK) {
            value[k] = "";
            return fail(S, "fmi2GetString", cam_instance_message(S->drive));
        }
    return fmi2OK;
}

#define SET_STATES (INSTANTIATED | INITIALIZATION | STEP_COMPLETE)

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Real value[]) {
    Instance *S = instance(c);
    char text[MESSAGE_MAX];
    size_t k;
    if (!S) return fmi2Error;
    if (!allowed(S, SET_STATES, "fmi2SetReal")) return fmi2Error;
    if (!check_references(S, vr, nvr, value, CAM_KIND_REAL, "fmi2SetReal")) return fmi2Error;
    for (k = 0; k < nvr; k++) /* all or nothing: every value is checked before one is written */
        if (cam_instance_check_real(S->drive, vr[k], value[k], text, sizeof text) != CAM_OK)
            return fail(S, "fmi2SetReal", text);
    for (k = 0; k < nvr; k++)
        if (cam_instance_set_real(S->drive, vr[k], value[k]) != CAM_OK)
            return fail(S, "fmi2SetReal", cam_instance_message(S->drive));
    return fmi2OK;
}

fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Integer value[]) {
    Instance *S = instance(c);
    (void)vr;
    (void)value;
    if (!S) return fmi2Error;
    if (nvr == 0) return fmi2OK;
    return fail(S, "fmi2SetInteger", "cam.fmu has no Integer variables");
}

fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Boolean value[]) {
    Instance *S = instance(c);
    size_t k;
    if (!S) return fmi2Error;
    if (!allowed(S, SET_STATES, "fmi2SetBoolean")) return fmi2Error;
    if (!check_references(S, vr, nvr, value, CAM_KIND_BOOLEAN, "fmi2SetBoolean")) return fmi2Error;
    for (k = 0; k < nvr; k++) /* booleans are parameters: the drive refuses them after initialisation */
        if (cam_instance_initialized(S->drive))
            return fail(S, "fmi2SetBoolean", "parameters are fixed after initialisation (fmi2Reset first)");
    for (k = 0; k < nvr; k++)
        if (cam_instance_set_boolean(S->drive, vr[k], value[k] != fmi2False) != CAM_OK)
            return fail(S, "fmi2SetBoolean", cam_instance_message(S->drive));
    return fmi2OK;
}

fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2String value[]) {
    Instance *S = instance(c);
    size_t k;
    if (!S) return fmi2Error;
    if (!allowed(S, SET_STATES, "fmi2SetString")) return fmi2Error;
    if (!check_references(S, vr, nvr, value, CAM_KIND_STRING, "fmi2SetString")) return fmi2Error;
    for (k = 0; k < nvr; k++)
        if (!value[k]) return fail(S, "fmi2SetString", "a string value must not be NULL");
    /* Strings are checked as they are set; a multi-value set is undone on refusal by saving first. */
    {
        size_t size = cam_instance_state_size(S->drive);
        unsigned char *saved = malloc(size ? size : 1);
        if (!saved || cam_instance_save(S->drive, saved, size) != CAM_OK) {
            free(saved);
            return fail(S, "fmi2SetString", "out of memory");
        }
        for (k = 0; k < nvr; k++)
            if (cam_instance_set_string(S->drive, vr[k], value[k], strlen(value[k])) != CAM_OK) {
                fmi2Status status = fail(S, "fmi2SetString", cam_instance_message(S->drive));
                cam_instance_restore(S->drive, saved, size);
                free(saved);
                return status;
            }
        free(saved);
    }
    return fmi2OK;
}

/* ------------------------------------------------------------------ stepping */

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint, fmi2Real communicationStepSize,
                      fmi2Boolean noSetFMUStatePriorToCurrentPoint) {
    Instance *S = instance(c);
    char text[300];
    double now;
    fmi2Status status;
    (void)noSetFMUStatePriorToCurrentPoint;
    if (!S) return fmi2Error;
    if (!allowed(S, STEP_COMPLETE, "fmi2DoStep")) return fmi2Error;
    now = cam_instance_time(S->drive);
    if (!isfinite(currentCommunicationPoint) || fabs(currentCommunicationPoint - now) > TIME_SLACK(now)) {
        snprintf(text, sizeof text, "currentCommunicationPoint = %.17g s is not where the FMU is, t = %.17g s "
                 "(allowed difference %.3g s)", currentCommunicationPoint, now, TIME_SLACK(now));
        return fail(S, "fmi2DoStep", text);
    }
    if (!(communicationStepSize > 0.0) || !isfinite(communicationStepSize)) {
        snprintf(text, sizeof text, "communicationStepSize = %.17g s: allowed a finite value > 0",
                 communicationStepSize);
        return fail(S, "fmi2DoStep", text);
    }
    status = drive_status(S, cam_instance_step(S->drive, now, communicationStepSize), "fmi2DoStep");
    if (status == fmi2OK) S->last_successful_time = cam_instance_time(S->drive);
    return status;
}

fmi2Status fmi2CancelStep(fmi2Component c) {
    Instance *S = instance(c);
    if (!S) return fmi2Error;
    return fail(S, "fmi2CancelStep", "cam.fmu steps synchronously: there is no step to cancel");
}

fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                       const fmi2Integer order[], const fmi2Real value[]) {
    Instance *S = instance(c);
    (void)vr;
    (void)order;
    (void)value;
    if (!S) return fmi2Error;
    if (nvr == 0) return fmi2OK;
    return fail(S, "fmi2SetRealInputDerivatives", "cam.fmu cannot interpolate inputs (canInterpolateInputs=false)");
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                        const fmi2Integer order[], fmi2Real value[]) {
    Instance *S = instance(c);
    size_t k;
    (void)vr;
    (void)order;
    if (value) for (k = 0; k < nvr; k++) value[k] = 0.0;
    if (!S) return fmi2Error;
    if (nvr == 0) return fmi2OK;
    return fail(S, "fmi2GetRealOutputDerivatives", "cam.fmu provides no output derivatives (maxOutputDerivativeOrder=0)");
}

fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *value) {
    Instance *S = instance(c);
    if (value) *value = fmi2OK;
    if (!S || !value) return fmi2Error;
    if (s == fmi2DoStepStatus) return fmi2OK; /* steps are synchronous: never pending */
    return fail(S, "fmi2GetStatus", "only fmi2DoStepStatus is a status kind of this call");
}

fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *value) {
    Instance *S = instance(c);
    if (value) *value = 0.0;
    if (!S || !value) return fmi2Error;
    if (s != fmi2LastSuccessfulTime) return fail(S, "fmi2GetRealStatus", "only fmi2LastSuccessfulTime is a Real status");
    *value = S->last_successful_time;
    return fmi2OK;
}

fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *value) {
    Instance *S = instance(c);
    (void)s;
    if (value) *value = 0;
    if (!S) return fmi2Error;
    return fail(S, "fmi2GetIntegerStatus", "cam.fmu has no Integer status");
}

fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *value) {
    Instance *S = instance(c);
    if (value) *value = fmi2False;
    if (!S || !value) return fmi2Error;
    if (s != fmi2Terminated) return fail(S, "fmi2GetBooleanStatus", "only fmi2Terminated is a Boolean status");
    *value = S->state == STEP_FAILED ? fmi2True : fmi2False;
    return fmi2OK;
}

fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *value) {
    Instance *S = instance(c);
    (void)s;
    if (value) *value = "";
    if (!S) return fmi2Error;
    return fail(S, "fmi2GetStringStatus", "cam.fmu has no String status (steps are synchronous)");
}

/* ------------------------------------------------------------------ FMU states */

static SavedState *save_state(Instance *S) {
    size_t size = cam_instance_state_size(S->drive);
    SavedState *saved = malloc(sizeof *saved + size);
    if (!saved) return NULL;
    saved->size = size;
    if (cam_instance_save(S->drive, saved->bytes, size) != CAM_OK) {
        free(saved);
        return NULL;
    }
    return saved;
}

fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *FMUstate) {
    Instance *S = instance(c);
    SavedState *saved;
    if (!S || !FMUstate) return fmi2Error;
    saved = save_state(S);
    if (!saved) return fail(S, "fmi2GetFMUstate", "out of memory");
    free(*FMUstate); /* a state given back to be overwritten */
    *FMUstate = saved;
    return fmi2OK;
}

static fmi2Status restore(Instance *S, const SavedState *saved, const char *call) {
    /* the instance state follows the drive's: initialised states go to step mode */
    if (cam_instance_restore(S->drive, saved->bytes, saved->size) != CAM_OK)
        return fail(S, call, cam_instance_message(S->drive));
    if (cam_instance_initialized(S->drive)) {
        S->state = STEP_COMPLETE;
        S->last_successful_time = cam_instance_time(S->drive);
    } else {
        S->state = INSTANTIATED;
    }
    return fmi2OK;
}

fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate FMUstate) {
    Instance *S = instance(c);
    if (!S) return fmi2Error;
    if (!FMUstate) return fail(S, "fmi2SetFMUstate", "FMUstate must not be NULL");
    return restore(S, FMUstate, "fmi2SetFMUstate");
}

fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *FMUstate) {
    if (!instance(c)) return fmi2Error;
    if (FMUstate) {
        free(*FMUstate);
        *FMUstate = NULL;
    }
    return fmi2OK;
}

fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate FMUstate, size_t *size) {
    Instance *S = instance(c);
    if (size) *size = 0;
    if (!S || !size) return fmi2Error;
    if (!FMUstate) return fail(S, "fmi2SerializedFMUstateSize", "FMUstate must not be NULL");
    *size = STATE_HEADER + ((SavedState *)FMUstate)->size;
    return fmi2OK;
}

static void put_u32(unsigned char *p, unsigned long v) {
    int k;
    for (k = 0; k < 4; k++) p[k] = (unsigned char)(v >> (8 * k));
}

static unsigned long get_u32(const unsigned char *p) {
    unsigned long v = 0;
    int k;
    for (k = 3; k >= 0; k--) v = (v << 8) | p[k];
    return v;
}

fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate FMUstate, fmi2Byte serializedState[], size_t size) {
    Instance *S = instance(c);
    const SavedState *saved = FMUstate;
    unsigned char *out = (unsigned char *)serializedState;
    if (!S) return fmi2Error;
    if (!saved || !serializedState) return fail(S, "fmi2SerializeFMUstate", "FMUstate and the buffer must not be NULL");
    if (size < STATE_HEADER + saved->size) return fail(S, "fmi2SerializeFMUstate", "the buffer is smaller than fmi2SerializedFMUstateSize");
    put_u32(out, STATE_MAGIC);
    put_u32(out + 4, STATE_FORMAT);
    put_u32(out + 8, (unsigned long)(saved->size & 0xffffffffu));
    put_u32(out + 12, 0);
    memcpy(out + STATE_HEADER, saved->bytes, saved->size);
    return fmi2OK;
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte serializedState[], size_t size,
                                   fmi2FMUstate *FMUstate) {
    Instance *S = instance(c);
    const unsigned char *in = (const unsigned char *)serializedState;
    SavedState *saved;
    size_t payload;
    if (!S) return fmi2Error;
    if (!serializedState || !FMUstate) return fail(S, "fmi2DeSerializeFMUstate", "the arguments must not be NULL");
    if (size < STATE_HEADER || get_u32(in) != STATE_MAGIC || get_u32(in + 4) != STATE_FORMAT)
        return fail(S, "fmi2DeSerializeFMUstate", "these bytes are not a serialised cam.fmu state (format 1)");
    payload = get_u32(in + 8);
    if (payload != size - STATE_HEADER)
        return fail(S, "fmi2DeSerializeFMUstate", "the serialised state is truncated or has trailing bytes");
    saved = malloc(sizeof *saved + payload);
    if (!saved) return fail(S, "fmi2DeSerializeFMUstate", "out of memory");
    saved->size = payload;
    memcpy(saved->bytes, in + STATE_HEADER, payload);
    free(*FMUstate);
    *FMUstate = saved;
    return fmi2OK;
}

fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference vUnknown_ref[], size_t nUnknown,
                                        const fmi2ValueReference vKnown_ref[], size_t nKnown,
                                        const fmi2Real dvKnown[], fmi2Real dvUnknown[]) {
    Instance *S = instance(c);
    size_t k;
    (void)vUnknown_ref;
    (void)vKnown_ref;
    (void)nKnown;
    (void)dvKnown;
    if (dvUnknown) for (k = 0; k < nUnknown; k++) dvUnknown[k] = 0.0;
    if (!S) return fmi2Error;
    return fail(S, "fmi2GetDirectionalDerivative", "cam.fmu provides no directional derivatives");
}
