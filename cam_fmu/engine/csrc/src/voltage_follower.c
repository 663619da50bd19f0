/* The follower as a body of its own on a voltage-driven cam, closures 'spring' and 'form' (a groove's flanks at
 * s_cam - c, contact +1, and s_cam + c, contact -1): the consistent formulation with a rigid shaft and no guide
 * friction (docs/model.md section 13.6; its check is the reference's physics/voltage_follower.py and
 * reference/voltage_flight.py, written independently). y = (theta, omega, i, s, v): theta, omega, i in d->x,
 * the follower's s, v, contact (+1, -1 on a flank, 0 in flight), touch-downs and the rebound guard in d->speed (saved
 * with the state). In contact J omega_dot = c_m i - M_f sgn(omega) - (m s'' omega^2 + F_close) s' with J = J_0 + m
 * s'^2 and the force P = m (s'' omega^2 + s' omega_dot) + F_close along X; lift-off where contact P reaches 0; in
 * flight J_0 omega_dot = c_m i - M_f sgn(omega) and m s_dd = -F_close(s); touch-down where a gap reaches -TOUCH,
 * an impact exchanging momentum with the shaft (J_0 omega + m s' v kept, w+ = -e w-) and the Zeno guard. Classic
 * Runge-Kutta steps of at most STEP_ANGLE of cam angle and STEP_PHASE of the flight's period; an event function
 * gone from > 0 to <= 0 over a step is located by bisection on the step's length. A shaft that stops is refused. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "cam_drive.h"

#define TOUCH 1e-12             /* m: a touch-down is located this far inside the flank (reference/flight.py) */
#define ZENO_HEIGHT 1e-9        /* m: a rebound rising less ends in contact (physics/speed_follower.py) */
#define STEP_ANGLE 1e-4         /* rad: cam angle of one Runge-Kutta step */
#define STEP_PHASE 4e-4         /* rad: phase of the flight's oscillation sqrt(k/m) t in one step */
#define MAX_EVENTS 100000       /* transitions in one step before the step is refused */
#define MAX_STEPS 10000000 /* Runge-Kutta steps in one step before the step is refused (never a hang) */
#define NY 5

enum { EV_NONE = 0, EV_STOP, EV_LIFT_OFF, EV_TOUCH_UP, EV_TOUCH_DOWN };   /* touch-down on flank +1, -1 */

static double sgn(double x)
{
    return x > 0.0 ? 1.0 : (x < 0.0 ? -1.0 : 0.0);
}

/* N m: the motor's torque (the state's current with L > 0, else quasi-static) less the shaft's friction. */
static double torque(const CamModel *m, const double y[NY], double u)
{
    double drive = m->has_current ? m->c_m * y[2] : m->c_m * (u - m->c_e * y[1]) / m->R;
    return drive - m->M_f * sgn(y[1]);
}

static double closing(const CamModel *m, double s)
{
    return m->F_spring0 + m->k_spring * s - m->F_gx;
}

/* m: the clearance of a groove (closure 'form'), 0 for a spring's one flank. */
static double clearance(const CamModel *m)
{
    return m->closure == CAM_CHOICE_CLOSURE_FORM ? m->c : 0.0;
}

/* On the flank `contact` at y: d = (s_cam, s', s'', s'''), omega_dot [rad/s2] and the force P [N] along X of the
 * coupled equations. */
static void on_flank(const CamModel *m, const double y[NY], double u, int contact, double d[4], double *omega_dot,
                     double *P)
{
    double omega = y[1], F;
    cam_profile_eval(&m->profile, y[0], d);
    F = closing(m, d[0] - contact * clearance(m));
    *omega_dot = (torque(m, y, u) - (m->m * d[2] * omega * omega + F) * d[1]) / (m->J_0 + m->m * d[1] * d[1]);
    *P = m->m * (d[2] * omega * omega + d[1] * *omega_dot) + F;
}

static void rates(const CamModel *m, double u, int contact, const double y[NY], double dy[NY])
{
    dy[0] = y[1];
    dy[2] = m->has_current ? (u - m->R * y[2] - m->c_e * y[1]) / m->L : 0.0;
    if (contact) {
        double d[4], P;
        on_flank(m, y, u, contact, d, &dy[1], &P);
        dy[3] = d[1] * y[1];
        dy[4] = d[2] * y[1] * y[1] + d[1] * dy[1];
        return;
    }
    dy[1] = torque(m, y, u) / m->J_0;
    dy[3] = y[4];
    dy[4] = -closing(m, y[3]) / m->m;
}

/* The follower set on the flank `contact` at y's angle, moving with it. */
static void set_on_flank(const CamModel *m, double y[NY], int contact)
{
    double d[4];
    cam_profile_eval(&m->profile, y[0], d);
    y[3] = d[0] - contact * clearance(m);
    y[4] = d[1] * y[1];
}

/* One classic Runge-Kutta step of h [s] from y into out. */
static void rk4(const CamModel *m, double u, int contact, const double y[NY], double h, double out[NY])
{
    double k1[NY], k2[NY], k3[NY], k4[NY], t[NY];
    int j;
    rates(m, u, contact, y, k1);
    for (j = 0; j < NY; j++)
        t[j] = y[j] + 0.5 * h * k1[j];
    rates(m, u, contact, t, k2);
    for (j = 0; j < NY; j++)
        t[j] = y[j] + 0.5 * h * k2[j];
    rates(m, u, contact, t, k3);
    for (j = 0; j < NY; j++)
        t[j] = y[j] + h * k3[j];
    rates(m, u, contact, t, k4);
    for (j = 0; j < NY; j++)
        out[j] = y[j] + h / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j]);
    if (contact)
        set_on_flank(m, out, contact);
}

/* The event function `code` at y on or off the flank `contact` (> 0: nothing happens). */
static double event_value(const CamModel *m, double u, int code, int contact, const double y[NY])
{
    double d[4], omega_dot, P;
    if (code == EV_STOP)
        return y[1];
    if (code == EV_LIFT_OFF) {
        on_flank(m, y, u, contact, d, &omega_dot, &P);
        return contact * P;
    }
    cam_profile_eval(&m->profile, y[0], d);
    return code == EV_TOUCH_UP ? y[3] - (d[0] - clearance(m)) + TOUCH : (d[0] + clearance(m)) - y[3] + TOUCH;
}

static int crossed(double before, double after)
{
    return (before > 0.0 && after <= 0.0) || (before == 0.0 && after < 0.0);
}

/* m/s2: a bound of the follower's acceleration relative to the flank near y (voltage_follower.acceleration_scale). */
static double acceleration_scale(const CamModel *m, const double y[NY], double u)
{
    double d[4];
    cam_profile_eval(&m->profile, y[0], d);
    return fabs(closing(m, d[0]) / m->m) + fabs(d[2]) * y[1] * y[1] + fabs(d[1] * torque(m, y, u) / m->J_0) + 1e-300;
}

/* The impact of the follower on the flank at y with restitution e: y's omega and v after (follower.impact). */
static void impact(const CamModel *m, double y[NY], double s1, double e)
{
    double w = y[4] - s1 * y[1], m_eff = m->m * m->J_0 / (m->J_0 + m->m * s1 * s1);
    double P = -(1.0 + e) * m_eff * w;
    y[4] += P / m->m;
    y[1] -= s1 * P / m->J_0;
}

/* A touch-down on the flank `flank` at y (voltage_follower.land): the contact after; y's follower on the flank,
 * omega and v after. */
static int land(const CamModel *m, double y[NY], double u, int flank, double *rebound)
{
    double d[4], before[NY], w, omega_dot, P, scale = acceleration_scale(m, y, u);
    memcpy(before, y, sizeof before);
    cam_profile_eval(&m->profile, y[0], d);
    y[3] = d[0] - flank * clearance(m);
    impact(m, y, d[1], m->restitution);
    w = y[4] - d[1] * y[1];
    if (w * w >= 2.0 * scale * ZENO_HEIGHT) {
        *rebound = w != 0.0 ? fabs(w) / (2.0 * acceleration_scale(m, y, u)) : 0.0;
        return 0;
    }
    memcpy(y, before, sizeof before);   /* plastic: the flank holds it where its force points away */
    y[3] = d[0] - flank * clearance(m);
    impact(m, y, d[1], 0.0);
    y[4] = d[1] * y[1];
    on_flank(m, y, u, flank, d, &omega_dot, &P);
    return flank * P >= 0.0 ? flank : 0;
}

static void load_y(const CamDrive *d, double y[NY])
{
    y[0] = d->x[CAM_THETA];
    y[1] = d->x[CAM_OMEGA];
    y[2] = d->x[CAM_CURRENT];
    y[3] = d->speed.s;
    y[4] = d->speed.v;
}

static void store_y(CamDrive *d, const double y[NY])
{
    d->x[CAM_THETA] = y[0];
    d->x[CAM_OMEGA] = y[1];
    d->x[CAM_CURRENT] = y[2];
    d->speed.s = y[3];
    d->speed.v = y[4];
    d->speed.theta = y[0];
    d->speed.speed = y[1];
}

/* On the flank `contact`: the follower set on it, or lifted off at once where contact P is already < 0 (a jump of
 * s''): the contact after. */
static int settle(const CamModel *m, double y[NY], double u, int contact)
{
    double d[4], omega_dot, P;
    if (!contact)
        return 0;
    set_on_flank(m, y, contact);
    on_flank(m, y, u, contact, d, &omega_dot, &P);
    return contact * P >= 0.0 ? contact : 0;
}

static int vf_init(CamDrive *d, CamError *err)
{
    const double *v = d->model.params.v;
    double y[NY], other[NY];
    int contact;
    (void)err;
    cam_initial(&d->model, v[CAM_P_THETA0], v[CAM_P_OMEGA0], v[CAM_P_I0], d->x, &d->mode);
    d->mode.contact = 1;   /* the kinematic backlash's mode is not this follower's (d->speed.contact is): held engaged */
    d->mode.s_free = 0.0;
    d->form_u = d->u;
    memset(&d->speed, 0, sizeof d->speed);
    d->speed.contact = 1.0;
    load_y(d, y);
    contact = settle(&d->model, y, d->u, 1);
    if (!contact && d->model.closure == CAM_CHOICE_CLOSURE_FORM) {   /* a groove: its other flank, if it holds */
        memcpy(other, y, sizeof other);
        if ((contact = settle(&d->model, other, d->u, -1)) != 0)
            memcpy(y, other, sizeof other);
    }
    d->speed.contact = contact;
    store_y(d, y);
    return CAM_OK;
}

static void vf_set_inputs(CamDrive *d, double u, double omega_ref, double omega_dot_ref)
{
    (void)omega_ref;
    (void)omega_dot_ref;
    d->form_u = u;
}

static int vf_advance(CamDrive *d, double h, double time, long *steps, CamError *err)
{
    const CamModel *m = &d->model;
    double y[NY], next[NY], trial[NY], u = d->form_u, tau = 0.0, rebound = d->speed.rebound;
    double wn = m->k_spring > 0.0 ? sqrt(m->k_spring / m->m) : 0.0;
    double pole = m->has_current ? m->R / m->L + sqrt(m->c_e * m->c_m / (m->J_0 * m->L)) : 0.0;
    int contact = (int)d->speed.contact, events = 0;
    long dropped = 0, taken = 0;
    d->step_events[0] = '\0';
    load_y(d, y);
    if (contact && !(contact = settle(m, y, u, contact)))
        cam_follower_note(d->step_events, sizeof d->step_events, &dropped, "follower: lift-off at t = %.9g s "
                          "(theta = %.6g rad); ", time, y[0]);
    while (tau < h) {
        int codes[3], n = 0, k, code = EV_NONE;
        double dt = h - tau, at = dt;
        if (y[1] != 0.0)
            dt = fmin(dt, STEP_ANGLE / fabs(y[1]));
        if (!contact && wn > 0.0)
            dt = fmin(dt, STEP_PHASE / wn);
        if (pole > 0.0)
            dt = fmin(dt, 0.5 / pole);
        if (rebound > 0.0)
            dt = fmin(dt, rebound);   /* a bounce lasts about 4 rebound: the first step cannot hold it */
        if (++taken > MAX_STEPS)
            return cam_error(err, CAM_ERR_SIMULATION, "more than %d Runge-Kutta steps in one step from t = %g s (at "
                             "t = %.9g s, step %g s, contact %d, rebound guard %g s): the step is refused", MAX_STEPS,
                             time, time + tau, dt, contact, rebound);
        rk4(m, u, contact, y, dt, next);
        codes[n++] = EV_STOP;
        if (contact)
            codes[n++] = EV_LIFT_OFF;
        else {
            codes[n++] = EV_TOUCH_UP;
            if (m->closure == CAM_CHOICE_CLOSURE_FORM)
                codes[n++] = EV_TOUCH_DOWN;
        }
        at = dt;
        for (k = 0; k < n; k++) {
            double lo = 0.0, hi = dt, before = event_value(m, u, codes[k], contact, y);
            if (!crossed(before, event_value(m, u, codes[k], contact, next)))
                continue;
            while (hi - lo > 0.0) {
                double mid = 0.5 * (lo + hi);
                if (mid <= lo || mid >= hi)
                    break;
                rk4(m, u, contact, y, mid, trial);
                if (crossed(before, event_value(m, u, codes[k], contact, trial)))
                    hi = mid;
                else
                    lo = mid;
            }
            if (hi < at || code == EV_NONE) {
                at = hi;
                code = codes[k];
            }
        }
        if (code == EV_NONE) {
            memcpy(y, next, sizeof y);
        } else if (at < dt) {
            rk4(m, u, contact, y, at, trial);
            memcpy(y, trial, sizeof y);
        } else {
            memcpy(y, next, sizeof y);
        }
        tau = code == EV_NONE ? tau + dt : tau + at;
        if (rebound > 0.0)
            rebound = fmax(rebound - (code == EV_NONE ? dt : at), 0.0);
        if (code == EV_NONE)
            continue;
        if (++events > MAX_EVENTS)
            return cam_error(err, CAM_ERR_SIMULATION, "the follower changed contact more than %d times in one step "
                             "from t = %g s: the step is refused", MAX_EVENTS, time);
        if (code == EV_STOP)
            return cam_error(err, CAM_ERR_SIMULATION, "the shaft stops at t = %.9g s: its static friction with a "
                             "spring-closed follower of its own is not modelled (docs/model.md 13.6)", time + tau);
        if (code == EV_LIFT_OFF) {
            set_on_flank(m, y, contact);
            cam_follower_note(d->step_events, sizeof d->step_events, &dropped, "follower: lift-off from flank %+d at "
                              "t = %.9g s (theta = %.6g rad); ", contact, time + tau, y[0]);
            contact = 0;
        } else {
            double dd[4], w_before, w_after;
            int flank = code == EV_TOUCH_UP ? 1 : -1;
            cam_profile_eval(&m->profile, y[0], dd);
            w_before = y[4] - dd[1] * y[1];
            rebound = 0.0;
            contact = land(m, y, u, flank, &rebound);
            w_after = y[4] - dd[1] * y[1];
            d->speed.impacts += 1.0;
            cam_follower_note(d->step_events, sizeof d->step_events, &dropped, "follower: touch-down on flank %+d at "
                              "t = %.9g s (theta = %.6g rad), relative speed %.6g m/s, after %.6g m/s; ", flank,
                              time + tau, y[0], w_before, w_after);
        }
    }
    if (dropped > 0 && sizeof d->step_events > strlen(d->step_events))
        snprintf(d->step_events + strlen(d->step_events), sizeof d->step_events - strlen(d->step_events),
                 "and %ld more", dropped);
    store_y(d, y);
    d->speed.contact = contact;
    d->speed.rebound = rebound;
    d->mode.direction = y[1] >= 0.0 ? 1.0 : -1.0;
    *steps = taken;
    return CAM_OK;
}

/* voltage_follower.outputs: the follower's own s, v, a; in flight M = M_f sgn(omega) and J = J_0. */
static void vf_outputs(CamDrive *d, double out[])
{
    const CamModel *m = &d->model;
    double y[NY], dd[4], omega_dot, P, i;
    CamLoad load;
    load_y(d, y);
    cam_profile_eval(&m->profile, y[0], dd);
    i = m->has_current ? y[2] : (d->form_u - m->c_e * y[1]) / m->R;
    load.alpha = atan(dd[1] / (m->r_b + dd[0]));
    load.s_cam = dd[0];
    load.f = 0.0;
    load.N = 0.0;   /* in flight */
    if (d->speed.contact != 0.0) {
        int contact = (int)d->speed.contact;
        double tan_a = dd[1] / (m->r_b + dd[0]);
        on_flank(m, y, d->form_u, contact, dd, &omega_dot, &P);
        load.M = m->M_f * sgn(y[1]) + P * dd[1];
        load.N = P * sqrt(1.0 + tan_a * tan_a);   /* P / cos(alpha), signed as contact */
        load.J = m->J_0 + m->m * dd[1] * dd[1];
        load.v = dd[1] * y[1];
        load.a = dd[2] * y[1] * y[1] + dd[1] * omega_dot;
        y[3] = dd[0] - contact * clearance(m);
    } else {
        load.M = m->M_f * sgn(y[1]);
        load.J = m->J_0;
        load.v = y[4];
        load.a = -closing(m, y[3]) / m->m;
    }
    cam_record_outputs(&load, y[1], y[0], y[3], i, d->form_u, out);
}

static void vf_advice(const CamDrive *d, char *buf, size_t len)
{
    (void)d;
    snprintf(buf, len, "Runge-Kutta steps of %g rad of cam angle (fixed): reduce the communication step", STEP_ANGLE);
}

const CamFormulation cam_voltage_follower = {
    "consistent", 1, vf_init, vf_set_inputs, vf_advance, vf_outputs, vf_advice,
};
