/* Fixed-step methods inside their stability and resolution limits (solvers/hybrid.py _stable_step).
 * Not yet ported: the fixed-step solvers are written against this contract separately. */
#include "cam_solver.h"

int cam_step_fixed(CamDrive *d, CamIntegrator *it, double remaining, double *dt, long *retries, CamError *err)
{
    *dt = remaining;
    *retries = 0;
    return cam_error(err, CAM_ERR_SIMULATION, "solver '%s' is not yet available in the C engine (model %p)",
                    it->method->name, (void *)d);
}
