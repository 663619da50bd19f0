/* FMI 2.0 Model Exchange, in one place: the calls, their argument checks and the state machine of event and
 * continuous-time mode, over the model's Model Exchange functions (model.h; cam.fmu's: exchange.c through
 * model_cam.c). The common functions are fmi2.c's; FMI 3.0's Model Exchange is fmi3_me.c, over
 * the same model functions in the same order. */
#include <stddef.h>

#include "fmi2_glue.h"

#define READ_STATES (GLUE_ME_STATES | GLUE_TERMINATED | GLUE_ERROR_STATE)

/* The instance is a Model Exchange one, in one of states, and (attached) initialised for Model Exchange. */
static int allowed(Glue *g, int states, int attached, const char *call)
{
    if (!g->exchange || !g->model->exchange) {
        glue_fail(g, call, "a Model Exchange function: this instance is a co-simulation one (step it with DoStep)");
        return 0;
    }
    if (!glue_allowed(g, states, call))
        return 0;
    if (attached && !g->model->exchange->attached(g->m)) {
        glue_fail(g, call, "the model was not initialised for Model Exchange (ExitInitializationMode failed)");
        return 0;
    }
    return 1;
}

/* An error of the model (energy created, an event not handled, an event iteration that does not settle):
 * Error and the error state. */
static fmi2Status model_error(Glue *g, const char *call)
{
    glue_log(g, GLUE_ERROR, "logStatusError", "%s: %s", call, g->model->message(g->m));
    g->state = GLUE_ERROR_STATE;
    return fmi2Error;
}

fmi2Status fmi2EnterEventMode(fmi2Component c) {
    Glue *g;
    if (!instance(c)) return fmi2Error;
    g = GLUE(c);
    if (!allowed(g, GLUE_ME_STATES, 1, "fmi2EnterEventMode")) return fmi2Error;
    g->model->exchange->enter_event_mode(g->m);
    g->state = GLUE_EVENT_MODE;
    return fmi2OK;
}

/* One event update (the model's event_update, which co-simulation's step shares); newDiscreteStatesNeeded: call
 * again; valuesOfContinuousStatesChanged: the states jumped. */
fmi2Status fmi2NewDiscreteStates(fmi2Component c, fmi2EventInfo *eventInfo) {
    const char *call = "fmi2NewDiscreteStates";
    int needed = 0, changed = 0;
    char fired[400];
    Glue *g;
    if (eventInfo) {
        eventInfo->newDiscreteStatesNeeded = fmi2False;
        eventInfo->terminateSimulation = fmi2False;
        eventInfo->nominalsOfContinuousStatesChanged = fmi2False;
        eventInfo->valuesOfContinuousStatesChanged = fmi2False;
        eventInfo->nextEventTimeDefined = fmi2False;
        eventInfo->nextEventTime = 0.0;
    }
    if (!instance(c)) return fmi2Error;
    g = GLUE(c);
    if (!eventInfo) return (fmi2Status)glue_fail(g, call, "eventInfo must not be NULL");
    if (!allowed(g, GLUE_EVENT_MODE, 1, call)) return fmi2Error;
    if (g->model->exchange->event_update(g->m, &changed, &needed, fired, sizeof fired) != MODEL_OK)
        return model_error(g, call);
    if (fired[0]) glue_log(g, GLUE_OK, "logEvents", "%s", fired);
    eventInfo->newDiscreteStatesNeeded = needed ? fmi2True : fmi2False;
    eventInfo->valuesOfContinuousStatesChanged = changed ? fmi2True : fmi2False;
    return fmi2OK;
}

fmi2Status fmi2EnterContinuousTimeMode(fmi2Component c) {
    Glue *g;
    if (!instance(c)) return fmi2Error;
    g = GLUE(c);
    if (!allowed(g, GLUE_EVENT_MODE, 1, "fmi2EnterContinuousTimeMode")) return fmi2Error;
    g->model->exchange->enter_continuous(g->m);
    g->state = GLUE_CONTINUOUS_TIME_MODE;
    return fmi2OK;
}

/* The guards at a completed integrator step; on a model error terminateSimulation and the error state. */
fmi2Status fmi2CompletedIntegratorStep(fmi2Component c, fmi2Boolean noSetFMUStatePriorToCurrentPoint,
                                       fmi2Boolean *enterEventMode, fmi2Boolean *terminateSimulation) {
    const char *call = "fmi2CompletedIntegratorStep";
    int enter = 0, status;
    Glue *g;
    (void)noSetFMUStatePriorToCurrentPoint;
    if (enterEventMode) *enterEventMode = fmi2False;
    if (terminateSimulation) *terminateSimulation = fmi2False;
    if (!instance(c)) return fmi2Error;
    g = GLUE(c);
    if (!enterEventMode || !terminateSimulation)
        return (fmi2Status)glue_fail(g, call, "enterEventMode and terminateSimulation must not be NULL");
    if (!allowed(g, GLUE_CONTINUOUS_TIME_MODE, 1, call)) return fmi2Error;
    status = g->model->exchange->completed_step(g->m, &enter);
    if (status != MODEL_OK && status != MODEL_WARNING) {
        *terminateSimulation = fmi2True;
        return model_error(g, call);
    }
    g->last_successful_time = g->model->time(g->m);
    *enterEventMode = enter ? fmi2True : fmi2False;
    if (status == MODEL_WARNING) {
        glue_log(g, GLUE_WARNING, "logStatusWarning", "%s: %s", call, g->model->message(g->m));
        return fmi2Warning;
    }
    return fmi2OK;
}

fmi2Status fmi2SetTime(fmi2Component c, fmi2Real time) {
    Glue *g;
    if (!instance(c)) return fmi2Error;
    g = GLUE(c);
    if (!allowed(g, GLUE_ME_STATES, 1, "fmi2SetTime")) return fmi2Error;
    if (g->model->exchange->set_time(g->m, time) != MODEL_OK)
        return (fmi2Status)glue_fail(g, "fmi2SetTime", g->model->message(g->m));
    return fmi2OK;
}

fmi2Status fmi2SetContinuousStates(fmi2Component c, const fmi2Real x[], size_t nx) {
    const char *call = "fmi2SetContinuousStates";
    Glue *g;
    if (!instance(c)) return fmi2Error;
    g = GLUE(c);
    if (!allowed(g, GLUE_CONTINUOUS_TIME_MODE, 1, call)) return fmi2Error;
    if (!x) return (fmi2Status)glue_fail(g, call, "x must not be NULL");
    if (g->model->exchange->set_states(g->m, x, nx) != MODEL_OK)
        return (fmi2Status)glue_fail(g, call, g->model->message(g->m));
    return fmi2OK;
}

/* The read calls: the array zeroed first, also for a component that is no instance; the nominals need no drive
 * (a host may ask for them before initialisation). */
static fmi2Status read(fmi2Component c, ModelRead which, fmi2Real values[], size_t n, const char *call) {
    int nominals = which == MODEL_READ_NOMINALS;
    size_t k;
    Glue *g;
    if (values) for (k = 0; k < n; k++) values[k] = 0.0;
    if (!instance(c)) return fmi2Error;
    g = GLUE(c);
    if (!allowed(g, nominals ? GLUE_INSTANTIATED | GLUE_INITIALIZATION | READ_STATES : READ_STATES, !nominals, call))
        return fmi2Error;
    if (!values && n > 0) return (fmi2Status)glue_fail(g, call, "the array must not be NULL");
    if (g->model->exchange->read(g->m, which, values, n) != MODEL_OK) {
        for (k = 0; values && k < n; k++) values[k] = 0.0;
        return (fmi2Status)glue_fail(g, call, g->model->message(g->m));
    }
    return fmi2OK;
}

fmi2Status fmi2GetDerivatives(fmi2Component c, fmi2Real derivatives[], size_t nx) {
    return read(c, MODEL_READ_DERIVATIVES, derivatives, nx, "fmi2GetDerivatives");
}

fmi2Status fmi2GetEventIndicators(fmi2Component c, fmi2Real eventIndicators[], size_t ni) {
    return read(c, MODEL_READ_INDICATORS, eventIndicators, ni, "fmi2GetEventIndicators");
}

fmi2Status fmi2GetContinuousStates(fmi2Component c, fmi2Real x[], size_t nx) {
    return read(c, MODEL_READ_STATES, x, nx, "fmi2GetContinuousStates");
}

fmi2Status fmi2GetNominalsOfContinuousStates(fmi2Component c, fmi2Real x_nominal[], size_t nx) {
    return read(c, MODEL_READ_NOMINALS, x_nominal, nx, "fmi2GetNominalsOfContinuousStates");
}

/* The derivatives of state derivatives and outputs (vUnknown_ref) along a seed of states and inputs (vKnown_ref,
 * dvKnown), analytic in the engine (jacobian.c); Model Exchange only. A refusal zeroes nothing into a derivative's
 * place silently: dvUnknown is zeroed and the call returns fmi2Error with the reason. */
fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference vUnknown_ref[], size_t nUnknown,
                                        const fmi2ValueReference vKnown_ref[], size_t nKnown,
                                        const fmi2Real dvKnown[], fmi2Real dvUnknown[]) {
    const char *call = "fmi2GetDirectionalDerivative";
    size_t k;
    Glue *g;
    if (dvUnknown) for (k = 0; k < nUnknown; k++) dvUnknown[k] = 0.0;
    if (!instance(c)) return fmi2Error;
    g = GLUE(c);
    if (!allowed(g, READ_STATES, 1, call)) return fmi2Error;
    if (g->model->exchange->directional == NULL)
        return (fmi2Status)glue_fail(g, call, "this FMU provides no directional derivatives");
    if (g->model->exchange->directional(g->m, vUnknown_ref, nUnknown, vKnown_ref, nKnown, dvKnown, dvUnknown)
        != MODEL_OK) {
        for (k = 0; dvUnknown && k < nUnknown; k++) dvUnknown[k] = 0.0;
        return (fmi2Status)glue_fail(g, call, g->model->message(g->m));
    }
    return fmi2OK;
}
