/* The drive's state as a flat, versioned array of doubles (the CAM_S_* slots of cam_drive.h), and its
 * restoration with every entry checked before use (DriveSimulator.get_state/set_state in engine/simulator.py). */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include "cam_drive.h"

/* The saved state's entries that are the drive's doubles as they stand (engine/contract.py STATE_LAYOUT): slot,
 * member, doubles; the energy account's comes last (restored only with an account). */
typedef struct {
    int slot, count;
    size_t offset;
} StateEntry;
#define ENTRY_OF(name, member) {CAM_S_##name, CAM_S_##name##_N, offsetof(CamDrive, member)}
static const StateEntry PLAIN[] = {
    ENTRY_OF(TIME, time), ENTRY_OF(U, u), ENTRY_OF(OMEGA_REF, omega_ref), ENTRY_OF(OMEGA_DOT_REF, omega_dot_ref),
    ENTRY_OF(H_NEXT, solver.h_next), ENTRY_OF(X, x), ENTRY_OF(FORM_U, form_u), ENTRY_OF(PAPER, paper),
    ENTRY_OF(SPEED, speed), {CAM_S_WORK_IN, CAM_S_E_MAG0 + 1 - CAM_S_WORK_IN, offsetof(CamDrive, budget.work_in)}};
#define N_PLAIN ((int)(sizeof PLAIN / sizeof PLAIN[0]))
/* the members the layout copies as runs of doubles are such runs (a compile error otherwise) */
typedef char layout_matches_drive[(sizeof(CamPaperState) == CAM_S_PAPER_N * sizeof(double)
                                   && sizeof(CamSpeedState) == CAM_S_SPEED_N * sizeof(double)
                                   && sizeof(((CamDrive *)0)->x) == CAM_S_X_N * sizeof(double)
                                   && offsetof(CamEnergy, e_mag0) - offsetof(CamEnergy, work_in)
                                          == (CAM_S_E_MAG0 - CAM_S_WORK_IN) * sizeof(double)) ? 1 : -1];

/* Copy entries [first, last) of PLAIN from the drive into the saved state (into_state), or back. */
static void copy_plain(const void *from, void *to, int first, int last, int into_state)
{
    int k;
    for (k = first; k < last; k++) {
        size_t drive_at = PLAIN[k].offset, state_at = (size_t)PLAIN[k].slot * sizeof(double);
        memcpy((char *)to + (into_state ? state_at : drive_at),
               (const char *)from + (into_state ? drive_at : state_at), (size_t)PLAIN[k].count * sizeof(double));
    }
}

void cam_drive_get_state(const CamDrive *d, double s[CAM_STATE_LEN])
{
    memset(s, 0, sizeof(double) * CAM_STATE_LEN);
    s[CAM_S_VERSION] = CAM_STATE_VERSION;
    s[CAM_S_FORMULATION] = (double)d->model.formulation;
    s[CAM_S_STEPS_TAKEN] = (double)d->steps_taken;
    copy_plain(d, s, 0, N_PLAIN, 1);
    s[CAM_S_STUCK] = d->mode.stuck ? 1.0 : 0.0;
    s[CAM_S_DIRECTION] = d->mode.direction;
    s[CAM_S_CONTACT] = (double)d->mode.contact;
    s[CAM_S_S_FREE] = d->mode.s_free;
    s[CAM_S_SIDE] = d->mode.side;
    s[CAM_S_LEFT] = (double)d->mode.left;
    s[CAM_S_SIGMA] = d->mode.sigma;
    s[CAM_S_HAVE_BUDGET] = d->have_budget ? 1.0 : 0.0;
}

static const char *const ENTRY[] = {"version", "formulation", "time", "u", "omega_ref", "omega_dot_ref", "h_next",
                                    "steps_taken"};

/* The entries into the drive, unchecked (cam_drive_set_state checks first). */
static void apply_state(CamDrive *d, const double s[CAM_STATE_LEN], const CamMode *mode)
{
    d->stale = 1;
    copy_plain(s, d, 0, N_PLAIN - 1, 0);
    d->solver.k1_valid = 0;
    d->steps_taken = (long)s[CAM_S_STEPS_TAKEN];
    d->mode = *mode;
    d->have_budget = s[CAM_S_HAVE_BUDGET] != 0.0;
    if (d->have_budget) {
        const double *out = cam_drive_outputs(d);
        cam_energy_init(&d->budget, &d->model, out);
        copy_plain(s, d, N_PLAIN - 1, N_PLAIN, 0);
    }
}

/* The entries against each other and against the drive's parameters (docs/fmu.md, saved states): each rule
 * that fails is named. A state that passes every entry's own check can still be none the drive can be in. */
static int consistent_entries(const CamDrive *d, const double s[CAM_STATE_LEN], const CamMode *mode, CamError *err)
{
    const CamModel *m = &d->model;
    const double *x = s + CAM_S_X;
    char a[40], b[40];
    if (s[CAM_S_TIME] < d->start_time - CAM_TIME_SLACK(d->start_time))
        return cam_error(err, CAM_ERR_SIMULATION, "state time %s s is before the drive's start time %s s",
                         cam_num(s[CAM_S_TIME], a), cam_num(d->start_time, b));
    if (!m->has_current && x[CAM_CURRENT] != 0.0)
        return cam_error(err, CAM_ERR_SIMULATION, "state current i = %s A, but this drive has no inductance "
                         "(L = 0: the current is no state, its slot holds 0)", cam_num(x[CAM_CURRENT], a));
    if (!m->compliant && (x[CAM_TWIST] != 0.0 || x[CAM_OMEGA_M] != 0.0))
        return cam_error(err, CAM_ERR_SIMULATION, "state twist %s rad and rotor speed %s rad/s, but this drive's "
                         "shaft is rigid (k_shaft = 0: their slots hold 0)", cam_num(x[CAM_TWIST], a),
                         cam_num(x[CAM_OMEGA_M], b));
    if (!m->train && (x[CAM_X_END] != 0.0 || x[CAM_V_END] != 0.0))
        return cam_error(err, CAM_ERR_SIMULATION, "state end mass position %s m and velocity %s m/s, but this drive "
                         "has no follower train (k_train = 0: their slots hold 0)", cam_num(x[CAM_X_END], a),
                         cam_num(x[CAM_V_END], b));
    if (s[CAM_S_HAVE_BUDGET] != 0.0 && !d->form->energy_bounded)
        return cam_error(err, CAM_ERR_SIMULATION, "state has an energy account, but the %s drive keeps none",
                         d->form->name);
    if (m->free_follower) {
        CamSpeedState saved;   /* the entry as the drive's struct (a run of doubles: checked above) */
        double contact = m->follower_states ? (double)mode->contact : 0.0, sigma = mode->sigma;
        int left = mode->left;
        memcpy(&saved, s + CAM_S_SPEED, sizeof saved);
        if (!m->follower_states)
            contact = saved.contact;
        if (!(contact == 0.0 || contact == 1.0 || (contact == -1.0 && m->closure == CAM_CHOICE_CLOSURE_FORM)))
            return cam_error(err, CAM_ERR_SIMULATION, "state follower contact %s: allowed +1 (on the flank), 0 (in "
                             "flight)%s", cam_num(contact, a), m->closure == CAM_CHOICE_CLOSURE_FORM
                             ? " or -1 (on the groove's other flank)" : "");
        if (m->follower_states && left != 1 && left != (m->closure == CAM_CHOICE_CLOSURE_FORM ? -1 : 1))
            return cam_error(err, CAM_ERR_SIMULATION, "state follower flank left last %d: allowed +1%s", left,
                             m->closure == CAM_CHOICE_CLOSURE_FORM ? " or -1" : "");
        if (m->follower_states && !(sigma == 0.0 || fabs(sigma) == 1.0))
            return cam_error(err, CAM_ERR_SIMULATION, "state follower direction in flight %s: allowed -1, 0, +1",
                             cam_num(sigma, a));
        if (m->follower_states && contact == 0.0
            && (x[CAM_GAP] < -1e-9 || (m->closure == CAM_CHOICE_CLOSURE_FORM
                                         && x[CAM_GAP] > 2.0 * m->c * (1.0 + 1e-9) + 1e-9)))
            return cam_error(err, CAM_ERR_SIMULATION, "state follower gap %s m from the flank it left is beyond the "
                             "clearance c = %g m (the gap lies in [0, 2 c] in a groove, >= 0 on a spring's flank)",
                             cam_num(x[CAM_GAP], a), m->c);
        if (m->follower_states && contact != 0.0 && (x[CAM_GAP] != 0.0 || x[CAM_RATE] != 0.0))
            return cam_error(err, CAM_ERR_SIMULATION, "state follower gap %s m and rate %s m/s on flank %+g: on a "
                             "flank both are 0", cam_num(x[CAM_GAP], a), cam_num(x[CAM_RATE], b), contact);
    } else if (x[CAM_GAP] != 0.0 || x[CAM_RATE] != 0.0) {
        return cam_error(err, CAM_ERR_SIMULATION, "state follower gap %s m and rate %s m/s, but this drive's follower "
                         "moves with the cam (their slots hold 0)", cam_num(x[CAM_GAP], a),
                         cam_num(x[CAM_RATE], b));
    }
    if (m->formulation != CAM_FORM_CONSISTENT)
        return CAM_OK;   /* the mode is the consistent formulation's (the others keep cam_initial's) */
    if (mode->stuck && x[CAM_OMEGA] != 0.0)
        return cam_error(err, CAM_ERR_SIMULATION, "state mode 'stuck' (held by static friction) with omega = %s "
                         "rad/s: a held shaft has omega = 0", cam_num(x[CAM_OMEGA], a));
    if (!mode->stuck && mode->direction * x[CAM_OMEGA] < 0.0)
        return cam_error(err, CAM_ERR_SIMULATION, "state direction %+g with omega = %s rad/s: a moving shaft's "
                         "direction is the sign of omega", mode->direction, cam_num(x[CAM_OMEGA], a));
    if (m->follower_states)
        return CAM_OK;   /* its contact is the follower's (above) */
    if (!m->backlash && mode->contact != 1)
        return cam_error(err, CAM_ERR_SIMULATION, "state contact %d, but this drive has no backlash (c = 0: the "
                         "follower is always engaged, contact +1)", mode->contact);
    if (mode->contact == 0) {
        double dd[4];
        cam_profile_eval(&m->profile, x[CAM_THETA], dd);
        if (fabs(mode->s_free - dd[0]) > m->c * (1.0 + 1e-9) + 1e-12)
            return cam_error(err, CAM_ERR_SIMULATION, "state follower position s_free = %s m is %.6g m from the "
                             "cam at theta = %g rad, beyond the clearance c = %g m", cam_num(mode->s_free, a),
                             fabs(mode->s_free - dd[0]), x[CAM_THETA], m->c);
    }
    return CAM_OK;
}

/* The restored state as the guards of a step would see it: finite outputs, the follower within the clearance,
 * no energy created (a copy of the account books nothing more: h = 0). */
static int publishable_state(CamDrive *d, CamError *err)
{
    const double *out = cam_drive_outputs(d);
    CamEnergy books = d->budget;
    char shown[40];
    int k, verdict = cam_publishable(&d->model, out, d->have_budget ? &books : NULL, d->u, 0.0);
    if (verdict == CAM_PUBLISH_NOT_FINITE) {
        for (k = 0; k < CAM_N_OUTPUTS - 1 && isfinite(out[k]); k++)
            ;
        return cam_error(err, CAM_ERR_SIMULATION, "the state's output '%s' = %s: the state is none the drive can "
                         "reach (its entries are too large)", cam_output_spec(k)->name, cam_num(out[k], shown));
    }
    if (verdict == CAM_PUBLISH_CLEARANCE)
        return cam_error(err, CAM_ERR_SIMULATION, "the state's follower is %.6g m from the cam, beyond the "
                         "clearance c = %g m", fabs(out[CAM_O_S] - out[CAM_O_S_CAM]), d->model.c);
    if (verdict == CAM_PUBLISH_ENERGY) {
        double excess, tolerance;
        cam_energy_excess(&books, out, &excess, &tolerance);
        return cam_error(err, CAM_ERR_SIMULATION, "the state holds %.6g J more energy than its account says the "
                         "source delivered (tolerance %.3g J): its entries disagree", excess, tolerance);
    }
    return CAM_OK;
}

int cam_drive_set_state(CamDrive *d, const double s[CAM_STATE_LEN], CamError *err)
{
    char shown[40];
    int k, status;
    CamMode mode, mode_before;
    double before[CAM_STATE_LEN], values[CAM_N_OUTPUTS];
    int stale;
    if (s[CAM_S_VERSION] != CAM_STATE_VERSION)
        return cam_error(err, CAM_ERR_SIMULATION, "state version %s: this engine reads version %g",
                        cam_num(s[CAM_S_VERSION], shown), CAM_STATE_VERSION);
    if (s[CAM_S_FORMULATION] != (double)d->model.formulation)
        return cam_error(err, CAM_ERR_SIMULATION, "state of formulation %s, this drive's is %d",
                        cam_num(s[CAM_S_FORMULATION], shown), (int)d->model.formulation);
    for (k = CAM_S_TIME; k <= CAM_S_H_NEXT; k++)
        if (!isfinite(s[k]))
            return cam_error(err, CAM_ERR_SIMULATION, "state entry '%s' = %s is not finite", ENTRY[k],
                            cam_num(s[k], shown));
    if (!(s[CAM_S_STEPS_TAKEN] >= 0.0 && s[CAM_S_STEPS_TAKEN] <= 9.0e15))
        return cam_error(err, CAM_ERR_SIMULATION, "state entry 'steps_taken' = %s is not a count",
                        cam_num(s[CAM_S_STEPS_TAKEN], shown));
    for (k = CAM_S_X; k < CAM_S_END; k++)
        if (!isfinite(s[k]))
            return cam_error(err, CAM_ERR_SIMULATION, "state entry %d = %s is not finite", k,
                            cam_num(s[k], shown));
    mode.stuck = s[CAM_S_STUCK] != 0.0;
    mode.direction = s[CAM_S_DIRECTION];
    mode.contact = s[CAM_S_CONTACT] == 1.0 ? CAM_ON_LOWER_FLANK
                   : (s[CAM_S_CONTACT] == -1.0 ? CAM_ON_UPPER_FLANK : CAM_IN_FLIGHT);   /* checked below */
    mode.s_free = s[CAM_S_S_FREE];
    mode.side = s[CAM_S_SIDE];
    mode.left = s[CAM_S_LEFT] == -1.0 ? CAM_ON_UPPER_FLANK : CAM_ON_LOWER_FLANK;   /* checked below */
    mode.sigma = s[CAM_S_SIGMA];
    if ((s[CAM_S_STUCK] != 0.0 && s[CAM_S_STUCK] != 1.0) || (mode.direction != 1.0 && mode.direction != -1.0)
        || (mode.side != 1.0 && mode.side != -1.0 && !(d->model.follower_states && mode.side == 0.0))
        || (double)mode.left != s[CAM_S_LEFT] || (double)mode.contact != s[CAM_S_CONTACT]
        || (s[CAM_S_HAVE_BUDGET] != 0.0 && s[CAM_S_HAVE_BUDGET] != 1.0))
        return cam_error(err, CAM_ERR_SIMULATION, "state mode (stuck %g, direction %g, contact %g, side %g) is not a "
                        "valid mode", s[CAM_S_STUCK], s[CAM_S_DIRECTION], s[CAM_S_CONTACT], s[CAM_S_SIDE]);
    if ((status = consistent_entries(d, s, &mode, err)) != CAM_OK)
        return status;
    /* the drive as it is, to put back if the restored state fails the guards of a published one */
    cam_drive_get_state(d, before);
    mode_before = d->mode;
    memcpy(values, d->values, sizeof values);
    stale = d->stale;
    apply_state(d, s, &mode);
    if ((status = publishable_state(d, err)) != CAM_OK) {
        apply_state(d, before, &mode_before);
        memcpy(d->values, values, sizeof values);
        d->stale = stale;
        return status;
    }
    return CAM_OK;
}
