/* libFuzzer entry for the motion table parser (not part of the engine library).
 *
 * Any bytes are a motion_table string: the parser must refuse them with a message or build a
 * table whose curve stays within its rows' lifts. A violated promise aborts, which the fuzzer
 * (or tests/engine_c/fuzz_driver.c under ASan/UBSan) reports as a crash. Commands: docs/architecture.md,
 * "Fuzzing the parsers of untrusted bytes".
 */
#include "cam_profile.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    CamProfile p;
    CamError err;
    static const double probes[] = {0.0, 1e-9, 0.5, 1.0, 3.0, 6.283185307179586, -2.0, 1e6, -1e300};
    size_t k;
    err.message[0] = '\0';
    if (cam_profile_init_table(&p, (const char *)data, size, &err) != CAM_OK) {
        if (err.message[0] == '\0' || err.status == CAM_OK) {
            abort();  /* every refusal says why */
        }
        cam_profile_free(&p);
        return 0;
    }
    {
        const CamTable *t = &p.table;
        double lo = t->lift[0], hi = t->lift[0];
        if (t->n < 2 || p.n_points != t->n) {
            abort();
        }
        for (k = 0; k < t->n; k++) {
            if (!(t->angle[k] >= 0.0 && t->angle[k] < 6.283185307179586) || (k && !(t->angle[k] > t->angle[k - 1]))) {
                abort();
            }
            lo = fmin(lo, t->lift[k]);
            hi = fmax(hi, t->lift[k]);
        }
        for (k = 0; k < sizeof probes / sizeof probes[0]; k++) {
            double d[4];
            cam_profile_eval(&p, probes[k], d);
            if (!(d[0] >= lo && d[0] <= hi) || !isfinite(d[1]) || !isfinite(d[2]) || !isfinite(d[3])) {
                abort();
            }
            (void)cam_profile_first_breakpoint(&p, probes[k], probes[k] + 1.0);
            (void)cam_profile_first_breakpoint(&p, probes[k], probes[k] - 7.0);
        }
        for (k = 0; k < t->n; k++) {
            double d[4];
            cam_profile_eval(&p, t->angle[k], d);
            if (d[0] != t->lift[k]) {
                abort();  /* the rows are reproduced exactly */
            }
        }
    }
    cam_profile_free(&p);
    cam_profile_free(&p);  /* safe twice */
    return 0;
}
