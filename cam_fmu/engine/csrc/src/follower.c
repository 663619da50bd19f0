/* The follower as a body of its own on a cam at imposed speed (docs/model.md section 13; its check is the
 * reference's physics/speed_follower.py and reference/flight.py, which integrate the flight numerically where
 * this file takes its closed form). Closures 'spring' (one flank, a return spring) and 'form' (a groove with
 * clearance c): in contact the follower rides its flank; lift-off where the flank's force reaches 0; in flight
 * m s'' = -(F_spring0 + k_spring s) + F_gx - sgn(v) f0; touch-down where a gap reaches -CAM_TOUCH, an impact with
 * restitution, and the Zeno guard. Events are found by sampling each step (at most SCAN_ANGLE of cam angle and
 * a twentieth of the flight's period apart, finer just after a rebound) and located by the engine's one locator
 * (integrate.c cam_locate_first_event). The output
 * N_contact is the flank's force along X (with the guide friction) over cos(alpha), signed: > 0 on the +1 flank,
 * < 0 on a groove's -1 flank, 0 in flight (docs/model.md 13.1). */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "cam_drive.h"

#define SCAN_ANGLE 1e-3         /* rad: cam angle between two samples of an event function */
#define MAX_EVENTS 100000       /* transitions in one step before the step is refused */

typedef struct {
    const CamModel *m;
    double theta0, omega0, omega_dot;   /* theta(tau) = theta0 + (omega0 + omega_dot tau / 2) tau */
    double f0;                          /* N: guide friction at zero contact force */
    double c;                           /* m: the clearance (0 for a spring) */
    int two_sided;                      /* a groove: the -1 flank exists */
} Motion;

typedef struct {
    double tau0, s0, v0, sigma;         /* a piece of flight from tau0, the friction's direction -sigma */
} Piece;

typedef struct {                        /* an event function's arguments but its code and time (motion_event) */
    const Motion *mo;
    const Piece *p;
    double contact;
} Scan;

static double sgn(double x)
{
    return x > 0.0 ? 1.0 : (x < 0.0 ? -1.0 : 0.0);
}

static double theta_at(const Motion *mo, double tau)
{
    return mo->theta0 + (mo->omega0 + 0.5 * mo->omega_dot * tau) * tau;
}

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

/* The follower on the flank `contact`: d = (s, s', s'', s_cam). */
static void on_flank(const Motion *mo, double theta, double contact, double d[4])
{
    cam_kind_eval(mo->m, theta, d);
    d[3] = d[0];
    d[0] = d[3] - contact * mo->c;
}

/* > 0 while the flank `contact` holds the follower: contact (m a + F_close + sgn(v) f0). */
static double held(const Motion *mo, double theta, double omega, double omega_dot, double contact)
{
    const CamModel *m = mo->m;
    double d[4], v, friction;
    on_flank(mo, theta, contact, d);
    v = d[1] * omega;
    friction = v > 0.0 ? mo->f0 : (v < 0.0 ? -mo->f0 : 0.0);
    return contact * (m->I_f * (d[2] * omega * omega + d[1] * omega_dot) + cam_follower_closing(m, d[0]) + friction);
}

/* m/s2 in flight with the friction's direction -sigma; sigma = 0 at a halt: 0 while static friction holds. */
static double free_acceleration(const Motion *mo, double s, double sigma)
{
    double net = -cam_follower_closing(mo->m, s);
    if (sigma == 0.0) {
        if (fabs(net) <= mo->f0)
            return 0.0;
        sigma = net > 0.0 ? 1.0 : -1.0;
    }
    return (net - sigma * mo->f0) / mo->m->I_f;
}

/* The closed-form flight (physics.follower.Flight) tau - tau0 after the piece's start. */
static void fly(const Motion *mo, const Piece *p, double tau, double *s, double *v)
{
    const CamModel *m = mo->m;
    double t = tau - p->tau0, force;
    if (p->sigma == 0.0) {   /* held by the guide's static friction */
        *s = p->s0;
        *v = 0.0;
        return;
    }
    force = -cam_follower_closing(m, 0.0) - p->sigma * mo->f0;   /* its constant part (an arm's weight: refused) */
    if (m->k_spring > 0.0) {
        double k = cam_follower_stiffness(m), wn = sqrt(k / m->I_f), s_eq = force / k, c = cos(wn * t);
        double sn = sin(wn * t);
        *s = s_eq + (p->s0 - s_eq) * c + p->v0 / wn * sn;
        *v = -(p->s0 - s_eq) * wn * sn + p->v0 * c;
    } else {
        double b = force / m->I_f;
        *s = p->s0 + p->v0 * t + 0.5 * b * t * t;
        *v = p->v0 + b * t;
    }
}

/* The event function `code` at tau (> 0: nothing happens). */
static double event_value(const Motion *mo, const Piece *p, double contact, int code, double tau)
{
    double theta = theta_at(mo, tau), d[4], s, v;
    if (code == EV_LIFT_OFF)
        return held(mo, theta, mo->omega0 + mo->omega_dot * tau, mo->omega_dot, contact);
    fly(mo, p, tau, &s, &v);
    if (code == EV_HALT)
        return p->sigma * v;
    cam_kind_eval(mo->m, theta, d);
    return code == EV_TOUCH_UP ? s - (d[0] - mo->c) + CAM_TOUCH / cam_follower_length(mo->m)
                               : (d[0] + mo->c) - s + CAM_TOUCH / cam_follower_length(mo->m);
}

/* m/s2: a bound of the follower's acceleration relative to the flank near theta (speed_follower.acceleration_scale). */
static double acceleration_scale(const Motion *mo, double theta, double omega, double omega_dot)
{
    double d[4];
    on_flank(mo, theta, 1.0, d);
    return fabs(free_acceleration(mo, d[0], 1.0)) + mo->f0 / mo->m->I_f + fabs(d[2]) * omega * omega
           + fabs(d[1] * omega_dot) + 1e-300;
}

/* A downward crossing of an event function (solve_ivp's direction -1): from >= 0 to <= 0. */
static int downward(double before, double after)
{
    return before >= 0.0 && after <= 0.0;
}

static double motion_event(void *ctx, int code, double tau)
{
    const Scan *scan = ctx;
    return event_value(scan->mo, scan->p, scan->contact, code, tau);
}

/* The first event in (tau, end]: its code (EV_NONE: none) and *at, located between samples. */
static int first_event(const Motion *mo, const Piece *p, double contact, double tau, double end, double rebound,
                       double *at)
{
    int codes[3], n = 0, k, found = EV_NONE;
    double spacing, a = tau, fa[3], fb[3], omega_max = fabs(mo->omega0) + fabs(mo->omega_dot) * (end - tau);
    Scan scan = {mo, p, contact};
    if (contact != 0.0)
        codes[n++] = EV_LIFT_OFF;
    else {
        codes[n++] = EV_TOUCH_UP;
        if (mo->two_sided)
            codes[n++] = EV_TOUCH_DOWN;
        if (mo->f0 > 0.0 && p->sigma != 0.0)
            codes[n++] = EV_HALT;
    }
    spacing = omega_max > 0.0 ? SCAN_ANGLE / omega_max : end - tau;
    if (contact == 0.0 && mo->m->k_spring > 0.0)
        spacing = fmin(spacing, 0.05 * sqrt(mo->m->I_f / cam_follower_stiffness(mo->m)));   /* a twentieth of the
                                                                                                 * flight's period */
    for (k = 0; k < n; k++)
        fa[k] = event_value(mo, p, contact, codes[k], a);
    while (a < end && found == EV_NONE) {
        double b = a + (rebound > 0.0 && a - tau < rebound ? fmin(spacing, rebound / 8.0) : spacing);
        if (b > end || end - b < 1e-3 * spacing)
            b = end;
        for (k = 0; k < n; k++)
            fb[k] = event_value(mo, p, contact, codes[k], b);
        k = cam_locate_first_event(n, codes, a, b, fa, fb, downward, motion_event, &scan, 0.0, at);
        found = k >= 0 ? codes[k] : EV_NONE;
        for (k = 0; k < n; k++)
            fa[k] = fb[k];
        a = b;
    }
    return found;
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

/* The contact the follower starts in at the inputs omega, omega_dot (reference/flight.py _start_contact). */
void cam_follower_start(const CamModel *m, CamSpeedState *st, double omega, double omega_dot)
{
    Motion mo = {m, st->theta, omega, omega_dot, cam_follower_friction0(m), cam_follower_clearance(m),
                 m->closure == CAM_CHOICE_CLOSURE_FORM};
    double d[4], side;
    st->contact = held(&mo, st->theta, omega, omega_dot, 1.0) >= 0.0 ? 1.0
                  : (mo.two_sided && held(&mo, st->theta, omega, omega_dot, -1.0) >= 0.0 ? -1.0 : 0.0);
    side = st->contact != 0.0 ? st->contact : 1.0;
    on_flank(&mo, st->theta, side, d);
    st->s = d[0];
    st->v = d[1] * omega;
}

/* An impact of the flank `flank` on the follower at theta (physics.speed_follower.land with J_0 = inf): the relative
 * speed w -> -e w; a rebound rising less than CAM_ZENO_HEIGHT is plastic and leaves the follower on the flank if it holds
 * it. Sets the contact, s, v and the rebound's time bound. */
static void strike(const Motion *mo, CamSpeedState *st, double flank, double theta, double omega, double omega_dot,
                   double time, char *events, size_t events_len, long *dropped)
{
    const CamModel *m = mo->m;
    double d[4], w, v_after, w_after, scale = acceleration_scale(mo, theta, omega, omega_dot);
    on_flank(mo, theta, flank, d);
    w = st->v - d[1] * omega;
    v_after = st->v - (1.0 + m->restitution) * w;   /* the impulse -(1 + e) m w over m */
    w_after = v_after - d[1] * omega;
    st->s = d[0];
    st->impacts += 1.0;
    if (w_after * w_after < 2.0 * scale * (CAM_ZENO_HEIGHT / cam_follower_length(m)))
        w_after = 0.0;   /* the Zeno guard: a plastic impact */
    cam_follower_note(events, events_len, dropped, "follower: touch-down on flank %+d at t = %.9g s (theta = %.6g rad), "
                      "relative speed %.6g m/s, after %.6g m/s; ", (int)flank, time, theta, w, w_after);
    if (w_after != 0.0) {
        st->contact = 0.0;
        st->v = v_after;
        st->rebound = fabs(w_after) / (2.0 * scale);
    } else {
        st->contact = held(mo, theta, omega, omega_dot, flank) >= 0.0 ? flank : 0.0;
        st->v = d[1] * omega;
        st->rebound = 0.0;
    }
}

/* A step of omega to omega0 at the step's start (docs/model.md 13.2, physics.speed_follower.speed_step): the flank's
 * speed jumps, the follower's does not. A flank now moving away from the follower lets it fly on with its speed; a
 * flank moving into it strikes it; below the Zeno guard's relative speed nothing happens. */
static void speed_step(const Motion *mo, CamSpeedState *st, double omega0, double omega_dot, double time,
                       char *events, size_t events_len, long *dropped)
{
    double d[4], w;
    on_flank(mo, st->theta, st->contact, d);
    w = st->v - d[1] * omega0;
    if (w * w < 2.0 * acceleration_scale(mo, st->theta, omega0, omega_dot) * (CAM_ZENO_HEIGHT / cam_follower_length(mo->m)))
        return;
    if (st->contact * w > 0.0) {
        cam_follower_note(events, events_len, dropped, "follower: lift-off from flank %+d at t = %.9g s (theta = %.6g "
                          "rad), the cam's speed stepped to %.6g rad/s; ", (int)st->contact, time, st->theta, omega0);
        st->contact = 0.0;
        st->rebound = 0.0;
    } else
        strike(mo, st, st->contact, st->theta, omega0, omega_dot, time, events, events_len, dropped);
}

/* The follower over a step of h [s] from st->theta at omega0 + omega_dot tau; st->theta is left unchanged
 * (the caller moves it). */
int cam_follower_advance(const CamModel *m, CamSpeedState *st, double omega0, double omega_dot, double h,
                         double time, char *events, size_t events_len, CamError *err)
{
    Motion mo = {m, st->theta, omega0, omega_dot, cam_follower_friction0(m), cam_follower_clearance(m),
                 m->closure == CAM_CHOICE_CLOSURE_FORM};
    double tau = 0.0, d[4];
    long count = 0, dropped = 0;
    Piece p = {0.0, st->s, st->v, 0.0};
    if (st->contact != 0.0)
        speed_step(&mo, st, omega0, omega_dot, time, events, events_len, &dropped);
    for (;;) {
        double at = h, theta, omega;
        int code;
        if (st->contact != 0.0 && held(&mo, theta_at(&mo, tau), omega0 + omega_dot * tau, omega_dot, st->contact) < 0.0)
            code = EV_LIFT_OFF, at = tau;   /* already pulling (s'' jumped at a breakpoint, or the input did) */
        else {
            if (st->contact == 0.0) {
                p.tau0 = tau;
                p.s0 = st->s;
                p.v0 = st->v;
                p.sigma = st->v != 0.0 ? sgn(st->v) : sgn(free_acceleration(&mo, st->s, 0.0));
            }
            code = first_event(&mo, &p, st->contact, tau, h, st->rebound, &at);
        }
        theta = theta_at(&mo, at);
        omega = omega0 + omega_dot * at;
        if (st->contact == 0.0) {
            fly(&mo, &p, at, &st->s, &st->v);
            st->rebound = st->rebound > at - tau ? st->rebound - (at - tau) : 0.0;
        } else {
            on_flank(&mo, theta, st->contact, d);
            st->s = d[0];
            st->v = d[1] * omega;
        }
        if (code == EV_NONE) {
            if (dropped > 0 && events_len > strlen(events))
                snprintf(events + strlen(events), events_len - strlen(events), "and %ld more", dropped);
            return CAM_OK;
        }
        if (++count > MAX_EVENTS)
            return cam_error(err, CAM_ERR_SIMULATION, "the follower: more than %d lift-offs and touch-downs in one "
                             "step of %g s (at theta = %g rad): refused, never a hang", MAX_EVENTS, h, theta);
        tau = at;
        if (code == EV_LIFT_OFF) {
            cam_follower_note(events, events_len, &dropped, "follower: lift-off from flank %+d at t = %.9g s (theta = %.6g rad); ",
                 (int)st->contact, time + at, theta);
            st->contact = 0.0;
            st->rebound = 0.0;
        } else if (code == EV_HALT)
            st->v = 0.0;
        else
            strike(&mo, st, code == EV_TOUCH_UP ? 1.0 : -1.0, theta, omega, omega_dot, time + at, events, events_len,
                   &dropped);
    }
}

/* N m: another type's load torque on the flank `contact` at theta (docs/model.md 16.3), its load into *load. */
static double kind_torque(const Motion *mo, double theta, double omega, double omega_dot, double contact,
                          double direction, CamLoad *load)
{
    const CamModel *m = mo->m;
    double q[4], P;
    on_flank(mo, theta, contact, q);
    P = m->I_f * (q[2] * omega * omega + q[1] * omega_dot) + cam_follower_closing(m, q[0]);
    q[0] = q[3];   /* the lever and the geometry at the cam's q */
    cam_kind_contact_load(m, q, P, direction, load);
    return load->M;
}

/* The speed drive's outputs for another type (docs/model.md 16.3): kind_torque on a flank, the follower's own q,
 * q_dot in the law's lift units, an arm's psi, psi_dot. */
static void kind_outputs(const Motion *mo, const CamSpeedState *st, double omega_dot, double direction, double out[])
{
    const CamModel *m = mo->m;
    double omega = st->speed, theta = st->theta, q[4], s_cam[4], i, voltage, a;
    CamLoad load, shifted;
    cam_kind_eval(m, theta, q);
    cam_profile_eval(&m->profile, theta, s_cam);
    load.alpha = load.f = load.N = 0.0;
    load.M = m->M_f * direction;
    load.J = m->J_0;
    a = free_acceleration(mo, st->s, sgn(st->v));
    if (st->contact != 0.0) {
        double step = 1e-6, ahead, behind;
        kind_torque(mo, theta, omega, omega_dot, st->contact, direction, &load);
        a = q[2] * omega * omega + q[1] * omega_dot;
        ahead = kind_torque(mo, theta + step, omega, omega_dot, st->contact, direction, &shifted);
        behind = kind_torque(mo, theta - step, omega, omega_dot, st->contact, direction, &shifted);
        i = (m->J_0 * omega_dot + load.M) / m->c_m;
        voltage = m->R * i + m->c_e * omega;
        if (m->L > 0.0 && omega != 0.0)   /* the voltage's L di/dt = L omega dM/dtheta / c_m */
            voltage += m->L * omega * ((ahead - behind) / (2.0 * step)) / m->c_m;
    } else {
        i = (m->J_0 * omega_dot + load.M) / m->c_m;
        voltage = m->R * i + m->c_e * omega;
    }
    load.v = st->v / m->q_scale;
    load.a = a / m->q_scale;
    load.s_cam = s_cam[0];
    cam_record_outputs(&load, omega, theta, st->s / m->q_scale, i, voltage, out);
    if (m->arm) {
        out[CAM_O_PSI] = st->s;
        out[CAM_O_PSI_DOT] = st->v;
    }
}

/* physics.speed_follower.SpeedFollower.outputs: the speed drive's outputs with the follower's own s, v, a. */
void cam_follower_outputs(const CamModel *m, const CamSpeedState *st, double omega_dot, double direction, double out[])
{
    Motion mo = {m, st->theta, st->speed, omega_dot, cam_follower_friction0(m), cam_follower_clearance(m),
                 m->closure == CAM_CHOICE_CLOSURE_FORM};
    double omega = st->speed, theta = st->theta, d[4], tan_a, shaft, i, voltage, s = st->s, v = st->v, a;
    double M, J, N = 0.0;
    CamLoad load;
    if (m->kind != CAM_CHOICE_FOLLOWER_TYPE_TRANSLATING_ROLLER) {
        kind_outputs(&mo, st, omega_dot, direction, out);
        return;
    }
    cam_kind_eval(m, theta, d);
    tan_a = d[1] / (m->r_b + d[0]);
    shaft = m->M_f * direction;
    if (st->contact != 0.0) {
        int k;
        double Ms[3], step = 1e-6;
        for (k = 0; k < 3; k++) {   /* at theta, theta + step and theta - step: the voltage's dM/dtheta */
            double angle = theta + (k == 0 ? 0.0 : (k == 1 ? step : -step)), e[4], push, t_a, sigma, f;
            on_flank(&mo, angle, st->contact, e);
            push = m->m * (e[2] * omega * omega + e[1] * omega_dot) + cam_follower_closing(m, e[0]);
            t_a = e[1] / (m->r_b + e[3]);
            sigma = sgn(e[1] * direction);
            f = cam_guide_friction(push * t_a + m->G_y, t_a, sigma, m->mu, m->N_g, 0.0);
            Ms[k] = shaft + (push + sigma * f) * e[1];
            if (k == 0)   /* the force along X over cos(alpha): > 0 on the +1 flank, < 0 on a groove's -1 flank */
                N = cam_normal_force(push + sigma * f, t_a);
        }
        M = Ms[0];
        J = m->J_0 + m->m * d[1] * d[1];
        s = d[0] - st->contact * m->c;
        v = d[1] * omega;
        a = d[2] * omega * omega + d[1] * omega_dot;
        i = (m->J_0 * omega_dot + M) / m->c_m;
        voltage = m->R * i + m->c_e * omega;
        if (m->L > 0.0 && omega != 0.0)
            voltage += m->L * omega * ((Ms[1] - Ms[2]) / (2.0 * step)) / m->c_m;
    } else {
        M = shaft;
        J = m->J_0;
        a = free_acceleration(&mo, s, sgn(v));
        i = (m->J_0 * omega_dot + M) / m->c_m;
        voltage = m->R * i + m->c_e * omega;
    }
    load.M = M;
    load.J = J;
    load.N = N;
    load.f = 0.0;
    load.v = v;
    load.a = a;
    load.alpha = atan(tan_a);
    load.s_cam = d[0];
    cam_record_outputs(&load, omega, theta, s, i, voltage, out);
}
