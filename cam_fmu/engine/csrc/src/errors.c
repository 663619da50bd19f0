/* Errors: a status and a message, and Python's repr() of numbers and strings for messages
 * that must read text-for-text as the Python engine's. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cam_model.h"

int cam_fail(CamError *err, CamStatus status, const char *fmt, ...)
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

/* The shortest decimal digits that read back as value (value finite, > 0): into digits, with the
 * decimal point's position decpt (value = 0.d1d2... x 10^decpt). */
static void shortest_digits(double value, char digits[32], int *decpt)
{
    char buf[40];
    int prec, n = 0;
    for (prec = 1; prec <= 17; prec++) {
        snprintf(buf, sizeof buf, "%.*e", prec - 1, value);
        if (strtod(buf, NULL) == value)
            break;
    }
    {
        const char *p = buf;
        char *e = strchr(buf, 'e');
        for (; p < e; p++)
            if (*p >= '0' && *p <= '9')
                digits[n++] = *p;
        while (n > 1 && digits[n - 1] == '0')
            n--;
        digits[n] = '\0';
        *decpt = atoi(e + 1) + 1;
    }
}

const char *cam_repr(double value, char *buf, size_t len)
{
    char digits[32], body[64];
    int decpt, n, k, pos = 0;
    if (isnan(value)) {
        snprintf(buf, len, "nan");
        return buf;
    }
    if (isinf(value)) {
        snprintf(buf, len, value > 0 ? "inf" : "-inf");
        return buf;
    }
    if (value == 0.0) {
        snprintf(buf, len, signbit(value) ? "-0.0" : "0.0");
        return buf;
    }
    shortest_digits(fabs(value), digits, &decpt);
    n = (int)strlen(digits);
    if (decpt <= -4 || decpt > 16) {    /* exponent form, as Python's 'r' format */
        int exp10 = decpt - 1;
        body[pos++] = digits[0];
        if (n > 1) {
            body[pos++] = '.';
            for (k = 1; k < n; k++)
                body[pos++] = digits[k];
        }
        snprintf(body + pos, sizeof body - (size_t)pos, "e%c%02d", exp10 < 0 ? '-' : '+', abs(exp10));
    } else if (decpt <= 0) {
        body[pos++] = '0';
        body[pos++] = '.';
        for (k = 0; k < -decpt; k++)
            body[pos++] = '0';
        for (k = 0; k < n; k++)
            body[pos++] = digits[k];
        body[pos] = '\0';
    } else {
        for (k = 0; k < decpt; k++)
            body[pos++] = k < n ? digits[k] : '0';
        body[pos++] = '.';
        if (decpt >= n)
            body[pos++] = '0';
        for (k = decpt; k < n; k++)
            body[pos++] = digits[k];
        body[pos] = '\0';
    }
    snprintf(buf, len, "%s%s", value < 0 ? "-" : "", body);
    return buf;
}

const char *cam_repr_text(const char *text, size_t text_len, char *buf, size_t len)
{
    size_t k, pos = 0;
    char quote = '\'';
    if (memchr(text, '\'', text_len) != NULL && memchr(text, '"', text_len) == NULL)
        quote = '"';
    if (len < 8) {
        if (len > 0)
            buf[0] = '\0';
        return buf;
    }
    buf[pos++] = quote;
    for (k = 0; k < text_len && pos + 6 < len; k++) {
        unsigned char ch = (unsigned char)text[k];
        if (ch == '\\' || ch == (unsigned char)quote) {
            buf[pos++] = '\\';
            buf[pos++] = (char)ch;
        } else if (ch == '\n') {
            buf[pos++] = '\\';
            buf[pos++] = 'n';
        } else if (ch == '\r') {
            buf[pos++] = '\\';
            buf[pos++] = 'r';
        } else if (ch == '\t') {
            buf[pos++] = '\\';
            buf[pos++] = 't';
        } else if (ch < 32 || ch == 127) {
            pos += (size_t)snprintf(buf + pos, len - pos, "\\x%02x", ch);
        } else {
            buf[pos++] = (char)ch;
        }
    }
    if (k < text_len && pos + 4 < len) {
        buf[pos++] = '.';
        buf[pos++] = '.';
        buf[pos++] = '.';
    }
    buf[pos++] = quote;
    buf[pos] = '\0';
    return buf;
}
