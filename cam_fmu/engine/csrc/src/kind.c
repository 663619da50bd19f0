/* The follower's kind in the drive (docs/model.md 16; physics/kind_drive.py, the reference): a translating flat
 * face, or an arm about a pivot with a roller or a flat face. One degree of freedom, theta: the follower's coordinate
 * q = s (translating) or psi = lift_angle s / lift (an arm), its inertia I_f = m or J_arm + m L^2, its potential
 * V = -F_gx s or W sin(psi + psi_0); P = I_f (q'' omega^2 + q' omega_dot) + dV/dq moves it, and the load torque is
 * M = M_f d + P q' + mu |P| lambda d (d = sgn(omega)), the friction's lever lambda >= 0 the type's (cam_kind_lever).
 * The drive equation J_0 omega_dot = T - M_f d - P q' - mu |P| lambda d is solved on the branch b = sgn(P):
 * (J_0 + I_f q' k) omega_dot = T - M_f d - A k, A = I_f q'' omega^2 + dV/dq, k = q' + mu lambda d b (cam_kind_branch,
 * the one place of that equation). */
#include <math.h>

#include "cam_model.h"

#define PI 3.141592653589793
#define WEDGE_GRID 3600   /* angles over a turn where the friction's wedging is tested (kind_drive.LOCKING_GRID) */

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

double cam_kind_lever(const CamModel *m, const double q[4])
{
    if (m->kind == CAM_CHOICE_FOLLOWER_TYPE_TRANSLATING_FLAT)   /* the face slides at r_b + s from the cam axis */
        return m->r_b + q[0];
    if (m->kind == CAM_CHOICE_FOLLOWER_TYPE_OSCILLATING_FLAT)   /* p / l: the cam's offset over the contact's arm */
        return tan(m->delta0 + q[0]) * (1.0 - q[1]);
    return fabs(q[1]);   /* the roller arm: the pivot's Coulomb torque mu |P| against the arm's turn */
}

/* d(lambda)/d(theta) at q (q[4]): the lever's rate along the cam (cam_kind_lever). */
static double lever_rate(const CamModel *m, const double q[4])
{
    double t;
    if (m->kind == CAM_CHOICE_FOLLOWER_TYPE_TRANSLATING_FLAT)
        return q[1];
    if (m->kind == CAM_CHOICE_FOLLOWER_TYPE_OSCILLATING_FLAT) {
        t = tan(m->delta0 + q[0]);
        return (1.0 + t * t) * q[1] * (1.0 - q[1]) - t * q[2];
    }
    return cam_sign(q[1]) * q[2];
}

double cam_kind_branch(const CamModel *m, const double q[4], double omega, double drive, double direction,
                       double side, double force, CamKindBranch *out)
{
    double A = m->I_f * q[2] * omega * omega + force, omega_dot;
    out->b = 0.0;
    out->k = q[1];
    if (m->mu != 0.0) {
        out->b = side != 0.0 ? side : (A * m->J_0 + m->I_f * q[1] * drive < 0.0 ? -1.0 : 1.0);
        out->k = q[1] + m->mu * cam_kind_lever(m, q) * direction * out->b;
    }
    out->den = m->J_0 + m->I_f * q[1] * out->k;
    /* wedged (refused before the run on a 0.1 deg grid, cam_kind_check): no finite answer, the guards stop */
    omega_dot = out->den > 0.0 ? (drive - A * out->k) / out->den : NAN;
    out->P = A + m->I_f * q[1] * omega_dot;
    return omega_dot;
}

const char *cam_train_names(const CamModel *m)
{
    return m->arm ? "sqrt(k_train_arm / J_end) + d_train_arm / J_end" : "sqrt(k_train / m_end) + d_train / m_end";
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

void cam_arm_end_outputs(const CamModel *m, double out[])
{
    out[CAM_O_PSI_END] = m->arm ? m->q_scale * out[CAM_O_S_END] : 0.0;
    out[CAM_O_PSI_DOT_END] = m->arm ? m->q_scale * out[CAM_O_V_END] : 0.0;
    out[CAM_O_M_TRAIN] = m->arm ? out[CAM_O_F_TRAIN] / m->q_scale : 0.0;
}

void cam_kind_contact_load(const CamModel *m, const double q[4], double P, double direction, CamLoad *out)
{
    double alpha = 0.0, N, friction;
    friction = m->mu != 0.0 ? m->mu * fabs(P) * cam_kind_lever(m, q) : 0.0;   /* N m on the cam, against its turn */
    N = P;
    if (m->kind == CAM_CHOICE_FOLLOWER_TYPE_OSCILLATING_ROLLER) {   /* the rocker's triangle (15.1) */
        double delta = m->delta0 + q[0], d = m->pivot_distance, L = m->arm_length, turn = q[1] * direction;
        alpha = atan2(d * cos(delta) - L * (1.0 - q[1]), d * sin(delta));
        /* the contact supplies P and the pivot's friction against the arm's turn */
        N = (m->mu != 0.0 ? P + m->mu * fabs(P) * cam_sign(turn) : P)
            / (L * cos(alpha));
    } else if (m->kind == CAM_CHOICE_FOLLOWER_TYPE_OSCILLATING_FLAT) {   /* the face at l from the pivot (15.2) */
        N = P * (1.0 - q[1]) / (m->pivot_distance * cos(m->delta0 + q[0]));
    }
    out->alpha = alpha;
    out->M = m->mu != 0.0 ? m->M_f * direction + P * q[1] + friction * direction : m->M_f * direction + P * q[1];
    out->f = m->mu * fabs(N);   /* the reference's friction field (no output of its own) */
    out->J = m->J_0 + m->I_f * q[1] * q[1];
    out->N = N;
}

void cam_kind_load(const CamModel *m, double theta, double omega, double omega_dot, double direction, int engaged,
                   double axial, CamLoad *out)
{
    double q[4];
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
    cam_kind_contact_load(m, q, m->I_f * (q[2] * omega * omega + q[1] * omega_dot) + cam_kind_slope(m, q[0])
                          + axial / m->q_scale, direction, out);   /* axial: the train's force along s (0 without) */
    out->v = q[1] / m->q_scale * omega;   /* the law's lift rates, as the reference's */
    out->a = q[2] / m->q_scale * omega * omega + q[1] / m->q_scale * omega_dot;
}

/* The friction's wedging (kind_drive.KindDriveModel._check_locking): the drive equation's J_0 + I_f q' k must stay
 * > 0 on either branch, J_0 + I_f (q'^2 - |q'| mu lambda) > 0 at every 0.1 deg, else refused with the reference's
 * message. */
static int wedge_check(const CamModel *m, CamError *err)
{
    double worst = INFINITY, at = 0.0, theta, value, q[4];
    char a[40], b[40];
    int k;
    if (m->mu == 0.0 || m->I_f == 0.0)
        return CAM_OK;
    for (k = 0; k <= WEDGE_GRID; k++) {
        theta = 2.0 * PI * k / WEDGE_GRID;
        cam_kind_eval(m, theta, q);
        value = m->J_0 + m->I_f * (q[1] * q[1] - fabs(q[1]) * m->mu * cam_kind_lever(m, q));
        if (value < worst) {
            worst = value;
            at = theta;
        }
    }
    if (worst <= 0.0)
        return cam_error(err, CAM_ERR_PARAMETER, "parameters 'mu' = %s and 'r_b' = %s m wedge the %s follower by its "
                         "friction at theta = %.4g deg (J_0 + I_f q' (q' - mu lambda) = %.4g kg m2 <= 0): allowed "
                         "where it stays > 0 (lower mu or add inertia J_cam)", cam_num(m->mu, a), cam_num(m->r_b, b),
                         cam_param_spec(CAM_P_FOLLOWER_TYPE)->choices[m->kind], at * (180.0 / PI), worst);
    return CAM_OK;
}

/* Geometry that the contour on a 0.1 deg grid cannot build (kinematics/follower_checks.py refuse_unbuildable): a
 * roller arm's cam sweeping over its pivot (the roller's centre sqrt(d^2 + L^2 - 2 d L cos(delta)) from the cam axis,
 * the cam built on its pitch curve), an oscillating face turning faster than the cam (psi' >= 1: the contact runs off
 * along the face), a flat face's cusp (its contour's radius of curvature rho = p + d2p/dphi2 <= 0, docs/model.md
 * 15.2: r_b + s + s'' for a translating face). */
static int contour_check(const CamModel *m, CamError *err)
{
    double q[4], theta, d = m->pivot_distance, L = m->arm_length, worst = -INFINITY, at = 0.0, need = -INFINITY, value;
    char a[40];
    int k, kind = m->kind;
    if (kind == CAM_CHOICE_FOLLOWER_TYPE_TRANSLATING_ROLLER)
        return CAM_OK;
    for (k = 0; k < WEDGE_GRID; k++) {
        theta = 2.0 * PI * k / WEDGE_GRID;
        cam_kind_eval(m, theta, q);
        if (kind == CAM_CHOICE_FOLLOWER_TYPE_OSCILLATING_ROLLER)
            value = sqrt(d * d + L * L - 2.0 * d * L * cos(m->delta0 + q[0]));   /* the roller's reach */
        else if (kind == CAM_CHOICE_FOLLOWER_TYPE_OSCILLATING_FLAT && q[1] >= 1.0)
            value = INFINITY;
        else if (kind == CAM_CHOICE_FOLLOWER_TYPE_OSCILLATING_FLAT) {   /* -rho of the face's envelope */
            double delta = m->delta0 + q[0], p = d * sin(delta), p1 = d * cos(delta) * q[1];
            double p2 = d * (cos(delta) * q[2] - sin(delta) * q[1] * q[1]), f1 = q[1] - 1.0;
            value = -(p + (p2 * f1 - p1 * q[2]) / (f1 * f1 * f1));
        } else {
            value = -(m->r_b + q[0] + q[2]);
            need = fmax(need, -(q[0] + q[2]));
        }
        if (value > worst) {
            worst = value;
            at = theta;
        }
    }
    if (kind == CAM_CHOICE_FOLLOWER_TYPE_OSCILLATING_ROLLER && worst >= d)
        return cam_error(err, CAM_ERR_PARAMETER, "parameter 'pivot_distance' = %s m: the cam's contour reaches %.6g mm "
                         "from its axis (at theta = %.6g deg) and would sweep over the pivot; allowed > %.6g m",
                         cam_num(d, a), worst * 1e3, at * (180.0 / PI), worst);
    if (kind == CAM_CHOICE_FOLLOWER_TYPE_OSCILLATING_FLAT && worst == INFINITY)
        return cam_error(err, CAM_ERR_PARAMETER, "parameter 'lift_angle' = %s rad: the arm turns faster than the cam "
                         "(psi' >= 1 at theta = %.6g deg) and the contact runs off along the face; allowed a lift_angle "
                         "where psi' < 1", cam_num(m->params.v[CAM_P_LIFT_ANGLE], a), at * (180.0 / PI));
    if (kind == CAM_CHOICE_FOLLOWER_TYPE_TRANSLATING_FLAT && worst >= 0.0)
        return cam_error(err, CAM_ERR_PARAMETER, "parameter 'r_b' = %s m: the flat face's contour has radius of "
                         "curvature r_b + s + s'' = %.6g mm <= 0 at theta = %.6g deg (a cusp, it cannot be made); "
                         "allowed r_b > %.6g m (max of -(s + s'') on a 0.1 deg grid)", cam_num(m->r_b, a), -worst * 1e3,
                         at * (180.0 / PI), need);
    if (kind == CAM_CHOICE_FOLLOWER_TYPE_OSCILLATING_FLAT && worst >= 0.0)
        return cam_error(err, CAM_ERR_PARAMETER, "parameter 'r_b' = %s m: the flat face's contour has radius of "
                         "curvature p + d2p/dphi2 = %.6g mm <= 0 at theta = %.6g deg (a cusp, it cannot be made); "
                         "allowed a larger r_b (or a smaller lift_angle)", cam_num(m->r_b, a), -worst * 1e3,
                         at * (180.0 / PI));
    return CAM_OK;
}

/* The refusals of geometry that cannot be built whose limits are closed forms (kinematics/follower_checks.py and
 * the cam classes' constructors): the arm cannot reach the cam, the pivot inside the base circle, an arm turned to
 * the pressure angle's 90 deg or a face past the perpendicular; then the contour's and the friction's. */
int cam_kind_check(const CamModel *m, CamError *err)
{
    double L = m->arm_length, d = m->pivot_distance, r_b = m->r_b, lift_angle = m->params.v[CAM_P_LIFT_ANGLE], top;
    char a[40], b[40], c[40];
    int status;
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
    if ((status = contour_check(m, err)) != CAM_OK)
        return status;
    return wedge_check(m, err);
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
    if (v[CAM_P_K_TRAIN_ARM] > 0.0) {   /* the torsional train in the law's lift units along s (docs/model.md 14.6) */
        double k2 = m->q_scale * m->q_scale;
        m->train = 1;
        m->k_train = v[CAM_P_K_TRAIN_ARM] * k2;
        m->d_train = v[CAM_P_D_TRAIN_ARM] * k2;
        m->m_end = v[CAM_P_J_END] * k2;
        m->F_ex = 0.0;   /* the end inertia turns about its own centre: no weight's torque */
    }
    if (m->kind == CAM_CHOICE_FOLLOWER_TYPE_OSCILLATING_ROLLER) {   /* cam_kind_check refuses the arm out of reach */
        if (fabs(d - L) < r_b && r_b < d + L)
            m->delta0 = acos((d * d + L * L - r_b * r_b) / (2.0 * d * L));
    } else {
        m->delta0 = asin(fmin(1.0, r_b / d));
    }
}

void cam_kind_contact_tangent(const CamModel *m, const double q[4], double P, double dP, double dtheta, double *dalpha,
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
                     double T, double dT, double du, double omega_dot, int own, double ddx[CAM_NX], double dout[])
{
    double q[4], theta = x[CAM_THETA], dtheta = seed[CAM_THETA], domega = seed[CAM_OMEGA];
    double di = m->has_current ? seed[CAM_CURRENT] : 0.0, w, dw, A, dA, dJ, V2, domega_dot = 0.0, P, dP;
    double k = m->q_scale, dalpha, dN, d = mode->stuck ? 0.0 : mode->direction, lam = 0.0, dlam = 0.0, dk;
    double sP, Pc, dPc, qf, force, dF = 0.0, side = own ? mode->contact : (m->guide_side ? mode->side : 0.0);
    CamKindBranch branch;
    int n, moving = !mode->stuck, engaged = mode->contact != 0;
    cam_kind_eval(m, theta, q);
    qf = q[0] - (own ? mode->contact * cam_follower_clearance(m) : 0.0);   /* where the follower is */
    V2 = m->arm && m->W != 0.0 ? -m->W * sin(qf + m->psi_0) : 0.0;   /* d2V/dq2 */
    force = own ? cam_follower_closing(m, qf) : cam_kind_slope(m, q[0]);   /* its load beside its inertia */
    if (own)
        V2 += cam_follower_stiffness(m);   /* the spring's */
    for (n = 0; n < CAM_NX; n++)
        ddx[n] = 0.0;
    if (!moving)
        omega_dot = 0.0;
    w = moving ? x[CAM_OMEGA] : 0.0;
    dw = moving ? domega : 0.0;
    if (m->train) {   /* the train (docs/model.md 14.6): its force along s at the follower, over k along an arm's q */
        force += cam_train_pull(m, qf / k, q[1] * w / k, x[CAM_X_END], x[CAM_V_END]) / k;
        dF = cam_train_tangent(m, q[1] * dtheta / k, (q[2] * dtheta * w + q[1] * dw) / k, seed);
    }
    dJ = 2.0 * m->I_f * q[1] * q[2] * dtheta;
    if (m->mu != 0.0) {   /* the friction's lever and its rate */
        lam = cam_kind_lever(m, q);
        dlam = lever_rate(m, q) * dtheta;
    }
    A = m->I_f * q[2] * w * w + force;
    dA = m->I_f * (q[3] * dtheta * w * w + 2.0 * q[2] * w * dw) + V2 * q[1] * dtheta + dF / k;
    if (moving && m->follower) {   /* den omega_dot = T - M_f d - A k on the branch cam_rhs holds (model.c) */
        cam_kind_branch(m, q, w, T - m->M_f * d, d, side, force, &branch);
        dk = q[2] * dtheta + m->mu * d * branch.b * dlam;
        domega_dot = (dT - dA * branch.k - A * dk - omega_dot * m->I_f * (q[2] * dtheta * branch.k + q[1] * dk))
                     / branch.den;
    } else if (moving) {
        domega_dot = dT / m->J_0;
    }
    if (moving) {
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
    if (engaged) {   /* cam_kind_load at the state's omega_dot */
        P = A + m->I_f * q[1] * omega_dot;
        dP = dA + m->I_f * (q[2] * dtheta * omega_dot + q[1] * domega_dot);
        sP = cam_sign(P);
        Pc = P;   /* the roller arm's contact supplies P and the pivot's friction against the arm's turn */
        dPc = dP;
        if (m->mu != 0.0 && m->kind == CAM_CHOICE_FOLLOWER_TYPE_OSCILLATING_ROLLER) {
            double turn = q[1] * d, st = cam_sign(turn);
            Pc = P + m->mu * fabs(P) * st;
            dPc = dP + m->mu * sP * dP * st;
        }
        cam_kind_contact_tangent(m, q, Pc, dPc, dtheta, &dalpha, &dN);
        dout[CAM_O_J] = dJ;
        dout[CAM_O_V] = (q[2] * dtheta * w + q[1] * dw) / k;
        dout[CAM_O_A] = (q[3] * dtheta * w * w + 2.0 * q[2] * w * dw + q[2] * dtheta * omega_dot
                         + q[1] * domega_dot) / k;
        dout[CAM_O_M] = dP * q[1] + P * q[2] * dtheta + m->mu * d * (sP * dP * lam + fabs(P) * dlam);
        dout[CAM_O_ALPHA] = dalpha;
        dout[CAM_O_N_CONTACT] = dN;
    }
    if (mode->stuck)   /* static friction takes the whole torque */
        dout[CAM_O_M] = dT;
    dout[CAM_O_S_END] = dout[CAM_O_S];   /* without a train the end is the follower */
    dout[CAM_O_V_END] = dout[CAM_O_V];
    dout[CAM_O_A_END] = dout[CAM_O_A];
    if (m->train)   /* the end mass (model.c train_rhs) */
        cam_train_rows(m, seed, dF, dF, ddx, dout);
    if (m->arm) {
        dout[CAM_O_PSI] = q[1] * dtheta;
        dout[CAM_O_PSI_DOT] = q[2] * dtheta * w + q[1] * dw;
    }
    return CAM_OK;
}
