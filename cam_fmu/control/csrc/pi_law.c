/* The sampled PI speed controller (pi_law.h); control/pi.py is the same law in Python. */
#include <math.h>

#include "pi_law.h"

/* The law on the inputs: setpoint w, error e, feedforward u_ff, unclamped v and clamped u. h <= 0: no
 * previous sample, the setpoint's rate is taken as 0. Returns NULL, or the name of the first quantity that is
 * not finite (an overflow; the outputs then are not to be used). */
static const char *law(const PiState *s, const double p[PI_N_PARAMS], const double in[PI_N_INPUTS], double h,
                       double *w, double *e, double *u_ff, double *v, double *u)
{
    double w_dot, clamped;
    *w = p[PI_P_EXTERNAL_SETPOINT] != 0.0 ? in[PI_I_OMEGA_SETPOINT] : p[PI_P_OMEGA_SET];
    *e = *w - in[PI_I_OMEGA_MEAS];
    if (!isfinite(*e))
        return "the speed error 'error' = w - omega_meas";
    *u_ff = 0.0;
    if (p[PI_P_FEEDFORWARD] > 0.0) {
        w_dot = (h <= 0.0 || !s->have_w_prev) ? 0.0 : (*w - s->w_prev) / h;
        if (!isfinite(w_dot))
            return "the setpoint's rate (w - w_prev) / h";
        *u_ff = p[PI_P_FEEDFORWARD] * (p[PI_P_R] / p[PI_P_C_M] * (in[PI_I_M_LOAD] + in[PI_I_J_LOAD] * w_dot)
                                       + p[PI_P_C_E] * *w);
        if (!isfinite(*u_ff))
            return "the feedforward 'u_ff'";
    }
    *v = *u_ff + p[PI_P_KP] * *e + s->integral;
    if (!isfinite(*v))
        return "the unclamped command u_ff + kp error + integral";
    clamped = p[PI_P_U_MIN] > *v ? p[PI_P_U_MIN] : *v;    /* max(v, u_min) */
    *u = p[PI_P_U_MAX] < clamped ? p[PI_P_U_MAX] : clamped;  /* min(., u_max) */
    return NULL;
}

void pi_state_clear(PiState *s)
{
    s->integral = 0.0;
    s->w_prev = 0.0;
    s->have_w_prev = 0;
    s->u = s->error = s->u_ff = 0.0;
}

const char *pi_initialize(PiState *s, const double p[PI_N_PARAMS], const double in[PI_N_INPUTS])
{
    double w, e, u_ff, v, u;
    const char *overflow = law(s, p, in, 0.0, &w, &e, &u_ff, &v, &u);
    if (overflow)
        return overflow;
    s->w_prev = w;
    s->have_w_prev = 1;
    s->error = e;
    s->u_ff = u_ff;
    s->u = u;
    return NULL;
}

const char *pi_sample(PiState *s, const double p[PI_N_PARAMS], const double in[PI_N_INPUTS], double h)
{
    double w, e, u_ff, v, u, integral = s->integral;
    const char *overflow = law(s, p, in, h, &w, &e, &u_ff, &v, &u);
    if (overflow)
        return overflow;
    if (!((v > p[PI_P_U_MAX] && e > 0.0) || (v < p[PI_P_U_MIN] && e < 0.0)))
        integral += p[PI_P_KI] * h * e;
    if (!isfinite(integral))
        return "the integral 'integral' + ki h error";
    s->integral = integral;
    s->w_prev = w;
    s->have_w_prev = 1;
    s->error = e;
    s->u_ff = u_ff;
    s->u = u;
    return NULL;
}

void pi_outputs(const PiState *s, double out[PI_N_OUTPUTS])
{
    out[PI_O_U] = s->u;
    out[PI_O_ERROR] = s->error;
    out[PI_O_INTEGRAL] = s->integral;
    out[PI_O_U_FF] = s->u_ff;
}
