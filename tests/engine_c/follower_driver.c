/* The follower as a body of its own (cam_fmu/engine/csrc/src/follower.c) under AddressSanitizer and UBSan:
 * spring-closed and groove drives at imposed speed with bounces, a spring-closed and a groove cam in the voltage
 * drive (voltage_follower.c), the latter with guide friction and a compliant shaft, a saved state taken in flight and
 * restored, and the refusals of contradicting parameters.
 *
 *   follower_driver
 *
 * Prints one line per case, "<case> <impact-free checksum> <s at the end>", and "ok" at the end; a broken
 * promise (a state in flight that does not repeat its run bit for bit, a refusal without a message) aborts. From rest
 * (omega0 = 0): a spring-closed cam that stalls and sticks, a state saved while stuck; a cam that stops under the
 * flying follower.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cam_instance.h"

static unsigned vr_of(const char *wanted)
{
    unsigned vr;
    CamKind kind;
    const char *name;
    for (vr = 0; cam_instance_variable(vr, &kind, &name); vr++)
        if (!strcmp(name, wanted))
            return vr;
    abort();
}

static void set_string(CamInstance *d, const char *name, const char *value)
{
    if (cam_instance_set_string(d, vr_of(name), value, strlen(value)) != CAM_OK) abort();
}

static void set_real(CamInstance *d, const char *name, double value)
{
    if (cam_instance_set_real(d, vr_of(name), value) != CAM_OK) abort();
}

static CamInstance *drive(const char *closure, double e, double omega, int shaft)
{
    CamInstance *d = cam_instance_new();
    int voltage = omega < 0.0;   /* the voltage drive at u = -omega V from 60 rad/s on a flywheel */
    if (!d) abort();
    set_string(d, "drive", voltage ? "voltage" : "speed");
    set_string(d, "closure", closure);
    if (voltage) {
        set_real(d, "mu", shaft ? 0.05 : 0.0);   /* shaft: guide friction and a compliant shaft */
        if (shaft) {
            set_real(d, "k_shaft", 100.0);
            set_real(d, "d_shaft", 0.01);
        }
        set_real(d, "omega0", strcmp(closure, "form") ? 60.0 : 10.0);
        set_real(d, "J_cam", 0.05);
        set_real(d, "gamma", 3.141592653589793);
        set_real(d, "u", -omega);
        omega = 0.0;
    }
    set_real(d, "restitution", e);
    if (!strcmp(closure, "spring")) {
        set_real(d, "k_spring", 800.0);
        set_real(d, "F_spring0", 20.0);
    } else
        set_real(d, "c", 5e-4);
    set_real(d, "omega_ref", omega);
    if (cam_instance_initialize(d, 0.0) != CAM_OK) abort();
    return d;
}

/* Steps of 1e-4 s from step k0 to k1; the sum of s over them. */
static double run(CamInstance *d, int k0, int k1)
{
    double sum = 0.0;
    int k;
    unsigned vr_s = vr_of("s");
    for (k = k0; k < k1; k++) {
        double s;
        if (cam_instance_step(d, k * 1e-4, 1e-4) != CAM_OK) {
            fprintf(stderr, "step refused: %s\n", cam_instance_message(d));
            abort();
        }
        if (cam_instance_get_real(d, vr_s, &s) != CAM_OK) abort();
        sum += s;
    }
    return sum;
}

/* A state saved at step k repeats the n steps after it bit for bit (else abort): their sum of s. */
static double repeats(CamInstance *d, int k, int n)
{
    size_t size = cam_instance_state_size(d);
    unsigned char *saved = malloc(size);
    double first, again;
    if (!saved || cam_instance_save(d, saved, size) != CAM_OK) abort();
    first = run(d, k, k + n);
    if (cam_instance_restore(d, saved, size) != CAM_OK) abort();
    again = run(d, k, k + n);
    if (first != again) abort();
    free(saved);
    return first;
}

int main(void)
{
    static const char *closures[] = {"spring", "spring", "form", "spring", "form", "spring"};
    static const double es[] = {0.5, 1.0, 0.0, 0.5, 0.5, 0.5}, omegas[] = {60.0, 90.0, 10.0, -11.0, -1.6, -11.0};
    int c;
    for (c = 0; c < 6; c++) {
        CamInstance *d = drive(closures[c], es[c], omegas[c], c == 5);
        unsigned vr_s = vr_of("s"), vr_s_cam = vr_of("s_cam");
        double s, s_cam, first;
        int k = 0;
        /* to the first step in flight */
        do {
            run(d, k, k + 1);
            k++;
            if (cam_instance_get_real(d, vr_s, &s) != CAM_OK || cam_instance_get_real(d, vr_s_cam, &s_cam) != CAM_OK)
                abort();
        } while ((!strcmp(closures[c], "form") ? fabs(fabs(s - s_cam) - 5e-4) : s - s_cam) < 1e-6 && k < 20000);
        if (k >= 20000) abort();
        first = repeats(d, k, 2000);   /* a state saved in flight repeats its run bit for bit */
        if (cam_instance_get_real(d, vr_s, &s) != CAM_OK) abort();
        printf("%s %.17g %.17g\n", closures[c], first, s);
        cam_instance_free(d);
    }
    {   /* the voltage drive from rest (omega0 = 0): a spring too strong for the motor stalls the cam on the rise, it
         * swings back and sticks; a state saved while stuck repeats its run bit for bit */
        CamInstance *d = cam_instance_new();
        unsigned vr_omega = vr_of("omega");
        double omega = 1.0;
        int k = 0;
        if (!d) abort();
        set_string(d, "closure", "spring");
        set_real(d, "k_spring", 500.0);
        set_real(d, "F_spring0", 5.0);
        set_real(d, "u", 3.5);
        if (cam_instance_initialize(d, 0.0) != CAM_OK) abort();
        while (k < 1000 || omega != 0.0) {   /* past the start, to a step that ends stuck */
            run(d, k, k + 1);
            k++;
            if (cam_instance_get_real(d, vr_omega, &omega) != CAM_OK || k > 20000) abort();
        }
        printf("stuck %d %.17g\n", k, repeats(d, k, 2000));
        cam_instance_free(d);
    }
    {   /* a vertical groove coasting at u = 0 against a large shaft friction: the cam stops under the flying
         * follower (stuck), which lands on it and turns it back; a state saved there repeats its run */
        CamInstance *d = cam_instance_new();
        if (!d) abort();
        set_string(d, "closure", "form");
        set_real(d, "c", 5e-4);
        set_real(d, "restitution", 0.5);
        set_real(d, "gamma", 1.5707963267948966);
        set_real(d, "beta", 3.141592653589793);
        set_real(d, "omega0", 8.0);
        set_real(d, "theta0", 0.5);
        set_real(d, "M_f", 0.3);
        set_real(d, "u", 0.0);
        if (cam_instance_initialize(d, 0.0) != CAM_OK) abort();
        run(d, 0, 200);   /* 17-31 ms: the cam stuck, the follower flying */
        printf("stopped %.17g\n", repeats(d, 200, 900));
        cam_instance_free(d);
    }
    printf("ok\n");
    return 0;
}
