/* The consistent formulation's discrete side: event indicators and the transitions at events and at
 * rest (physics/formulations/consistent.py: HybridDrive; docs/model.md sections 5-6), ported with the
 * order of floating-point operations kept. */
#include <math.h>

#include "cam_model.h"

int cam_event_codes(const CamModel *m, const CamMode *mode, int codes[CAM_MAX_EVENTS])
{
    int n = 0;
    if (m->follower_states)
        return cam_vf_codes(m, mode, codes);
    if (mode->stuck) {
        if (m->has_current || m->compliant || m->train)   /* the torque on the held cam changes: a current, a
                                                            * shaft, a train's ringing */
            codes[n++] = CAM_EV_BREAK_AWAY;
    } else if (m->backlash && mode->contact == 0) {
        codes[n++] = CAM_EV_STOP;
        codes[n++] = CAM_EV_ENGAGE_UP;
        codes[n++] = CAM_EV_ENGAGE_DOWN;
    } else {
        codes[n++] = CAM_EV_STOP;
        if (m->backlash)
            codes[n++] = CAM_EV_CONTACT;
        if (m->guide_side)
            codes[n++] = CAM_EV_SIDE_FORCE;
    }
    return n;
}

int cam_engaged_toward(const CamModel *m, const CamMode *mode, double theta, double direction)
{
    double d[4];
    if (mode->contact == 0)
        return 0;
    if (!m->backlash)
        return 1;
    cam_profile_eval(&m->profile, theta, d);
    return !(mode->contact * d[1] * direction < 0.0);
}

double cam_breakaway_margin(const CamModel *m, const CamMode *mode, double theta, double torque, double axial)
{
    double forward = cam_omega_dot(m, theta, 0.0, torque, 1.0, cam_engaged_toward(m, mode, theta, 1.0), 0.0, axial);
    double backward = -cam_omega_dot(m, theta, 0.0, torque, -1.0, cam_engaged_toward(m, mode, theta, -1.0), 0.0,
                                     axial);
    return backward > forward ? backward : forward;
}

double cam_event_value(const CamModel *m, const CamMode *mode, int code, const double x[CAM_NX], double u)
{
    double theta = x[CAM_THETA], omega = x[CAM_OMEGA], d[4];
    if (m->follower_states)
        return cam_vf_value(m, mode, code, x, u);
    if (code == CAM_EV_STOP)
        return omega * mode->direction;
    if (code == CAM_EV_SIDE_FORCE)
        return mode->side * cam_side_force(m, theta, omega, cam_drive_torque(m, x, omega, u), mode->direction,
                                           mode->side, cam_train_force_at(m, x, omega))
               + CAM_SIDE_HYSTERESIS;
    if (code == CAM_EV_BREAK_AWAY)
        return -cam_breakaway_margin(m, mode, theta, cam_drive_torque(m, x, 0.0, u), cam_train_force_at(m, x, 0.0));
    cam_profile_eval(&m->profile, theta, d);
    if (code == CAM_EV_ENGAGE_UP)
        return mode->s_free - (d[0] - m->c);
    if (code == CAM_EV_ENGAGE_DOWN)
        return (d[0] + m->c) - mode->s_free;
    /* CONTACT: s' times the direction held between events, not times omega: at a stop omega = 0
     * would zero both functions at once; the stop decides there. */
    return mode->contact * d[1] * mode->direction;
}

void cam_event_values(const CamModel *m, const CamMode *mode, int n, const int codes[], const double x[CAM_NX],
                      double u, double g[])
{
    int k;
    if (m->follower_states) {
        cam_vf_values(m, mode, n, codes, x, u, g);
        return;
    }
    for (k = 0; k < n; k++)
        g[k] = cam_event_value(m, mode, codes[k], x, u);
}

void cam_initial(const CamModel *m, double theta0, double omega0, double i0, double x[CAM_NX], CamMode *mode)
{
    x[CAM_THETA] = theta0;
    x[CAM_OMEGA] = omega0;
    x[CAM_CURRENT] = m->has_current ? i0 : 0.0;
    x[CAM_TWIST] = 0.0;   /* a compliant shaft starts relaxed, the rotor at the cam's speed */
    x[CAM_OMEGA_M] = m->compliant ? omega0 : 0.0;
    x[CAM_X_END] = x[CAM_V_END] = 0.0;
    x[CAM_GAP] = x[CAM_RATE] = 0.0;
    if (m->train) {   /* the end mass at rest relative to the follower, the spring at its static deflection */
        double d[4];
        cam_profile_eval(&m->profile, theta0, d);
        x[CAM_X_END] = d[0] + m->F_ex / m->k_train;
        x[CAM_V_END] = d[1] * omega0;
    }
    mode->stuck = omega0 == 0.0;
    mode->direction = omega0 >= 0.0 ? 1.0 : -1.0;
    mode->contact = CAM_ON_LOWER_FLANK;
    mode->s_free = 0.0;
    mode->side = 1.0;
    mode->left = CAM_ON_LOWER_FLANK;
    mode->sigma = 0.0;
    if (m->backlash) {   /* the paper's step 1: the follower starts where the cam is, centred in the gap */
        double d[4];
        cam_profile_eval(&m->profile, theta0, d);
        mode->contact = CAM_IN_FLIGHT;   /* free in the gap */
        mode->s_free = d[0];
    }
}

void cam_choose_side(const CamModel *m, CamMode *mode, const double x[CAM_NX], double u)
{
    if (m->guide_side && mode->contact != 0 && !mode->stuck) {
        double n_r = cam_side_force(m, x[CAM_THETA], x[CAM_OMEGA], cam_drive_torque(m, x, x[CAM_OMEGA], u),
                                    mode->direction, 0.0, cam_train_force_at(m, x, x[CAM_OMEGA]));
        if (fabs(n_r) > CAM_SIDE_HYSTERESIS)
            mode->side = n_r < 0.0 ? -1.0 : 1.0;
    }
}

/* At rest: stay stuck or start in the direction the torques allow (HybridDrive._settle_motion).
 * at_threshold: at a located break-away, where the margin is zero to rounding; the shaft then starts
 * toward the larger acceleration instead of waiting for the next communication step. */
static void settle_motion(const CamModel *m, CamMode *mode, double x[CAM_NX], double u, int at_threshold)
{
    double theta = x[CAM_THETA], torque = cam_drive_torque(m, x, x[CAM_OMEGA], u), direction, d[4];
    double axial = cam_train_force_at(m, x, 0.0);   /* N: the train's pull at rest (0 without one) */
    int forward_engaged, backward_engaged, leaves = 0;
    if (!mode->stuck) {
        if (x[CAM_OMEGA] != 0.0)
            return;
        /* at rest but marked as moving: it goes on unless it now accelerates backwards */
        if (mode->direction * cam_omega_dot(m, theta, 0.0, torque, mode->direction,
                                            cam_engaged_toward(m, mode, theta, mode->direction), 0.0, axial) >= 0.0)
            return;
        mode->stuck = 1;
    }
    /* each direction with the follower as it would be there: the break-away event's margin is the same
     * test, so a break-away it locates always starts the shaft (no event that fires without effect) */
    forward_engaged = cam_engaged_toward(m, mode, theta, 1.0);
    backward_engaged = cam_engaged_toward(m, mode, theta, -1.0);
    direction = cam_breakaway_direction(m, theta, torque, forward_engaged, backward_engaged, axial);
    if (direction == 0.0 && at_threshold) {
        double forward = cam_omega_dot(m, theta, 0.0, torque, 1.0, forward_engaged, 0.0, axial);
        double backward = -cam_omega_dot(m, theta, 0.0, torque, -1.0, backward_engaged, 0.0, axial);
        if (forward == backward && (m->has_current || m->compliant)) {
            /* a tie (no shaft friction, zero torque as the current or the twist passes through 0): the
             * shaft goes where the torque is heading */
            double rate = m->compliant ? x[CAM_OMEGA_M] : (u - m->R * x[CAM_CURRENT] - m->c_e * 0.0) / m->L;
            if (m->compliant && rate == 0.0)   /* the rotor at rest too: where its acceleration takes the twist */
                rate = cam_torque(m, 0.0, x[CAM_CURRENT], u) - torque;
            if (m->compliant && rate == 0.0 && m->has_current)   /* no torque yet: where the current heads */
                rate = (u - m->R * x[CAM_CURRENT] - m->c_e * 0.0) / m->L;
            direction = cam_sign(rate);
        } else {
            direction = forward >= backward ? 1.0 : -1.0;
        }
    }
    if (direction == 0.0)
        return;
    if (m->backlash && mode->contact != 0) {
        cam_profile_eval(&m->profile, theta, d);
        leaves = mode->contact * d[1] * direction < 0.0;   /* the cam would leave the follower */
        /* starting that way is consistent only if the shaft, rid of the follower, still accelerates
         * that way; else it stays at rest instead of chattering */
        if (leaves && direction * cam_omega_dot(m, theta, 0.0, torque, direction, 0, 0.0, 0.0) <= 0.0)
            return;
    }
    mode->stuck = 0;
    mode->direction = direction;
    if (leaves) {
        mode->s_free = d[0] - m->c * mode->contact;
        mode->contact = CAM_IN_FLIGHT;
    }
}

void cam_settle(const CamModel *m, CamMode *mode, double x[CAM_NX], double u, int at_threshold)
{
    settle_motion(m, mode, x, u, at_threshold);
    cam_choose_side(m, mode, x, u);
}

void cam_apply_event(const CamModel *m, CamMode *mode, double x[CAM_NX], int code, double u)
{
    double d[4];
    switch (code) {
    case CAM_EV_STOP:
        x[CAM_OMEGA] = 0.0;
        mode->stuck = 1;
        cam_settle(m, mode, x, u, 0);
        break;
    case CAM_EV_BREAK_AWAY:
        /* the located zero of the margin: the torque is at the threshold, so the shaft starts now */
        cam_settle(m, mode, x, u, 1);
        break;
    case CAM_EV_SIDE_FORCE:
        mode->side = -mode->side;   /* N_r passed through zero: the other friction branch */
        break;
    case CAM_EV_CONTACT:
        cam_profile_eval(&m->profile, x[CAM_THETA], d);
        mode->s_free = d[0] - m->c * mode->contact;
        mode->contact = CAM_IN_FLIGHT;
        break;
    default:   /* ENGAGE_UP, ENGAGE_DOWN: a plastic impact keeps the generalised momentum J_0 omega of the
                * cam side (a compliant shaft's rotor is not in the impact: the shaft's torque is finite) */
        mode->contact = code == CAM_EV_ENGAGE_UP ? CAM_ON_LOWER_FLANK : CAM_ON_UPPER_FLANK;
        cam_profile_eval(&m->profile, x[CAM_THETA], d);
        x[CAM_OMEGA] = m->J_0 * x[CAM_OMEGA] / (m->J_0 + m->m * d[1] * d[1]);
        cam_choose_side(m, mode, x, u);
        break;
    }
}
