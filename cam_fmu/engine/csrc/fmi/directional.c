/* Model Exchange's directional derivatives (directional.h): value references to the engine's tangent and back (the
 * drive's, jacobian.c; a follower of its own's, jacobian_follower.c). */
#include "directional.h"

static int refuse(CamExchange *e, const char *what, unsigned vr)
{
    CamKind kind;
    const char *name = "?";
    if (!cam_instance_variable(vr, &kind, &name))
        name = "no variable";
    return cam_error(cam_instance_error(e->instance), CAM_ERR_SIMULATION, "directional derivative: value reference "
                     "%u ('%s') is no %s; allowed: %s", vr, name, what,
                     what[0] == 'k' ? "the continuous states x_* and the inputs u, omega_ref, omega_dot_ref"
                                    : "the state derivatives der(x_*) and the outputs");
}

int cam_exchange_directional(CamExchange *e, const unsigned unknown[], size_t n_unknown, const unsigned known[],
                             size_t n_known, const double dv_known[], double dv_unknown[])
{
    CamDrive *d = e->drive;
    double x[CAM_ME_NX], seed[CAM_ME_NX] = {0.0}, du = 0.0, ddx[CAM_ME_NX] = {0.0}, dout[CAM_N_OUTPUTS];
    size_t k;
    int status;
    if ((n_known > 0 && (known == NULL || dv_known == NULL)) || (n_unknown > 0 && (unknown == NULL || dv_unknown == NULL)))
        return cam_error(cam_instance_error(e->instance), CAM_ERR_SIMULATION,
                         "directional derivative: the arrays must not be NULL");
    for (k = 0; k < n_known; k++) {
        unsigned vr = known[k];
        if (vr >= CAM_VR_STATES && vr < CAM_VR_STATES + CAM_ME_NX) {
            seed[vr - CAM_VR_STATES] += dv_known[k];   /* the follower's gap slots move a follower of its own only */
        } else if (vr == CAM_VR_INPUTS + CAM_I_U) {
            du += dv_known[k];
        } else if (vr - (unsigned)CAM_VR_INPUTS >= (unsigned)CAM_N_INPUTS) {   /* omega_ref, omega_dot_ref:
                                                                                      * no effect on a voltage drive */
            return refuse(e, "known (a continuous state or input)", vr);
        }
    }
    for (k = 0; k < n_unknown; k++)
        if (!(unknown[k] >= CAM_VR_DERIVATIVES && unknown[k] < CAM_VR_DERIVATIVES + CAM_ME_NX)
            && !(unknown[k] >= CAM_VR_OUTPUTS && unknown[k] < CAM_VR_OUTPUTS + CAM_N_OUTPUTS))
            return refuse(e, "unknown (a state derivative or output)", unknown[k]);
    cam_exchange_sync(e);
    cam_drive_me_states(d, x);
    if (d->form == &cam_voltage_follower) {   /* a follower of its own: its gap and rate are states */
        cam_vf_tangent(d, x, d->form_u, seed, du, ddx, dout);
    } else {
        status = cam_tangent(&d->model, &d->mode, x, d->form_u, seed, du, ddx, dout, cam_instance_error(e->instance));
        if (status != CAM_OK)
            return status;
        for (k = (size_t)d->model.slots; k < CAM_ME_NX; k++)   /* the held slots (a rigid shaft's, the gap's): 0 */
            ddx[k] = 0.0;
    }
    for (k = 0; k < n_unknown; k++) {
        unsigned vr = unknown[k];
        if (vr >= CAM_VR_OUTPUTS && vr < CAM_VR_OUTPUTS + CAM_N_OUTPUTS)
            dv_unknown[k] = dout[vr - CAM_VR_OUTPUTS];
        else
            dv_unknown[k] = ddx[vr - CAM_VR_DERIVATIVES];
    }
    return CAM_OK;
}
