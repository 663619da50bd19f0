/* The engine's one error path (cam_error.h). */
#include <stdarg.h>
#include <stdio.h>

#include "cam_error.h"

int cam_verror(CamError *err, CamStatus status, const char *fmt, va_list args)
{
    if (err != NULL) {
        err->status = status;
        vsnprintf(err->message, sizeof err->message, fmt, args);
    }
    return (int)status;
}

int cam_error(CamError *err, CamStatus status, const char *fmt, ...)
{
    va_list args;
    va_start(args, fmt);
    cam_verror(err, status, fmt, args);
    va_end(args);
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
