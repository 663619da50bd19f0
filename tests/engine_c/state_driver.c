/* A gcc stand-in for libFuzzer on saved states: runs LLVMFuzzerTestOneInput
 * (cam_fmu/engine/csrc/fuzz/fuzz_state.c) on mutations of real saved states.
 *
 *   state_driver [-n N] [-s SEED]
 *
 * Seeds: the states of three drives (the default, backlash, a motion table) after a few steps.
 * Mutations: bit flips, random bytes, a double overwritten with a special value (0, -1, NaN,
 * inf, 1e308, a huge count), truncation and extension. The generator's state is local (no
 * globals). Prints "ok <inputs>" and returns 0; a broken promise aborts.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cam_instance.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static uint64_t next(uint64_t *state)
{
    *state = *state * 6364136223846793005ULL + 1442695040888963407ULL;
    return *state >> 33;
}

static unsigned char *seed_state(int which, size_t *size)
{
    CamInstance *d = cam_instance_new();
    unsigned char *blob;
    int k;
    static const char table[] = "angle_deg,lift_mm\n0,0\n90,40\n180,0\n";
    unsigned vr_c = 0, vr_table = 0, vr;
    CamKind kind;
    const char *name;
    for (vr = 0; cam_instance_variable(vr, &kind, &name); vr++) {
        if (!strcmp(name, "c")) vr_c = vr;
        if (!strcmp(name, "motion_table")) vr_table = vr;
    }
    if (which == 1 && cam_instance_set_real(d, vr_c, 0.002) != CAM_OK) abort();
    if (which == 2 && cam_instance_set_string(d, vr_table, table, strlen(table)) != CAM_OK) abort();
    if (cam_instance_initialize(d, 0.0) != CAM_OK) abort();
    for (k = 0; k < 50; k++)
        if (cam_instance_step(d, k * 1e-3, 1e-3) != CAM_OK) abort();
    *size = cam_instance_state_size(d);
    blob = malloc(*size + 64);
    if (!blob || cam_instance_save(d, blob, *size) != CAM_OK) abort();
    cam_instance_free(d);
    return blob;
}

int main(int argc, char **argv)
{
    long count = 2000, k;
    uint64_t state = 1;
    size_t sizes[3];
    unsigned char *seeds[3], *buf;
    static const double specials[] = {0.0, -1.0, 1.0, 2.0, -0.0, 1e308, -1e308, 1e-308, 4e9, 1e19};
    int a;
    for (a = 1; a + 1 < argc; a += 2) {
        if (!strcmp(argv[a], "-n")) count = atol(argv[a + 1]);
        else if (!strcmp(argv[a], "-s")) state = (uint64_t)atoll(argv[a + 1]);
    }
    for (a = 0; a < 3; a++)
        seeds[a] = seed_state(a, &sizes[a]);
    buf = malloc(sizes[2] + sizes[1] + sizes[0] + 128);
    if (!buf) abort();
    for (a = 0; a < 3; a++)  /* the seeds themselves restore */
        LLVMFuzzerTestOneInput(seeds[a], sizes[a]);
    for (k = 0; k < count; k++) {
        int which = (int)(next(&state) % 3), mode = (int)(next(&state) % 5), edits = 1 + (int)(next(&state) % 4), e;
        size_t size = sizes[which];
        memcpy(buf, seeds[which], size);
        for (e = 0; e < edits; e++) {
            size_t at = size ? (size_t)(next(&state) % size) : 0;
            if (mode == 0 && size) {
                buf[at] ^= (unsigned char)(1u << (next(&state) % 8));
            } else if (mode == 1 && size) {
                buf[at] = (unsigned char)next(&state);
            } else if (mode == 2 && size >= 8) {
                double v = next(&state) % 3 == 0 ? NAN : next(&state) % 3 == 0 ? INFINITY
                           : specials[next(&state) % (sizeof specials / sizeof specials[0])];
                size_t slot = (at / 8) * 8;
                if (slot + 8 <= size) memcpy(buf + slot, &v, 8);
            } else if (mode == 3) {
                size = (size_t)(next(&state) % (size + 1));
            } else {
                size_t extra = (size_t)(next(&state) % 64);
                memset(buf + size, (int)(next(&state) & 0xff), extra);
                size += extra;
            }
        }
        LLVMFuzzerTestOneInput(buf, size);
    }
    for (a = 0; a < 3; a++) free(seeds[a]);
    free(buf);
    printf("ok %ld\n", count);
    return 0;
}
