/* The engine's one error path: a status and a message, filled by cam_error (printf-style) where a check
 * refuses, passed down by pointer to every function that can fail, and read by whoever reports it (the
 * Python binding raises it, the FMI glue logs it through the host's logger).
 *
 * Messages name the parameter, input or setting and what to change, with numbers and a user's text quoted
 * as cam_text.h writes them, so that they read text-for-text as the Python model's (physics/, kinematics/).
 * C99, no globals.
 */
#ifndef CAM_ERROR_H
#define CAM_ERROR_H

#include <stdarg.h>
#include <stddef.h>

#include "cam_text.h"

#include "cam_contract.h"   /* generated: CamStatus (CAM_OK, CAM_ERR_*), CAM_MESSAGE_LEN, CamError */

/* Set err (status and printf-style message; nothing when err is NULL) and return the status. */
int cam_error(CamError *err, CamStatus status, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
/* cam_error with the arguments as a va_list, for a layer's own printf-style refusal function. */
int cam_verror(CamError *err, CamStatus status, const char *fmt, va_list args);

/* Python's repr() of a float into out (cam_text.h's cam_repr), returned for use in a message. */
const char *cam_num(double value, char out[CAM_REPR_LEN]);
/* A user's text quoted for a message (cam_text.h's cam_quote), returned for use in a message. */
const char *cam_text(const char *text, size_t len, char *out, size_t out_len);

#endif
