/* FMI 3.0 Model Exchange, in one place: the calls, their argument checks and the state machine of event and
 * continuous-time mode, over the model's Model Exchange functions (model.h; cam.fmu's: exchange.c through
 * model_cam.c), exactly as fmi2_me.c for FMI 2.0: the same functions of the model in the same order, so both
 * versions share one event update. What FMI 3.0 changes: fmi3InstantiateModelExchange, fmi3EnterEventMode without
 * arguments, fmi3UpdateDiscreteStates' out-arguments, the counts of states and indicators as calls, and the event
 * indicators as variables (value references after 'time', model_description3.py). */
#include <stddef.h>
#include <stdio.h>

#include "fmi3_glue.h"

#define READ_STATES (GLUE_ME_STATES | GLUE_TERMINATED | GLUE_ERROR_STATE)

fmi3Instance fmi3InstantiateModelExchange(fmi3String instanceName, fmi3String instantiationToken,
                                          fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                          fmi3InstanceEnvironment instanceEnvironment,
                                          fmi3LogMessageCallback logMessage) {
    (void)resourcePath;
    (void)visible;
    if (!model_table()->exchange) {
        fmi3_refuse_instantiation(instanceName, instanceEnvironment, logMessage, "fmi3InstantiateModelExchange",
                                  "this FMU is a co-simulation FMU (use fmi3InstantiateCoSimulation)");
        return NULL;
    }
    return fmi3_instantiate(instanceName, instantiationToken, loggingOn, instanceEnvironment, logMessage, 1,
                            "fmi3InstantiateModelExchange");
}

/* The instance is a Model Exchange one, in one of states, and (attached) initialised for Model Exchange. */
static int allowed(Glue *g, int states, int attached, const char *call)
{
    if (!g->exchange || !g->model->exchange) {
        glue_fail(g, call, "a Model Exchange function: this instance is a co-simulation one without event mode "
                  "(step it with fmi3DoStep)");
        return 0;
    }
    if (!glue_allowed(g, states, call))
        return 0;
    if (attached && !g->model->exchange->attached(g->m)) {
        glue_fail(g, call, "the model was not initialised for Model Exchange (fmi3ExitInitializationMode failed)");
        return 0;
    }
    return 1;
}

/* An error of the model (energy created, an event not handled, an event iteration that does not settle):
 * Error and the error state. */
static fmi3Status model_error(Glue *g, const char *call)
{
    glue_log(g, GLUE_ERROR, "logStatusError", "%s: %s", call, g->model->message(g->m));
    g->state = GLUE_ERROR_STATE;
    return fmi3Error;
}

fmi3Status fmi3EnterEventMode(fmi3Instance c) {
    Glue *g;
    if (!instance(c)) return fmi3Error;
    g = GLUE(c);
    if (!allowed(g, GLUE_ME_STATES, 1, "fmi3EnterEventMode")) return fmi3Error;
    g->model->exchange->enter_event_mode(g->m);
    g->state = GLUE_EVENT_MODE;
    return fmi3OK;
}

/* One event update (the model's event_update, which FMI 2.0's fmi2NewDiscreteStates and co-simulation's step
 * share); discreteStatesNeedUpdate: call again; valuesOfContinuousStatesChanged: the states jumped. */
fmi3Status fmi3UpdateDiscreteStates(fmi3Instance c, fmi3Boolean *discreteStatesNeedUpdate, fmi3Boolean *terminate,
                                    fmi3Boolean *nominalsChanged, fmi3Boolean *valuesChanged,
                                    fmi3Boolean *nextEventTimeDefined, fmi3Float64 *nextEventTime) {
    const char *call = "fmi3UpdateDiscreteStates";
    int needed = 0, changed = 0;
    char fired[400];
    Glue *g;
    if (discreteStatesNeedUpdate) *discreteStatesNeedUpdate = fmi3False;
    if (terminate) *terminate = fmi3False;
    if (nominalsChanged) *nominalsChanged = fmi3False;
    if (valuesChanged) *valuesChanged = fmi3False;
    if (nextEventTimeDefined) *nextEventTimeDefined = fmi3False;
    if (nextEventTime) *nextEventTime = 0.0;
    if (!instance(c)) return fmi3Error;
    g = GLUE(c);
    if (!discreteStatesNeedUpdate || !terminate || !nominalsChanged || !valuesChanged || !nextEventTimeDefined
        || !nextEventTime)
        return STATUS(glue_fail(g, call, "the out-arguments must not be NULL"));
    if (!allowed(g, GLUE_EVENT_MODE, 1, call)) return fmi3Error;
    if (g->model->exchange->event_update(g->m, &changed, &needed, fired, sizeof fired) != MODEL_OK)
        return model_error(g, call);
    if (fired[0]) glue_log(g, GLUE_OK, "logEvents", "%s", fired);
    *discreteStatesNeedUpdate = needed ? fmi3True : fmi3False;
    *valuesChanged = changed ? fmi3True : fmi3False;
    return fmi3OK;
}

fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance c) {
    Glue *g;
    if (!instance(c)) return fmi3Error;
    g = GLUE(c);
    if (!allowed(g, GLUE_EVENT_MODE, 1, "fmi3EnterContinuousTimeMode")) return fmi3Error;
    g->model->exchange->enter_continuous(g->m);
    g->state = GLUE_CONTINUOUS_TIME_MODE;
    return fmi3OK;
}

/* The guards at a completed integrator step; on a model error terminateSimulation and the error state. */
fmi3Status fmi3CompletedIntegratorStep(fmi3Instance c, fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                                       fmi3Boolean *enterEventMode, fmi3Boolean *terminateSimulation) {
    const char *call = "fmi3CompletedIntegratorStep";
    int enter = 0, status;
    Glue *g;
    (void)noSetFMUStatePriorToCurrentPoint;
    if (enterEventMode) *enterEventMode = fmi3False;
    if (terminateSimulation) *terminateSimulation = fmi3False;
    if (!instance(c)) return fmi3Error;
    g = GLUE(c);
    if (!enterEventMode || !terminateSimulation)
        return STATUS(glue_fail(g, call, "enterEventMode and terminateSimulation must not be NULL"));
    if (!allowed(g, GLUE_CONTINUOUS_TIME_MODE, 1, call)) return fmi3Error;
    status = g->model->exchange->completed_step(g->m, &enter);
    if (status != MODEL_OK && status != MODEL_WARNING) {
        *terminateSimulation = fmi3True;
        return model_error(g, call);
    }
    g->last_successful_time = g->model->time(g->m);
    *enterEventMode = enter ? fmi3True : fmi3False;
    if (status == MODEL_WARNING) {
        glue_log(g, GLUE_WARNING, "logStatusWarning", "%s: %s", call, g->model->message(g->m));
        return fmi3Warning;
    }
    return fmi3OK;
}

fmi3Status fmi3SetTime(fmi3Instance c, fmi3Float64 time) {
    Glue *g;
    if (!instance(c)) return fmi3Error;
    g = GLUE(c);
    if (!allowed(g, GLUE_ME_STATES, 1, "fmi3SetTime")) return fmi3Error;
    if (g->model->exchange->set_time(g->m, time) != MODEL_OK)
        return STATUS(glue_fail(g, "fmi3SetTime", g->model->message(g->m)));
    return fmi3OK;
}

fmi3Status fmi3SetContinuousStates(fmi3Instance c, const fmi3Float64 states[], size_t n) {
    const char *call = "fmi3SetContinuousStates";
    Glue *g;
    if (!instance(c)) return fmi3Error;
    g = GLUE(c);
    if (!allowed(g, GLUE_CONTINUOUS_TIME_MODE, 1, call)) return fmi3Error;
    if (!states) return STATUS(glue_fail(g, call, "continuousStates must not be NULL"));
    if (g->model->exchange->set_states(g->m, states, n) != MODEL_OK)
        return STATUS(glue_fail(g, call, g->model->message(g->m)));
    return fmi3OK;
}

/* The read calls: the array zeroed first, also for a pointer that is no instance; the nominals need no drive
 * (a host may ask for them before initialisation). */
static fmi3Status read(fmi3Instance c, ModelRead which, fmi3Float64 values[], size_t n, const char *call) {
    int nominals = which == MODEL_READ_NOMINALS;
    size_t k;
    Glue *g;
    if (values) for (k = 0; k < n; k++) values[k] = 0.0;
    if (!instance(c)) return fmi3Error;
    g = GLUE(c);
    if (!allowed(g, nominals ? GLUE_INSTANTIATED | GLUE_INITIALIZATION | READ_STATES : READ_STATES, !nominals, call))
        return fmi3Error;
    if (!values && n > 0) return STATUS(glue_fail(g, call, "the array must not be NULL"));
    if (g->model->exchange->read(g->m, which, values, n) != MODEL_OK) {
        for (k = 0; values && k < n; k++) values[k] = 0.0;
        return STATUS(glue_fail(g, call, g->model->message(g->m)));
    }
    return fmi3OK;
}

fmi3Status fmi3GetContinuousStateDerivatives(fmi3Instance c, fmi3Float64 derivatives[], size_t n) {
    return read(c, MODEL_READ_DERIVATIVES, derivatives, n, "fmi3GetContinuousStateDerivatives");
}

fmi3Status fmi3GetEventIndicators(fmi3Instance c, fmi3Float64 indicators[], size_t n) {
    return read(c, MODEL_READ_INDICATORS, indicators, n, "fmi3GetEventIndicators");
}

fmi3Status fmi3GetContinuousStates(fmi3Instance c, fmi3Float64 states[], size_t n) {
    return read(c, MODEL_READ_STATES, states, n, "fmi3GetContinuousStates");
}

fmi3Status fmi3GetNominalsOfContinuousStates(fmi3Instance c, fmi3Float64 nominals[], size_t n) {
    return read(c, MODEL_READ_NOMINALS, nominals, n, "fmi3GetNominalsOfContinuousStates");
}

/* The counts: fixed by the model (no structural parameters), in every state of a Model Exchange instance. */
static fmi3Status count(fmi3Instance c, size_t *n, int indicators, const char *call) {
    Glue *g;
    if (n) *n = 0;
    if (!instance(c)) return fmi3Error;
    g = GLUE(c);
    if (!n) return STATUS(glue_fail(g, call, "the count's pointer must not be NULL"));
    if (!allowed(g, ~0, 0, call)) return fmi3Error;
    *n = indicators ? g->model->exchange->n_indicators : g->model->exchange->n_states;
    return fmi3OK;
}

fmi3Status fmi3GetNumberOfEventIndicators(fmi3Instance c, size_t *n) {
    return count(c, n, 1, "fmi3GetNumberOfEventIndicators");
}

fmi3Status fmi3GetNumberOfContinuousStates(fmi3Instance c, size_t *n) {
    return count(c, n, 0, "fmi3GetNumberOfContinuousStates");
}

int fmi3_own_variable(fmi3ValueReference vr) {
    const Model *m = model_table();
    return vr >= m->vr_end && vr <= m->vr_end + (m->exchange ? m->exchange->n_indicators : 0);
}

/* An event indicator as a variable (fmi3GetFloat64): where fmi3GetEventIndicators can read it. */
int fmi3_me_indicator(Glue *g, size_t k, fmi3Float64 *value, const char *call) {
    double z[16];
    size_t n;
    char text[200];
    if (!g->exchange || !g->model->exchange) {
        snprintf(text, sizeof text, "event indicator %lu is Model Exchange's: a co-simulation instance has none",
                 (unsigned long)k);
        return glue_fail(g, call, text);
    }
    n = g->model->exchange->n_indicators;
    if (n > sizeof z / sizeof z[0] || k >= n)
        return glue_fail(g, call, "no such event indicator");
    if (!allowed(g, READ_STATES, 1, call))
        return GLUE_ERROR;
    if (g->model->exchange->read(g->m, MODEL_READ_INDICATORS, z, n) != MODEL_OK)
        return glue_fail(g, call, g->model->message(g->m));
    *value = z[k];
    return GLUE_OK;
}

/* The derivatives of state derivatives and outputs (unknowns) along a seed of states and inputs (knowns), analytic
 * in the engine (jacobian.c) as fmi2GetDirectionalDerivative's: a Model Exchange instance, initialised, scalar
 * variables (nSeed = nKnowns, nSensitivity = nUnknowns). A refusal leaves the sensitivities 0 and returns Error
 * with the reason, never a 0 in a derivative's place with OK. */
typedef char value_reference_is_unsigned[sizeof(fmi3ValueReference) == sizeof(unsigned) ? 1 : -1];

fmi3Status fmi3GetDirectionalDerivative(fmi3Instance c, const fmi3ValueReference unknowns[], size_t nUnknowns,
                                        const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[],
                                        size_t nSeed, fmi3Float64 sensitivity[], size_t nSensitivity) {
    const char *call = "fmi3GetDirectionalDerivative";
    char text[160];
    size_t k;
    Glue *g;
    if (sensitivity) for (k = 0; k < nSensitivity; k++) sensitivity[k] = 0.0;
    if (!instance(c)) return fmi3Error;
    g = GLUE(c);
    if (!allowed(g, READ_STATES, 1, call)) return fmi3Error;
    if (nSeed != nKnowns || nSensitivity != nUnknowns) {
        snprintf(text, sizeof text, "nSeed (%lu) must equal nKnowns (%lu) and nSensitivity (%lu) nUnknowns (%lu): "
                 "every variable here is a scalar", (unsigned long)nSeed, (unsigned long)nKnowns,
                 (unsigned long)nSensitivity, (unsigned long)nUnknowns);
        glue_fail(g, call, text);
        return fmi3Error;
    }
    if (g->model->exchange->directional == NULL) {
        glue_fail(g, call, "this FMU provides no directional derivatives");
        return fmi3Error;
    }
    if (g->model->exchange->directional(g->m, (const unsigned *)unknowns, nUnknowns, (const unsigned *)knowns,
                                        nKnowns, seed, sensitivity) != MODEL_OK) {
        for (k = 0; sensitivity && k < nSensitivity; k++) sensitivity[k] = 0.0;
        glue_fail(g, call, g->model->message(g->m));
        return fmi3Error;
    }
    return fmi3OK;
}
