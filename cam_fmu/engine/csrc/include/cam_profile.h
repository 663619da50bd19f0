/* The cam program as the engine sees it: s(theta) and its first three derivatives.
 *
 * Two kinds of program: two motion laws (rise and return, each the general
 * harmonic-trapezoid curve with split points T1..T6) with dwells between them,
 * or a user's motion table (angle [deg], lift [mm] rows) interpolated by a
 * shape-preserving periodic piecewise cubic. Both are periodic in theta with
 * period 2 pi. The formulas are docs/model.md sections 1-2 and docs/cam_design.md.
 *
 * C99, libc and libm only, no globals. Every function that can refuse its input
 * returns 0 on success and otherwise writes a message naming the parameter and
 * its allowed range (or the table row) into err[0..err_len-1].
 */
#ifndef CAM_PROFILE_H
#define CAM_PROFILE_H

#include <stddef.h>

#define CAM_LAW_SEGMENTS 7          /* segments of one law */
#define CAM_SEGMENT_FIELDS 7        /* end, start, F, c, kind, V0, S0 per non-empty segment */
#define CAM_SHAPE_CONST 0           /* A = c */
#define CAM_SHAPE_SIN 1             /* A = c sin(x) */
#define CAM_SHAPE_COS 2             /* A = c cos(x) */

typedef enum { CAM_PROGRAM_LAWS = 0, CAM_PROGRAM_TABLE = 1 } CamProgramKind;

/* One dimensionless law: its non-empty segments, CAM_SEGMENT_FIELDS doubles each. */
typedef struct {
    double segments[CAM_LAW_SEGMENTS * CAM_SEGMENT_FIELDS];
    int n_segments;
} CamLaw;

/* A user's motion table after parsing: knots of the periodic interpolant (SI units). */
typedef struct {
    double *angle;      /* rad, strictly increasing, in [0, 2 pi) */
    double *lift;       /* m */
    double *slope;      /* m/rad: Hermite slopes at the knots */
    size_t n;           /* knots */
} CamTable;

typedef struct {
    CamProgramKind kind;
    /* laws */
    CamLaw rise, ret;
    double lift;                    /* m */
    double b1, b2, b3;              /* rad: end of rise, of upper dwell, of return */
    double kr0, kr1, kr2, kr3;      /* 1/beta, h/beta, h/beta^2, h/beta^3 of the rise */
    double kd0, kd1, kd2, kd3;      /* the same of the return */
    /* table */
    CamTable table;
    /* breakpoints of the program (rad, each in [0, 2 pi)), ascending */
    double *points;
    size_t n_points;
    double feature_angle;           /* rad: the program's finest angular detail */
} CamProfile;

/* The law with split points T[0..5] = T1..T6 (checked: finite, in [0, 1], ordered,
 * T3 > 0, T4 < 1); ``name`` names the parameters in messages (e.g. "rise"). */
int cam_law_init(CamLaw *law, const double T[6], const char *name, char *err, size_t err_len);

/* (S, V, A, J) of a dimensionless law at T into out[0..3]; dwells outside [0, 1]. */
void cam_law_eval(const CamLaw *law, double T, double out[4]);

/* A program of two laws and dwells; the four angles must sum to 2 pi (to 1e-9 rad). */
int cam_profile_init_laws(CamProfile *p, const double rise_T[6], const double return_T[6], double lift,
                          double rise_angle, double upper_dwell, double return_angle, double lower_dwell,
                          char *err, size_t err_len);

/* A program from the CSV text of a motion table (see docs/cam_design.md for the format and the
 * refusals); ``text_len`` bytes, not necessarily NUL-terminated. */
int cam_profile_init_table(CamProfile *p, const char *text, size_t text_len, char *err, size_t err_len);

/* Free what an init allocated; safe on a zeroed or already freed profile. */
void cam_profile_free(CamProfile *p);

/* s [m], ds/dtheta [m/rad], d2s/dtheta2, d3s/dtheta3 at theta [rad] into d[0..3]. */
void cam_profile_eval(const CamProfile *p, double theta, double d[4]);

/* The first breakpoint angle [rad] strictly between start and end in the direction of travel
 * (periodic: the angle itself, not reduced), or NaN when none; O(log n_points). */
double cam_profile_first_breakpoint(const CamProfile *p, double start, double end);

#endif
