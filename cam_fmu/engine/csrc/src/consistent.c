/* The energy-consistent formulation under a voltage input (docs/model.md section 5; the readable model: physics/formulations/consistent.py):
 * an ODE with events, advanced by the solvers of cam_solver.h; with a follower of its own (section 13.6) too. */
#include <stdio.h>
#include <string.h>

#include "cam_solver.h"
#include "cam_voltage_follower.h"

/* The start; a follower of its own (the formulation's transition hook) sets itself on its flank
 * (voltage_follower.c cam_vf_start). */
static int consistent_init(CamDrive *d, CamError *err)
{
    const double *v = d->model.params.v;
    (void)err;
    cam_initial(&d->model, v[CAM_P_THETA0], v[CAM_P_OMEGA0], v[CAM_P_I0], d->x, &d->mode);
    d->form_u = d->u;
    memset(&d->speed, 0, sizeof d->speed);
    if (d->form->transition != NULL)
        cam_vf_start(d, d->u);
    else
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
    d->step_events[0] = '\0';
    if (d->form->transition != NULL)   /* at rest: stuck, or starting now */
        d->form->transition(d, EV_NONE, d->time);
    else
        cam_settle(&d->model, &d->mode, d->x, u, 0);
}

static int consistent_advance(CamDrive *d, double h, double time, long *steps, CamError *err)
{
    d->step_events[0] = '\0';
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

/* The same with the follower a body of its own (closures 'form', 'spring'; voltage_follower.c): its outputs,
 * exchange, transitions and step bound as hooks. */
const CamFormulation cam_voltage_follower = {
    "consistent", 1, consistent_init, consistent_set_inputs, consistent_advance, cam_vf_outputs, consistent_advice,
    &cam_vf_exchange, cam_vf_apply, cam_vf_step_limit,
};
