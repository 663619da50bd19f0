/* The solvers the parameter ``solver`` names: each a few lines of data over the generic step of rk.c
 * (or its own step function, etdrk4.c) and the one driver of integrate.c. The limits are the measured
 * ones of the former Python solvers (docs/performance.md). */
#include <math.h>
#include <stddef.h>

#include "cam_solver.h"

/* Adaptive Dormand-Prince 5(4) with error control (rtol, atol); h_max caps its step. The smallest
 * step is 1e-12 of the communication step; theta's error is scaled by at most 2 pi. */
static const CamMethod RK45 = {"rk45", &cam_dopri5, cam_rk_step, 1, HUGE_VAL, HUGE_VAL, HUGE_VAL, 0};

/* Adaptive Bogacki-Shampine 3(2) with error control (rtol, atol): half the stages of rk45 per step, for
 * loose tolerances. */
static const CamMethod RK23 = {"rk23", &cam_bs23, cam_rk_step, 1, HUGE_VAL, HUGE_VAL, HUGE_VAL, 0};

/* Explicit Euler: no resolution sub-steps (measured on fig. 6, sub-stepping euler to the profile's
 * features made its error larger, 0.59 rad against 0.053 rad at h_max 1 ms); instead a step that sweeps
 * more than a quarter of the finest feature is refused, naming h_max (it was 41 rad of 68 off at 100 V). */
static const CamMethod EULER = {"euler", &cam_euler, cam_rk_step, 0, 1.0, HUGE_VAL, 0.25, 0};

/* The classical RK4: resolution 0.1 (100 V: 4e-3 rad of 68; 29 rad off with the stability limit alone). */
static const CamMethod RK4 = {"rk4", &cam_rk4, cam_rk_step, 0, 2.5, 0.1, HUGE_VAL, 0};

/* Exponential RK4, exact on the electrical pole (400 V: 0.07 rad of 266; 214 rad off without resolution). */
static const CamMethod ETDRK4 = {"etdrk4", NULL, cam_etdrk4_step, 0, 2.5, 0.1, HUGE_VAL, 1};

const CamMethod *cam_method(int solver_choice)
{
    switch (solver_choice) {
    case CAM_CHOICE_SOLVER_EULER:
        return &EULER;
    case CAM_CHOICE_SOLVER_RK4:
        return &RK4;
    case CAM_CHOICE_SOLVER_RK45:
        return &RK45;
    case CAM_CHOICE_SOLVER_RK23:
        return &RK23;
    case CAM_CHOICE_SOLVER_ETDRK4:
        return &ETDRK4;
    default:
        return NULL;
    }
}
