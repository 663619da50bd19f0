/* The drive's tangent (forward-mode derivatives, written out by hand): the directional derivative of the state
 * derivatives (cam_rhs, model.c) and of the outputs (cam_outputs, outputs.c) of the consistent formulation along a
 * seed of the states and the input u, at a fixed mode. Exact to rounding, no differencing; the FMI 2.0 Model
 * Exchange glue forwards fmi2GetDirectionalDerivative here (fmi/directional.c; docs/fmu.md, "Model Exchange").
 * Every mode of the drive whose cam carries the follower (rigid or compliant, L = 0 or L > 0, engaged with or without
 * guide friction, free in the clearance, stuck; every follower type, kind.c's cam_kind_tangent); a follower of its
 * own: jacobian_follower.c. */
#include <math.h>

#include "cam_model.h"

/* The guide friction f = mu (side n0 + N_g) / (1 - side mu sigma kappa) (cam_guide_friction, model.c) on the branch
 * side (0: the one that holds there) and its tangent *df from those of n0 and kappa. */
static double friction_tangent(const CamModel *m, double n0, double dn0, double kappa, double dkappa, double sigma,
                               double side, double *df)
{
    double f, denominator;
    *df = 0.0;
    if (m->mu == 0.0)
        return 0.0;
    if (side == 0.0) {
        f = m->mu * (n0 + m->N_g) / (1.0 - m->mu * sigma * kappa);
        side = f >= 0.0 && n0 + sigma * kappa * f >= 0.0 ? 1.0 : -1.0;
    }
    denominator = 1.0 - side * m->mu * sigma * kappa;
    f = m->mu * (side * n0 + m->N_g) / denominator;
    *df = (m->mu * side * dn0 + f * side * m->mu * sigma * dkappa) / denominator;
    return f;
}

double cam_flank_tangent(const CamModel *m, const double d[4], double omega, double T, double F, double dir,
                         double side, const double dq[4], double *f_out, double *df_out)
{
    double s1 = d[1], s2 = d[2], dtheta = dq[0], domega = dq[1], ds1, ds2, inertial, dinertial, J, dJ, x0, dx0;
    double sigma, tan_a, dtan, n0, dn0, kappa, dkappa, f, df, base = m->r_b + d[0];
    ds1 = s2 * dtheta;
    ds2 = d[3] * dtheta;
    inertial = m->m * s2 * omega * omega + F;
    dinertial = m->m * (ds2 * omega * omega + 2.0 * s2 * omega * domega) + dq[3];
    J = m->J_0 + m->m * s1 * s1;
    dJ = 2.0 * m->m * s1 * ds1;
    x0 = (T - m->M_f * dir - inertial * s1) / J;
    dx0 = (dq[2] - dinertial * s1 - inertial * ds1 - x0 * dJ) / J;
    *f_out = *df_out = 0.0;
    if (m->mu == 0.0)
        return dx0;
    sigma = cam_sign(s1 * dir);
    tan_a = s1 / base;
    dtan = (ds1 * base - s1 * s1 * dtheta) / (base * base);
    n0 = (inertial + m->m * s1 * x0) * tan_a + m->G_y;
    dn0 = (dinertial + m->m * (ds1 * x0 + s1 * dx0)) * tan_a + (inertial + m->m * s1 * x0) * dtan;
    kappa = m->J_0 / J * tan_a;
    dkappa = m->J_0 * (dtan * J - tan_a * dJ) / (J * J);
    f = friction_tangent(m, n0, dn0, kappa, dkappa, sigma, side, &df);
    *f_out = f;
    *df_out = df;
    return dx0 - sigma * ((df * s1 + f * ds1) * J - f * s1 * dJ) / (J * J);
}

/* The tangent of omega_dot [rad/s3 per seed] at (theta, omega) under the drive torque T with tangents dtheta,
 * domega, dT (cam_omega_dot, model.c's load_terms): on the flank the closing force is gravity's, -F_gx, and the
 * train's F [N] (tangent dF). */
static double omega_dot_tangent(const CamModel *m, const CamMode *mode, const double d[4], double omega, double T,
                                double dtheta, double domega, double dT, double F, double dF)
{
    double dq[4] = {dtheta, domega, dT, dF}, f, df;
    if (!(mode->contact != 0 && m->follower))
        return dT / m->J_0;
    return cam_flank_tangent(m, d, omega, T, F - m->F_gx, mode->direction, m->guide_side ? mode->side : 0.0, dq, &f,
                             &df);
}

double cam_train_tangent(const CamModel *m, double ds, double dv, const double seed[CAM_NX])
{
    return m->train ? cam_train_pull(m, ds, dv, seed[CAM_X_END], seed[CAM_V_END]) : 0.0;
}

void cam_train_rows(const CamModel *m, const double seed[CAM_NX], double dF_rate, double dF_out, double ddx[CAM_NX],
                    double dout[])
{
    ddx[CAM_X_END] = seed[CAM_V_END];
    ddx[CAM_V_END] = dF_rate / m->m_end;
    dout[CAM_O_S_END] = seed[CAM_X_END];
    dout[CAM_O_V_END] = seed[CAM_V_END];
    dout[CAM_O_A_END] = dF_out / m->m_end;
    dout[CAM_O_F_TRAIN] = dF_out;
}

/* The tangent of the motor's torque c_m i (L > 0) or c_m (u - c_e omega_m) / R (L = 0). */
static double torque_tangent(const CamModel *m, double domega_m, double di, double du)
{
    if (m->has_current)
        return m->c_m * di;
    return m->c_m * (du - m->c_e * domega_m) / m->R;
}

int cam_tangent(const CamModel *m, const CamMode *mode, const double x[CAM_NX], double u, const double seed[CAM_NX],
                double du, double ddx[CAM_NX], double dout[], CamError *err)
{
    (void)err;   /* every mode of the rigid and the compliant drive is implemented */
    double d[4], dx[CAM_NX], theta = x[CAM_THETA], omega = x[CAM_OMEGA], dtheta = seed[CAM_THETA];
    double domega = seed[CAM_OMEGA], di = m->has_current ? seed[CAM_CURRENT] : 0.0;
    double dtwist = m->compliant ? seed[CAM_TWIST] : 0.0, domega_m = m->compliant ? seed[CAM_OMEGA_M] : domega;
    double dT_motor = torque_tangent(m, domega_m, di, du), dT, omega_dot = 0.0, domega_dot = 0.0;
    double w, dw, s1, ds1, t, dt, a, da, push, root, i_dot, sigma, f, df, along, dalong, F, dF = 0.0;
    int k, engaged = mode->contact != 0, moving = !mode->stuck;
    cam_rhs(m, mode, x, u, dx);
    if (m->kind != CAM_CHOICE_FOLLOWER_TYPE_TRANSLATING_ROLLER)   /* kind.c: a rigid shaft */
        return cam_kind_tangent(m, mode, x, seed, cam_drive_torque(m, x, omega, u), dT_motor, du, dx[CAM_OMEGA], 0,
                                ddx, dout);
    cam_profile_eval(&m->profile, theta, d);
    for (k = 0; k < CAM_NX; k++)
        ddx[k] = 0.0;
    /* the train's force k (s - x_e) + d (s' omega - v_e) at the cam's speed (0 while stuck) and its tangent */
    F = cam_train_force_at(m, x, moving ? omega : 0.0);
    dF = cam_train_tangent(m, d[1] * dtheta, d[2] * dtheta * (moving ? omega : 0.0) + d[1] * (moving ? domega : 0.0),
                           seed);
    /* the torque on the cam: the shaft's k twist + d (omega_m - omega) (the cam's speed 0 while stuck), else the motor's */
    dT = m->compliant ? m->k_shaft * dtwist + m->d_shaft * (domega_m - (moving ? domega : 0.0)) : dT_motor;
    if (moving) {
        omega_dot = dx[CAM_OMEGA];
        domega_dot = omega_dot_tangent(m, mode, d, omega, cam_drive_torque(m, x, omega, u), dtheta, domega, dT, F,
                                       dF);
        ddx[CAM_THETA] = domega;
        ddx[CAM_OMEGA] = domega_dot;
    }
    if (m->compliant) {
        ddx[CAM_TWIST] = domega_m - domega;
        ddx[CAM_OMEGA_M] = (dT_motor - dT) / m->J_m;
    }
    i_dot = m->has_current ? (du - m->R * di - m->c_e * domega_m) / m->L : 0.0;
    ddx[CAM_CURRENT] = i_dot;
    /* the outputs (cam_outputs over cam_load): the load at the cam's speed and acceleration, 0 while stuck */
    w = moving ? omega : 0.0;
    dw = moving ? domega : 0.0;
    s1 = d[1];
    ds1 = d[2] * dtheta;
    t = s1 / (m->r_b + d[0]);
    dt = (ds1 * (m->r_b + d[0]) - s1 * s1 * dtheta) / ((m->r_b + d[0]) * (m->r_b + d[0]));
    root = sqrt(1.0 + t * t);
    for (k = 0; k < CAM_N_OUTPUTS; k++)
        dout[k] = 0.0;
    dout[CAM_O_OMEGA] = domega;
    dout[CAM_O_THETA] = dtheta;
    dout[CAM_O_I] = m->has_current ? di : (du - m->c_e * domega_m) / m->R;
    dout[CAM_O_VOLTAGE] = du;
    dout[CAM_O_ALPHA] = dt / (1.0 + t * t);
    dout[CAM_O_S_CAM] = s1 * dtheta;
    dout[CAM_O_S] = engaged ? s1 * dtheta : 0.0;   /* free in the clearance: s_free, held */
    if (engaged) {
        a = d[2] * w * w + s1 * omega_dot;
        da = d[2] * dtheta * w * w + 2.0 * d[2] * w * dw + ds1 * omega_dot + s1 * domega_dot;
        push = m->m * a - m->F_gx + F;   /* cam_load: the friction at the axial force, on the branch that holds */
        sigma = cam_sign(s1 * (moving ? mode->direction : 0.0));
        f = friction_tangent(m, push * t + m->G_y, (m->m * da + dF) * t + push * dt, t, dt, sigma, 0.0, &df);
        along = push + sigma * f;
        dalong = m->m * da + dF + sigma * df;
        dout[CAM_O_J] = 2.0 * m->m * s1 * ds1;
        dout[CAM_O_V] = ds1 * w + s1 * dw;
        dout[CAM_O_A] = da;
        dout[CAM_O_M] = dalong * s1 + along * ds1;
        dout[CAM_O_N_CONTACT] = dalong * root + along * t * dt / root;
    }
    if (mode->stuck)   /* static friction takes the whole torque */
        dout[CAM_O_M] = m->compliant ? dT : dT_motor;
    dout[CAM_O_THETA_M] = dtheta + dtwist;
    dout[CAM_O_OMEGA_M] = domega_m;
    dout[CAM_O_M_SHAFT] = m->compliant ? dT : 0.0;
    dout[CAM_O_S_END] = dout[CAM_O_S];   /* without a train the end is the follower */
    dout[CAM_O_V_END] = dout[CAM_O_V];
    dout[CAM_O_A_END] = dout[CAM_O_A];
    if (m->train)
        cam_train_rows(m, seed, dF, dF, ddx, dout);
    return CAM_OK;
}
