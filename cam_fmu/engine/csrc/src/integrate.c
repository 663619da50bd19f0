/* One communication step of the consistent formulation with any method: adaptive steps with error
 * control (or fixed steps inside the method's limits), profile breakpoints, events located on the step's dense
 * output and polished on re-stepped trial states by Illinois false position (locate: every hybrid run's one
 * locator), transitions, the work bound max_steps, rollback.
 *
 * Ported from the former Python engine (its step attempt, trial, locate, first_event,
 * advance) with the order of floating-point operations kept: rk45 agrees with it to the last bit. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "cam_solver.h"

#define EVENT_ITERATIONS 60   /* Illinois iterations at most per zero located to a tolerance */
#define EXACT_ITERATIONS 400  /* and to the last bit (never a hang; 60 halvings alone get there from 1 s) */
#define PHASE_STEPS 10000000  /* internal steps at most where a formulation's phases bound them (a follower's flight
                               * resolved at a fixed phase per step): max_steps does not cap those (never a hang) */

/* f(x) into d->solver.k1 unless it is valid already. */
static void ensure_k1(CamDrive *d, double u)
{
    if (!d->solver.k1_valid) {
        cam_rhs(&d->model, &d->mode, d->x, u, d->solver.k1);
        d->solver.k1_valid = 1;
    }
}

/* One step of size h from d->x into it->work (k1 valid): the method's, or the exponential pair when the
 * step in hand is one (so the event locator's trial steps continue the step that was taken). */
static void method_step(CamDrive *d, CamIntegrator *it, double h, double u)
{
    if (it->exponential) {
        cam_exponential_pair(&d->model, &d->mode, d->x, u, h, &it->work);
        return;
    }
    memcpy(it->work.k[0], d->solver.k1, sizeof d->solver.k1);
    it->method->step(it->method, &d->model, &d->mode, d->x, u, h, &it->work);
    cam_impose_motion(&d->model, d->x, u, h, it->work.x_new);
}

/* A likely cause of many small steps, into buf ("" for none): a follower train ringing faster than h_max resolves, or
 * a compliant shaft's rate against the lightest cam side, or the electrical pole, which rk45 then takes explicitly
 * (docs/model.md 12.1, 14.6). */
static void stiff_cause(const CamModel *m, char *buf, size_t len)
{
    double shaft, pole;
    buf[0] = '\0';
    if (m->train && m->train_rate * m->h_max > 1.0) {
        snprintf(buf, len, "; the follower train's rate (%s) = %.3g 1/s asks for steps of about %.3g s (a tenth "
                 "of that with a fixed step: soften its spring or raise its end's inertia, or raise max_steps)",
                 cam_train_names(m), m->train_rate, 1.0 / m->train_rate);
        return;
    }
    if (!m->compliant)
        return;
    shaft = cam_shaft_rate(m, m->J_0);
    pole = m->has_current ? m->R / m->L : 0.0;
    if (pole > shaft)
        snprintf(buf, len, "; with a compliant shaft the electrical pole R/L = %.3g 1/s is integrated explicitly "
                 "(set L = 0 if it does not matter)", pole);
    else
        snprintf(buf, len, "; the compliant shaft's rate sqrt(k_shaft (1/J_m + 1/J_cam)) + d_shaft (1/J_m + 1/J_cam) "
                 "= %.3g 1/s asks for steps of about %.3g s (soften the shaft or lower d_shaft, raise J_cam, or make it "
                 "rigid: k_shaft = 0)", shaft, 1.0 / shaft);
}

int cam_step_control(double norm, double exponent, double bound, double *dt, double *h_next)
{
    double factor, t;   /* no fmin/fmax: a call each where the compiler may not assume finite numbers */
    if (norm <= 1.0) {
        t = norm == 0.0 ? 5.0 : 0.9 * pow(norm, exponent);
        factor = t < 5.0 ? t : 5.0;
        if (*dt < bound || factor < 1.0) {
            t = *dt * factor;
            *h_next = 1e3 < t ? 1e3 : t;
        } else {   /* a step the bounds cut: its success says nothing against a longer next one */
            t = *dt * (1.0 < factor ? 1.0 : factor);
            *h_next = t > *h_next ? t : *h_next;
        }
        return 1;
    }
    t = 0.9 * pow(isfinite(norm) ? norm : 1e10, exponent);
    *dt *= t > 0.1 ? t : 0.1;
    return 0;
}

int cam_step_adaptive(CamDrive *d, CamIntegrator *it, double remaining, double time, double span, double *dt_out,
                      CamError *err)
{
    const CamModel *m = &d->model;
    double dt = d->solver.h_next, floor_ = 1e-12 * span, u = d->form_u;
    if (remaining < dt)
        dt = remaining;
    if (m->h_max < dt)
        dt = m->h_max;
    ensure_k1(d, u);
    for (;;) {
        it->exponential = m->has_current && m->slots == CAM_NX_RIGID && dt * m->R / m->L > CAM_POLE_LIMIT;
        method_step(d, it, dt, u);
        if (cam_step_control(cam_error_norm(m, d->x, &it->work), it->method->tableau->error_exponent, remaining, &dt,
                             &d->solver.h_next)) {
            memcpy(it->x_end, it->work.x_new, sizeof it->x_end);
            if (!it->exponential)
                memcpy(it->f_end, it->work.f_new, sizeof it->f_end);
            *dt_out = dt;
            return CAM_OK;
        }
        if (dt < floor_) {
            char a[32], b[32], c[32], e[32], cause[300];
            stiff_cause(m, cause, sizeof cause);
            snprintf(a, sizeof a, "%g", m->rtol);
            snprintf(b, sizeof b, "%g", m->atol);
            snprintf(c, sizeof c, "%g", floor_);
            snprintf(e, sizeof e, "%g", time);
            *dt_out = dt;
            return cam_error(err, CAM_ERR_REJECTED,
                            "solver '%s' cannot meet rtol = %s, atol = %s: its step fell below %s s (1e-12 of "
                            "the communication step) at t = %s s: loosen rtol/atol, or check the inputs and "
                            "parameters for a near-singular drive%s", it->method->name, a, b, c, e, cause);
        }
    }
}

/* The state tau [s] into the current step, into it->work.x_new (moving: a step; stuck: exact). */
static void trial(CamDrive *d, CamIntegrator *it, double tau, double u)
{
    if (d->mode.stuck && d->model.slots == CAM_NX_RIGID) {
        it->work.x_new[CAM_THETA] = d->x[CAM_THETA];
        it->work.x_new[CAM_OMEGA] = 0.0;
        it->work.x_new[CAM_CURRENT] = cam_current_at_rest(&d->model, d->x[CAM_CURRENT], u, tau);
    } else {
        method_step(d, it, tau, u);
    }
}

static double zero_value(CamDrive *d, int code, double target, const double x[CAM_NX], double u)
{
    if (code < 0)
        return d->mode.direction * (target - x[CAM_THETA]);
    return cam_event_value(&d->model, &d->mode, code, x, u);
}

/* Is the bracket (lo, hi] still open after j iterations: wider than tol, or (tol = 0) has it a double inside? */
static int open_bracket(double lo, double hi, double tol, int j)
{
    double mid = 0.5 * (lo + hi);
    return tol > 0.0 ? j < EVENT_ITERATIONS && hi - lo > tol : j < EXACT_ITERATIONS && lo < mid && mid < hi;
}

typedef struct {                /* the values' arguments but the code and the time */
    CamDrive *d;
    CamIntegrator *it;
    const int *codes;           /* the functions located */
    double target;              /* rad: the breakpoint of code -1 */
    double dt;                  /* s: the step's length */
    double x[CAM_MAX_EVENTS][CAM_NX];   /* each function's latest trial state on its event side (<= 0) */
} Trial;

typedef double (*Value)(Trial *t, int k, double tau);

/* Illinois false position on function k from g_lo > 0 at lo to g_hi <= 0 at hi, to a bracket of tol [s]: the
 * bracket's end past the zero; the secant slope of the last bracket's values into *slope. */
static double illinois(Value value, Trial *t, int k, double lo, double hi, double g_lo, double g_hi, double tol,
                       double *slope)
{
    int side = 0, j;
    double tau, g, raw_lo = g_lo, raw_hi = g_hi;
    for (j = 0; open_bracket(lo, hi, tol, j); j++) {
        tau = g_hi != g_lo ? hi - g_hi * (hi - lo) / (g_hi - g_lo) : 0.5 * (lo + hi);
        if (g_hi == 0.0 && side != 2) {   /* the secant stays at an exact zero: first a try just before it */
            tau = hi - 0.9 * tol;
            side = 2;
        }
        if (!(lo < tau && tau < hi))
            tau = 0.5 * (lo + hi);
        g = value(t, k, tau);
        if (g <= 0.0) {
            hi = tau;
            g_hi = raw_hi = g;
            g_lo *= side == -1 ? 0.5 : 1.0;
            side = -1;
        } else {
            lo = tau;
            g_lo = raw_lo = g;
            g_hi *= side == 1 ? 0.5 : 1.0;
            side = 1;
        }
    }
    *slope = (raw_hi - raw_lo) / (hi - lo);
    return hi;
}

/* Function k at the trial state tau [s] into the step (moving: a step taken again; stuck: exact), the state kept
 * where it is <= 0 (the located time is the latest such trial: no step taken again). */
static double trial_value(Trial *t, int k, double tau)
{
    double g;
    trial(t->d, t->it, tau, t->d->form_u);
    g = zero_value(t->d, t->codes[k], t->target, t->it->work.x_new, t->d->form_u);
    if (g <= 0.0)
        memcpy(t->x[k], t->it->work.x_new, sizeof t->x[k]);
    return g;
}

/* Function k on the step's dense output at tau [s]: the cubic Hermite interpolant of its ends' states and rates,
 * every method's (no stage computed; docs/model.md 10). */
static double dense_value(Trial *t, int k, double tau)
{
    const double *x0 = t->d->x, *f0 = t->d->solver.k1, *x1 = t->it->x_end, *f1 = t->it->f_end;
    double s = tau / t->dt, r = 1.0 - s, x[CAM_NX];
    int slot;
    memcpy(x, x1, sizeof x);
    for (slot = 0; slot < t->d->model.slots; slot++)
        x[slot] = (1.0 + 2.0 * s) * r * r * x0[slot] + s * r * r * t->dt * f0[slot] + s * s * (3.0 - 2.0 * s) * x1[slot]
                  - s * s * r * t->dt * f1[slot];
    return zero_value(t->d, t->codes[k], t->target, x, t->d->form_u);
}

/* Function k's zero in (0, end], from g0 > 0 at the step's start to g_end <= 0 at end, polished from its zero `root`
 * on the dense output [s] on trial states: two secant steps (the first on the interpolant's slope), then two trials a
 * bracket of tol [s] apart about the result, and Illinois from what they leave (each trial inside narrows it). */
static double zero_of(Trial *t, int k, double g0, double end, double g_end, double root, double tol)
{
    double slope, lo = 0.0, hi = end, g_lo = g0, g_hi = g_end, tau, g, last = 0.0, g_last = 0.0;
    int j;
    slope = (dense_value(t, k, root + 1e-4 * t->dt) - dense_value(t, k, root - 1e-4 * t->dt)) / (2e-4 * t->dt);
    for (j = 0; j < 4; j++) {
        tau = j < 2 ? root : root + (j == 2 ? 0.45 : -0.45) * tol;
        if (!(lo < tau && tau <= hi))
            continue;
        g = trial_value(t, k, tau);
        if (j == 1)   /* the secant through the two trials */
            slope = (g - g_last) / (tau - last);
        if (j < 2) {
            last = tau;
            g_last = g;
            root = tau - g / slope;
        }
        if (g <= 0.0) {
            hi = tau;
            g_hi = g;
        } else {
            lo = tau;
            g_lo = g;
        }
    }
    return illinois(trial_value, t, k, lo, hi, g_lo, g_hi, tol, &slope);
}

/* The first of n functions codes[k] to go from before[k] > 0 to after[k] <= 0 over the step of dt from d->x to
 * it->x_end: its index (-1: none), its time *tau from the step start [s] and the state there in it->x_hit. Each
 * crossing function's zero is found on the dense output and polished on trial steps; one that is already <= 0 at
 * the first polished zero went first and is located before it in turn. */
static int locate(CamDrive *d, CamIntegrator *it, int n, const int codes[], const double before[],
                  const double after[], double target, double dt, double *tau)
{
    Trial t;
    int k, first = -1, exact = d->mode.stuck && d->model.slots == CAM_NX_RIGID, open[CAM_MAX_EVENTS];
    double tol = 1e-13 * (1e-300 > dt ? 1e-300 : dt) + 1e-15, end = dt, slope, seed[CAM_MAX_EVENTS],
           g_end[CAM_MAX_EVENTS];
    t.d = d;
    t.it = it;
    t.codes = codes;
    t.target = target;
    t.dt = dt;
    for (k = 0; k < n; k++) {   /* the earliest seed; the common case: nothing crossed, no call */
        g_end[k] = after[k];
        open[k] = before[k] > 0.0 && after[k] <= 0.0;
        if (!open[k])
            continue;
        if (first < 0 && !exact && !it->f_end_valid)
            cam_rhs(&d->model, &d->mode, it->x_end, d->form_u, it->f_end);
        seed[k] = exact ? dt : illinois(dense_value, &t, k, 0.0, dt, before[k], after[k], tol, &slope);
        first = first < 0 || seed[k] < seed[first] ? k : first;
    }
    while (first >= 0) {   /* polish the first; another function at or below 0 at its zero went before it */
        memcpy(t.x[first], end < dt ? it->x_hit : it->x_end, sizeof t.x[first]);   /* the state at end */
        end = exact ? illinois(trial_value, &t, first, 0.0, end, before[first], g_end[first], tol, &slope)
                    : zero_of(&t, first, before[first], end, g_end[first], seed[first], tol);
        memcpy(it->x_hit, t.x[first], sizeof it->x_hit);
        *tau = end;
        open[first] = 0;
        for (k = 0; k < n; k++)
            if (open[k] && (g_end[k] = zero_value(d, codes[k], target, it->x_hit, d->form_u)) <= 0.0)
                break;
        if (k == n)
            return first;
        first = k;
    }
    return -1;
}

/* The earliest event in (0, dt] of the step from d->x to it->x_end: its time from the step start [s],
 * its code in it->hit and the state there in it->x_hit; or -1 (none). A function at or below zero at
 * the start fires at once if it goes into the event (g1 < 0, or it started below zero). */
static double first_event(CamDrive *d, CamIntegrator *it, double dt)
{
    int n = it->n_events, k;
    double tau, u = d->form_u;
    if (!it->have_before)
        cam_event_values(&d->model, &d->mode, n, it->codes, d->x, u, it->before);
    it->have_before = 0;
    if (n == 0)
        return -1.0;
    cam_event_values(&d->model, &d->mode, n, it->codes, it->x_end, u, it->after);
    for (k = 0; k < n; k++)
        if (it->before[k] < 0.0 || (it->before[k] == 0.0 && it->after[k] < 0.0)) {
            it->hit = it->codes[k];
            memcpy(it->x_hit, d->x, sizeof it->x_hit);
            return 0.0;
        }
    k = locate(d, it, n, it->codes, it->before, it->after, 0.0, dt, &tau);
    if (k < 0) {
        for (k = 0; k < n; k++)
            it->before[k] = it->after[k];
        it->have_before = 1;   /* the next step starts where this one ended */
        return -1.0;
    }
    it->hit = it->codes[k];
    return tau;
}

static int max_steps_error(const CamDrive *d, const CamMethod *method, double time, double h, CamError *err)
{
    const CamModel *m = &d->model;
    char advice[256], cause[300];
    stiff_cause(m, cause, sizeof cause);
    if (h > m->h_max * (double)m->max_steps)  /* h_max alone makes the count impossible: say so */
        snprintf(advice, sizeof advice, "h_max = %g s caps every internal step, so this communication step "
                 "needs at least %.4g of them: raise h_max or max_steps, or shorten the communication step",
                 m->h_max, h / m->h_max);
    else if (method->adaptive)   /* the pole is no cause here: the exponential pair takes it */
        snprintf(advice, sizeof advice, "raise max_steps, loosen rtol/atol or shorten the communication step");
    else
        snprintf(advice, sizeof advice, "raise max_steps or h_max (now %g s), or shorten the communication step; "
                 "'%s' takes steps no longer than its stability limit", m->h_max, method->name);
    return cam_error(err, CAM_ERR_REJECTED, "solver '%s' needed more than max_steps = %ld internal steps in one "
                    "communication step of %g s at t = %g s: %s%s", method->name, m->max_steps, h, time, advice,
                    cause);
}

/* Are two modes the same (the rates and the event functions alike)? */
static int same_mode(const CamMode *a, const CamMode *b)
{
    return a->stuck == b->stuck && a->direction == b->direction && a->contact == b->contact
           && a->s_free == b->s_free && a->side == b->side && a->left == b->left && a->sigma == b->sigma;
}

/* The loop of one communication step (the state saved by the caller). */
static int advance(CamDrive *d, CamIntegrator *it, double h, double time, long *steps_out, CamError *err)
{
    const CamModel *m = &d->model;
    double t = 0.0, u = d->form_u, remaining, dt, target, cut, tau;
    long steps = 0, retries;
    int was_stuck = d->mode.stuck, status, at_break;
    it->have_before = 0;
    if (!(d->solver.k1_valid && d->solver.fsal_u == u && !was_stuck)) {   /* else settled where the last step ended */
        if (d->form->transition != NULL)   /* the formulation settles its own modes */
            d->form->transition(d, EV_NONE, time);
        else
            cam_settle(m, &d->mode, d->x, u, 0);
        d->solver.k1_valid = 0;
    }
    it->n_events = cam_event_codes(m, &d->mode, it->codes);
    while (h - t > 1e-12 * h) {
        if (d->mode.stuck && !m->has_current && m->slots == CAM_NX_RIGID)
            break;   /* nothing evolves until the input changes */
        steps += 1;
        if (steps > m->max_steps && !(d->form->step_limit != NULL && steps <= PHASE_STEPS)) {
            *steps_out = steps;
            return max_steps_error(d, it->method, time + t, h, err);
        }
        remaining = h - t;
        if (d->form->step_limit != NULL) {   /* the formulation's phases (a follower's flight) bound the step */
            double limit = d->form->step_limit(d, time + t);
            remaining = limit < remaining ? limit : remaining;
        }
        it->f_end_valid = 0;
        at_break = 0;
        it->exponential = 0;
        if (d->mode.stuck && m->slots == CAM_NX_RIGID) {   /* only the current moves, exactly (shaft, train: solver) */
            dt = remaining;
            it->x_end[CAM_THETA] = d->x[CAM_THETA];
            it->x_end[CAM_OMEGA] = 0.0;
            it->x_end[CAM_CURRENT] = cam_current_at_rest(m, d->x[CAM_CURRENT], u, dt);
        } else {
            if (it->method->adaptive) {
                status = cam_step_adaptive(d, it, remaining, time + t, h, &dt, err);
                it->f_end_valid = !it->exponential;   /* the pair computes no f at its end */
            } else {
                ensure_k1(d, u);
                status = cam_step_fixed(d, it, remaining, &dt, &retries, err);
                steps += retries;
                it->f_end_valid = it->method->tableau != NULL && it->method->tableau->fsal;
            }
            if (status != CAM_OK) {
                *steps_out = steps;
                return status;
            }
            target = cam_profile_first_breakpoint(&m->profile, d->x[CAM_THETA], it->x_end[CAM_THETA]);
            if (target == target) {   /* the step crosses a breakpoint and ends just past it */
                int code = -1;
                double g[2] = {d->mode.direction * (target - d->x[CAM_THETA]),
                               d->mode.direction * (target - it->x_end[CAM_THETA])};
                if (locate(d, it, 1, &code, &g[0], &g[1], target, dt, &cut) < 0)
                    cut = dt;
                if (cut != dt) {   /* its first-same-as-last derivative belonged to the longer step */
                    dt = cut;
                    memcpy(it->x_end, it->x_hit, sizeof it->x_end);
                    it->f_end_valid = 0;
                }
                at_break = d->form->transition != NULL;   /* the formulation's modes settle past it */
            }
        }
        tau = first_event(d, it, dt);
        if (tau < 0.0) {
            memcpy(d->x, it->x_end, sizeof d->x);
            t += dt;
            d->solver.k1_valid = it->f_end_valid;
            if (it->f_end_valid)
                memcpy(d->solver.k1, it->f_end, sizeof d->solver.k1);
            if (at_break) {   /* a jump of s'' may let the follower go at once */
                CamMode before = d->mode;
                d->form->transition(d, EV_BREAK, time + t);
                if (!same_mode(&before, &d->mode)) {
                    d->solver.k1_valid = 0;
                    it->n_events = cam_event_codes(m, &d->mode, it->codes);
                    it->have_before = 0;
                }
            }
            continue;
        }
        memcpy(d->x, it->x_hit, sizeof d->x);
        t += tau;
        d->solver.k1_valid = 0;
        {
            CamEventRecord *record = &d->event_log[d->events_logged % CAM_EVENT_LOG];
            record->code = it->hit;
            record->time = time + t;
            memcpy(record->x_before, d->x, sizeof d->x);
            record->mode_before = d->mode;
            if (d->form->transition != NULL)
                d->form->transition(d, it->hit, time + t);
            else
                cam_apply_event(m, &d->mode, d->x, it->hit, u);
            memcpy(record->x_after, d->x, sizeof d->x);
            d->events_logged += 1;
        }
        it->n_events = cam_event_codes(m, &d->mode, it->codes);
        it->have_before = 0;
    }
    if (d->mode.stuck)
        d->solver.k1_valid = 0;
    d->solver.fsal_u = u;
    *steps_out = steps;
    return CAM_OK;
}

int cam_integrate(CamDrive *d, double h, double time, long *steps, CamError *err)
{
    CamIntegrator it;
    double x[CAM_NX], h_next = d->solver.h_next;
    CamMode mode = d->mode;
    long logged = d->events_logged;
    int status;
    /* what the loop reads before writing: the flags, and the slots a rigid drive's steps leave alone (they are
     * copied into d->x whole); zeroing the whole integrator cost a rigid run 0.6 % of its instructions */
    it.n_events = it.have_before = it.hit = it.exponential = it.f_end_valid = 0;
    memset(it.x_end, 0, sizeof it.x_end);
    memset(it.x_hit, 0, sizeof it.x_hit);
    memset(it.work.x_new, 0, sizeof it.work.x_new);
    memset(it.work.f_new, 0, sizeof it.work.f_new);
    memset(it.f_end, 0, sizeof it.f_end);
    it.method = cam_method(d->model.solver);
    if (it.method == NULL)
        return cam_error(err, CAM_ERR_SIMULATION, "solver choice %d is not available in the engine", d->model.solver);
    memcpy(x, d->x, sizeof x);
    status = advance(d, &it, h, time, steps, err);
    if (status != CAM_OK) {   /* a refused step leaves the state as before it (fmi2Discard) */
        memcpy(d->x, x, sizeof x);
        d->mode = mode;
        d->solver.k1_valid = 0;
        d->solver.h_next = h_next;
        d->events_logged = logged;   /* its transitions did not happen */
    }
    return status;
}
