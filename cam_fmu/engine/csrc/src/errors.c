/* Errors: a status and a message (numbers and user text quoted as cam_text.h writes them, so that
 * messages read text-for-text as the Python engine's). */
#include <stdarg.h>
#include <stdio.h>

#include "cam_model.h"

int cam_error(CamError *err, CamStatus status, const char *fmt, ...)
{
    va_list args;
    if (err != NULL) {
        err->status = status;
        va_start(args, fmt);
        vsnprintf(err->message, sizeof err->message, fmt, args);
        va_end(args);
    }
    return (int)status;
}

const char *cam_num(double value, char out[CAM_REPR_LEN])
{
    cam_repr(value, out);
    return out;
}

const char *cam_text(const char *text, size_t len, char *out, size_t out_len)
{
    cam_quote(text, len, out, out_len);
    return out;
}
