/* The solvers the parameter ``solver`` names (solvers/ of the Python engine): each a few lines of data
 * over the generic step of rk.c and the one driver of integrate.c. */
#include <math.h>
#include <stddef.h>

#include "cam_solver.h"

/* Adaptive Dormand-Prince 5(4) with error control (rtol, atol); h_max caps its step. The smallest
 * step is 1e-12 of the communication step; theta's error is scaled by at most 2 pi. */
static const CamMethod RK45 = {"rk45", &cam_dopri5, cam_rk_step, 1, HUGE_VAL, HUGE_VAL, HUGE_VAL, 0};

const CamMethod *cam_method(int solver_choice)
{
    switch (solver_choice) {
    case CAM_CHOICE_SOLVER_RK45:
        return &RK45;
    default:
        return NULL;   /* euler, rk4, etdrk4: not yet ported (their entries go here) */
    }
}
