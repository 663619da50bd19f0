/* The voltage drive's follower of its own: its transitions (docs/model.md 13.6, 13.7) in the one event update
 * (cam_vf_event_update) that co-simulation's step (voltage_follower.c) and Model Exchange's (cam_vf_me_apply, below)
 * both call: the impact with restitution and the Zeno guard (land), the follower set on a flank or let go (settle),
 * a lift-off or touch-down (cam_vf_transition), the shaft at rest (cam_vf_at_rest); y to and from the drive's state;
 * and Model Exchange's view of that state (the formulation's hooks cam_vf_exchange). */
#include <math.h>
#include <string.h>

#include "cam_voltage_follower.h"

/* A stuck cam struck by the follower: its static friction, a finite force, gives no impulse; the cam moves off
 * where the impact turned it (omega != 0; on a dwell, s' = 0, it stays stuck). A turning cam the impact turns back
 * (a light cam, a heavy follower) moves on the new way: its shaft's friction turns with it (held the old way,
 * M_f sgn would feed the drive energy). */
static void unstick(double y[NY])
{
    if (y[1] != 0.0 && y[Y_DIR] != (y[1] > 0.0 ? 1.0 : -1.0))
        y[Y_DIR] = y[1] > 0.0 ? 1.0 : -1.0;
}

/* The impact of the follower on the flank `flank` at y (the cam's d = q at theta) with restitution e: y's follower
 * on the flank, omega and v after (follower.impact), the shaft's direction unstuck. */
static void impact(const CamModel *m, double y[NY], const double d[4], int flank, double e)
{
    double w = y[4] - d[1] * y[1], m_eff = m->I_f * m->J_0 / (m->J_0 + m->I_f * d[1] * d[1]), P;
    y[3] = d[0] - flank * cam_follower_clearance(m);
    P = -(1.0 + e) * m_eff * w;
    if (m->prescribed) {   /* the speed drive's cam (J_0 = inf): its speed is kept */
        y[4] -= (1.0 + e) * w;
    } else {
        y[4] += P / m->I_f;
        y[1] -= d[1] * P / m->J_0;
    }
    unstick(y);
}

/* A touch-down on the flank `flank` at y (voltage_follower.land): the contact after; y's follower on the flank,
 * omega and v after. */
static int land(const CamModel *m, double y[NY], double u, int flank, double *rebound)
{
    double d[4], before[NY], w, omega_dot, P, scale = cam_vf_acceleration_scale(m, y, u);
    memcpy(before, y, sizeof before);
    cam_kind_eval(m, y[0], d);
    impact(m, y, d, flank, m->restitution);
    w = y[4] - d[1] * y[1];
    if (w * w >= 2.0 * scale * (CAM_ZENO_HEIGHT / cam_follower_length(m))) {
        *rebound = w != 0.0 ? fabs(w) / (2.0 * cam_vf_acceleration_scale(m, y, u)) : 0.0;
        return 0;
    }
    memcpy(y, before, sizeof before);   /* plastic: the flank holds it where its force points away */
    impact(m, y, d, flank, 0.0);
    y[4] = d[1] * y[1];
    cam_vf_on_flank(m, y, u, flank, d, &omega_dot, &P, NULL);
    return flank * P >= 0.0 ? flank : 0;
}

/* On the flank `contact`: the follower set on it, or lifted off at once where contact P is already < 0 (a jump of
 * s''): the contact after; *left (left NULL: not kept) the flank it lets go of where it does. */
int cam_vf_settle(const CamModel *m, double y[NY], double u, int contact, int *left)
{
    double d[4], omega_dot, P;
    if (!contact)
        return 0;
    cam_vf_set_on_flank(m, y, contact);
    cam_vf_on_flank(m, y, u, contact, d, &omega_dot, &P, NULL);
    if (contact * P >= 0.0)
        return contact;
    if (left != NULL)
        *left = contact;
    return 0;
}

/* The lift-off or touch-down `code` from the contact `contact` at y at time [s] (a touch-down: the impact and the
 * rebound guard of land, *rebound its guard), for co-simulation's step and Model Exchange's event update alike: the
 * contact after, *left the flank the follower leaves (its gap's origin in Model Exchange); its line appended to
 * d->step_events. */
int cam_vf_transition(CamDrive *d, double y[NY], double u, int code, int contact, double time, double *rebound,
                      int *left, long *dropped)
{
    const CamModel *m = &d->model;
    double dd[4], w_before, w_after;
    int flank = code == EV_TOUCH_UP ? 1 : -1;
    if (code == EV_LIFT_OFF) {
        cam_vf_set_on_flank(m, y, contact);
        cam_follower_note(d->step_events, sizeof d->step_events, dropped, "follower: lift-off from flank %+d at "
                          "t = %.9g s (theta = %.6g rad); ", contact, time, y[0]);
        *left = contact;
        return 0;
    }
    cam_kind_eval(m, y[0], dd);
    w_before = y[4] - dd[1] * y[1];
    *rebound = 0.0;
    contact = land(m, y, u, flank, rebound);
    w_after = y[4] - dd[1] * y[1];
    d->speed.impacts += 1.0;
    if (!contact)
        *left = flank;
    cam_follower_note(d->step_events, sizeof d->step_events, dropped, "follower: touch-down on flank %+d at "
                      "t = %.9g s (theta = %.6g rad), relative speed %.6g m/s, after %.6g m/s; ", flank, time, y[0],
                      w_before, w_after);
    return contact;
}

/* At rest (omega = 0: the start, a new input, a stop, a located break-away): the shaft stays stuck, the follower at
 * rest on its flank, or starts toward where it accelerates (model.c cam_breakaway_direction's rule with the contact's
 * load; at a located break-away, where the margin is 0 to rounding, at once); *contact after, 0 where the flank lets
 * the follower go (the cam stuck, it flies alone and lands on the cam at rest). */
void cam_vf_at_rest(const CamModel *m, double y[NY], double u, int *contact, int *left, int at_threshold)
{
    double dir;
    y[1] = 0.0;
    y[Y_DIR] = m->prescribed ? cam_sign(u) : 0.0;   /* the speed drive: u turns it */
    *contact = cam_vf_settle(m, y, u, *contact, left);
    if (!m->prescribed && (cam_vf_breakaway(m, y, u, *contact, &dir) > 0.0 || at_threshold)) {
        y[Y_DIR] = dir;
        *contact = cam_vf_settle(m, y, u, *contact, left);
    }
}

/* The one event update of co-simulation and Model Exchange: the transition `code` at y at time [s] (*contact, *left,
 * *rebound before and after; its log line appended to d->step_events). EV_STOP, EV_BREAK_AWAY or EV_NONE at rest:
 * stuck, or moving off; a halt: v = 0; a lift-off or touch-down: cam_vf_transition; else (EV_BREAK, EV_NONE) the
 * contact settled: lifted at once where the flank would pull (a breakpoint's jump of s''). */
void cam_vf_event_update(CamDrive *d, double y[NY], double u, int code, int *contact, int *left, double *rebound,
                         double time, long *dropped)
{
    if (code == EV_STOP || code == EV_BREAK_AWAY || (code == EV_NONE && y[1] == 0.0)) {
        int was = *contact;
        cam_vf_at_rest(&d->model, y, u, contact, left, code == EV_BREAK_AWAY);
        if (code != EV_NONE || y[Y_DIR] != 0.0)
            cam_follower_note(d->step_events, sizeof d->step_events, dropped, y[Y_DIR] == 0.0 ? "shaft: stuck at "
                              "t = %.9g s (theta = %.6g rad); " : "shaft: moving at t = %.9g s (theta = %.6g rad); ",
                              time, y[0]);
        if (was && !*contact)
            cam_follower_note(d->step_events, sizeof d->step_events, dropped, "follower: lift-off from flank %+d "
                              "at t = %.9g s (theta = %.6g rad); ", was, time, y[0]);
    } else if (code == EV_HALT) {
        y[4] = 0.0;   /* the friction turns, or holds the follower (its direction at the next step) */
    } else if (code == EV_LIFT_OFF || code == EV_TOUCH_UP || code == EV_TOUCH_DOWN) {
        *contact = cam_vf_transition(d, y, u, code, *contact, time, rebound, left, dropped);
    } else if (*contact && !(*contact = cam_vf_settle(&d->model, y, u, *contact, left))) {
        cam_follower_note(d->step_events, sizeof d->step_events, dropped, "follower: lift-off at t = %.9g s "
                          "(theta = %.6g rad); ", time, y[0]);
    }
}

/* ------------------------------------------------------------------ Model Exchange (cam_vf_me_*)
 * The same rates, event functions and event update, driven by a host's solver (fmi/exchange.c). In flight the
 * follower's states are its gap g = left (s - s_flank) to the flank it left last and the gap's rate w: both start at
 * 0 at a lift-off (exactly: the event update sets them), so the host integrates the gap's t^3 opening with its
 * relative accuracy, not with theta's absolute error times s' (absolute s, v as states chattered between lift-off
 * and touch-down at 1e-11 m: docs/model.md 13.6). In contact both are 0 with derivative 0 and the follower is on its
 * flank. */

#define EV_TOUCH EV_TOUCH_UP    /* Model Exchange: the touch-down on the nearer flank (one indicator for both) */

typedef char cam_vf_me_event_slots[(int)CAM_VF_ME_EVENTS <= (int)CAM_MAX_EVENTS ? 1 : -1];

int cam_vf_me_codes(const CamDrive *d, int codes[CAM_VF_ME_EVENTS])
{
    int n = 0, stuck = d->mode.stuck;
    codes[n++] = stuck ? EV_BREAK_AWAY : EV_STOP;   /* stuck: the input and the current may start it */
    if (d->mode.contact != 0) {
        if (!stuck || d->model.train)   /* stuck, only a train's ringing changes the flank's force */
            codes[n++] = EV_LIFT_OFF;
        return n;
    }
    codes[n++] = EV_TOUCH;
    if ((d->mode.sigma != 0.0 || d->model.train) && cam_follower_friction0(&d->model) > 0.0)
        codes[n++] = EV_HALT;   /* held (sigma 0): released where a train's pull beats f0 */
    return n;
}

double cam_vf_me_event(const CamDrive *d, int code, const double x[CAM_ME_NX])
{
    const CamModel *m = &d->model;
    double g = x[CAM_GAP];
    if (code == EV_TOUCH)   /* the flank left at g = 0, a groove's other at g = 2 c, each TOUCH inside */
        return (m->closure == CAM_CHOICE_CLOSURE_FORM ? fmin(g, 2.0 * m->c - g) : g) + CAM_TOUCH;
    return cam_vf_value(m, &d->mode, code, x, d->form_u);
}

int cam_vf_me_apply(CamDrive *d, int code, CamError *err)
{
    const CamModel *m = &d->model;
    (void)err;
    d->step_events[0] = '\0';
    if (code == EV_TOUCH)   /* the nearer flank: a groove's other one past half its width */
        code = (m->closure == CAM_CHOICE_CLOSURE_FORM && d->x[CAM_GAP] > m->c ? -d->mode.left
                : d->mode.left) > 0 ? EV_TOUCH_UP : EV_TOUCH_DOWN;
    d->form->transition(d, code, d->time);
    d->stale = 1;
    return CAM_OK;
}

const CamExchangeHooks cam_vf_exchange = {cam_vf_me_codes, cam_vf_me_event, cam_vf_me_apply, cam_vf_me_tangent};
