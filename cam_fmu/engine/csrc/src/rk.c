/* Explicit Runge-Kutta methods as data over one generic step, and the error norm of embedded pairs.
 *
 * The stage increments are summed left to right over the nonzero coefficients only; a row with a
 * single nonzero coefficient a is applied as x + (h a) k. That is the order of the former Python engine's
 * Dormand-Prince step, so rk45 agrees with it to the last bit. */
#include <math.h>

#include "cam_solver.h"

#define TWO_PI (2.0 * 3.141592653589793)

/* Dormand-Prince 5(4) (Hairer, Norsett, Wanner, Solving ODE I, table 5.2); e = b5 - b4. */
const CamTableau cam_dopri5 = {
    6,
    {{0.0},
     {1.0 / 5.0},
     {3.0 / 40.0, 9.0 / 40.0},
     {44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0},
     {19372.0 / 6561.0, -25360.0 / 2187.0, 64448.0 / 6561.0, -212.0 / 729.0},
     {9017.0 / 3168.0, -355.0 / 33.0, 46732.0 / 5247.0, 49.0 / 176.0, -5103.0 / 18656.0}},
    {35.0 / 384.0, 0.0, 500.0 / 1113.0, 125.0 / 192.0, -2187.0 / 6784.0, 11.0 / 84.0},
    {0.0, 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0, 1.0},
    1,
    {71.0 / 57600.0, 0.0, -71.0 / 16695.0, 71.0 / 1920.0, -17253.0 / 339200.0, 22.0 / 525.0, -1.0 / 40.0},
    -0.2,
    0.0,
};

/* Bogacki-Shampine 3(2), FSAL, embedded error: 3 new stages per step where dopri5 takes 6. */
const CamTableau cam_bs23 = {
    3,
    {{0.0}, {1.0 / 2.0}, {0.0, 3.0 / 4.0}},
    {2.0 / 9.0, 1.0 / 3.0, 4.0 / 9.0},
    {0.0, 1.0 / 2.0, 3.0 / 4.0},
    1,
    {-5.0 / 72.0, 1.0 / 12.0, 1.0 / 9.0, -1.0 / 8.0},
    -1.0 / 3.0,
    0.0,
};

/* The classical Runge-Kutta method: x + (h / 6) (k1 + 2 k2 + 2 k3 + k4), in that order. */
const CamTableau cam_rk4 = {
    4,
    {{0.0}, {0.5}, {0.0, 0.5}, {0.0, 0.0, 1.0}},
    {1.0, 2.0, 2.0, 1.0},
    {0.0, 0.5, 0.5, 1.0},
    0,
    {0.0},
    0.0,
    6.0,
};

/* Explicit Euler: x + h k1. */
const CamTableau cam_euler = {1, {{0.0}}, {1.0}, {0.0}, 0, {0.0}, 0.0, 0.0};

/* The nonzero coefficients of one row: their indices into idx, returning how many. */
static inline int nonzero(const double *coef, int n, int idx[CAM_MAX_STAGES + 1])
{
    int j, count = 0;
    for (j = 0; j < n; j++)
        if (coef[j] != 0.0)
            idx[count++] = j;
    return count;
}

/* x + h * sum_j coef[j] k[j][slot] over the nonzero coefficients idx[0..count-1], left to right (a single
 * one as x + (h coef) k; see the file's comment). */
static inline double combine(const double *coef, const int *idx, int count, double (*k)[CAM_NX], int slot, double x,
                      double h)
{
    double sum;
    int m;
    if (count == 0)
        return x;
    if (count == 1)
        return x + h * coef[idx[0]] * k[idx[0]][slot];
    sum = coef[idx[0]] * k[idx[0]][slot];
    for (m = 1; m < count; m++)
        sum += coef[idx[m]] * k[idx[m]][slot];
    return x + h * sum;
}

/* The step over the first n slots: inlined below with n a constant (CAM_NX_RIGID, CAM_NX_SHAFT, CAM_NX), so that a rigid
 * drive's loops unroll over its three slots as they did before the compliant shaft's two existed. */
static inline void rk_step_slots(const CamMethod *method, const CamModel *m, const CamMode *mode,
                                 const double x[CAM_NX], double u, double h, CamStepWork *w, const int n)
{
    const CamTableau *t = method->tableau;
    double arg[CAM_NX];
    int i, slot, s = t->stages, idx[CAM_MAX_STAGES + 1], count;
    for (i = 1; i < s; i++) {
        count = nonzero(t->a[i], i, idx);
        for (slot = 0; slot < n; slot++)
            arg[slot] = combine(t->a[i], idx, count, w->k, slot, x[slot], h);
        cam_rhs(m, mode, arg, u, w->k[i]);
    }
    count = nonzero(t->b, s, idx);
    if (t->b_divisor > 0.0) {   /* x + (h / d) * (b_1 k_1 + ...): the weights' common factor first */
        double scaled = h / t->b_divisor;
        for (slot = 0; slot < n; slot++)
            w->x_new[slot] = x[slot] + scaled * combine(t->b, idx, count, w->k, slot, 0.0, 1.0);   /* 0 + 1 sum */
    } else {
        for (slot = 0; slot < n; slot++)
            w->x_new[slot] = combine(t->b, idx, count, w->k, slot, x[slot], h);
    }
    if (t->fsal) {
        cam_rhs(m, mode, w->x_new, u, w->k[s]);
        for (slot = 0; slot < n; slot++)
            w->f_new[slot] = w->k[s][slot];
    }
    if (method->adaptive) {   /* the error h * sum e_j k_j, the FSAL stage included */
        count = nonzero(t->e, s + (t->fsal ? 1 : 0), idx);
        for (slot = 0; slot < n; slot++)
            w->error[slot] = combine(t->e, idx, count, w->k, slot, 0.0, h);
    }
}

void cam_rk_step(const CamMethod *method, const CamModel *m, const CamMode *mode, const double x[CAM_NX], double u,
                 double h, CamStepWork *w)
{
    if (m->slots == CAM_NX)
        rk_step_slots(method, m, mode, x, u, h, w, CAM_NX);
    else if (m->slots == CAM_NX_SHAFT)
        rk_step_slots(method, m, mode, x, u, h, w, CAM_NX_SHAFT);
    else
        rk_step_slots(method, m, mode, x, u, h, w, CAM_NX_RIGID);
}

/* sum[slot] = h * sum_j coef[j] k[j][slot] over the nonzero coefficients idx[0..count-1], left to right (count >= 2),
 * for the first n slots of rows of `width`: combine's sum, slot by slot in the same order, over whole rows. */
static inline void weighted_sum(const double *coef, const int *idx, int count, const double *k, int n, int width,
                                double h, double *sum)
{
    int j, slot;
    const double *row = k + idx[0] * width;
    for (slot = 0; slot < n; slot++)
        sum[slot] = coef[idx[0]] * row[slot];
    for (j = 1; j < count; j++) {
        double a = coef[idx[j]];
        row = k + idx[j] * width;
        for (slot = 0; slot < n; slot++)
            sum[slot] += a * row[slot];
    }
    for (slot = 0; slot < n; slot++)
        sum[slot] *= h;
}

/* rk_step_slots over any state vector: k holds the stages as rows of `width`, k[0] = rates(y) on entry; the slots
 * from n on are carried unchanged. */
void cam_tableau_step(const CamTableau *t, int n, int width, CamRates rates, void *ctx, const double *y, double h,
                      double *k, double *y_new, double *error)
{
    double arg[CAM_MAX_SLOTS], sum[CAM_MAX_SLOTS];
    int i, slot, s = t->stages, idx[CAM_MAX_STAGES + 1] = {0}, count;
    for (slot = n; slot < width; slot++)
        arg[slot] = y_new[slot] = y[slot];
    for (i = 1; i < s; i++) {   /* the stages: x + (h a) k for a single coefficient, else x + h sum (combine) */
        count = nonzero(t->a[i], i, idx);
        if (count == 1) {
            double ha = h * t->a[i][idx[0]];
            const double *row = k + idx[0] * width;
            for (slot = 0; slot < n; slot++)
                arg[slot] = y[slot] + ha * row[slot];
        } else {
            weighted_sum(t->a[i], idx, count, k, n, width, h, sum);
            for (slot = 0; slot < n; slot++)
                arg[slot] = y[slot] + sum[slot];
        }
        rates(ctx, arg, k + i * width);
    }
    count = nonzero(t->b, s, idx);
    if (count == 1 && t->b_divisor <= 0.0) {   /* Euler */
        double hb = h * t->b[idx[0]];
        for (slot = 0; slot < n; slot++)
            y_new[slot] = y[slot] + hb * k[idx[0] * width + slot];
    } else {   /* (h / d) * (b_1 k_1 + ...) with the weights' common factor d, else h * (b_1 k_1 + ...) */
        weighted_sum(t->b, idx, count, k, n, width, 1.0, sum);
        for (slot = 0; slot < n; slot++)
            y_new[slot] = y[slot] + (t->b_divisor > 0.0 ? h / t->b_divisor : h) * sum[slot];
    }
    if (error == NULL || t->error_exponent == 0.0)
        return;
    if (t->fsal)
        rates(ctx, y_new, k + s * width);
    count = nonzero(t->e, s + (t->fsal ? 1 : 0), idx);
    weighted_sum(t->e, idx, count, k, n, width, h, error);
}

double cam_error_norm(const CamModel *m, const double x[CAM_NX], const CamStepWork *w)
{
    double total = 0.0, scale, atol = m->atol, rtol = m->rtol;
    int slot, n = m->nx;
    for (slot = 0; slot < m->slots; slot++) {
        if (slot == CAM_CURRENT && !m->has_current)
            continue;   /* quasi-static: no state */
        if (slot >= CAM_GAP && x[slot] == 0.0 && w->x_new[slot] == 0.0) {
            n -= 1;   /* a follower on its flank: its gap and rate are held at 0, no states */
            continue;
        }
        scale = fabs(w->x_new[slot]) > fabs(x[slot]) ? fabs(w->x_new[slot]) : fabs(x[slot]);
        if (slot == CAM_THETA && TWO_PI < scale)   /* theta enters the physics mod 2 pi */
            scale = TWO_PI;
        if (slot >= CAM_GAP) {   /* the follower's gap: its error is the follower's, on the scale of the lift */
            double lift = m->lift_scale * m->q_scale * cam_follower_length(m);   /* along the path: an arm's arc */
            double at = slot == CAM_GAP ? lift : lift * fabs(x[CAM_OMEGA]);
            scale = at > scale ? at : scale;
        }
        if (slot == 0)
            total = pow(w->error[slot] / (atol + rtol * scale), 2.0);
        else
            total += pow(w->error[slot] / (atol + rtol * scale), 2.0);
    }
    return sqrt(total / n);
}
