/* Fixed-step methods inside their stability and resolution limits (the former Python engine's
 * stable step), with the order of operations kept.
 *
 * Two limits: stability (h times the fastest rate of the dynamics within the method's stability
 * factor) and resolution (the cam turns at most ``resolution`` of the profile's finest angular detail
 * per step: a step cannot resolve a shorter feature). Both are taken at the start and checked again at
 * the end of the step; where the step ends faster (omega grows to 1300 rad/s at 100 V), it is retaken
 * with the limits of the faster end, at most RETRIES times. Measured with the Python engine: rk4 at
 * 100 V gave theta(0.5 s) = 38.96 rad against 67.98 with the stability limit alone; 4e-3 rad off with
 * both. A method without resolution steps (euler) refuses a step that sweeps more than max_sweep of
 * the finest feature instead, naming h_max. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "cam_solver.h"

#define RETRIES 30

static double smaller(double a, double b)
{
    return b < a ? b : a;
}

int cam_step_fixed(CamDrive *d, CamIntegrator *it, double remaining, double *dt_out, long *retries_out,
                   CamError *err)
{
    const CamModel *m = &d->model;
    const CamMethod *method = it->method;
    int electrical = !method->exact_electrical_pole, finite, slot;
    double stab = method->stability, res = method->resolution, u = d->form_u;
    double rate = cam_stiffness_rate(m, &d->mode, d->x, electrical), sweep = cam_profile_rate(m, d->x);
    double dt, rate_end, sweep_end, swept, fastest;
    long retries = 0;
    for (;;) {
        dt = smaller(remaining, m->h_max);
        dt = smaller(dt, rate > 0.0 ? stab / rate : HUGE_VAL);
        dt = smaller(dt, sweep > 0.0 ? res / sweep : HUGE_VAL);
        memcpy(it->work.k[0], d->solver.k1, sizeof d->solver.k1);
        method->step(method, m, &d->mode, d->x, u, dt, &it->work);
        cam_impose_motion(m, d->x, u, dt, it->work.x_new);
        finite = 1;
        for (slot = 0; slot < m->slots; slot++)
            finite = finite && isfinite(it->work.x_new[slot]);
        if (finite) {
            rate_end = cam_stiffness_rate(m, &d->mode, it->work.x_new, electrical);
            sweep_end = cam_profile_rate(m, it->work.x_new);
        } else {
            rate_end = sweep_end = HUGE_VAL;
        }
        if ((dt * rate_end <= 1.25 * stab && dt * sweep_end <= 1.25 * res) || retries >= RETRIES) {
            fastest = sweep_end > sweep ? sweep_end : sweep;
            swept = dt * fastest;
            *dt_out = dt;
            *retries_out = retries;
            if (swept > method->max_sweep) {
                char a[32], b[32], c[32], e[32], f[32];
                snprintf(a, sizeof a, "%g", m->h_max);
                snprintf(b, sizeof b, "%.3g", swept);
                snprintf(c, sizeof c, "%.4g", it->work.x_new[CAM_OMEGA]);
                snprintf(e, sizeof e, "%g", method->max_sweep);
                snprintf(f, sizeof f, "%.3g", method->max_sweep / fastest);
                char g[120] = "";
                if (m->train)   /* cam_profile_rate: a radian of the train's phase counts as a feature */
                    snprintf(g, sizeof g, "; and the follower train's %.4g 1/s from %s, a radian of its ringing "
                             "counted as a feature", m->train_rate, cam_train_names(m));
                return cam_error(err, CAM_ERR_SIMULATION,
                                 "solver '%s' with h_max = %s s turns the cam through %s of the profile's finest "
                                 "feature in one step (omega = %s rad/s%s), more than %s: its first-order error is "
                                 "large there; reduce h_max below %s s or use solver 'rk4' or 'rk45'",
                                 method->name, a, b, c, g, e, f);
            }
            memcpy(it->x_end, it->work.x_new, sizeof it->x_end);
            return CAM_OK;
        }
        if (isfinite(rate_end))
            rate = rate_end > rate ? rate_end : rate;
        else
            rate = 4.0 * stab / dt > rate ? 4.0 * stab / dt : rate;
        if (isfinite(sweep_end))
            sweep = sweep_end > sweep ? sweep_end : sweep;
        else
            sweep = 4.0 * res / dt > sweep ? 4.0 * res / dt : sweep;
        retries += 1;
    }
}
