/* libFuzzer entry for the saved-state parser of the FMI instance layer (not part of any library).
 *
 * Any bytes are a saved state offered to cam_instance_restore (what fmi2SetFMUstate and
 * fmi2DeSerializeFMUstate hand it): it must refuse them with a message and leave the instance as
 * it was, or restore a state from which a step either succeeds with finite outputs or is refused
 * with a message. A broken promise aborts, which libFuzzer (or tests/engine_c/state_driver.c under
 * ASan/UBSan) reports as a crash. Commands: docs/architecture.md, "Fuzzing the parsers of untrusted bytes".
 */
#include "cam_instance.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    CamInstance *d = cam_instance_new();
    double before = 0.0, after = 0.0;
    const double *out;
    int k;
    if (!d)
        abort();
    if (cam_instance_initialize(d, 0.0) != CAM_OK || cam_instance_step(d, 0.0, 1e-3) != CAM_OK)
        abort();  /* the default drive runs */
    before = cam_instance_time(d);
    if (cam_instance_restore(d, data, size) != CAM_OK) {
        if (cam_instance_message(d)[0] == '\0')
            abort();  /* every refusal says why */
        after = cam_instance_time(d);
        if (after != before)
            abort();  /* a refused state changes nothing */
        cam_instance_free(d);
        return 0;
    }
    if (cam_instance_initialized(d)) {
        double t = cam_instance_time(d);
        if (cam_instance_step(d, t, 1e-4) == CAM_OK) {
            out = cam_instance_outputs(d);
            for (k = 0; k < CAM_N_OUTPUTS; k++)
                if (!isfinite(out[k]))
                    abort();  /* a step that succeeds publishes finite outputs */
        } else if (cam_instance_message(d)[0] == '\0') {
            abort();
        }
    }
    cam_instance_free(d);
    return 0;
}
