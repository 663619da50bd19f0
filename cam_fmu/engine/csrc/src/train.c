/* The follower train under the speed drive's imposed motion (docs/model.md 14.6; the reference:
 * reference/train_speed.py): the cam turns as theta(t) = theta0 + omega0 t + alpha t^2 / 2 over a step, the follower
 * rides on it, and the end mass x[CAM_X_END], x[CAM_V_END] follows m_end v_e' = F_train + F_ex with
 * F_train = k_train (s - x_e) + d_train (s' omega - v_e). Dormand-Prince 5(4) under error control on the model's
 * rtol and atol (the speed drive has no solver of its own to choose); its step carried in *h_next. */
#include <math.h>

#include "cam_solver.h"

#define TRAIN_SLOTS 3           /* (tau, x_e, v_e): the time into the step makes the rates autonomous */

typedef struct {                /* the cam's motion over the step */
    const CamModel *m;
    double theta0, omega0, alpha;   /* rad, rad/s, rad/s2 */
} Motion;

static void rates(void *ctx, const double *y, double *dy)
{
    const Motion *mo = ctx;
    double tau = y[0], theta = mo->theta0 + (mo->omega0 + 0.5 * mo->alpha * tau) * tau;
    double F = cam_train_force(mo->m, theta, mo->omega0 + mo->alpha * tau, y[1], y[2]);
    dy[0] = 1.0;
    dy[1] = y[2];
    dy[2] = (F + mo->m->F_ex) / mo->m->m_end;
}

int cam_train_follow(const CamModel *m, double x[CAM_NX], double theta0, double omega0, double alpha, double h,
                     double *h_next, long *steps, CamError *err)
{
    const CamTableau *t = &cam_dopri5;
    Motion mo = {m, theta0, omega0, alpha};
    double y[TRAIN_SLOTS] = {0.0, x[CAM_X_END], x[CAM_V_END]}, out[TRAIN_SLOTS], e[TRAIN_SLOTS];
    double k[(CAM_MAX_STAGES + 1) * TRAIN_SLOTS], dt, norm, scale, bound;
    int slot;
    *steps = 0;
    while (h - y[0] > 1e-12 * h) {
        bound = h - y[0];
        dt = *h_next < bound ? *h_next : bound;
        rates(&mo, y, k);   /* k[0]: the rates at y, for every trial from it */
        for (;;) {
            cam_tableau_step(t, TRAIN_SLOTS, TRAIN_SLOTS, rates, &mo, y, dt, k, out, e);
            for (norm = 0.0, slot = 1; slot < TRAIN_SLOTS; slot++) {
                scale = fabs(y[slot]) > fabs(out[slot]) ? fabs(y[slot]) : fabs(out[slot]);
                norm += pow(e[slot] / (m->atol + m->rtol * scale), 2.0);
            }
            if (cam_step_control(sqrt(norm / 2.0), t->error_exponent, bound, &dt, h_next))
                break;
            if (dt < 1e-12 * h)
                return cam_error(err, CAM_ERR_REJECTED, "the follower train's end mass cannot meet rtol = %g, atol = "
                                 "%g: its step fell below %g s (1e-12 of the communication step); loosen rtol/atol or "
                                 "check k_train, d_train, m_end", m->rtol, m->atol, 1e-12 * h);
        }
        y[0] += dt;   /* the time exactly (the step's sum would round) */
        y[1] = out[1];
        y[2] = out[2];
        *steps += 1;
    }
    x[CAM_X_END] = y[1];
    x[CAM_V_END] = y[2];
    return CAM_OK;
}
