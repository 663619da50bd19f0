/* The drive's state as a flat, versioned array of doubles (the CAM_S_* slots of cam_model.h), and its
 * restoration with every entry checked before use (DriveSimulator.get_state/set_state in engine/simulator.py). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "cam_model.h"

void cam_drive_get_state(const CamDrive *d, double s[CAM_STATE_LEN])
{
    const CamPaperState *p = &d->paper;
    memset(s, 0, sizeof(double) * CAM_STATE_LEN);
    s[CAM_S_VERSION] = CAM_STATE_VERSION;
    s[CAM_S_FORMULATION] = (double)d->model.formulation;
    s[CAM_S_TIME] = d->time;
    s[CAM_S_U] = d->u;
    s[CAM_S_OMEGA_REF] = d->omega_ref;
    s[CAM_S_OMEGA_DOT_REF] = d->omega_dot_ref;
    s[CAM_S_H_NEXT] = d->solver.h_next;
    s[CAM_S_STEPS_TAKEN] = (double)d->steps_taken;
    memcpy(s + CAM_S_X, d->x, sizeof d->x);
    s[CAM_S_STUCK] = d->mode.stuck ? 1.0 : 0.0;
    s[CAM_S_DIRECTION] = d->mode.direction;
    s[CAM_S_CONTACT] = (double)d->mode.contact;
    s[CAM_S_S_FREE] = d->mode.s_free;
    s[CAM_S_SIDE] = d->mode.side;
    s[CAM_S_FORM_U] = d->form_u;
    s[CAM_S_HAVE_BUDGET] = d->have_budget ? 1.0 : 0.0;
    s[CAM_S_WORK_IN] = d->budget.work_in;
    s[CAM_S_WORK_ABS] = d->budget.work_abs;
    s[CAM_S_BUDGET_THETA] = d->budget.theta;
    s[CAM_S_BUDGET_I] = d->budget.i;
    s[CAM_S_E_MECH0] = d->budget.e_mech0;
    s[CAM_S_E_MAG0] = d->budget.e_mag0;
    s[CAM_S_PAPER + 0] = p->theta;
    s[CAM_S_PAPER + 1] = p->omega;
    s[CAM_S_PAPER + 2] = p->i;
    s[CAM_S_PAPER + 3] = p->J;
    s[CAM_S_PAPER + 4] = p->M;
    s[CAM_S_PAPER + 5] = p->s;
    s[CAM_S_PAPER + 6] = p->v;
    s[CAM_S_PAPER + 7] = p->a;
    s[CAM_S_PAPER + 8] = p->alpha;
    s[CAM_S_PAPER + 9] = p->voltage;
    s[CAM_S_PAPER + 10] = p->M_l;
    s[CAM_S_SPEED + 0] = d->speed.theta;
    s[CAM_S_SPEED + 1] = d->speed.s;
    s[CAM_S_SPEED + 2] = d->speed.speed;
}

static const char *const ENTRY[] = {"version", "formulation", "time", "u", "omega_ref", "omega_dot_ref", "h_next",
                                    "steps_taken"};

int cam_drive_set_state(CamDrive *d, const double s[CAM_STATE_LEN], CamError *err)
{
    char shown[40];
    int k;
    CamMode mode;
    if (s[CAM_S_VERSION] != CAM_STATE_VERSION)
        return cam_error(err, CAM_ERR_SIMULATION, "state version %s: this engine reads version %g",
                        cam_num(s[CAM_S_VERSION], shown), CAM_STATE_VERSION);
    if (s[CAM_S_FORMULATION] != (double)d->model.formulation)
        return cam_error(err, CAM_ERR_SIMULATION, "state of formulation %s, this drive's is %d",
                        cam_num(s[CAM_S_FORMULATION], shown), (int)d->model.formulation);
    for (k = CAM_S_TIME; k <= CAM_S_H_NEXT; k++)
        if (!isfinite(s[k]))
            return cam_error(err, CAM_ERR_SIMULATION, "state entry '%s' = %s is not finite", ENTRY[k],
                            cam_num(s[k], shown));
    if (!(s[CAM_S_STEPS_TAKEN] >= 0.0 && s[CAM_S_STEPS_TAKEN] <= 9.0e15))
        return cam_error(err, CAM_ERR_SIMULATION, "state entry 'steps_taken' = %s is not a count",
                        cam_num(s[CAM_S_STEPS_TAKEN], shown));
    for (k = CAM_S_X; k < CAM_S_END; k++)
        if (!isfinite(s[k]))
            return cam_error(err, CAM_ERR_SIMULATION, "state entry %d = %s is not finite", k,
                            cam_num(s[k], shown));
    mode.stuck = s[CAM_S_STUCK] != 0.0;
    mode.direction = s[CAM_S_DIRECTION];
    mode.contact = s[CAM_S_CONTACT] == 1.0 ? 1 : (s[CAM_S_CONTACT] == -1.0 ? -1 : 0);   /* checked below */
    mode.s_free = s[CAM_S_S_FREE];
    mode.side = s[CAM_S_SIDE];
    if ((s[CAM_S_STUCK] != 0.0 && s[CAM_S_STUCK] != 1.0) || (mode.direction != 1.0 && mode.direction != -1.0)
        || (mode.side != 1.0 && mode.side != -1.0) || (double)mode.contact != s[CAM_S_CONTACT]
        || (s[CAM_S_HAVE_BUDGET] != 0.0 && s[CAM_S_HAVE_BUDGET] != 1.0))
        return cam_error(err, CAM_ERR_SIMULATION, "state mode (stuck %g, direction %g, contact %g, side %g) is not a "
                        "valid mode", s[CAM_S_STUCK], s[CAM_S_DIRECTION], s[CAM_S_CONTACT], s[CAM_S_SIDE]);
    d->stale = 1;
    d->time = s[CAM_S_TIME];
    d->u = s[CAM_S_U];
    d->omega_ref = s[CAM_S_OMEGA_REF];
    d->omega_dot_ref = s[CAM_S_OMEGA_DOT_REF];
    d->solver.h_next = s[CAM_S_H_NEXT];
    d->solver.k1_valid = 0;
    d->steps_taken = (long)s[CAM_S_STEPS_TAKEN];
    memcpy(d->x, s + CAM_S_X, sizeof d->x);
    if (!d->model.has_current)
        d->x[CAM_CURRENT] = 0.0;
    if (!d->model.compliant)
        d->x[CAM_TWIST] = d->x[CAM_OMEGA_M] = 0.0;
    d->mode = mode;
    d->form_u = s[CAM_S_FORM_U];
    d->paper.theta = s[CAM_S_PAPER + 0];
    d->paper.omega = s[CAM_S_PAPER + 1];
    d->paper.i = s[CAM_S_PAPER + 2];
    d->paper.J = s[CAM_S_PAPER + 3];
    d->paper.M = s[CAM_S_PAPER + 4];
    d->paper.s = s[CAM_S_PAPER + 5];
    d->paper.v = s[CAM_S_PAPER + 6];
    d->paper.a = s[CAM_S_PAPER + 7];
    d->paper.alpha = s[CAM_S_PAPER + 8];
    d->paper.voltage = s[CAM_S_PAPER + 9];
    d->paper.M_l = s[CAM_S_PAPER + 10];
    d->speed.theta = s[CAM_S_SPEED + 0];
    d->speed.s = s[CAM_S_SPEED + 1];
    d->speed.speed = s[CAM_S_SPEED + 2];
    d->have_budget = s[CAM_S_HAVE_BUDGET] != 0.0;
    if (d->have_budget) {
        const double *out = cam_drive_outputs(d);
        cam_energy_init(&d->budget, &d->model, out);
        d->budget.work_in = s[CAM_S_WORK_IN];
        d->budget.work_abs = s[CAM_S_WORK_ABS];
        d->budget.theta = s[CAM_S_BUDGET_THETA];
        d->budget.i = s[CAM_S_BUDGET_I];
        d->budget.e_mech0 = s[CAM_S_E_MECH0];
        d->budget.e_mag0 = s[CAM_S_E_MAG0];
    }
    return CAM_OK;
}
