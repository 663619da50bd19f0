/* Exponential RK4 for the motor's linear part (the former Python engine's etdrk4), order of operations kept.
 *
 * ETD runs on the current's deviation e = i - (u - c_e omega) / R from its quasi-static value:
 * de/dt = -(R/L) e + (c_e/R) omega_dot, and on e's torque c_m e / J on omega. The linear part
 * [[0, a], [0, c]] on (omega, e), c = -R/L and a = c_m / J (the torque gain, frozen over the step), is
 * integrated exactly (Cox and Matthews 2002), so the electrical pole and the fast transient after a
 * break-away are exact at any step; theta is plain RK4. A function F of h [[0, a], [0, c]] is
 * [[F(0), a h (F(ch) - F(0)) / (ch)], [0, F(ch)]]; the divided differences of phi_k are phi_(k+1). */
#include <math.h>

#include "cam_solver.h"

/* (e^z, phi1..phi4)(z), phi_k(z) = sum_n z^n / (n + k)!: a 30-term series near 0, else the recurrences. */
static void phi_functions(double z, double out[5])
{
    int n, k;
    if (fabs(z) < 1.0) {
        double p[4] = {0.0, 0.0, 0.0, 0.0}, term = 1.0, denom;   /* term = z^n / n! */
        for (n = 0; n < 30; n++) {
            denom = 1.0;
            for (k = 0; k < 4; k++) {
                denom *= (double)(n + k + 1);
                p[k] += term / denom;
            }
            term *= z / (double)(n + 1);
        }
        out[0] = exp(z);
        for (k = 0; k < 4; k++)
            out[k + 1] = p[k];
        return;
    }
    out[0] = exp(z);
    out[1] = (out[0] - 1.0) / z;
    out[2] = (out[1] - 1.0) / z;
    out[3] = (out[2] - 0.5) / z;
    out[4] = (out[3] - 1.0 / 6.0) / z;
}

/* The step's coefficients for the decay rate c [1/s] and the step h [s]. */
typedef struct {
    double h, c;
    double e_full, e_half, dd_e_full, dd_e_half, phi_half, dd_phi_half;
    double f[3], dd_f[3];
} EtdCoefficients;

static void coefficients(double c, double h, EtdCoefficients *k)
{
    double full[5], half[5];
    phi_functions(c * h, full);
    phi_functions(0.5 * c * h, half);
    k->h = h;
    k->c = c;
    k->e_full = full[0];
    k->e_half = half[0];
    k->dd_e_full = full[1];
    k->dd_e_half = half[1];
    k->phi_half = half[1];
    k->dd_phi_half = half[2];
    k->f[0] = full[1] - 3.0 * full[2] + 4.0 * full[3];
    k->f[1] = full[2] - 2.0 * full[3];
    k->f[2] = -full[2] + 4.0 * full[3];
    k->dd_f[0] = full[2] - 3.0 * full[3] + 4.0 * full[4];
    k->dd_f[1] = full[3] - 2.0 * full[4];
    k->dd_f[2] = -full[3] + 4.0 * full[4];
}

static double quasi_static_current(const CamModel *m, double u, double omega)
{
    return (u - m->c_e * omega) / m->R;
}

/* d(theta, omega, e)/dt at z: the drive's derivatives with i = i_qs(omega) + e. */
static void deviation_rate(const CamModel *m, const CamMode *mode, const double z[CAM_NX], double u,
                           double out[CAM_NX])
{
    double x[CAM_NX], d[CAM_NX];
    x[CAM_THETA] = z[CAM_THETA];
    x[CAM_OMEGA] = z[CAM_OMEGA];
    x[CAM_CURRENT] = quasi_static_current(m, u, z[CAM_OMEGA]) + z[CAM_CURRENT];
    cam_rhs(m, mode, x, u, d);
    out[0] = d[0];
    out[1] = d[1];
    out[2] = -(m->R / m->L) * z[CAM_CURRENT] + m->c_e / m->R * d[1];
}

/* The nonlinear remainder: the rate less the linear part [[0, a], [0, c]] on (omega, e). */
static void nonlinear(const CamModel *m, const CamMode *mode, const double v[CAM_NX], double u, double a, double c,
                      double out[CAM_NX])
{
    double d[CAM_NX];
    deviation_rate(m, mode, v, u, d);
    out[0] = d[0];
    out[1] = d[1] - a * v[2];
    out[2] = d[2] - c * v[2];
}

/* e^(M/2) v + (h/2) phi1(M/2) n on the block; an RK4 stage on theta. */
static void half_stage(const EtdCoefficients *k, double a_half, const double v[CAM_NX], const double n[CAM_NX],
                       double out[CAM_NX])
{
    double hh = 0.5 * k->h;
    out[0] = v[0] + hh * n[0];
    out[1] = v[1] + a_half * k->dd_e_half * v[2] + hh * (n[1] + a_half * k->dd_phi_half * n[2]);
    out[2] = k->e_half * v[2] + hh * k->phi_half * n[2];
}

void cam_etdrk4_step(const CamMethod *method, const CamModel *m, const CamMode *mode, const double x[CAM_NX],
                     double u, double h, CamStepWork *w)
{
    EtdCoefficients k;
    double rate, a, y[CAM_NX], n_y[CAM_NX], st_a[CAM_NX], n_a[CAM_NX], st_b[CAM_NX], n_b[CAM_NX];
    double st_c[CAM_NX], n_c[CAM_NX], mix[CAM_NX], wt = 1.0 / 6.0, a_full;
    int slot;
    if (!m->has_current || m->follower_states) {   /* no pole (or a follower's slots): the classical RK4 */
        CamMethod rk4 = *method;
        rk4.tableau = &cam_rk4;
        cam_rk_step(&rk4, m, mode, x, u, h, w);
        return;
    }
    rate = m->R / m->L;
    coefficients(-rate, h, &k);
    a = cam_torque_gain(m, mode, x);
    y[0] = x[CAM_THETA];
    y[1] = x[CAM_OMEGA];
    y[2] = x[CAM_CURRENT] - quasi_static_current(m, u, x[CAM_OMEGA]);
    nonlinear(m, mode, y, u, a, k.c, n_y);
    half_stage(&k, a * (0.5 * h), y, n_y, st_a);
    nonlinear(m, mode, st_a, u, a, k.c, n_a);
    half_stage(&k, a * (0.5 * h), y, n_a, st_b);
    nonlinear(m, mode, st_b, u, a, k.c, n_b);
    for (slot = 0; slot < CAM_NX; slot++)
        mix[slot] = 2.0 * n_b[slot] - n_y[slot];
    half_stage(&k, a * (0.5 * h), st_a, mix, st_c);
    nonlinear(m, mode, st_c, u, a, k.c, n_c);
    a_full = a * h;
    w->x_new[CAM_THETA] = y[0] + h * (wt * n_y[0] + 2.0 * wt * (n_a[0] + n_b[0]) + wt * n_c[0]);
    w->x_new[CAM_OMEGA] = y[1] + a_full * k.dd_e_full * y[2]
                          + h * (wt * n_y[1] + 2.0 * wt * (n_a[1] + n_b[1]) + wt * n_c[1])
                          + h * a_full * (k.dd_f[0] * n_y[2] + 2.0 * k.dd_f[1] * (n_a[2] + n_b[2]) + k.dd_f[2] * n_c[2]);
    w->x_new[CAM_CURRENT] = k.e_full * y[2] + h * (k.f[0] * n_y[2] + 2.0 * k.f[1] * (n_a[2] + n_b[2]) + k.f[2] * n_c[2]);
    w->x_new[CAM_CURRENT] += quasi_static_current(m, u, w->x_new[CAM_OMEGA]);
}

void cam_exponential_pair(const CamModel *m, const CamMode *mode, const double x[CAM_NX], double u, double h,
                          CamStepWork *w)
{
    double full[CAM_NX], mid[CAM_NX];
    int slot;
    cam_etdrk4_step(NULL, m, mode, x, u, h, w);
    for (slot = 0; slot < CAM_NX; slot++)
        full[slot] = w->x_new[slot];
    cam_etdrk4_step(NULL, m, mode, x, u, 0.5 * h, w);
    for (slot = 0; slot < CAM_NX; slot++)
        mid[slot] = w->x_new[slot];
    cam_etdrk4_step(NULL, m, mode, mid, u, 0.5 * h, w);
    for (slot = 0; slot < CAM_NX; slot++)
        w->error[slot] = (w->x_new[slot] - full[slot]) / 15.0;
}
