/* The follower as a body of its own on a voltage-driven cam, closures 'spring' and 'form' (a groove's flanks at
 * s_cam - c, contact +1, and s_cam + c, contact -1): the consistent formulation with guide friction and a rigid or
 * compliant shaft (docs/model.md section 13.6; its check is the reference's physics/voltage_follower.py and
 * reference/voltage_flight.py, written independently). y = (theta, omega, i, s, v, phi, omega_m, sigma): theta,
 * omega, i and a compliant shaft's twist phi and rotor speed omega_m in d->x, the follower's s, v, contact (+1, -1 on
 * a flank, 0 in flight), touch-downs and the rebound guard in d->speed (saved with the state); sigma is the flying
 * follower's direction, held over a step (rate 0). The cam side is driven by T = c_m i (rigid) or the shaft's
 * k phi + d (omega_m - omega), less M_f sgn(omega). In contact
 * J omega_dot = T - (m s'' omega^2 + F_close + sgn(v) f) s'
 * with J = J_0 + m s'^2, the guide friction f solved with omega_dot as model.c's load_terms does (section 4.4 with
 * F_close in gravity's place), and the force P = m (s'' omega^2 + s' omega_dot) + F_close + sgn(v) f along X;
 * lift-off where contact P reaches 0; in flight J_0 omega_dot = T and m s_dd = -F_close(s) - sigma f0 (f0 the
 * friction at no contact force; a halt where v reaches 0); touch-down where a gap reaches -CAM_TOUCH, an impact exchanging
 * momentum with the cam side (J_0 omega + m s' v kept, w+ = -e w-) and the Zeno guard. The steps of the parameter
 * `solver` (rk.c's tableaus: rk45 with error control on rtol, atol; euler, rk4 and etdrk4's RK4 core fixed at h_max
 * within the stability and resolution limits of fixed_step.c), at most STEP_PHASE of the flight's oscillation and
 * of the shaft's (SHAFT_PHASE_RK45 under rk45), a tenth of the electrical time constant, FLIGHT_ANGLE of cam angle in flight; an event function gone
 * from > 0 to <= 0 over a step is located on the step's length (integrate.c's locator). At rest (omega = 0: the start, a stop)
 * the shaft is stuck, the follower at rest on its flank (y[8] = 0), until the consistent formulation's break-away
 * rule with the contact's load starts it; the shaft's direction y[8] is held over a step. A cam stuck with the
 * follower off it: the follower flies alone and lands on the cam at rest (voltage_follower_events.c unstick). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "cam_solver.h"
#include "cam_voltage_follower.h"

#define STEP_PHASE 4e-4         /* rad: phase of the flight's oscillation sqrt(k/m) t in one step */
#define MAX_EVENTS 100000       /* transitions in one step before the step is refused */
#define MAX_STEPS 10000000 /* Runge-Kutta steps in one step before the step is refused (never a hang) */
#define SHAFT_PHASE_RK45 0.03  /* rad: the shaft's phase in one rk45 step. Its error norm alone left M_shaft's damper
                                 * term 1.8e-8 of M_shaft off the reference (0.1: 2.2e-9; 0.03 and below: 2.1e-10, the
                                 * reference's own floor); STEP_PHASE there took 56x the steps for no gain (measured) */
#define POLE_STEP 0.1           /* a step at most this many electrical time constants (1 / pole) */
#define FLIGHT_ANGLE 1e-2       /* rad: cam angle of one adaptive step in flight (a gap's crossing and return unseen) */
#define SLOW 1.0                /* rad/s: below it a fixed step also sweeps at most its share from rest */


static double sgn(double x)
{
    return x > 0.0 ? 1.0 : (x < 0.0 ? -1.0 : 0.0);
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

/* The shaft's direction of motion, held over a step (a stop ends it; 0: stuck): a Runge-Kutta stage past omega = 0
 * with sgn(omega) would turn the friction inside the step and misplace the stop (3.3e-6 rad at steps of 7e-4 s). */
static double shaft_direction(const double y[NY])
{
    return y[Y_DIR];
}

/* N m: what drives the cam side, the motor's torque (rigid) or the shaft's, less the shaft's friction against the
 * direction `dir`. */
double cam_vf_torque_toward(const CamModel *m, const double y[NY], double u, double dir)
{
    double drive = m->compliant ? shaft_torque(m, y)
                   : (m->has_current ? m->c_m * y[2] : m->c_m * (u - m->c_e * y[1]) / m->R);
    return drive - m->M_f * dir;
}

static double torque(const CamModel *m, const double y[NY], double u)
{
    return cam_vf_torque_toward(m, y, u, shaft_direction(y));
}

/* m: the clearance of a groove (closure 'form'), 0 for a spring's one flank. */
double cam_vf_clearance(const CamModel *m)
{
    return m->closure == CAM_CHOICE_CLOSURE_FORM ? m->c : 0.0;
}

/* On the flank `contact` at y, the shaft moving toward `dir`: d = (s_cam, s', s'', s'''), omega_dot [rad/s2] and the
 * force P [N] along X of the coupled equations; with guide friction f = mu (|N_r| + |N_g|) solved with omega_dot
 * (model.c load_terms with F_close in gravity's place: N_r = n0 + sigma kappa f, kappa = (J_0 / J) tan(alpha)). */
static void flank_toward(const CamModel *m, const double y[NY], double u, int contact, double dir, double d[4],
                         double *omega_dot, double *P, double *n_r)
{
    double omega = y[1], F, J, inertial, x0, sigma, tan_a, f, n0, kappa;
    cam_profile_eval(&m->profile, y[0], d);
    F = cam_follower_closing(m, d[0] - contact * cam_vf_clearance(m));
    if (m->mu == 0.0) {
        *omega_dot = (cam_vf_torque_toward(m, y, u, dir) - (m->m * d[2] * omega * omega + F) * d[1])
                     / (m->J_0 + m->m * d[1] * d[1]);
        *P = m->m * (d[2] * omega * omega + d[1] * *omega_dot) + F;
        *n_r = 0.0;
        return;
    }
    J = m->J_0 + m->m * d[1] * d[1];
    inertial = m->m * d[2] * omega * omega + F;
    x0 = (cam_vf_torque_toward(m, y, u, dir) - inertial * d[1]) / J;
    sigma = sgn(d[1] * dir);
    tan_a = d[1] / (m->r_b + d[0]);
    n0 = (inertial + m->m * d[1] * x0) * tan_a + m->G_y;
    kappa = m->J_0 / J * tan_a;
    f = cam_guide_friction(n0, kappa, sigma, m->mu, m->N_g, 0.0);
    *omega_dot = x0 - sigma * f * d[1] / J;
    *P = m->m * (d[2] * omega * omega + d[1] * *omega_dot) + F + sigma * f;
    *n_r = n0 + sigma * kappa * f;
}

/* flank_toward in the shaft's direction; the cam stuck: at rest, the contact's force P = F_close(s) balancing the
 * spring and gravity (the guide's friction at rest carries nothing), omega_dot = 0. */
static void flank_terms(const CamModel *m, const double y[NY], double u, int contact, double d[4], double *omega_dot,
                        double *P, double *n_r)
{
    if (y[Y_DIR] == 0.0) {
        cam_profile_eval(&m->profile, y[0], d);
        *P = cam_follower_closing(m, d[0] - contact * cam_vf_clearance(m));
        *omega_dot = 0.0;
        *n_r = *P * d[1] / (m->r_b + d[0]) + m->G_y;
        return;
    }
    flank_toward(m, y, u, contact, shaft_direction(y), d, omega_dot, P, n_r);
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

void cam_vf_on_flank(const CamModel *m, const double y[NY], double u, int contact, double d[4], double *omega_dot,
                     double *P)
{
    double n_r;
    flank_terms(m, y, u, contact, d, omega_dot, P, &n_r);
}

/* N: the guide's side force N_r on the flank `contact` at y (0 without guide friction). */
static double side_force(const CamModel *m, const double y[NY], double u, int contact)
{
    double d[4], omega_dot, P, n_r;
    flank_terms(m, y, u, contact, d, &omega_dot, &P, &n_r);
    return n_r;
}

/* m/s2: the flying follower's acceleration with the friction's direction -sigma (0: held by it). */
static double free_acceleration(const CamModel *m, double s, double sigma)
{
    return sigma == 0.0 ? 0.0 : (-cam_follower_closing(m, s) - sigma * cam_follower_friction0(m)) / m->m;
}

/* The flying follower's direction over the next step: sgn(v), or at a halt the way the net force pushes it beyond
 * the guide's static friction (0: held). */
double cam_vf_flight_direction(const CamModel *m, const double y[NY])
{
    double net;
    if (y[4] != 0.0)
        return sgn(y[4]);
    net = -cam_follower_closing(m, y[3]);
    return fabs(net) > cam_follower_friction0(m) ? sgn(net) : 0.0;
}

/* cam_vf_rates, and on a moving flank the contact's force *P [N] along X and the guide's side force *n_r [N] (else
 * both untouched). */
static void flank_rates(const CamModel *m, double u, int contact, const double y[NY], double dy[NY], double *P,
                        double *n_r)
{
    double omega_m = m->compliant ? y[Y_ROTOR] : y[1];
    dy[0] = y[1];
    dy[2] = m->has_current ? (u - m->R * y[2] - m->c_e * omega_m) / m->L : 0.0;
    dy[Y_TWIST] = m->compliant ? omega_m - y[1] : 0.0;
    dy[Y_ROTOR] = m->compliant ? (m->c_m * current(m, y, u) - shaft_torque(m, y)) / m->J_m : 0.0;
    dy[Y_SIGMA] = 0.0;
    dy[Y_DIR] = 0.0;
    if (contact && y[Y_DIR] == 0.0) {   /* stuck: the cam and the follower on its flank at rest */
        dy[0] = dy[1] = dy[3] = dy[4] = 0.0;
        return;
    }
    if (contact) {
        double d[4];
        flank_terms(m, y, u, contact, d, &dy[1], P, n_r);
        dy[3] = d[1] * y[1];
        dy[4] = d[2] * y[1] * y[1] + d[1] * dy[1];
        return;
    }
    dy[1] = y[Y_DIR] == 0.0 ? 0.0 : torque(m, y, u) / m->J_0;   /* the cam stuck: the follower flies alone */
    dy[3] = y[4];
    dy[4] = m->mu == 0.0 ? -cam_follower_closing(m, y[3]) / m->m : free_acceleration(m, y[3], y[Y_SIGMA]);
}

void cam_vf_rates(const CamModel *m, double u, int contact, const double y[NY], double dy[NY])
{
    double P, n_r;
    flank_rates(m, u, contact, y, dy, &P, &n_r);
}

/* The follower set on the flank `contact` at y's angle, moving with it. */
void cam_vf_set_on_flank(const CamModel *m, double y[NY], int contact)
{
    double d[4];
    cam_profile_eval(&m->profile, y[0], d);
    y[3] = d[0] - contact * cam_vf_clearance(m);
    y[4] = d[1] * y[1];
}

typedef struct {                /* cam_vf_rates' arguments but the state (a CamRates context) */
    const CamModel *m;
    double u;
    int contact;
    double P, n_r;              /* N: the flank's force and the side force where the rates were last taken (a flank) */
} Rates;

static void rates(void *ctx, const double *y, double *dy)
{
    Rates *r = ctx;
    flank_rates(r->m, r->u, r->contact, y, dy, &r->P, &r->n_r);
}

/* One step of the tableau t of h [s] from y into out (the follower set on its flank in contact); err: the embedded
 * pair's error estimate, or NULL. k: the stages (NULL: scratch of its own), k[0] the rates at y already if k0. */
static void vf_step(const CamModel *m, const CamTableau *t, double u, int contact, const double y[NY], double h,
                    double out[NY], double *err, double *k, int k0, double end[2])
{
    double scratch[(CAM_MAX_STAGES + 1) * NY];
    Rates r = {m, u, contact, NAN, NAN};
    if (k == NULL)
        k = scratch, k0 = 0;
    if (!k0)
        rates(&r, y, k);
    cam_tableau_step(t, m->compliant ? Y_SIGMA : Y_TWIST, NY, rates, &r, y, h, k, out, err);   /* sigma, dir: held */
    if (end != NULL) {   /* an embedded FSAL pair took its last rates at out: the flank's forces there (P, N_r) */
        int fsal = err != NULL && t->fsal && t->error_exponent != 0.0;
        end[0] = fsal ? r.P : NAN;
        end[1] = fsal ? r.n_r : NAN;
    }
    if (contact)
        cam_vf_set_on_flank(m, out, contact);
}

/* The event function `code` at y on or off the flank `contact` (> 0: nothing happens). */
double cam_vf_event_value(const CamModel *m, double u, int code, int contact, const double y[NY])
{
    double d[4], omega_dot, P;
    if (code == EV_STOP)
        return y[Y_DIR] * y[1];
    if (code == EV_BREAK_AWAY)
        return -cam_vf_breakaway(m, y, u, contact, &omega_dot);
    if (code == EV_LIFT_OFF) {
        cam_vf_on_flank(m, y, u, contact, d, &omega_dot, &P);
        return contact * P;
    }
    if (code == EV_HALT)
        return y[Y_SIGMA] * y[4];
    cam_profile_eval(&m->profile, y[0], d);
    return code == EV_TOUCH_UP ? y[3] - (d[0] - cam_vf_clearance(m)) + CAM_TOUCH : (d[0] + cam_vf_clearance(m)) - y[3] + CAM_TOUCH;
}

/* event_value, and the step's ends: for EV_BREAK the cam's angle short of the profile's breakpoint at[0] [rad], for
 * EV_SIDE the side force N_r times its sign at[1] at the step's start, past 0 by CAM_SIDE_HYSTERESIS (|N_r|'s kink). */
static double event_at(const CamModel *m, double u, int code, int contact, const double at[2], const double y[NY])
{
    if (code == EV_BREAK)
        return at[0] - y[0];
    if (code == EV_SIDE)
        return at[1] * side_force(m, y, u, contact) + CAM_SIDE_HYSTERESIS;
    return cam_vf_event_value(m, u, code, contact, y);
}

static int crossed(double before, double after)
{
    return (before > 0.0 && after <= 0.0) || (before == 0.0 && after < 0.0);
}

typedef struct {                /* a Runge-Kutta step from y and its event functions (trial_event) */
    const CamModel *m;
    const CamTableau *t;
    double u;
    int contact;
    const double *ends, *y;
} Trial;

/* The event function `code` at the end of a Runge-Kutta step of h [s] from the trial's y. */
static double trial_event(void *ctx, int code, double h)
{
    const Trial *t = ctx;
    double out[NY];
    vf_step(t->m, t->t, t->u, t->contact, t->y, h, out, NULL, NULL, 0, NULL);
    return event_at(t->m, t->u, code, t->contact, t->ends, out);
}

/* m/s2: a bound of the follower's acceleration relative to the flank near y (voltage_follower.acceleration_scale). */
double cam_vf_acceleration_scale(const CamModel *m, const double y[NY], double u)
{
    double d[4];
    cam_profile_eval(&m->profile, y[0], d);
    return fabs(cam_follower_closing(m, d[0]) / m->m) + cam_follower_friction0(m) / m->m + fabs(d[2]) * y[1] * y[1]
           + fabs(d[1] * torque(m, y, u) / m->J_0) + 1e-300;
}

/* The error norm of an embedded step from y to out (rk.c cam_error_norm over y's slots): RMS of err / (atol + rtol
 * max(|y|, |out|)) over theta (its scale capped at 2 pi), omega, the current and a compliant shaft's slots where they
 * are states, and the follower's s, v in flight (on a flank they follow the cam's). */
static double vf_error_norm(const CamModel *m, int contact, const double y[NY], const double out[NY],
                            const double err[NY])
{
    static const int SLOTS[] = {0, 1, 2, Y_TWIST, Y_ROTOR, 3, 4};
    double total = 0.0, scale;
    int k, n = 0;
    for (k = 0; k < 7; k++) {
        int j = SLOTS[k];
        if ((j == 2 && !m->has_current) || ((j == Y_TWIST || j == Y_ROTOR) && !m->compliant) || ((j == 3 || j == 4)
                                                                                                   && contact))
            continue;
        scale = fmax(fabs(y[j]), fabs(out[j]));
        if (j == 0)
            scale = fmin(scale, 2.0 * 3.141592653589793);
        total += pow(err[j] / (m->atol + m->rtol * scale), 2.0);
        n += 1;
    }
    return sqrt(total / n);
}

static int vf_init(CamDrive *d, CamError *err)
{
    const double *v = d->model.params.v;
    double y[NY], other[NY];
    int contact, left = 1;
    (void)err;
    cam_initial(&d->model, v[CAM_P_THETA0], v[CAM_P_OMEGA0], v[CAM_P_I0], d->x, &d->mode);
    d->mode.contact = 1;   /* the kinematic backlash's mode is not this follower's (d->speed.contact is): held engaged */
    d->mode.s_free = 0.0;
    d->form_u = d->u;
    memset(&d->speed, 0, sizeof d->speed);
    d->speed.contact = 1.0;
    cam_vf_load_y(d, y);
    contact = cam_vf_settle(&d->model, y, d->u, 1);
    if (!contact && d->model.closure == CAM_CHOICE_CLOSURE_FORM) {   /* a groove: its other flank, if it holds */
        memcpy(other, y, sizeof other);
        if ((contact = cam_vf_settle(&d->model, other, d->u, -1)) != 0)
            memcpy(y, other, sizeof other);
    }
    if (y[Y_DIR] == 0.0)   /* with the input's start value; the first step decides again with the host's */
        cam_vf_at_rest(&d->model, y, d->u, &contact, &left, 0);
    d->speed.contact = contact;
    d->speed.left = contact != 0 ? contact : left;   /* in flight from the start: it was set on flank +1 */
    d->speed.sigma = cam_vf_flight_direction(&d->model, y);
    cam_vf_store_y(d, y);
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
    double pole = m->has_current ? m->R / m->L + sqrt(m->c_e * m->c_m / ((m->compliant ? m->J_m : m->J_0) * m->L))
                  : 0.0;
    double ws = m->compliant ? sqrt(m->k_shaft * (1.0 / m->J_m + 1.0 / m->J_0)) + m->d_shaft * (1.0 / m->J_m
                                                                                                  + 1.0 / m->J_0)
                : 0.0;   /* rad/s: the shaft's rate (docs/model.md 12.1) */
    int contact = (int)d->speed.contact, left = (int)d->speed.left, events = 0;
    const CamMethod *method = cam_method(m->solver);
    int adaptive = method->adaptive;   /* rk45: error control; else fixed steps of h_max within the method's limits */
    const CamTableau *tableau = method->tableau != NULL ? method->tableau : &cam_rk4;   /* etdrk4: its RK4 core */
    double sweep = m->feature_angle * (method->resolution < HUGE_VAL ? method->resolution : method->max_sweep);
    long dropped = 0, taken = 0;
    double stages[(CAM_MAX_STAGES + 1) * NY], fsal_sigma = 0.0;   /* the adaptive steps' stages */
    double after_before[6];   /* the event functions at the last step's end, codes_before[] */
    int fsal = 0, fsal_contact = 0, have_before = 0, n_before = 0, codes_before[6], carried;
    double n_r_end = NAN;   /* N: the side force at the last step's end (NAN: not computed) */
    d->step_events[0] = '\0';
    cam_vf_load_y(d, y);
    if (y[1] == 0.0)   /* at rest: the step's input may start or hold it */
        cam_vf_at_rest(m, y, u, &contact, &left, 0);
    carried = adaptive && d->solver.k1_valid && d->solver.fsal_u == u && y[1] != 0.0;   /* as the last step ended */
    if (contact && !carried && !(contact = cam_vf_settle_from(m, y, u, contact, &left)))   /* its end was settled */
        cam_follower_note(d->step_events, sizeof d->step_events, &dropped, "follower: lift-off at t = %.9g s "
                          "(theta = %.6g rad); ", time, y[0]);
    if (carried && contact == (int)d->speed.contact) {
        memcpy(stages, d->solver.k_own, NY * sizeof *stages);   /* the last step's end under the same input and mode */
        fsal = 1;
        fsal_contact = contact;
        fsal_sigma = y[Y_SIGMA];
    }
    d->solver.k1_valid = 0;
    while (tau < h) {
        int codes[6], n = 0, k, code = EV_NONE;
        double dt = h - tau, at = dt, ends[2] = {0.0, 0.0}, before[6], after[6], forces[2] = {NAN, NAN}, n_r_y;
        int carry;
        if (y[1] != 0.0 && !contact)   /* in flight a step at most scans the gap's events */
            dt = fmin(dt, FLIGHT_ANGLE / fabs(y[1]));
        if (!adaptive) {   /* the internal step h_max, the cam sweeping at most the method's share of the finest
                            * feature (fixed_step.c's resolution; euler's max_sweep), from rest at its acceleration */
            double rate[NY], x[CAM_NX] = {y[0], y[1], y[2], y[Y_TWIST], y[Y_ROTOR]}, fastest;
            CamMode engaged = d->mode;
            engaged.contact = contact != 0;   /* fixed_step.c's stability limit, the pole explicit (RK4's core) */
            fastest = cam_stiffness_rate(m, &engaged, x, 1);
            dt = fmin(dt, m->h_max);
            if (fastest > 0.0)
                dt = fmin(dt, method->stability / fastest);
            if (y[1] != 0.0)
                dt = fmin(dt, sweep / fabs(y[1]));
            if (y[Y_DIR] != 0.0 && fabs(y[1]) < SLOW) {
                cam_vf_rates(m, u, contact, y, rate);
                if (rate[1] != 0.0)
                    dt = fmin(dt, sqrt(2.0 * sweep / fabs(rate[1])));
            }
        }
        if (!contact && wn > 0.0)
            dt = fmin(dt, STEP_PHASE / wn);
        if (!contact && y[Y_DIR] == 0.0 && cam_vf_clearance(m) > 0.0) {   /* flying at a stuck cam: a tenth of the gap */
            double c = cam_vf_clearance(m), A = cam_vf_acceleration_scale(m, y, u);
            dt = fmin(dt, 0.1 * sqrt(2.0 * c / A));
            if (y[4] != 0.0)
                dt = fmin(dt, 0.1 * c / fabs(y[4]));
        }
        if (pole > 0.0)   /* also under error control: measured, the shaft's twist drifted 1.8e-8 of M_shaft without */
            dt = fmin(dt, POLE_STEP / pole);
        if (ws > 0.0)
            dt = fmin(dt, (adaptive ? SHAFT_PHASE_RK45 : STEP_PHASE) / ws);
        if (!contact)
            y[Y_SIGMA] = cam_vf_flight_direction(m, y);
        carry = have_before && contact == fsal_contact && y[Y_SIGMA] == fsal_sigma;   /* y is the last step's end */
        if (rebound > 0.0)
            dt = fmin(dt, rebound);   /* a bounce lasts about 4 rebound: the first step cannot hold it */
        if (++taken > MAX_STEPS)
            return cam_error(err, CAM_ERR_SIMULATION, "more than %d Runge-Kutta steps in one step from t = %g s (at "
                             "t = %.9g s, step %g s, contact %d, rebound guard %g s): the step is refused", MAX_STEPS,
                             time, time + tau, dt, contact, rebound);
        if (adaptive) {   /* error control on rtol, atol within the bounds above (integrate.c cam_step_adaptive) */
            double bound = fmin(dt, m->h_max), e[NY];
            dt = fmin(bound, d->solver.h_next);
            if (!(fsal && contact == fsal_contact && y[Y_SIGMA] == fsal_sigma))
                fsal = 0;   /* the rates at y are those the last step ended with while its mode holds */
            for (;;) {
                vf_step(m, tableau, u, contact, y, dt, next, e, stages, fsal, forces);
                fsal = 1;   /* k[0] is the rates at y from here on */
                if (cam_step_control(vf_error_norm(m, contact, y, next, e), tableau->error_exponent, bound, &dt,
                                     &d->solver.h_next))
                    break;
                if (dt < 1e-12 * h)
                    return cam_error(err, CAM_ERR_REJECTED, "solver 'rk45' cannot meet rtol = %g, atol = %g: its step "
                                     "fell below %g s (1e-12 of the communication step) at t = %g s: loosen rtol/atol, "
                                     "or check the inputs and parameters", m->rtol, m->atol, 1e-12 * h, time + tau);
            }
        } else
            vf_step(m, tableau, u, contact, y, dt, next, NULL, NULL, 0, NULL);
        codes[n++] = y[Y_DIR] == 0.0 ? EV_BREAK_AWAY : EV_STOP;   /* stuck: the torque on it may change */
        if (contact) {
            if (y[Y_DIR] != 0.0)
                codes[n++] = EV_LIFT_OFF;
        } else {
            codes[n++] = EV_TOUCH_UP;
            if (m->closure == CAM_CHOICE_CLOSURE_FORM)
                codes[n++] = EV_TOUCH_DOWN;
            if (y[Y_SIGMA] != 0.0 && cam_follower_friction0(m) > 0.0)
                codes[n++] = EV_HALT;
        }
        ends[0] = cam_profile_first_breakpoint(&m->profile, y[0], next[0]);
        if (ends[0] == ends[0])   /* the step ends just past the profile's breakpoint (s'' or s''' jumps there) */
            codes[n++] = EV_BREAK;
        n_r_y = carry && n_r_end == n_r_end ? n_r_end : (contact && y[Y_DIR] != 0.0 && m->mu > 0.0
                                                         ? side_force(m, y, u, contact) : 0.0);
        if (contact && y[Y_DIR] != 0.0 && m->mu > 0.0 && (ends[1] = sgn(n_r_y)) != 0.0)
            codes[n++] = EV_SIDE;   /* and just past the kink of |N_r| (docs/model.md 10) */
        at = dt;
        if (!(carry && n == n_before))
            have_before = 0;   /* the functions at y are the last step's at its end while its mode holds */
        if (contact && y[Y_DIR] != 0.0 && forces[0] != forces[0] && n > 1) {   /* the lift-off's and side force's */
            double dd[4], omega_dot;
            flank_terms(m, next, u, contact, dd, &omega_dot, &forces[0], &forces[1]);
        }
        n_r_end = forces[1];
        for (k = 0; k < n; k++) {
            int kept = have_before && codes[k] == codes_before[k] && codes[k] != EV_BREAK && codes[k] != EV_SIDE;
            if (codes[k] == EV_SIDE) {   /* event_at's at[1] N_r + CAM_SIDE_HYSTERESIS from the forces in hand */
                before[k] = ends[1] * n_r_y + CAM_SIDE_HYSTERESIS;
                after[k] = ends[1] * forces[1] + CAM_SIDE_HYSTERESIS;
                continue;
            }
            before[k] = kept ? after_before[k] : event_at(m, u, codes[k], contact, ends, y);
            after[k] = codes[k] == EV_LIFT_OFF ? contact * forces[0] : event_at(m, u, codes[k], contact, ends, next);
        }
        {
            Trial tr = {m, tableau, u, contact, ends, y};
            k = cam_locate_first_event(n, codes, 0.0, dt, before, after, crossed, trial_event, &tr, 0.0, &at);
            code = k >= 0 ? codes[k] : EV_NONE;
        }
        have_before = code == EV_NONE;
        if (have_before) {   /* the mode the next step must keep to reuse the end's rates and event functions */
            fsal_contact = contact;
            fsal_sigma = y[Y_SIGMA];
            n_before = n;
            memcpy(codes_before, codes, sizeof codes_before);
            memcpy(after_before, after, sizeof after_before);
        }
        if (code == EV_NONE && adaptive && tableau->fsal)   /* first same as last: the next step's k[0] */
            memcpy(stages, stages + tableau->stages * NY, NY * sizeof *stages);
        else
            fsal = 0;
        if (code == EV_NONE) {
            memcpy(y, next, sizeof y);
        } else if (at < dt) {
            vf_step(m, tableau, u, contact, y, at, trial, NULL, NULL, 0, NULL);
            memcpy(y, trial, sizeof y);
        } else {
            memcpy(y, next, sizeof y);
        }
        tau = code == EV_NONE ? tau + dt : tau + at;
        if (rebound > 0.0)
            rebound = fmax(rebound - (code == EV_NONE ? dt : at), 0.0);
        if (code == EV_NONE || code == EV_SIDE)
            continue;
        if (code != EV_BREAK && ++events > MAX_EVENTS)   /* past a breakpoint only the contact is settled */
            return cam_error(err, CAM_ERR_SIMULATION, "the follower changed contact more than %d times in one step "
                             "from t = %g s: the step is refused", MAX_EVENTS, time);
        cam_vf_event_update(d, y, u, code, &contact, &left, &rebound, time + tau, &dropped);
    }
    if (dropped > 0 && sizeof d->step_events > strlen(d->step_events))
        snprintf(d->step_events + strlen(d->step_events), sizeof d->step_events - strlen(d->step_events),
                 "and %ld more", dropped);
    if (fsal && contact == fsal_contact && cam_vf_flight_direction(m, y) == fsal_sigma) {   /* the next step's k[0] */
        memcpy(d->solver.k_own, stages, NY * sizeof *stages);
        d->solver.k1_valid = 1;
        d->solver.fsal_u = u;
    }
    cam_vf_store_y(d, y);
    d->speed.contact = contact;
    d->speed.rebound = rebound;
    d->speed.left = left;
    d->speed.sigma = cam_vf_flight_direction(m, y);   /* Model Exchange's (co-simulation decides it at each step) */
    *steps = taken;
    return CAM_OK;
}

/* voltage_follower.outputs: the follower's own s, v, a; in flight M = M_f sgn(omega) and J = J_0. */
static void vf_outputs(CamDrive *d, double out[])
{
    const CamModel *m = &d->model;
    double y[NY], dd[4], omega_dot, P, i;
    CamLoad load;
    cam_vf_load_y(d, y);
    cam_profile_eval(&m->profile, y[0], dd);
    i = current(m, y, d->form_u);
    load.alpha = atan(dd[1] / (m->r_b + dd[0]));
    load.s_cam = dd[0];
    load.f = 0.0;
    load.N = 0.0;   /* in flight */
    if (d->speed.contact != 0.0) {
        int contact = (int)d->speed.contact;
        double tan_a = dd[1] / (m->r_b + dd[0]);
        cam_vf_on_flank(m, y, d->form_u, contact, dd, &omega_dot, &P);
        /* stuck: static friction takes it all */
        load.M = y[Y_DIR] == 0.0 ? cam_vf_torque_toward(m, y, d->form_u, 0.0)
                 : m->M_f * shaft_direction(y) + P * dd[1];
        load.N = cam_normal_force(P, tan_a);   /* signed as contact */
        load.J = m->J_0 + m->m * dd[1] * dd[1];
        load.v = dd[1] * y[1];
        load.a = dd[2] * y[1] * y[1] + dd[1] * omega_dot;
        y[3] = dd[0] - contact * cam_vf_clearance(m);
    } else {
        load.M = m->M_f * shaft_direction(y);
        load.J = m->J_0;
        load.v = y[4];
        load.a = m->mu == 0.0 ? -cam_follower_closing(m, y[3]) / m->m : free_acceleration(m, y[3], y[Y_SIGMA]);
    }
    cam_record_outputs(&load, y[1], y[0], y[3], i, d->form_u, out);
    if (m->compliant) {   /* the rotor's side of the shaft; J counts the rotor too (outputs.c cam_outputs) */
        out[CAM_O_J] = load.J + m->J_m;
        out[CAM_O_THETA_M] = y[0] + y[Y_TWIST];
        out[CAM_O_OMEGA_M] = y[Y_ROTOR];
        out[CAM_O_M_SHAFT] = shaft_torque(m, y);
    }
}

static void vf_advice(const CamDrive *d, char *buf, size_t len)
{
    snprintf(buf, len, d->model.solver == CAM_CHOICE_SOLVER_RK45 ? "tighten rtol and atol, or lower h_max"
             : "lower h_max, or use solver 'rk45'");
}

const CamFormulation cam_voltage_follower = {
    "consistent", 1, vf_init, vf_set_inputs, vf_advance, vf_outputs, vf_advice, &cam_vf_exchange,
};
