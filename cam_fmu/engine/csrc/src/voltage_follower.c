/* The follower as a body of its own on a voltage-driven cam, closures 'spring' and 'form' (a groove's flanks at
 * s_cam - c, contact +1, and s_cam + c, contact -1): the consistent formulation with guide friction and a rigid or
 * compliant shaft (docs/model.md section 13.6; its check is the reference's physics/voltage_follower.py and
 * reference/voltage_flight.py, written independently), inside the model contract: its gap and rate are x's last
 * slots, its contact, flank left and flying direction are CamMode's, and cam_rhs, cam_event_codes and
 * cam_event_value reach its rates and event functions here, so cam_integrate (integrate.c), the one hybrid driver,
 * runs it with every solver and its h_max, rtol and atol, its events on the one locator; its transitions are the
 * formulation's hook (vf_transition: cam_vf_event_update, the one event update of co-simulation and Model Exchange)
 * and its phases bound the step (vf_step_limit). The equations work on y = (theta, omega, i, s, v, phi, omega_m,
 * sigma, dir) (cam_vf_y, cam_vf_x). The cam side is driven by T = c_m i (rigid) or the shaft's
 * k phi + d (omega_m - omega), less M_f sgn(omega). In contact
 * J omega_dot = T - (m s'' omega^2 + F_close + sgn(v) f) s'
 * with J = J_0 + m s'^2, the guide friction f solved with omega_dot as model.c's load_terms does (section 4.4 with
 * F_close in gravity's place), and the force P = m (s'' omega^2 + s' omega_dot) + F_close + sgn(v) f along X;
 * lift-off where contact P reaches 0; in flight J_0 omega_dot = T and m s_dd = -F_close(s) - sigma f0 (f0 the
 * friction at no contact force; a halt where v reaches 0); touch-down where a gap reaches -CAM_TOUCH, an impact
 * exchanging momentum with the cam side (J_0 omega + m s' v kept, w+ = -e w-) and the Zeno guard. A step is at most
 * STEP_PHASE of the flight's oscillation and of the shaft's (TRAIN_PHASE, SHAFT_PHASE_RK45 under error control), a tenth of the
 * electrical time constant, FLIGHT_ANGLE of cam angle in flight. At rest (omega = 0: the start, a stop) the shaft is
 * stuck, the follower at rest on its flank, until the consistent formulation's break-away rule with the contact's
 * load starts it. A cam stuck with the follower off it: the follower flies alone and lands on the cam at rest
 * (voltage_follower_events.c unstick). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "cam_solver.h"
#include "cam_voltage_follower.h"

#define STEP_PHASE 4e-4         /* rad: phase of the flight's oscillation sqrt(k/m) t in one fixed step */
#define SHAFT_PHASE_RK45 0.03  /* rad: the shaft's phase in one rk45 step. Its error norm alone left M_shaft's damper
                                 * term 1.8e-8 of M_shaft off the reference (0.1: 2.2e-9; 0.03 and below: 2.1e-10, the
                                 * reference's own floor); STEP_PHASE there took 56x the steps for no gain (measured) */
#define TRAIN_PHASE 0.05        /* rad: the flying follower's phase on the train's spring in one step, and on its own
                                 * under error control (STEP_PHASE there cost spring_voltage 2.3x for the same 6e-12 rad) */
#define RELEASE_MARGIN 1e-9    /* N: a held follower leaves where the net force exceeds the guide's f0 by this */
#define POLE_STEP 0.1           /* a step at most this many electrical time constants (1 / pole) */
#define FLIGHT_ANGLE 1e-2       /* rad: cam angle of one adaptive step in flight (a gap's crossing and return unseen) */

/* N: the train's force F_train = k_train (s - x_e) + d_train (v - v_e) on its end mass, the follower at q, q_dot
 * (s = q / q_scale: an arm's train in the law's lift units); its reaction loads the follower (docs/model.md 14.6; 0
 * without a train). */
static double train_force(const CamModel *m, const double y[NY], double q, double q_dot)
{
    return m->train ? cam_train_pull(m, q / m->q_scale, q_dot / m->q_scale, y[Y_XE], y[Y_VE]) : 0.0;
}

/* N (an arm: N m): what closes the follower onto its +1 flank at q, q_dot: the return spring and gravity, and a
 * train's force along q. */
static double closing_at(const CamModel *m, const double y[NY], double q, double q_dot)
{
    return m->train ? cam_follower_closing(m, q) + train_force(m, y, q, q_dot) / m->q_scale
                    : cam_follower_closing(m, q);
}

/* A: the armature current, the state's with L > 0, else quasi-static at the rotor's speed. */
static double current(const CamModel *m, const double y[NY], double u)
{
    return m->has_current ? y[2] : (u - m->c_e * (m->compliant ? y[Y_ROTOR] : y[1])) / m->R;
}

/* N m: a compliant shaft's torque on the cam, k phi + d (omega_m - omega). */
static double shaft_torque(const CamModel *m, const double y[NY])
{
    return m->k_shaft * y[Y_TWIST] + m->d_shaft * (y[Y_ROTOR] - y[1]);
}

/* N m: what drives the cam side, the motor's torque (rigid) or the shaft's, less the shaft's friction against the
 * direction `dir`. */
double cam_vf_torque_toward(const CamModel *m, const double y[NY], double u, double dir)
{
    double drive = m->compliant ? shaft_torque(m, y)
                   : (m->has_current ? m->c_m * y[2] : m->c_m * (u - m->c_e * y[1]) / m->R);
    return drive - m->M_f * dir;
}

/* On the flank `contact` at y, the shaft moving toward `dir`: d = (s_cam, s', s'', s'''), omega_dot [rad/s2] and the
 * force P [N] along X of the coupled equations; with guide friction f = mu (|N_r| + |N_g|) solved with omega_dot
 * (model.c load_terms with F_close in gravity's place: N_r = n0 + sigma kappa f, kappa = (J_0 / J) tan(alpha)). */
static void flank_toward(const CamModel *m, const double y[NY], double u, int contact, double dir, double d[4],
                         double *omega_dot, double *P, double *n_r)
{
    double omega = y[1], F, J, inertial, x0, sigma = 0.0, tan_a, kappa = 0.0, n0 = 0.0, f = 0.0;
    int guided = m->mu != 0.0 && m->kind == CAM_CHOICE_FOLLOWER_TYPE_TRANSLATING_ROLLER;   /* the guide's friction */
    cam_kind_eval(m, y[0], d);
    F = closing_at(m, y, d[0] - contact * cam_follower_clearance(m), d[1] * omega);
    if (m->kind != CAM_CHOICE_FOLLOWER_TYPE_TRANSLATING_ROLLER && !m->prescribed) {   /* kind.c's, b = contact */
        CamKindBranch branch;
        *omega_dot = cam_kind_branch(m, d, omega, cam_vf_torque_toward(m, y, u, dir), dir, contact, F, &branch);
        *P = branch.P;
        *n_r = 0.0;   /* no side event: the friction's kink is the lift-off itself (docs/model.md 16.3) */
        return;
    }
    /* the translating roller, or any type under the speed drive's imposed omega_dot = u (J_0 = inf: kappa = tan(alpha);
     * another type's friction loads the cam there, not the follower) */
    J = m->J_0 + m->I_f * d[1] * d[1];
    inertial = m->I_f * d[2] * omega * omega + F;
    x0 = m->prescribed ? u : (cam_vf_torque_toward(m, y, u, dir) - inertial * d[1]) / J;
    if (guided) {
        sigma = cam_sign(d[1] * dir);
        tan_a = d[1] / (m->r_b + d[0]);
        kappa = m->prescribed ? tan_a : m->J_0 / J * tan_a;
        n0 = (inertial + m->I_f * d[1] * x0) * tan_a + m->G_y;
        f = cam_guide_friction(n0, kappa, sigma, m->mu, m->N_g, 0.0);
    }
    *omega_dot = m->prescribed ? u : x0 - sigma * f * d[1] / J;
    *P = m->I_f * (d[2] * omega * omega + d[1] * *omega_dot) + F + sigma * f;
    *n_r = guided ? n0 + sigma * kappa * f : 0.0;
}

/* flank_toward in the shaft's direction; the cam stuck: at rest, the contact's force P = F_close(s) balancing the
 * spring and gravity (the guide's friction at rest carries nothing), omega_dot = 0. */
void cam_vf_on_flank(const CamModel *m, const double y[NY], double u, int contact, double d[4], double *omega_dot,
                     double *P, double *n_r)
{
    double unused;
    if (n_r == NULL)
        n_r = &unused;
    if (y[Y_DIR] == 0.0) {
        cam_kind_eval(m, y[0], d);
        *P = closing_at(m, y, d[0] - contact * cam_follower_clearance(m), 0.0);
        *omega_dot = 0.0;
        *n_r = *P * d[1] / (m->r_b + d[0]) + m->G_y;
        return;
    }
    flank_toward(m, y, u, contact, y[Y_DIR], d, omega_dot, P, n_r);
}

/* rad/s2: > 0 where the stuck shaft starts (model.c cam_breakaway_margin with the follower's contact): the larger of
 * its acceleration forward and backward, each with the shaft's and the guide's friction against that direction. */
double cam_vf_breakaway(const CamModel *m, const double y[NY], double u, int contact, double *dir)
{
    double d[4], forward, backward, P, n_r;
    if (contact) {
        flank_toward(m, y, u, contact, 1.0, d, &forward, &P, &n_r);
        flank_toward(m, y, u, contact, -1.0, d, &backward, &P, &n_r);
    } else {
        forward = cam_vf_torque_toward(m, y, u, 1.0) / m->J_0;
        backward = cam_vf_torque_toward(m, y, u, -1.0) / m->J_0;
    }
    backward = -backward;
    *dir = forward >= backward ? 1.0 : -1.0;
    return fmax(forward, backward);
}

/* m/s2: the flying follower's acceleration at y, the guide's friction (where it acts in flight) against the
 * direction y[Y_SIGMA] (0: held by it). */
static double flight_acceleration(const CamModel *m, const double y[NY])
{
    double f0 = cam_follower_friction0(m);
    if (f0 == 0.0)
        return -closing_at(m, y, y[3], y[4]) / m->I_f;
    return y[Y_SIGMA] == 0.0 ? 0.0 : (-closing_at(m, y, y[3], y[4]) - y[Y_SIGMA] * f0) / m->I_f;
}

/* The flying follower's direction over the next step: sgn(v), or at a halt the way the net force pushes it beyond
 * the guide's static friction (0: held). */
double cam_vf_flight_direction(const CamModel *m, const double y[NY])
{
    double net;
    if (y[4] != 0.0)
        return cam_sign(y[4]);
    net = -closing_at(m, y, y[3], 0.0);
    return fabs(net) > cam_follower_friction0(m) ? cam_sign(net) : 0.0;
}

/* A train's end mass: its rates under the follower at s [m] moving at v [m/s] (held at 0 without a train). */
static void end_mass_rates(const CamModel *m, const double y[NY], double s, double v, double dy[NY])
{
    dy[Y_XE] = m->train ? y[Y_VE] : 0.0;
    dy[Y_VE] = m->train ? (train_force(m, y, s, v) + m->F_ex) / m->m_end : 0.0;
}

void cam_vf_rates(const CamModel *m, double u, int contact, const double y[NY], double dy[NY])
{
    double omega_m = m->compliant ? y[Y_ROTOR] : y[1], d[4];
    dy[0] = y[1];
    dy[2] = m->has_current && !m->prescribed ? (u - m->R * y[2] - m->c_e * omega_m) / m->L : 0.0;
    dy[Y_TWIST] = m->compliant ? omega_m - y[1] : 0.0;
    dy[Y_ROTOR] = m->compliant ? (m->c_m * current(m, y, u) - shaft_torque(m, y)) / m->J_m : 0.0;
    dy[Y_SIGMA] = 0.0;
    dy[Y_DIR] = 0.0;
    if (contact && y[Y_DIR] == 0.0) {   /* stuck: the cam and the follower on its flank at rest */
        dy[0] = dy[1] = dy[3] = dy[4] = 0.0;
        if (m->train) {
            cam_kind_eval(m, y[0], d);
            end_mass_rates(m, y, d[0] - contact * cam_follower_clearance(m), 0.0, dy);
        } else {
            dy[Y_XE] = dy[Y_VE] = 0.0;
        }
        return;
    }
    if (contact) {
        double P;
        cam_vf_on_flank(m, y, u, contact, d, &dy[1], &P, NULL);
        dy[3] = d[1] * y[1];
        dy[4] = d[2] * y[1] * y[1] + d[1] * dy[1];
        end_mass_rates(m, y, d[0] - contact * cam_follower_clearance(m), dy[3], dy);
        return;
    }
    /* the cam stuck: the follower flies alone */
    dy[1] = y[Y_DIR] == 0.0 ? 0.0 : (m->prescribed ? u : cam_vf_torque_toward(m, y, u, y[Y_DIR]) / m->J_0);
    dy[3] = y[4];
    dy[4] = flight_acceleration(m, y);
    end_mass_rates(m, y, y[3], y[4], dy);
}

/* The follower set on the flank `contact` at y's angle, moving with it. */
void cam_vf_set_on_flank(const CamModel *m, double y[NY], int contact)
{
    double d[4];
    cam_kind_eval(m, y[0], d);
    y[3] = d[0] - contact * cam_follower_clearance(m);
    y[4] = d[1] * y[1];
}

/* m/s2: a bound of the follower's acceleration relative to the flank near y (voltage_follower.acceleration_scale). */
double cam_vf_acceleration_scale(const CamModel *m, const double y[NY], double u)
{
    double d[4];
    cam_kind_eval(m, y[0], d);
    return fabs(closing_at(m, y, d[0], d[1] * y[1]) / m->I_f) + cam_follower_friction0(m) / m->I_f
           + fabs(d[2]) * y[1] * y[1]
           + fabs(d[1] * (m->prescribed ? u : cam_vf_torque_toward(m, y, u, y[Y_DIR]) / m->J_0)) + 1e-300;
}

/* ------------------------------------------------------------------ the model contract's view (x, mode)
 * The follower's slots of x are its gap g = left (s - s_flank(theta)) to the flank it left last and the gap's rate
 * w, both 0 (rate 0) on a flank: a lift-off starts them at 0 exactly, so a solver integrates the gap's opening with
 * its relative accuracy, not with theta's absolute error times s' (docs/model.md 13.6). The mode holds the contact
 * (+1, -1 on a flank, 0 off them), the flank left last, the flying direction sigma and the shaft's (stuck,
 * direction). */

void cam_vf_x(const CamModel *m, const double y[NY], double u, int contact, int left, double x[CAM_NX],
              CamMode *mode)
{
    double dd[4];
    x[CAM_THETA] = y[0];
    x[CAM_OMEGA] = y[1];
    x[CAM_CURRENT] = y[2];
    if (m->compliant) {
        x[CAM_TWIST] = y[Y_TWIST];
        x[CAM_OMEGA_M] = y[Y_ROTOR];
    }
    if (m->train) {
        x[CAM_X_END] = y[Y_XE];
        x[CAM_V_END] = y[Y_VE];
    }
    mode->stuck = y[Y_DIR] == 0.0;
    if (y[Y_DIR] != 0.0)
        mode->direction = y[Y_DIR];
    mode->contact = (CamFlank)contact;
    mode->left = (CamFlank)left;
    x[CAM_GAP] = x[CAM_RATE] = 0.0;
    mode->sigma = 0.0;
    mode->side = 0.0;
    if (contact) {   /* the side force's sign: the kink of |N_r| ends a step (docs/model.md 10) */
        double P, n_r, omega_dot;
        if (y[Y_DIR] != 0.0 && m->mu > 0.0 && !m->prescribed) {   /* imposed motion: P's kink changes nothing */
            cam_vf_on_flank(m, y, u, contact, dd, &omega_dot, &P, &n_r);
            mode->side = cam_sign(n_r);
        }
        return;
    }
    cam_kind_eval(m, y[0], dd);
    x[CAM_GAP] = left * (y[3] - (dd[0] - left * cam_follower_clearance(m))) * cam_follower_length(m);
    x[CAM_RATE] = left * (y[4] - dd[1] * y[1]) * cam_follower_length(m);
    mode->sigma = cam_vf_flight_direction(m, y);
}

/* cam_vf_y for the rates and the event functions: on a flank without s, v (0: they take them from the flank), in
 * flight with the profile at theta into dd. */
static void working_y(const CamModel *m, const CamMode *mode, const double x[CAM_NX], double y[NY], double dd[4])
{
    y[0] = x[CAM_THETA];
    y[1] = x[CAM_OMEGA];
    y[2] = x[CAM_CURRENT];
    y[Y_TWIST] = m->compliant ? x[CAM_TWIST] : 0.0;
    y[Y_ROTOR] = m->compliant ? x[CAM_OMEGA_M] : 0.0;
    y[Y_SIGMA] = mode->contact ? 0.0 : mode->sigma;
    y[Y_DIR] = mode->stuck ? 0.0 : mode->direction;
    y[Y_XE] = m->train ? x[CAM_X_END] : 0.0;
    y[Y_VE] = m->train ? x[CAM_V_END] : 0.0;
    y[3] = y[4] = 0.0;   /* on a flank the rates take s, v from the flank (cam_vf_y's; cam_vf_on_flank) */
    if (!mode->contact) {
        cam_kind_eval(m, y[0], dd);
        y[3] = dd[0] - mode->left * cam_follower_clearance(m) + mode->left * x[CAM_GAP] / cam_follower_length(m);
        y[4] = dd[1] * y[1] + mode->left * x[CAM_RATE] / cam_follower_length(m);
    }
}

void cam_vf_y(const CamModel *m, const CamMode *mode, const double x[CAM_NX], double y[NY])
{
    double dd[4];
    working_y(m, mode, x, y, dd);
    if (mode->contact)
        cam_vf_set_on_flank(m, y, mode->contact);
}

void cam_vf_rhs(const CamModel *m, const CamMode *mode, const double x[CAM_NX], double u, double dx[CAM_NX])
{
    double y[NY], dy[NY], dd[4];
    working_y(m, mode, x, y, dd);
    cam_vf_rates(m, u, mode->contact, y, dy);
    dx[CAM_THETA] = dy[0];
    dx[CAM_OMEGA] = dy[1];
    dx[CAM_CURRENT] = dy[2];
    dx[CAM_TWIST] = dy[Y_TWIST];
    dx[CAM_OMEGA_M] = dy[Y_ROTOR];
    dx[CAM_X_END] = dy[Y_XE];   /* a train's end mass (held at 0 without one) */
    dx[CAM_V_END] = dy[Y_VE];
    dx[CAM_GAP] = dx[CAM_RATE] = 0.0;
    if (mode->contact)
        return;
    dx[CAM_GAP] = x[CAM_RATE];   /* the follower's acceleration less the flank's */
    dx[CAM_RATE] = mode->left * (dy[4] - (dd[2] * y[1] * y[1] + dd[1] * dy[1])) * cam_follower_length(m);
}

int cam_vf_codes(const CamModel *m, const CamMode *mode, int codes[CAM_MAX_EVENTS])
{
    int n = 0;
    if (!m->prescribed)
        codes[n++] = mode->stuck ? EV_BREAK_AWAY : EV_STOP;   /* stuck: the torque on it may change */
    else if (!mode->stuck)
        codes[n++] = EV_STOP;   /* the imposed motion through omega = 0: its direction turns */
    if (mode->contact) {
        if (!mode->stuck || m->train)   /* stuck, only a train's ringing changes the flank's force */
            codes[n++] = EV_LIFT_OFF;
        if (!mode->stuck && mode->side != 0.0)
            codes[n++] = EV_SIDE;   /* ends a step at the kink of |N_r| */
        return n;
    }
    codes[n++] = EV_TOUCH_UP;
    if (m->closure == CAM_CHOICE_CLOSURE_FORM)
        codes[n++] = EV_TOUCH_DOWN;
    if ((mode->sigma != 0.0 || m->train) && cam_follower_friction0(m) > 0.0)
        codes[n++] = EV_HALT;   /* held (sigma 0): only a train's ringing changes the force the guide holds */
    return n;
}

void cam_vf_values(const CamModel *m, const CamMode *mode, int n, const int codes[], const double x[CAM_NX],
                   double u, double g[])
{
    double y[NY], d[4], omega_dot, P = NAN, n_r = NAN, dir, c = cam_follower_clearance(m);
    double touch = CAM_TOUCH / cam_follower_length(m);
    int k, code;
    working_y(m, mode, x, y, d);   /* in flight d is the cam's q at theta */
    for (k = 0; k < n; k++) {
        code = codes[k];
        if ((code == EV_LIFT_OFF || code == EV_SIDE) && P != P)   /* the flank's forces, once */
            cam_vf_on_flank(m, y, u, mode->contact, d, &omega_dot, &P, &n_r);
        if (code == EV_LIFT_OFF)
            g[k] = mode->contact * P;
        else if (code == EV_SIDE)
            g[k] = mode->side * n_r + CAM_SIDE_HYSTERESIS;
        else if (code == EV_STOP)
            g[k] = y[Y_DIR] * y[1];
        else if (code == EV_BREAK_AWAY)
            g[k] = -cam_vf_breakaway(m, y, u, mode->contact, &dir);
        else if (code == EV_HALT)   /* held by the guide (sigma 0): released where a train's pull beats f0 */
            g[k] = y[Y_SIGMA] == 0.0 ? cam_follower_friction0(m) + RELEASE_MARGIN - fabs(closing_at(m, y, y[3], 0.0))
                                     : y[Y_SIGMA] * y[4];
        else
            g[k] = code == EV_TOUCH_UP ? y[3] - (d[0] - c) + touch : (d[0] + c) - y[3] + touch;
    }
}

double cam_vf_value(const CamModel *m, const CamMode *mode, int code, const double x[CAM_NX], double u)
{
    double g;
    cam_vf_values(m, mode, 1, &code, x, u, &g);
    return g;
}

/* s: the longest step the follower's phases allow at the drive's state at `time` [s] (the flight's oscillation,
 * a gap's crossing, the electrical pole, the shaft, a rebound; the solver's own limits come on top). */
double cam_vf_step_limit(const CamDrive *d, double time)
{
    const CamModel *m = &d->model;
    const CamMode *mode = &d->mode;
    const CamMethod *method = cam_method(m->solver);
    double y[NY], dt = HUGE_VAL, u = d->form_u;
    double wn = m->k_spring > 0.0 ? sqrt(cam_follower_stiffness(m) / m->I_f) : 0.0;
    double wt = m->train ? sqrt((cam_follower_stiffness(m) + m->k_train) / m->I_f) : 0.0;   /* on the train */
    double pole = m->has_current && !m->prescribed ? m->R / m->L + sqrt(m->c_e * m->c_m / ((m->compliant ? m->J_m : m->J_0) * m->L))
                  : 0.0;
    double ws = m->compliant ? cam_shaft_rate(m, m->J_0) : 0.0;
    if (!mode->contact && d->x[CAM_OMEGA] != 0.0)   /* in flight a step at most scans the gap's events */
        dt = fmin(dt, FLIGHT_ANGLE / fabs(d->x[CAM_OMEGA]));
    if (!mode->contact && wn > 0.0)   /* (error control holds the flight: only a crossing's return to see) */
        dt = fmin(dt, (method != NULL && method->adaptive ? TRAIN_PHASE : STEP_PHASE) / wn);
    if (!mode->contact && wt > 0.0)   /* the follower rings on the train's spring: a gap's crossing and return unseen */
        dt = fmin(dt, TRAIN_PHASE / wt);
    if (!mode->contact && mode->stuck && cam_follower_clearance(m) > 0.0) {   /* flying at a stuck cam: a tenth of the gap */
        double c = cam_follower_clearance(m), A;
        cam_vf_y(m, mode, d->x, y);
        A = cam_vf_acceleration_scale(m, y, u);
        dt = fmin(dt, 0.1 * sqrt(2.0 * c / A));
        if (y[4] != 0.0)
            dt = fmin(dt, 0.1 * c / fabs(y[4]));
    }
    if (pole > 0.0)   /* also under error control: measured, the shaft's twist drifted 1.8e-8 of M_shaft without */
        dt = fmin(dt, POLE_STEP / pole);
    if (ws > 0.0)
        dt = fmin(dt, (method != NULL && method->adaptive ? SHAFT_PHASE_RK45 : STEP_PHASE) / ws);
    if (d->speed.rebound > time)   /* a bounce lasts about 4 rebound: the first step cannot hold it */
        dt = fmin(dt, d->speed.rebound - time);
    return dt;
}

/* The follower's transition `code` at the drive's state at `time` [s] (EV_NONE: the step's start, settled;
 * EV_BREAK: a profile breakpoint, the contact settled): cam_vf_event_update on y, the log line appended. */
void cam_vf_apply(CamDrive *d, int code, double time)
{
    const CamModel *m = &d->model;
    double y[NY], held[NY], rebound = d->speed.rebound > time ? d->speed.rebound - time : 0.0;
    int contact = d->mode.contact, left = d->mode.left;
    long dropped = 0;
    if (code == EV_SIDE) {   /* the friction's branch turned: nothing else happens */
        d->mode.side = -d->mode.side;
        return;
    }
    cam_vf_y(m, &d->mode, d->x, y);
    memcpy(held, y, sizeof held);
    cam_vf_event_update(d, y, d->form_u, code, &contact, &left, &rebound, time, &dropped);
    if (dropped > 0 && sizeof d->step_events > strlen(d->step_events))
        snprintf(d->step_events + strlen(d->step_events), sizeof d->step_events - strlen(d->step_events),
                 "and %ld more; ", dropped);
    if (code == EV_NONE && contact == d->mode.contact && left == d->mode.left && !memcmp(held, y, sizeof held))
        return;   /* settled already: x as it was, not its round trip through y (a restored state repeats its run) */
    cam_vf_x(m, y, d->form_u, contact, left, d->x, &d->mode);
    d->speed.rebound = rebound > 0.0 ? time + rebound : 0.0;
}

/* A train's end mass at rest relative to the follower on the flank `contact` at y (its weight on the train's spring:
 * transitions.c cam_initial's rest, taken from the follower's flank, not the cam's s). */
static void relax_train(const CamModel *m, double y[NY], int contact)
{
    double d[4];
    if (!m->train)
        return;
    cam_kind_eval(m, y[0], d);
    y[Y_XE] = (d[0] - contact * cam_follower_clearance(m)) / m->q_scale + m->F_ex / m->k_train;
    y[Y_VE] = d[1] * y[1] / m->q_scale;
}

/* The follower's start at the drive's x (on its lower flank, or a groove's upper one where that holds; the shaft at
 * rest decided by its rule) under the input u (the voltage, or the speed drive's imposed acceleration). */
void cam_vf_start(CamDrive *d, double u)
{
    const CamModel *m = &d->model;
    double y[NY], other[NY];
    int contact, left = 1;
    d->mode.contact = CAM_ON_LOWER_FLANK;   /* or (a groove) on its upper flank where that one holds */
    d->mode.left = CAM_ON_LOWER_FLANK;
    d->mode.s_free = 0.0;
    d->x[CAM_GAP] = d->x[CAM_RATE] = 0.0;
    cam_vf_y(m, &d->mode, d->x, y);
    relax_train(m, y, 1);
    contact = cam_vf_settle(m, y, u, 1, NULL);
    if (!contact && m->closure == CAM_CHOICE_CLOSURE_FORM) {   /* a groove: its other flank, if it holds */
        memcpy(other, y, sizeof other);
        relax_train(m, other, -1);
        if ((contact = cam_vf_settle(m, other, u, -1, NULL)) != 0)
            memcpy(y, other, sizeof other);
    }
    if (y[Y_DIR] == 0.0)   /* with the input's start value; the first step decides again with the host's */
        cam_vf_at_rest(m, y, u, &contact, &left, 0);
    cam_vf_x(m, y, u, contact, contact != 0 ? contact : left, d->x, &d->mode);
    d->solver.k1_valid = 0;
}

/* The load on the flank `contact` at y: another type's by kind.c (docs/model.md 16.3), the roller's M_f d + P s' with
 * N along its normal; the cam stuck, static friction takes it all (the speed drive's cam at rest: the flank's holding
 * torque). */
static void flank_load(const CamModel *m, const double y[NY], double u, int contact, CamLoad *load)
{
    double q[4], omega_dot, P, tan_a;
    cam_vf_on_flank(m, y, u, contact, q, &omega_dot, &P, NULL);
    if (m->kind != CAM_CHOICE_FOLLOWER_TYPE_TRANSLATING_ROLLER) {
        cam_kind_contact_load(m, q, P, y[Y_DIR], load);
    } else {
        tan_a = q[1] / (m->r_b + q[0]);
        load->alpha = atan(tan_a);
        load->M = m->M_f * y[Y_DIR] + P * q[1];
        load->N = cam_normal_force(P, tan_a);   /* signed as contact */
        load->J = m->J_0 + m->m * q[1] * q[1];
        load->f = 0.0;
    }
    if (y[Y_DIR] == 0.0 && !m->prescribed)
        load->M = cam_vf_torque_toward(m, y, u, 0.0);
    load->v = q[1] * y[1];
    load->a = q[2] * y[1] * y[1] + q[1] * omega_dot;
}

/* voltage_follower.outputs: the follower's own s, v, a (another type: its own q, q_dot, in the law's lift units, and
 * an arm's psi, psi_dot); in flight M = M_f sgn(omega) and J = J_0. */
void cam_vf_outputs(CamDrive *d, double out[])
{
    const CamModel *m = &d->model;
    double y[NY], dd[4], i;
    CamLoad load;
    cam_vf_y(m, &d->mode, d->x, y);
    if (m->prescribed)   /* the speed drive: the left limit's direction (a stop at the step's end still moves there) */
        y[Y_DIR] = cam_motion_sign(d->x[CAM_OMEGA], d->omega_ref, d->omega_dot_ref, fabs(d->time));
    cam_kind_eval(m, y[0], dd);
    i = current(m, y, d->form_u);
    load.s_cam = dd[0];
    if (d->mode.contact != 0) {
        flank_load(m, y, d->form_u, d->mode.contact, &load);
    } else {   /* in flight */
        load.alpha = atan(dd[1] / (m->r_b + dd[0]));
        load.M = m->M_f * y[Y_DIR];
        load.J = m->J_0;
        load.N = load.f = 0.0;
        load.v = y[4];
        load.a = flight_acceleration(m, y);
    }
    if (m->kind != CAM_CHOICE_FOLLOWER_TYPE_TRANSLATING_ROLLER) {   /* q in the law's lift units; the cam's s_cam */
        double s_cam[4];
        cam_profile_eval(&m->profile, y[0], s_cam);
        load.s_cam = s_cam[0];
        if (d->mode.contact == 0) {   /* in flight the cam's pressure angle at theta, as the translating roller's */
            CamLoad geometry;
            cam_kind_contact_load(m, dd, 0.0, 0.0, &geometry);
            load.alpha = geometry.alpha;
        }
        load.v /= m->q_scale;
        load.a /= m->q_scale;
        cam_record_outputs(&load, y[1], y[0], y[3] / m->q_scale, i, d->form_u, out);
        if (m->arm) {
            out[CAM_O_PSI] = y[3];
            out[CAM_O_PSI_DOT] = y[4];
        }
    } else {
        cam_record_outputs(&load, y[1], y[0], y[3], i, d->form_u, out);
    }
    if (m->train) {   /* the end mass on the follower's own s, v (docs/model.md 14.6) */
        double F = train_force(m, y, y[3], y[4]);
        out[CAM_O_S_END] = y[Y_XE];
        out[CAM_O_V_END] = y[Y_VE];
        out[CAM_O_A_END] = (F + m->F_ex) / m->m_end;
        out[CAM_O_F_TRAIN] = F;
    }
    if (m->compliant) {   /* the rotor's side of the shaft; J counts the rotor too (outputs.c cam_outputs) */
        out[CAM_O_J] = load.J + m->J_m;
        out[CAM_O_THETA_M] = y[0] + y[Y_TWIST];
        out[CAM_O_OMEGA_M] = y[Y_ROTOR];
        out[CAM_O_M_SHAFT] = shaft_torque(m, y);
    }
}

/* N m: the load torque with the follower on the flank `contact` at y (M_f d + P q' and another type's friction). */
double cam_vf_flank_torque(const CamModel *m, const double y[NY], double u, int contact)
{
    CamLoad load;
    flank_load(m, y, u, contact, &load);
    return load.M;
}
