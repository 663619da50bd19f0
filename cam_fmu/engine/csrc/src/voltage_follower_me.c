/* The voltage drive's follower of its own in Model Exchange (cam_drive.h cam_vf_me_*; docs/model.md 13.6):
 * voltage_follower.c's rates, event functions and transitions (cam_voltage_follower.h), driven by a host's solver
 * through fmi/exchange.c. */
#include <math.h>
#include <string.h>

#include "cam_voltage_follower.h"

/* ------------------------------------------------------------------ Model Exchange (cam_drive.h cam_vf_me_*)
 * The same rates, event functions, impact law and rebound guard, driven by a host's solver (fmi/exchange.c). In
 * flight the follower's states are its gap g = left (s - s_flank) to the flank it left last and the gap's rate w:
 * both start at 0 at a lift-off (exactly: the event update sets them), so the host integrates the gap's t^3 opening
 * with its relative accuracy, not with theta's absolute error times s' (absolute s, v as states chattered between
 * lift-off and touch-down at 1e-11 m: docs/model.md 13.6). In contact both are 0 with derivative 0 and the follower
 * is on its flank. */

#define EV_TOUCH EV_TOUCH_UP    /* Model Exchange: the touch-down on the nearer flank (one indicator for both) */

typedef char cam_vf_me_event_slots[(int)CAM_VF_ME_EVENTS <= (int)CAM_MAX_EVENTS ? 1 : -1];
typedef char cam_vf_me_break_away_code[(int)CAM_VF_BREAK_AWAY == (int)EV_BREAK_AWAY ? 1 : -1];

/* y at Model Exchange's state x: the follower on its flank in contact, else at its gap from the flank left. */
static void me_load(const CamDrive *d, const double x[CAM_ME_NX], double y[NY])
{
    const CamModel *m = &d->model;
    double dd[4];
    int contact = (int)d->speed.contact, left = (int)d->speed.left;
    cam_vf_load_y(d, y);
    y[0] = x[CAM_THETA];
    y[1] = x[CAM_OMEGA];
    y[2] = x[CAM_CURRENT];
    y[Y_TWIST] = m->compliant ? x[CAM_TWIST] : 0.0;
    y[Y_ROTOR] = m->compliant ? x[CAM_OMEGA_M] : 0.0;
    cam_profile_eval(&m->profile, y[0], dd);
    if (contact) {
        y[3] = dd[0] - contact * cam_vf_clearance(m);
        y[4] = dd[1] * y[1];
    } else {
        y[3] = dd[0] - left * cam_vf_clearance(m) + left * x[CAM_ME_GAP];
        y[4] = dd[1] * y[1] + left * x[CAM_ME_RATE];
    }
    y[Y_SIGMA] = d->speed.sigma;
}

void cam_vf_me_states(const CamDrive *d, double x[CAM_ME_NX])
{
    const CamModel *m = &d->model;
    double dd[4];
    int left = (int)d->speed.left;
    memcpy(x, d->x, sizeof d->x);
    x[CAM_ME_GAP] = x[CAM_ME_RATE] = 0.0;
    if (d->speed.contact != 0.0)
        return;
    cam_profile_eval(&m->profile, d->x[CAM_THETA], dd);
    x[CAM_ME_GAP] = left * (d->speed.s - (dd[0] - left * cam_vf_clearance(m)));
    x[CAM_ME_RATE] = left * (d->speed.v - dd[1] * d->x[CAM_OMEGA]);
}

void cam_vf_set_me_states(CamDrive *d, const double x[CAM_ME_NX])
{
    double y[NY];
    memcpy(d->x, x, (size_t)d->model.slots * sizeof x[0]);
    me_load(d, x, y);
    d->speed.s = y[3];
    d->speed.v = y[4];
    d->speed.theta = y[0];
    d->speed.speed = y[1];
    d->stale = 1;
}

void cam_vf_me_rates(const CamDrive *d, const double x[CAM_ME_NX], double dx[CAM_ME_NX])
{
    double y[NY], dy[NY], dd[4];
    me_load(d, x, y);
    cam_vf_rates(&d->model, d->form_u, (int)d->speed.contact, y, dy);
    dx[CAM_THETA] = dy[0];
    dx[CAM_OMEGA] = dy[1];
    dx[CAM_CURRENT] = dy[2];
    dx[CAM_TWIST] = dy[Y_TWIST];
    dx[CAM_OMEGA_M] = dy[Y_ROTOR];
    dx[CAM_ME_GAP] = dx[CAM_ME_RATE] = 0.0;
    if (d->speed.contact != 0.0)
        return;
    cam_profile_eval(&d->model.profile, y[0], dd);   /* the follower's acceleration less the flank's */
    dx[CAM_ME_GAP] = x[CAM_ME_RATE];
    dx[CAM_ME_RATE] = d->speed.left * (dy[4] - (dd[2] * y[1] * y[1] + dd[1] * dy[1]));
}

int cam_vf_me_codes(const CamDrive *d, int codes[CAM_VF_ME_EVENTS])
{
    int n = 0, stuck = d->mode.stuck;
    codes[n++] = stuck ? EV_BREAK_AWAY : EV_STOP;   /* stuck: the input and the current may start it */
    if (d->speed.contact != 0.0) {
        if (!stuck)
            codes[n++] = EV_LIFT_OFF;
        return n;
    }
    codes[n++] = EV_TOUCH;
    if (d->speed.sigma != 0.0 && cam_vf_friction0(&d->model) > 0.0)
        codes[n++] = EV_HALT;
    return n;
}

double cam_vf_me_event(const CamDrive *d, int code, const double x[CAM_ME_NX])
{
    const CamModel *m = &d->model;
    double y[NY], g = x[CAM_ME_GAP];
    if (code == EV_TOUCH)   /* the flank left at g = 0, a groove's other at g = 2 c, each TOUCH inside */
        return (m->closure == CAM_CHOICE_CLOSURE_FORM ? fmin(g, 2.0 * cam_vf_clearance(m) - g) : g) + CAM_TOUCH;
    me_load(d, x, y);
    return cam_vf_event_value(m, d->form_u, code, (int)d->speed.contact, y);
}

int cam_vf_me_apply(CamDrive *d, int code, CamError *err)
{
    const CamModel *m = &d->model;
    double x[CAM_ME_NX], y[NY], u = d->form_u, rebound = d->speed.rebound;
    int contact = (int)d->speed.contact, left = (int)d->speed.left;
    long dropped = 0;
    d->step_events[0] = '\0';
    cam_vf_me_states(d, x);
    me_load(d, x, y);
    (void)err;
    if (code == EV_STOP || code == EV_BREAK_AWAY || (code == EV_NONE && y[1] == 0.0)) {
        int was = contact;   /* at rest: stuck with the follower on its flank (or flying), or moving off */
        cam_vf_at_rest(m, y, u, &contact, &left, code == EV_BREAK_AWAY);
        if (code != EV_NONE || y[Y_DIR] != 0.0)
            cam_follower_note(d->step_events, sizeof d->step_events, &dropped, y[Y_DIR] == 0.0 ? "shaft: stuck at "
                              "t = %.9g s (theta = %.6g rad); " : "shaft: moving at t = %.9g s (theta = %.6g rad); ",
                              d->time, y[0]);
        if (was && !contact)
            cam_follower_note(d->step_events, sizeof d->step_events, &dropped, "follower: lift-off from flank %+d "
                              "at t = %.9g s (theta = %.6g rad); ", was, d->time, y[0]);
    } else if (code == EV_HALT) {
        y[4] = 0.0;   /* the friction turns, or holds the follower (its direction below) */
    } else if (code == EV_TOUCH) {
        int flank = m->closure == CAM_CHOICE_CLOSURE_FORM && x[CAM_ME_GAP] > cam_vf_clearance(m) ? -left : left;
        contact = cam_vf_transition(d, y, u, flank > 0 ? EV_TOUCH_UP : EV_TOUCH_DOWN, contact, d->time, &rebound, &left,
                             &dropped);
    } else if (code == EV_LIFT_OFF) {
        contact = cam_vf_transition(d, y, u, code, contact, d->time, &rebound, &left, &dropped);
    } else if (contact && !(contact = cam_vf_settle_from(m, y, u, contact, &left))) {   /* a breakpoint's jump of s'' */
        cam_follower_note(d->step_events, sizeof d->step_events, &dropped, "follower: lift-off at t = %.9g s "
                          "(theta = %.6g rad); ", d->time, y[0]);
    }
    cam_vf_store_y(d, y);
    d->speed.contact = contact;
    d->speed.left = left;
    d->speed.sigma = contact ? 0.0 : cam_vf_flight_direction(m, y);
    d->speed.rebound = rebound;
    d->stale = 1;
    return CAM_OK;
}
