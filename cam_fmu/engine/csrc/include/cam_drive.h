/* The cam drive: the model of cam_model.h stepped from one communication point to the next
 * (Python: engine/simulator.py DriveSimulator).
 *
 * Three formulations (docs/model.md sections 5-8; in Python physics/formulations/) share the model
 * contract through a table of functions each (``CamFormulation``): the consistent one is an ODE with
 * events advanced by the solvers of cam_solver.h; the paper's algorithm is a
 * fixed-step discrete scheme and the speed drive imposes omega, so both provide
 * their own ``advance``. Here too: the drive's state (its formulations' states, the
 * solver's carried step, the event log), its flat saved state (CAM_S_*), and the
 * accessors for bindings that hold the structures as opaque memory (ctypes).
 *
 * C99, libc and libm only, no globals; errors as cam_model.h's CamError.
 */
#ifndef CAM_DRIVE_H
#define CAM_DRIVE_H

#include <stddef.h>

#include "cam_model.h"

struct CamDrive;

/* One formulation: how the drive's state advances over one communication step. */
typedef struct {
    const char *name;
    int energy_bounded;         /* a voltage drive: its states respect the energy bound */
    /* set up the formulation's state from the parameters at the start inputs */
    int (*init)(struct CamDrive *d, CamError *err);
    /* inputs held from now on (may re-decide stick/slip) */
    void (*set_inputs)(struct CamDrive *d, double u, double omega_ref, double omega_dot_ref);
    /* advance by h [s] from time [s]; the steps taken into *steps; on error the state as before */
    int (*advance)(struct CamDrive *d, double h, double time, long *steps, CamError *err);
    /* every output at the current state */
    void (*outputs)(struct CamDrive *d, double out[]);
    /* the advice named in the guard messages ("reduce h_max ...") into buf */
    void (*advice)(const struct CamDrive *d, char *buf, size_t len);
    /* optional: Model Exchange of states of its own (NULL: x under cam_rhs, the rigid drive's event table) */
    const struct CamExchangeHooks *exchange;
    /* optional, for cam_integrate: the transition of event `code` at the drive's state at time [s] in place of
     * cam_apply_event (EV_NONE: the step's start, settled in place of cam_settle; EV_BREAK: a profile breakpoint
     * reached), with what it logs; and the longest internal step [s] the state allows beyond the solver's limits */
    void (*transition)(struct CamDrive *d, int code, double time);
    double (*step_limit)(const struct CamDrive *d, double time);
} CamFormulation;

/* A formulation's Model Exchange beyond the model contract's states x and rates cam_rhs (cam_drive_me_* and
 * fmi/exchange.c call them): its event codes (how many, at most CAM_VF_ME_EVENTS) and functions (> 0: nothing
 * happens), and its event update: the transition `code` (EV_NONE: none, the mode settled at the state), the one its
 * co-simulation runs. */
typedef struct CamExchangeHooks {
    int (*codes)(const struct CamDrive *d, int *codes);
    double (*event)(const struct CamDrive *d, int code, const double *x);
    int (*event_update)(struct CamDrive *d, int code, CamError *err);
    /* the tangent of rates and of the outputs along seed and du (directional derivatives) */
    void (*tangent)(const struct CamDrive *d, const double *x, const double *seed, double du, double *ddx,
                    double *dout);
} CamExchangeHooks;

/* The formulation of a model (formulations.c; the consistent one with a follower of its own: the voltage
 * follower's), or NULL; each is const data in its own file. */
const CamFormulation *cam_formulation(const CamModel *m);
extern const CamFormulation cam_consistent;   /* consistent.c */
extern const CamFormulation cam_paper;        /* paper.c */
extern const CamFormulation cam_speed;        /* speed.c */
extern const CamFormulation cam_voltage_follower;   /* consistent.c with voltage_follower.c's hooks: closures 'form', 'spring' */
extern const CamFormulation cam_speed_follower;   /* voltage_follower.c: the speed drive, closures 'form', 'spring' */

/* The fixed-step paper scheme's state (paper.PaperScheme: FIELDS and M_l), in SI units. */
typedef struct {
    double theta, omega, i, J, M, s, v, a, alpha, voltage, M_l;
} CamPaperState;

/* The speed drive's state. */
typedef struct {
    double theta, s, speed;     /* rad, m, rad/s */
    /* The follower as a body of its own (model.free_follower; docs/model.md section 13): */
    double v;                   /* m/s, its velocity */
    double contact;             /* +1 on the flank pushing along +X, -1 on a groove's other flank, 0 in flight */
    double impacts;             /* touch-downs so far */
    double rebound;             /* s: shorter than the flight the last rebound starts (the scan's first step), or 0; the
                                 * voltage drive's follower: the time until which that guard holds [s] (0: none) */
    double fresh;               /* 1 until the first step: the start's contact follows the inputs set */
} CamSpeedState;

/* The way the speed drive's cam moves at the end of a step (the left limit, docs/model.md 8.1): sgn(omega), and where
 * omega ends at 0 (within the rounding of omega_ref + omega_dot_ref h and of the end time t [s]) the way the step
 * started (speed.c). */
double cam_motion_sign(double omega, double omega_ref, double omega_dot_ref, double t);
/* The follower's names for the one table of event codes (CAM_EV_*, generated; docs/model.md 10 and 13.7), for the
 * speed drive's follower (follower.c) and the voltage drive's (voltage_follower.c, Model Exchange's indicators):
 * lift-off is the contact's loss, touch-down on flank +1 (TOUCH_UP) and -1 (TOUCH_DOWN) its engagements; EV_BREAK (a
 * profile breakpoint, integrate.c's code -1) and EV_SIDE only end a step; EV_NONE: no event. */
typedef enum { EV_NONE = -2, EV_BREAK = -1, EV_STOP = CAM_EV_STOP, EV_LIFT_OFF = CAM_EV_CONTACT,
               EV_TOUCH_UP = CAM_EV_ENGAGE_UP, EV_TOUCH_DOWN = CAM_EV_ENGAGE_DOWN, EV_BREAK_AWAY = CAM_EV_BREAK_AWAY,
               EV_SIDE = CAM_EV_SIDE_FORCE, EV_HALT = CAM_EV_HALT } CamFollowerEvent;
#define CAM_TOUCH 1e-12         /* m: a touch-down is located this far inside the flank (reference/flight.py TOUCH) */
#define CAM_ZENO_HEIGHT 1e-9    /* m: a rebound rising less ends in contact (physics/speed_follower.py ZENO_HEIGHT) */

/* Append one transition to a step's log line `events` of `len` bytes (*dropped counts what no longer fits). */
void cam_follower_note(char *events, size_t len, long *dropped, const char *format, ...);

#define CAM_MAX_SLOTS 16         /* slots of a formulation's own state vector at most (cam_solver.h cam_tableau_step) */

/* The solver's carried state (rk45: step size and first-same-as-last derivative). */
typedef struct {
    double h_next;              /* s: the next trial step of an adaptive method */
    int k1_valid;               /* k1 holds f(x) under fsal_u and the mode */
    double k1[CAM_NX];
    double fsal_u;
} CamSolverState;

/* CamEventRecord, one transition as the event log keeps it, is generated (cam_contract.h). */
#define CAM_EVENT_LOG 256       /* the last this many transitions are kept */
#define CAM_STEP_EVENTS 512     /* bytes of a step's line of follower events (the rest is counted, not written) */

/* One cam drive stepped from one communication point to the next (Python: engine/simulator.py DriveSimulator). */
typedef struct CamDrive {
    CamModel model;
    const CamFormulation *form;
    double x[CAM_NX];
    CamMode mode;
    CamSolverState solver;
    CamPaperState paper;
    CamSpeedState speed;
    double time;                /* s */
    double start_time;          /* s: where the drive started (0; an FMU's start time); a state is never before it */
    double u, omega_ref, omega_dot_ref;
    double form_u;              /* the input the formulation has settled for */
    long steps_taken;           /* internal steps, for benchmarks */
    long last_steps;            /* of the last step */
    int have_budget;
    CamEnergy budget;
    double values[CAM_N_OUTPUTS];   /* the published outputs */
    int stale;                  /* values not yet computed for the current state */
    char step_events[CAM_STEP_EVENTS];   /* the last step's lift-offs and touch-downs as one log line ("" none) */
    long events_logged;         /* transitions since the drive was built (the log keeps the last CAM_EVENT_LOG) */
    CamEventRecord event_log[CAM_EVENT_LOG];
} CamDrive;

/* Model Exchange's continuous state (physics/variables.py STATES) is x[CAM_NX] itself: its last slots, the voltage
 * drive's free follower (closures 'form', 'spring'; docs/model.md 13.6) as its gap g = left (s - s_flank(theta)) [m]
 * to the flank it left last and the gap's rate w [m/s], are held at 0 (derivative 0) in contact and without a follower
 * of its own. The follower's Model Exchange indicators and event update are its formulation's hooks
 * (CamExchangeHooks, voltage_follower_events.c); exchange.c drives them. */
enum { CAM_VF_ME_EVENTS = 3,   /* (CAM_ME_NX = CAM_NX: generated, engine/contract.py X_SLOTS) */
       CAM_VF_BREAK_AWAY = EV_BREAK_AWAY /* the stuck shaft's break-away, driven by the input (at 0 it is due) */ };
void cam_drive_me_states(const CamDrive *d, double x[CAM_ME_NX]);
void cam_drive_set_me_states(CamDrive *d, const double x[CAM_ME_NX]);
/* The derivatives at x under the input d->form_u (the drive's mode and contact). */
void cam_drive_me_rates(const CamDrive *d, const double x[CAM_ME_NX], double dx[CAM_ME_NX]);
/* The tangent of cam_drive_me_rates (ddx, the held slots' 0) and of the outputs (dout[CAM_N_OUTPUTS]) at x along
 * seed (state units) and du [V], in the drive's mode: analytic, no differencing. */
void cam_drive_me_tangent(const CamDrive *d, const double x[CAM_ME_NX], const double seed[CAM_ME_NX], double du,
                          double ddx[CAM_ME_NX], double dout[]);

/* Build a drive from parameters (checked: cam_params_check, cam_model_init) at the start inputs. */
int cam_drive_init(CamDrive *d, const CamParams *params, CamError *err);
/* Start the drive's clock at t0 [s] (finite, |t0| <= 1e15) instead of 0; only before its first step. */
int cam_drive_set_start_time(CamDrive *d, double t0, CamError *err);
void cam_drive_free(CamDrive *d);
/* Inputs used by outputs before the first step; out of range: an error naming the input. */
int cam_drive_set_inputs(CamDrive *d, double u, double omega_ref, double omega_dot_ref, CamError *err);
/* Advance from t to t + h with the inputs held (FMI co-simulation); the outputs in d->values only
 * once every check passed; on CAM_ERR_REJECTED the state is as before the step. t must be where the drive
 * is, to within CAM_TIME_SLACK (fmi2DoStep's rule: the rounding of a host's summed steps). */
#define CAM_TIME_SLACK(t) (1e-9 * (fabs(t) > 1.0 ? fabs(t) : 1.0))
int cam_drive_do_step(CamDrive *d, double t, double h, double u, double omega_ref, double omega_dot_ref,
                      CamError *err);
/* The current outputs (computed once per state). */
const double *cam_drive_outputs(CamDrive *d);

/* The whole state as doubles (CAM_STATE_LEN of them): the layout CAM_S_* and its version CAM_STATE_VERSION are
 * generated from engine/contract.py STATE_LAYOUT (cam_contract.h). */
/* CAM_STATE_LEN, for bindings (engine/simulator.py reads it rather than repeating the number). */
size_t cam_state_len(void);
void cam_drive_get_state(const CamDrive *d, double state[CAM_STATE_LEN]);
/* Restore; every entry checked (finite, a valid mode) before use, the message naming what is wrong. */
int cam_drive_set_state(CamDrive *d, const double state[CAM_STATE_LEN], CamError *err);

/* A whole scene in one call: n_steps communication steps, step k from table[5 k .. 5 k + 4] =
 * (t [s], h [s], u [V], omega_ref [rad/s], omega_dot_ref [rad/s2]), the outputs after step k written to
 * out[CAM_N_OUTPUTS k ..]. Returns the status of the first failing step (*done: the steps completed). */
int cam_drive_run(CamDrive *d, long n_steps, const double *table, double *out, long *done, CamError *err);

/* For bindings that hold the structures as opaque memory (ctypes): their sizes, and the drive's fields. */
/* The k-th transition of the log, k counted from the first ever (events_logged - CAM_EVENT_LOG <= k <
 * events_logged), or NULL when it is no longer (or not yet) kept. */
const CamEventRecord *cam_drive_event(const CamDrive *d, long k);
long cam_drive_events_logged(const CamDrive *d);
size_t cam_event_record_sizeof(void);

size_t cam_params_sizeof(void);
size_t cam_drive_sizeof(void);
size_t cam_model_sizeof(void);
double cam_drive_time(const CamDrive *d);
long cam_drive_steps_taken(const CamDrive *d);
long cam_drive_last_steps(const CamDrive *d);
int cam_drive_nx(const CamDrive *d);
double *cam_drive_values(CamDrive *d);   /* the published outputs (CAM_N_OUTPUTS), valid while d lives */

#endif
