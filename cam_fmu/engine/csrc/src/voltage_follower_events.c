/* The voltage drive's follower of its own: its transitions (docs/model.md 13.6, 13.7), shared by co-simulation's
 * step (voltage_follower.c) and Model Exchange's event update (voltage_follower_me.c): the impact with restitution
 * and the Zeno guard (land), the follower set on a flank or let go (settle), a lift-off or touch-down
 * (cam_vf_transition), the shaft at rest (cam_vf_at_rest), and y to and from the drive's state. */
#include <math.h>
#include <string.h>

#include "cam_voltage_follower.h"

/* The impact of the follower on the flank at y with restitution e: y's omega and v after (follower.impact). */
static void impact(const CamModel *m, double y[NY], double s1, double e)
{
    double w = y[4] - s1 * y[1], m_eff = m->m * m->J_0 / (m->J_0 + m->m * s1 * s1);
    double P = -(1.0 + e) * m_eff * w;
    y[4] += P / m->m;
    y[1] -= s1 * P / m->J_0;
}

/* A stuck cam struck by the follower: its static friction, a finite force, gives no impulse; the cam moves off
 * where the impact turned it (omega != 0; on a dwell, s' = 0, it stays stuck). */
static void unstick(double y[NY])
{
    if (y[Y_DIR] == 0.0 && y[1] != 0.0)
        y[Y_DIR] = y[1] > 0.0 ? 1.0 : -1.0;
}

/* A touch-down on the flank `flank` at y (voltage_follower.land): the contact after; y's follower on the flank,
 * omega and v after. */
static int land(const CamModel *m, double y[NY], double u, int flank, double *rebound)
{
    double d[4], before[NY], w, omega_dot, P, scale = cam_vf_acceleration_scale(m, y, u);
    memcpy(before, y, sizeof before);
    cam_profile_eval(&m->profile, y[0], d);
    y[3] = d[0] - flank * cam_vf_clearance(m);
    impact(m, y, d[1], m->restitution);
    unstick(y);
    w = y[4] - d[1] * y[1];
    if (w * w >= 2.0 * scale * CAM_ZENO_HEIGHT) {
        *rebound = w != 0.0 ? fabs(w) / (2.0 * cam_vf_acceleration_scale(m, y, u)) : 0.0;
        return 0;
    }
    memcpy(y, before, sizeof before);   /* plastic: the flank holds it where its force points away */
    y[3] = d[0] - flank * cam_vf_clearance(m);
    impact(m, y, d[1], 0.0);
    unstick(y);
    y[4] = d[1] * y[1];
    cam_vf_on_flank(m, y, u, flank, d, &omega_dot, &P);
    return flank * P >= 0.0 ? flank : 0;
}

void cam_vf_load_y(const CamDrive *d, double y[NY])
{
    y[0] = d->x[CAM_THETA];
    y[1] = d->x[CAM_OMEGA];
    y[2] = d->x[CAM_CURRENT];
    y[3] = d->speed.s;
    y[4] = d->speed.v;
    y[Y_TWIST] = d->model.compliant ? d->x[CAM_TWIST] : 0.0;
    y[Y_ROTOR] = d->model.compliant ? d->x[CAM_OMEGA_M] : 0.0;
    y[Y_SIGMA] = cam_vf_flight_direction(&d->model, y);
    y[Y_DIR] = d->mode.stuck ? 0.0 : d->mode.direction;
}

void cam_vf_store_y(CamDrive *d, const double y[NY])
{
    d->x[CAM_THETA] = y[0];
    d->x[CAM_OMEGA] = y[1];
    d->x[CAM_CURRENT] = y[2];
    d->speed.s = y[3];
    d->speed.v = y[4];
    if (d->model.compliant) {
        d->x[CAM_TWIST] = y[Y_TWIST];
        d->x[CAM_OMEGA_M] = y[Y_ROTOR];
    }
    d->speed.theta = y[0];
    d->speed.speed = y[1];
    d->mode.stuck = y[Y_DIR] == 0.0;
    if (y[Y_DIR] != 0.0)
        d->mode.direction = y[Y_DIR];
}

/* On the flank `contact`: the follower set on it, or lifted off at once where contact P is already < 0 (a jump of
 * s''): the contact after. */
int cam_vf_settle(const CamModel *m, double y[NY], double u, int contact)
{
    double d[4], omega_dot, P;
    if (!contact)
        return 0;
    cam_vf_set_on_flank(m, y, contact);
    cam_vf_on_flank(m, y, u, contact, d, &omega_dot, &P);
    return contact * P >= 0.0 ? contact : 0;
}

/* settle, and *left the flank the follower lets go of where it does. */
int cam_vf_settle_from(const CamModel *m, double y[NY], double u, int contact, int *left)
{
    int after = cam_vf_settle(m, y, u, contact);
    if (contact && !after)
        *left = contact;
    return after;
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
    cam_profile_eval(&m->profile, y[0], dd);
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
    double dir, margin;
    y[1] = 0.0;
    y[Y_DIR] = 0.0;
    *contact = cam_vf_settle_from(m, y, u, *contact, left);
    margin = cam_vf_breakaway(m, y, u, *contact, &dir);
    if (margin > 0.0 || at_threshold) {
        y[Y_DIR] = dir;
        *contact = cam_vf_settle_from(m, y, u, *contact, left);
    }
}
