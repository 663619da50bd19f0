/* FMI 3.0 glue, common and co-simulation functions, over the shared glue (glue.h) and the model table (model.h),
 * as fmi2.c is for FMI 2.0; Model Exchange's functions are fmi3_me.c's.
 *
 * The same engine, instance layer and rules (docs/fmu.md "Errors"); what FMI 3.0 changes is here: the
 * instantiation token, fmi3DoStep's out-arguments (lastSuccessfulTime where the FMU stands after a Discard),
 * Float64 in place of Real, arrays of nValues. The FMU declares no co-simulation event mode, no early return,
 * no clocks and no Scheduled Execution: their entry points exist (the standard asks every function
 * of the binary) and refuse with fmi3Error and a message. Compiled with the official FMI 3.0 headers (vendored
 * in csrc/fmi/headers); MODEL_GUID is the instantiation token, from guid.h (written by the build) or -DMODEL_GUID.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi3_glue.h"

#ifndef MODEL_GUID
#include "guid.h" /* the model description's instantiationToken: written by the build beside the sources */
#endif

static void emit(void *host, int status, const char *category, const char *message) {
    Instance *S = host;
    S->logger(S->environment, (fmi3Status)status, category, message);
}

Instance *instance(fmi3Instance c) {
    Instance *S = c;
    return S && S->glue.magic == INSTANCE_MAGIC ? S : NULL;
}

fmi3Status fmi3_unsupported(fmi3Instance c, const char *call, const char *why) {
    if (!instance(c)) return fmi3Error;
    return STATUS(glue_fail(GLUE(c), call, why));
}

#define unsupported fmi3_unsupported

#define NOT_CS "this FMU has no clocks, no Scheduled Execution and no event mode in co-simulation"

/* ------------------------------------------------------------------ inquire, instantiate, free */

const char *fmi3GetVersion(void) { return fmi3Version; }

fmi3Status fmi3SetDebugLogging(fmi3Instance c, fmi3Boolean loggingOn, size_t nCategories,
                               const fmi3String categories[]) {
    (void)nCategories;
    (void)categories;
    if (!instance(c)) return fmi3Error;
    GLUE(c)->logging_on = loggingOn ? 1 : 0;
    return fmi3OK;
}

void fmi3_refuse_instantiation(const char *name, fmi3InstanceEnvironment environment,
                               fmi3LogMessageCallback logger, const char *call, const char *why) {
    Instance probe;
    memset(&probe, 0, sizeof probe);
    probe.logger = logger;
    probe.environment = environment;
    probe.glue.emit = logger ? emit : NULL;
    probe.glue.host = &probe;
    probe.glue.name = (char *)(name ? name : model_table()->name);
    glue_log(&probe.glue, GLUE_ERROR, "logStatusError", "%s: %s", call, why);
}

Instance *fmi3_instantiate(fmi3String instanceName, fmi3String instantiationToken, fmi3Boolean loggingOn,
                           fmi3InstanceEnvironment environment, fmi3LogMessageCallback logMessage, int exchange,
                           const char *call) {
    char why[300];
    Instance *S;
    if (!instanceName || !instanceName[0]) {
        fmi3_refuse_instantiation(instanceName, environment, logMessage, call, "instanceName must not be empty");
        return NULL;
    }
    if (!instantiationToken || strcmp(instantiationToken, MODEL_GUID) != 0) {
        snprintf(why, sizeof why, "instantiationToken '%.80s' is not this binary's %s: the model description and "
                 "the binary come from different builds", instantiationToken ? instantiationToken : "(null)",
                 MODEL_GUID);
        fmi3_refuse_instantiation(instanceName, environment, logMessage, call, why);
        return NULL;
    }
    S = calloc(1, sizeof *S);
    if (!S || !glue_init(&S->glue, instanceName, loggingOn, "fmi3", exchange)) {
        free(S);
        fmi3_refuse_instantiation(instanceName, environment, logMessage, call, "out of memory");
        return NULL;
    }
    S->logger = logMessage;
    S->environment = environment;
    S->glue.emit = logMessage ? emit : NULL;
    S->glue.host = S;
    S->glue.magic = INSTANCE_MAGIC;
    return S;
}

fmi3Instance fmi3InstantiateScheduledExecution(fmi3String instanceName, fmi3String instantiationToken,
                                               fmi3String resourcePath, fmi3Boolean visible,
                                               fmi3Boolean loggingOn, fmi3InstanceEnvironment instanceEnvironment,
                                               fmi3LogMessageCallback logMessage,
                                               fmi3ClockUpdateCallback clockUpdate,
                                               fmi3LockPreemptionCallback lockPreemption,
                                               fmi3UnlockPreemptionCallback unlockPreemption) {
    (void)instantiationToken;
    (void)resourcePath;
    (void)visible;
    (void)loggingOn;
    (void)clockUpdate;
    (void)lockPreemption;
    (void)unlockPreemption;
    fmi3_refuse_instantiation(instanceName, instanceEnvironment, logMessage, "fmi3InstantiateScheduledExecution",
                              "this FMU has no Scheduled Execution (use fmi3InstantiateCoSimulation or "
                              "fmi3InstantiateModelExchange)");
    return NULL;
}

fmi3Instance fmi3InstantiateCoSimulation(fmi3String instanceName, fmi3String instantiationToken,
                                         fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                         fmi3Boolean eventModeUsed, fmi3Boolean earlyReturnAllowed,
                                         const fmi3ValueReference requiredIntermediateVariables[],
                                         size_t nRequiredIntermediateVariables,
                                         fmi3InstanceEnvironment instanceEnvironment,
                                         fmi3LogMessageCallback logMessage,
                                         fmi3IntermediateUpdateCallback intermediateUpdate) {
    (void)resourcePath;
    (void)visible;
    (void)requiredIntermediateVariables;
    (void)nRequiredIntermediateVariables;
    (void)intermediateUpdate;
    /* eventModeUsed, earlyReturnAllowed: the FMU never enters event mode nor returns early (hasEventMode and
     * canReturnEarlyAfterIntermediateUpdate are false), so an importer that allows either sees neither. */
    (void)eventModeUsed;
    (void)earlyReturnAllowed;
    return fmi3_instantiate(instanceName, instantiationToken, loggingOn, instanceEnvironment, logMessage, 0,
                            "fmi3InstantiateCoSimulation");
}

void fmi3FreeInstance(fmi3Instance c) {
    Instance *S = instance(c);
    if (!S) return;
    glue_free(&S->glue);
    free(S);
}

/* ------------------------------------------------------------------ life cycle */

fmi3Status fmi3EnterInitializationMode(fmi3Instance c, fmi3Boolean toleranceDefined, fmi3Float64 tolerance,
                                       fmi3Float64 startTime, fmi3Boolean stopTimeDefined, fmi3Float64 stopTime) {
    (void)toleranceDefined;
    (void)tolerance;
    if (!instance(c)) return fmi3Error;
    if (!glue_allowed(GLUE(c), GLUE_INSTANTIATED, "fmi3EnterInitializationMode")) return fmi3Error;
    if (glue_setup(GLUE(c), startTime, stopTimeDefined, stopTime, "fmi3EnterInitializationMode") != GLUE_OK)
        return fmi3Error;
    return STATUS(glue_enter_initialization(GLUE(c), "fmi3EnterInitializationMode"));
}

fmi3Status fmi3ExitInitializationMode(fmi3Instance c) {
    if (!instance(c)) return fmi3Error;
    return STATUS(glue_exit_initialization(GLUE(c), "fmi3ExitInitializationMode"));
}

fmi3Status fmi3Terminate(fmi3Instance c) {
    if (!instance(c)) return fmi3Error;
    return STATUS(glue_terminate(GLUE(c), "fmi3Terminate"));
}

fmi3Status fmi3Reset(fmi3Instance c) {
    if (!instance(c)) return fmi3Error;
    glue_reset(GLUE(c));
    return fmi3OK;
}

/* ------------------------------------------------------------------ variables */

/* Scalars only: nValues must equal nValueReferences. */
static int scalar_count(fmi3Instance c, size_t nvr, size_t nValues, const char *call) {
    if (nvr == nValues) return 1;
    glue_fail(GLUE(c), call, "this FMU has scalar variables only: nValues must equal nValueReferences");
    return 0;
}

/* The independent variable 'time' [s], after the whole table (model_description3.py), then the event indicators
 * (fmi3_me.c; TIME_VR + 1 + k is indicator k). */
#define TIME_VR ((fmi3ValueReference)model_table()->vr_end)

/* One of the version's own variables: 'time' or an event indicator (vr > TIME_VR). */
static int own_variable(fmi3Instance c, fmi3ValueReference vr, fmi3Float64 *value) {
    Glue *g = GLUE(c);
    if (vr > TIME_VR)
        return fmi3_me_indicator(g, vr - TIME_VR - 1, value, "fmi3GetFloat64");
    if (!glue_allowed(g, GLUE_GET_STATES, "fmi3GetFloat64"))
        return GLUE_ERROR;
    *value = g->model->initialized(g->m) ? g->model->time(g->m) : g->start_time;
    return GLUE_OK;
}

fmi3Status fmi3GetFloat64(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, fmi3Float64 values[],
                          size_t nValues) {
    size_t k;
    int status = GLUE_OK;
    if (values) for (k = 0; k < nValues; k++) values[k] = 0.0;
    if (!instance(c)) return fmi3Error;
    if (!scalar_count(c, nvr, nValues, "fmi3GetFloat64")) return fmi3Error;
    for (k = 0; k < nvr && vr && !fmi3_own_variable(vr[k]); k++)
        ;
    if (k == nvr || !vr || !values)   /* none of the version's own: the table's variables */
        return STATUS(glue_get_reals(GLUE(c), vr, nvr, values, "fmi3GetFloat64"));
    for (k = 0; k < nvr && status == GLUE_OK; k++)
        status = fmi3_own_variable(vr[k]) ? own_variable(c, vr[k], &values[k])
                                          : glue_get_reals(GLUE(c), &vr[k], 1, &values[k], "fmi3GetFloat64");
    if (status != GLUE_OK)
        for (k = 0; k < nvr; k++) values[k] = 0.0;
    return STATUS(status);
}

fmi3Status fmi3SetFloat64(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, const fmi3Float64 values[],
                          size_t nValues) {
    if (!instance(c)) return fmi3Error;
    if (!scalar_count(c, nvr, nValues, "fmi3SetFloat64")) return fmi3Error;
    return STATUS(glue_set_reals(GLUE(c), vr, nvr, values, "fmi3SetFloat64"));
}

fmi3Status fmi3GetBoolean(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, fmi3Boolean values[],
                          size_t nValues) {
    int flags[64] = {0}, *buffer = flags, status;
    size_t k;
    if (values) for (k = 0; k < nValues; k++) values[k] = fmi3False;
    if (!instance(c)) return fmi3Error;
    if (!scalar_count(c, nvr, nValues, "fmi3GetBoolean")) return fmi3Error;
    if (nvr > 64 && !(buffer = malloc(nvr * sizeof *buffer)))
        return STATUS(glue_fail(GLUE(c), "fmi3GetBoolean", "out of memory"));
    status = glue_get_booleans(GLUE(c), vr, nvr, values ? buffer : NULL, "fmi3GetBoolean");
    if (status == GLUE_OK)
        for (k = 0; k < nvr; k++) values[k] = buffer[k] ? fmi3True : fmi3False;
    if (buffer != flags) free(buffer);
    return STATUS(status);
}

fmi3Status fmi3SetBoolean(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, const fmi3Boolean values[],
                          size_t nValues) {
    int flags[64] = {0}, *buffer = flags, status;
    size_t k;
    if (!instance(c)) return fmi3Error;
    if (!scalar_count(c, nvr, nValues, "fmi3SetBoolean")) return fmi3Error;
    if (nvr > 64 && !(buffer = malloc(nvr * sizeof *buffer)))
        return STATUS(glue_fail(GLUE(c), "fmi3SetBoolean", "out of memory"));
    if (values) for (k = 0; k < nvr; k++) buffer[k] = values[k] ? 1 : 0;
    status = glue_set_booleans(GLUE(c), vr, nvr, values ? buffer : NULL, "fmi3SetBoolean");
    if (buffer != flags) free(buffer);
    return STATUS(status);
}

fmi3Status fmi3GetString(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, fmi3String values[],
                         size_t nValues) {
    size_t k;
    if (values) for (k = 0; k < nValues; k++) values[k] = "";
    if (!instance(c)) return fmi3Error;
    if (!scalar_count(c, nvr, nValues, "fmi3GetString")) return fmi3Error;
    return STATUS(glue_get_strings(GLUE(c), vr, nvr, values, "fmi3GetString"));
}

fmi3Status fmi3SetString(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, const fmi3String values[],
                         size_t nValues) {
    if (!instance(c)) return fmi3Error;
    if (!scalar_count(c, nvr, nValues, "fmi3SetString")) return fmi3Error;
    return STATUS(glue_set_strings(GLUE(c), vr, nvr, values, "fmi3SetString"));
}

/* The types the FMU has no variable of: nothing to get or set (0 references: fmi3OK). */
#define NO_SUCH_TYPE(Get, Set, T, zero, what)                                                                   \
    fmi3Status Get(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, T values[], size_t nValues) {   \
        size_t k;                                                                                              \
        (void)vr;                                                                                              \
        if (values) for (k = 0; k < nValues; k++) values[k] = zero;                                            \
        if (!instance(c)) return fmi3Error;                                                                    \
        return nvr == 0 ? fmi3OK : unsupported(c, #Get, "this FMU has no " what " variables");                 \
    }                                                                                                          \
    fmi3Status Set(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, const T values[], size_t nValues) { \
        (void)vr;                                                                                              \
        (void)values;                                                                                          \
        (void)nValues;                                                                                         \
        if (!instance(c)) return fmi3Error;                                                                    \
        return nvr == 0 ? fmi3OK : unsupported(c, #Set, "this FMU has no " what " variables");                 \
    }

NO_SUCH_TYPE(fmi3GetFloat32, fmi3SetFloat32, fmi3Float32, 0.0f, "Float32")
NO_SUCH_TYPE(fmi3GetInt8, fmi3SetInt8, fmi3Int8, 0, "Int8")
NO_SUCH_TYPE(fmi3GetUInt8, fmi3SetUInt8, fmi3UInt8, 0, "UInt8")
NO_SUCH_TYPE(fmi3GetInt16, fmi3SetInt16, fmi3Int16, 0, "Int16")
NO_SUCH_TYPE(fmi3GetUInt16, fmi3SetUInt16, fmi3UInt16, 0, "UInt16")
NO_SUCH_TYPE(fmi3GetInt32, fmi3SetInt32, fmi3Int32, 0, "Int32")
NO_SUCH_TYPE(fmi3GetUInt32, fmi3SetUInt32, fmi3UInt32, 0, "UInt32")
NO_SUCH_TYPE(fmi3GetInt64, fmi3SetInt64, fmi3Int64, 0, "Int64")
NO_SUCH_TYPE(fmi3GetUInt64, fmi3SetUInt64, fmi3UInt64, 0, "UInt64")

fmi3Status fmi3GetBinary(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, size_t valueSizes[],
                         fmi3Binary values[], size_t nValues) {
    size_t k;
    (void)vr;
    for (k = 0; k < nValues; k++) {
        if (valueSizes) valueSizes[k] = 0;
        if (values) values[k] = NULL;
    }
    if (!instance(c)) return fmi3Error;
    return nvr == 0 ? fmi3OK : unsupported(c, "fmi3GetBinary", "this FMU has no Binary variables");
}

fmi3Status fmi3SetBinary(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, const size_t valueSizes[],
                         const fmi3Binary values[], size_t nValues) {
    (void)vr;
    (void)valueSizes;
    (void)values;
    (void)nValues;
    if (!instance(c)) return fmi3Error;
    return nvr == 0 ? fmi3OK : unsupported(c, "fmi3SetBinary", "this FMU has no Binary variables");
}

fmi3Status fmi3GetClock(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, fmi3Clock values[]) {
    size_t k;
    (void)vr;
    if (values) for (k = 0; k < nvr; k++) values[k] = fmi3ClockInactive;
    return nvr == 0 && instance(c) ? fmi3OK : unsupported(c, "fmi3GetClock", NOT_CS);
}

fmi3Status fmi3SetClock(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, const fmi3Clock values[]) {
    (void)vr;
    (void)values;
    return nvr == 0 && instance(c) ? fmi3OK : unsupported(c, "fmi3SetClock", NOT_CS);
}

fmi3Status fmi3GetNumberOfVariableDependencies(fmi3Instance c, fmi3ValueReference vr, size_t *n) {
    (void)vr;
    if (n) *n = 0;
    return unsupported(c, "fmi3GetNumberOfVariableDependencies",
                       "this FMU declares its dependencies in the model description only");
}

fmi3Status fmi3GetVariableDependencies(fmi3Instance c, fmi3ValueReference dependent, size_t elementIndices[],
                                       fmi3ValueReference independents[], size_t independentIndices[],
                                       fmi3DependencyKind kinds[], size_t n) {
    (void)dependent;
    (void)elementIndices;
    (void)independents;
    (void)independentIndices;
    (void)kinds;
    (void)n;
    return unsupported(c, "fmi3GetVariableDependencies",
                       "this FMU declares its dependencies in the model description only");
}

/* ------------------------------------------------------------------ FMU states */

fmi3Status fmi3GetFMUState(fmi3Instance c, fmi3FMUState *state) {
    GlueSaved *saved;
    if (!instance(c) || !state) return fmi3Error;
    saved = glue_save(GLUE(c));
    if (!saved) return STATUS(glue_fail(GLUE(c), "fmi3GetFMUState", "out of memory"));
    free(*state); /* a state given back to be overwritten */
    *state = saved;
    return fmi3OK;
}

fmi3Status fmi3SetFMUState(fmi3Instance c, fmi3FMUState state) {
    if (!instance(c)) return fmi3Error;
    return STATUS(glue_restore(GLUE(c), state, "fmi3SetFMUState"));
}

fmi3Status fmi3FreeFMUState(fmi3Instance c, fmi3FMUState *state) {
    if (!instance(c)) return fmi3Error;
    if (state) {
        free(*state);
        *state = NULL;
    }
    return fmi3OK;
}

fmi3Status fmi3SerializedFMUStateSize(fmi3Instance c, fmi3FMUState state, size_t *size) {
    if (size) *size = 0;
    if (!instance(c) || !size) return fmi3Error;
    if (!state) return STATUS(glue_fail(GLUE(c), "fmi3SerializedFMUStateSize", "the FMU state must not be NULL"));
    *size = glue_serialized_size(state);
    return fmi3OK;
}

fmi3Status fmi3SerializeFMUState(fmi3Instance c, fmi3FMUState state, fmi3Byte serializedState[], size_t size) {
    if (!instance(c)) return fmi3Error;
    return STATUS(glue_serialize(GLUE(c), state, serializedState, size, "fmi3SerializeFMUState"));
}

fmi3Status fmi3DeserializeFMUState(fmi3Instance c, const fmi3Byte serializedState[], size_t size,
                                   fmi3FMUState *state) {
    if (!instance(c)) return fmi3Error;
    return STATUS(glue_deserialize(GLUE(c), serializedState, size, (GlueSaved **)state, "fmi3DeserializeFMUState"));
}

/* ------------------------------------------------------------------ what the FMU does not provide */

/* Adjoint derivatives, which the FMU does not provide: the sensitivities 0, then the refusal (the directional
 * derivatives are Model Exchange's: fmi3_me.c). */
static fmi3Status no_derivatives(fmi3Instance c, const char *call, fmi3Float64 sensitivity[], size_t n) {
    size_t k;
    if (sensitivity) for (k = 0; k < n; k++) sensitivity[k] = 0.0;
    return unsupported(c, call, "this FMU provides no adjoint derivatives");
}

fmi3Status fmi3GetAdjointDerivative(fmi3Instance c, const fmi3ValueReference unknowns[], size_t nUnknowns,
                                    const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[],
                                    size_t nSeed, fmi3Float64 sensitivity[], size_t nSensitivity) {
    (void)unknowns; (void)nUnknowns; (void)knowns; (void)nKnowns; (void)seed; (void)nSeed;
    return no_derivatives(c, "fmi3GetAdjointDerivative", sensitivity, nSensitivity);
}

fmi3Status fmi3EnterConfigurationMode(fmi3Instance c) {
    return unsupported(c, "fmi3EnterConfigurationMode", "this FMU has no structural parameters");
}

fmi3Status fmi3ExitConfigurationMode(fmi3Instance c) {
    return unsupported(c, "fmi3ExitConfigurationMode", "this FMU has no structural parameters");
}

fmi3Status fmi3GetIntervalDecimal(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, fmi3Float64 intervals[],
                                  fmi3IntervalQualifier qualifiers[]) {
    (void)vr; (void)nvr; (void)intervals; (void)qualifiers;
    return unsupported(c, "fmi3GetIntervalDecimal", NOT_CS);
}

fmi3Status fmi3GetIntervalFraction(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, fmi3UInt64 counters[],
                                   fmi3UInt64 resolutions[], fmi3IntervalQualifier qualifiers[]) {
    (void)vr; (void)nvr; (void)counters; (void)resolutions; (void)qualifiers;
    return unsupported(c, "fmi3GetIntervalFraction", NOT_CS);
}

fmi3Status fmi3GetShiftDecimal(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, fmi3Float64 shifts[]) {
    (void)vr; (void)nvr; (void)shifts;
    return unsupported(c, "fmi3GetShiftDecimal", NOT_CS);
}

fmi3Status fmi3GetShiftFraction(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, fmi3UInt64 counters[],
                                fmi3UInt64 resolutions[]) {
    (void)vr; (void)nvr; (void)counters; (void)resolutions;
    return unsupported(c, "fmi3GetShiftFraction", NOT_CS);
}

fmi3Status fmi3SetIntervalDecimal(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr,
                                  const fmi3Float64 intervals[]) {
    (void)vr; (void)nvr; (void)intervals;
    return unsupported(c, "fmi3SetIntervalDecimal", NOT_CS);
}

fmi3Status fmi3SetIntervalFraction(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr,
                                   const fmi3UInt64 counters[], const fmi3UInt64 resolutions[]) {
    (void)vr; (void)nvr; (void)counters; (void)resolutions;
    return unsupported(c, "fmi3SetIntervalFraction", NOT_CS);
}

fmi3Status fmi3SetShiftDecimal(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, const fmi3Float64 shifts[]) {
    (void)vr; (void)nvr; (void)shifts;
    return unsupported(c, "fmi3SetShiftDecimal", NOT_CS);
}

fmi3Status fmi3SetShiftFraction(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr,
                                const fmi3UInt64 counters[], const fmi3UInt64 resolutions[]) {
    (void)vr; (void)nvr; (void)counters; (void)resolutions;
    return unsupported(c, "fmi3SetShiftFraction", NOT_CS);
}

fmi3Status fmi3EvaluateDiscreteStates(fmi3Instance c) { return unsupported(c, "fmi3EvaluateDiscreteStates", NOT_CS); }

fmi3Status fmi3EnterStepMode(fmi3Instance c) { return unsupported(c, "fmi3EnterStepMode", NOT_CS); }

fmi3Status fmi3GetOutputDerivatives(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr,
                                    const fmi3Int32 orders[], fmi3Float64 values[], size_t nValues) {
    size_t k;
    (void)vr;
    (void)orders;
    if (values) for (k = 0; k < nValues; k++) values[k] = 0.0;
    if (!instance(c)) return fmi3Error;
    return nvr == 0 ? fmi3OK : unsupported(c, "fmi3GetOutputDerivatives",
                                           "this FMU provides no output derivatives (maxOutputDerivativeOrder=0)");
}

fmi3Status fmi3ActivateModelPartition(fmi3Instance c, fmi3ValueReference clockReference,
                                      fmi3Float64 activationTime) {
    (void)clockReference;
    (void)activationTime;
    return unsupported(c, "fmi3ActivateModelPartition", NOT_CS);
}

/* ------------------------------------------------------------------ the step */

fmi3Status fmi3DoStep(fmi3Instance c, fmi3Float64 currentCommunicationPoint, fmi3Float64 communicationStepSize,
                      fmi3Boolean noSetFMUStatePriorToCurrentPoint, fmi3Boolean *eventHandlingNeeded,
                      fmi3Boolean *terminateSimulation, fmi3Boolean *earlyReturn, fmi3Float64 *lastSuccessfulTime) {
    int status;
    (void)noSetFMUStatePriorToCurrentPoint;
    if (eventHandlingNeeded) *eventHandlingNeeded = fmi3False;
    if (terminateSimulation) *terminateSimulation = fmi3False;
    if (earlyReturn) *earlyReturn = fmi3False;
    if (lastSuccessfulTime) *lastSuccessfulTime = currentCommunicationPoint;
    if (!instance(c)) return fmi3Error;
    status = glue_do_step(GLUE(c), currentCommunicationPoint, communicationStepSize, "fmi3DoStep");
    /* OK: at the step's end; Discard: where the FMU stands, the state as before the step */
    if (lastSuccessfulTime) *lastSuccessfulTime = GLUE(c)->last_successful_time;
    return STATUS(status);
}
