/* A gcc stand-in for libFuzzer: runs LLVMFuzzerTestOneInput (cam_fmu/engine/csrc/fuzz/fuzz_table.c)
 * on every file named on the command line, then on N inputs from a fixed seed:
 *
 *   fuzz_driver [-n N] [-s SEED] [FILE...]
 *
 * The inputs mix random bytes with fragments of tables (numbers, separators, line ends, a BOM,
 * headers, comments), so that both the refusals and the curve are reached. The generator's state
 * is local (no globals). Prints "ok <inputs>" and returns 0; a broken promise aborts.
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static uint64_t next(uint64_t *state)
{
    *state = *state * 6364136223846793005ULL + 1442695040888963407ULL;
    return *state >> 33;
}

static size_t make_input(uint64_t *state, uint8_t *buf, size_t cap)
{
    static const char *const pieces[] = {"0", "1", "90", "180", "359.99", "360", "40", "0.5", "1e-3", "-1", "1e400",
                                         "nan", "inf", "-0", ".5", "5.", "1e", "+", "x", "O", "angle,lift", ",", ";",
                                         " ", "\t", "\n", "\r\n", "\r", "#c", "\xef\xbb\xbf", "\xc3\xa9", "\x80",
                                         "00000000000000000000000000000000000000000000000000", "9", "45", "270"};
    size_t n = 0, target = (size_t)(next(state) % cap);
    int mode = (int)(next(state) % 3);
    while (n < target) {
        if (mode == 0 || next(state) % 8 == 0) {
            buf[n++] = (uint8_t)next(state);
        } else {
            const char *p = pieces[next(state) % (sizeof pieces / sizeof pieces[0])];
            size_t len = strlen(p);
            if (n + len > cap) {
                break;
            }
            memcpy(buf + n, p, len);
            n += len;
        }
    }
    return n;
}

int main(int argc, char **argv)
{
    long count = 2000, k;
    uint64_t state = 1;
    size_t inputs = 0;
    int i;
    uint8_t *buf = malloc(4096);
    if (buf == NULL) {
        return 2;
    }
    for (i = 1; i < argc; i++) {
        if (strcmp(argv[i], "-n") == 0 && i + 1 < argc) {
            count = atol(argv[++i]);
        } else if (strcmp(argv[i], "-s") == 0 && i + 1 < argc) {
            state = (uint64_t)strtoull(argv[++i], NULL, 10);
        } else {
            FILE *f = fopen(argv[i], "rb");
            long size;
            uint8_t *data;
            if (f == NULL || fseek(f, 0, SEEK_END) != 0 || (size = ftell(f)) < 0 || fseek(f, 0, SEEK_SET) != 0) {
                fprintf(stderr, "cannot read %s\n", argv[i]);
                return 2;
            }
            data = malloc((size_t)size + 1);  /* exactly the file's bytes are passed: no NUL is read */
            if (data == NULL || fread(data, 1, (size_t)size, f) != (size_t)size) {
                return 2;
            }
            fclose(f);
            LLVMFuzzerTestOneInput(data, (size_t)size);
            free(data);
            inputs++;
        }
    }
    for (k = 0; k < count; k++) {
        size_t n = make_input(&state, buf, 4096);
        uint8_t *exact = malloc(n ? n : 1);  /* its own allocation: ASan sees a read past the end */
        if (exact == NULL) {
            return 2;
        }
        memcpy(exact, buf, n);
        LLVMFuzzerTestOneInput(exact, n);
        free(exact);
        inputs++;
    }
    free(buf);
    printf("ok %lu\n", (unsigned long)inputs);
    return 0;
}
