/* Python-compatible number text and quoting for messages: see cam_text.h. */
#include "cam_text.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The decimal digits (no leading zeros except for 0) and exponent of the shortest
 * %.*e form of x that reads back as x. Locale-proof: only digits and the text after
 * 'e' are read from the formatted string; strtod reads it in the same locale. */
static int shortest_digits(double x, char digits[24], int *exponent)
{
    char buf[64];
    int p;
    for (p = 1; p <= 17; p++) {
        snprintf(buf, sizeof buf, "%.*e", p - 1, x);
        if (strtod(buf, NULL) == x || p == 17) {
            break;
        }
    }
    {
        int n = 0;
        const char *c = buf;
        while (*c && *c != 'e' && *c != 'E') {
            if (*c >= '0' && *c <= '9' && n < 23) {
                digits[n++] = *c;
            }
            c++;
        }
        while (n > 1 && digits[n - 1] == '0') {
            n--;  /* %.*e pads with zeros; repr does not */
        }
        digits[n] = '\0';
        *exponent = (*c) ? (int)strtol(c + 1, NULL, 10) : 0;
        return n;
    }
}

void cam_repr(double x, char out[CAM_REPR_LEN])
{
    char digits[24];
    int exponent, n, decpt, k;
    size_t pos = 0;
    if (x != x) {
        strcpy(out, "nan");
        return;
    }
    if (x > 1.7976931348623157e308 || x < -1.7976931348623157e308) {
        strcpy(out, x > 0 ? "inf" : "-inf");
        return;
    }
    if (x < 0.0 || (x == 0.0 && 1.0 / x < 0.0)) {
        out[pos++] = '-';
        x = -x;
    }
    if (x == 0.0) {
        strcpy(out + pos, "0.0");
        return;
    }
    n = shortest_digits(x, digits, &exponent);
    decpt = exponent + 1;              /* x = 0.d1d2... * 10^decpt */
    if (decpt <= -4 || decpt > 16) {   /* repr's switch to exponent notation */
        out[pos++] = digits[0];
        if (n > 1) {
            out[pos++] = '.';
            for (k = 1; k < n; k++) {
                out[pos++] = digits[k];
            }
        }
        snprintf(out + pos, CAM_REPR_LEN - pos, "e%c%02d", exponent < 0 ? '-' : '+',
                 exponent < 0 ? -exponent : exponent);
        return;
    }
    if (decpt <= 0) {
        out[pos++] = '0';
        out[pos++] = '.';
        for (k = 0; k < -decpt; k++) {
            out[pos++] = '0';
        }
        for (k = 0; k < n; k++) {
            out[pos++] = digits[k];
        }
    } else {
        for (k = 0; k < decpt; k++) {
            out[pos++] = k < n ? digits[k] : '0';
        }
        out[pos++] = '.';
        if (n > decpt) {
            for (k = decpt; k < n; k++) {
                out[pos++] = digits[k];
            }
        } else {
            out[pos++] = '0';
        }
    }
    out[pos] = '\0';
}

void cam_quote(const char *text, size_t len, char *out, size_t out_len)
{
    size_t i = 0, pos = 0;
    int chars = 0;
    if (out == NULL || out_len == 0) {
        return;
    }
    if (out_len < 2) {
        out[0] = '\0';
        return;
    }
    out[pos++] = '\'';
    while (i < len && chars < CAM_QUOTE_CHARS && pos + 2 < out_len) {
        unsigned char b = (unsigned char)text[i];
        if (b >= 0x20 && b < 0x7f) {
            out[pos++] = (char)b;
            i++;
        } else {
            /* one character: a UTF-8 lead byte and its continuation bytes, or one stray byte */
            i++;
            if (b >= 0xc0) {
                while (i < len && ((unsigned char)text[i] & 0xc0) == 0x80) {
                    i++;
                }
            }
            out[pos++] = '?';
        }
        chars++;
    }
    if (i < len && pos + 5 < out_len) {
        memcpy(out + pos, "...", 3);
        pos += 3;
    }
    out[pos++] = '\'';
    out[pos] = '\0';
}
