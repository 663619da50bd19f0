/* The cam drive as a hybrid model: the one contract every formulation, solver and the FMI glue use.
 *
 * In the style of the Modelica Reference FMUs' model.h: the continuous state is
 * ``double x[CAM_NX]`` with named slots, the discrete mode is its own struct,
 * and the model is a set of functions over (model, mode, x, u): derivatives,
 * event indicators, transitions at events, outputs, the guards a published
 * state must pass, and the validation of parameters. No FMI type appears here.
 *
 * Three formulations (docs/model.md sections 5-8) share this contract through
 * a table of functions each (``CamFormulation``, like the Python
 * ``physics.formulations.base.Formulation``): the consistent one is an ODE with
 * events advanced by the solvers of cam_solver.h; the paper's algorithm is a
 * fixed-step discrete scheme and the speed drive imposes omega, so both provide
 * their own ``advance``.
 *
 * Parameters come from the generated header cam_params.h (written at build time
 * by cam_fmu/engine/codegen.py from physics/parameters.py and physics/variables.py:
 * names, value references, kinds, defaults, ranges, choices, units).
 *
 * C99, libc and libm only, no globals. Errors: every function that can fail
 * fills a CamError (status and a message naming the parameter, input or setting
 * and what to change, text-for-text the Python engine's) and returns its status.
 */
#ifndef CAM_MODEL_H
#define CAM_MODEL_H

#include <stddef.h>

#include "cam_params.h"   /* generated: CAM_N_PARAMS, CAM_P_*, CAM_N_OUTPUTS, CAM_O_*, CamParamSpec, ... */
#include "cam_profile.h"

/* ------------------------------------------------------------------ errors */

typedef enum {
    CAM_OK = 0,
    CAM_ERR_PARAMETER = 1,   /* a parameter outside its range (Python: ParameterError) */
    CAM_ERR_SIMULATION = 2,  /* the run cannot go on correctly (SimulationError; FMI: fmi2Error) */
    CAM_ERR_REJECTED = 3,    /* this step cannot be done at this size, state as before (StepRejected; fmi2Discard) */
    CAM_ERR_MEMORY = 4       /* an allocation failed */
} CamStatus;

#define CAM_MESSAGE_LEN 1024

typedef struct {
    CamStatus status;
    char message[CAM_MESSAGE_LEN];
} CamError;

/* Set err (status and printf-style message) and return the status. */
int cam_fail(CamError *err, CamStatus status, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* Python's repr() of a float (shortest round-trip digits, 'inf', 'nan', '1e-05', '100.0') into buf. */
const char *cam_repr(double value, char *buf, size_t len);

/* ------------------------------------------------------------------ state */

/* Slots of the continuous state x. With L = 0 the current is quasi-static and x[CAM_CURRENT] unused. */
enum { CAM_THETA = 0, CAM_OMEGA = 1, CAM_CURRENT = 2, CAM_NX = 3 };

/* The discrete mode (physics.formulations.consistent.Mode). */
typedef struct {
    int stuck;          /* 1: the shaft is held by static friction */
    double direction;   /* +1/-1: sgn(omega) while moving (the trial direction at rest) */
    int contact;        /* backlash: +1 the cam drives the follower up, -1 down, 0 free in the gap; 1 without */
    double s_free;      /* m: the follower's position while contact == 0 */
    double side;        /* +1/-1: sign of the guide's side force N_r (the friction branch) */
} CamMode;

/* Event codes (the order of drive_kernel.EVENT_NAMES). */
enum { CAM_EV_STOP = 0, CAM_EV_CONTACT = 1, CAM_EV_ENGAGE_UP = 2, CAM_EV_ENGAGE_DOWN = 3,
       CAM_EV_BREAK_AWAY = 4, CAM_EV_SIDE = 5, CAM_MAX_EVENTS = 3 };

/* N: the side-force event fires at N_r = -side * CAM_SIDE_HYSTERESIS (a side force that stays
 * exactly 0 cannot flip the branch back and forth at one instant). */
#define CAM_SIDE_HYSTERESIS 1e-9
/* Relative slack of the energy bound, of the scale |E| + r sum |W_in| (physics/energy.py). */
#define CAM_ENERGY_SLACK 1e-3

/* ------------------------------------------------------------------ parameters, resolved */

/* The parameter values: reals as doubles, booleans 0/1, strings with choices as the choice's
 * index (CAM_CHOICE_*), the motion table as owned text. Set through cam_params_set_*. */
typedef struct {
    double v[CAM_N_PARAMS];
    char *motion_table;        /* owned, NUL-terminated; "" (or NULL) for none */
} CamParams;

/* Defaults (the generated table's); motion_table NULL. */
void cam_params_defaults(CamParams *p);
void cam_params_free(CamParams *p);
/* Copy (the motion table duplicated); CAM_ERR_MEMORY on failure. */
int cam_params_copy(CamParams *dst, const CamParams *src, CamError *err);
/* The index of a parameter by name, or -1. */
int cam_param_index(const char *name);
/* ParameterSpec.check: a real (or boolean 0/1) value, checked against its range; the message
 * text-for-text Python's ("parameter 'R' = 0.0 [Ohm] is outside the allowed range [0.001, 10000] Ohm"). */
int cam_params_set_real(CamParams *p, int index, double value, CamError *err);
/* A string parameter: a choice by name, or the motion table's text (len bytes, copied). */
int cam_params_set_string(CamParams *p, int index, const char *text, size_t len, CamError *err);
/* parameters.resolve's checks across parameters (the four program angles sum to 2 pi). */
int cam_params_check(const CamParams *p, CamError *err);

/* ------------------------------------------------------------------ the model */

typedef enum { CAM_FORM_CONSISTENT = 0, CAM_FORM_PAPER = 1, CAM_FORM_SPEED = 2 } CamFormulationId;

/* The constants a parameter set implies (physics.drive.DriveModel), effects switched off
 * already zero, and the cam program. Read-only once built. */
typedef struct {
    CamParams params;           /* the resolved values (owned copy) */
    CamProfile profile;
    double R, L, c_e, c_m;      /* motor: Ohm, H (0: quasi-static current), V/(rad/s), N m/A */
    double J_m, M_f, m;         /* kg m2, N m, kg */
    double F_gx, G_y, N_g;      /* N: gravity along X, along Y, the guide's support |N_g| */
    double mu, r_b, c;          /* 1, m, m */
    int follower;               /* the follower loads the shaft (m, F_gx or mu nonzero) */
    int has_current;            /* L > 0: x[CAM_CURRENT] is a state */
    int backlash;               /* c > 0 */
    int guide_side;             /* mu > 0 and follower: the side force's sign is an event */
    int nx;                     /* 3 with the current as a state, else 2 */
    CamFormulationId formulation;
    int solver;                 /* CAM_CHOICE_SOLVER_* */
    double h_max, rtol, atol;   /* s, 1, 1 */
    long max_steps;
    double feature_angle;       /* rad: the profile's finest angular detail */
} CamModel;

/* Build the model from resolved parameters: the program, the derived constants, the self-locking
 * check (mu tan(max alpha) < 1). The messages are physics/drive.py's. cam_model_free releases it. */
int cam_model_init(CamModel *model, const CamParams *params, CamError *err);
void cam_model_free(CamModel *model);

/* What the drive equation gives at one instant besides omega_dot (physics.drive.LoadState). */
typedef struct {
    double M, J, f, v, a, alpha, s_cam;   /* N m, kg m2, N, m/s, m/s2, rad, m */
} CamLoad;

/* Guide friction f >= 0 [N] solving f = mu (|n0 + sigma kappa f| + n_support), exactly on its two
 * branches; side +1/-1 takes that branch, 0 the one that holds (docs/model.md section 5). */
double cam_guide_friction(double n0, double kappa, double sigma, double mu, double n_support, double side);

/* omega_dot [rad/s2] of the consistent formulation at (theta, omega) under motor torque c_m i [N m];
 * direction sgn(omega) or the trial one at rest; engaged 0: free in the gap; side +1/-1/0. */
double cam_omega_dot(const CamModel *m, double theta, double omega, double torque, double direction,
                     int engaged, double side);
/* The guide's side force N_r [N] while engaged and moving (0 without guide friction). */
double cam_side_force(const CamModel *m, double theta, double omega, double torque, double direction,
                      double side);
/* Load torque, inertia, follower motion for a known omega_dot. */
void cam_load(const CamModel *m, double theta, double omega, double omega_dot, double direction, int engaged,
              CamLoad *out);
/* Motor torque [N m]: c_m x[CURRENT], or with L = 0 c_m (u - c_e omega) / R. */
double cam_torque(const CamModel *m, double omega, double i, double u);
/* i [A] after dt [s] with the shaft held: exact approach to u / R (L > 0). */
double cam_current_at_rest(const CamModel *m, double i, double u, double dt);

/* Derivatives: dx/dt at x under u and the mode (stuck: theta and omega still). */
void cam_rhs(const CamModel *m, const CamMode *mode, const double x[CAM_NX], double u, double dx[CAM_NX]);

/* Event indicators: the active event codes into codes[], returning how many (<= CAM_MAX_EVENTS);
 * each function is > 0 while nothing happens, a crossing to <= 0 fires its transition. */
int cam_event_codes(const CamModel *m, const CamMode *mode, int codes[CAM_MAX_EVENTS]);
double cam_event_value(const CamModel *m, const CamMode *mode, int code, const double x[CAM_NX], double u);

/* Transitions. The initial state and mode (the follower centred in the gap with backlash); the
 * transition of an event, in place; settle at rest (stay stuck or start, then the friction branch;
 * at_threshold: at a located break-away); the friction branch of the current state. */
void cam_initial(const CamModel *m, double theta0, double omega0, double i0, double x[CAM_NX], CamMode *mode);
void cam_apply_event(const CamModel *m, CamMode *mode, double x[CAM_NX], int code, double u);
void cam_settle(const CamModel *m, CamMode *mode, double x[CAM_NX], double u, int at_threshold);
void cam_choose_side(const CamModel *m, CamMode *mode, const double x[CAM_NX], double u);
/* > 0 when the shaft would start moving from rest [rad/s2]. */
double cam_breakaway_margin(const CamModel *m, const CamMode *mode, double theta, double i, double u);
/* +1, -1, or 0 (stays stuck): the direction the shaft starts from rest. */
double cam_breakaway_direction(const CamModel *m, double theta, double torque, int engaged);

/* Outputs: every output in physics.variables.OUTPUTS order into out[CAM_N_OUTPUTS]; known: omega_dot
 * is the acceleration at x already (the solver's last stage), else it is computed. */
void cam_outputs(const CamModel *m, const CamMode *mode, const double x[CAM_NX], double u, double omega_dot,
                 int known, double out[]);

/* ------------------------------------------------------------------ guards */

/* The energy bound's bookkeeping (physics/energy.py). */
typedef struct {
    double c_e, L, R, F_gx, ratio;
    double work_in, work_abs;   /* J */
    double theta, i;            /* at the last booked step */
    double e_mech0, e_mag0;     /* J */
} CamEnergy;

void cam_energy_init(CamEnergy *e, const CamModel *m, double theta, double omega, double i, double s, double J);
void cam_energy_step(CamEnergy *e, double u, double h, double theta, double i);
/* (energy above the bound [J], its tolerance [J]) at the state. */
void cam_energy_excess(const CamEnergy *e, double omega, double s, double J, double i, double *excess,
                       double *tolerance);

/* The verdict on a step's outputs before they are published: 0 fine, 1 an output is not finite,
 * 2 the follower is beyond the clearance (a contact event was missed), 3 energy was created. The
 * budget (may be NULL) books the step. */
enum { CAM_PUBLISH_OK = 0, CAM_PUBLISH_NOT_FINITE = 1, CAM_PUBLISH_CLEARANCE = 2, CAM_PUBLISH_ENERGY = 3 };
int cam_publishable(const CamModel *m, const double out[], CamEnergy *budget, double u, double h);

/* ------------------------------------------------------------------ the drive and its formulations */

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
} CamFormulation;

const CamFormulation *cam_formulation(CamFormulationId id);

/* The fixed-step paper scheme's state (paper.PaperScheme: FIELDS and M_l), in SI units. */
typedef struct {
    double theta, omega, i, J, M, s, v, a, alpha, voltage, M_l;
} CamPaperState;

/* The speed drive's state. */
typedef struct {
    double theta, s, speed;     /* rad, m, rad/s */
} CamSpeedState;

/* The solver's carried state (rk45: step size and first-same-as-last derivative). */
typedef struct {
    double h_next;              /* s: the next trial step of an adaptive method */
    int k1_valid;               /* k1 holds f(x) under fsal_u and the mode */
    double k1[CAM_NX];
    double fsal_u;
} CamSolverState;

/* One cam drive stepped from one communication point to the next (fmu/engine.py DriveSimulator). */
typedef struct CamDrive {
    CamModel model;
    const CamFormulation *form;
    double x[CAM_NX];
    CamMode mode;
    CamSolverState solver;
    CamPaperState paper;
    CamSpeedState speed;
    double time;                /* s */
    double u, omega_ref, omega_dot_ref;
    long steps_taken;           /* internal steps, for benchmarks */
    long last_steps;            /* of the last step */
    int have_budget;
    CamEnergy budget;
    double values[CAM_N_OUTPUTS];   /* the published outputs */
    int stale;                  /* values not yet computed for the current state */
} CamDrive;

/* Build a drive from parameters (checked: cam_params_check, cam_model_init) at the start inputs. */
int cam_drive_init(CamDrive *d, const CamParams *params, CamError *err);
void cam_drive_free(CamDrive *d);
/* Inputs used by outputs before the first step; out of range: an error naming the input. */
int cam_drive_set_inputs(CamDrive *d, double u, double omega_ref, double omega_dot_ref, CamError *err);
/* Advance from t to t + h with the inputs held (FMI co-simulation); the outputs in d->values only
 * once every check passed; on CAM_ERR_REJECTED the state is as before the step. */
int cam_drive_do_step(CamDrive *d, double t, double h, double u, double omega_ref, double omega_dot_ref,
                      CamError *err);
/* The current outputs (computed once per state). */
const double *cam_drive_outputs(CamDrive *d);

/* The whole state as doubles (CAM_STATE_LEN of them): versioned layout, see cam_drive.c. */
#define CAM_STATE_LEN 48
void cam_drive_get_state(const CamDrive *d, double state[CAM_STATE_LEN]);
/* Restore; every entry checked (finite, a valid mode) before use, the message naming what is wrong. */
int cam_drive_set_state(CamDrive *d, const double state[CAM_STATE_LEN], CamError *err);

/* A whole scene in one call: n_steps communication steps of h from t0, the inputs held over step k
 * read from inputs[3 k .. 3 k + 2] (u, omega_ref, omega_dot_ref), the outputs after step k written to
 * out[CAM_N_OUTPUTS k ..]. Returns the status; *done the steps completed. */
int cam_drive_run(CamDrive *d, double t0, double h, long n_steps, const double *inputs, double *out,
                  long *done, CamError *err);

#endif
