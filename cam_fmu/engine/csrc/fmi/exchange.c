/* Model Exchange over the model contract (exchange.h): derivatives, event indicators in fixed slots,
 * the event update, the guards at a completed integrator step. Holds no physics: cam_model.h does. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "exchange.h"

#define TWO_PI (2.0 * 3.141592653589793)

static const char *const EVENT_NAMES[] = {"stop", "contact", "engage_up", "engage_down", "break_away", "side_force"};

const char *cam_exchange_event_name(int code)
{
    return code >= 0 && code < (int)(sizeof EVENT_NAMES / sizeof EVENT_NAMES[0]) ? EVENT_NAMES[code] : "none";
}

static int fail(CamExchange *e, int status, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* A refusal: its message into the instance's error, the status returned. */
static int fail(CamExchange *e, int status, const char *fmt, ...)
{
    va_list args;
    va_start(args, fmt);
    cam_verror(cam_instance_error(e->instance), (CamStatus)status, fmt, args);
    va_end(args);
    return status;
}

/* A formulation with Model Exchange hooks of its own (the voltage drive's follower of its own, closures 'form',
 * 'spring'): its states, events and event update are the hooks' (cam_drive.h CamExchangeHooks). */
static const CamExchangeHooks *follower(const CamDrive *d)
{
    return d->form->exchange;
}

void cam_exchange_init(CamExchange *e, CamInstance *instance)
{
    memset(e, 0, sizeof *e);
    e->instance = instance;
    e->target = NAN;
}

/* The next breakpoint ahead of theta in the direction of travel [rad], NaN if the profile has none. */
static double next_breakpoint(const CamDrive *d)
{
    double theta = d->x[CAM_THETA];
    return cam_profile_first_breakpoint(&d->model.profile, theta, theta + d->mode.direction * 1.5 * TWO_PI);
}

void cam_exchange_sync(CamExchange *e)
{
    CamDrive *d = e->drive;
    const double *in = cam_instance_inputs(e->instance);
    if (d == NULL)
        return;
    if (d->u != in[CAM_I_U] || d->form_u != in[CAM_I_U] || d->omega_ref != in[CAM_I_OMEGA_REF]
        || d->omega_dot_ref != in[CAM_I_OMEGA_DOT_REF]) {
        /* the mode is left alone: it changes only at events (the break-away indicator watches u) */
        d->u = d->form_u = in[CAM_I_U];
        d->omega_ref = in[CAM_I_OMEGA_REF];
        d->omega_dot_ref = in[CAM_I_OMEGA_DOT_REF];
        d->stale = 1;
    }
}

int cam_exchange_attach(CamExchange *e)
{
    CamDrive *d = cam_instance_drive(e->instance);
    e->drive = NULL;
    if (d == NULL)
        return fail(e, CAM_ERR_SIMULATION, "the drive is not initialised");
    if (d->model.formulation == CAM_FORM_PAPER)
        return fail(e, CAM_ERR_PARAMETER, "formulation 'paper' is the paper's fixed-step discrete algorithm: it "
                    "defines the state at the points of its own step, no derivatives a host's solver could "
                    "integrate, so it runs in co-simulation only; in Model Exchange use "
                    "formulation 'consistent' (the default)");
    if (d->model.formulation == CAM_FORM_SPEED)
        return fail(e, CAM_ERR_PARAMETER, "drive 'speed' imposes omega from the input omega_ref and moves the "
                    "follower through a play operator (memory in the gap, a jump to the rest position at "
                    "standstill): no ODE for a host's solver, and co-simulation computes it exactly, so it runs "
                    "in co-simulation only; in Model Exchange use drive 'voltage'");
    e->drive = d;
    d->solver.k1_valid = 0;   /* outputs compute omega_dot at the host's state, never a solver's stage */
    cam_exchange_sync(e);
    d->stale = 1;
    e->target = next_breakpoint(d);
    e->book_time = d->time;
    e->book_u = d->u;
    e->requested = 0;
    e->iterations = 0;
    e->broke_away = 0;
    e->longest_gap = 0.0;
    e->evaluations = 0;
    e->last_time = e->step_time = d->time;
    return CAM_OK;
}

int cam_exchange_set_time(CamExchange *e, double time)
{
    if (!isfinite(time) || fabs(time) > 1e15)
        return fail(e, CAM_ERR_SIMULATION, "time = %.17g s must be finite within [-1e15, 1e15] s", time);
    if (time - e->last_time > e->longest_gap)   /* the host's sampling of the drive, forward in time */
        e->longest_gap = time - e->last_time;
    e->last_time = time;
    e->drive->time = time;
    return CAM_OK;
}

static int check_count(CamExchange *e, size_t n, size_t expected, const char *what)
{
    if (n == expected)
        return CAM_OK;
    return fail(e, CAM_ERR_SIMULATION, "%s: %lu given, cam.fmu has %lu (the model description's count)", what,
                (unsigned long)n, (unsigned long)expected);
}

int cam_exchange_set_states(CamExchange *e, const double x[], size_t nx)
{
    size_t k;
    if (check_count(e, nx, CAM_ME_NX, "continuous states") != CAM_OK)
        return CAM_ERR_SIMULATION;
    for (k = 0; k < CAM_ME_NX; k++)
        if (!isfinite(x[k]))
            return fail(e, CAM_ERR_SIMULATION, "continuous state '%s' = %g is not finite",
                        cam_state_spec((int)k)->name, x[k]);
    cam_drive_set_me_states(e->drive, x);
    return CAM_OK;
}

int cam_exchange_get_states(CamExchange *e, double x[], size_t nx)
{
    if (check_count(e, nx, CAM_ME_NX, "continuous states") != CAM_OK)
        return CAM_ERR_SIMULATION;
    cam_drive_me_states(e->drive, x);
    return CAM_OK;
}

int cam_exchange_derivatives(CamExchange *e, double dx[], size_t nx)
{
    double x[CAM_ME_NX];
    if (check_count(e, nx, CAM_ME_NX, "state derivatives") != CAM_OK)
        return CAM_ERR_SIMULATION;
    cam_exchange_sync(e);
    cam_drive_me_states(e->drive, x);
    cam_drive_me_rates(e->drive, x, dx);
    e->evaluations++;
    e->evaluated_at = e->drive->time;
    return CAM_OK;
}

int cam_exchange_nominals(CamExchange *e, double nominal[], size_t nx)
{
    size_t k;
    if (check_count(e, nx, CAM_ME_NX, "nominals of the continuous states") != CAM_OK)
        return CAM_ERR_SIMULATION;
    for (k = 0; k < nx; k++)
        nominal[k] = 1.0;
    nominal[CAM_GAP] = 1e-3;    /* m, m/s: a follower's flight (a groove's clearance, a bounce's height) is of */
    nominal[CAM_RATE] = 1e-2;   /* millimetres; a host's absolute tolerance is its relative one times these */
    return CAM_OK;
}

/* The mode's event codes: cam_event_codes', and the break-away also at rest with L = 0, where the
 * co-simulation settles at each step's input but here the input changes continuously. */
static int active_codes(const CamDrive *d, int codes[CAM_MAX_EVENTS])
{
    int n;
    if (follower(d))
        return follower(d)->codes(d, codes);
    n = cam_event_codes(&d->model, &d->mode, codes);
    if (d->mode.stuck && !d->model.has_current && !d->model.compliant && n < CAM_ME_EVENTS)
        codes[n++] = CAM_EV_BREAK_AWAY;
    return n;
}

/* The event function `code` of the drive's mode at the states x. */
static double event_value(const CamDrive *d, int code, const double x[CAM_ME_NX])
{
    return follower(d) ? follower(d)->event(d, code, x) : cam_event_value(&d->model, &d->mode, code, x, d->u);
}

/* Every indicator into z[CAM_EXCHANGE_NZ]; the codes of the slots into codes (n of them). */
static int indicators(const CamDrive *d, double target, double z[CAM_EXCHANGE_NZ], int codes[CAM_MAX_EVENTS])
{
    int n = active_codes(d, codes), k;
    double x[CAM_ME_NX];
    cam_drive_me_states(d, x);
    for (k = 0; k < CAM_ME_EVENTS; k++)
        z[k] = k < n ? event_value(d, codes[k], x) : CAM_EXCHANGE_IDLE;
    z[CAM_EXCHANGE_BREAKPOINT] = d->mode.stuck || target != target ? CAM_EXCHANGE_IDLE
                                                                    : d->mode.direction * (target - d->x[CAM_THETA]);
    return n;
}

int cam_exchange_indicators(CamExchange *e, double z[], size_t nz)
{
    int codes[CAM_MAX_EVENTS];
    if (check_count(e, nz, CAM_EXCHANGE_NZ, "event indicators") != CAM_OK)
        return CAM_ERR_SIMULATION;
    cam_exchange_sync(e);
    indicators(e->drive, e->target, z, codes);
    return CAM_OK;
}

void cam_exchange_enter_event_mode(CamExchange *e)
{
    e->requested = 0;
    e->iterations = 0;
    e->broke_away = 0;
}

static int below_zero(const double z[CAM_EXCHANGE_NZ], int n)
{
    int k;
    for (k = 0; k < n; k++)
        if (z[k] < 0.0)
            return k;
    return -1;
}

/* The first slot whose event is due at an event instant: below zero, or exactly zero and heading below it
 * (the co-simulation integrator's rule for a function at zero at a step's start). A root finder such as
 * CVode's returns the state where the function it bracketed is exactly 0 when the arithmetic cancels
 * exactly there (the follower at the cam's lift plus the clearance); it then takes the function as
 * inactive and never sees it go below zero. The heading is the function a short probe later along the
 * derivatives, CAM_EXCHANGE_PROBE [s]: far below the drive's time scales, far above rounding.
 * The break-away at rest is driven by the input, which no probe of the state sees (with L = 0 the state does
 * not move at all): at exactly zero its margin is at the threshold, which is where its transition starts the
 * shaft (cam_apply_event), so it is due once per event instant. */
static int due(const CamExchange *e, const double z[CAM_EXCHANGE_NZ], const int codes[CAM_MAX_EVENTS], int n)
{
    const CamDrive *d = e->drive;
    double x[CAM_ME_NX], dx[CAM_ME_NX], probe[CAM_ME_NX];
    int k, j, have = 0;
    for (k = 0; k < n; k++) {
        if (z[k] < 0.0)
            return k;
        if (z[k] > 0.0)
            continue;
        if (codes[k] == (follower(d) ? CAM_VF_BREAK_AWAY : CAM_EV_BREAK_AWAY) && !e->broke_away)
            return k;
        if (!have) {
            cam_drive_me_states(d, x);
            cam_drive_me_rates(d, x, dx);
            for (j = 0; j < CAM_ME_NX; j++)
                probe[j] = x[j] + CAM_EXCHANGE_PROBE * dx[j];
            have = 1;
        }
        if (event_value(d, codes[k], probe) < 0.0)
            return k;
    }
    return -1;
}

int cam_exchange_event_update(CamExchange *e, CamExchangeEvent *fired, int *values_changed, int *needed)
{
    CamDrive *d = e->drive;
    const CamModel *m = &d->model;
    double z[CAM_EXCHANGE_NZ];
    int codes[CAM_MAX_EVENTS], n, k;
    *values_changed = 0;
    *needed = 0;
    fired->code = -1;
    fired->note = NULL;
    fired->time = d->time;
    cam_exchange_sync(e);
    if (e->iterations >= CAM_EXCHANGE_MAX_ITERATIONS)
        return fail(e, CAM_ERR_SIMULATION, "the event iteration at t = %g s did not settle after %d transitions "
                    "(theta = %g rad, omega = %g rad/s): the drive's mode cannot be decided there", d->time,
                    CAM_EXCHANGE_MAX_ITERATIONS, d->x[CAM_THETA], d->x[CAM_OMEGA]);
    e->iterations += 1;
    cam_drive_me_states(d, fired->x_before);
    n = indicators(d, e->target, z, codes);
    k = due(e, z, codes, n);
    if (follower(d)) {   /* a lift-off, touch-down or halt, else the contact settled; its log line is the note */
        int status = follower(d)->event_update(d, k >= 0 ? codes[k] : EV_NONE, cam_instance_error(e->instance));
        if (status != CAM_OK)
            return status;
        fired->code = k >= 0 ? codes[k] : -1;
        fired->note = d->step_events;
        e->broke_away |= k >= 0 && codes[k] == CAM_VF_BREAK_AWAY;
    } else if (k >= 0) {   /* one transition, logged as the co-simulation integrator logs its own */
        CamEventRecord *record = &d->event_log[d->events_logged % CAM_EVENT_LOG];
        fired->code = codes[k];
        record->code = codes[k];
        record->time = d->time;
        memcpy(record->x_before, d->x, sizeof d->x);
        record->mode_before = d->mode;
        cam_apply_event(m, &d->mode, d->x, codes[k], d->u);
        e->broke_away |= codes[k] == CAM_EV_BREAK_AWAY;
        memcpy(record->x_after, d->x, sizeof d->x);
        d->events_logged += 1;
    } else {   /* at rest: stay stuck or start under the input now; the friction branch */
        cam_settle(m, &d->mode, d->x, d->u, 0);
    }
    cam_drive_me_states(d, fired->x_after);
    for (k = 0; k < CAM_ME_NX; k++)
        if (fired->x_after[k] != fired->x_before[k])
            *values_changed = 1;
    d->stale = 1;
    e->target = next_breakpoint(d);
    n = indicators(d, e->target, z, codes);
    *needed = due(e, z, codes, n) >= 0;
    return CAM_OK;
}

/* The energy bound's books open at the first entry into continuous time (after the initial event
 * update), like the co-simulation's at its first step. */
void cam_exchange_enter_continuous(CamExchange *e)
{
    CamDrive *d = e->drive;
    e->requested = 0;
    e->iterations = 0;
    e->broke_away = 0;
    e->longest_gap = 0.0;
    e->evaluations = 0;
    e->last_time = e->step_time = d->time;
    cam_exchange_sync(e);
    if (!d->have_budget) {
        cam_energy_init(&d->budget, &d->model, cam_drive_outputs(d));
        d->have_budget = 1;
        e->book_time = d->time;
        e->book_u = d->u;
    }
}

/* Book the source's work from the last booking to now.
 * - L = 0: the circuit's charge is exact, (u h - c_e (theta_m - theta_m0)) / R over any trajectory of the angle,
 *   the input taken as the mean of its values at both ends (exact for an input held between the host's steps).
 * - L > 0: the trapezoid of the source's power u i at both ends. The circuit's charge would subtract L (i - i0),
 *   and a host's low-order step gets i - i0 wrong at the order of the step itself: explicit Euler's first step
 *   from rest would "create" all of its magnetic energy. The trapezoid errs at the step's square (measured in
 *   docs/fmu.md, Model Exchange), and an unstable host still shows: its oscillating current books little work
 *   while its stored energy grows. */
static void book(CamExchange *e, CamEnergy *budget, const double out[])
{
    const CamDrive *d = e->drive;
    double h = d->time - e->book_time;
    if (!d->model.has_current) {
        cam_energy_step(budget, 0.5 * (e->book_u + d->u), h, out[CAM_O_THETA_M], out[CAM_O_I]);
        return;
    }
    cam_energy_book(budget, 0.5 * h * (e->book_u * budget->i + d->u * out[CAM_O_I]), out[CAM_O_THETA_M], out[CAM_O_I]);
}

/* m: the amplitude of the train's free ringing, its end's motion y = x_e - s about the quasi-static deflection
 * y_qs = (F_ex / m_end - a) / w^2 that the follower's slow acceleration a holds it at (w^2 = k_train / m_end):
 * y - y_qs = -(y'' + (d_train / m_end) y') / w^2 with y' = v_e - v, y'' = a_e - a, and its rate y' / w. */
static double train_ringing(const CamModel *m, const double out[])
{
    double w2 = m->k_train / m->m_end, rate = out[CAM_O_V_END] - out[CAM_O_V];
    double offset = (out[CAM_O_A_END] - out[CAM_O_A] + m->d_train / m->m_end * rate) / w2;
    return sqrt(offset * offset + rate * rate / w2);
}

/* The host's integration of a ringing train (docs/model.md 14.7), judged from how it samples the drive, while the
 * train rings by more than CAM_EXCHANGE_TRAIN_RINGING of the lift (a quiet train may be stepped over: an adaptive
 * host's long first steps):
 * - a host that evaluates the derivatives once a step, at the step's start, is explicit Euler (it grows the
 *   ringing's amplitude by exp(w^2 h t / 2)): the drift w^2 h^2 / 2 summed over its steps past
 *   CAM_EXCHANGE_TRAIN_DRIFT (an adaptive host's one evaluation in an output interval is at its step's end);
 * - any other: its longest forward stretch between two settings of the time since the last completed step (its
 *   step, h / 2 for rk4's stages) past CAM_EXCHANGE_TRAIN_PHASE rad of the ringing (rk4 then errs by percents of
 *   the train's force; an adaptive host at a loose tolerance steps over the ringing, measured in docs/model.md 14.7).
 * Said once, as a warning: the host chose its method, and the FMU sees only its samples. */
static void check_train_sampling(CamExchange *e, const double out[])
{
    CamDrive *d = e->drive;
    const CamModel *m = &d->model;
    double w = m->train_rate, h = d->time - e->step_time, ringing = train_ringing(m, out);
    int explicit_euler = e->evaluations == 1 && e->evaluated_at == e->step_time;
    if (explicit_euler && h > 0.0)
        e->drift += 0.5 * w * w * h * h;
    if (!e->train_warned && ringing > CAM_EXCHANGE_TRAIN_RINGING * m->lift_scale
        && (explicit_euler ? e->drift > CAM_EXCHANGE_TRAIN_DRIFT : w * e->longest_gap > CAM_EXCHANGE_TRAIN_PHASE)) {
        e->train_warned = e->warning = 1;
        if (explicit_euler)
            cam_error(cam_instance_error(e->instance), CAM_OK, "the host evaluates the drive once a step, at "
                      "its start (explicit Euler), at %g s before t = %g s: it may have grown the follower train's "
                      "ringing (%s, %.4g 1/s, ringing by %.3g m, %.2g of the lift) by up to %.2g of its amplitude "
                      "so far (w^2 h t / 2) without a sign; explicit Euler keeps that below 0.01 over T seconds only "
                      "below 0.02 / (w^2 T) (%.3g s for 1 s): use a higher-order or adaptive solver (said once)", h,
                      d->time, cam_train_names(m), w, ringing, ringing / m->lift_scale, e->drift,
                      2.0 * CAM_EXCHANGE_TRAIN_DRIFT / (w * w));
        else
            cam_error(cam_instance_error(e->instance), CAM_OK, "the host sampled the drive %g s apart before "
                      "t = %g s, %.3g rad of the follower train's ringing (%s, %.4g 1/s), while it rings by %.3g m "
                      "(%.2g of the lift): its method aliases or damps the ringing there without a sign; use steps "
                      "below about %.3g s (rk4: %.3g s), or a tighter tolerance (said once)", e->longest_gap,
                      d->time, w * e->longest_gap, cam_train_names(m), w, ringing, ringing / m->lift_scale,
                      CAM_EXCHANGE_TRAIN_PHASE / w, 2.0 * CAM_EXCHANGE_TRAIN_PHASE / w);
    }
    e->longest_gap = 0.0;
    e->evaluations = 0;
    e->step_time = d->time;
}

int cam_exchange_completed_step(CamExchange *e, int *enter_event)
{
    CamDrive *d = e->drive;
    double z[CAM_EXCHANGE_NZ], excess, tolerance, out[CAM_N_OUTPUTS];
    int codes[CAM_MAX_EVENTS], n, k, verdict;
    *enter_event = 0;
    e->warning = 0;
    cam_exchange_sync(e);
    memcpy(out, cam_drive_outputs(d), sizeof out);
    verdict = cam_publishable(&d->model, out, NULL, d->u, 0.0);
    if (verdict == CAM_PUBLISH_NOT_FINITE) {
        for (k = 0; k < CAM_N_OUTPUTS && isfinite(out[k]); k++)
            ;
        return fail(e, CAM_ERR_SIMULATION, "output '%s' is not finite at t = %g s (theta = %g rad, omega = %g rad/s): "
                    "the host's step diverged; reduce its step size or tighten its tolerance",
                    cam_output_spec(k < CAM_N_OUTPUTS ? k : 0)->name, d->time, d->x[CAM_THETA], d->x[CAM_OMEGA]);
    }
    n = indicators(d, e->target, z, codes);
    k = below_zero(z, n);
    if (z[CAM_EXCHANGE_BREAKPOINT] < 0.0)   /* a host without root finding passed a breakpoint: the next */
        *enter_event = 1;                    /* event update sets the indicator to the one after it */
    if (k >= 0 || verdict == CAM_PUBLISH_CLEARANCE) {
        if (e->requested || k < 0) {
            if (verdict == CAM_PUBLISH_CLEARANCE)
                return fail(e, CAM_ERR_SIMULATION, "the follower is %.6g m from the cam at t = %g s, beyond the "
                            "clearance c = %g m: a contact event was not handled (the completed "
                            "integrator step asked for event mode and the host went on integrating)", fabs(out[CAM_O_S] - out[CAM_O_S_CAM]),
                            d->time, d->model.c);
            return fail(e, CAM_ERR_SIMULATION, "event '%s' is due since the last step before t = %g s and the host "
                        "went on integrating without event mode (the completed integrator step asked for it): the "
                        "drive's mode is wrong from there", cam_exchange_event_name(codes[k]), d->time);
        }
        e->requested = 1;   /* the event the host's solver stepped over: handled at the next event mode */
        *enter_event = 1;
    }
    if (d->have_budget) {
        book(e, &d->budget, out);
        e->book_time = d->time;
        e->book_u = d->u;
        cam_energy_excess(&d->budget, out, &excess, &tolerance);
        if (cam_energy_created(&d->budget, out))
            return fail(e, CAM_ERR_SIMULATION, "the state at t = %g s holds %.6g J more energy than the source "
                        "delivered (tolerance %.3g J): energy was created, the result cannot be trusted; reduce the "
                        "host's step size or tighten its tolerance", d->time, excess, tolerance);
    }
    if (d->model.train)
        check_train_sampling(e, out);
    return CAM_OK;
}

int cam_exchange_save(CamExchange *e, unsigned char *buffer, size_t size)
{
    CamDrive *d = e->drive;
    CamEnergy live;
    int status;
    if (d == NULL || !d->have_budget || d->time == e->book_time)
        return cam_instance_save(e->instance, buffer, size);
    live = d->budget;
    cam_exchange_sync(e);
    book(e, &d->budget, cam_drive_outputs(d));
    status = cam_instance_save(e->instance, buffer, size);
    d->budget = live;
    return status;
}
