/* The follower's kind in the drive (docs/model.md 16; physics/kind_drive.py, the reference): a translating flat
 * face, or an arm about a pivot with a roller or a flat face. One degree of freedom, theta: the follower's coordinate
 * q = s (translating) or psi = lift_angle s / lift (an arm), its inertia I_f = m or J_arm + m L^2, its potential
 * V = -F_gx s or W sin(psi + psi_0); P = I_f (q'' omega^2 + q' omega_dot) + dV/dq moves it, M = M_f sgn + P q'. */
#include <math.h>

#include "cam_model.h"

#define PI 3.141592653589793

void cam_kind_eval(const CamModel *m, double theta, double q[4])
{
    int k;
    cam_profile_eval(&m->profile, theta, q);
    if (m->arm)
        for (k = 0; k < 4; k++)
            q[k] = m->q_scale * q[k];
}

double cam_kind_slope(const CamModel *m, double q)
{
    if (m->arm)
        return m->W != 0.0 ? m->W * cos(q + m->psi_0) : 0.0;
    return -m->F_gx;
}

double cam_kind_potential(const CamModel *m, double q, double s)
{
    return m->arm ? m->W * sin(q + m->psi_0) : -m->F_gx * s;
}

void cam_kind_outputs(const CamModel *m, double theta, double omega, double out[])
{
    double q[4];
    if (!m->arm)
        return;
    cam_kind_eval(m, theta, q);
    out[CAM_O_PSI] = q[0];
    out[CAM_O_PSI_DOT] = q[1] * omega;
}

void cam_kind_load(const CamModel *m, double theta, double omega, double omega_dot, double direction, int engaged,
                   CamLoad *out)
{
    double q[4], P, alpha = 0.0, N;
    int k;
    cam_profile_eval(&m->profile, theta, q);
    out->s_cam = q[0];
    if (m->arm)
        for (k = 0; k < 4; k++)
            q[k] = m->q_scale * q[k];
    out->alpha = 0.0;
    out->f = 0.0;
    if (!engaged) {
        out->M = m->M_f * direction;
        out->J = m->J_0;
        out->v = out->a = out->N = 0.0;
        return;
    }
    P = m->I_f * (q[2] * omega * omega + q[1] * omega_dot) + cam_kind_slope(m, q[0]);
    N = P;
    if (m->kind == CAM_CHOICE_FOLLOWER_TYPE_OSCILLATING_ROLLER) {   /* the rocker's triangle (15.1) */
        double delta = m->delta0 + q[0], d = m->pivot_distance, L = m->arm_length;
        alpha = atan2(d * cos(delta) - L * (1.0 - q[1]), d * sin(delta));
        N = P / (L * cos(alpha));
    } else if (m->kind == CAM_CHOICE_FOLLOWER_TYPE_OSCILLATING_FLAT) {   /* the face at l from the pivot (15.2) */
        N = P * (1.0 - q[1]) / (m->pivot_distance * cos(m->delta0 + q[0]));
    }
    out->alpha = alpha;
    out->M = m->M_f * direction + P * q[1];
    out->J = m->J_0 + m->I_f * q[1] * q[1];
    out->N = N;
    out->v = q[1] / m->q_scale * omega;   /* the law's lift rates, as the reference's */
    out->a = q[2] / m->q_scale * omega * omega + q[1] / m->q_scale * omega_dot;
}

/* The refusals of geometry that cannot be built whose limits are closed forms (kinematics/follower_checks.py and
 * the cam classes' constructors): the arm cannot reach the cam, the pivot inside the base circle, an arm turned to
 * the pressure angle's 90 deg or a face past the perpendicular. */
int cam_kind_check(const CamModel *m, CamError *err)
{
    double L = m->arm_length, d = m->pivot_distance, r_b = m->r_b, lift_angle = m->params.v[CAM_P_LIFT_ANGLE], top;
    char a[40], b[40], c[40];
    if (m->kind == CAM_CHOICE_FOLLOWER_TYPE_OSCILLATING_ROLLER) {
        if (!(fabs(d - L) < r_b && r_b < d + L))
            return cam_error(err, CAM_ERR_PARAMETER, "parameters 'arm_length' = %s m, 'pivot_distance' = %s m: the arm "
                             "cannot reach the cam; allowed |d - L| < r_b < d + L with 'r_b' = %s m",
                             cam_num(L, a), cam_num(d, b), cam_num(r_b, c));
        top = PI - m->delta0;
        if (lift_angle >= top)
            return cam_error(err, CAM_ERR_PARAMETER, "parameter 'lift_angle' = %s rad turns the arm to 180 deg at the "
                             "pivot, where the pressure angle reaches 90 deg; allowed < pi - delta0 = %.6g rad",
                             cam_num(lift_angle, a), top);
    } else if (m->kind == CAM_CHOICE_FOLLOWER_TYPE_OSCILLATING_FLAT) {
        if (!(r_b < d))
            return cam_error(err, CAM_ERR_PARAMETER, "parameter 'pivot_distance' = %s m lies inside the base circle; "
                             "allowed > r_b = %s m", cam_num(d, a), cam_num(r_b, b));
        top = 0.5 * PI - m->delta0;
        if (lift_angle >= top)
            return cam_error(err, CAM_ERR_PARAMETER, "parameter 'lift_angle' = %s rad turns the face past the "
                             "perpendicular to the cam axis; allowed < pi/2 - delta0 = %.6g rad (sin delta0 = r_b / d)",
                             cam_num(lift_angle, a), top);
    }
    return CAM_OK;
}

void cam_kind_init(CamModel *m)
{
    const double *v = m->params.v;
    double L = v[CAM_P_ARM_LENGTH], d = v[CAM_P_PIVOT_DISTANCE], gamma = v[CAM_P_GAMMA], r_b = m->r_b, in_plane;
    m->kind = (int)v[CAM_P_FOLLOWER_TYPE];
    m->arm = m->kind == CAM_CHOICE_FOLLOWER_TYPE_OSCILLATING_ROLLER
             || m->kind == CAM_CHOICE_FOLLOWER_TYPE_OSCILLATING_FLAT;
    m->I_f = m->m;
    m->q_scale = 1.0;
    if (!m->arm)
        return;
    m->arm_length = L;
    m->pivot_distance = d;
    m->q_scale = v[CAM_P_LIFT_ANGLE] / v[CAM_P_LIFT];
    m->I_f = (v[CAM_P_FOLLOWER_INERTIA] != 0.0 ? v[CAM_P_J_ARM] : 0.0) + m->m * L * L;
    in_plane = fabs(sin(gamma)) <= CAM_MOUNTING_ZERO * fmax(1.0, fabs(gamma)) ? 0.0 : sin(gamma);
    m->W = v[CAM_P_GRAVITY] != 0.0
           ? (v[CAM_P_G] * L + v[CAM_P_M_ARM] * CAM_G_N * v[CAM_P_R_CM_ARM]) * in_plane : 0.0;
    m->psi_0 = v[CAM_P_PSI_0];
    m->F_gx = m->G_y = m->N_g = 0.0;   /* an arm's weight is W's torque (beta is refused with gravity) */
    if (m->kind == CAM_CHOICE_FOLLOWER_TYPE_OSCILLATING_ROLLER) {   /* cam_kind_check refuses the arm out of reach */
        if (fabs(d - L) < r_b && r_b < d + L)
            m->delta0 = acos((d * d + L * L - r_b * r_b) / (2.0 * d * L));
    } else {
        m->delta0 = asin(fmin(1.0, r_b / d));
    }
}

/* d(alpha) and d(N) [rad, N per the seed] of cam_kind_load's contact at q (q[4]) for P, dP, dtheta. */
static void contact_tangent(const CamModel *m, const double q[4], double P, double dP, double dtheta, double *dalpha,
                            double *dN)
{
    double delta = m->delta0 + q[0], d = m->pivot_distance, L = m->arm_length, c = cos(delta), sn = sin(delta);
    *dalpha = 0.0;
    *dN = dP;
    if (m->kind == CAM_CHOICE_FOLLOWER_TYPE_OSCILLATING_ROLLER) {
        double Y = d * c - L * (1.0 - q[1]), X = d * sn, alpha = atan2(Y, X);
        double dY = (-d * sn * q[1] + L * q[2]) * dtheta, dX = d * c * q[1] * dtheta, ca = cos(alpha);
        *dalpha = (X * dY - Y * dX) / (X * X + Y * Y);
        *dN = dP / (L * ca) + P * sin(alpha) * *dalpha / (L * ca * ca);
    } else if (m->kind == CAM_CHOICE_FOLLOWER_TYPE_OSCILLATING_FLAT) {
        *dN = (dP * (1.0 - q[1]) - P * q[2] * dtheta) / (d * c) + P * (1.0 - q[1]) * sn * q[1] * dtheta / (d * c * c);
    }
}

int cam_kind_tangent(const CamModel *m, const CamMode *mode, const double x[CAM_NX], const double seed[CAM_NX],
                     double dT, double du, double omega_dot, double ddx[CAM_NX], double dout[])
{
    double q[4], theta = x[CAM_THETA], dtheta = seed[CAM_THETA], domega = seed[CAM_OMEGA];
    double di = m->has_current ? seed[CAM_CURRENT] : 0.0, w, dw, B, dB, J, dJ, V2, domega_dot = 0.0, P, dP;
    double k = m->q_scale, dalpha, dN;
    int n, moving = !mode->stuck, engaged = mode->contact != 0;
    cam_kind_eval(m, theta, q);
    V2 = m->arm && m->W != 0.0 ? -m->W * sin(q[0] + m->psi_0) : 0.0;   /* d2V/dq2 */
    for (n = 0; n < CAM_NX; n++)
        ddx[n] = 0.0;
    if (!moving)
        omega_dot = 0.0;
    w = moving ? x[CAM_OMEGA] : 0.0;
    dw = moving ? domega : 0.0;
    J = m->J_0 + m->I_f * q[1] * q[1];
    dJ = 2.0 * m->I_f * q[1] * q[2] * dtheta;
    if (moving) {   /* J omega_dot = T - M_f d - (I_f q'' w^2 + V'(q)) q' */
        B = m->I_f * q[2] * w * w + cam_kind_slope(m, q[0]);
        dB = m->I_f * (q[3] * dtheta * w * w + 2.0 * q[2] * w * dw) + V2 * q[1] * dtheta;
        domega_dot = (dT - dB * q[1] - B * q[2] * dtheta - omega_dot * dJ) / J;
        ddx[CAM_THETA] = domega;
        ddx[CAM_OMEGA] = domega_dot;
    }
    ddx[CAM_CURRENT] = m->has_current ? (du - m->R * di - m->c_e * domega) / m->L : 0.0;
    for (n = 0; n < CAM_N_OUTPUTS; n++)
        dout[n] = 0.0;
    dout[CAM_O_OMEGA] = domega;
    dout[CAM_O_THETA] = dout[CAM_O_THETA_M] = dtheta;
    dout[CAM_O_OMEGA_M] = domega;
    dout[CAM_O_I] = m->has_current ? di : (du - m->c_e * domega) / m->R;
    dout[CAM_O_VOLTAGE] = du;
    dout[CAM_O_S] = dout[CAM_O_S_CAM] = q[1] / k * dtheta;
    if (engaged) {
        P = m->I_f * (q[2] * w * w + q[1] * omega_dot) + cam_kind_slope(m, q[0]);
        dP = m->I_f * (q[3] * dtheta * w * w + 2.0 * q[2] * w * dw + q[2] * dtheta * omega_dot + q[1] * domega_dot)
             + V2 * q[1] * dtheta;
        contact_tangent(m, q, P, dP, dtheta, &dalpha, &dN);
        dout[CAM_O_J] = dJ;
        dout[CAM_O_V] = (q[2] * dtheta * w + q[1] * dw) / k;
        dout[CAM_O_A] = (q[3] * dtheta * w * w + 2.0 * q[2] * w * dw + q[2] * dtheta * omega_dot
                         + q[1] * domega_dot) / k;
        dout[CAM_O_M] = dP * q[1] + P * q[2] * dtheta;
        dout[CAM_O_ALPHA] = dalpha;
        dout[CAM_O_N_CONTACT] = dN;
    }
    if (mode->stuck)   /* static friction takes the whole torque */
        dout[CAM_O_M] = dT;
    dout[CAM_O_S_END] = dout[CAM_O_S];   /* no train with a kind (the rules) */
    dout[CAM_O_V_END] = dout[CAM_O_V];
    dout[CAM_O_A_END] = dout[CAM_O_A];
    if (m->arm) {
        dout[CAM_O_PSI] = q[1] * dtheta;
        dout[CAM_O_PSI_DOT] = q[2] * dtheta * w + q[1] * dw;
    }
    return CAM_OK;
}
