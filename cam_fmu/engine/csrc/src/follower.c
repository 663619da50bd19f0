/* The follower as a body of its own, what both drives share (docs/model.md 13, 16.3): its closing force, the
 * translating roller's guide friction at no contact force, the spring's stiffness, a groove's clearance and the
 * length of one unit of the follower's coordinate along its path (cam_model.h), and the step's event log line. The
 * follower's motion is voltage_follower.c's (the voltage drive) and speed_follower.c's (the speed drive), in the
 * one hybrid driver (integrate.c). */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "cam_drive.h"

double cam_follower_closing(const CamModel *m, double q)
{
    if (m->arm)
        return m->arm_length * (m->F_spring0 + m->k_spring * m->arm_length * q) + cam_kind_slope(m, q);
    return m->F_spring0 + m->k_spring * q - m->F_gx;
}

double cam_follower_friction0(const CamModel *m)
{
    return m->kind == CAM_CHOICE_FOLLOWER_TYPE_TRANSLATING_ROLLER ? m->mu * (fabs(m->G_y) + m->N_g) : 0.0;
}

double cam_follower_stiffness(const CamModel *m)
{
    return m->arm ? m->k_spring * m->arm_length * m->arm_length : m->k_spring;
}

double cam_follower_clearance(const CamModel *m)
{
    if (m->closure != CAM_CHOICE_CLOSURE_FORM)
        return 0.0;
    return m->arm ? m->c / m->arm_length : m->c;
}

double cam_follower_length(const CamModel *m)
{
    return m->arm ? m->arm_length : 1.0;
}

/* Append one event to the step's log line while it has room (40 bytes kept for "and <n> more"); else count it. */
void cam_follower_note(char *events, size_t len, long *dropped, const char *format, ...)
{
    size_t used = strlen(events);
    va_list args;
    if (*dropped > 0 || used + 160 > len) {
        *dropped += 1;
        return;
    }
    va_start(args, format);
    vsnprintf(events + used, len - used - 40, format, args);
    va_end(args);
}
