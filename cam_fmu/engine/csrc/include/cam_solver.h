/* The solvers of the consistent formulation: one contract, Runge-Kutta methods as data.
 *
 * In the style of scipy's integrate/_ivp: an explicit Runge-Kutta method is its
 * Butcher tableau (CamTableau) over one generic step (cam_rk_step), with an
 * embedded error estimate where the tableau has one. A method that is not a
 * plain tableau (etdrk4: exponential, exact on the electrical pole) provides its
 * own step function with the same signature. One communication-step driver
 * (cam_integrate) serves every method: profile breakpoints, event location
 * (seeded on the step's dense output, polished on re-stepped trial states), transitions, the work
 * bound max_steps and its message, and rollback to the state before the step
 * when the step is refused.
 *
 * Order of operations: the generic step evaluates a stage's increment as
 * x + h * (a_1 k_1 + a_2 k_2 + ...) summed left to right over the nonzero
 * coefficients only, except a row with a single nonzero coefficient, which is
 * x + (h a) k; the error as h * (e_1 k_1 + ...). This is the order of the
 * former Python engine, so results agree with its recorded outputs to the last bit.
 *
 * C99, libc and libm only, no globals: the tableaus are const data.
 */
#ifndef CAM_SOLVER_H
#define CAM_SOLVER_H

#include "cam_drive.h"

#define CAM_MAX_STAGES 7

/* An explicit Runge-Kutta method as data. */
typedef struct {
    int stages;                                   /* s: stages computed per step (FSAL stage excluded) */
    double a[CAM_MAX_STAGES][CAM_MAX_STAGES];     /* a[i][j], j < i */
    double b[CAM_MAX_STAGES];                     /* weights of the solution */
    double c[CAM_MAX_STAGES];                     /* nodes (unused by autonomous stages; documentation) */
    int fsal;                                     /* 1: f at the new state is stage s + 1 (first same as last) */
    double e[CAM_MAX_STAGES + 1];                 /* error weights b - b_hat, the FSAL stage last; all 0: none */
    double error_exponent;                        /* -1/(q+1) for an embedded pair of order q (dopri5: -0.2) */
    double b_divisor;                             /* > 0: x + (h / b_divisor) * sum b_j k_j (rk4's h/6) */
} CamTableau;

/* Scratch of one step: the stages, the new state, its error and f at it. */
typedef struct {
    double k[CAM_MAX_STAGES + 1][CAM_NX];         /* k[0] = f(x) on entry (k1) */
    double x_new[CAM_NX];
    double error[CAM_NX];
    double f_new[CAM_NX];                         /* f(x_new), valid when the method is FSAL */
} CamStepWork;

struct CamMethod;

/* One step of size h [s] from x (mode and input u fixed, w->k[0] = f(x) already): x_new, and for an
 * embedded pair error and f_new, into w. */
typedef void (*CamStepFunction)(const struct CamMethod *method, const CamModel *m, const CamMode *mode,
                                const double x[CAM_NX], double u, double h, CamStepWork *w);

/* One solver (the parameter ``solver``). */
typedef struct CamMethod {
    const char *name;                 /* 'euler', 'rk4', 'rk45', 'etdrk4' */
    const CamTableau *tableau;        /* NULL for a method with its own step */
    CamStepFunction step;             /* cam_rk_step for a tableau method */
    int adaptive;                     /* 1: error control on rtol, atol (needs tableau->e) */
    double stability;                 /* h |lambda| allowed on the negative real axis (fixed step) */
    double resolution;                /* fixed step: the cam turns at most this of the finest feature per step */
    double max_sweep;                 /* fixed step without resolution: refuse a step sweeping more */
    int exact_electrical_pole;        /* the pole -R/L needs no stability cut */
} CamMethod;

/* The method the parameter ``solver`` names (CAM_CHOICE_SOLVER_*), or NULL (methods.c). */
const CamMethod *cam_method(int solver_choice);

/* The tableaus: const data (no mutable state), in rk.c. */
extern const CamTableau cam_dopri5;   /* Dormand-Prince 5(4), FSAL, embedded error */
extern const CamTableau cam_bs23;     /* Bogacki-Shampine 3(2), FSAL, embedded error */
extern const CamTableau cam_rk4;      /* the classical Runge-Kutta method, order 4 */
extern const CamTableau cam_euler;    /* explicit Euler, order 1 */

/* Exponential RK4 (Cox and Matthews 2002) on (theta, omega, e), e the current's deviation from its
 * quasi-static value: exact on the electrical pole -R/L and on its torque on omega (etdrk4.c); the
 * classical RK4 when the current is no state (L = 0). */
void cam_etdrk4_step(const struct CamMethod *method, const CamModel *m, const CamMode *mode, const double x[CAM_NX],
                     double u, double h, CamStepWork *w);

/* The generic explicit Runge-Kutta step over method->tableau. */
void cam_rk_step(const CamMethod *method, const CamModel *m, const CamMode *mode, const double x[CAM_NX],
                 double u, double h, CamStepWork *w);

/* The derivatives dy [per s] of a hybrid driver's own state vector y (its slots its own), ctx its arguments. */
typedef void (*CamRates)(void *ctx, const double *y, double *dy);

/* cam_rk_step's step, in its order of operations, over a state vector y of `width` <= CAM_MAX_SLOTS slots whose first
 * n move (the rest carried unchanged: their rates are 0): the stages in k (rows of `width` doubles, CAM_MAX_STAGES + 1
 * rows; k[0] = rates(y) on entry), the new state in y_new and, for a tableau with an embedded pair and error != NULL,
 * its error estimate h sum e_j k_j over the n slots (the FSAL stage computed into k's row `stages`). */
void cam_tableau_step(const CamTableau *t, int n, int width, CamRates rates, void *ctx, const double *y, double h,
                      double *k, double *y_new, double *error);

/* The error norm of an embedded step: RMS over the nx slots of error / (atol + rtol max(|x|, |x_new|)),
 * theta's scale capped at 2 pi (it enters the physics mod 2 pi). */
double cam_error_norm(const CamModel *m, const double x[CAM_NX], const CamStepWork *w);

/* What the communication-step driver keeps between its internal steps. */
typedef struct {
    const CamMethod *method;
    CamStepWork work;
    double x_end[CAM_NX];       /* the accepted step's end state */
    double f_end[CAM_NX];       /* f there (valid when the step was a full FSAL step, or located in) */
    int f_end_valid;            /* f_end holds f at x_end */
    double x_hit[CAM_NX];       /* locate: the state just past the zero */
    double before[CAM_MAX_EVENTS], after[CAM_MAX_EVENTS];
    int codes[CAM_MAX_EVENTS];
    int n_events;
    int have_before;            /* before[] holds the values at the current x */
    int hit;                    /* the code of the event first found */
    int exponential;            /* the adaptive step in hand is the exponential pair (a stiff pole) */
} CamIntegrator;

/* rk45 and the electrical pole: where a step is longer than CAM_POLE_LIMIT electrical time constants
 * L/R, Dormand-Prince would be unstable (its real-axis limit is 3.3), so the adaptive driver takes the
 * step as the exponential pair instead: etdrk4 over the step and over its two halves, the halves
 * accepted, their difference / 15 the error estimate (Richardson, order 4). Exact on the pole at any
 * L, with the same error control (docs/model.md section 7). */
#define CAM_POLE_LIMIT 3.0

/* The exponential pair of size h from x (the mode and u fixed): x_new and error into w. */
void cam_exponential_pair(const CamModel *m, const CamMode *mode, const double x[CAM_NX], double u, double h,
                          CamStepWork *w);

/* Error control (the former Python engine's, scipy's RK45): a step of *dt [s] with error norm `norm` (> 1 or NaN:
 * rejected) under the method's error exponent. Accepted: 1, and the next trial step into *h_next (dt times the
 * growth factor, at most 5x and 1e3 s; where the step reached `bound` [s] and may grow, no shorter than *h_next
 * was). Rejected: 0, and *dt shrunk (to no less than a tenth). Every adaptive step of the engine takes it. */
int cam_step_control(double norm, double exponent, double bound, double *dt, double *h_next);
/* The follower train's end mass x[CAM_X_END], x[CAM_V_END] over a step of h [s] of the speed drive's imposed motion
 * theta0 + omega0 t + alpha t^2 / 2 (train.c): Dormand-Prince 5(4) on the model's rtol, atol, its step carried in
 * *h_next, the steps taken into *steps; CAM_ERR_REJECTED (x as before) where the step falls below 1e-12 h. */
int cam_train_follow(const CamModel *m, double x[CAM_NX], double theta0, double omega0, double alpha, double h,
                     double *h_next, long *steps, CamError *err);

/* The speed drive's imposed motion over a step of h [s] from x at the acceleration u [rad/s2] into x_new's theta and
 * omega, exact whatever the method (m->prescribed only; speed_follower.c). */
void cam_impose_motion(const CamModel *m, const double x[CAM_NX], double u, double h, double x_new[CAM_NX]);

/* One accepted adaptive step no longer than remaining, h_max and d->solver.h_next: its length [s],
 * the end state in it->x_end, f there in it->f_end. span is the communication step (the step floor is
 * 1e-12 of it); below the floor: CAM_ERR_REJECTED with the former engine's message. */
int cam_step_adaptive(CamDrive *d, CamIntegrator *it, double remaining, double time, double span, double *dt,
                      CamError *err);

/* One fixed step inside the method's stability and resolution limits along the whole step:
 * its length [s], the end state in it->x_end; the retries it took into *retries. */
int cam_step_fixed(CamDrive *d, CamIntegrator *it, double remaining, double *dt, long *retries, CamError *err);

/* Advance the consistent formulation's state d->x, d->mode by one communication step h [s] from
 * ``time`` with the method of d->model.solver: every step ends at the profile breakpoint it would
 * cross and at the located zero of the first event, whose transition is cam_apply_event. More than
 * max_steps internal steps: CAM_ERR_REJECTED naming the setting (the former engine's message). On any error
 * the state, mode and solver state are as before the call. */
int cam_integrate(CamDrive *d, double h, double time, long *steps, CamError *err);

#endif
