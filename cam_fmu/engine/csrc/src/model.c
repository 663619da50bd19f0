/* The drive's constants and its physics at one instant (docs/model.md sections 3-5): the load terms,
 * the guide friction's exact solve, omega_dot, the side force, the load, the motor torque.
 *
 * Ported from the former Python engine's kernel with the order of every floating-point
 * operation kept, so that results agree with it to the last bit. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cam_model.h"

#define TWO_PI (2.0 * 3.141592653589793)

/* The intermediate terms of the drive equation at one state. */
typedef struct {
    double d[4];                /* s, s', s'', s''' */
    double x0, J, sigma, f, n0, kappa;
} Terms;

double cam_normal_force(double along_x, double tan_a)
{
    return along_x * sqrt(1.0 + tan_a * tan_a);
}

double cam_guide_friction(double n0, double kappa, double sigma, double mu, double n_support, double side)
{
    double sk, f;
    if (mu == 0.0)
        return 0.0;
    if (side != 0.0)
        return mu * (side * n0 + n_support) / (1.0 - side * mu * sigma * kappa);
    sk = sigma * kappa;
    f = mu * (n0 + n_support) / (1.0 - mu * sk);
    if (f >= 0.0 && n0 + sk * f >= 0.0)
        return f;
    return mu * (n_support - n0) / (1.0 + mu * sk);
}

/* x0 = the frictionless omega_dot [rad/s2]; with guide friction J, sigma, f, n0, kappa too. */
static void load_terms(const CamModel *m, double theta, double omega, double drive, double direction, double side,
                       double axial, Terms *t)
{
    double s, s1, mass, J, inertial, tan_a;
    cam_profile_eval(&m->profile, theta, t->d);
    s = t->d[0];
    s1 = t->d[1];
    mass = m->m;
    J = m->J_0 + mass * s1 * s1;
    inertial = mass * t->d[2] * omega * omega - m->F_gx + axial;   /* N: the profile's curvature, gravity, train */
    t->J = J;
    t->x0 = (drive - inertial * s1) / J;
    if (m->mu == 0.0)
        return;
    t->sigma = cam_sign(s1 * direction);
    tan_a = s1 / (m->r_b + s);
    t->n0 = (inertial + mass * s1 * t->x0) * tan_a + m->G_y;
    t->kappa = m->J_0 / J * tan_a;
    t->f = cam_guide_friction(t->n0, t->kappa, t->sigma, m->mu, m->N_g, side);
}

double cam_omega_dot(const CamModel *m, double theta, double omega, double torque, double direction, int engaged,
                     double side, double axial)
{
    Terms t;
    double drive = torque - m->M_f * direction, q[4];
    CamKindBranch branch;
    if (!(engaged && m->follower))
        return drive / m->J_0;
    if (m->kind != CAM_CHOICE_FOLLOWER_TYPE_TRANSLATING_ROLLER) {   /* kind.c: q, I_f, dV/dq, its friction */
        cam_kind_eval(m, theta, q);
        return cam_kind_branch(m, q, omega, drive, direction, side, cam_kind_slope(m, q[0]) + axial / m->q_scale,
                               &branch);   /* the train's force along s: an arm's torque along q over q_scale */
    }
    load_terms(m, theta, omega, drive, direction, side, axial, &t);
    if (m->mu == 0.0)
        return t.x0;
    return t.x0 - t.sigma * t.f * t.d[1] / t.J;
}

double cam_side_force(const CamModel *m, double theta, double omega, double torque, double direction, double side,
                      double axial)
{
    Terms t;
    double q[4];
    CamKindBranch branch;
    if (m->mu == 0.0 || !m->follower)
        return 0.0;
    if (m->kind != CAM_CHOICE_FOLLOWER_TYPE_TRANSLATING_ROLLER) {   /* P: its sign is the kind's friction branch */
        cam_kind_eval(m, theta, q);
        cam_kind_branch(m, q, omega, torque - m->M_f * direction, direction, side,
                        cam_kind_slope(m, q[0]) + axial / m->q_scale, &branch);
        return branch.P;
    }
    load_terms(m, theta, omega, torque - m->M_f * direction, direction, side, axial, &t);
    return t.n0 + t.sigma * t.kappa * t.f;
}

double cam_torque(const CamModel *m, double omega, double i, double u)
{
    if (m->has_current)
        return m->c_m * i;
    return m->c_m * (u - m->c_e * omega) / m->R;
}

double cam_motor_speed(const CamModel *m, const double x[CAM_NX])
{
    return m->compliant ? x[CAM_OMEGA_M] : x[CAM_OMEGA];
}

double cam_drive_torque(const CamModel *m, const double x[CAM_NX], double omega, double u)
{
    if (m->compliant)
        return m->k_shaft * x[CAM_TWIST] + m->d_shaft * (x[CAM_OMEGA_M] - omega);
    return cam_torque(m, omega, x[CAM_CURRENT], u);
}

double cam_train_force(const CamModel *m, double theta, double omega, double x_e, double v_e)
{
    double d[4];
    if (!m->train)
        return 0.0;
    cam_profile_eval(&m->profile, theta, d);
    return cam_train_pull(m, d[0], d[1] * omega, x_e, v_e);
}

double cam_train_force_at(const CamModel *m, const double x[CAM_NX], double omega)
{
    return cam_train_force(m, x[CAM_THETA], omega, x[CAM_X_END], x[CAM_V_END]);
}

/* The end mass's rates (docs/model.md 14.6) into dx: x_e' = v_e, m_end v_e' = F_train + F_ex; held at 0 without a
 * train. */
static void train_rhs(const CamModel *m, const double x[CAM_NX], double F, double dx[CAM_NX])
{
    dx[CAM_X_END] = m->train ? x[CAM_V_END] : 0.0;
    dx[CAM_V_END] = m->train ? (F + m->F_ex) / m->m_end : 0.0;
}

double cam_current_at_rest(const CamModel *m, double i, double u, double dt)
{
    double target = u / m->R;
    return target + (i - target) * exp(-dt * m->R / m->L);
}

void cam_rhs(const CamModel *m, const CamMode *mode, const double x[CAM_NX], double u, double dx[CAM_NX])
{
    double theta = x[CAM_THETA], omega = x[CAM_OMEGA], i = x[CAM_CURRENT], drive, F;
    if (m->follower_states) {   /* the follower's gap and rate are states (voltage_follower.c) */
        cam_vf_rhs(m, mode, x, u, dx);
        return;
    }
    drive = cam_drive_torque(m, x, omega, u);   /* the motor's or a compliant shaft's (x[CAM_OMEGA] 0 while stuck) */
    F = cam_train_force_at(m, x, mode->stuck ? 0.0 : omega);
    if (mode->stuck) {
        dx[CAM_THETA] = 0.0;
        dx[CAM_OMEGA] = 0.0;
    } else {
        dx[CAM_THETA] = omega;
        dx[CAM_OMEGA] = cam_omega_dot(m, theta, omega, drive, mode->direction, mode->contact != 0,
                                      m->guide_side ? mode->side : 0.0, F);
    }
    if (m->compliant) {   /* the two-mass drive (docs/model.md 12): the rotor J_m omega_m' = c_m i - M_shaft */
        double omega_motor = x[CAM_OMEGA_M];
        train_rhs(m, x, F, dx);
        dx[CAM_TWIST] = omega_motor - omega;
        dx[CAM_OMEGA_M] = (cam_torque(m, omega_motor, i, u) - drive) / m->J_m;
        dx[CAM_CURRENT] = m->has_current ? (u - m->R * i - m->c_e * omega_motor) / m->L : 0.0;
        return;
    }
    dx[CAM_CURRENT] = m->has_current ? (u - m->R * i - m->c_e * omega) / m->L : 0.0;
    if (m->train) {   /* a train: its end mass moves, the rigid shaft's slots are held */
        dx[CAM_TWIST] = dx[CAM_OMEGA_M] = 0.0;
        train_rhs(m, x, F, dx);
    }
}

void cam_load(const CamModel *m, double theta, double omega, double omega_dot, double direction, int engaged,
              double axial, CamLoad *out)
{
    double d[4], s, s1, tan_a, shaft, v, a, sigma, push, f;
    if (m->kind != CAM_CHOICE_FOLLOWER_TYPE_TRANSLATING_ROLLER) {   /* kind.c: the train's force joins P */
        cam_kind_load(m, theta, omega, omega_dot, direction, engaged, axial, out);
        return;
    }
    cam_profile_eval(&m->profile, theta, d);
    s = d[0];
    s1 = d[1];
    tan_a = s1 / (m->r_b + s);
    shaft = m->M_f * direction;
    out->alpha = atan(tan_a);
    out->s_cam = s;
    if (!engaged) {
        out->M = shaft;
        out->J = m->J_0;
        out->f = out->v = out->a = out->N = 0.0;
        return;
    }
    v = s1 * omega;
    a = d[2] * omega * omega + s1 * omega_dot;
    sigma = cam_sign(s1 * direction);
    push = m->m * a - m->F_gx + axial;   /* N: axial force without friction */
    f = cam_guide_friction(push * tan_a + m->G_y, tan_a, sigma, m->mu, m->N_g, 0.0);
    out->M = shaft + (push + sigma * f) * s1;
    out->N = cam_normal_force(push + sigma * f, tan_a);
    out->J = m->J_0 + m->m * s1 * s1;
    out->f = f;
    out->v = v;
    out->a = a;
}

double cam_breakaway_direction(const CamModel *m, double theta, double torque, int engaged_forward,
                               int engaged_backward, double axial)
{
    if (cam_omega_dot(m, theta, 0.0, torque, 1.0, engaged_forward, 0.0, axial) > 0.0)
        return 1.0;
    if (cam_omega_dot(m, theta, 0.0, torque, -1.0, engaged_backward, 0.0, axial) < 0.0)
        return -1.0;
    return 0.0;
}

/* ------------------------------------------------------------------ construction */

#define INV_PHI ((sqrt(5.0) - 1.0) / 2.0)

static double pressure_angle(const CamProfile *p, double theta, double r_b)
{
    double d[4];
    cam_profile_eval(p, theta, d);
    return atan(d[1] / (r_b + d[0]));
}

static int ascending(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : (x > y ? 1 : 0);
}

/* (max |alpha| [rad], theta where it is): a grid of 4096 angles and the breakpoints, refined by
 * golden-section search around the grid's maximum (cam_program.ProgramBase.max_pressure_angle). */
static int max_pressure_angle(const CamProfile *p, double r_b, double *best, double *best_t, CamError *err)
{
    const int n = 4096;
    size_t count = (size_t)n + p->n_points, k, used = 0, at = 0;
    double *grid = malloc(count * sizeof *grid), step = TWO_PI / n, a, b, c, dd, fc, fd, alpha;
    if (grid == NULL)
        return cam_error(err, CAM_ERR_MEMORY, "out of memory checking the pressure angle");
    for (k = 0; k < (size_t)n; k++)
        grid[k] = (double)k * step;
    for (k = 0; k < p->n_points; k++)
        grid[n + k] = p->points[k];
    qsort(grid, count, sizeof *grid, ascending);
    for (k = 0; k < count; k++)
        if (used == 0 || grid[k] != grid[used - 1])
            grid[used++] = grid[k];
    *best = -1.0;
    for (k = 0; k < used; k++) {
        alpha = fabs(pressure_angle(p, grid[k], r_b));
        if (alpha > *best) {
            *best = alpha;
            at = k;
        }
    }
    *best_t = grid[at];
    a = grid[at > 0 ? at - 1 : 0];
    b = grid[at + 1 < used ? at + 1 : used - 1];
    free(grid);
    c = b - INV_PHI * (b - a);
    dd = a + INV_PHI * (b - a);
    fc = fabs(pressure_angle(p, c, r_b));
    fd = fabs(pressure_angle(p, dd, r_b));
    while (b - a > 1e-12) {
        if (fc >= fd) {
            b = dd;
            dd = c;
            fd = fc;
            c = b - INV_PHI * (b - a);
            fc = fabs(pressure_angle(p, c, r_b));
        } else {
            a = c;
            c = dd;
            fc = fd;
            dd = a + INV_PHI * (b - a);
            fd = fabs(pressure_angle(p, dd, r_b));
        }
    }
    c = 0.5 * (a + b);
    alpha = fabs(pressure_angle(p, c, r_b));
    if (alpha > *best) {
        *best = alpha;
        *best_t = c;
    }
    return CAM_OK;
}

static int has_text(const char *text)
{
    if (text == NULL)
        return 0;
    for (; *text; text++)
        if (!(*text == ' ' || (*text >= '\t' && *text <= '\r') || (unsigned char)*text == 0x1c
              || (unsigned char)*text == 0x1d || (unsigned char)*text == 0x1e || (unsigned char)*text == 0x1f))
            return 1;
    return 0;
}

static void law_T(const CamParams *p, int law_index, int first_T, double T[6])
{
    const double *preset = cam_preset_T((int)p->v[law_index]);
    int k;
    for (k = 0; k < 6; k++)
        T[k] = preset != NULL ? preset[k] : p->v[first_T + k];
}

static int build_program(CamModel *model, CamError *err)
{
    const CamParams *p = &model->params;
    CamError why;
    double rise[6], ret[6];
    if (has_text(p->motion_table)) {
        if (cam_profile_init_table(&model->profile, p->motion_table, strlen(p->motion_table), &why) != CAM_OK)
            return cam_error(err, CAM_ERR_PARAMETER, "parameter 'motion_table': %s", why.message);
        return CAM_OK;
    }
    law_T(p, CAM_P_RISE_LAW, CAM_P_RISE_T1, rise);
    law_T(p, CAM_P_RETURN_LAW, CAM_P_RETURN_T1, ret);
    if (cam_profile_init_laws(&model->profile, rise, ret, p->v[CAM_P_LIFT], p->v[CAM_P_RISE_ANGLE],
                              p->v[CAM_P_UPPER_DWELL], p->v[CAM_P_RETURN_ANGLE], p->v[CAM_P_LOWER_DWELL], &why)
        != CAM_OK)
        return cam_error(err, CAM_ERR_PARAMETER, "parameters 'rise_law'/'rise_T1'..'rise_T6', "
                        "'return_law'/'return_T1'..'return_T6': %s", why.message);
    return CAM_OK;
}

/* The sine or cosine `value` of a mounting angle [rad], exactly 0 where the angle makes it 0 to within a few of
 * its rounding units (parameters.mounting_component; docs/model.md 4.1): sin(pi) = 1.2e-16 is no force. */
static double mounting(double value, double angle)
{
    return fabs(value) <= CAM_MOUNTING_ZERO * fmax(1.0, fabs(angle)) ? 0.0 : value;
}

int cam_model_init(CamModel *model, const CamParams *params, CamError *err)
{
    const double *v;
    double G;
    int status;
    memset(model, 0, sizeof *model);
    if ((status = cam_params_check(params, err)) != CAM_OK)
        return status;
    if ((status = cam_params_copy(&model->params, params, err)) != CAM_OK)
        return status;
    if ((status = build_program(model, err)) != CAM_OK) {
        cam_model_free(model);
        return status;
    }
    v = model->params.v;
    model->R = v[CAM_P_R];
    model->L = v[CAM_P_INDUCTANCE] != 0.0 ? v[CAM_P_L] : 0.0;
    model->c_e = v[CAM_P_C_E];
    model->c_m = v[CAM_P_C_M];
    model->J_m = v[CAM_P_J_M];
    model->k_shaft = v[CAM_P_K_SHAFT];
    model->d_shaft = v[CAM_P_D_SHAFT];
    model->compliant = model->k_shaft > 0.0;
    model->J_0 = model->compliant ? v[CAM_P_J_CAM] : model->J_m + v[CAM_P_J_CAM];
    model->M_f = v[CAM_P_SHAFT_FRICTION] != 0.0 ? v[CAM_P_M_F] : 0.0;
    model->m = v[CAM_P_FOLLOWER_INERTIA] != 0.0 ? v[CAM_P_M] : 0.0;
    G = v[CAM_P_GRAVITY] != 0.0 ? v[CAM_P_G] : 0.0;
    model->F_gx = G * mounting(sin(v[CAM_P_GAMMA]), v[CAM_P_GAMMA]) * mounting(cos(v[CAM_P_BETA]), v[CAM_P_BETA]);
    model->G_y = G * mounting(sin(v[CAM_P_GAMMA]), v[CAM_P_GAMMA]) * mounting(sin(v[CAM_P_BETA]), v[CAM_P_BETA]);
    model->N_g = fabs(G * mounting(cos(v[CAM_P_GAMMA]), v[CAM_P_GAMMA]));
    model->mu = v[CAM_P_GUIDE_FRICTION] != 0.0 ? v[CAM_P_MU] : 0.0;
    model->r_b = v[CAM_P_R_B];
    model->c = v[CAM_P_BACKLASH] != 0.0 ? v[CAM_P_C] : 0.0;
    model->k_train = v[CAM_P_K_TRAIN];   /* the follower train (docs/model.md 14.6; rules: the follower on the cam) */
    model->train = model->k_train > 0.0;
    model->d_train = model->train ? v[CAM_P_D_TRAIN] : 0.0;
    model->m_end = model->train ? v[CAM_P_M_END] : 0.0;
    model->F_ex = v[CAM_P_GRAVITY] != 0.0 ? model->m_end * CAM_G_N * mounting(sin(v[CAM_P_GAMMA]), v[CAM_P_GAMMA])
                                             * mounting(cos(v[CAM_P_BETA]), v[CAM_P_BETA]) : 0.0;   /* N: its weight */
    cam_kind_init(model);   /* the follower's type (kind.c, docs/model.md 16; an arm's torsional train) */
    model->train_rate = model->train ? sqrt(model->k_train / model->m_end) + model->d_train / model->m_end : 0.0;
    model->follower = model->I_f != 0.0 || model->F_gx != 0.0 || model->W != 0.0 || model->mu != 0.0 || model->train;
    model->has_current = model->L > 0.0;
    model->backlash = model->c > 0.0;
    model->guide_side = model->mu > 0.0 && model->follower;
    model->nx = (model->has_current ? 3 : 2) + (model->compliant ? 2 : 0) + (model->train ? 2 : 0);
    model->formulation = (int)v[CAM_P_DRIVE] == CAM_CHOICE_DRIVE_SPEED ? CAM_FORM_SPEED
                         : (CamFormulationId)(int)v[CAM_P_FORMULATION];
    model->solver = (int)v[CAM_P_SOLVER];
    model->h_max = v[CAM_P_H_MAX];
    model->rtol = v[CAM_P_RTOL];
    model->atol = v[CAM_P_ATOL];
    model->max_steps = (long)v[CAM_P_MAX_STEPS];
    model->feature_angle = model->profile.feature_angle;
    model->lift_scale = model->profile.kind == CAM_PROGRAM_LAWS ? model->profile.lift : 0.0;
    if (model->profile.kind == CAM_PROGRAM_TABLE) {
        size_t k;
        for (k = 0; k < model->profile.table.n; k++)
            model->lift_scale = fmax(model->lift_scale, fabs(model->profile.table.lift[k]));
    }
    model->closure = (int)v[CAM_P_CLOSURE];
    model->k_spring = model->closure == CAM_CHOICE_CLOSURE_SPRING ? v[CAM_P_K_SPRING] : 0.0;
    model->F_spring0 = model->closure == CAM_CHOICE_CLOSURE_SPRING ? v[CAM_P_F_SPRING0] : 0.0;
    model->restitution = v[CAM_P_RESTITUTION];
    model->free_follower = cam_own_follower(v);   /* physics/rules.py OWN_FOLLOWER (docs/model.md 13) */
    model->prescribed = model->formulation == CAM_FORM_SPEED;
    model->follower_states = model->free_follower && (model->formulation == CAM_FORM_CONSISTENT || model->prescribed);
    model->slots = model->follower_states ? CAM_NX : (model->compliant || model->train ? CAM_NX_SHAFT : CAM_NX_RIGID);
    if (model->follower_states)
        model->nx += 2;   /* its gap and rate (0 on a flank) */
    if ((status = cam_check_rules(v, err)) != CAM_OK                  /* physics/rules.py RULES, generated */
        || (status = cam_kind_check(model, err)) != CAM_OK) {      /* then geometry an arm or a face cannot have */
        cam_model_free(model);
        return status;
    }
    /* the roller's self-locking in its guide (another type's friction: cam_kind_check's wedge) */
    if (model->mu > 0.0 && model->kind == CAM_CHOICE_FOLLOWER_TYPE_TRANSLATING_ROLLER) {
        double alpha = 0.0, theta = 0.0, locking;
        char a[40], b[40];
        if ((status = max_pressure_angle(&model->profile, model->r_b, &alpha, &theta, err)) != CAM_OK) {
            cam_model_free(model);
            return status;
        }
        locking = model->mu * tan(alpha);
        if (locking >= 1.0 - 1e-12) {
            status = cam_error(err, CAM_ERR_PARAMETER,
                              "parameters 'mu' = %s and 'r_b' = %s m make the follower self-lock in its guide: "
                              "mu tan(alpha) = %.4g >= 1 at theta = %.4g deg (pressure angle alpha = %.4g deg); "
                              "allowed: mu tan(max alpha) < 1 (lower mu below %.4g or raise r_b)",
                              cam_num(model->mu, a), cam_num(model->r_b, b), locking,
                              theta * (180.0 / 3.141592653589793), alpha * (180.0 / 3.141592653589793),
                              1.0 / tan(alpha));
            cam_model_free(model);
            return status;
        }
    }
    return CAM_OK;
}

void cam_model_free(CamModel *model)
{
    cam_profile_free(&model->profile);
    cam_params_free(&model->params);
}
