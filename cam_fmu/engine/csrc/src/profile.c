/* A cam program of two laws with dwells, its evaluation, breakpoints and breakpoint search.
 *
 * cam_profile_init_laws checks as kinematics/cam_program.py's CamProgram (and physics/parameters.py for
 * the sum of the angles) and computes what kinematics.cam_program.CamProgram does; cam_profile_eval is
 * CamProgram.derivatives (same operations, same order: the same doubles); breakpoints and the
 * feature angle are CamProgram.breakpoints() and CamProgram.feature_angle(). A table program is built here
 * around the CamTable that motion_table.c parses, interpolates and frees (cam_table.h).
 */
#include "cam_profile.h"
#include "cam_table.h"
#include "cam_text.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define TWO_PI (2.0 * 3.141592653589793)

static int check_program(double lift, const double angle[4], CamError *err)
{
    static const char *const names[4] = {"rise_angle", "upper_dwell", "return_angle", "lower_dwell"};
    char list[512], r[CAM_REPR_LEN];
    size_t pos = 0;
    double total;
    int k;
    if (!(isfinite(lift) && lift > 0.0)) {
        cam_repr(lift, r);
        return cam_error(err, CAM_ERR_PARAMETER, "lift must be a finite number > 0 [m], got %s", r);
    }
    list[0] = '\0';
    for (k = 0; k < 4; k++) {
        if (!(isfinite(angle[k]) && angle[k] >= 0.0)) {
            cam_repr(angle[k], r);
            pos += (size_t)snprintf(list + pos, sizeof list - pos, "%s%s=%s", pos ? ", " : "", names[k], r);
        }
    }
    if (pos) {
        return cam_error(err, CAM_ERR_PARAMETER, "angles must be finite and >= 0 [rad]: %s", list);
    }
    for (k = 0; k < 4; k += 2) {
        if (angle[k] < CAM_MIN_STROKE_ANGLE) {
            cam_repr(angle[k], r);
            pos += (size_t)snprintf(list + pos, sizeof list - pos, "%s%s=%s", pos ? ", " : "", names[k], r);
        }
    }
    if (pos) {
        return cam_error(err, CAM_ERR_PARAMETER, "rise and return angles must be >= 0.000174533 rad (0.01 deg) "
                         "[rad]: %s", list);
    }
    total = angle[0] + angle[1] + angle[2] + angle[3];
    if (fabs(total - TWO_PI) > 1e-9) {
        char two_pi[CAM_REPR_LEN];
        cam_repr(total, r);
        cam_repr(TWO_PI, two_pi);
        return cam_error(err, CAM_ERR_PARAMETER, "parameters 'rise_angle' + 'upper_dwell' + 'return_angle' + "
                         "'lower_dwell' = %s rad must equal 2 pi = %s rad (to 1e-9 rad)", r, two_pi);
    }
    return 0;
}

/* CamProgram.breakpoints(): split points of both laws, dwell ends, reduced, sorted, merged. */
static size_t law_breakpoints(const double rise_T[6], const double return_T[6], double rise_angle, double b1,
                              double b2, double return_angle, double b3, double out[16])
{
    double pts[16];
    size_t n = 0, m = 0, i, j;
    pts[n++] = 0.0;
    for (i = 0; i < 6; i++) {
        pts[n++] = rise_angle * rise_T[i];
    }
    pts[n++] = b1;
    pts[n++] = b2;
    for (i = 0; i < 6; i++) {
        pts[n++] = b2 + return_angle * return_T[i];
    }
    pts[n++] = b3;
    for (i = 0; i < n; i++) {
        pts[i] = fmod(pts[i], TWO_PI);
    }
    for (i = 1; i < n; i++) {  /* insertion sort of 16 values */
        double v = pts[i];
        for (j = i; j > 0 && pts[j - 1] > v; j--) {
            pts[j] = pts[j - 1];
        }
        pts[j] = v;
    }
    for (i = 0; i < n; i++) {
        if (pts[i] >= TWO_PI - 1e-12) {
            continue;  /* 2 pi is 0 */
        }
        if (m == 0 || pts[i] - out[m - 1] > 1e-12) {
            out[m++] = pts[i];
        }
    }
    return m;
}

/* CamProgram.feature_angle(): the smallest beta F (sine, cosine) or beta (end - start) (constant). */
static double law_feature(const CamLaw *law, double beta, double best)
{
    int k;
    for (k = 0; k < law->n_segments; k++) {
        const double *seg = law->segments + CAM_SEGMENT_FIELDS * k;
        double scale = beta * (seg[4] != CAM_SHAPE_CONST ? seg[2] : seg[0] - seg[1]);
        if (scale < best) {
            best = scale;
        }
    }
    return best;
}

int cam_profile_init_laws(CamProfile *p, const double rise_T[6], const double return_T[6], double lift,
                          double rise_angle, double upper_dwell, double return_angle, double lower_dwell,
                          CamError *err)
{
    double angle[4], pts[16], beta, h;
    size_t n;
    memset(p, 0, sizeof *p);
    p->kind = CAM_PROGRAM_LAWS;
    angle[0] = rise_angle;
    angle[1] = upper_dwell;
    angle[2] = return_angle;
    angle[3] = lower_dwell;
    if (cam_law_init(&p->rise, rise_T, "rise", err) ||
        cam_law_init(&p->ret, return_T, "return", err) || check_program(lift, angle, err)) {
        memset(p, 0, sizeof *p);
        return CAM_ERR_PARAMETER;
    }
    p->lift = lift;
    p->b1 = rise_angle;
    p->b2 = p->b1 + upper_dwell;
    p->b3 = p->b2 + return_angle;
    beta = rise_angle;
    h = lift;
    p->kr0 = 1.0 / beta;
    p->kr1 = h / beta;
    p->kr2 = h / pow(beta, 2.0);  /* Python's beta ** 2: libm's pow, as the Python program */
    p->kr3 = h / pow(beta, 3.0);
    beta = return_angle;
    p->kd0 = 1.0 / beta;
    p->kd1 = h / beta;
    p->kd2 = h / pow(beta, 2.0);
    p->kd3 = h / pow(beta, 3.0);
    n = law_breakpoints(rise_T, return_T, rise_angle, p->b1, p->b2, return_angle, p->b3, pts);
    p->points = malloc(n * sizeof *p->points);
    if (p->points == NULL) {
        memset(p, 0, sizeof *p);
        return cam_error(err, CAM_ERR_MEMORY, "cam program: out of memory");
    }
    memcpy(p->points, pts, n * sizeof *pts);
    p->n_points = n;
    p->feature_angle = law_feature(&p->ret, return_angle, law_feature(&p->rise, rise_angle, INFINITY));
    return 0;
}

int cam_profile_init_table(CamProfile *p, const char *text, size_t text_len, CamError *err)
{
    const CamTable *t = &p->table;
    size_t i;
    int status;
    memset(p, 0, sizeof *p);
    if ((status = cam_table_init(&p->table, text, text_len, err)) != CAM_OK) {
        return status;
    }
    p->kind = CAM_PROGRAM_TABLE;
    p->points = t->angle;
    p->n_points = t->n;
    p->feature_angle = t->width[0];
    for (i = 1; i < t->n; i++) {
        if (t->width[i] < p->feature_angle) {
            p->feature_angle = t->width[i];
        }
    }
    for (i = 0; i < t->n; i++) {
        if (t->lift[i] > p->lift) {
            p->lift = t->lift[i];  /* the largest lift [m], as TableProgram.lift */
        }
    }
    return CAM_OK;
}

void cam_profile_free(CamProfile *p)
{
    if (p == NULL) {
        return;
    }
    if (p->kind == CAM_PROGRAM_TABLE) {
        cam_table_free(&p->table);  /* points is the table's array of angles */
    } else {
        free(p->points);
    }
    memset(p, 0, sizeof *p);
}

double cam_angle_mod(double theta)
{
    const double two = 2.0 * TWO_PI;
    if (theta >= 0.0 && theta < TWO_PI)
        return theta;
    if (theta >= TWO_PI && theta < two)
        return theta - TWO_PI;                 /* in [2 pi, 4 pi): exact */
    if (theta >= two && theta < 2.0 * two) {  /* [4 pi, 8 pi): minus 4 pi exact, then maybe minus 2 pi */
        double r = theta - two;
        return r < TWO_PI ? r : r - TWO_PI;
    }
    return fmod(theta, TWO_PI);
}

void cam_profile_eval_counted(const CamProfile *p, double theta, double d[4], size_t *comparisons)
{
    double th, law[4];
    th = cam_angle_mod(theta);  /* [0, 2 pi): a knot is its own reduction, so a table's rows come back exactly */
    if (th < 0.0) {
        th += TWO_PI;
        if (th >= TWO_PI) {  /* -tiny + 2 pi rounds to 2 pi */
            th = 0.0;
        }
    }
    if (p->kind == CAM_PROGRAM_TABLE) {
        cam_table_eval(&p->table, th, d, comparisons);
        return;
    }
    if (th <= p->b1) {
        cam_law_eval(&p->rise, th * p->kr0, law);
        d[0] = p->lift * law[0];
        d[1] = p->kr1 * law[1];
        d[2] = p->kr2 * law[2];
        d[3] = p->kr3 * law[3];
    } else if (th <= p->b2) {
        d[0] = p->lift;
        d[1] = d[2] = d[3] = 0.0;
    } else if (th <= p->b3) {
        cam_law_eval(&p->ret, (th - p->b2) * p->kd0, law);
        d[0] = p->lift * (1.0 - law[0]);
        d[1] = -p->kd1 * law[1];
        d[2] = -p->kd2 * law[2];
        d[3] = -p->kd3 * law[3];
    } else {
        d[0] = d[1] = d[2] = d[3] = 0.0;
    }
}

void cam_profile_eval(const CamProfile *p, double theta, double d[4])
{
    cam_profile_eval_counted(p, theta, d, NULL);
}

/* ---- the first breakpoint crossed ------------------------------------------------------------
 * kinematics.cam_program.first_angle_crossed computes, for every point p, the crossing angle
 *   forward:  K = ceil((start - p) / 2 pi),  a = p + K 2 pi,  a <= start ? a + 2 pi : a   (smallest wins)
 *   backward: K = floor((start - p) / 2 pi), a = p + K 2 pi,  a >= start ? a - 2 pi : a  (largest wins)
 * Rounding is monotone, so over ascending points K never increases (it takes at most 3 values:
 * the points fall into contiguous groups of equal K) and within a group p + K 2 pi never decreases.
 * The extreme of a group is therefore at its ends or where the comparison with start flips, all
 * found by bisection; evaluating the Python formula there gives its result to the bit. */

static double turns(double start, double p, int forward)
{
    double q = (start - p) / TWO_PI;
    return forward ? ceil(q) : floor(q);
}

static double crossing(double start, double p, double K, int forward)
{
    double angle = p + K * TWO_PI;
    if (forward) {
        if (angle <= start) {
            angle += TWO_PI;
        }
    } else if (angle >= start) {
        angle -= TWO_PI;
    }
    return angle;
}

double cam_first_crossed(const double *points, size_t n, double start, double end, size_t *evaluations)
{
    int forward;
    double best;
    size_t lo = 0, count = 0;
    if (end > start) {
        forward = 1;
        best = INFINITY;
    } else if (end < start) {
        forward = 0;
        best = -INFINITY;
    } else {
        return NAN;
    }
    while (lo < n) {
        double K = turns(start, points[lo], forward), c = K * TWO_PI;
        size_t a = lo + 1, b = n, q;
        count++;
        while (a < b) {  /* hi: the first index after lo with a smaller K */
            size_t mid = a + (b - a) / 2;
            count++;
            if (turns(start, points[mid], forward) < K) {
                b = mid;
            } else {
                a = mid + 1;
            }
        }
        {
            size_t hi = a;
            a = lo;
            b = hi;
            while (a < b) {  /* q: the first index of the group with p + K 2 pi past start */
                size_t mid = a + (b - a) / 2;
                double angle = points[mid] + c;
                count++;
                if (forward ? angle > start : angle >= start) {
                    b = mid;
                } else {
                    a = mid + 1;
                }
            }
            q = a;
            if (forward) {  /* smallest: the group's first point (moved on a turn) or q (not moved) */
                double x = crossing(start, points[lo], K, 1);
                count++;
                if (x < best) {
                    best = x;
                }
                if (q < hi) {
                    x = crossing(start, points[q], K, 1);
                    count++;
                    if (x < best) {
                        best = x;
                    }
                }
            } else {  /* largest: the last point before q (not moved) or the group's last (moved back) */
                double x;
                if (q > lo) {
                    x = crossing(start, points[q - 1], K, 0);
                    count++;
                    if (x > best) {
                        best = x;
                    }
                }
                x = crossing(start, points[hi - 1], K, 0);
                count++;
                if (x > best) {
                    best = x;
                }
            }
            lo = hi;
        }
    }
    if (evaluations != NULL) {
        *evaluations += count;
    }
    if (forward) {
        return best < end ? best : NAN;
    }
    return best > end ? best : NAN;
}

double cam_profile_first_breakpoint(const CamProfile *p, double start, double end)
{
    return cam_first_crossed(p->points, p->n_points, start, end, NULL);
}

size_t cam_profile_sizeof(void)
{
    return sizeof(CamProfile);
}
