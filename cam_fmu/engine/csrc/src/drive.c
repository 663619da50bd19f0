/* One cam drive stepped from one communication point to the next (Python: engine/simulator.py DriveSimulator): the
 * time, the inputs, the formulation and its checks on every published state. Holds no physics. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "cam_solver.h"

int cam_drive_init(CamDrive *d, const CamParams *params, CamError *err)
{
    int status;
    memset(d, 0, sizeof *d);
    if ((status = cam_model_init(&d->model, params, err)) != CAM_OK)
        return status;
    d->form = cam_formulation(&d->model);
    if (d->form == NULL || cam_method(d->model.solver) == NULL) {   /* the generated choices and the registries */
        status = cam_error(err, CAM_ERR_PARAMETER, "formulation %d or solver %d is not in the engine",
                           (int)d->model.formulation, d->model.solver);
        cam_model_free(&d->model);
        return status;
    }
    d->time = 0.0;
    d->u = cam_input_spec(CAM_I_U)->start;
    d->omega_ref = cam_input_spec(CAM_I_OMEGA_REF)->start;
    d->omega_dot_ref = cam_input_spec(CAM_I_OMEGA_DOT_REF)->start;
    d->solver.h_next = 1e-4 < d->model.h_max ? 1e-4 : d->model.h_max;
    if ((status = d->form->init(d, err)) != CAM_OK) {
        cam_model_free(&d->model);
        return status;
    }
    d->stale = 1;
    return CAM_OK;
}

int cam_drive_set_start_time(CamDrive *d, double t0, CamError *err)
{
    char shown[40];
    if (!(isfinite(t0) && fabs(t0) <= 1e15))
        return cam_error(err, CAM_ERR_SIMULATION, "start time = %s s: allowed a finite time in [-1e15, 1e15] s",
                         cam_num(t0, shown));
    if (d->time != d->start_time || d->steps_taken != 0 || d->have_budget)
        return cam_error(err, CAM_ERR_SIMULATION, "the start time is set before the first step (the drive is at "
                         "t = %g s)", d->time);
    d->time = d->start_time = t0;
    return CAM_OK;
}

void cam_drive_free(CamDrive *d)
{
    cam_model_free(&d->model);
}

static int check_input(int index, double value, CamError *err)
{
    const CamVariableSpec *s = cam_input_spec(index);
    char shown[40];
    if (s->low <= value && value <= s->high)
        return CAM_OK;
    return cam_error(err, CAM_ERR_SIMULATION, "input '%s' = %s [%s] is outside the allowed range [%g, %g] %s", s->name,
                    cam_num(value, shown), s->unit, s->low, s->high, s->unit);
}

int cam_drive_set_inputs(CamDrive *d, double u, double omega_ref, double omega_dot_ref, CamError *err)
{
    int status;
    if ((status = check_input(CAM_I_U, u, err)) != CAM_OK || (status = check_input(CAM_I_OMEGA_REF, omega_ref, err))
        || (status = check_input(CAM_I_OMEGA_DOT_REF, omega_dot_ref, err)))
        return status;
    d->u = u;
    d->omega_ref = omega_ref;
    d->omega_dot_ref = omega_dot_ref;
    d->form->set_inputs(d, u, omega_ref, omega_dot_ref);
    d->stale = 1;
    return CAM_OK;
}

/* The error a guard's verdict on a step's outputs stands for, naming the cause. */
static int refuse(CamDrive *d, int verdict, const double out[], CamError *err)
{
    char advice[512], shown[40];
    const CamParamSpec *solver = cam_param_spec(CAM_P_SOLVER);
    int k;
    if (verdict == CAM_PUBLISH_NOT_FINITE) {
        for (k = 0; k < CAM_N_OUTPUTS && isfinite(out[k]); k++)
            ;
        if (k == CAM_N_OUTPUTS)   /* every output finite, their sum overflowed (DriveSimulator had no message) */
            return cam_error(err, CAM_ERR_SIMULATION, "the outputs at t = %g s are too large to check (their sum "
                             "is not finite) with solver '%s', h_max = %g s: reduce h_max or use 'rk45'/'etdrk4'",
                             d->time, solver->choices[d->model.solver], d->model.h_max);
        return cam_error(err, CAM_ERR_SIMULATION, "output '%s' became %s at t = %g s with solver '%s', h_max = %g s: "
                        "reduce h_max or use 'rk45'/'etdrk4'", cam_output_spec(k)->name,
                        cam_num(out[k], shown), d->time, solver->choices[d->model.solver],
                        d->model.h_max);
    }
    d->form->advice(d, advice, sizeof advice);
    if (verdict == CAM_PUBLISH_CLEARANCE)
        return cam_error(err, CAM_ERR_SIMULATION, "the follower is %.6g m from the cam at t = %g s, beyond the "
                        "clearance c = %g m: a contact event was missed; %s",
                        fabs(out[CAM_O_S] - out[CAM_O_S_CAM]) * d->model.q_scale * cam_follower_length(&d->model),
                        d->time, d->model.c, advice);
    {
        double excess, tolerance;
        cam_energy_excess(&d->budget, out, &excess, &tolerance);
        return cam_error(err, CAM_ERR_SIMULATION, "the state at t = %g s holds %.6g J more energy than the source "
                        "delivered (tolerance %.3g J): energy was created, the result cannot be trusted; %s", d->time,
                        excess, tolerance, advice);
    }
}

/* The formulation's outputs, an arm's train end in its own units beside the lift units' (kind.c). */
static void publish(CamDrive *d, double out[])
{
    d->form->outputs(d, out);
    cam_arm_end_outputs(&d->model, out);
}

int cam_drive_do_step(CamDrive *d, double t, double h, double u, double omega_ref, double omega_dot_ref,
                      CamError *err)
{
    double out[CAM_N_OUTPUTS];
    char shown[40];
    long steps = 0;
    int status, verdict, opened = 0;
    CamEnergy opening;
    if (!isfinite(t) || fabs(t - d->time) > CAM_TIME_SLACK(d->time))
        return cam_error(err, CAM_ERR_SIMULATION, "communication point t = %.17g s is not where the drive is, "
                         "t = %.17g s (allowed difference %.3g s)", t, d->time, CAM_TIME_SLACK(d->time));
    if (!(h > 0.0 && isfinite(h)))
        return cam_error(err, CAM_ERR_SIMULATION, "communication step size = %s s: allowed (0, inf)",
                        cam_num(h, shown));
    if ((status = cam_drive_set_inputs(d, u, omega_ref, omega_dot_ref, err)) != CAM_OK)
        return status;
    if (!d->have_budget && d->form->energy_bounded) {   /* the books open at the first step that is taken */
        if (d->stale) {
            publish(d, d->values);
            d->stale = 0;
        }
        cam_energy_init(&opening, &d->model, d->values);
        opened = 1;
    }
    if ((status = d->form->advance(d, h, d->time, &steps, err)) != CAM_OK)
        return status;   /* refused: the state as before the step, the books unopened */
    if (opened) {
        d->budget = opening;
        d->have_budget = 1;
    }
    publish(d, out);
    verdict = cam_publishable(&d->model, out, d->have_budget ? &d->budget : NULL, d->u, h);
    d->last_steps = steps;
    d->steps_taken += steps;
    d->time = t + h;
    if (verdict != CAM_PUBLISH_OK)
        return refuse(d, verdict, out, err);
    memcpy(d->values, out, sizeof out);
    d->stale = 0;
    return CAM_OK;
}

const double *cam_drive_outputs(CamDrive *d)
{
    if (d->stale) {
        publish(d, d->values);
        d->stale = 0;
    }
    return d->values;
}

int cam_drive_run(CamDrive *d, long n_steps, const double *table, double *out, long *done, CamError *err)
{
    long k;
    int status;
    *done = 0;
    for (k = 0; k < n_steps; k++) {
        const double *row = table + 5 * k;
        status = cam_drive_do_step(d, row[0], row[1], row[2], row[3], row[4], err);
        if (status != CAM_OK)
            return status;
        memcpy(out + (size_t)CAM_N_OUTPUTS * (size_t)k, d->values, sizeof d->values);
        *done = k + 1;
    }
    return CAM_OK;
}

/* ------------------------------------------------------------------ Model Exchange's state (cam_drive.h) */

void cam_drive_me_states(const CamDrive *d, double x[CAM_ME_NX])
{
    memcpy(x, d->x, sizeof d->x);
}

void cam_drive_set_me_states(CamDrive *d, const double x[CAM_ME_NX])
{
    /* a drive holds the slots past its own at 0 (their derivatives are 0: a host's solver leaves them) */
    memcpy(d->x, x, (size_t)d->model.slots * sizeof x[0]);
    d->stale = 1;
}

void cam_drive_me_rates(const CamDrive *d, const double x[CAM_ME_NX], double dx[CAM_ME_NX])
{
    int k;
    for (k = 0; k < CAM_ME_NX; k++)   /* the held slots */
        dx[k] = 0.0;
    cam_rhs(&d->model, &d->mode, x, d->form_u, dx);
    for (k = d->model.slots; k < CAM_ME_NX; k++)
        dx[k] = 0.0;
}

void cam_drive_me_tangent(const CamDrive *d, const double x[CAM_ME_NX], const double seed[CAM_ME_NX], double du,
                          double ddx[CAM_ME_NX], double dout[])
{
    int k;
    if (d->form->exchange != NULL) {
        d->form->exchange->tangent(d, x, seed, du, ddx, dout);
    } else {
        cam_tangent(&d->model, &d->mode, x, d->form_u, seed, du, ddx, dout, NULL);
        for (k = d->model.slots; k < CAM_ME_NX; k++)   /* the held slots (a rigid shaft's, the follower's gap) */
            ddx[k] = 0.0;
    }
    cam_arm_end_outputs(&d->model, dout);
}
