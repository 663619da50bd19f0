/* The speed drive (physics/formulations/speed.py; docs/model.md section 8): omega(t) is imposed, the
 * torque, current and voltage it needs are outputs. Over a communication step omega(t) = omega_ref +
 * omega_dot_ref (t - t_k), so a ramp of omega is exact; the play operator sees every breakpoint passed
 * (where the extrema of s_cam lie), not only the end point. At rest the follower lies on the cam at the
 * edge of the gap its weight pushes it to (physics.contact.rest_position), so the holding torque does
 * not vanish with a clearance. */
#include <float.h>
#include <math.h>

#include "cam_solver.h"

#define TWO_PI (2.0 * 3.141592653589793)

static double play(double s_cam, double s_prev, double c)
{
    if (s_cam > s_prev + c)
        return s_cam - c;
    if (s_cam < s_prev - c)
        return s_cam + c;
    return s_prev;
}

static double s_at(const CamProfile *p, double theta)
{
    double d[4];
    cam_profile_eval(p, theta, d);
    return d[0];
}

/* The play operator along start -> end, through every breakpoint passed, in order. */
static double play_along(const CamProfile *p, double s, double start, double end, double c)
{
    double at = start, next;
    for (;;) {
        next = cam_profile_first_breakpoint(p, at, end);
        if (next != next)
            break;
        s = play(s_at(p, next), s, c);
        at = next;
    }
    return play(s_at(p, end), s, c);
}

/* The follower's position [m] after the cam turns from start to end [rad] (contact.follower_along):
 * whole turns after the first change nothing. */
static double follower_along(const CamProfile *p, double s, double start, double end, double c)
{
    double turns, direction;
    if (c == 0.0)
        return s_at(p, end);
    turns = floor(fabs(end - start) / TWO_PI);
    if (turns >= 2.0) {
        direction = end > start ? 1.0 : -1.0;
        s = play_along(p, s, start, start + direction * TWO_PI, c);
        start = start + direction * TWO_PI * turns;
    }
    return play_along(p, s, start, end, c);
}

/* contact.speed_engaged: is the follower carried by the cam? */
static int engaged(const CamModel *m, double theta, double s, double omega, double omega_dot)
{
    double d[4], gap;
    if (m->c == 0.0)
        return 1;
    cam_profile_eval(&m->profile, theta, d);
    if (omega == 0.0 && m->F_gx != 0.0)
        return 1;
    gap = d[0] - s;
    return fabs(gap) >= m->c * (1.0 - 1e-9) && gap * d[1] * (omega != 0.0 ? omega : omega_dot) > 0.0;
}

/* contact.rest_position: on the cam at the edge the force along the stroke pushes the follower to. */
static double rest_position(const CamModel *m, double theta, double s)
{
    if (m->c == 0.0 || m->F_gx == 0.0)
        return s;
    return m->F_gx > 0.0 ? s_at(&m->profile, theta) + m->c : s_at(&m->profile, theta) - m->c;
}

static int speed_init(CamDrive *d, CamError *err)
{
    double x0[CAM_NX];   /* the model's start: the speed drive keeps only a train's end mass of it */
    (void)err;
    cam_initial(&d->model, d->model.params.v[CAM_P_THETA0], 0.0, 0.0, x0, &d->mode);   /* a valid mode in every saved state */
    d->speed.theta = d->model.params.v[CAM_P_THETA0];
    d->speed.speed = d->omega_ref;
    d->speed.s = s_at(&d->model.profile, d->speed.theta);
    d->speed.v = d->speed.contact = d->speed.impacts = d->speed.rebound = 0.0;
    d->speed.fresh = 1.0;
    if (d->model.train) {   /* the end mass at rest relative to the follower (its speed set with the inputs) */
        d->x[CAM_X_END] = x0[CAM_X_END];
        d->x[CAM_V_END] = 0.0;
    }
    return CAM_OK;
}

static void speed_set_inputs(CamDrive *d, double u, double omega_ref, double omega_dot_ref)
{
    (void)u;
    (void)omega_dot_ref;
    d->speed.speed = omega_ref;
    if (d->model.train && d->speed.fresh != 0.0) {   /* before the first step: v_e = v, the cam at omega_ref */
        double p[4];
        cam_profile_eval(&d->model.profile, d->speed.theta, p);
        d->x[CAM_V_END] = p[1] * omega_ref;
    }
    if (omega_ref == 0.0)   /* at rest from now: the follower lies where the force along the stroke pushes it (the
                               reference: after the output at a time where omega_ref is 0) */
        d->speed.s = rest_position(&d->model, d->speed.theta, d->speed.s);
}

static int speed_advance(CamDrive *d, double h, double time, long *steps, CamError *err)
{
    CamSpeedState *st = &d->speed;
    double end = st->theta + (d->omega_ref + 0.5 * d->omega_dot_ref * h) * h;
    d->step_events[0] = '\0';
    (void)time;
    if (d->model.train) {   /* the end mass under the step's motion (train.c), before the cam moves on */
        double h_next = d->solver.h_next > 0.0 ? d->solver.h_next : h;
        int status = cam_train_follow(&d->model, d->x, st->theta, d->omega_ref, d->omega_dot_ref, h, &h_next, steps,
                                      err);
        if (status != CAM_OK)
            return status;
        d->solver.h_next = h_next;
        st->fresh = 0.0;
    } else {
        *steps = 1;
    }
    st->speed = d->omega_ref + d->omega_dot_ref * h;
    st->s = follower_along(&d->model.profile, st->s, st->theta, end, d->model.c);
    st->theta = end;
    if (st->speed == 0.0 && d->omega_ref == 0.0)   /* a step at rest; one that stops the cam at its end still moves
                                                        there (the left limit), at rest from the next input on */
        st->s = rest_position(&d->model, st->theta, st->s);
    return CAM_OK;
}

/* The way the cam moves at the end of the step with the inputs held (the left limit, docs/model.md 8.1): sgn(omega),
 * and where omega ends at 0 the way the step started: a stop at the step's end still moves there. "At 0": within the
 * rounding of omega_ref + omega_dot_ref h and of the step's end time t [s] (a grid time k h is a few ulps off the
 * input's time stamp; the reference's Signal.left_value takes stamps within 1e-12 max(1, t) as t). */
double cam_motion_sign(double omega, double omega_ref, double omega_dot_ref, double t)
{
    double stop = 1e-12 * (t > 1.0 ? t : 1.0) * fabs(omega_dot_ref) + 4.0 * DBL_EPSILON * fabs(omega_ref);
    double x = fabs(omega) <= stop ? omega_ref : omega;
    return cam_sign(x);
}

/* speed.speed_drive_outputs: c_m i = J_0 omega_dot + M (J_0 = J_m + J_cam); the voltage adds L di/dt, di/dt = omega dM/dtheta
 * at constant speed (central difference, 1e-6 rad). */
static void speed_outputs(CamDrive *d, double out[])
{
    const CamModel *m = &d->model;
    const CamSpeedState *st = &d->speed;
    double omega = st->speed, omega_dot = d->omega_dot_ref, theta = st->theta, direction, i, voltage;
    CamLoad load, ahead, behind;
    int on;
    direction = cam_motion_sign(omega, d->omega_ref, omega_dot, fabs(d->time));
    double x_e = d->x[CAM_X_END], v_e = d->x[CAM_V_END], F = cam_train_force(m, theta, omega, x_e, v_e), a_e = 0.0;
    on = engaged(m, theta, st->s, direction, omega_dot);
    cam_load(m, theta, omega, omega_dot, direction, on, F, &load);
    i = (m->J_0 * omega_dot + load.M) / m->c_m;
    voltage = m->R * i + m->c_e * omega;
    if (m->train)
        a_e = (F + m->F_ex) / m->m_end;
    if (m->L > 0.0 && omega != 0.0) {   /* along the motion: the cam 1e-6 rad on at constant speed, the train's force
                                         * with the end mass and the speed over that time */
        double step = 1e-6, dt = step / omega, dM;
        cam_load(m, theta + step, omega, omega_dot, direction, on,
                 cam_train_force(m, theta + step, omega + omega_dot * dt, x_e + v_e * dt, v_e + a_e * dt), &ahead);
        cam_load(m, theta - step, omega, omega_dot, direction, on,
                 cam_train_force(m, theta - step, omega - omega_dot * dt, x_e - v_e * dt, v_e - a_e * dt), &behind);
        dM = (ahead.M - behind.M) / (2.0 * step);
        voltage += m->L * omega * dM / m->c_m;
    }
    cam_record_outputs(&load, omega, theta, st->s, i, voltage, out);   /* load.s_cam: s_cam at theta */
    cam_kind_outputs(m, theta, omega, out);
    if (m->train) {
        out[CAM_O_S_END] = x_e;
        out[CAM_O_V_END] = v_e;
        out[CAM_O_A_END] = a_e;
        out[CAM_O_F_TRAIN] = F;
    }
}

static void speed_advice(const CamDrive *d, char *buf, size_t len)
{
    (void)d;
    if (len > 0)
        buf[0] = '\0';   /* not energy-bounded: the guards that name an advice do not apply */
}

const CamFormulation cam_speed = {
    "speed", 0, speed_init, speed_set_inputs, speed_advance, speed_outputs, speed_advice, NULL, NULL,
    NULL,
};
