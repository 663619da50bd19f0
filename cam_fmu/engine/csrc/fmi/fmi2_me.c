/* FMI 2.0 Model Exchange functions over the shared glue (glue.h, glue_me.c: the state machine
 * of event and continuous-time mode over exchange.h); the common functions are fmi2.c's. */
#include "fmi2_glue.h"

fmi2Status fmi2EnterEventMode(fmi2Component c) {
    if (!instance(c)) return fmi2Error;
    return (fmi2Status)glue_enter_event_mode(GLUE(c), "fmi2EnterEventMode");
}

fmi2Status fmi2NewDiscreteStates(fmi2Component c, fmi2EventInfo *eventInfo) {
    int needed = 0, changed = 0, status;
    if (eventInfo) {
        eventInfo->newDiscreteStatesNeeded = fmi2False;
        eventInfo->terminateSimulation = fmi2False;
        eventInfo->nominalsOfContinuousStatesChanged = fmi2False;
        eventInfo->valuesOfContinuousStatesChanged = fmi2False;
        eventInfo->nextEventTimeDefined = fmi2False;
        eventInfo->nextEventTime = 0.0;
    }
    if (!instance(c)) return fmi2Error;
    if (!eventInfo) return (fmi2Status)glue_fail(GLUE(c), "fmi2NewDiscreteStates", "eventInfo must not be NULL");
    status = glue_new_discrete_states(GLUE(c), &needed, &changed, "fmi2NewDiscreteStates");
    eventInfo->newDiscreteStatesNeeded = needed ? fmi2True : fmi2False;
    eventInfo->valuesOfContinuousStatesChanged = changed ? fmi2True : fmi2False;
    return (fmi2Status)status;
}

fmi2Status fmi2EnterContinuousTimeMode(fmi2Component c) {
    if (!instance(c)) return fmi2Error;
    return (fmi2Status)glue_enter_continuous_time_mode(GLUE(c), "fmi2EnterContinuousTimeMode");
}

fmi2Status fmi2CompletedIntegratorStep(fmi2Component c, fmi2Boolean noSetFMUStatePriorToCurrentPoint,
                                       fmi2Boolean *enterEventMode, fmi2Boolean *terminateSimulation) {
    int enter = 0, terminate = 0, status;
    (void)noSetFMUStatePriorToCurrentPoint;
    if (enterEventMode) *enterEventMode = fmi2False;
    if (terminateSimulation) *terminateSimulation = fmi2False;
    if (!instance(c)) return fmi2Error;
    if (!enterEventMode || !terminateSimulation)
        return (fmi2Status)glue_fail(GLUE(c), "fmi2CompletedIntegratorStep",
                                     "enterEventMode and terminateSimulation must not be NULL");
    status = glue_completed_integrator_step(GLUE(c), &enter, &terminate, "fmi2CompletedIntegratorStep");
    *enterEventMode = enter ? fmi2True : fmi2False;
    *terminateSimulation = terminate ? fmi2True : fmi2False;
    return (fmi2Status)status;
}

fmi2Status fmi2SetTime(fmi2Component c, fmi2Real time) {
    if (!instance(c)) return fmi2Error;
    return (fmi2Status)glue_set_time(GLUE(c), time, "fmi2SetTime");
}

fmi2Status fmi2SetContinuousStates(fmi2Component c, const fmi2Real x[], size_t nx) {
    if (!instance(c)) return fmi2Error;
    return (fmi2Status)glue_set_continuous_states(GLUE(c), x, nx, "fmi2SetContinuousStates");
}

/* The read calls: the array zeroed first, also for a component that is no instance. */
static fmi2Status read(fmi2Component c, ModelRead which, fmi2Real values[], size_t n, const char *call) {
    size_t k;
    if (!instance(c)) {
        if (values) for (k = 0; k < n; k++) values[k] = 0.0;
        return fmi2Error;
    }
    return (fmi2Status)glue_me_read(GLUE(c), which, values, n, call);
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
