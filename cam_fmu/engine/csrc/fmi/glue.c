/* The glue both FMI versions share (glue.h): state machine, logging, variable access, steps and saved
 * states over the model table (model.h); Model Exchange is fmi2_me.c. No FMI header, no model's
 * header, no globals. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "glue.h"
#include "checksum.h"

#define MESSAGE_MAX 1024              /* a log line is cut here (a 20 MB bad value is not echoed whole) */
#define STATE_HEADER 16               /* magic, format, payload size (8 bytes) */
#define STATE_FORMAT 2u             /* 2: a CRC-32 after the payload (checksum.h) */
/* |currentCommunicationPoint - the FMU's time| allowed: rounding of a host's summed steps */
#define TIME_SLACK(t) (1e-9 * (fabs(t) > 1.0 ? fabs(t) : 1.0))

int glue_init(Glue *g, const char *name, int logging_on, const char *version, int exchange)
{
    g->model = model_table();
    g->name = malloc(strlen(name) + 1);
    g->m = g->model->create();
    if (!g->name || !g->m) {
        free(g->name);
        if (g->m)
            g->model->destroy(g->m);
        g->name = NULL;
        g->m = NULL;
        return 0;
    }
    strcpy(g->name, name);
    g->logging_on = logging_on ? 1 : 0;
    g->state = GLUE_INSTANTIATED;
    g->start_time = g->last_successful_time = 0.0;
    g->version = version;
    g->vr_end = g->model->vr_end;
    g->exchange = exchange ? 1 : 0;
    return 1;
}

void glue_free(Glue *g)
{
    g->magic = 0;
    if (g->m)
        g->model->destroy(g->m);
    free(g->name);
    g->m = NULL;
    g->name = NULL;
}

static const char *state_name(GlueState s)
{
    switch (s) {
    case GLUE_INSTANTIATED: return "instantiated";
    case GLUE_INITIALIZATION: return "initialization mode";
    case GLUE_STEP_COMPLETE: return "step mode";
    case GLUE_STEP_FAILED: return "step mode after Discard";
    case GLUE_ERROR_STATE: return "error (after Error: Reset or SetFMUState to go on)";
    case GLUE_TERMINATED: return "terminated";
    case GLUE_EVENT_MODE: return "event mode";
    case GLUE_CONTINUOUS_TIME_MODE: return "continuous-time mode";
    }
    return "unknown";
}

void glue_log(const Glue *g, int status, const char *category, const char *format, ...)
{
    char text[MESSAGE_MAX], escaped[2 * MESSAGE_MAX];
    size_t k, n = 0;
    va_list args;
    if (!g->emit || (status == GLUE_OK && !g->logging_on))
        return;
    va_start(args, format);
    vsnprintf(text, sizeof text, format, args);
    va_end(args);
    if (strlen(text) == sizeof text - 1)
        memcpy(text + sizeof text - 5, "...", 4);
    for (k = 0; text[k] && n + 2 < sizeof escaped; k++) {
        if (text[k] == '%')
            escaped[n++] = '%';
        escaped[n++] = text[k];
    }
    escaped[n] = '\0';
    g->emit(g->host, status, category, escaped);
}

int glue_fail(const Glue *g, const char *call, const char *text)
{
    glue_log(g, GLUE_ERROR, "logStatusError", "%s: %s", call, text);
    return GLUE_ERROR;
}

int glue_allowed(const Glue *g, int states, const char *call)
{
    if (g->state & states)
        return 1;
    glue_log(g, GLUE_ERROR, "logStatusError", "%s: not allowed in state '%s'", call, state_name(g->state));
    return 0;
}

int glue_model_status(Glue *g, int status, const char *call)
{
    if (status == MODEL_OK)
        return GLUE_OK;
    if (status == MODEL_DISCARD) {
        glue_log(g, GLUE_DISCARD, "logStatusDiscard", "%s: %s", call, g->model->message(g->m));
        g->state = GLUE_STEP_FAILED;
        return GLUE_DISCARD;
    }
    glue_log(g, GLUE_ERROR, "logStatusError", "%s: %s", call, g->model->message(g->m));
    g->state = GLUE_ERROR_STATE;
    return GLUE_ERROR;
}

/* ------------------------------------------------------------------ life cycle */

int glue_setup(Glue *g, double start_time, int stop_defined, double stop_time, const char *call)
{
    char text[200];
    if (!isfinite(start_time) || fabs(start_time) > 1e15 || (stop_defined && !(isfinite(stop_time)
                                                                               && stop_time >= start_time))) {
        snprintf(text, sizeof text, "startTime = %.17g s must be finite within [-1e15, 1e15] s and "
                 "stopTime = %.17g s finite and >= startTime", start_time, stop_time);
        return glue_fail(g, call, text);
    }
    g->start_time = start_time;
    return GLUE_OK;
}

int glue_enter_initialization(Glue *g, const char *call)
{
    if (!glue_allowed(g, GLUE_INSTANTIATED, call))
        return GLUE_ERROR;
    g->state = GLUE_INITIALIZATION;
    return GLUE_OK;
}

int glue_exit_initialization(Glue *g, const char *call)
{
    int status;
    if (!glue_allowed(g, GLUE_INITIALIZATION, call))
        return GLUE_ERROR;
    status = glue_model_status(g, g->model->initialize(g->m, g->start_time), call);
    if (status == GLUE_OK && g->exchange) {   /* Model Exchange starts in event mode */
        if (g->model->exchange->attach(g->m) != MODEL_OK) {
            glue_log(g, GLUE_ERROR, "logStatusError", "%s: %s", call, g->model->message(g->m));
            g->state = GLUE_ERROR_STATE;
            return GLUE_ERROR;
        }
        g->state = GLUE_EVENT_MODE;
        g->last_successful_time = g->start_time;
        return GLUE_OK;
    }
    if (status == GLUE_OK) {
        g->state = GLUE_STEP_COMPLETE;
        g->last_successful_time = g->start_time;
    }
    return status;
}

int glue_terminate(Glue *g, const char *call)
{
    if (!glue_allowed(g, GLUE_STEP_COMPLETE | GLUE_STEP_FAILED | GLUE_ERROR_STATE | GLUE_ME_STATES, call))
        return GLUE_ERROR;
    g->state = GLUE_TERMINATED;
    return GLUE_OK;
}

void glue_reset(Glue *g)
{
    g->model->reset(g->m);
    g->state = GLUE_INSTANTIATED;
    g->start_time = g->last_successful_time = 0.0;
}

/* ------------------------------------------------------------------ variables */

static const char *kind_name(ModelKind kind)
{
    return kind == MODEL_REAL ? "Real" : kind == MODEL_BOOLEAN ? "Boolean" : "String";
}

static int check_references(const Glue *g, const unsigned vr[], size_t nvr, const void *value, ModelKind type,
                            const char *call)
{
    char text[300];
    size_t k;
    ModelKind kind;
    const char *name;
    if (nvr == 0)
        return 1;
    if (!vr || !value) {
        glue_fail(g, call, "the value reference and value arrays must not be NULL");
        return 0;
    }
    for (k = 0; k < nvr; k++) {
        if (vr[k] >= g->vr_end || !g->model->variable(vr[k], &kind, &name)) {
            snprintf(text, sizeof text, "value reference %u is not a variable of %s (0 to %u)", vr[k],
                     g->model->name, g->vr_end - 1);
            glue_fail(g, call, text);
            return 0;
        }
        if (kind != type) {
            snprintf(text, sizeof text, "variable '%s' (value reference %u) is a %s, not a %s", name, vr[k],
                     kind_name(kind), kind_name(type));
            glue_fail(g, call, text);
            return 0;
        }
    }
    return 1;
}

int glue_get_reals(Glue *g, const unsigned vr[], size_t nvr, double value[], const char *call)
{
    size_t k;
    if (value)
        for (k = 0; k < nvr; k++)
            value[k] = 0.0;
    if (!glue_allowed(g, GLUE_GET_STATES, call) || !check_references(g, vr, nvr, value, MODEL_REAL, call))
        return GLUE_ERROR;
    if (g->state & GLUE_ME_STATES)
        g->model->exchange->sync(g->m);   /* outputs at the host's state and inputs */
    for (k = 0; k < nvr; k++)
        if (g->model->get_real(g->m, vr[k], &value[k]) != MODEL_OK)
            return glue_fail(g, call, g->model->message(g->m));
    return GLUE_OK;
}

int glue_get_booleans(Glue *g, const unsigned vr[], size_t nvr, int value[], const char *call)
{
    size_t k;
    if (value)
        for (k = 0; k < nvr; k++)
            value[k] = 0;
    if (!glue_allowed(g, GLUE_GET_STATES, call) || !check_references(g, vr, nvr, value, MODEL_BOOLEAN, call))
        return GLUE_ERROR;
    for (k = 0; k < nvr; k++)
        if (g->model->get_boolean(g->m, vr[k], &value[k]) != MODEL_OK)
            return glue_fail(g, call, g->model->message(g->m));
    return GLUE_OK;
}

int glue_get_strings(Glue *g, const unsigned vr[], size_t nvr, const char *value[], const char *call)
{
    size_t k;
    if (value)
        for (k = 0; k < nvr; k++)
            value[k] = "";
    if (!glue_allowed(g, GLUE_GET_STATES, call) || !check_references(g, vr, nvr, value, MODEL_STRING, call))
        return GLUE_ERROR;
    for (k = 0; k < nvr; k++)
        if (g->model->get_string(g->m, vr[k], &value[k]) != MODEL_OK) {
            value[k] = "";
            return glue_fail(g, call, g->model->message(g->m));
        }
    return GLUE_OK;
}

int glue_set_reals(Glue *g, const unsigned vr[], size_t nvr, const double value[], const char *call)
{
    size_t k;
    if (!glue_allowed(g, GLUE_SET_STATES, call) || !check_references(g, vr, nvr, value, MODEL_REAL, call))
        return GLUE_ERROR;
    for (k = 0; k < nvr; k++)   /* all or nothing: every value is checked before one is written */
        if (g->model->check_real(g->m, vr[k], value[k]) != MODEL_OK)
            return glue_fail(g, call, g->model->message(g->m));
    for (k = 0; k < nvr; k++)
        if (g->model->set_real(g->m, vr[k], value[k]) != MODEL_OK)
            return glue_fail(g, call, g->model->message(g->m));
    return GLUE_OK;
}

int glue_set_booleans(Glue *g, const unsigned vr[], size_t nvr, const int value[], const char *call)
{
    size_t k;
    if (!glue_allowed(g, GLUE_SET_STATES, call) || !check_references(g, vr, nvr, value, MODEL_BOOLEAN, call))
        return GLUE_ERROR;
    if (nvr > 0 && g->model->initialized(g->m))   /* booleans are parameters */
        return glue_fail(g, call, "parameters are fixed after initialisation (Reset first)");
    for (k = 0; k < nvr; k++)
        if (g->model->set_boolean(g->m, vr[k], value[k] != 0) != MODEL_OK)
            return glue_fail(g, call, g->model->message(g->m));
    return GLUE_OK;
}

int glue_set_strings(Glue *g, const unsigned vr[], size_t nvr, const char *const value[], const char *call)
{
    size_t k, size;
    unsigned char *saved;
    if (!glue_allowed(g, GLUE_SET_STATES, call) || !check_references(g, vr, nvr, value, MODEL_STRING, call))
        return GLUE_ERROR;
    for (k = 0; k < nvr; k++)
        if (!value[k])
            return glue_fail(g, call, "a string value must not be NULL");
    /* strings are checked as they are set: a multi-value set is undone on refusal by saving first */
    size = g->model->state_size(g->m);
    saved = malloc(size ? size : 1);
    if (!saved || g->model->save(g->m, saved, size) != MODEL_OK) {
        free(saved);
        return glue_fail(g, call, "out of memory");
    }
    for (k = 0; k < nvr; k++)
        if (g->model->set_string(g->m, vr[k], value[k], strlen(value[k])) != MODEL_OK) {
            int status = glue_fail(g, call, g->model->message(g->m));
            g->model->restore(g->m, saved, size);
            free(saved);
            return status;
        }
    free(saved);
    return GLUE_OK;
}

/* ------------------------------------------------------------------ stepping */

int glue_do_step(Glue *g, double t, double h, const char *call)
{
    char text[300];
    double now;
    int status;
    if (!glue_allowed(g, GLUE_STEP_COMPLETE, call))
        return GLUE_ERROR;
    now = g->model->time(g->m);
    if (!isfinite(t) || fabs(t - now) > TIME_SLACK(now)) {
        snprintf(text, sizeof text, "currentCommunicationPoint = %.17g s is not where the FMU is, t = %.17g s "
                 "(allowed difference %.3g s)", t, now, TIME_SLACK(now));
        return glue_fail(g, call, text);
    }
    if (!(h > 0.0) || !isfinite(h)) {
        snprintf(text, sizeof text, "communicationStepSize = %.17g s: allowed a finite value > 0", h);
        return glue_fail(g, call, text);
    }
    status = glue_model_status(g, g->model->step(g->m, now, h), call);
    if (status == GLUE_OK) {
        const char *events = g->model->step_events ? g->model->step_events(g->m) : NULL;
        g->last_successful_time = g->model->time(g->m);
        if (events && events[0])
            glue_log(g, GLUE_OK, "logEvents", "%s", events);
    }
    return status;
}

/* ------------------------------------------------------------------ FMU states */

GlueSaved *glue_save(Glue *g)
{
    size_t size = g->model->state_size(g->m);
    GlueSaved *saved = malloc(sizeof *saved + size);
    int me = (g->state & GLUE_ME_STATES) != 0;
    if (!saved)
        return NULL;
    saved->size = size;
    saved->mode = me ? (unsigned)g->state : 0u;
    if ((me ? g->model->exchange->save(g->m, saved->bytes, size) : g->model->save(g->m, saved->bytes, size))
        != MODEL_OK) {
        free(saved);
        return NULL;
    }
    return saved;
}

/* Model Exchange: the restored model must be one Model Exchange runs, else the state before is put back. */
static int restore_exchange(Glue *g, const GlueSaved *saved, const char *call)
{
    const Model *model = g->model;
    GlueSaved *before = glue_save(g);
    int status;
    if (!before)
        return glue_fail(g, call, "out of memory");
    if (model->restore(g->m, saved->bytes, saved->size) != MODEL_OK) {
        free(before);
        return glue_fail(g, call, model->message(g->m));
    }
    if (!model->initialized(g->m)) {
        free(before);
        g->state = GLUE_INSTANTIATED;
        return GLUE_OK;
    }
    if (model->exchange->attach(g->m) != MODEL_OK) {
        status = glue_fail(g, call, model->message(g->m));
        model->restore(g->m, before->bytes, before->size);
        if (model->initialized(g->m))
            model->exchange->attach(g->m);
        free(before);
        return status;
    }
    free(before);
    /* the mode it was saved in; a co-simulation state enters event mode (the host then iterates) */
    g->state = saved->mode == GLUE_CONTINUOUS_TIME_MODE ? GLUE_CONTINUOUS_TIME_MODE : GLUE_EVENT_MODE;
    g->last_successful_time = model->time(g->m);
    return GLUE_OK;
}

int glue_restore(Glue *g, const GlueSaved *saved, const char *call)
{
    if (!saved)
        return glue_fail(g, call, "the FMU state must not be NULL");
    if (g->exchange)
        return restore_exchange(g, saved, call);
    /* the instance's state follows the model's: an initialised one goes to step mode */
    if (g->model->restore(g->m, saved->bytes, saved->size) != MODEL_OK)
        return glue_fail(g, call, g->model->message(g->m));
    if (g->model->initialized(g->m)) {
        g->state = GLUE_STEP_COMPLETE;
        g->last_successful_time = g->model->time(g->m);
    } else {
        g->state = GLUE_INSTANTIATED;
    }
    return GLUE_OK;
}

size_t glue_serialized_size(const GlueSaved *saved)
{
    return STATE_HEADER + saved->size + CHECKSUM_BYTES;
}

static void put_u32(unsigned char *p, unsigned long v)
{
    int k;
    for (k = 0; k < 4; k++)
        p[k] = (unsigned char)(v >> (8 * k));
}

static unsigned long get_u32(const unsigned char *p)
{
    unsigned long v = 0;
    int k;
    for (k = 3; k >= 0; k--)
        v = (v << 8) | p[k];
    return v;
}

int glue_serialize(Glue *g, const GlueSaved *saved, unsigned char *out, size_t size, const char *call)
{
    if (!saved || !out)
        return glue_fail(g, call, "the FMU state and the buffer must not be NULL");
    if (size < STATE_HEADER + saved->size + CHECKSUM_BYTES)
        return glue_fail(g, call, "the buffer is smaller than the serialised state's size");
    put_u32(out, g->model->state_magic);
    put_u32(out + 4, STATE_FORMAT);
    put_u32(out + 8, (unsigned long)(saved->size & 0xffffffffu));
    put_u32(out + 12, saved->mode);
    memcpy(out + STATE_HEADER, saved->bytes, saved->size);
    checksum_append(out, STATE_HEADER + saved->size);
    return GLUE_OK;
}

int glue_deserialize(Glue *g, const unsigned char *in, size_t size, GlueSaved **saved, const char *call)
{
    GlueSaved *made;
    size_t payload;
    unsigned mode;
    if (!in || !saved)
        return glue_fail(g, call, "the arguments must not be NULL");
    if (size < STATE_HEADER + CHECKSUM_BYTES || get_u32(in) != g->model->state_magic
        || get_u32(in + 4) != STATE_FORMAT) {
        glue_log(g, GLUE_ERROR, "logStatusError", "%s: these bytes are not a serialised %s state (format %u)", call,
                 g->model->name, STATE_FORMAT);
        return GLUE_ERROR;
    }
    if (!checksum_valid(in, size - CHECKSUM_BYTES))
        return glue_fail(g, call, "the serialised state is corrupt: its CRC-32 does not match its bytes (changed "
                         "or truncated since it was serialised)");
    payload = get_u32(in + 8);
    if (payload != size - STATE_HEADER - CHECKSUM_BYTES)
        return glue_fail(g, call, "the serialised state is truncated or has trailing bytes");
    mode = (unsigned)get_u32(in + 12);
    if (mode != 0u && mode != GLUE_EVENT_MODE && mode != GLUE_CONTINUOUS_TIME_MODE)
        return glue_fail(g, call, "the serialised state's mode word is not a mode of this FMU");
    made = malloc(sizeof *made + payload);
    if (!made)
        return glue_fail(g, call, "out of memory");
    made->size = payload;
    made->mode = mode;
    memcpy(made->bytes, in + STATE_HEADER, payload);
    free(*saved);
    *saved = made;
    return GLUE_OK;
}
