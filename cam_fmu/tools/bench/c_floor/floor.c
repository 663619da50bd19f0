/* The C cost floor of the cam_fmu bench: an FMI 2.0 co-simulation slave with
 * cam.fmu's inputs and outputs and a trivial model, so that a run measures what
 * the host (fmpy: its step loop, input setting and output recording) costs per
 * communication step when the model itself costs next to nothing.
 *
 * Model: two states integrated by one forward-Euler step per fmi2DoStep,
 *     theta' = omega,  omega' = u - omega,
 * every other output set from them at every step. The variables are numbered
 * by the modelDescription that cam_fmu/tools/bench/c_floor.py writes: value
 * reference k is r[k], the inputs first (0 .. N_INPUTS-1), then the outputs.
 * The build passes N_INPUTS, N_OUTPUTS, VR_U, VR_THETA and VR_OMEGA with -D.
 *
 * Reals get/set; integers, booleans and strings: there are none (any value
 * reference is fmi2Error); FMU state functions return fmi2Error (the model
 * description does not claim them).
 */
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"

#if !defined(N_INPUTS) || !defined(N_OUTPUTS) || !defined(VR_U) || !defined(VR_THETA) || !defined(VR_OMEGA)
#error "compile with -DN_INPUTS=.. -DN_OUTPUTS=.. -DVR_U=.. -DVR_THETA=.. -DVR_OMEGA=.. (c_floor.py does)"
#endif
#define N_VARS (N_INPUTS + N_OUTPUTS)

typedef struct {
    fmi2Real r[N_VARS];
    fmi2Real start[N_VARS];
    fmi2Real time;
    fmi2CallbackLogger logger;
    fmi2ComponentEnvironment env;
    char name[128];
} Instance;

static void say(Instance *in, fmi2Status status, const char *message) {
    if (in && in->logger) in->logger(in->env, in->name, status, "logStatusError", message);
}

static void outputs(Instance *in) {
    fmi2Real theta = in->r[VR_THETA], omega = in->r[VR_OMEGA];
    int k;
    for (k = N_INPUTS; k < N_VARS; k++)
        if (k != VR_THETA && k != VR_OMEGA) in->r[k] = theta + (fmi2Real)(k - N_INPUTS) * omega;
}

/* ------------------------------------------------------------------ common functions */
FMI2_Export const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
FMI2_Export const char *fmi2GetVersion(void) { return fmi2Version; }

FMI2_Export fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean on, size_t n, const fmi2String cats[]) {
    (void)c; (void)on; (void)n; (void)cats;
    return fmi2OK;
}

FMI2_Export fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid, fmi2String location,
                                          const fmi2CallbackFunctions *cb, fmi2Boolean visible, fmi2Boolean logging) {
    Instance *in;
    int k;
    (void)guid; (void)location; (void)visible; (void)logging;
    if (type != fmi2CoSimulation) return NULL;
    in = (Instance *)calloc(1, sizeof(Instance));
    if (!in) return NULL;
    if (cb) { in->logger = cb->logger; in->env = cb->componentEnvironment; }
    strncpy(in->name, name ? name : "c_floor", sizeof(in->name) - 1);
    for (k = 0; k < N_VARS; k++) in->start[k] = 0.0;
    in->start[VR_U] = START_U;
    memcpy(in->r, in->start, sizeof(in->r));
    return in;
}

FMI2_Export void fmi2FreeInstance(fmi2Component c) { free(c); }

FMI2_Export fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean tolDefined, fmi2Real tol, fmi2Real start,
                                           fmi2Boolean stopDefined, fmi2Real stop) {
    (void)tolDefined; (void)tol; (void)stopDefined; (void)stop;
    ((Instance *)c)->time = start;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2EnterInitializationMode(fmi2Component c) { (void)c; return fmi2OK; }
FMI2_Export fmi2Status fmi2ExitInitializationMode(fmi2Component c) { outputs((Instance *)c); return fmi2OK; }
FMI2_Export fmi2Status fmi2Terminate(fmi2Component c) { (void)c; return fmi2OK; }

FMI2_Export fmi2Status fmi2Reset(fmi2Component c) {
    Instance *in = (Instance *)c;
    memcpy(in->r, in->start, sizeof(in->r));
    in->time = 0.0;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Real value[]) {
    Instance *in = (Instance *)c;
    size_t k;
    for (k = 0; k < n; k++) {
        if (vr[k] >= N_VARS) { say(in, fmi2Error, "fmi2GetReal: unknown value reference"); return fmi2Error; }
        value[k] = in->r[vr[k]];
    }
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Real value[]) {
    Instance *in = (Instance *)c;
    size_t k;
    for (k = 0; k < n; k++) {
        if (vr[k] >= N_INPUTS) { say(in, fmi2Error, "fmi2SetReal: only the inputs can be set"); return fmi2Error; }
        in->r[vr[k]] = value[k];
    }
    return fmi2OK;
}

static fmi2Status none(fmi2Component c, size_t n, const char *what) {
    if (n == 0) return fmi2OK;
    say((Instance *)c, fmi2Error, what);
    return fmi2Error;
}

FMI2_Export fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Integer v[]) {
    (void)vr; (void)v; return none(c, n, "fmi2GetInteger: the C floor has no integer variables");
}
FMI2_Export fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Boolean v[]) {
    (void)vr; (void)v; return none(c, n, "fmi2GetBoolean: the C floor has no boolean variables");
}
FMI2_Export fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2String v[]) {
    (void)vr; (void)v; return none(c, n, "fmi2GetString: the C floor has no string variables");
}
FMI2_Export fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer v[]) {
    (void)vr; (void)v; return none(c, n, "fmi2SetInteger: the C floor has no integer variables");
}
FMI2_Export fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Boolean v[]) {
    (void)vr; (void)v; return none(c, n, "fmi2SetBoolean: the C floor has no boolean variables");
}
FMI2_Export fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2String v[]) {
    (void)vr; (void)v; return none(c, n, "fmi2SetString: the C floor has no string variables");
}

FMI2_Export fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *s) { (void)c; (void)s; return fmi2Error; }
FMI2_Export fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate s) { (void)c; (void)s; return fmi2Error; }
FMI2_Export fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *s) { (void)c; (void)s; return fmi2Error; }
FMI2_Export fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate s, size_t *n) {
    (void)c; (void)s; (void)n; return fmi2Error;
}
FMI2_Export fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate s, fmi2Byte b[], size_t n) {
    (void)c; (void)s; (void)b; (void)n; return fmi2Error;
}
FMI2_Export fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte b[], size_t n, fmi2FMUstate *s) {
    (void)c; (void)b; (void)n; (void)s; return fmi2Error;
}
FMI2_Export fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference u[], size_t nu,
                                                    const fmi2ValueReference z[], size_t nz, const fmi2Real du[],
                                                    fmi2Real dz[]) {
    (void)c; (void)u; (void)nu; (void)z; (void)nz; (void)du; (void)dz; return fmi2Error;
}

/* ------------------------------------------------------------------ co-simulation */
FMI2_Export fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                                   const fmi2Integer order[], const fmi2Real value[]) {
    (void)c; (void)vr; (void)n; (void)order; (void)value; return fmi2Error;
}
FMI2_Export fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                                    const fmi2Integer order[], fmi2Real value[]) {
    (void)c; (void)vr; (void)n; (void)order; (void)value; return fmi2Error;
}

FMI2_Export fmi2Status fmi2DoStep(fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean noSetPrior) {
    Instance *in = (Instance *)c;
    fmi2Real theta = in->r[VR_THETA], omega = in->r[VR_OMEGA];
    (void)noSetPrior;
    in->r[VR_THETA] = theta + h * omega;              /* forward Euler */
    in->r[VR_OMEGA] = omega + h * (in->r[VR_U] - omega);
    in->time = t + h;
    outputs(in);
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2CancelStep(fmi2Component c) { (void)c; return fmi2Error; }

FMI2_Export fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind k, fmi2Status *v) {
    (void)c; (void)k; (void)v; return fmi2Discard;
}
FMI2_Export fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind k, fmi2Real *v) {
    Instance *in = (Instance *)c;
    if (k == fmi2LastSuccessfulTime) { *v = in->time; return fmi2OK; }
    return fmi2Discard;
}
FMI2_Export fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind k, fmi2Integer *v) {
    (void)c; (void)k; (void)v; return fmi2Discard;
}
FMI2_Export fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind k, fmi2Boolean *v) {
    (void)c; (void)k; (void)v; return fmi2Discard;
}
FMI2_Export fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind k, fmi2String *v) {
    (void)c; (void)k; (void)v; return fmi2Discard;
}
