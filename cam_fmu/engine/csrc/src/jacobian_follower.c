/* The tangent of the voltage drive's follower of its own in Model Exchange (forward-mode derivatives, written out by
 * hand, as jacobian.c's for the rigid drive): the directional derivative of cam_vf_rhs (voltage_follower.c)
 * and of the outputs (voltage_follower.c's vf_outputs) along a seed of the states x[CAM_ME_NX] (theta, omega, i, the
 * shaft's twist and rotor speed; in flight the gap and its rate from the flank last left) and the input u, at the
 * fixed mode: on a flank (moving or stuck), in flight (the cam moving or stuck, the follower sliding or held by the
 * guide's friction). Exact to rounding, no differencing (docs/fmu.md, "Model Exchange"). */
#include <math.h>

#include "cam_voltage_follower.h"

/* The seed's tangents of what drives the cam side: the current's (quasi-static with L = 0), the motor's torque, the
 * shaft's torque (compliant) and the torque on the cam (the shaft's or the motor's). */
typedef struct {
    double omega_m, current, motor, shaft, drive;
} Tangents;

static Tangents drive_tangents(const CamModel *m, const double seed[CAM_ME_NX], double du)
{
    Tangents t;
    t.omega_m = m->compliant ? seed[CAM_OMEGA_M] : seed[CAM_OMEGA];
    t.current = m->has_current ? seed[CAM_CURRENT] : (du - m->c_e * t.omega_m) / m->R;
    t.motor = m->c_m * t.current;
    t.shaft = m->compliant ? m->k_shaft * seed[CAM_TWIST] + m->d_shaft * (t.omega_m - seed[CAM_OMEGA]) : 0.0;
    t.drive = m->compliant ? t.shaft : t.motor;
    return t;
}

/* Another type's follower of its own (docs/model.md 16.3; rigid shaft: the rules): on its flank kind.c's tangent
 * with the closing force at the flank; in flight the cam alone and the follower under Q_close(q_f). */
static void kind_tangent(const CamDrive *d, const double x[CAM_ME_NX], const double seed[CAM_ME_NX], double du,
                         double ddx[CAM_ME_NX], double dout[])
{
    const CamModel *m = &d->model;
    const double left = d->mode.left, dtheta = seed[CAM_THETA], domega = seed[CAM_OMEGA];
    double y[NY], dy[NY], q[4], s_cam[4], dq, dq_dot, dq_dd, domega_dot, V2, dF_t;
    Tangents g = drive_tangents(m, seed, du);
    int k, stuck = d->mode.stuck;
    cam_vf_y(m, &d->mode, x, y);
    cam_vf_rates(m, d->form_u, d->mode.contact, y, dy);
    cam_kind_eval(m, y[0], q);
    if (d->mode.contact) {
        cam_kind_tangent(m, &d->mode, x, seed, cam_vf_torque_toward(m, y, d->form_u, 0.0), g.drive, du, dy[1], 1,
                         ddx, dout);
        if (stuck) {   /* the follower rides the flank at the state's omega, q' omega, as the outputs take it */
            dq_dot = q[2] * dtheta * y[1] + q[1] * domega;
            dout[CAM_O_V] = dout[CAM_O_V_END] = dq_dot / m->q_scale;
            dout[CAM_O_PSI_DOT] = m->arm ? dq_dot : 0.0;
            if (m->train)   /* the end mass's rates take the follower at rest, the outputs at omega (lift units) */
                cam_train_rows(m, seed, cam_train_tangent(m, q[1] * dtheta / m->q_scale, 0.0, seed),
                               cam_train_tangent(m, q[1] * dtheta / m->q_scale, dq_dot / m->q_scale, seed), ddx, dout);
        }
        return;
    }
    cam_profile_eval(&m->profile, y[0], s_cam);
    for (k = 0; k < CAM_ME_NX; k++)
        ddx[k] = 0.0;
    for (k = 0; k < CAM_N_OUTPUTS; k++)
        dout[k] = 0.0;
    V2 = cam_follower_stiffness(m) + (m->arm && m->W != 0.0 ? -m->W * sin(y[3] + m->psi_0) : 0.0);
    dq = q[1] * dtheta + left * seed[CAM_GAP] / cam_follower_length(m);   /* the gap's slots in m along the path */
    dq_dot = q[2] * dtheta * y[1] + q[1] * domega + left * seed[CAM_RATE] / cam_follower_length(m);
    dF_t = cam_train_tangent(m, dq / m->q_scale, dq_dot / m->q_scale, seed);   /* a train's, lift units (0: none) */
    dq_dd = -(V2 * dq + dF_t / m->q_scale) / m->I_f;   /* I_f q_f_dd = -Q_close(q_f) */
    domega_dot = stuck ? 0.0 : g.drive / m->J_0;
    ddx[CAM_THETA] = domega;   /* the rates' theta_dot = omega in flight, the cam stuck at omega = 0 too */
    ddx[CAM_OMEGA] = domega_dot;
    ddx[CAM_CURRENT] = m->has_current ? (du - m->R * seed[CAM_CURRENT] - m->c_e * g.omega_m) / m->L : 0.0;
    ddx[CAM_GAP] = seed[CAM_RATE];
    ddx[CAM_RATE] = left * cam_follower_length(m) * (dq_dd - (q[3] * dtheta * y[1] * y[1] + 2.0 * q[2] * y[1] * domega
                                                              + q[2] * dtheta * dy[1] + q[1] * domega_dot));
    dout[CAM_O_OMEGA] = dout[CAM_O_OMEGA_M] = domega;
    dout[CAM_O_THETA] = dout[CAM_O_THETA_M] = dtheta;
    dout[CAM_O_I] = g.current;
    dout[CAM_O_VOLTAGE] = du;
    dout[CAM_O_S_CAM] = s_cam[1] * dtheta;
    dout[CAM_O_S] = dout[CAM_O_S_END] = dq / m->q_scale;
    dout[CAM_O_V] = dout[CAM_O_V_END] = dq_dot / m->q_scale;
    dout[CAM_O_A] = dout[CAM_O_A_END] = dq_dd / m->q_scale;
    if (m->arm) {
        dout[CAM_O_PSI] = dq;
        dout[CAM_O_PSI_DOT] = dq_dot;
    }
    if (m->train)   /* the end mass under the flying follower's own q, q_dot */
        cam_train_rows(m, seed, dF_t, dF_t, ddx, dout);
    {   /* the cam's pressure angle at theta (no contact force) */
        double dN;
        cam_kind_contact_tangent(m, q, 0.0, 0.0, dtheta, &dout[CAM_O_ALPHA], &dN);
    }
}

void cam_vf_me_tangent(const CamDrive *d, const double x[CAM_ME_NX], const double seed[CAM_ME_NX], double du,
                       double ddx[CAM_ME_NX], double dout[])
{
    const CamModel *m = &d->model;
    const int contact = d->mode.contact;
    const double left = d->mode.left, dtheta = seed[CAM_THETA], domega = seed[CAM_OMEGA];
    double y[NY], dy[NY], p[4], base, t, dt, root, ds, dv, da, dF, domega_dot = 0.0, dP = 0.0, P = 0.0, f, df;
    double F_t = 0.0, dF_t = 0.0, dF_out = 0.0;   /* a train's force on the follower (docs/model.md 14.6) */
    Tangents g = drive_tangents(m, seed, du);
    int k, stuck;
    if (m->kind != CAM_CHOICE_FOLLOWER_TYPE_TRANSLATING_ROLLER) {
        kind_tangent(d, x, seed, du, ddx, dout);
        return;
    }
    cam_vf_y(m, &d->mode, x, y);
    stuck = y[Y_DIR] == 0.0;
    cam_vf_rates(m, d->form_u, contact, y, dy);   /* the values the tangent needs: omega_dot */
    cam_kind_eval(m, y[0], p);
    for (k = 0; k < CAM_ME_NX; k++)
        ddx[k] = 0.0;
    for (k = 0; k < CAM_N_OUTPUTS; k++)
        dout[k] = 0.0;
    ddx[CAM_CURRENT] = m->has_current ? (du - m->R * seed[CAM_CURRENT] - m->c_e * g.omega_m) / m->L : 0.0;
    ddx[CAM_TWIST] = m->compliant ? g.omega_m - domega : 0.0;
    ddx[CAM_OMEGA_M] = m->compliant ? (g.motor - g.shaft) / m->J_m : 0.0;
    ds = p[1] * dtheta;   /* the follower's position: on the flank, s_cam's */
    dv = p[2] * dtheta * y[1] + p[1] * domega;
    if (contact) {
        if (m->train) {   /* on a stuck flank the rates take the follower at rest */
            F_t = cam_train_pull(m, y[3], stuck ? 0.0 : y[4], y[Y_XE], y[Y_VE]);
            dF_t = cam_train_tangent(m, ds, stuck ? 0.0 : dv, seed);
        }
        dF = m->k_spring * p[1] * dtheta + dF_t;   /* the closing force at s = s_cam - contact c, a train's */
        if (!stuck) {
            double dq[4] = {dtheta, domega, g.drive, dF};
            domega_dot = cam_flank_tangent(m, p, y[1], cam_vf_torque_toward(m, y, d->form_u, 0.0),
                                           cam_follower_closing(m, y[3]) + F_t, y[Y_DIR], 0.0, dq, &f, &df);
            ddx[CAM_THETA] = domega;
            ddx[CAM_OMEGA] = domega_dot;
            cam_vf_on_flank(m, y, d->form_u, contact, p, &dy[1], &P, NULL);
        } else {
            P = cam_follower_closing(m, y[3]) + F_t;
            f = df = 0.0;
        }
        da = p[3] * dtheta * y[1] * y[1] + 2.0 * p[2] * y[1] * domega + p[2] * dtheta * dy[1] + p[1] * domega_dot;
        dP = stuck ? dF : m->m * da + dF + (p[1] * y[Y_DIR] > 0.0 ? df : (p[1] * y[Y_DIR] < 0.0 ? -df : 0.0));
        dout[CAM_O_M] = stuck ? g.drive : dP * p[1] + P * p[2] * dtheta;
        dout[CAM_O_J] = 2.0 * m->m * p[1] * p[2] * dtheta;
    } else {
        int held = m->mu != 0.0 && y[Y_SIGMA] == 0.0;   /* at a halt, held by the guide's friction */
        ds += left * seed[CAM_GAP];
        dv += left * seed[CAM_RATE];
        domega_dot = stuck ? 0.0 : g.drive / m->J_0;
        dF_t = cam_train_tangent(m, ds, dv, seed);
        da = held ? 0.0 : -(m->k_spring * ds + dF_t) / m->m;   /* the free follower's acceleration */
        ddx[CAM_THETA] = domega;
        ddx[CAM_OMEGA] = domega_dot;
        ddx[CAM_GAP] = seed[CAM_RATE];
        ddx[CAM_RATE] = left * (da - (p[3] * dtheta * y[1] * y[1] + 2.0 * p[2] * y[1] * domega
                                         + p[2] * dtheta * dy[1] + p[1] * domega_dot));
    }
    base = m->r_b + p[0];
    t = p[1] / base;
    dt = (p[2] * dtheta * base - p[1] * p[1] * dtheta) / (base * base);
    root = sqrt(1.0 + t * t);
    dout[CAM_O_OMEGA] = domega;
    dout[CAM_O_THETA] = dtheta;
    dout[CAM_O_S] = ds;
    dout[CAM_O_I] = g.current;
    dout[CAM_O_V] = dv;
    dout[CAM_O_A] = da;
    dout[CAM_O_ALPHA] = dt / (1.0 + t * t);
    dout[CAM_O_S_CAM] = p[1] * dtheta;
    dout[CAM_O_VOLTAGE] = du;
    dout[CAM_O_N_CONTACT] = contact ? dP * root + P * t * dt / root : 0.0;
    dout[CAM_O_THETA_M] = dtheta + (m->compliant ? seed[CAM_TWIST] : 0.0);
    dout[CAM_O_OMEGA_M] = g.omega_m;
    dout[CAM_O_M_SHAFT] = m->compliant ? g.shaft : 0.0;
    dout[CAM_O_S_END] = ds;   /* without a train the end is the follower */
    dout[CAM_O_V_END] = dv;
    dout[CAM_O_A_END] = da;
    dout[CAM_O_F_TRAIN] = 0.0;
    if (m->train) {   /* the end mass's rows, its force at the follower's own s, v (the rates': at rest if stuck) */
        dF_out = cam_train_tangent(m, ds, dv, seed);
        cam_train_rows(m, seed, contact ? dF_t : dF_out, dF_out, ddx, dout);
    }
}
