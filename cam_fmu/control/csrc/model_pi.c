/* pi_speed.fmu's model table (csrc/fmi/model.h): the controller of pi_law.h as an FMI host sees it, the
 * parameters and inputs it sets, the outputs, the time, and the saved state. Co-simulation only (a sampled
 * controller has no continuous states). No FMI header, no globals (the table is const data).
 *
 * Rules, as cam.fmu's: a parameter is set before initialisation only, within its range (the message names
 * it and the range); an input is any finite value; an output is never set; a refused call changes nothing.
 * Outputs before initialisation are the law on the parameters and inputs as set (no integration).
 */
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "model.h"
#include "pi_law.h"

#define MESSAGE_LEN 512
#define BLOB_MAGIC 0x49504950u     /* 'PIPI' */
#define BLOB_VERSION 1u

typedef struct {
    double p[PI_N_PARAMS];
    double in[PI_N_INPUTS];
    int initialized;
    double start_time, time;   /* s */
    PiState state;
    char message[MESSAGE_LEN];
} Pi;

/* The state's bytes: everything but the message, in a fixed layout of doubles. */
enum { B_MAGIC, B_VERSION, B_INITIALIZED, B_START, B_TIME, B_INTEGRAL, B_W_PREV, B_HAVE_W_PREV, B_U, B_ERROR, B_U_FF,
       B_PARAMS, B_INPUTS = B_PARAMS + PI_N_PARAMS, B_LEN = B_INPUTS + PI_N_INPUTS };

/* MODEL_ERROR with the message. */
static int refuse(Pi *c, const char *format, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

static int refuse(Pi *c, const char *format, ...)
{
    va_list args;
    va_start(args, format);
    vsnprintf(c->message, sizeof c->message, format, args);
    va_end(args);
    return MODEL_ERROR;
}

/* MODEL_ERROR for an overflow of the law (pi_law.h names the quantity) at time t [s], with the inputs that gave it. */
static int overflowed(Pi *c, const char *what, double t)
{
    return refuse(c, "%s is not finite (an overflow) at t = %.17g s: setpoint w = %.17g rad/s, omega_meas = %.17g "
                  "rad/s, integral = %.17g V, kp = %.17g V/(rad/s), ki = %.17g V/rad (the state is as before)", what,
                  t, c->p[PI_P_EXTERNAL_SETPOINT] != 0.0 ? c->in[PI_I_OMEGA_SETPOINT] : c->p[PI_P_OMEGA_SET],
                  c->in[PI_I_OMEGA_MEAS], c->state.integral, c->p[PI_P_KP], c->p[PI_P_KI]);
}

static void defaults(Pi *c)
{
    int k;
    for (k = 0; k < PI_N_PARAMS; k++)
        c->p[k] = pi_param_spec(k)->default_value;
    for (k = 0; k < PI_N_INPUTS; k++)
        c->in[k] = pi_input_spec(k)->start;
    c->initialized = 0;
    c->start_time = c->time = 0.0;
    pi_state_clear(&c->state);
    c->message[0] = '\0';
}

static void *create(void)
{
    Pi *c = calloc(1, sizeof *c);
    if (c)
        defaults(c);
    return c;
}

static void destroy(void *m) { free(m); }

static void reset(void *m) { defaults(m); }

static const char *message(const void *m) { return ((const Pi *)m)->message; }

static int variable(unsigned vr, ModelKind *kind, const char **name)
{
    if (vr < PI_VR_OUTPUTS) {
        *kind = MODEL_REAL;
        *name = pi_input_spec((int)vr)->name;
        return 1;
    }
    if (vr < PI_VR_PARAMS) {
        *kind = MODEL_REAL;
        *name = pi_output_spec((int)(vr - PI_VR_OUTPUTS))->name;
        return 1;
    }
    if (vr < PI_VR_END) {
        const PiParamSpec *s = pi_param_spec((int)(vr - PI_VR_PARAMS));
        *kind = s->boolean ? MODEL_BOOLEAN : MODEL_REAL;
        *name = s->name;
        return 1;
    }
    return 0;
}

/* The check of a parameter's real value: MODEL_OK or MODEL_ERROR with the message in text. */
static int check_parameter(const PiParamSpec *s, double value, char *text, size_t len)
{
    int too_low = s->low_open ? value <= s->low : value < s->low;
    if (s->zero_ok && value == 0.0)
        return MODEL_OK;
    if (!isfinite(value) || too_low || value > s->high) {
        snprintf(text, len, "parameter '%s' = %.17g [%s] is outside the allowed range %s", s->name, value, s->unit,
                 s->allowed);
        return MODEL_ERROR;
    }
    return MODEL_OK;
}

static int check_value(const Pi *c, unsigned vr, double value, char *text, size_t len)
{
    ModelKind kind;
    const char *name;
    if (!variable(vr, &kind, &name) || kind != MODEL_REAL) {
        snprintf(text, len, "value reference %u is not a Real variable of pi_speed", vr);
        return MODEL_ERROR;
    }
    if (vr < PI_VR_OUTPUTS) {
        if (isfinite(value))
            return MODEL_OK;
        snprintf(text, len, "input '%s' = %.17g [%s] is not finite: allowed any finite value", name, value,
                 pi_input_spec((int)vr)->unit);
        return MODEL_ERROR;
    }
    if (vr < PI_VR_PARAMS) {
        snprintf(text, len, "variable '%s' is an output: it cannot be set", name);
        return MODEL_ERROR;
    }
    if (c->initialized) {
        snprintf(text, len, "parameter '%s' is fixed after initialisation (Reset, then set it)", name);
        return MODEL_ERROR;
    }
    return check_parameter(pi_param_spec((int)(vr - PI_VR_PARAMS)), value, text, len);
}

/* The model's check_real: the refusal's message in message(m). */
static int check_real(void *m, unsigned vr, double value)
{
    Pi *c = m;
    return check_value(c, vr, value, c->message, sizeof c->message);
}

static int set_real(void *m, unsigned vr, double value)
{
    Pi *c = m;
    if (check_real(c, vr, value) != MODEL_OK)
        return MODEL_ERROR;
    if (vr < PI_VR_OUTPUTS)
        c->in[vr] = value;
    else
        c->p[vr - PI_VR_PARAMS] = value;
    return MODEL_OK;
}

static int get_real(void *m, unsigned vr, double *value)
{
    Pi *c = m;
    double out[PI_N_OUTPUTS];
    if (vr < PI_VR_OUTPUTS) {
        *value = c->in[vr];
        return MODEL_OK;
    }
    if (vr < PI_VR_PARAMS) {
        PiState preview = c->state;
        const char *overflow = NULL;
        if (!c->initialized)   /* before initialisation: the law on the inputs as set */
            overflow = pi_initialize(&preview, c->p, c->in);
        if (overflow)
            return overflowed(c, overflow, c->time);
        pi_outputs(&preview, out);
        *value = out[vr - PI_VR_OUTPUTS];
        return MODEL_OK;
    }
    if (vr < PI_VR_END && !pi_param_spec((int)(vr - PI_VR_PARAMS))->boolean) {
        *value = c->p[vr - PI_VR_PARAMS];
        return MODEL_OK;
    }
    return refuse(c, "value reference %u is not a Real variable of pi_speed", vr);
}

static int get_boolean(void *m, unsigned vr, int *value)
{
    Pi *c = m;
    if (vr >= PI_VR_PARAMS && vr < PI_VR_END && pi_param_spec((int)(vr - PI_VR_PARAMS))->boolean) {
        *value = c->p[vr - PI_VR_PARAMS] != 0.0;
        return MODEL_OK;
    }
    return refuse(c, "value reference %u is not a Boolean variable of pi_speed", vr);
}

static int set_boolean(void *m, unsigned vr, int value)
{
    Pi *c = m;
    if (!(vr >= PI_VR_PARAMS && vr < PI_VR_END && pi_param_spec((int)(vr - PI_VR_PARAMS))->boolean))
        return refuse(c, "value reference %u is not a Boolean variable of pi_speed", vr);
    if (c->initialized)
        return refuse(c, "parameter '%s' is fixed after initialisation (Reset, then set it)",
                      pi_param_spec((int)(vr - PI_VR_PARAMS))->name);
    c->p[vr - PI_VR_PARAMS] = value ? 1.0 : 0.0;
    return MODEL_OK;
}

static int get_string(void *m, unsigned vr, const char **value)
{
    *value = "";
    return refuse(m, "value reference %u: pi_speed has no String variables", vr);
}

static int set_string(void *m, unsigned vr, const char *value, size_t len)
{
    (void)value;
    (void)len;
    return refuse(m, "value reference %u: pi_speed has no String variables", vr);
}

/* The parameters together: u_min <= u_max. */
static int check_together(Pi *c, const double p[PI_N_PARAMS])
{
    if (p[PI_P_U_MIN] > p[PI_P_U_MAX]) {
        snprintf(c->message, sizeof c->message, "parameters 'u_min' = %.17g V > 'u_max' = %.17g V: allowed u_min <= "
                 "u_max", p[PI_P_U_MIN], p[PI_P_U_MAX]);
        return MODEL_ERROR;
    }
    return MODEL_OK;
}

static int initialize(void *m, double start_time)
{
    Pi *c = m;
    PiState state;
    const char *overflow;
    if (check_together(c, c->p) != MODEL_OK)
        return MODEL_ERROR;
    pi_state_clear(&state);
    overflow = pi_initialize(&state, c->p, c->in);
    if (overflow)
        return overflowed(c, overflow, start_time);
    c->state = state;
    c->start_time = c->time = start_time;
    c->initialized = 1;
    return MODEL_OK;
}

static int initialized(const void *m) { return ((const Pi *)m)->initialized; }

static int step(void *m, double t, double h)
{
    Pi *c = m;
    const char *overflow;
    if (!isfinite(t + h))
        return refuse(c, "the time t + h = %.17g s + %.17g s is not finite (an overflow; the state is as before)",
                      t, h);
    overflow = pi_sample(&c->state, c->p, c->in, h);
    if (overflow)
        return overflowed(c, overflow, t);
    c->time = t + h;
    return MODEL_OK;
}

static double time_of(const void *m) { return ((const Pi *)m)->time; }

static size_t state_size(const void *m)
{
    (void)m;
    return B_LEN * sizeof(double);
}

static int save(const void *m, unsigned char *buffer, size_t size)
{
    const Pi *c = m;
    double b[B_LEN];
    if (size != sizeof b)
        return MODEL_ERROR;
    b[B_MAGIC] = BLOB_MAGIC;
    b[B_VERSION] = BLOB_VERSION;
    b[B_INITIALIZED] = c->initialized;
    b[B_START] = c->start_time;
    b[B_TIME] = c->time;
    b[B_INTEGRAL] = c->state.integral;
    b[B_W_PREV] = c->state.w_prev;
    b[B_HAVE_W_PREV] = c->state.have_w_prev;
    b[B_U] = c->state.u;
    b[B_ERROR] = c->state.error;
    b[B_U_FF] = c->state.u_ff;
    memcpy(&b[B_PARAMS], c->p, sizeof c->p);
    memcpy(&b[B_INPUTS], c->in, sizeof c->in);
    memcpy(buffer, b, sizeof b);
    return MODEL_OK;
}

/* A blob's entries, each and together; MODEL_OK or MODEL_ERROR with what is wrong in c->message. */
static int check_blob(Pi *c, const double b[B_LEN])
{
    char text[MESSAGE_LEN];
    int k;
    if (b[B_MAGIC] != BLOB_MAGIC || b[B_VERSION] != BLOB_VERSION)
        return refuse(c, "the saved state is not one of pi_speed (format %u)", BLOB_VERSION);
    if (b[B_INITIALIZED] != 0.0 && b[B_INITIALIZED] != 1.0)
        return refuse(c, "saved state: 'initialized' = %.17g: allowed 0 or 1", b[B_INITIALIZED]);
    if (b[B_HAVE_W_PREV] != 0.0 && b[B_HAVE_W_PREV] != 1.0)
        return refuse(c, "saved state: 'have_w_prev' = %.17g: allowed 0 or 1", b[B_HAVE_W_PREV]);
    for (k = B_START; k <= B_U_FF; k++)
        if (!isfinite(b[k]))
            return refuse(c, "saved state: entry %d is not finite", k);
    if (b[B_TIME] < b[B_START])
        return refuse(c, "saved state: time %.17g s is before the start time %.17g s", b[B_TIME], b[B_START]);
    for (k = 0; k < PI_N_PARAMS; k++) {
        const PiParamSpec *s = pi_param_spec(k);
        if (s->boolean ? (b[B_PARAMS + k] != 0.0 && b[B_PARAMS + k] != 1.0)
                       : check_parameter(s, b[B_PARAMS + k], text, sizeof text) != MODEL_OK)
            return refuse(c, "saved state: parameter '%s' = %.17g is outside its range %s", s->name, b[B_PARAMS + k],
                          s->allowed);
    }
    for (k = 0; k < PI_N_INPUTS; k++)
        if (!isfinite(b[B_INPUTS + k]))
            return refuse(c, "saved state: input '%s' = %.17g is not finite", pi_input_spec(k)->name, b[B_INPUTS + k]);
    if (b[B_INITIALIZED] == 1.0 && b[B_HAVE_W_PREV] != 1.0)
        return refuse(c, "saved state: initialised without a previous setpoint");
    return check_together(c, &b[B_PARAMS]);
}

static int restore(void *m, const unsigned char *buffer, size_t size)
{
    Pi *c = m;
    double b[B_LEN];
    if (size != sizeof b)
        return refuse(c, "the saved state has %lu bytes, not the %lu of a pi_speed state", (unsigned long)size,
                      (unsigned long)sizeof b);
    memcpy(b, buffer, sizeof b);
    if (check_blob(c, b) != MODEL_OK)
        return MODEL_ERROR;
    c->initialized = b[B_INITIALIZED] == 1.0;
    c->start_time = b[B_START];
    c->time = b[B_TIME];
    c->state.integral = b[B_INTEGRAL];
    c->state.w_prev = b[B_W_PREV];
    c->state.have_w_prev = b[B_HAVE_W_PREV] == 1.0;
    c->state.u = b[B_U];
    c->state.error = b[B_ERROR];
    c->state.u_ff = b[B_U_FF];
    memcpy(c->p, &b[B_PARAMS], sizeof c->p);
    memcpy(c->in, &b[B_INPUTS], sizeof c->in);
    c->message[0] = '\0';
    return MODEL_OK;
}

static const Model PI = {
    "pi_speed", 0x50495353u /* 'PISS' */, PI_VR_END, PI_VR_END,
    create, destroy, reset, message, variable, get_real, check_real, set_real, get_boolean, set_boolean,
    get_string, set_string, initialize, initialized, step, time_of, state_size, save, restore, NULL,
    NULL,   /* no step events */
};

const Model *model_table(void) { return &PI; }
