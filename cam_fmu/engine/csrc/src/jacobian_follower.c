/* The tangent of a follower of its own in Model Exchange (forward-mode derivatives, written out by hand): the
 * directional derivative of the state derivatives (cam_vf_me_rates, voltage_follower_events.c over cam_vf_rates,
 * voltage_follower.c) and of the outputs (vf_outputs) along a seed of the states x[CAM_ME_NX] and the input u, at the
 * mode the last event update left (docs/model.md 13.6): on a flank moving (the coupled equations with the contact's
 * force and the guide friction), on a flank stuck, in flight (the cam driven alone, the follower's gap g and its
 * rate w to the flank left last) with the cam moving or stuck, with or without guide friction, rigid or compliant
 * shaft, L = 0 or L > 0. Exact to rounding, no differencing; fmi/directional.c forwards here. */
#include <math.h>

#include "cam_voltage_follower.h"

/* The follower's mode as the last event update left it (the one place this file reads it). */
typedef struct {
    int contact;                /* the flank the follower is on (+1, -1), 0 in flight */
    int left;                   /* in flight: the flank it left last, the gap's origin */
    double sigma;               /* in flight: its direction sgn(v) held between events (0: held by friction) */
    double dir;                 /* the shaft's direction, 0 while stuck */
} FollowerMode;

static FollowerMode follower_mode(const CamDrive *d)
{
    FollowerMode mode;
    mode.contact = (int)d->speed.contact;
    mode.left = (int)d->speed.left;
    mode.sigma = d->speed.sigma;
    mode.dir = d->mode.stuck ? 0.0 : d->mode.direction;
    return mode;
}

static double sgn(double x)
{
    return x > 0.0 ? 1.0 : (x < 0.0 ? -1.0 : 0.0);
}

/* The drive's torque on the cam side [N m] (the motor's, or a compliant shaft's k phi + d (omega_m - omega)) before
 * the shaft's friction, and its tangent *dT. */
static double drive_tangent(const CamModel *m, const double x[CAM_ME_NX], double u, const double dx[CAM_ME_NX],
                            double du, double *dT)
{
    if (m->compliant) {
        *dT = m->k_shaft * dx[CAM_TWIST] + m->d_shaft * (dx[CAM_OMEGA_M] - dx[CAM_OMEGA]);
        return m->k_shaft * x[CAM_TWIST] + m->d_shaft * (x[CAM_OMEGA_M] - x[CAM_OMEGA]);
    }
    if (m->has_current) {
        *dT = m->c_m * dx[CAM_CURRENT];
        return m->c_m * x[CAM_CURRENT];
    }
    *dT = m->c_m * (du - m->c_e * dx[CAM_OMEGA]) / m->R;
    return m->c_m * (u - m->c_e * x[CAM_OMEGA]) / m->R;
}

/* On the flank `contact`, the shaft moving toward dir (voltage_follower.c flank_toward): omega_dot [rad/s2] and the
 * force P [N] along X with their tangents, from d = (s_cam, s', s'', s''') at theta and the torque T less M_f dir. */
static void flank_tangent(const CamModel *m, int contact, double dir, const double d[4], double omega, double T,
                          double dtheta, double domega, double dT, double *omega_dot, double *domega_dot, double *P,
                          double *dP)
{
    double s1 = d[1], s2 = d[2], ds1 = s2 * dtheta, ds2 = d[3] * dtheta, base = m->r_b + d[0];
    double F = cam_follower_closing(m, d[0] - contact * cam_vf_clearance(m)), dF = m->k_spring * s1 * dtheta;
    double J = m->J_0 + m->m * s1 * s1, dJ = 2.0 * m->m * s1 * ds1;
    double inertial = m->m * s2 * omega * omega + F;
    double dinertial = m->m * (ds2 * omega * omega + 2.0 * s2 * omega * domega) + dF;
    double x0 = (T - inertial * s1) / J, dx0 = (dT - dinertial * s1 - inertial * ds1 - x0 * dJ) / J;
    double sigma, tan_a, dtan, n0, dn0, kappa, dkappa, f = 0.0, df = 0.0;
    *omega_dot = x0;
    *domega_dot = dx0;
    sigma = sgn(s1 * dir);
    if (m->mu != 0.0) {   /* the guide friction solved with omega_dot (model.c load_terms, F_close for gravity) */
        tan_a = s1 / base;
        dtan = (ds1 * base - s1 * s1 * dtheta) / (base * base);
        n0 = (inertial + m->m * s1 * x0) * tan_a + m->G_y;
        dn0 = (dinertial + m->m * (ds1 * x0 + s1 * dx0)) * tan_a + (inertial + m->m * s1 * x0) * dtan;
        kappa = m->J_0 / J * tan_a;
        dkappa = m->J_0 * (dtan * J - tan_a * dJ) / (J * J);
        f = cam_friction_tangent(m, n0, dn0, kappa, dkappa, sigma, 0.0, &df);
        *omega_dot = x0 - sigma * f * s1 / J;
        *domega_dot = dx0 - sigma * ((df * s1 + f * ds1) * J - f * s1 * dJ) / (J * J);
    }
    *P = m->m * (s2 * omega * omega + s1 * *omega_dot) + F + sigma * f;
    *dP = m->m * (ds2 * omega * omega + 2.0 * s2 * omega * domega + ds1 * *omega_dot + s1 * *domega_dot) + dF
          + sigma * df;
}

void cam_vf_tangent(const CamDrive *d, const double x[CAM_ME_NX], double u, const double seed[CAM_ME_NX], double du,
                    double ddx[CAM_ME_NX], double dout[])
{
    const CamModel *m = &d->model;
    FollowerMode mode = follower_mode(d);
    double dx[CAM_ME_NX] = {0.0}, dd[4], y[NY] = {0.0}, T, dT, omega_dot = 0.0, domega_dot = 0.0, P = 0.0, dP = 0.0;
    double theta = x[CAM_THETA], omega = x[CAM_OMEGA], dtheta, domega, domega_m, dI, tan_a, dtan, base, s1, ds1;
    double ds, a_slope;
    int k, stuck = mode.dir == 0.0;
    for (k = 0; k < CAM_ME_NX; k++)   /* the slots the drive holds move nothing (me_load reads them not) */
        dx[k] = seed[k];
    if (!m->has_current)
        dx[CAM_CURRENT] = 0.0;
    if (!m->compliant)
        dx[CAM_TWIST] = dx[CAM_OMEGA_M] = 0.0;
    if (mode.contact)
        dx[CAM_ME_GAP] = dx[CAM_ME_RATE] = 0.0;
    dtheta = dx[CAM_THETA];
    domega = dx[CAM_OMEGA];
    domega_m = m->compliant ? dx[CAM_OMEGA_M] : domega;
    for (k = 0; k < CAM_ME_NX; k++)
        ddx[k] = 0.0;
    for (k = 0; k < CAM_N_OUTPUTS; k++)
        dout[k] = 0.0;
    cam_profile_eval(&m->profile, theta, dd);
    s1 = dd[1];
    ds1 = dd[2] * dtheta;
    T = drive_tangent(m, x, u, dx, du, &dT) - m->M_f * mode.dir;
    /* the electrical and the shaft's slots (flank_rates' first lines) */
    dI = m->has_current ? dx[CAM_CURRENT] : (du - m->c_e * domega_m) / m->R;
    if (m->has_current)
        ddx[CAM_CURRENT] = (du - m->R * dx[CAM_CURRENT] - m->c_e * domega_m) / m->L;
    if (m->compliant) {
        ddx[CAM_TWIST] = domega_m - domega;
        ddx[CAM_OMEGA_M] = (m->c_m * dI - dT) / m->J_m;
    }
    if (mode.contact) {
        if (stuck) {   /* the cam and the follower at rest on the flank: P = F_close(s) balances the spring */
            P = cam_follower_closing(m, dd[0] - mode.contact * cam_vf_clearance(m));
            dP = m->k_spring * s1 * dtheta;
        } else {
            flank_tangent(m, mode.contact, mode.dir, dd, omega, T, dtheta, domega, dT, &omega_dot, &domega_dot, &P,
                          &dP);
            ddx[CAM_THETA] = domega;
            ddx[CAM_OMEGA] = domega_dot;
        }
    } else {
        ddx[CAM_THETA] = domega;
        if (!stuck) {   /* the cam driven alone: J_0 omega_dot = T */
            omega_dot = T / m->J_0;
            domega_dot = dT / m->J_0;
            ddx[CAM_OMEGA] = domega_dot;
        }
        /* the gap g = left (s - s_flank), s = s_cam - left c + left g: der(g) = w, der(w) = left (a_free(s) - the
         * flank's acceleration s'' omega^2 + s' omega_dot); a_free's slope -k_spring / m unless friction holds it */
        ds = s1 * dtheta + mode.left * dx[CAM_ME_GAP];
        a_slope = m->mu == 0.0 || mode.sigma != 0.0 ? -m->k_spring / m->m : 0.0;
        ddx[CAM_ME_GAP] = dx[CAM_ME_RATE];
        ddx[CAM_ME_RATE] = mode.left * (a_slope * ds - (dd[3] * dtheta * omega * omega + 2.0 * dd[2] * omega * domega
                                                        + ds1 * omega_dot + s1 * domega_dot));
    }
    /* the outputs (vf_outputs) */
    base = m->r_b + dd[0];
    tan_a = s1 / base;
    dtan = (ds1 * base - s1 * s1 * dtheta) / (base * base);
    dout[CAM_O_OMEGA] = domega;
    dout[CAM_O_THETA] = dtheta;
    dout[CAM_O_I] = dI;
    dout[CAM_O_VOLTAGE] = du;
    dout[CAM_O_ALPHA] = dtan / (1.0 + tan_a * tan_a);
    dout[CAM_O_S_CAM] = s1 * dtheta;
    if (mode.contact) {
        double root = sqrt(1.0 + tan_a * tan_a);
        dout[CAM_O_S] = s1 * dtheta;
        dout[CAM_O_V] = ds1 * omega + s1 * domega;
        dout[CAM_O_A] = dd[3] * dtheta * omega * omega + 2.0 * dd[2] * omega * domega + ds1 * omega_dot
                        + s1 * domega_dot;
        dout[CAM_O_J] = 2.0 * m->m * s1 * ds1;
        dout[CAM_O_M] = stuck ? dT : dP * s1 + P * ds1;   /* stuck: static friction takes the drive's whole torque */
        dout[CAM_O_N_CONTACT] = dP * root + P * tan_a * dtan / root;
    } else {   /* the follower's own s, v; its acceleration with the direction the outputs read from v */
        y[3] = dd[0] - mode.left * cam_vf_clearance(m) + mode.left * x[CAM_ME_GAP];
        y[4] = s1 * omega + mode.left * x[CAM_ME_RATE];
        ds = s1 * dtheta + mode.left * dx[CAM_ME_GAP];
        dout[CAM_O_S] = ds;
        dout[CAM_O_V] = ds1 * omega + s1 * domega + mode.left * dx[CAM_ME_RATE];
        dout[CAM_O_A] = (m->mu == 0.0 || cam_vf_flight_direction(m, y) != 0.0 ? -m->k_spring / m->m : 0.0) * ds;
    }
    dout[CAM_O_THETA_M] = dtheta + (m->compliant ? dx[CAM_TWIST] : 0.0);
    dout[CAM_O_OMEGA_M] = domega_m;
    if (m->compliant)
        dout[CAM_O_M_SHAFT] = dT;
}
