/* cam.fmu's model table (model.h): the drive's instance layer (cam_instance.h) and its Model Exchange layer
 * (exchange.h) behind the functions the FMI glue calls. Only translation: statuses, kinds, the object that
 * holds both layers. No FMI header, no globals (the table is const data). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "exchange.h"
#include "directional.h"
#include "model.h"

typedef struct {
    CamInstance *drive;
    CamExchange me;
} CamFmuModel;

/* CamStatus to ModelStatus: a step the solver cannot complete at this size is Discard, the rest Error. */
static int status_of(int cam_status)
{
    return cam_status == CAM_OK ? MODEL_OK : cam_status == CAM_ERR_REJECTED ? MODEL_DISCARD : MODEL_ERROR;
}

static void *create(void)
{
    CamFmuModel *c = calloc(1, sizeof *c);
    if (!c)
        return NULL;
    c->drive = cam_instance_new();
    if (!c->drive) {
        free(c);
        return NULL;
    }
    cam_exchange_init(&c->me, c->drive);
    return c;
}

static void destroy(void *m)
{
    CamFmuModel *c = m;
    if (!c)
        return;
    cam_instance_free(c->drive);
    free(c);
}

static void reset(void *m)
{
    CamFmuModel *c = m;
    cam_instance_reset(c->drive);
    cam_exchange_init(&c->me, c->drive);
}

static const char *message(const void *m) { return cam_instance_message(((const CamFmuModel *)m)->drive); }

static int variable(unsigned vr, ModelKind *kind, const char **name)
{
    CamKind k;
    if (!cam_instance_variable(vr, &k, name))
        return 0;
    *kind = k == CAM_KIND_REAL ? MODEL_REAL : k == CAM_KIND_BOOLEAN ? MODEL_BOOLEAN : MODEL_STRING;
    return 1;
}

static int get_real(void *m, unsigned vr, double *value)
{
    return status_of(cam_instance_get_real(((CamFmuModel *)m)->drive, vr, value));
}

static int check_real(void *m, unsigned vr, double value)
{
    return status_of(cam_instance_check_real(((CamFmuModel *)m)->drive, vr, value));
}

static int set_real(void *m, unsigned vr, double value)
{
    return status_of(cam_instance_set_real(((CamFmuModel *)m)->drive, vr, value));
}

static int get_boolean(void *m, unsigned vr, int *value)
{
    return status_of(cam_instance_get_boolean(((CamFmuModel *)m)->drive, vr, value));
}

static int set_boolean(void *m, unsigned vr, int value)
{
    return status_of(cam_instance_set_boolean(((CamFmuModel *)m)->drive, vr, value));
}

static int get_string(void *m, unsigned vr, const char **value)
{
    return status_of(cam_instance_get_string(((CamFmuModel *)m)->drive, vr, value));
}

static int set_string(void *m, unsigned vr, const char *value, size_t len)
{
    return status_of(cam_instance_set_string(((CamFmuModel *)m)->drive, vr, value, len));
}

static int initialize(void *m, double start_time)
{
    return status_of(cam_instance_initialize(((CamFmuModel *)m)->drive, start_time));
}

static int initialized(const void *m) { return cam_instance_initialized(((const CamFmuModel *)m)->drive); }

/* The drive's step itself (cam_drive.h), so fmi2DoStep -> glue_do_step -> step -> cam_drive_do_step: the glue's
 * state machine steps only an initialised instance (cam_instance_step is this, for C hosts without the glue). */
static int step(void *m, double t, double h)
{
    CamInstance *c = ((CamFmuModel *)m)->drive;
    const double *in = cam_instance_inputs(c);
    return status_of(cam_drive_do_step(cam_instance_drive(c), t, h, in[CAM_I_U], in[CAM_I_OMEGA_REF],
                                       in[CAM_I_OMEGA_DOT_REF], cam_instance_error(c)));
}

static double time_of(const void *m) { return cam_instance_time(((const CamFmuModel *)m)->drive); }

/* The last step's lift-offs and touch-downs of a free follower (follower.c), logged under logEvents. */
static const char *step_events(const void *m)
{
    CamDrive *d = cam_instance_drive(((const CamFmuModel *)m)->drive);
    return d ? d->step_events : NULL;
}

static size_t state_size(const void *m) { return cam_instance_state_size(((const CamFmuModel *)m)->drive); }

static int save(const void *m, unsigned char *buffer, size_t size)
{
    return status_of(cam_instance_save(((const CamFmuModel *)m)->drive, buffer, size));
}

static int restore(void *m, const unsigned char *buffer, size_t size)
{
    return status_of(cam_instance_restore(((CamFmuModel *)m)->drive, buffer, size));
}

/* ------------------------------------------------------------------ Model Exchange */

static int me_attach(void *m) { return status_of(cam_exchange_attach(&((CamFmuModel *)m)->me)); }

static int me_attached(const void *m) { return ((const CamFmuModel *)m)->me.drive != NULL; }

static void me_detach(void *m)
{
    CamFmuModel *c = m;
    cam_exchange_init(&c->me, c->drive);
}

static void me_sync(void *m) { cam_exchange_sync(&((CamFmuModel *)m)->me); }

static int me_set_time(void *m, double time) { return status_of(cam_exchange_set_time(&((CamFmuModel *)m)->me, time)); }

static int me_set_states(void *m, const double x[], size_t nx)
{
    return status_of(cam_exchange_set_states(&((CamFmuModel *)m)->me, x, nx));
}

static int me_read(void *m, ModelRead which, double values[], size_t n)
{
    CamExchange *e = &((CamFmuModel *)m)->me;
    switch (which) {
    case MODEL_READ_STATES: return status_of(cam_exchange_get_states(e, values, n));
    case MODEL_READ_DERIVATIVES: return status_of(cam_exchange_derivatives(e, values, n));
    case MODEL_READ_INDICATORS: return status_of(cam_exchange_indicators(e, values, n));
    default: return status_of(cam_exchange_nominals(e, values, n));
    }
}

static void me_enter_event_mode(void *m) { cam_exchange_enter_event_mode(&((CamFmuModel *)m)->me); }

static int me_event_update(void *m, int *values_changed, int *needed, char *log, size_t log_len)
{
    CamExchangeEvent fired;
    int status = cam_exchange_event_update(&((CamFmuModel *)m)->me, &fired, values_changed, needed);
    log[0] = '\0';
    if (status == CAM_OK && fired.note != NULL && fired.note[0] != '\0')
        snprintf(log, log_len, "%s", fired.note);   /* a follower of its own, as co-simulation logs it */
    else if (status == CAM_OK && fired.code >= 0 && fired.note == NULL)
        snprintf(log, log_len, "t = %.17g s: event '%s' at theta = %.17g rad, omega %.17g -> %.17g rad/s",
                 fired.time, cam_exchange_event_name(fired.code), fired.x_before[CAM_THETA],
                 fired.x_before[CAM_OMEGA], fired.x_after[CAM_OMEGA]);
    return status_of(status);
}

static void me_enter_continuous(void *m) { cam_exchange_enter_continuous(&((CamFmuModel *)m)->me); }

static int me_completed_step(void *m, int *enter_event)
{
    CamExchange *e = &((CamFmuModel *)m)->me;
    int status = status_of(cam_exchange_completed_step(e, enter_event));
    return status == MODEL_OK && e->warning ? MODEL_WARNING : status;
}

static int me_save(void *m, unsigned char *buffer, size_t size)
{
    return status_of(cam_exchange_save(&((CamFmuModel *)m)->me, buffer, size));
}

static int me_directional(void *m, const unsigned unknown[], size_t n_unknown, const unsigned known[], size_t n_known,
                          const double dv_known[], double dv_unknown[])
{
    return status_of(cam_exchange_directional(&((CamFmuModel *)m)->me, unknown, n_unknown, known, n_known, dv_known,
                                              dv_unknown));
}

static const ModelExchangeOps EXCHANGE = {
    me_attach, me_attached, me_detach, me_sync, me_set_time, me_set_states, me_read, me_enter_event_mode,
    me_event_update, me_enter_continuous, me_completed_step, me_save, CAM_ME_NX, CAM_EXCHANGE_NZ, me_directional,
};

static const Model CAM = {
    "cam", 0x43414d53u /* 'CAMS' */, CAM_VR_END, CAM_VR_STATES,
    create, destroy, reset, message, variable, get_real, check_real, set_real, get_boolean, set_boolean,
    get_string, set_string, initialize, initialized, step, time_of, state_size, save, restore, &EXCHANGE,
    step_events,
};

const Model *model_table(void) { return &CAM; }
