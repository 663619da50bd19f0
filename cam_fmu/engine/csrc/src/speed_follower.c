/* The speed drive's follower of its own (docs/model.md 13, 16.3): the voltage drive's follower (voltage_follower.c,
 * its equations, events and transitions) under the imposed motion omega(t) = omega_ref + omega_dot_ref (t - t_k)
 * (m->prescribed: the cam's J_0 is infinite, an impact keeps its speed; the rates' input u is omega_dot_ref), in the
 * one hybrid driver (integrate.c) with any solver and its settings, the cam's motion set exactly after each step. A step of omega_ref at a
 * communication point moves the flank, not the follower (speed_step); the outputs add the current and the voltage
 * that impose the motion. Its check is the reference's physics/speed_follower.py and reference/flight.py. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "cam_solver.h"
#include "cam_voltage_follower.h"

/* The step of omega to the input omega_ref at the step's start (physics.speed_follower.speed_step): the flank's
 * speed jumps, the follower's does not; a flank now moving away lets it fly on, one moving into it strikes it;
 * below the Zeno guard's relative speed it stays on; in flight its gap's rate is taken from the new flank's. */
static void speed_step(CamDrive *d, double time)
{
    const CamModel *m = &d->model;
    double y[NY], q[4], w, omega = d->omega_ref, u = d->omega_dot_ref, rebound = 0.0;
    int contact = d->mode.contact, left = d->mode.left;
    long dropped = 0;
    cam_vf_y(m, &d->mode, d->x, y);   /* the follower's own s, v at the old speed */
    if (omega == y[1])
        return;
    d->solver.k1_valid = 0;   /* f at the step's start moved with the speed */
    y[1] = omega;
    y[Y_DIR] = omega != 0.0 ? cam_sign(omega) : cam_sign(u);
    if (contact) {
        cam_kind_eval(m, y[0], q);
        w = y[4] - q[1] * omega;
        if (w * w < 2.0 * cam_vf_acceleration_scale(m, y, u) * (CAM_ZENO_HEIGHT / cam_follower_length(m)))
            y[4] = q[1] * omega;
        else if (contact * w > 0.0) {
            cam_follower_note(d->step_events, sizeof d->step_events, &dropped, "follower: lift-off from flank %+d at "
                              "t = %.9g s (theta = %.6g rad), the cam's speed stepped to %.6g rad/s; ", contact, time,
                              y[0], omega);
            left = contact;
            contact = 0;
        } else {
            contact = cam_vf_transition(d, y, u, contact > 0 ? EV_TOUCH_UP : EV_TOUCH_DOWN, contact, time, &rebound,
                                        &left, &dropped);
            d->speed.rebound = rebound > 0.0 ? time + rebound : 0.0;
        }
    }
    cam_vf_x(m, y, u, contact, contact != 0 ? contact : left, d->x, &d->mode);
}

void cam_impose_motion(const CamModel *m, const double x[CAM_NX], double u, double h, double x_new[CAM_NX])
{
    if (m->prescribed) {   /* theta, omega exact under every method (euler's theta would be off by u h^2 / 2) */
        x_new[CAM_THETA] = x[CAM_THETA] + (x[CAM_OMEGA] + 0.5 * u * h) * h;
        x_new[CAM_OMEGA] = x[CAM_OMEGA] + u * h;
    }
}

static int sf_init(CamDrive *d, CamError *err)
{
    const double *v = d->model.params.v;
    (void)err;
    cam_initial(&d->model, v[CAM_P_THETA0], d->omega_ref, 0.0, d->x, &d->mode);
    memset(&d->speed, 0, sizeof d->speed);
    d->speed.fresh = 1.0;
    d->form_u = d->omega_dot_ref;
    cam_vf_start(d, d->form_u);
    return CAM_OK;
}

/* The inputs before the first step set the start (the follower on the flank that holds it at that motion). */
static void sf_set_inputs(CamDrive *d, double u, double omega_ref, double omega_dot_ref)
{
    (void)u;
    if (d->speed.fresh == 0.0)
        return;
    d->x[CAM_OMEGA] = omega_ref;
    d->mode.stuck = omega_ref == 0.0;
    if (omega_ref != 0.0)
        d->mode.direction = cam_sign(omega_ref);
    d->form_u = omega_dot_ref;
    cam_vf_start(d, omega_dot_ref);
}

static int sf_advance(CamDrive *d, double h, double time, long *steps, CamError *err)
{
    d->step_events[0] = '\0';
    if (d->speed.fresh != 0.0)
        d->speed.fresh = 0.0;
    else
        speed_step(d, time);
    d->form_u = d->omega_dot_ref;
    return cam_integrate(d, h, time, steps, err);
}

/* speed.speed_drive_outputs with the follower's own motion: c_m i = J_0 omega_dot + M; the voltage adds L di/dt,
 * di/dt = omega dM/dtheta along the flank (central difference, 1e-6 rad). */
static void sf_outputs(CamDrive *d, double out[])
{
    const CamModel *m = &d->model;
    double y[NY], omega_dot = d->form_u, i, step = 1e-6;
    cam_vf_outputs(d, out);   /* (in the left limit's direction of motion) */
    i = (m->J_0 * omega_dot + out[CAM_O_M]) / m->c_m;
    out[CAM_O_I] = i;
    out[CAM_O_VOLTAGE] = m->R * i + m->c_e * out[CAM_O_OMEGA];
    if (d->mode.contact != 0 && m->L > 0.0 && out[CAM_O_OMEGA] != 0.0) {
        double ahead, behind;
        cam_vf_y(m, &d->mode, d->x, y);
        y[Y_DIR] = cam_sign(out[CAM_O_OMEGA]);
        y[0] += step;
        ahead = cam_vf_flank_torque(m, y, omega_dot, d->mode.contact);
        y[0] -= 2.0 * step;
        behind = cam_vf_flank_torque(m, y, omega_dot, d->mode.contact);
        out[CAM_O_VOLTAGE] += m->L * out[CAM_O_OMEGA] * ((ahead - behind) / (2.0 * step)) / m->c_m;
    }
}

static void sf_advice(const CamDrive *d, char *buf, size_t len)
{
    (void)d;
    snprintf(buf, len, "tighten rtol and atol, or lower h_max");
}

const CamFormulation cam_speed_follower = {
    "speed", 0, sf_init, sf_set_inputs, sf_advance, sf_outputs, sf_advice, NULL, cam_vf_apply, cam_vf_step_limit,
};
