/* Model Exchange over the model contract (cam_model.h): the host's solver integrates x[CAM_ME_NX] of the
 * consistent formulation, the FMU gives derivatives, event indicators and the transitions at events.
 *
 * FMI-free, like cam_instance.h: an FMI 2.0 glue (fmi2.c) and an FMI 3.0 one call the same functions.
 * The layer works on the drive of a CamInstance (cam_instance_drive) and holds only what Model
 * Exchange adds to it: the breakpoint ahead, the energy bound's booking point, the event iteration.
 *
 * - States: x[CAM_ME_NX], cam_model.h's slots (with L = 0 the current slot is held at 0, derivative 0;
 *   a rigid shaft, k_shaft = 0, holds the twist and the motor's speed at 0 the same way), then a free
 *   follower's gap and its rate (cam_drive.h CAM_GAP; held at 0 in contact and without one).
 * - Inputs are continuous: every evaluation uses the inputs the host set last.
 * - Event indicators, CAM_EXCHANGE_NZ of them: slots 0..CAM_ME_EVENTS-1 hold the event functions of
 *   the mode (cam_event_codes' order; the break-away function also at rest with L = 0, where the input
 *   can start the shaft), an unused slot CAM_EXCHANGE_IDLE; the last slot is the angle to the profile's
 *   next breakpoint ahead [rad], so that the host's solver restarts where the profile's higher
 *   derivatives jump, as the co-simulation integrator ends its steps there. Each is > 0 while nothing
 *   happens.
 * - Event update: one transition per call (the first slot below zero, or at zero and heading below it),
 *   else the settling at rest and the friction branch; the caller repeats while *needed.
 * - A completed integrator step: an output not finite, energy created (the bound of docs/model.md
 *   section 9 booked over the host's steps), or an event the host was asked to handle and did not
 *   (the follower beyond the clearance) is an error with its message. A passed breakpoint (a host
 *   without root finding) asks for event mode, where the indicator moves on to the next one.
 */
#ifndef CAM_EXCHANGE_H
#define CAM_EXCHANGE_H

#include <stddef.h>

#include "cam_instance.h"

enum { CAM_ME_EVENTS = 3,   /* a mode's event functions a host sees at most (a rigid drive's, a follower's) */
       CAM_EXCHANGE_BREAKPOINT = CAM_ME_EVENTS, CAM_EXCHANGE_NZ = CAM_ME_EVENTS + 1 };
/* physics/variables.py's EVENT_INDICATORS is CAM_ME_EVENTS + 1 (a compile error if not) */
typedef char cam_exchange_indicator_count[CAM_N_EVENT_INDICATORS == CAM_EXCHANGE_NZ ? 1 : -1];
#define CAM_EXCHANGE_IDLE 1.0            /* an unused indicator slot */
#define CAM_EXCHANGE_MAX_ITERATIONS 32   /* transitions at one event instant at most */
#define CAM_EXCHANGE_PROBE 1e-9          /* s: how far ahead an indicator at exactly 0 is looked at */
#define CAM_EXCHANGE_TRAIN_PHASE 0.25    /* rad of a ringing train between a host's samples (exchange.c) */
#define CAM_EXCHANGE_TRAIN_DRIFT 0.01    /* of its amplitude: explicit Euler's growth of a ringing train */
#define CAM_EXCHANGE_TRAIN_RINGING 1e-4  /* of the lift: a train ringing less is quiet enough for a long step */

typedef struct {
    CamInstance *instance;      /* not owned */
    CamDrive *drive;            /* the instance's, once attached */
    double target;              /* rad: the next breakpoint ahead (NaN: none) */
    double book_time, book_u;   /* s, V: where the energy bound was booked last */
    int requested;              /* a completed step asked for event mode, not entered since */
    int iterations;             /* event updates at this event instant */
    int broke_away;             /* the break-away's transition was applied at this event instant */
    double last_time;           /* s: the time the host set last */
    double longest_gap;         /* s: the longest forward stretch between its settings since the last completed step */
    double step_time;           /* s: the last completed step (or the entry into continuous time) */
    int evaluations;            /* the derivatives evaluated since then */
    double evaluated_at;        /* s: the time of the last of them */
    double drift;               /* explicit Euler's growth of the train's ringing amplitude so far, w^2 h t / 2 */
    int train_warned;           /* a ringing train sampled too sparsely was said once: not again */
    int warning;                /* this completed step's message is a warning (status OK otherwise) */
} CamExchange;

/* A transition applied by an event update (code -1: none), for the host's log. */
typedef struct {
    int code;                   /* CAM_EV_* (a follower of its own: voltage_follower.c's code) or -1 */
    double time;                /* s */
    double x_before[CAM_ME_NX], x_after[CAM_ME_NX];
    const char *note;           /* a follower of its own: its lift-off or touch-down line ("" or NULL: none) */
} CamExchangeEvent;

void cam_exchange_init(CamExchange *e, CamInstance *instance);
/* After initialisation or a restored state: refuse what is no ODE here (formulation 'paper', drive
 * 'speed'), take the drive. Every refusal of this layer is the instance's error (cam_instance_error). */
int cam_exchange_attach(CamExchange *e);
const char *cam_exchange_event_name(int code);

/* The inputs the host set, into the drive (outputs and derivatives follow them). */
void cam_exchange_sync(CamExchange *e);
int cam_exchange_set_time(CamExchange *e, double time);
int cam_exchange_set_states(CamExchange *e, const double x[], size_t nx);
int cam_exchange_get_states(CamExchange *e, double x[], size_t nx);
int cam_exchange_derivatives(CamExchange *e, double dx[], size_t nx);
int cam_exchange_indicators(CamExchange *e, double z[], size_t nz);
/* 1 rad, 1 rad/s, 1 A, 1e-3 m, 1e-2 m/s: the states' scale (no drive needed). */
int cam_exchange_nominals(CamExchange *e, double nominal[], size_t nx);

void cam_exchange_enter_event_mode(CamExchange *e);
int cam_exchange_event_update(CamExchange *e, CamExchangeEvent *fired, int *values_changed, int *needed);
void cam_exchange_enter_continuous(CamExchange *e);
/* A follower train ringing by more than CAM_EXCHANGE_TRAIN_RINGING of the lift that explicit Euler has grown past
 * CAM_EXCHANGE_TRAIN_DRIFT, or that another host samples more than CAM_EXCHANGE_TRAIN_PHASE rad of its ringing apart,
 * is said once, as a warning (e->warning; exchange.c's check_train_sampling, docs/model.md 14.7). */
int cam_exchange_completed_step(CamExchange *e, int *enter_event);

/* cam_instance_save with the energy bound booked up to the drive's time (the live books unchanged). */
int cam_exchange_save(CamExchange *e, unsigned char *buffer, size_t size);

#endif
