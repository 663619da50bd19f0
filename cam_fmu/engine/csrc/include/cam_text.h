/* Text helpers for the engine's messages (C99, libc only, no globals).
 *
 * Messages quote numbers as Python's repr() writes them and quote a user's text
 * cut to a readable length, so that the C engine and the Python model (and the
 * messages users saw before the engine was written in C) say the same thing.
 */
#ifndef CAM_TEXT_H
#define CAM_TEXT_H

#include <stddef.h>

#define CAM_REPR_LEN 32        /* enough for any double's repr and its NUL */
#define CAM_QUOTE_CHARS 40     /* characters of a user's text quoted in a message */

/* x as Python's repr(float) writes it ("0.1", "7.0", "1e+16", "-inf", "nan") into out.
 * The shortest digit string that reads back as x, independent of the C locale. */
void cam_repr(double x, char out[CAM_REPR_LEN]);

/* text[0..len-1] quoted for a message: 'text', at most CAM_QUOTE_CHARS characters
 * (UTF-8 code points) followed by "..." when longer; every character outside
 * printable ASCII is written as '?'. Truncated to out_len - 1 bytes, NUL-terminated. */
void cam_quote(const char *text, size_t len, char *out, size_t out_len);

#endif
