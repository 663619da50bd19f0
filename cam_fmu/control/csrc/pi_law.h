/* The sampled PI speed controller of pi_speed.fmu in C: the law of control/pi.py (its docstring has the
 * equations), operation for operation in the same order, so that both give the same bits. libm only, no
 * globals. Parameters and inputs are indexed by the generated table (pi_params.h, from control/pi.py).
 */
#ifndef PI_LAW_H
#define PI_LAW_H

#include <stddef.h>

#include "pi_params.h"

typedef struct {
    double integral;     /* V: the integrator's state I */
    double w_prev;       /* rad/s: the setpoint of the last sample */
    int have_w_prev;     /* 0 before the first sample or initialisation: the setpoint's rate is 0 then */
    double u;            /* V: the published command */
    double error;        /* rad/s: the speed error of the last sample */
    double u_ff;         /* V: the feedforward part of the last sample */
} PiState;

/* Before initialisation: integral 0, no previous setpoint, outputs 0. */
void pi_state_clear(PiState *s);

/* The output before the first step: the law on the inputs, no integration; sets w_prev. Returns NULL, or
 * (an overflow: finite inputs whose error, setpoint rate, feedforward or command is beyond a double) the name
 * of the first quantity that is not finite, s unchanged. */
const char *pi_initialize(PiState *s, const double p[PI_N_PARAMS], const double in[PI_N_INPUTS]);

/* One sample at the start of a step of length h [s] > 0 with the inputs at its start; the command is
 * published at its end. Integrates unless the clamp is active and the error pushes further into it.
 * Returns NULL, or as pi_initialize the name of what overflowed (the integral too), s unchanged. */
const char *pi_sample(PiState *s, const double p[PI_N_PARAMS], const double in[PI_N_INPUTS], double h);

/* The outputs in PI_O_* order. */
void pi_outputs(const PiState *s, double out[PI_N_OUTPUTS]);

#endif
