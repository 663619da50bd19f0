/* A C host for the engine (no Python): runs scenes, state round trips and error paths, and prints
 * one line per case, "name status theta omega steps" with the numbers as %a (exact bits), so that a
 * test can compare a sanitizer or valgrind build with the Python binding's results.
 *
 *     scene_host            (built by tests/engine/test_engine_c_host.py against the engine library)
 */
#include <stdio.h>
#include <string.h>

#include "cam_drive.h"

static int set(CamParams *p, const char *name, double value, CamError *err)
{
    int index = cam_param_index(name);
    if (index < 0)
        return cam_params_unknown(name, err);
    return cam_params_set_real(p, index, value, err);
}

static int set_text(CamParams *p, const char *name, const char *text, CamError *err)
{
    return cam_params_set_string(p, cam_param_index(name), text, strlen(text), err);
}

/* n steps of h under u from a new drive; the state saved at n / 2 is restored into a second drive,
 * which must end with the same bits. */
static int scene(const char *name, CamParams *p, double u, double h, long n)
{
    CamDrive a, b;
    CamError err;
    double state[CAM_STATE_LEN];
    const double *out;
    long k;
    int status = cam_drive_init(&a, p, &err);
    if (status != CAM_OK) {
        printf("%s init %d %s\n", name, status, err.message);
        return status;
    }
    for (k = 0; k < n && status == CAM_OK; k++) {
        status = cam_drive_do_step(&a, k * h, h, u, 1.0, 0.0, &err);
        if (k == n / 2)
            cam_drive_get_state(&a, state);
    }
    out = cam_drive_outputs(&a);
    printf("%s %d %a %a %ld\n", name, status, out[CAM_O_THETA], out[CAM_O_OMEGA], a.steps_taken);
    if (status == CAM_OK && cam_drive_init(&b, p, &err) == CAM_OK) {
        if (cam_drive_set_state(&b, state, &err) == CAM_OK) {
            for (k = n / 2 + 1; k < n && status == CAM_OK; k++)
                status = cam_drive_do_step(&b, k * h, h, u, 1.0, 0.0, &err);
            printf("%s-resumed %d %s\n", name, status,
                   memcmp(cam_drive_outputs(&b), out, sizeof(double) * CAM_N_OUTPUTS) == 0 ? "same" : "DIFFERENT");
        }
        cam_drive_free(&b);
    }
    cam_drive_free(&a);
    return status;
}

int main(void)
{
    CamParams p;
    CamError err;
    CamDrive d;
    double bad[CAM_STATE_LEN];
    int status;

    cam_params_defaults(&p);
    scene("fig6", &p, 3.5, 1e-3, 2000);
    set(&p, "c", 5e-4, &err);
    scene("backlash", &p, 3.5, 1e-3, 2000);
    set(&p, "c", 0.0, &err);
    set(&p, "L", 1e-3, &err);
    scene("inductance", &p, 3.5, 1e-3, 2000);
    set(&p, "L", 0.0, &err);
    set(&p, "gamma", 1.5707963267948966, &err);
    set(&p, "beta", 0.0, &err);
    scene("tilted", &p, 3.5, 1e-3, 2000);
    cam_params_free(&p);

    cam_params_defaults(&p);   /* every formulation and solver, and the exponential pair of rk45 */
    set_text(&p, "formulation", "paper", &err);
    scene("paper", &p, 3.5, 1e-3, 2000);
    set_text(&p, "formulation", "consistent", &err);
    set_text(&p, "drive", "speed", &err);
    set(&p, "c", 5e-4, &err);
    set(&p, "gamma", 1.5707963267948966, &err);
    scene("speed", &p, 3.5, 1e-3, 2000);
    cam_params_free(&p);
    cam_params_defaults(&p);   /* the solvers on the paper's rule (a free follower takes its own steps) */
    set_text(&p, "closure", "kinematic", &err);
    set(&p, "c", 5e-4, &err);
    set_text(&p, "solver", "euler", &err);
    set(&p, "h_max", 1e-4, &err);
    scene("euler", &p, 3.5, 1e-3, 1000);
    set_text(&p, "solver", "rk4", &err);
    scene("rk4", &p, 3.5, 1e-3, 1000);
    set(&p, "L", 1e-3, &err);
    set_text(&p, "solver", "etdrk4", &err);
    scene("etdrk4", &p, 3.5, 1e-3, 1000);
    set_text(&p, "solver", "rk45", &err);
    set(&p, "h_max", 1e-3, &err);
    set(&p, "L", 1e-6, &err);
    scene("stiff-pole", &p, 3.5, 1e-2, 100);
    cam_params_free(&p);

    cam_params_defaults(&p);   /* a compliant shaft: the two-mass drive, with backlash and L; stick-slip */
    set(&p, "J_m", 3e-5, &err);
    set(&p, "J_cam", 1.41e-5, &err);
    set(&p, "k_shaft", 50.0, &err);
    set(&p, "d_shaft", 1e-3, &err);
    scene("compliant", &p, 3.5, 1e-3, 2000);
    set(&p, "c", 5e-4, &err);
    set(&p, "L", 1e-3, &err);
    scene("compliant-backlash", &p, 3.5, 1e-3, 1000);
    cam_params_free(&p);
    cam_params_defaults(&p);
    set(&p, "J_m", 3e-5, &err);
    set(&p, "J_cam", 1.41e-5, &err);
    set(&p, "k_shaft", 0.5, &err);
    set(&p, "M_f", 0.02, &err);
    set(&p, "follower_inertia", 0.0, &err);
    set(&p, "gravity", 0.0, &err);
    set(&p, "guide_friction", 0.0, &err);
    scene("stick-slip", &p, 2.9, 1e-3, 600);
    set(&p, "J_cam", 0.0, &err);
    status = cam_drive_init(&d, &p, &err);
    printf("no-J_cam %d %s\n", status, err.message);
    if (status == CAM_OK)
        cam_drive_free(&d);
    cam_params_free(&p);

    cam_params_defaults(&p);   /* a motion table: the parser and the table's curve */
    set_text(&p, "motion_table", "angle_deg,lift_mm\n0,0\n90,40\n180,60\n270,20\n360,0\n", &err);
    set(&p, "mu", 0.0, &err);
    scene("table", &p, 3.5, 1e-3, 500);
    set_text(&p, "motion_table", "angle_deg,lift_mm\n0,0\n90,x\n", &err);
    status = cam_drive_init(&d, &p, &err);
    printf("bad-table %d %s\n", status, err.message);
    if (status == CAM_OK)
        cam_drive_free(&d);
    cam_params_free(&p);

    cam_params_defaults(&p);   /* error paths */
    status = set(&p, "R", 0.0, &err);
    printf("bad-R %d %s\n", status, err.message);
    status = set(&p, "nonsense", 1.0, &err);
    printf("unknown %d %.60s\n", status, err.message);
    status = set_text(&p, "solver", "rk99", &err);
    printf("bad-solver %d %s\n", status, err.message);
    set(&p, "max_steps", 50.0, &err);
    set(&p, "L", 1e-3, &err);
    if (cam_drive_init(&d, &p, &err) == CAM_OK) {
        status = cam_drive_do_step(&d, 0.0, 1e-2, 3.5, 1.0, 0.0, &err);
        printf("max-steps %d %s\n", status, err.message);
        status = cam_drive_do_step(&d, 0.0, -1.0, 3.5, 1.0, 0.0, &err);
        printf("bad-step %d %s\n", status, err.message);
        status = cam_drive_do_step(&d, 0.0, 1e-3, 1e9, 1.0, 0.0, &err);
        printf("bad-input %d %s\n", status, err.message);
        cam_drive_get_state(&d, bad);
        bad[CAM_S_DIRECTION] = 0.5;
        status = cam_drive_set_state(&d, bad, &err);
        printf("bad-state %d %s\n", status, err.message);
        bad[CAM_S_DIRECTION] = 1.0;
        bad[CAM_S_CONTACT] = 1e300;   /* no conversion of an out-of-range double to int (UB) */
        status = cam_drive_set_state(&d, bad, &err);
        printf("bad-contact %d %s\n", status, err.message);
        bad[CAM_S_CONTACT] = 1.0;
        bad[CAM_S_X + 1] = 0.0 / 0.0 + bad[CAM_S_X + 1];
        status = cam_drive_set_state(&d, bad, &err);
        printf("bad-nan %d %s\n", status, err.message);
        cam_drive_free(&d);
    }
    cam_params_free(&p);
    return 0;
}
