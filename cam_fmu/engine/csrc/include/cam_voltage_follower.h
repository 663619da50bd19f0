/* The voltage drive's follower of its own (docs/model.md 13.6): what voltage_follower.c (its equations and
 * its model-contract functions) shares with voltage_follower_events.c (its transitions in the one event update,
 * Model Exchange's indicators).
 * Internal to the engine, not for bindings. y = (theta, omega, i, s, v, phi, omega_m, sigma, dir): see
 * voltage_follower.c. */
#ifndef CAM_VOLTAGE_FOLLOWER_H
#define CAM_VOLTAGE_FOLLOWER_H

#include "cam_drive.h"

#define NY 11
#define Y_TWIST 5               /* y[5], y[6]: a compliant shaft's twist [rad] and rotor speed [rad/s] */
#define Y_ROTOR 6
#define Y_SIGMA 7               /* y[7]: the flying follower's direction sgn(v) over the step (0: held), rate 0 */
#define Y_DIR 8                 /* y[8]: the shaft's direction, sgn(omega) or the break-away's at omega = 0; 0: stuck;
                                 * held over a step (a stop ends it): a Runge-Kutta stage past omega = 0 with
                                 * sgn(omega) would turn the friction inside the step and misplace the stop (3.3e-6 rad
                                 * at steps of 7e-4 s) */
#define Y_XE 9                  /* y[9], y[10]: a follower train's end mass [m, m/s] (docs/model.md 14.6; 0 without) */
#define Y_VE 10


/* N m: what drives the cam side (the motor's torque, or a compliant shaft's) less the shaft's friction against the
 * direction dir (0: the drive alone). */
double cam_vf_torque_toward(const CamModel *m, const double y[NY], double u, double dir);
/* The flying follower's direction sgn(v), or at a halt where the net force pushes it (0: held by friction). */
double cam_vf_flight_direction(const CamModel *m, const double y[NY]);
/* The rates of y on the flank `contact` (0: in flight) under the input u [V]. */
void cam_vf_rates(const CamModel *m, double u, int contact, const double y[NY], double dy[NY]);
/* m/s2: the scale of the follower's relative acceleration at y (the Zeno guard's and the rebound's). */
double cam_vf_acceleration_scale(const CamModel *m, const double y[NY], double u);
/* On the flank `contact` at y: d = (s_cam, s', s'', s''') at the cam, omega_dot [rad/s2], the contact force P [N]
 * and (n_r not NULL) the guide's side force N_r [N] (0 without guide friction). */
void cam_vf_on_flank(const CamModel *m, const double y[NY], double u, int contact, double d[4], double *omega_dot,
                     double *P, double *n_r);
/* The follower's s, v set on the flank `contact` at y. */
void cam_vf_set_on_flank(const CamModel *m, double y[NY], int contact);
/* rad/s2: > 0 where the stuck shaft starts, *dir the way it starts. */
double cam_vf_breakaway(const CamModel *m, const double y[NY], double u, int contact, double *dir);
/* y from the model's state x and mode (the follower's gap and rate in x, its contact, flank left and flying direction
 * in the mode), and back: x and the mode from y with the contact `contact` and the flank left `left` after, under the
 * input u [V] (the side force's sign). */
void cam_vf_y(const CamModel *m, const CamMode *mode, const double x[CAM_NX], double y[NY]);
void cam_vf_x(const CamModel *m, const double y[NY], double u, int contact, int left, double x[CAM_NX],
              CamMode *mode);
/* (cam_vf_rhs, cam_vf_codes, cam_vf_value: the model contract's, declared in cam_model.h.) */
/* On the flank `contact`: the follower set on it, or lifted off at once where its contact force is already < 0: the
 * contact after, *left (if not NULL) the flank it lets go of where it does. */
int cam_vf_settle(const CamModel *m, double y[NY], double u, int contact, int *left);
/* A lift-off or touch-down `code` from `contact` at y at time [s]: the contact after (see voltage_follower.c). */
int cam_vf_transition(CamDrive *d, double y[NY], double u, int code, int contact, double time, double *rebound,
                      int *left, long *dropped);
/* At rest (omega = 0): stuck, or moving off where it accelerates (at once at a located break-away). */
void cam_vf_at_rest(const CamModel *m, double y[NY], double u, int *contact, int *left, int at_threshold);
/* The one event update of co-simulation and Model Exchange: the transition `code` (EV_NONE: the contact settled, or
 * at rest the shaft's rule) at y at time [s]; *contact, *left and *rebound before and after. */
void cam_vf_event_update(CamDrive *d, double y[NY], double u, int code, int *contact, int *left, double *rebound,
                         double time, long *dropped);

/* The formulation's parts the speed drive's follower (speed_follower.c) shares: the start on a flank under the input
 * u, the outputs, the transition hook, the step bound, and the load torque [N m] on the flank `contact` at y. */
void cam_vf_start(CamDrive *d, double u);
void cam_vf_outputs(CamDrive *d, double out[]);
void cam_vf_apply(CamDrive *d, int code, double time);
double cam_vf_step_limit(const CamDrive *d, double time);
double cam_vf_flank_torque(const CamModel *m, const double y[NY], double u, int contact);

/* Model Exchange's view (the formulation's hooks cam_vf_exchange, cam_drive.h CamExchangeHooks). */
int cam_vf_me_codes(const CamDrive *d, int codes[CAM_VF_ME_EVENTS]);
double cam_vf_me_event(const CamDrive *d, int code, const double x[CAM_ME_NX]);
int cam_vf_me_apply(CamDrive *d, int code, CamError *err);
/* The tangent of cam_vf_rhs and of the outputs at x along seed[CAM_ME_NX] and du, in the drive's mode
 * (jacobian_follower.c). */
void cam_vf_me_tangent(const CamDrive *d, const double x[CAM_ME_NX], const double seed[CAM_ME_NX], double du,
                       double ddx[CAM_ME_NX], double dout[]);
extern const CamExchangeHooks cam_vf_exchange;

#endif
