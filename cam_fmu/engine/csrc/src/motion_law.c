/* The general harmonic-trapezoid law (7 segments), dimensionless: cam_law_init and cam_law_eval.
 *
 * The same operations in the same order as cam_fmu/kinematics/motion_law.py (MotionLaw), so that
 * every segment field is the same double; evaluation as kinematics.motion_law's. Formulas:
 * docs/model.md section 1 and the docstring of motion_law.py.
 */
#include "cam_profile.h"
#include "cam_text.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define HALF_PI (0.5 * 3.141592653589793)

static const int KINDS[CAM_LAW_SEGMENTS] = {CAM_SHAPE_SIN, CAM_SHAPE_CONST, CAM_SHAPE_COS, CAM_SHAPE_CONST,
                                            CAM_SHAPE_SIN, CAM_SHAPE_CONST, CAM_SHAPE_COS};
static const int SIDE[CAM_LAW_SEGMENTS] = {1, 1, 1, 0, -1, -1, -1};

/* "rise_T3" for name "rise", "T3" without a name. */
static void param_name(char *out, size_t len, const char *name, int k)
{
    if (name != NULL && name[0] != '\0') {
        snprintf(out, len, "%.20s_T%d", name, k);
    } else {
        snprintf(out, len, "T%d", k);
    }
}

/* ", "-separated "NAME=repr" of the values whose flag is set, into list. */
static void list_named(char *list, size_t len, const char *name, const double T[6], const int flag[6])
{
    size_t pos = 0;
    int k;
    list[0] = '\0';
    for (k = 0; k < 6; k++) {
        char p[32], r[CAM_REPR_LEN];
        if (!flag[k] || pos >= len) {
            continue;
        }
        param_name(p, sizeof p, name, k + 1);
        cam_repr(T[k], r);
        pos += (size_t)snprintf(list + pos, len - pos, "%s%s=%s", pos ? ", " : "", p, r);
    }
}

static int refuse(CamError *err, const char *name, const char *fmt, const char *detail)
{
    if (name != NULL && name[0] != '\0') {
        char head[64];
        snprintf(head, sizeof head, "%.20s law: ", name);
        return cam_error(err, CAM_ERR_PARAMETER, "%s%s%s", head, fmt, detail);
    }
    return cam_error(err, CAM_ERR_PARAMETER, "%s%s", fmt, detail);
}

static int validate(const double T[6], const char *name, CamError *err)
{
    char list[512];
    int flag[6], k, any = 0;
    for (k = 0; k < 6; k++) {
        flag[k] = !isfinite(T[k]);
        any |= flag[k];
    }
    if (any) {
        list_named(list, sizeof list, name, T, flag);
        return refuse(err, name, "split points must be finite numbers: ", list);
    }
    for (k = 0; k < 6; k++) {
        flag[k] = !(0.0 <= T[k] && T[k] <= 1.0);
        any |= flag[k];
    }
    if (any) {
        list_named(list, sizeof list, name, T, flag);
        return refuse(err, name, "split points must lie in [0, 1]: ", list);
    }
    {
        size_t pos = 0;
        list[0] = '\0';
        for (k = 0; k < 5; k++) {
            if (T[k] > T[k + 1]) {
                char a[32], b[32], ra[CAM_REPR_LEN], rb[CAM_REPR_LEN];
                param_name(a, sizeof a, name, k + 1);
                param_name(b, sizeof b, name, k + 2);
                cam_repr(T[k], ra);
                cam_repr(T[k + 1], rb);
                if (pos < sizeof list) {
                    pos += (size_t)snprintf(list + pos, sizeof list - pos, "%s%s=%s > %s=%s",
                                            pos ? ", " : "", a, ra, b, rb);
                }
            }
        }
        if (pos) {
            char head[160], t1[32], t2[32], t6[32];
            param_name(t1, sizeof t1, name, 1);
            param_name(t2, sizeof t2, name, 2);
            param_name(t6, sizeof t6, name, 6);
            snprintf(head, sizeof head, "split points must be ordered %s <= %s <= ... <= %s: ", t1, t2, t6);
            return refuse(err, name, head, list);
        }
    }
    if (T[2] == 0.0) {
        char tail[96], t3[32];
        int f[6] = {1, 1, 1, 0, 0, 0};
        param_name(t3, sizeof t3, name, 3);
        list_named(list, sizeof list, name, T, f);
        snprintf(tail, sizeof tail, " (need %s > 0 to leave the lower dwell)", t3);
        strncat(list, tail, sizeof list - strlen(list) - 1);
        return refuse(err, name, "no acceleration segment: ", list);
    }
    if (T[3] == 1.0) {
        char tail[96], t4[32];
        int f[6] = {0, 0, 0, 1, 1, 1};
        param_name(t4, sizeof t4, name, 4);
        list_named(list, sizeof list, name, T, f);
        snprintf(tail, sizeof tail, " (need %s < 1 to reach the upper dwell)", t4);
        strncat(list, tail, sizeof list - strlen(list) - 1);
        return refuse(err, name, "no deceleration segment: ", list);
    }
    return 0;
}

/* (int_0^L shape, int_0^L int_0^v shape) for a unit coefficient. */
static void increments(int kind, double L, double F, double *dv, double *ds)
{
    if (L == 0.0) {
        *dv = 0.0;
        *ds = 0.0;
    } else if (kind == CAM_SHAPE_CONST) {
        *dv = L;
        *ds = 0.5 * L * L;
    } else if (kind == CAM_SHAPE_SIN) {
        *dv = F;
        *ds = F * (L - F);
    } else {
        *dv = F;
        *ds = F * F;
    }
}

/* V and S at each segment start for a unit coefficient on the segments of one side. */
static void propagate(int side, const double L[7], const double F[7], double V0[7], double S0[7], double *v_end,
                      double *s_end)
{
    double v = 0.0, s = 0.0;
    int i;
    for (i = 0; i < CAM_LAW_SEGMENTS; i++) {
        double c = SIDE[i] == side ? 1.0 : 0.0, dv, ds;
        V0[i] = v;
        S0[i] = s;
        increments(KINDS[i], L[i], F[i], &dv, &ds);
        s += v * L[i] + c * ds;
        v += c * dv;
    }
    *v_end = v;
    *s_end = s;
}

int cam_law_init(CamLaw *law, const double T[6], const char *name, CamError *err)
{
    double edges[8], L[7], F[7], Vp[7], Sp[7], Vm[7], Sm[7], vp, sp, vm, sm, det, Amp, Amm;
    int i;
    memset(law, 0, sizeof *law);
    if (validate(T, name, err)) {
        return CAM_ERR_PARAMETER;
    }
    edges[0] = 0.0;
    for (i = 0; i < 6; i++) {
        edges[i + 1] = T[i];
    }
    edges[7] = 1.0;
    for (i = 0; i < CAM_LAW_SEGMENTS; i++) {
        L[i] = edges[i + 1] - edges[i];
        F[i] = L[i] / HALF_PI;
    }
    propagate(1, L, F, Vp, Sp, &vp, &sp);
    propagate(-1, L, F, Vm, Sm, &vm, &sm);
    det = sp * vm - sm * vp;
    Amp = det > 0.0 ? vm / det : INFINITY;
    Amm = det > 0.0 ? vp / det : INFINITY;
    if (!(isfinite(Amp) && isfinite(Amm))) {
        char list[256], r[CAM_REPR_LEN];
        size_t pos = 0;
        for (i = 0; i < 6; i++) {
            cam_repr(T[i], r);
            pos += (size_t)snprintf(list + pos, sizeof list - pos, "%s%s", i ? ", " : "(", r);
        }
        snprintf(list + pos, sizeof list - pos, ")");
        if (name != NULL && name[0] != '\0') {
            return cam_error(err, CAM_ERR_PARAMETER, "%.20s law: split points %.20s_T1..%.20s_T6 = %s are too close "
                             "to make a finite curve (acceleration or deceleration phase of length ~0)", name, name,
                             name, list);
        }
        return cam_error(err, CAM_ERR_PARAMETER, "split points %s are too close to make a finite curve "
                         "(acceleration or deceleration phase of length ~0)", list);
    }
    for (i = 0; i < CAM_LAW_SEGMENTS; i++) {
        double *seg;
        if (!(L[i] > 0.0)) {
            continue;
        }
        seg = law->segments + CAM_SEGMENT_FIELDS * law->n_segments;
        seg[0] = edges[i + 1];
        seg[1] = edges[i];
        seg[2] = KINDS[i] != CAM_SHAPE_CONST ? F[i] : 1.0;
        seg[3] = SIDE[i] > 0 ? Amp : (SIDE[i] < 0 ? -Amm : 0.0);
        seg[4] = (double)KINDS[i];
        seg[5] = Amp * Vp[i] - Amm * Vm[i];
        seg[6] = Amp * Sp[i] - Amm * Sm[i];
        law->n_segments++;
    }
    return 0;
}

void cam_law_eval(const CamLaw *law, double T, double out[4])
{
    const double *seg;
    double t0, F, c, kind, V0, S0, u, x, sx, cx, cF;
    int k = 0, n = law->n_segments;
    if (T < 0.0) {
        out[0] = out[1] = out[2] = out[3] = 0.0;
        return;
    }
    if (T > 1.0) {
        out[0] = 1.0;
        out[1] = out[2] = out[3] = 0.0;
        return;
    }
    while (k < n - 1 && T > law->segments[CAM_SEGMENT_FIELDS * k]) {
        k++;
    }
    seg = law->segments + CAM_SEGMENT_FIELDS * k;
    t0 = seg[1];
    F = seg[2];
    c = seg[3];
    kind = seg[4];
    V0 = seg[5];
    S0 = seg[6];
    u = T - t0;
    if (kind == CAM_SHAPE_CONST) {
        out[0] = S0 + u * (V0 + 0.5 * c * u);
        out[1] = V0 + c * u;
        out[2] = c;
        out[3] = 0.0;
        return;
    }
    x = u / F;
    sx = sin(x);
    cx = cos(x);
    cF = c * F;
    if (kind == CAM_SHAPE_SIN) {
        out[0] = S0 + V0 * u + cF * (u - F * sx);
        out[1] = V0 + cF * (1.0 - cx);
        out[2] = c * sx;
        out[3] = c / F * cx;
        return;
    }
    out[0] = S0 + V0 * u + cF * F * (1.0 - cx);
    out[1] = V0 + cF * sx;
    out[2] = c * cx;
    out[3] = -c / F * sx;
}
