/* Outputs of the consistent formulation and the guards every published state passes: finite, the
 * follower within the clearance, the energy bound (docs/model.md section 9). */
#include <math.h>

#include "cam_model.h"

void cam_outputs(const CamModel *m, const CamMode *mode, const double x[CAM_NX], double u, double omega_dot,
                 int known, double out[])
{
    double theta = x[CAM_THETA], omega = x[CAM_OMEGA];
    double i = m->has_current ? x[CAM_CURRENT] : (u - m->c_e * cam_motor_speed(m, x)) / m->R;
    int engaged = mode->contact != 0;
    double F = cam_train_force_at(m, x, mode->stuck ? 0.0 : omega);
    CamLoad load;
    if (mode->stuck) {
        cam_load(m, theta, 0.0, 0.0, 0.0, engaged, F, &load);
        load.M = m->compliant ? cam_drive_torque(m, x, 0.0, u) : m->c_m * i;   /* static friction takes it all */
        load.v = load.a = 0.0;
    } else {
        if (!known) {
            double dx[CAM_NX];
            cam_rhs(m, mode, x, u, dx);
            omega_dot = dx[CAM_OMEGA];
        }
        cam_load(m, theta, omega, omega_dot, mode->direction, engaged, F, &load);
    }
    cam_record_outputs(&load, omega, theta, engaged ? load.s_cam - m->c * mode->contact : mode->s_free, i, u, out);
    cam_kind_outputs(m, theta, mode->stuck ? 0.0 : omega, out);
    if (m->train) {   /* the end mass (docs/model.md 14.6) */
        out[CAM_O_S_END] = x[CAM_X_END];
        out[CAM_O_V_END] = x[CAM_V_END];
        out[CAM_O_A_END] = (F + m->F_ex) / m->m_end;
        out[CAM_O_F_TRAIN] = F;
    }
    if (m->compliant) {   /* the rotor's side of the shaft; J counts the rotor too, as a rigid drive's does */
        out[CAM_O_J] = load.J + m->J_m;
        out[CAM_O_THETA_M] = theta + x[CAM_TWIST];
        out[CAM_O_OMEGA_M] = x[CAM_OMEGA_M];
        out[CAM_O_M_SHAFT] = cam_drive_torque(m, x, mode->stuck ? 0.0 : omega, u);
    }
}

void cam_record_outputs(const CamLoad *load, double omega, double theta, double s, double i, double voltage,
                        double out[])
{
    out[CAM_O_OMEGA] = omega;
    out[CAM_O_THETA] = theta;
    out[CAM_O_S] = s;
    out[CAM_O_I] = i;
    out[CAM_O_M] = load->M;
    out[CAM_O_J] = load->J;
    out[CAM_O_V] = load->v;
    out[CAM_O_A] = load->a;
    out[CAM_O_ALPHA] = load->alpha;
    out[CAM_O_S_CAM] = load->s_cam;
    out[CAM_O_VOLTAGE] = voltage;
    out[CAM_O_THETA_M] = theta;   /* a rigid drive: the rotor turns with the cam, no shaft torque */
    out[CAM_O_OMEGA_M] = omega;
    out[CAM_O_M_SHAFT] = 0.0;
    out[CAM_O_N_CONTACT] = load->N;
    out[CAM_O_S_END] = s;   /* without a train the end is the follower (outputs.c cam_outputs sets a train's) */
    out[CAM_O_V_END] = load->v;
    out[CAM_O_A_END] = load->a;
    out[CAM_O_F_TRAIN] = 0.0;
    out[CAM_O_PSI] = out[CAM_O_PSI_DOT] = 0.0;   /* an arm's: cam_kind_outputs */
}

/* J: the train's end mass's kinetic energy, its spring's and its weight's potential (docs/model.md 14.6; 0 without). */
static double train_energy(const CamEnergy *e, const double out[])
{
    double stretch = out[CAM_O_S] - out[CAM_O_S_END];
    if (e->k_train == 0.0)
        return 0.0;
    return 0.5 * e->m_end * out[CAM_O_V_END] * out[CAM_O_V_END] + 0.5 * e->k_train * stretch * stretch
           - e->F_ex * out[CAM_O_S_END];
}

/* J: an arm's weight's potential W sin(psi + psi_0) (docs/model.md 16; 0 without: a translating follower's weight is
 * F_gx's). */
static double arm_energy(const CamEnergy *e, const double out[])
{
    return e->W != 0.0 ? e->W * sin(out[CAM_O_PSI] + e->psi_0) : 0.0;
}

/* E_mech [J] of published outputs: kinetic + gravity potential; compliant: the cam side's and the rotor's
 * kinetic energy and the shaft's elastic energy k (theta_m - theta)^2 / 2 (docs/model.md section 12). */
static double mechanical(const CamEnergy *e, const double out[])
{
    double omega = out[CAM_O_OMEGA], twist, omega_m, s = out[CAM_O_S], v = out[CAM_O_V];
    if (e->own_follower && e->arm_length > 0.0) {   /* an arm's (rigid shaft: the rules): about its pivot, 16.3 */
        double psi = out[CAM_O_PSI], L = e->arm_length, rate = out[CAM_O_PSI_DOT];
        return 0.5 * e->J_0 * omega * omega + 0.5 * e->m * rate * rate + L * e->F_spring0 * psi
               + 0.5 * e->k_spring * L * L * psi * psi + arm_energy(e, out) + train_energy(e, out);
    }
    if (e->own_follower) {   /* the cam side's and the follower's kinetic energy, the spring's F0 s + k s^2 / 2 */
        double own = 0.5 * e->J_0 * omega * omega + 0.5 * e->m * v * v + e->F_spring0 * s
                     + 0.5 * e->k_spring * s * s - e->F_gx * s + train_energy(e, out);
        if (e->k_shaft == 0.0)
            return own;
        twist = out[CAM_O_THETA_M] - out[CAM_O_THETA];   /* and a compliant shaft's rotor and elastic energy */
        return own + 0.5 * e->J_m * out[CAM_O_OMEGA_M] * out[CAM_O_OMEGA_M] + 0.5 * e->k_shaft * twist * twist;
    }
    if (e->k_shaft == 0.0)
        return 0.5 * out[CAM_O_J] * omega * omega - e->F_gx * out[CAM_O_S] + train_energy(e, out) + arm_energy(e, out);
    twist = out[CAM_O_THETA_M] - out[CAM_O_THETA];
    omega_m = out[CAM_O_OMEGA_M];
    return 0.5 * (out[CAM_O_J] - e->J_m) * omega * omega + 0.5 * e->J_m * omega_m * omega_m
           + 0.5 * e->k_shaft * twist * twist - e->F_gx * out[CAM_O_S] + train_energy(e, out);
}

void cam_energy_init(CamEnergy *e, const CamModel *m, const double out[])
{
    double i = out[CAM_O_I];
    e->c_e = m->c_e;
    e->L = m->L;
    e->R = m->R;
    e->F_gx = m->F_gx;
    e->ratio = m->c_m / m->c_e;
    e->work_in = 0.0;
    e->work_abs = 0.0;
    e->k_shaft = m->compliant ? m->k_shaft : 0.0;
    e->J_m = m->J_m;
    e->own_follower = m->free_follower && m->formulation == CAM_FORM_CONSISTENT;
    e->J_0 = m->J_0;
    e->m = m->I_f;
    e->arm_length = m->arm ? m->arm_length : 0.0;
    e->k_spring = m->k_spring;
    e->F_spring0 = m->F_spring0;
    e->k_train = m->k_train;
    e->m_end = m->m_end;
    e->F_ex = m->F_ex;
    e->W = m->W;
    e->psi_0 = m->psi_0;
    e->theta = out[CAM_O_THETA_M];
    e->i = i;
    e->e_mech0 = mechanical(e, out);
    e->e_mag0 = 0.5 * e->L * i * i;
}

void cam_energy_step(CamEnergy *e, double u, double h, double theta, double i)
{
    cam_energy_book(e, u * (u * h - e->c_e * (theta - e->theta) - e->L * (i - e->i)) / e->R, theta, i);
}

void cam_energy_book(CamEnergy *e, double w, double theta, double i)
{
    e->work_in += w;
    e->work_abs += fabs(w);
    e->theta = theta;
    e->i = i;
}

void cam_energy_excess(const CamEnergy *e, const double out[], double *excess, double *tolerance)
{
    double i = out[CAM_O_I];
    double e_mech = mechanical(e, out);
    double e_mag = 0.5 * e->L * i * i;
    double lhs = (e_mech - e->e_mech0) + e->ratio * (e_mag - e->e_mag0);
    double rhs = e->ratio * e->work_in;
    double scale = fabs(e->e_mech0) + fabs(e_mech) + e->ratio * (e->work_abs + e->e_mag0 + e_mag) + 1e-12;
    *excess = lhs - rhs;
    *tolerance = CAM_ENERGY_SLACK * scale;
}

int cam_energy_created(const CamEnergy *e, const double out[])
{
    double excess, tolerance;
    cam_energy_excess(e, out, &excess, &tolerance);
    return !(excess <= tolerance && isfinite(excess) && isfinite(tolerance));   /* an overflowed energy: created */
}

int cam_publishable(const CamModel *m, const double out[], CamEnergy *budget, double u, double h)
{
    double total = 0.0, gap;
    int k;
    for (k = 0; k < CAM_N_OUTPUTS; k++)
        total += out[k];
    if (!isfinite(total))
        return CAM_PUBLISH_NOT_FINITE;
    gap = (out[CAM_O_S] - out[CAM_O_S_CAM]) * m->q_scale * cam_follower_length(m);   /* m along the follower's path */
    if (m->closure == CAM_CHOICE_CLOSURE_SPRING ? gap < -2e-12   /* on or off its flank */
        : fabs(gap) > m->c * (1.0 + 1e-9) + (m->free_follower ? 2e-12 : 1e-12))
        return CAM_PUBLISH_CLEARANCE;   /* a free follower touches down 1e-12 m inside a flank (follower.c) */
    if (budget != NULL) {
        cam_energy_step(budget, u, h, out[CAM_O_THETA_M], out[CAM_O_I]);
        if (cam_energy_created(budget, out))
            return CAM_PUBLISH_ENERGY;
    }
    return CAM_PUBLISH_OK;
}
