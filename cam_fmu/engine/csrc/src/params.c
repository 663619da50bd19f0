/* Parameter values: defaults, the checks of physics/parameters.py (ParameterSpec.check, resolve)
 * with their messages text-for-text, over the generated table cam_params.h. */
#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cam_model.h"

void cam_params_defaults(CamParams *p)
{
    int k;
    for (k = 0; k < CAM_N_PARAMS; k++)
        p->v[k] = cam_param_spec(k)->default_value;
    p->motion_table = NULL;
}

void cam_params_free(CamParams *p)
{
    free(p->motion_table);
    p->motion_table = NULL;
}

static char *duplicate(const char *text, size_t len)
{
    char *copy = malloc(len + 1);
    if (copy != NULL) {
        memcpy(copy, text, len);
        copy[len] = '\0';
    }
    return copy;
}

int cam_params_copy(CamParams *dst, const CamParams *src, CamError *err)
{
    memcpy(dst->v, src->v, sizeof dst->v);
    dst->motion_table = NULL;
    if (src->motion_table != NULL) {
        dst->motion_table = duplicate(src->motion_table, strlen(src->motion_table));
        if (dst->motion_table == NULL)
            return cam_error(err, CAM_ERR_MEMORY, "out of memory copying the parameter 'motion_table'");
    }
    return CAM_OK;
}

int cam_param_index(const char *name)
{
    int k;
    for (k = 0; k < CAM_N_PARAMS; k++)
        if (strcmp(cam_param_spec(k)->name, name) == 0)
            return k;
    return -1;
}

static int by_name(const void *a, const void *b)
{
    return strcmp(cam_param_spec(*(const int *)a)->name, cam_param_spec(*(const int *)b)->name);
}

int cam_params_unknown(const char *name, CamError *err)
{
    int order[CAM_N_PARAMS], k;
    char known[CAM_MESSAGE_LEN], shown[128];
    size_t pos = 0;
    for (k = 0; k < CAM_N_PARAMS; k++)
        order[k] = k;
    qsort(order, CAM_N_PARAMS, sizeof order[0], by_name);
    known[0] = '\0';
    for (k = 0; k < CAM_N_PARAMS && pos < sizeof known; k++)
        pos += (size_t)snprintf(known + pos, sizeof known - pos, "%s%s", k ? ", " : "",
                                cam_param_spec(order[k])->name);
    return cam_error(err, CAM_ERR_PARAMETER, "unknown parameter %s; known: %s",
                    cam_text(name, strlen(name), shown, sizeof shown), known);
}

/* ParameterSpec.allowed(): the allowed range as the messages show it. */
static const char *allowed(const CamParamSpec *s, char *buf, size_t len)
{
    size_t pos = 0;
    int k;
    if (s->kind == CAM_KIND_BOOLEAN) {
        snprintf(buf, len, "true or false");
        return buf;
    }
    if (s->kind == CAM_KIND_STRING) {
        pos += (size_t)snprintf(buf, len, "one of ");
        for (k = 0; k < s->n_choices && pos < len; k++)
            pos += (size_t)snprintf(buf + pos, len - pos, "%s'%s'", k ? ", " : "", s->choices[k]);
        return buf;
    }
    snprintf(buf, len, "%s%s%g, %g]%s%s", s->zero_ok ? "0 or " : "", s->low_open ? "(" : "[", s->low, s->high,
             (strcmp(s->unit, "") != 0 && strcmp(s->unit, "1") != 0) ? " " : "",
             (strcmp(s->unit, "") != 0 && strcmp(s->unit, "1") != 0) ? s->unit : "");
    return buf;
}

int cam_params_set_real(CamParams *p, int index, double value, CamError *err)
{
    const CamParamSpec *s = cam_param_spec(index);
    char range[256], number[40];
    int too_low;
    if (s == NULL)
        return cam_error(err, CAM_ERR_PARAMETER, "no parameter has index %d", index);
    if (s->kind == CAM_KIND_BOOLEAN) {
        p->v[index] = value != 0.0 ? 1.0 : 0.0;   /* bool(value) */
        return CAM_OK;
    }
    if (s->kind == CAM_KIND_STRING)
        return cam_error(err, CAM_ERR_PARAMETER, "parameter '%s' is a string: allowed %s", s->name,
                        allowed(s, range, sizeof range));
    too_low = s->low_open ? value <= s->low : value < s->low;
    if (s->zero_ok && value == 0.0) {
        p->v[index] = 0.0;
        return CAM_OK;
    }
    if (!isfinite(value) || too_low || value > s->high)
        return cam_error(err, CAM_ERR_PARAMETER, "parameter '%s' = %s [%s] is outside the allowed range %s", s->name,
                        cam_num(value, number), s->unit, allowed(s, range, sizeof range));
    p->v[index] = value;
    return CAM_OK;
}

static int equal_nocase(const char *text, size_t len, const char *word)
{
    size_t k;
    if (strlen(word) != len)
        return 0;
    for (k = 0; k < len; k++)
        if (tolower((unsigned char)text[k]) != word[k])
            return 0;
    return 1;
}

int cam_params_set_string(CamParams *p, int index, const char *text, size_t len, CamError *err)
{
    const CamParamSpec *s = cam_param_spec(index);
    char range[256], shown[160];
    int k;
    if (s == NULL)
        return cam_error(err, CAM_ERR_PARAMETER, "no parameter has index %d", index);
    if (s->kind == CAM_KIND_BOOLEAN) {
        static const char *const yes[] = {"true", "1", "yes", "on"}, *const no[] = {"false", "0", "no", "off"};
        for (k = 0; k < 4; k++) {
            if (equal_nocase(text, len, yes[k])) {
                p->v[index] = 1.0;
                return CAM_OK;
            }
            if (equal_nocase(text, len, no[k])) {
                p->v[index] = 0.0;
                return CAM_OK;
            }
        }
        return cam_error(err, CAM_ERR_PARAMETER, "parameter '%s' = %s: allowed %s", s->name,
                        cam_text(text, len, shown, sizeof shown), allowed(s, range, sizeof range));
    }
    if (s->kind == CAM_KIND_REAL) {
        char buf[64], *end;
        double number;
        size_t a = 0, b = len;
        while (a < b && isspace((unsigned char)text[a]))
            a++;
        while (b > a && isspace((unsigned char)text[b - 1]))
            b--;
        if (b > a && b - a < sizeof buf) {
            memcpy(buf, text + a, b - a);
            buf[b - a] = '\0';
            number = strtod(buf, &end);
            if (*end == '\0' && !(buf[0] == '0' && (buf[1] == 'x' || buf[1] == 'X')))
                return cam_params_set_real(p, index, number, err);
        }
        return cam_error(err, CAM_ERR_PARAMETER, "parameter '%s' = %s is not a number: allowed %s", s->name,
                        cam_text(text, len, shown, sizeof shown), allowed(s, range, sizeof range));
    }
    if (s->n_choices == 0) {   /* free text: the motion table */
        char *copy = duplicate(text, len);
        if (copy == NULL)
            return cam_error(err, CAM_ERR_MEMORY, "out of memory storing the parameter '%s'", s->name);
        free(p->motion_table);
        p->motion_table = copy;
        return CAM_OK;
    }
    for (k = 0; k < s->n_choices; k++)
        if (strlen(s->choices[k]) == len && memcmp(s->choices[k], text, len) == 0) {
            p->v[index] = (double)k;
            return CAM_OK;
        }
    return cam_error(err, CAM_ERR_PARAMETER, "parameter '%s' = %s: allowed %s", s->name,
                    cam_text(text, len, shown, sizeof shown), allowed(s, range, sizeof range));
}

int cam_params_check(const CamParams *p, CamError *err)
{
    const double two_pi = 2.0 * 3.141592653589793;
    double total = p->v[CAM_P_RISE_ANGLE] + p->v[CAM_P_UPPER_DWELL] + p->v[CAM_P_RETURN_ANGLE]
                   + p->v[CAM_P_LOWER_DWELL];
    char a[40], b[40];
    if (fabs(total - two_pi) > 1e-9)
        return cam_error(err, CAM_ERR_PARAMETER,
                        "parameters 'rise_angle' + 'upper_dwell' + 'return_angle' + 'lower_dwell' = %s rad must "
                        "equal 2 pi = %s rad (to 1e-9 rad)", cam_num(total, a),
                        cam_num(two_pi, b));
    return CAM_OK;
}
