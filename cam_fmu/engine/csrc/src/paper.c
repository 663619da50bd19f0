/* The paper's discrete simulation algorithm (section 3, steps 1-9) as a formulation
 * (physics/formulations/paper.py: PaperScheme; docs/model.md section 7), the order of floating-point
 * operations kept.
 *
 * The calculation step is T = h_max on a fixed grid: a communication step of h is n = round(h / h_max)
 * calculation steps of h / n when h is a whole number of them (to 1e-9 relative), else it is refused
 * (fmi2Discard) naming h_max. The scheme's answer must not depend on the host's step pattern: with
 * T = h / ceil(h / h_max) (the former rule), steps alternating 0.7/0.3 ms gave theta(0.5 s) = 0.719 rad
 * against 2.05 rad for uniform steps. A refused step leaves the state as it was. */
#include <limits.h>
#include <math.h>
#include <stdio.h>

#include "cam_drive.h"

static double quasi_static_current(const CamModel *m, double u, double omega)
{
    return (u - m->c_e * omega) / m->R;
}

/* Largest rate [1/s] of the motor's own dynamics with inertia J (motor.electrical_rate). */
static double electrical_rate(const CamModel *m, double J)
{
    if (m->L > 0.0)
        return m->R / m->L + sqrt(m->c_e * m->c_m / (J * m->L));
    return m->c_e * m->c_m / (m->R * J);
}

/* The cap of the sub-step count: 9e15 where long has 64 bits, LONG_MAX where it has 32 (Windows' LLP64). */
#if LONG_MAX > 9000000000000000
#define RK4_SUBSTEPS_CAP 9000000000000000L
#else
#define RK4_SUBSTEPS_CAP LONG_MAX
#endif

/* RK4 sub-steps that keep one calculation step T inside RK4's stability limit (rate * sub-step <= 2). */
static long rk4_substeps(const CamModel *m, double J, double T)
{
    double n = ceil(T * electrical_rate(m, J) / 2.0);
    return n > 1.0 ? (n < (double)RK4_SUBSTEPS_CAP ? (long)n : RK4_SUBSTEPS_CAP) : 1L;
}

/* RK4 on eq. (12): omega_dot = (c_m u - R M - c_e c_m omega) / (R J), in n sub-steps. */
static double rk4_motor(const CamModel *m, double omega, double M, double J, double u, double T, long n)
{
    double R = m->R, cm = m->c_m, ce = m->c_e, h = T / (double)n, k1, k2, k3, k4;
    long j;
#define RATE(w) ((cm * u - R * M - ce * cm * (w)) / (R * J))
    for (j = 0; j < n; j++) {
        k1 = RATE(omega);
        k2 = RATE(omega + 0.5 * h * k1);
        k3 = RATE(omega + 0.5 * h * k2);
        k4 = RATE(omega + h * k3);
        omega = omega + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
    }
#undef RATE
    return omega;
}

/* RK4 on eqs. (9)-(10) with L > 0 (omega and i), in n sub-steps. */
static void rk4_motor_inductive(const CamModel *m, double *omega, double *i, double M, double J, double u, double T,
                                long n)
{
    double cm = m->c_m, h = T / (double)n, w = *omega, c = *i;
    double a1, a2, a3, a4, b1, b2, b3, b4;
    long j;
#define W_RATE(c_) ((cm * (c_) - M) / J)
#define I_RATE(w_, c_) ((u - m->R * (c_) - m->c_e * (w_)) / m->L)
    for (j = 0; j < n; j++) {
        a1 = W_RATE(c);
        b1 = I_RATE(w, c);
        a2 = W_RATE(c + 0.5 * h * b1);
        b2 = I_RATE(w + 0.5 * h * a1, c + 0.5 * h * b1);
        a3 = W_RATE(c + 0.5 * h * b2);
        b3 = I_RATE(w + 0.5 * h * a2, c + 0.5 * h * b2);
        a4 = W_RATE(c + h * b3);
        b4 = I_RATE(w + h * a3, c + h * b3);
        w += h / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4);
        c += h / 6.0 * (b1 + 2.0 * b2 + 2.0 * b3 + b4);
    }
#undef W_RATE
#undef I_RATE
    *omega = w;
    *i = c;
}

/* Steps 2-8 for one calculation step T [s] under u [V]; CAM_ERR_REJECTED (nothing changed) when it
 * needs more than ``budget`` RK4 sub-steps; the sub-steps taken into *used. */
static int scheme_step(CamDrive *d, double T, double u, long budget, long *used, CamError *err)
{
    const CamModel *m = &d->model;
    CamPaperState *p = &d->paper;
    double drive, shaft = 0.0, net, omega_old, dd[4], s_cam, s1, s_new, v_new, X, tan_a, push, sigma, f;
    long n = rk4_substeps(m, p->J, T);
    int stuck;
    if (n > budget)
        return cam_error(err, CAM_ERR_REJECTED, "the paper formulation needs %ld RK4 sub-steps in one calculation "
                         "step of %g s (motor rate %.3g 1/s, L = %g H), more than max_steps allows: lower h_max, "
                         "raise max_steps, or use formulation 'consistent' (with solver 'etdrk4' for a stiff "
                         "electrical pole)", n, T, electrical_rate(m, p->J), m->L);
    *used = n;
    p->voltage = u;
    drive = m->c_m * (m->L > 0.0 ? p->i : quasi_static_current(m, u, p->omega));
    /* shaft friction with its sign, or stuck this step (stiction, which the paper leaves out) */
    stuck = 0;
    if (p->omega != 0.0) {
        shaft = m->M_f * cam_sign(p->omega);
    } else {
        net = drive - p->M_l;
        if (fabs(net) <= m->M_f)
            stuck = 1;
        else
            shaft = m->M_f * cam_sign(net);
    }
    omega_old = p->omega;
    if (!stuck) {
        p->M = shaft + p->M_l;
        /* step 2: RK4 on eq. (12) with M and J frozen over the step */
        if (m->L > 0.0)
            rk4_motor_inductive(m, &p->omega, &p->i, p->M, p->J, u, T, n);
        else
            p->omega = rk4_motor(m, p->omega, p->M, p->J, u, T, n);
        if (omega_old != 0.0 && p->omega * omega_old < 0.0)
            p->omega = 0.0;   /* friction cannot reverse the motion */
        else if (omega_old == 0.0 && p->omega * shaft < 0.0)
            p->omega = 0.0;
    } else if (m->L > 0.0) {
        p->i = cam_current_at_rest(m, p->i, u, T);
    }
    if (m->L == 0.0)
        p->i = quasi_static_current(m, u, p->omega);
    /* step 3: theta by summation of omega */
    p->theta += p->omega * T;
    /* step 4: profile and backlash law (eqs. 6-8) */
    cam_profile_eval(&m->profile, p->theta, dd);
    s_cam = dd[0];
    s1 = dd[1];
    if (m->c > 0.0)
        s_new = s_cam > p->s + m->c ? s_cam - m->c : (s_cam < p->s - m->c ? s_cam + m->c : p->s);
    else
        s_new = s_cam;
    /* steps 5-6: backward differences */
    v_new = (s_new - p->s) / T;
    p->a = (v_new - p->v) / T;
    p->v = v_new;
    X = (s_new != p->s || m->c == 0.0) ? s1 : 0.0;   /* ds/dtheta of the follower: the profile's while it follows */
    p->s = s_new;
    /* step 7: eqs. (1) and (3) */
    tan_a = s1 / (m->r_b + s_cam);
    p->alpha = atan(tan_a);
    push = m->m * p->a - m->F_gx;
    sigma = cam_sign(p->v);
    f = cam_guide_friction(push * tan_a + m->G_y, tan_a, sigma, m->mu, m->N_g, 0.0);
    p->M_l = (push + sigma * f) * X;
    /* step 8: eq. (4) */
    p->J = m->J_0 + m->m * X * X;
    p->M = m->M_f * cam_sign(p->omega) + p->M_l;
    return CAM_OK;
}

static int paper_init(CamDrive *d, CamError *err)
{
    double unused[CAM_NX];
    const CamModel *m = &d->model;
    const double *v = m->params.v;
    CamPaperState *p = &d->paper;
    double dd[4];
    (void)err;
    cam_initial(&d->model, d->model.params.v[CAM_P_THETA0], 0.0, 0.0, unused, &d->mode);   /* a valid mode in every saved state */
    /* step 1: initial values */
    p->theta = v[CAM_P_THETA0];
    p->omega = v[CAM_P_OMEGA0];
    p->i = m->L > 0.0 ? v[CAM_P_I0] : 0.0;
    p->J = m->J_0;
    p->M = v[CAM_P_OMEGA0] >= 0.0 ? m->M_f : -m->M_f;
    cam_profile_eval(&m->profile, p->theta, dd);
    p->s = dd[0];
    p->v = p->a = p->alpha = 0.0;
    p->voltage = d->u;   /* the input set, before any step (the reference's and the consistent one's) */
    p->M_l = 0.0;
    return CAM_OK;
}

static void paper_set_inputs(CamDrive *d, double u, double omega_ref, double omega_dot_ref)
{
    (void)omega_ref;
    (void)omega_dot_ref;
    if (d->steps_taken == 0)
        d->paper.voltage = u;   /* no step yet: the output shows the input set */
}

static int paper_advance(CamDrive *d, double h, double time, long *steps, CamError *err)
{
    const CamModel *m = &d->model;
    CamPaperState saved = d->paper;
    double ratio = h / m->h_max, n = floor(ratio + 0.5);
    long j, used = 0, taken = 0;
    int status;
    *steps = 0;
    if (n < 1.0 || fabs(ratio - n) > 1e-9 * n)
        return cam_error(err, CAM_ERR_REJECTED, "formulation 'paper' computes on a fixed grid of calculation steps "
                         "of h_max = %g s; a communication step of %g s at t = %g s is not a whole number of them: "
                         "use communication steps that are multiples of h_max, or set h_max to the communication "
                         "step", m->h_max, h, time);
    if (n > (double)m->max_steps)
        return cam_error(err, CAM_ERR_REJECTED, "the paper formulation needs %.0f calculation steps of h_max = %g s "
                         "in one communication step of %g s at t = %g s, more than max_steps = %ld: raise h_max or "
                         "max_steps, or shorten the communication step", n, m->h_max, h, time, m->max_steps);
    for (j = 0; j < (long)n; j++) {
        status = scheme_step(d, h / n, d->u, m->max_steps - used, &taken, err);
        if (status != CAM_OK) {
            d->paper = saved;   /* a refused step leaves the state as before it */
            return status;
        }
        used += taken;
    }
    *steps = used;
    return CAM_OK;
}

/* N [N]: step 7's force along X over cos(alpha), (m a - F_gx + sgn(v) f) / cos(alpha), while the follower follows
 * the profile (it moved in the last calculation step, v != 0, or c = 0); 0 while it rests in the clearance. */
static double paper_contact_force(const CamModel *m, const CamPaperState *p, const double dd[4])
{
    double tan_a = dd[1] / (m->r_b + dd[0]), push = m->m * p->a - m->F_gx, sigma = cam_sign(p->v), f;
    if (p->v == 0.0 && m->c > 0.0)
        return 0.0;
    f = cam_guide_friction(push * tan_a + m->G_y, tan_a, sigma, m->mu, m->N_g, 0.0);
    return cam_normal_force(push + sigma * f, tan_a);
}

static void paper_outputs(CamDrive *d, double out[])
{
    const CamPaperState *p = &d->paper;
    double dd[4];
    CamLoad load;
    cam_profile_eval(&d->model.profile, p->theta, dd);
    load.N = paper_contact_force(&d->model, p, dd);
    load.M = p->M;
    load.J = p->J;
    load.f = 0.0;
    load.v = p->v;
    load.a = p->a;
    load.alpha = p->alpha;
    load.s_cam = dd[0];
    cam_record_outputs(&load, p->omega, p->theta, p->s, p->i, p->voltage, out);
}

static void paper_advice(const CamDrive *d, char *buf, size_t len)
{
    snprintf(buf, len, "the paper formulation (the published steps 1-9, whose eq. (12) lags the follower's inertia "
             "by a calculation step of h_max = %g s) is not trustworthy here: reduce h_max, or use formulation "
             "'consistent'", d->model.h_max);
}

const CamFormulation cam_paper = {
    "paper", 1, paper_init, paper_set_inputs, paper_advance, paper_outputs, paper_advice, NULL, NULL, NULL,
};
