/* A user's motion table: the CSV parser (untrusted bytes) and the shape-preserving periodic
 * piecewise cubic Hermite interpolant through its rows. docs/cam_design.md states the format,
 * the refusals and the curve; kinematics/motion_table.py is the same model in Python (the same
 * messages and, operation for operation, the same doubles).
 *
 * Slopes: at each knot the slope of the parabola through it and its two neighbours, then
 * limited as Fritsch and Carlson's monotone cubic interpolation requires (Hyman's filter):
 * 0 where the chords on either side differ in sign or one is 0 (a local extremum or the edge
 * of a dwell), otherwise at most 3 times the smaller chord slope. Each piece is then monotone
 * between its two lifts: no overshoot, and a run of equal lifts is exactly flat.
 */
#include "cam_table.h"
#include "cam_text.h"

#include <locale.h>
#include <stdarg.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define TWO_PI (2.0 * 3.141592653589793)
#define DEG (3.141592653589793 / 180.0)   /* Python's math.radians factor */

typedef struct {
    const char *s;
    size_t n;
} Span;

enum { NOT_NUMBER = 0, DECIMAL = 1, INF_WORD = 2, NAN_WORD = 3 };

static int is_sep(char c)
{
    return c == ' ' || c == '\t' || c == ',' || c == ';';
}

static int is_digit(char c)
{
    return c >= '0' && c <= '9';
}

static int word_is(const char *s, size_t n, const char *word)
{
    size_t i;
    if (n != strlen(word)) {
        return 0;
    }
    for (i = 0; i < n; i++) {
        char c = s[i];
        if (c >= 'A' && c <= 'Z') {
            c = (char)(c - 'A' + 'a');
        }
        if (c != word[i]) {
            return 0;
        }
    }
    return 1;
}

/* What a field is: [+-] (digits [. digits] | . digits) [(e|E) [+-] digits], or [+-] inf, infinity, nan
 * (any case): Python's float() without its underscores and surrounding blanks. */
static int classify(Span f)
{
    const char *s = f.s;
    size_t n = f.n, i = 0, digits = 0;
    if (i < n && (s[i] == '+' || s[i] == '-')) {
        i++;
    }
    if (word_is(s + i, n - i, "inf") || word_is(s + i, n - i, "infinity")) {
        return INF_WORD;
    }
    if (word_is(s + i, n - i, "nan")) {
        return NAN_WORD;
    }
    while (i < n && is_digit(s[i])) {
        i++;
        digits++;
    }
    if (i < n && s[i] == '.') {
        i++;
        while (i < n && is_digit(s[i])) {
            i++;
            digits++;
        }
    }
    if (digits == 0) {
        return NOT_NUMBER;
    }
    if (i < n && (s[i] == 'e' || s[i] == 'E')) {
        size_t e = 0;
        i++;
        if (i < n && (s[i] == '+' || s[i] == '-')) {
            i++;
        }
        while (i < n && is_digit(s[i])) {
            i++;
            e++;
        }
        if (e == 0) {
            return NOT_NUMBER;
        }
    }
    return i == n ? DECIMAL : NOT_NUMBER;
}

/* The value of a field that classify() accepted: correctly rounded (strtod), whatever the C locale's
 * decimal point. 0 on success. */
static int to_double(Span f, int kind, double *value)
{
    char buf[CAM_TABLE_MAX_NUMBER + 16], *end;
    const char *point = localeconv()->decimal_point;
    size_t i, pos = 0, plen = point != NULL ? strlen(point) : 0;
    int negative = f.n > 0 && f.s[0] == '-';
    if (kind == INF_WORD) {
        *value = negative ? -INFINITY : INFINITY;
        return 0;
    }
    if (kind == NAN_WORD) {
        *value = NAN;
        return 0;
    }
    if (plen == 0 || plen > 8) {
        point = ".";
        plen = 1;
    }
    for (i = 0; i < f.n; i++) {
        if (f.s[i] == '.') {
            memcpy(buf + pos, point, plen);
            pos += plen;
        } else {
            buf[pos++] = f.s[i];
        }
    }
    buf[pos] = '\0';
    *value = strtod(buf, &end);
    return end != buf + pos;
}

/* The interpolant's slopes and piece coefficients from knots angle[0..n-1], lift[0..n-1] (n >= 2). */
static void build(CamTable *t)
{
    size_t n = t->n, i;
    double *delta = t->c3;  /* chord slopes, overwritten last */
    for (i = 0; i < n; i++) {
        double next = i + 1 < n ? t->angle[i + 1] : t->angle[0] + TWO_PI;
        t->width[i] = next - t->angle[i];
        delta[i] = (t->lift[i + 1 < n ? i + 1 : 0] - t->lift[i]) / t->width[i];
    }
    for (i = 0; i < n; i++) {
        size_t j = i > 0 ? i - 1 : n - 1;
        double a = delta[j], b = delta[i], ha = t->width[j], hb = t->width[i], d = 0.0;
        if ((a > 0.0 && b > 0.0) || (a < 0.0 && b < 0.0)) {
            double limit = 3.0 * fmin(fabs(a), fabs(b));
            d = (hb * a + ha * b) / (ha + hb);
            if (fabs(d) > limit) {
                d = copysign(limit, d);
            }
        }
        t->slope[i] = d;
    }
    for (i = 0; i < n; i++) {
        double w = t->width[i], d0 = t->slope[i], d1 = t->slope[i + 1 < n ? i + 1 : 0], chord = delta[i];
        t->c2[i] = (3.0 * chord - 2.0 * d0 - d1) / w;
        t->e2[i] = (d0 + 2.0 * d1 - 3.0 * chord) / w;
        t->c3[i] = (d0 + d1 - 2.0 * chord) / (w * w);
    }
}

void cam_table_eval(const CamTable *t, double th, double d[4], size_t *comparisons)
{
    size_t n = t->n, lo = 0, hi = n, i, count = 0;
    double u, w, y0, y1, c3, s;
    if (!isfinite(th) || n == 0) {  /* th in [0, 2 pi) (cam_table.h): a knot is its own reduction */
        d[0] = d[1] = d[2] = d[3] = NAN;
        return;
    }
    while (lo < hi) {  /* bisect_left: the first knot >= th */
        size_t mid = lo + (hi - lo) / 2;
        count++;
        if (t->angle[mid] < th) {
            lo = mid + 1;
        } else {
            hi = mid;
        }
    }
    if (comparisons != NULL) {
        *comparisons += count;
    }
    if (lo == 0) {  /* up to knot 0 (included): the last piece, which ends at knot 0 + 2 pi */
        i = n - 1;
        u = (th + TWO_PI) - t->angle[i];
    } else {
        i = lo - 1;
        u = th - t->angle[i];
    }
    w = t->width[i];
    y0 = t->lift[i];
    y1 = t->lift[i + 1 < n ? i + 1 : 0];
    c3 = t->c3[i];
    if (u <= 0.5 * w) {
        double c1 = t->slope[i], c2 = t->c2[i];
        s = y0 + u * (c1 + u * (c2 + u * c3));
        d[1] = c1 + u * (2.0 * c2 + 3.0 * c3 * u);
        d[2] = 2.0 * c2 + 6.0 * c3 * u;
    } else {
        double v = u - w, c1 = t->slope[i + 1 < n ? i + 1 : 0], c2 = t->e2[i];
        s = y1 + v * (c1 + v * (c2 + v * c3));
        d[1] = c1 + v * (2.0 * c2 + 3.0 * c3 * v);
        d[2] = 2.0 * c2 + 6.0 * c3 * v;
    }
    d[3] = 6.0 * c3;
    /* the piece is monotone between y0 and y1; rounding must not take s outside */
    d[0] = fmin(fmax(s, fmin(y0, y1)), fmax(y0, y1));
}

/* A refusal of row `row` on line `line`: "motion table line L (row R): " and the printf-style rest. */
static int row_fail(CamError *err, size_t line, size_t row, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;

static int row_fail(CamError *err, size_t line, size_t row, const char *fmt, ...)
{
    va_list args;
    int head;
    if (err == NULL) {
        return CAM_ERR_PARAMETER;
    }
    head = snprintf(err->message, sizeof err->message, "motion table line %lu (row %lu): ", (unsigned long)line,
                    (unsigned long)row);
    err->status = CAM_ERR_PARAMETER;
    va_start(args, fmt);
    vsnprintf(err->message + head, sizeof err->message - (size_t)head, fmt, args);
    va_end(args);
    return CAM_ERR_PARAMETER;
}

/* The number in field f (named name) or a refusal. */
static int field_value(Span f, const char *name, size_t line, size_t row, double *value, CamError *err)
{
    char q[200];
    int kind = classify(f);
    cam_quote(f.s, f.n, q, sizeof q);
    if (kind == NOT_NUMBER) {
        return row_fail(err, line, row, "the %s field is not a number: %s", name, q);
    }
    if (f.n > CAM_TABLE_MAX_NUMBER) {
        return row_fail(err, line, row, "the %s field has more than %d characters: %s", name, CAM_TABLE_MAX_NUMBER,
                        q);
    }
    if (to_double(f, kind, value)) {
        return row_fail(err, line, row, "the %s field could not be read as a number: %s", name, q);
    }
    return CAM_OK;
}

typedef struct {
    size_t line, row;   /* where a row was */
    Span angle, lift;   /* its texts */
    double degrees, radians, mm;
} RowInfo;

/* Where the parser is: the line and row counts, and the rows later checks compare with. */
typedef struct {
    size_t line, row;
    int first_line, closed;
    RowInfo first, prev, closing;
} Parser;

/* The line starting at *pos: its end (before '\n', '\r' or "\r\n"); *pos moves past the line break. */
static size_t line_end(const char *text, size_t len, size_t *pos)
{
    size_t end = *pos;
    while (end < len && text[end] != '\n' && text[end] != '\r') {
        end++;
    }
    *pos = end;
    if (end < len) {
        *pos += (text[end] == '\r' && end + 1 < len && text[end + 1] == '\n') ? 2 : 1;
    }
    return end;
}

/* The fields of text[start..end) before a '#' comment (its end into *stop): the first two into field,
 * how many look like numbers into *numbers; returns the number of fields. */
static size_t line_fields(const char *text, size_t start, size_t end, Span field[2], int *numbers, size_t *stop)
{
    size_t k, n_fields = 0;
    *stop = start;
    while (*stop < end && text[*stop] != '#') {
        (*stop)++;  /* '#' starts a comment */
    }
    *numbers = 0;
    for (k = start; k < *stop;) {
        size_t f0;
        if (is_sep(text[k])) {
            k++;
            continue;
        }
        f0 = k;
        while (k < *stop && !is_sep(text[k])) {
            k++;
        }
        if (n_fields < 2) {
            field[n_fields].s = text + f0;
            field[n_fields].n = k - f0;
        }
        if (classify((Span){text + f0, k - f0}) != NOT_NUMBER) {
            (*numbers)++;
        }
        n_fields++;
    }
    return n_fields;
}

/* The row on the parser's line (its text line[0..n), n_fields fields, the first two in field) read into
 * *r: two numbers, each in its range, and no row after a closing one. */
static int read_row(const Parser *ps, const char *line, size_t n, size_t n_fields, const Span field[2],
                    RowInfo *r, CamError *err)
{
    char q[200];
    if (ps->closed) {
        return row_fail(err, ps->line, ps->row, "no row may follow the closing row at 360 deg (row %lu, line %lu)",
                        (unsigned long)ps->closing.row, (unsigned long)ps->closing.line);
    }
    if (n_fields != 2) {
        size_t a = 0, b = n;
        while (a < b && is_sep(line[a])) {
            a++;
        }
        while (b > a && is_sep(line[b - 1])) {
            b--;
        }
        return row_fail(err, ps->line, ps->row, "expected 2 fields 'angle_deg, lift_mm', got %lu: %s",
                        (unsigned long)n_fields, cam_text(line + a, b - a, q, sizeof q));
    }
    memset(r, 0, sizeof *r);
    r->line = ps->line;
    r->row = ps->row;
    r->angle = field[0];
    r->lift = field[1];
    if (field_value(r->angle, "angle_deg", ps->line, ps->row, &r->degrees, err) ||
        field_value(r->lift, "lift_mm", ps->line, ps->row, &r->mm, err)) {
        return CAM_ERR_PARAMETER;
    }
    if (!(isfinite(r->degrees) && r->degrees >= 0.0 && r->degrees <= 360.0)) {
        return row_fail(err, ps->line, ps->row, "angle_deg must lie in [0, 360) (or be 360 in a closing row), got %s",
                        cam_text(r->angle.s, r->angle.n, q, sizeof q));
    }
    if (!(isfinite(r->mm) && r->mm >= 0.0 && r->mm <= CAM_TABLE_MAX_LIFT_MM)) {
        return row_fail(err, ps->line, ps->row, "lift_mm must be a number in [0, 10000], got %s",
                        cam_text(r->lift.s, r->lift.n, q, sizeof q));
    }
    return CAM_OK;
}

/* A row at 360 deg: it closes the period, after a first row at 0 deg and with that row's lift. */
static int close_period(Parser *ps, const CamTable *table, const RowInfo *r, CamError *err)
{
    char q1[200], q2[200];
    const RowInfo *first = &ps->first;
    if (table->n == 0 || first->degrees != 0.0) {
        return row_fail(err, ps->line, ps->row, "a row at 360 deg closes the period: it must come last, "
                        "after a first row at 0 deg");
    }
    if (fabs(r->mm - first->mm) > 1e-9 * fmax(1.0, fabs(first->mm))) {
        return row_fail(err, ps->line, ps->row, "the closing row at 360 deg must repeat the lift of row %lu "
                        "(line %lu), %s mm, got %s mm", (unsigned long)first->row, (unsigned long)first->line,
                        cam_text(first->lift.s, first->lift.n, q1, sizeof q1),
                        cam_text(r->lift.s, r->lift.n, q2, sizeof q2));
    }
    ps->closed = 1;
    ps->closing = *r;
    return CAM_OK;
}

/* A row inside the period: its angle above the previous one's by at least the minimum spacing, then kept. */
static int append_row(Parser *ps, CamTable *table, RowInfo *r, CamError *err)
{
    char q1[200], q2[200];
    const RowInfo *prev = &ps->prev;
    r->radians = r->degrees * DEG;
    if (table->n > 0) {
        if (r->degrees <= prev->degrees) {
            return row_fail(err, ps->line, ps->row, "angle %s deg %s %s deg of row %lu (line %lu); angles must "
                            "increase strictly", cam_text(r->angle.s, r->angle.n, q1, sizeof q1),
                            r->degrees == prev->degrees ? "repeats" : "is below",
                            cam_text(prev->angle.s, prev->angle.n, q2, sizeof q2), (unsigned long)prev->row,
                            (unsigned long)prev->line);
        }
        if (r->degrees - prev->degrees < CAM_TABLE_MIN_SPACING_DEG) {
            return row_fail(err, ps->line, ps->row, "angle %s deg is closer than 1e-06 deg to %s deg of row %lu "
                            "(line %lu)", cam_text(r->angle.s, r->angle.n, q1, sizeof q1),
                            cam_text(prev->angle.s, prev->angle.n, q2, sizeof q2), (unsigned long)prev->row,
                            (unsigned long)prev->line);
        }
    }
    if (table->n >= CAM_TABLE_MAX_ROWS) {
        return cam_error(err, CAM_ERR_PARAMETER, "motion table: more than %d rows (line %lu)", CAM_TABLE_MAX_ROWS,
                         (unsigned long)ps->line);
    }
    if (table->angle != NULL) {   /* the second pass: the rows into the table's block */
        table->angle[table->n] = r->radians;
        table->lift[table->n] = r->mm * 1e-3;
    }
    if (++table->n == 1) {
        ps->first = *r;
    }
    ps->prev = *r;
    return CAM_OK;
}

/* The whole table: at least two rows, and the last far enough from the first one's angle + 360 deg. */
static int check_period(const Parser *ps, const CamTable *table, CamError *err)
{
    char q1[200], q2[200];
    const RowInfo *first = &ps->first, *prev = &ps->prev;
    if (table->n < 2) {
        return cam_error(err, CAM_ERR_PARAMETER, "motion table: need at least 2 rows 'angle_deg, lift_mm' (a closing "
                         "row at 360 deg not counted), got %lu", (unsigned long)table->n);
    }
    if ((first->degrees + 360.0) - prev->degrees < CAM_TABLE_MIN_SPACING_DEG) {
        return row_fail(err, prev->line, prev->row, "angle %s deg is closer than 1e-06 deg to %s deg + 360 deg of "
                        "row %lu (line %lu), where the period starts again",
                        cam_text(prev->angle.s, prev->angle.n, q1, sizeof q1),
                        cam_text(first->angle.s, first->angle.n, q2, sizeof q2), (unsigned long)first->row,
                        (unsigned long)first->line);
    }
    return CAM_OK;
}

/* The rows of a motion table's text (docs/cam_design.md: the format and the refusals), line by line: counted
 * into table->n, and stored where table->angle, table->lift are allocated. */
static int parse(const char *text, size_t len, CamTable *table, CamError *err)
{
    Parser ps;
    size_t pos = 0;
    int status;
    memset(&ps, 0, sizeof ps);
    ps.first_line = 1;
    if (len >= 3 && (unsigned char)text[0] == 0xef && (unsigned char)text[1] == 0xbb &&
        (unsigned char)text[2] == 0xbf) {
        pos = 3;  /* a UTF-8 byte order mark, as spreadsheets write it */
    }
    while (pos < len) {
        size_t start = pos, end = line_end(text, len, &pos), stop, n_fields;
        Span field[2];
        RowInfo r;
        int numbers;
        ps.line++;
        n_fields = line_fields(text, start, end, field, &numbers, &stop);
        if (n_fields == 0) {
            continue;  /* blank or comment */
        }
        if (ps.first_line) {
            ps.first_line = 0;
            if (numbers == 0) {
                continue;  /* a header: no field is a number */
            }
        }
        ps.row++;
        if ((status = read_row(&ps, text + start, stop - start, n_fields, field, &r, err)) != CAM_OK) {
            return status;
        }
        status = r.degrees == 360.0 ? close_period(&ps, table, &r, err) : append_row(&ps, table, &r, err);
        if (status != CAM_OK) {
            return status;
        }
    }
    return check_period(&ps, table, err);
}

int cam_table_init(CamTable *t, const char *text, size_t text_len, CamError *err)
{
    double *block;
    size_t n;
    int status;
    memset(t, 0, sizeof *t);
    if (text == NULL && text_len > 0) {
        return cam_error(err, CAM_ERR_PARAMETER, "motion table: no text");
    }
    if ((status = parse(text, text_len, t, err)) != CAM_OK) {   /* the first pass counts the rows */
        memset(t, 0, sizeof *t);
        return status;
    }
    n = t->n;
    block = malloc(7 * n * sizeof *block);
    if (block == NULL) {
        memset(t, 0, sizeof *t);
        return cam_error(err, CAM_ERR_MEMORY, "motion table: out of memory for %lu rows", (unsigned long)n);
    }
    t->n = 0;
    t->angle = block;
    t->lift = block + n;
    t->slope = block + 2 * n;
    t->width = block + 3 * n;
    t->c2 = block + 4 * n;
    t->e2 = block + 5 * n;
    t->c3 = block + 6 * n;
    parse(text, text_len, t, err);   /* the second pass, over text the first accepted, stores them */
    build(t);
    return CAM_OK;
}

void cam_table_free(CamTable *t)
{
    free(t->angle);  /* the table's one allocation */
    memset(t, 0, sizeof *t);
}
