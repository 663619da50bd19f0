/* Accessors for bindings that hold the engine's structures as opaque memory (the ctypes binding). */
#include "cam_drive.h"

size_t cam_params_sizeof(void)
{
    return sizeof(CamParams);
}

size_t cam_drive_sizeof(void)
{
    return sizeof(CamDrive);
}

size_t cam_model_sizeof(void)
{
    return sizeof(CamModel);
}

double cam_drive_time(const CamDrive *d)
{
    return d->time;
}

long cam_drive_steps_taken(const CamDrive *d)
{
    return d->steps_taken;
}

long cam_drive_last_steps(const CamDrive *d)
{
    return d->last_steps;
}

int cam_drive_nx(const CamDrive *d)
{
    return d->model.nx;
}

double *cam_drive_values(CamDrive *d)
{
    return d->values;
}

const CamEventRecord *cam_drive_event(const CamDrive *d, long k)
{
    if (k < 0 || k >= d->events_logged || k < d->events_logged - CAM_EVENT_LOG)
        return NULL;
    return &d->event_log[k % CAM_EVENT_LOG];
}

long cam_drive_events_logged(const CamDrive *d)
{
    return d->events_logged;
}

size_t cam_event_record_sizeof(void)
{
    return sizeof(CamEventRecord);
}

size_t cam_state_len(void)
{
    return CAM_STATE_LEN;
}
