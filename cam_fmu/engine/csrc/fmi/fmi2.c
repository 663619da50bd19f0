/* FMI 2.0 glue, common and co-simulation functions, over the model table (model.h: cam.fmu's drive or
 * pi_speed.fmu's controller, whichever this binary carries); Model Exchange's functions are fmi2_me.c's.
 *
 * Thin by design: the FMI 2.0 calls over the shared glue (glue.h: the state machine, argument checks, logging,
 * variable access, steps, Model Exchange and FMU states, which fmi3_cs.c shares). Everything the drive does
 * is behind the model's table (model_table()).
 * Compiled into the FMU's binary with the engine (csrc/src/ *.c) and the official FMI 2.0 headers
 * (vendored in csrc/fmi/headers); MODEL_GUID comes from guid.h, the model description's guid, or -DMODEL_GUID.
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
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2_glue.h"

#ifndef MODEL_GUID
#include "guid.h" /* the model description's guid: written by the build beside the sources */
#endif

static void emit(void *host, int status, const char *category, const char *message) {
    Instance *S = host;
    S->logger(S->environment, S->glue.name, (fmi2Status)status, category, message);
}

Instance *instance(fmi2Component c) {
    Instance *S = c;
    return S && S->glue.magic == INSTANCE_MAGIC ? S : NULL;
}

/* ------------------------------------------------------------------ common functions */

const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation, const fmi2CallbackFunctions *functions,
                              fmi2Boolean visible, fmi2Boolean loggingOn) {
    Instance probe, *S;
    (void)fmuResourceLocation;
    (void)visible;
    memset(&probe, 0, sizeof probe);
    probe.logger = functions ? functions->logger : NULL;
    probe.environment = functions ? functions->componentEnvironment : NULL;
    probe.glue.emit = probe.logger ? emit : NULL;
    probe.glue.host = &probe;
    probe.glue.name = (char *)(instanceName ? instanceName : model_table()->name);
    if (!instanceName || !instanceName[0]) {
        glue_log(&probe.glue, GLUE_ERROR, "logStatusError", "fmi2Instantiate: instanceName must not be empty");
        return NULL;
    }
    if (fmuType != fmi2CoSimulation && !(fmuType == fmi2ModelExchange && model_table()->exchange)) {
        glue_log(&probe.glue, GLUE_ERROR, "logStatusError", "fmi2Instantiate: fmuType %d: %s.fmu is %s", (int)fmuType,
                 model_table()->name, model_table()->exchange ? "fmi2ModelExchange (0) or fmi2CoSimulation (1)"
                                                              : "fmi2CoSimulation (1) only");
        return NULL;
    }
    if (!fmuGUID || strcmp(fmuGUID, MODEL_GUID) != 0) {
        glue_log(&probe.glue, GLUE_ERROR, "logStatusError",
                 "fmi2Instantiate: GUID '%.80s' is not this binary's %s: the model description and the "
                 "binary come from different builds", fmuGUID ? fmuGUID : "(null)", MODEL_GUID);
        return NULL;
    }
    S = calloc(1, sizeof *S);
    if (!S || !glue_init(&S->glue, instanceName, loggingOn, "fmi2", fmuType == fmi2ModelExchange)) {
        free(S);
        glue_log(&probe.glue, GLUE_ERROR, "logStatusError", "fmi2Instantiate: out of memory");
        return NULL;
    }
    S->logger = probe.logger;
    S->environment = probe.environment;
    S->glue.emit = probe.glue.emit;
    S->glue.host = S;
    S->glue.magic = INSTANCE_MAGIC;
    return S;
}

void fmi2FreeInstance(fmi2Component c) {
    Instance *S = instance(c);
    if (!S) return;
    glue_free(&S->glue);
    free(S);
}

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean loggingOn, size_t nCategories,
                               const fmi2String categories[]) {
    (void)nCategories;
    (void)categories;
    if (!instance(c)) return fmi2Error;
    GLUE(c)->logging_on = loggingOn ? 1 : 0;
    return fmi2OK;
}

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined, fmi2Real tolerance,
                               fmi2Real startTime, fmi2Boolean stopTimeDefined, fmi2Real stopTime) {
    (void)toleranceDefined;
    (void)tolerance;
    if (!instance(c)) return fmi2Error;
    if (!glue_allowed(GLUE(c), GLUE_INSTANTIATED, "fmi2SetupExperiment")) return fmi2Error;
    return (fmi2Status)glue_setup(GLUE(c), startTime, stopTimeDefined, stopTime, "fmi2SetupExperiment");
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c) {
    if (!instance(c)) return fmi2Error;
    return (fmi2Status)glue_enter_initialization(GLUE(c), "fmi2EnterInitializationMode");
}

fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
    if (!instance(c)) return fmi2Error;
    return (fmi2Status)glue_exit_initialization(GLUE(c), "fmi2ExitInitializationMode");
}

fmi2Status fmi2Terminate(fmi2Component c) {
    if (!instance(c)) return fmi2Error;
    return (fmi2Status)glue_terminate(GLUE(c), "fmi2Terminate");
}

fmi2Status fmi2Reset(fmi2Component c) {
    if (!instance(c)) return fmi2Error;
    glue_reset(GLUE(c));
    return fmi2OK;
}

/* ------------------------------------------------------------------ variables */

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Real value[]) {
    size_t k;
    if (!instance(c)) {
        if (value) for (k = 0; k < nvr; k++) value[k] = 0.0;
        return fmi2Error;
    }
    return (fmi2Status)glue_get_reals(GLUE(c), vr, nvr, value, "fmi2GetReal");
}

fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Integer value[]) {
    size_t k;
    (void)vr;
    if (value) for (k = 0; k < nvr; k++) value[k] = 0;
    if (!instance(c)) return fmi2Error;
    if (nvr == 0) return fmi2OK;
    return (fmi2Status)glue_fail(GLUE(c), "fmi2GetInteger", "this FMU has no Integer variables");
}

fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Boolean value[]) {
    int flags[64] = {0}, *buffer = flags, status;
    size_t k;
    if (value) for (k = 0; k < nvr; k++) value[k] = fmi2False;
    if (!instance(c)) return fmi2Error;
    if (nvr > 64 && !(buffer = malloc(nvr * sizeof *buffer)))
        return (fmi2Status)glue_fail(GLUE(c), "fmi2GetBoolean", "out of memory");
    status = glue_get_booleans(GLUE(c), vr, nvr, value ? buffer : NULL, "fmi2GetBoolean");
    if (status == GLUE_OK)
        for (k = 0; k < nvr; k++) value[k] = buffer[k] ? fmi2True : fmi2False;
    if (buffer != flags) free(buffer);
    return (fmi2Status)status;
}

fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2String value[]) {
    size_t k;
    if (!instance(c)) {
        if (value) for (k = 0; k < nvr; k++) value[k] = "";
        return fmi2Error;
    }
    return (fmi2Status)glue_get_strings(GLUE(c), vr, nvr, value, "fmi2GetString");
}

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Real value[]) {
    if (!instance(c)) return fmi2Error;
    return (fmi2Status)glue_set_reals(GLUE(c), vr, nvr, value, "fmi2SetReal");
}

fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Integer value[]) {
    (void)vr;
    (void)value;
    if (!instance(c)) return fmi2Error;
    if (nvr == 0) return fmi2OK;
    return (fmi2Status)glue_fail(GLUE(c), "fmi2SetInteger", "this FMU has no Integer variables");
}

fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Boolean value[]) {
    int flags[64] = {0}, *buffer = flags, status;
    size_t k;
    if (!instance(c)) return fmi2Error;
    if (nvr > 64 && !(buffer = malloc(nvr * sizeof *buffer)))
        return (fmi2Status)glue_fail(GLUE(c), "fmi2SetBoolean", "out of memory");
    if (value) for (k = 0; k < nvr; k++) buffer[k] = value[k] != fmi2False;
    status = glue_set_booleans(GLUE(c), vr, nvr, value ? buffer : NULL, "fmi2SetBoolean");
    if (buffer != flags) free(buffer);
    return (fmi2Status)status;
}

fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2String value[]) {
    if (!instance(c)) return fmi2Error;
    return (fmi2Status)glue_set_strings(GLUE(c), vr, nvr, value, "fmi2SetString");
}

/* ------------------------------------------------------------------ stepping */

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint, fmi2Real communicationStepSize,
                      fmi2Boolean noSetFMUStatePriorToCurrentPoint) {
    (void)noSetFMUStatePriorToCurrentPoint;
    if (!instance(c)) return fmi2Error;
    return (fmi2Status)glue_do_step(GLUE(c), currentCommunicationPoint, communicationStepSize, "fmi2DoStep");
}

fmi2Status fmi2CancelStep(fmi2Component c) {
    if (!instance(c)) return fmi2Error;
    return (fmi2Status)glue_fail(GLUE(c), "fmi2CancelStep", "this FMU steps synchronously: there is no step to cancel");
}

fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                       const fmi2Integer order[], const fmi2Real value[]) {
    (void)vr;
    (void)order;
    (void)value;
    if (!instance(c)) return fmi2Error;
    if (nvr == 0) return fmi2OK;
    return (fmi2Status)glue_fail(GLUE(c), "fmi2SetRealInputDerivatives",
                                 "this FMU cannot interpolate inputs (canInterpolateInputs=false)");
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                        const fmi2Integer order[], fmi2Real value[]) {
    size_t k;
    (void)vr;
    (void)order;
    if (value) for (k = 0; k < nvr; k++) value[k] = 0.0;
    if (!instance(c)) return fmi2Error;
    if (nvr == 0) return fmi2OK;
    return (fmi2Status)glue_fail(GLUE(c), "fmi2GetRealOutputDerivatives",
                                 "this FMU provides no output derivatives (maxOutputDerivativeOrder=0)");
}

fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *value) {
    if (value) *value = fmi2OK;
    if (!instance(c) || !value) return fmi2Error;
    if (s == fmi2DoStepStatus) return fmi2OK; /* steps are synchronous: never pending */
    return (fmi2Status)glue_fail(GLUE(c), "fmi2GetStatus", "only fmi2DoStepStatus is a status kind of this call");
}

fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *value) {
    if (value) *value = 0.0;
    if (!instance(c) || !value) return fmi2Error;
    if (s != fmi2LastSuccessfulTime)
        return (fmi2Status)glue_fail(GLUE(c), "fmi2GetRealStatus", "only fmi2LastSuccessfulTime is a Real status");
    *value = GLUE(c)->last_successful_time;
    return fmi2OK;
}

fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *value) {
    (void)s;
    if (value) *value = 0;
    if (!instance(c)) return fmi2Error;
    return (fmi2Status)glue_fail(GLUE(c), "fmi2GetIntegerStatus", "this FMU has no Integer status");
}

fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *value) {
    if (value) *value = fmi2False;
    if (!instance(c) || !value) return fmi2Error;
    if (s != fmi2Terminated)
        return (fmi2Status)glue_fail(GLUE(c), "fmi2GetBooleanStatus", "only fmi2Terminated is a Boolean status");
    *value = GLUE(c)->state == GLUE_STEP_FAILED ? fmi2True : fmi2False;
    return fmi2OK;
}

fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *value) {
    (void)s;
    if (value) *value = "";
    if (!instance(c)) return fmi2Error;
    return (fmi2Status)glue_fail(GLUE(c), "fmi2GetStringStatus", "this FMU has no String status (steps are synchronous)");
}

/* ------------------------------------------------------------------ FMU states */

fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *FMUstate) {
    GlueSaved *saved;
    if (!instance(c) || !FMUstate) return fmi2Error;
    saved = glue_save(GLUE(c));
    if (!saved) return (fmi2Status)glue_fail(GLUE(c), "fmi2GetFMUstate", "out of memory");
    free(*FMUstate); /* a state given back to be overwritten */
    *FMUstate = saved;
    return fmi2OK;
}

fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate FMUstate) {
    if (!instance(c)) return fmi2Error;
    return (fmi2Status)glue_restore(GLUE(c), FMUstate, "fmi2SetFMUstate");
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
    if (size) *size = 0;
    if (!instance(c) || !size) return fmi2Error;
    if (!FMUstate) return (fmi2Status)glue_fail(GLUE(c), "fmi2SerializedFMUstateSize", "FMUstate must not be NULL");
    *size = glue_serialized_size(FMUstate);
    return fmi2OK;
}

fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate FMUstate, fmi2Byte serializedState[], size_t size) {
    if (!instance(c)) return fmi2Error;
    return (fmi2Status)glue_serialize(GLUE(c), FMUstate, (unsigned char *)serializedState, size,
                                      "fmi2SerializeFMUstate");
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte serializedState[], size_t size,
                                   fmi2FMUstate *FMUstate) {
    if (!instance(c)) return fmi2Error;
    return (fmi2Status)glue_deserialize(GLUE(c), (const unsigned char *)serializedState, size,
                                        (GlueSaved **)FMUstate, "fmi2DeSerializeFMUstate");
}
