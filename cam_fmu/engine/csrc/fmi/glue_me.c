/* Model Exchange's calls of the shared glue (glue.h), FMI-version neutral: the state machine of event and
 * continuous-time mode and the argument checks over the model's Model Exchange functions (model.h). No FMI
 * header, no globals. */
#include <stddef.h>

#include "glue.h"

#define READ_STATES (GLUE_ME_STATES | GLUE_TERMINATED | GLUE_ERROR_STATE)

int glue_me_allowed(Glue *g, int states, int attached, const char *call)
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
static int model_error(Glue *g, const char *call)
{
    glue_log(g, GLUE_ERROR, "logStatusError", "%s: %s", call, g->model->message(g->m));
    g->state = GLUE_ERROR_STATE;
    return GLUE_ERROR;
}

int glue_enter_event_mode(Glue *g, const char *call)
{
    if (!glue_me_allowed(g, GLUE_ME_STATES, 1, call))
        return GLUE_ERROR;
    g->model->exchange->enter_event_mode(g->m);
    g->state = GLUE_EVENT_MODE;
    return GLUE_OK;
}

int glue_new_discrete_states(Glue *g, int *needed, int *values_changed, const char *call)
{
    char fired[400];
    *needed = *values_changed = 0;
    if (!glue_me_allowed(g, GLUE_EVENT_MODE, 1, call))
        return GLUE_ERROR;
    if (g->model->exchange->event_update(g->m, values_changed, needed, fired, sizeof fired) != MODEL_OK)
        return model_error(g, call);
    if (fired[0])
        glue_log(g, GLUE_OK, "logEvents", "%s", fired);
    return GLUE_OK;
}

int glue_enter_continuous_time_mode(Glue *g, const char *call)
{
    if (!glue_me_allowed(g, GLUE_EVENT_MODE, 1, call))
        return GLUE_ERROR;
    g->model->exchange->enter_continuous(g->m);
    g->state = GLUE_CONTINUOUS_TIME_MODE;
    return GLUE_OK;
}

int glue_completed_integrator_step(Glue *g, int *enter_event, int *terminate, const char *call)
{
    *enter_event = *terminate = 0;
    if (!glue_me_allowed(g, GLUE_CONTINUOUS_TIME_MODE, 1, call))
        return GLUE_ERROR;
    if (g->model->exchange->completed_step(g->m, enter_event) != MODEL_OK) {
        *terminate = 1;
        return model_error(g, call);
    }
    g->last_successful_time = g->model->time(g->m);
    return GLUE_OK;
}

int glue_set_time(Glue *g, double time, const char *call)
{
    if (!glue_me_allowed(g, GLUE_ME_STATES, 1, call))
        return GLUE_ERROR;
    if (g->model->exchange->set_time(g->m, time) != MODEL_OK)
        return glue_fail(g, call, g->model->message(g->m));
    return GLUE_OK;
}

int glue_set_continuous_states(Glue *g, const double x[], size_t nx, const char *call)
{
    if (!glue_me_allowed(g, GLUE_CONTINUOUS_TIME_MODE, 1, call))
        return GLUE_ERROR;
    if (!x)
        return glue_fail(g, call, "x must not be NULL");
    if (g->model->exchange->set_states(g->m, x, nx) != MODEL_OK)
        return glue_fail(g, call, g->model->message(g->m));
    return GLUE_OK;
}

int glue_me_read(Glue *g, ModelRead which, double values[], size_t n, const char *call)
{
    size_t k;
    int nominals = which == MODEL_READ_NOMINALS;
    if (values)
        for (k = 0; k < n; k++)
            values[k] = 0.0;
    /* the nominals need no drive: a host may ask for them before initialisation */
    if (!glue_me_allowed(g, nominals ? GLUE_INSTANTIATED | GLUE_INITIALIZATION | READ_STATES : READ_STATES,
                         !nominals, call))
        return GLUE_ERROR;
    if (!values && n > 0)
        return glue_fail(g, call, "the array must not be NULL");
    if (g->model->exchange->read(g->m, which, values, n) != MODEL_OK) {
        for (k = 0; values && k < n; k++)
            values[k] = 0.0;
        return glue_fail(g, call, g->model->message(g->m));
    }
    return GLUE_OK;
}
