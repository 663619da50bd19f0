/* The energy-consistent formulation under a voltage input (docs/model.md section 5; the readable model: physics/formulations/consistent.py):
 * an ODE with events, advanced by the solvers of cam_solver.h. */
#include <stdio.h>

#include "cam_solver.h"

static int consistent_init(CamDrive *d, CamError *err)
{
    const double *v = d->model.params.v;
    (void)err;
    cam_initial(&d->model, v[CAM_P_THETA0], v[CAM_P_OMEGA0], v[CAM_P_I0], d->x, &d->mode);
    d->form_u = d->u;
    cam_settle(&d->model, &d->mode, d->x, d->u, 0);
    d->solver.k1_valid = 0;
    return CAM_OK;
}

static void consistent_set_inputs(CamDrive *d, double u, double omega_ref, double omega_dot_ref)
{
    (void)omega_ref;
    (void)omega_dot_ref;
    if (u == d->form_u)
        return;   /* settled for this input already (each advance settles again at its start) */
    d->form_u = u;
    cam_settle(&d->model, &d->mode, d->x, u, 0);   /* at rest: stuck, or starting now */
}

static int consistent_advance(CamDrive *d, double h, double time, long *steps, CamError *err)
{
    return cam_integrate(d, h, time, steps, err);
}

static void consistent_outputs(CamDrive *d, double out[])
{
    int known = d->solver.k1_valid && !d->mode.stuck && d->solver.fsal_u == d->form_u;
    cam_outputs(&d->model, &d->mode, d->x, d->form_u, d->solver.k1[CAM_OMEGA], known, out);
}

static void consistent_advice(const CamDrive *d, char *buf, size_t len)
{
    const CamParamSpec *solver = cam_param_spec(CAM_P_SOLVER);
    const CamMethod *method = cam_method(d->model.solver);
    if (method != NULL && method->adaptive) {
        /* its accuracy is rtol/atol's: name them, never advise the solver in use */
        snprintf(buf, len, "solver '%s' with rtol = %g, atol = %g and h_max = %g s: tighten rtol/atol "
                 "(defaults %g, %g), reduce h_max or the communication step", solver->choices[d->model.solver],
                 d->model.rtol, d->model.atol, d->model.h_max, cam_param_spec(CAM_P_RTOL)->default_value,
                 cam_param_spec(CAM_P_ATOL)->default_value);
        return;
    }
    snprintf(buf, len, "solver '%s' with h_max = %g s: reduce h_max or the communication step, or use solver 'rk45'",
             solver->choices[d->model.solver], d->model.h_max);
}

const CamFormulation cam_consistent = {
    "consistent", 1, consistent_init, consistent_set_inputs, consistent_advance, consistent_outputs,
    consistent_advice, NULL, NULL, NULL,
};
