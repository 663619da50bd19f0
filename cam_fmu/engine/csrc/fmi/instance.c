/* One cam drive as an FMI host sees it (cam_instance.h): the parameters and inputs a host sets,
 * the drive built from them at initialisation, outputs before and after it, and the saved state
 * with the parameters in it. Holds no physics: everything is cam_drive.h's CamDrive. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cam_instance.h"

#define BLOB_MAGIC 0x494d4143u     /* 'CAMI' little-endian */
#define BLOB_VERSION 1u

struct CamInstance {
    CamParams params;                   /* as set by the host; fixed after initialisation */
    double inputs[CAM_N_INPUTS];        /* as set by the host; the next step holds them */
    int initialized;
    CamDrive drive;                     /* built at initialisation */
    double start_time;                  /* s */
    int preview_valid;                  /* preview holds the outputs of params and inputs */
    double preview[CAM_N_OUTPUTS];      /* outputs before initialisation */
    double preview_x[CAM_ME_NX], preview_dx[CAM_ME_NX];   /* the states and derivatives then */
    CamError error;                     /* the last refusal, of this layer or of Model Exchange's */
};

int cam_instance_variable(unsigned vr, CamKind *kind, const char **name)
{
    if (vr < CAM_VR_OUTPUTS) {
        *kind = CAM_KIND_REAL;
        *name = cam_input_spec((int)vr)->name;
        return 1;
    }
    if (vr < CAM_VR_PARAMS) {
        *kind = CAM_KIND_REAL;
        *name = cam_output_spec((int)(vr - CAM_VR_OUTPUTS))->name;
        return 1;
    }
    if (vr < (unsigned)(CAM_VR_PARAMS + CAM_N_PARAMS)) {
        const CamParamSpec *s = cam_param_spec((int)(vr - CAM_VR_PARAMS));
        *kind = s->kind;
        *name = s->name;
        return 1;
    }
    if (vr < (unsigned)CAM_VR_END) {
        *kind = CAM_KIND_REAL;
        *name = vr < (unsigned)CAM_VR_DERIVATIVES ? cam_state_spec((int)(vr - CAM_VR_STATES))->name
                                                  : cam_derivative_spec((int)(vr - CAM_VR_DERIVATIVES))->name;
        return 1;
    }
    return 0;
}

const char *cam_kind_name(CamKind kind)
{
    return kind == CAM_KIND_REAL ? "Real" : kind == CAM_KIND_BOOLEAN ? "Boolean" : "String";
}

static void defaults(CamInstance *d)
{
    int k;
    cam_params_defaults(&d->params);
    for (k = 0; k < CAM_N_INPUTS; k++)
        d->inputs[k] = cam_input_spec(k)->start;
    d->initialized = 0;
    d->start_time = 0.0;
    d->preview_valid = 0;
    d->error.status = CAM_OK;
    d->error.message[0] = '\0';
}

CamInstance *cam_instance_new(void)
{
    CamInstance *d = calloc(1, sizeof *d);
    if (d)
        defaults(d);
    return d;
}

void cam_instance_free(CamInstance *d)
{
    if (!d)
        return;
    if (d->initialized)
        cam_drive_free(&d->drive);
    cam_params_free(&d->params);
    free(d);
}

void cam_instance_reset(CamInstance *d)
{
    if (d->initialized)
        cam_drive_free(&d->drive);
    cam_params_free(&d->params);
    defaults(d);
}

const char *cam_instance_message(const CamInstance *d)
{
    return d->error.message;
}

CamError *cam_instance_error(CamInstance *d)
{
    return &d->error;
}

int cam_instance_initialized(const CamInstance *d)
{
    return d->initialized;
}

CamDrive *cam_instance_drive(CamInstance *d)
{
    return d->initialized ? &d->drive : NULL;
}

const double *cam_instance_inputs(const CamInstance *d)
{
    return d->inputs;
}

double cam_instance_time(const CamInstance *d)
{
    return d->initialized ? d->drive.time : d->start_time;
}

/* ------------------------------------------------------------------ reals */

/* The check of a real value for vr, without writing it: 0 (CAM_OK) or a status with the message. */
static int check_real(const CamInstance *d, unsigned vr, double value, CamError *err)
{
    CamKind kind;
    const char *name;
    if (!cam_instance_variable(vr, &kind, &name))
        return cam_error(err, CAM_ERR_SIMULATION, "value reference %u is not a variable of cam.fmu", vr);
    if (vr < CAM_VR_OUTPUTS) {
        const CamVariableSpec *s = cam_input_spec((int)vr);
        char shown[CAM_REPR_LEN];
        if (s->low <= value && value <= s->high)
            return CAM_OK;
        return cam_error(err, CAM_ERR_SIMULATION, "input '%s' = %s [%s] is outside the allowed range [%g, %g] %s",
                         s->name, cam_num(value, shown), s->unit, s->low, s->high, s->unit);
    }
    if (vr < CAM_VR_PARAMS)
        return cam_error(err, CAM_ERR_SIMULATION, "variable '%s' is an output: it cannot be set", name);
    if (vr >= (unsigned)CAM_VR_STATES)
        return cam_error(err, CAM_ERR_SIMULATION, "variable '%s' is a continuous state or its derivative: it "
                         "cannot be set (Model Exchange sets the states with fmi2SetContinuousStates)", name);
    if (d->initialized)
        return cam_error(err, CAM_ERR_SIMULATION,
                         "parameter '%s' is fixed after initialisation (fmi2Reset, then set it)", name);
    {
        CamParams scratch = d->params; /* shallow: set_real of a real never touches the table text */
        return cam_params_set_real(&scratch, (int)(vr - CAM_VR_PARAMS), value, err);
    }
}

int cam_instance_check_real(CamInstance *d, unsigned vr, double value)
{
    return check_real(d, vr, value, &d->error);
}

int cam_instance_set_real(CamInstance *d, unsigned vr, double value)
{
    int status = check_real(d, vr, value, &d->error);
    if (status != CAM_OK)
        return status;
    if (vr < CAM_VR_OUTPUTS)
        d->inputs[vr] = value;
    else if ((status = cam_params_set_real(&d->params, (int)(vr - CAM_VR_PARAMS), value, &d->error)) != CAM_OK)
        return status;
    d->preview_valid = 0;
    return CAM_OK;
}

/* The outputs before initialisation: a drive built from the parameters and inputs set so far. */
static const double *preview(CamInstance *d)
{
    CamDrive scratch;
    if (d->preview_valid)
        return d->preview;
    if (cam_params_check(&d->params, &d->error) != CAM_OK || cam_drive_init(&scratch, &d->params, &d->error) != CAM_OK)
        return NULL;
    if (cam_drive_set_inputs(&scratch, d->inputs[CAM_I_U], d->inputs[CAM_I_OMEGA_REF],
                             d->inputs[CAM_I_OMEGA_DOT_REF], &d->error) != CAM_OK) {
        cam_drive_free(&scratch);
        return NULL;
    }
    memcpy(d->preview, cam_drive_outputs(&scratch), sizeof d->preview);
    cam_drive_me_states(&scratch, d->preview_x);
    cam_drive_me_rates(&scratch, d->preview_x, d->preview_dx);
    cam_drive_free(&scratch);
    d->preview_valid = 1;
    return d->preview;
}

const double *cam_instance_outputs(CamInstance *d)
{
    return d->initialized ? cam_drive_outputs(&d->drive) : preview(d);
}

/* A continuous state or its derivative (vr >= CAM_VR_STATES): of the consistent formulation only. */
static int state_value(CamInstance *d, unsigned vr, double *value)
{
    int derivative = vr >= (unsigned)CAM_VR_DERIVATIVES;
    int k = (int)(vr - (derivative ? CAM_VR_DERIVATIVES : CAM_VR_STATES));
    const char *name = derivative ? cam_derivative_spec(k)->name : cam_state_spec(k)->name;
    double x[CAM_ME_NX], dx[CAM_ME_NX];
    if ((int)d->params.v[CAM_P_FORMULATION] != CAM_CHOICE_FORMULATION_CONSISTENT
        || (int)d->params.v[CAM_P_DRIVE] != CAM_CHOICE_DRIVE_VOLTAGE)
        return cam_error(&d->error, CAM_ERR_SIMULATION, "variable '%s' belongs to the consistent formulation under "
                         "drive 'voltage' (the Model Exchange model); this drive has no such state: read the outputs",
                         name);
    if (!d->initialized) {
        if (!cam_instance_outputs(d))
            return CAM_ERR_PARAMETER; /* the message says which parameter prevents them */
        *value = derivative ? d->preview_dx[k] : d->preview_x[k];
        return CAM_OK;
    }
    cam_drive_me_states(&d->drive, x);
    if (!derivative) {
        *value = x[k];
        return CAM_OK;
    }
    cam_drive_me_rates(&d->drive, x, dx);
    *value = dx[k];
    return CAM_OK;
}

int cam_instance_get_real(CamInstance *d, unsigned vr, double *value)
{
    CamKind kind;
    const char *name;
    *value = 0.0;
    if (!cam_instance_variable(vr, &kind, &name) || kind != CAM_KIND_REAL)
        return cam_error(&d->error, CAM_ERR_SIMULATION, "no Real variable has this value reference");
    if (vr < CAM_VR_OUTPUTS) {
        *value = d->inputs[vr];
    } else if (vr < CAM_VR_PARAMS) {
        const double *out = cam_instance_outputs(d);
        if (!out)
            return CAM_ERR_PARAMETER; /* the message says which parameter prevents them */
        *value = out[vr - CAM_VR_OUTPUTS];
    } else if (vr < (unsigned)CAM_VR_STATES) {
        *value = d->params.v[vr - CAM_VR_PARAMS];
    } else {
        return state_value(d, vr, value);
    }
    return CAM_OK;
}

/* ------------------------------------------------------------------ booleans and strings */

int cam_instance_get_boolean(CamInstance *d, unsigned vr, int *value)
{
    *value = 0;
    if (vr < CAM_VR_PARAMS || vr >= (unsigned)(CAM_VR_PARAMS + CAM_N_PARAMS) ||
        cam_param_spec((int)(vr - CAM_VR_PARAMS))->kind != CAM_KIND_BOOLEAN)
        return cam_error(&d->error, CAM_ERR_SIMULATION, "no Boolean variable has this value reference");
    *value = d->params.v[vr - CAM_VR_PARAMS] != 0.0;
    return CAM_OK;
}

static int check_parameter(CamInstance *d, unsigned vr, CamKind kind)
{
    const CamParamSpec *s;
    if (vr < CAM_VR_PARAMS || vr >= (unsigned)(CAM_VR_PARAMS + CAM_N_PARAMS))
        return cam_error(&d->error, CAM_ERR_SIMULATION, "this value reference is not a parameter");
    s = cam_param_spec((int)(vr - CAM_VR_PARAMS));
    if (s->kind != kind)
        return cam_error(&d->error, CAM_ERR_SIMULATION, "variable '%s' is a %s, not a %s", s->name,
                         cam_kind_name(s->kind), cam_kind_name(kind));
    if (d->initialized)
        return cam_error(&d->error, CAM_ERR_SIMULATION,
                         "parameter '%s' is fixed after initialisation (fmi2Reset, then set it)", s->name);
    return CAM_OK;
}

int cam_instance_set_boolean(CamInstance *d, unsigned vr, int value)
{
    int status = check_parameter(d, vr, CAM_KIND_BOOLEAN);
    if (status != CAM_OK)
        return status;
    if ((status = cam_params_set_real(&d->params, (int)(vr - CAM_VR_PARAMS), value ? 1.0 : 0.0, &d->error)) != CAM_OK)
        return status;
    d->preview_valid = 0;
    return CAM_OK;
}

int cam_instance_get_string(CamInstance *d, unsigned vr, const char **value)
{
    const CamParamSpec *s;
    int choice;
    *value = "";
    if (vr < CAM_VR_PARAMS || vr >= (unsigned)(CAM_VR_PARAMS + CAM_N_PARAMS) ||
        cam_param_spec((int)(vr - CAM_VR_PARAMS))->kind != CAM_KIND_STRING)
        return cam_error(&d->error, CAM_ERR_SIMULATION, "no String variable has this value reference");
    s = cam_param_spec((int)(vr - CAM_VR_PARAMS));
    if (s->n_choices == 0) { /* the motion table: free text */
        *value = d->params.motion_table ? d->params.motion_table : "";
        return CAM_OK;
    }
    choice = (int)d->params.v[vr - CAM_VR_PARAMS];
    *value = choice >= 0 && choice < s->n_choices ? s->choices[choice] : "";
    return CAM_OK;
}

/* Offset of the first byte that is not UTF-8, or len when all are. */
static size_t utf8_invalid_at(const unsigned char *p, size_t len)
{
    size_t k = 0;
    while (k < len) {
        unsigned char c = p[k];
        size_t n = c < 0x80 ? 1 : (c >> 5) == 0x6 ? 2 : (c >> 4) == 0xe ? 3 : (c >> 3) == 0x1e ? 4 : 0;
        size_t j;
        if (n == 0 || k + n > len || (n == 2 && c < 0xc2) || (n == 4 && c > 0xf4))
            return k;
        for (j = 1; j < n; j++)
            if ((p[k + j] & 0xc0) != 0x80)
                return k;
        if ((n == 3 && c == 0xe0 && p[k + 1] < 0xa0) || (n == 4 && c == 0xf0 && p[k + 1] < 0x90) ||
            (n == 4 && c == 0xf4 && p[k + 1] >= 0x90) || (n == 3 && c == 0xed && p[k + 1] >= 0xa0))
            return k;
        k += n;
    }
    return len;
}

int cam_instance_set_string(CamInstance *d, unsigned vr, const char *value, size_t len)
{
    size_t bad;
    const CamParamSpec *s;
    int status = check_parameter(d, vr, CAM_KIND_STRING);
    if (status != CAM_OK)
        return status;
    s = cam_param_spec((int)(vr - CAM_VR_PARAMS));
    bad = utf8_invalid_at((const unsigned char *)value, len);
    if (bad < len)
        return cam_error(&d->error, CAM_ERR_PARAMETER, "parameter '%s': the value is not valid UTF-8 (byte 0x%02x "
                         "at offset %lu)", s->name, (unsigned)(unsigned char)value[bad], (unsigned long)bad);
    if (s->n_choices == 0 && len > 0) { /* the motion table: refused now, not at initialisation */
        CamProfile probe;
        CamError why;
        status = cam_profile_init_table(&probe, value, len, &why);
        cam_profile_free(&probe);
        if (status != CAM_OK)
            return cam_error(&d->error, CAM_ERR_PARAMETER, "parameter 'motion_table': %s", why.message);
    }
    if ((status = cam_params_set_string(&d->params, (int)(vr - CAM_VR_PARAMS), value, len, &d->error)) != CAM_OK)
        return status;
    d->preview_valid = 0;
    return CAM_OK;
}

/* ------------------------------------------------------------------ initialisation and steps */

int cam_instance_initialize(CamInstance *d, double start_time)
{
    int status;
    if (d->initialized)
        return cam_error(&d->error, CAM_ERR_SIMULATION, "the drive is initialised already");
    if ((status = cam_params_check(&d->params, &d->error)) != CAM_OK
        || (status = cam_drive_init(&d->drive, &d->params, &d->error)) != CAM_OK)
        return status;
    d->drive.time = start_time;
    d->drive.start_time = start_time;
    if ((status = cam_drive_set_inputs(&d->drive, d->inputs[CAM_I_U], d->inputs[CAM_I_OMEGA_REF],
                                       d->inputs[CAM_I_OMEGA_DOT_REF], &d->error)) != CAM_OK) {
        cam_drive_free(&d->drive);
        return status;
    }
    d->start_time = start_time;
    d->initialized = 1;
    return CAM_OK;
}

int cam_instance_step(CamInstance *d, double t, double h)
{
    if (!d->initialized)
        return cam_error(&d->error, CAM_ERR_SIMULATION, "the drive is not initialised");
    return cam_drive_do_step(&d->drive, t, h, d->inputs[CAM_I_U], d->inputs[CAM_I_OMEGA_REF],
                             d->inputs[CAM_I_OMEGA_DOT_REF], &d->error);
}

/* ------------------------------------------------------------------ the saved state
 * Layout (little-endian on every platform the FMU is built for, all 8-byte fields):
 *   magic/version (2 x u32), initialized (u64), table length (u64),
 *   start_time, inputs[CAM_N_INPUTS], params.v[CAM_N_PARAMS], drive state[CAM_STATE_LEN] (doubles),
 *   the motion table's bytes. */

#define FIXED_DOUBLES (1 + CAM_N_INPUTS + CAM_N_PARAMS + CAM_STATE_LEN)
#define HEADER_BYTES 24

static size_t table_length(const CamParams *p)
{
    return p->motion_table ? strlen(p->motion_table) : 0;
}

size_t cam_instance_state_size(const CamInstance *d)
{
    return HEADER_BYTES + 8 * FIXED_DOUBLES + table_length(&d->params);
}

static void put_u64(unsigned char *p, uint64_t v)
{
    int k;
    for (k = 0; k < 8; k++)
        p[k] = (unsigned char)(v >> (8 * k));
}

static uint64_t get_u64(const unsigned char *p)
{
    uint64_t v = 0;
    int k;
    for (k = 7; k >= 0; k--)
        v = (v << 8) | p[k];
    return v;
}

static void put_double(unsigned char *p, double x)
{
    uint64_t bits;
    memcpy(&bits, &x, 8);
    put_u64(p, bits);
}

static double get_double(const unsigned char *p)
{
    uint64_t bits = get_u64(p);
    double x;
    memcpy(&x, &bits, 8);
    return x;
}

int cam_instance_save(const CamInstance *d, unsigned char *buffer, size_t size)
{
    double state[CAM_STATE_LEN];
    unsigned char *p = buffer + HEADER_BYTES;
    size_t k, n = table_length(&d->params);
    if (size < cam_instance_state_size(d))
        return CAM_ERR_SIMULATION;
    put_u64(buffer, (uint64_t)BLOB_MAGIC | ((uint64_t)BLOB_VERSION << 32));
    put_u64(buffer + 8, (uint64_t)d->initialized);
    put_u64(buffer + 16, (uint64_t)n);
    put_double(p, d->start_time);
    p += 8;
    for (k = 0; k < CAM_N_INPUTS; k++, p += 8)
        put_double(p, d->inputs[k]);
    for (k = 0; k < CAM_N_PARAMS; k++, p += 8)
        put_double(p, d->params.v[k]);
    memset(state, 0, sizeof state);
    if (d->initialized)
        cam_drive_get_state(&d->drive, state);
    for (k = 0; k < CAM_STATE_LEN; k++, p += 8)
        put_double(p, state[k]);
    if (n)
        memcpy(p, d->params.motion_table, n);
    return CAM_OK;
}

static int same_params(const CamParams *a, const CamParams *b)
{
    const char *ta = a->motion_table ? a->motion_table : "", *tb = b->motion_table ? b->motion_table : "";
    return memcmp(a->v, b->v, sizeof a->v) == 0 && strcmp(ta, tb) == 0;
}

/* The blob's header: this format, and sizes that agree with size; the flag and the table's length out. */
static int decode_header(CamInstance *d, const unsigned char *buffer, size_t size, uint64_t *flag,
                         uint64_t *length)
{
    uint64_t initialized, n;
    if (size < HEADER_BYTES + 8 * FIXED_DOUBLES
        || get_u64(buffer) != ((uint64_t)BLOB_MAGIC | ((uint64_t)BLOB_VERSION << 32)))
        return cam_error(&d->error, CAM_ERR_SIMULATION, "the state is not a saved state of this cam.fmu (format 1)");
    initialized = get_u64(buffer + 8);
    n = get_u64(buffer + 16);
    if (initialized > 1 || n != size - HEADER_BYTES - 8 * FIXED_DOUBLES)
        return cam_error(&d->error, CAM_ERR_SIMULATION, "the saved state is truncated or corrupt (its sizes disagree)");
    *flag = initialized;
    *length = n;
    return CAM_OK;
}

/* The start time and the inputs at p, each input checked as if a host had set it. */
static int decode_inputs(CamInstance *d, const unsigned char *p, double *start_time, double inputs[CAM_N_INPUTS])
{
    size_t k;
    int status;
    *start_time = get_double(p);
    for (k = 0; k < CAM_N_INPUTS; k++) {
        inputs[k] = get_double(p + 8 * (1 + k));
        if ((status = check_real(d, (unsigned)k, inputs[k], &d->error)) != CAM_OK)
            return status;
    }
    if (!isfinite(*start_time))
        return cam_error(&d->error, CAM_ERR_SIMULATION, "the saved state's start time is not finite");
    return CAM_OK;
}

/* The parameters at p into params (at their defaults), each checked as if a host had set it. */
static int decode_params(CamInstance *d, const unsigned char *p, CamParams *params)
{
    size_t k;
    int status;
    for (k = 0; k < CAM_N_PARAMS; k++) {
        const CamParamSpec *s = cam_param_spec((int)k);
        double v = get_double(p + 8 * k);
        if (s->kind == CAM_KIND_STRING) {
            if (s->n_choices && !(v >= 0.0 && v < s->n_choices && v == floor(v)))
                return cam_error(&d->error, CAM_ERR_SIMULATION, "the saved state's parameter '%s' is not one of "
                                 "its choices", s->name);
            if (s->n_choices)
                params->v[k] = v;
            continue;
        }
        if (s->kind == CAM_KIND_BOOLEAN && v != 0.0 && v != 1.0)
            return cam_error(&d->error, CAM_ERR_SIMULATION, "the saved state's parameter '%s' is not a boolean",
                             s->name);
        if ((status = cam_params_set_real(params, (int)k, v, &d->error)) != CAM_OK)
            return status;
    }
    return CAM_OK;
}

/* The motion table's n bytes at p into params' table parameter. */
static int decode_table(CamInstance *d, const unsigned char *p, size_t n, CamParams *params)
{
    int table = -1, k;
    for (k = 0; k < CAM_N_PARAMS; k++)
        if (cam_param_spec(k)->kind == CAM_KIND_STRING && cam_param_spec(k)->n_choices == 0)
            table = k;
    if (table < 0)
        return cam_error(&d->error, CAM_ERR_SIMULATION, "the saved state has a table and no table parameter");
    return cam_params_set_string(params, table, (const char *)p, n, &d->error);
}

/* The drive of params (taken over: kept or freed) in the saved state: the instance's own drive when the
 * parameters are its own, else a new one; on refusal the instance is as before. */
static int restore_drive(CamInstance *d, CamParams *params, const double state[CAM_STATE_LEN], double start_time)
{
    CamDrive fresh;
    int status;
    if (d->initialized && same_params(&d->params, params)) {
        /* the usual case, a state of this instance: the drive's program is kept, not built again */
        CamDrive backup = d->drive;
        cam_params_free(params);
        d->drive.start_time = start_time;
        if ((status = cam_drive_set_state(&d->drive, state, &d->error)) != CAM_OK)
            d->drive = backup;
        return status;
    }
    if ((status = cam_params_check(params, &d->error)) != CAM_OK ||
        (status = cam_drive_init(&fresh, params, &d->error)) != CAM_OK) {
        cam_params_free(params);
        return status;
    }
    fresh.start_time = start_time;
    if ((status = cam_drive_set_state(&fresh, state, &d->error)) != CAM_OK) {
        cam_drive_free(&fresh);
        cam_params_free(params);
        return status;
    }
    if (d->initialized)
        cam_drive_free(&d->drive);
    cam_params_free(&d->params);
    d->params = *params;
    d->drive = fresh;
    return CAM_OK;
}

int cam_instance_restore(CamInstance *d, const unsigned char *buffer, size_t size)
{
    const unsigned char *p = buffer + HEADER_BYTES;
    const unsigned char *p_params = p + 8 * (1 + CAM_N_INPUTS), *p_state = p_params + 8 * CAM_N_PARAMS;
    CamParams params;
    double state[CAM_STATE_LEN], inputs[CAM_N_INPUTS], start_time;
    uint64_t initialized = 0, n = 0;   /* set by decode_header (initialised for the compiler) */
    size_t k;
    int status;
    if ((status = decode_header(d, buffer, size, &initialized, &n)) != CAM_OK
        || (status = decode_inputs(d, p, &start_time, inputs)) != CAM_OK)
        return status;
    cam_params_defaults(&params);
    if ((status = decode_params(d, p_params, &params)) == CAM_OK && n)
        status = decode_table(d, p_state + 8 * CAM_STATE_LEN, (size_t)n, &params);
    if (status != CAM_OK) {
        cam_params_free(&params);
        return status;
    }
    for (k = 0; k < CAM_STATE_LEN; k++)
        state[k] = get_double(p_state + 8 * k);
    if (initialized) {
        if ((status = restore_drive(d, &params, state, start_time)) != CAM_OK)
            return status;
    } else {
        if (d->initialized)
            cam_drive_free(&d->drive);
        cam_params_free(&d->params);
        d->params = params;
        d->preview_valid = 0;
    }
    memcpy(d->inputs, inputs, sizeof inputs);
    d->start_time = start_time;
    d->initialized = (int)initialized;
    return CAM_OK;
}
