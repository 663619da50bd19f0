/* The cam program as the engine sees it: s(theta) and its first three derivatives.
 *
 * Two kinds of program: two motion laws (rise and return, each the general
 * harmonic-trapezoid curve with split points T1..T6) with dwells between them,
 * or a user's motion table (angle [deg], lift [mm] rows) interpolated by a
 * shape-preserving periodic piecewise cubic. Both are periodic in theta with
 * period 2 pi. The formulas are docs/model.md sections 1-2 and docs/cam_design.md.
 *
 * C99, libc and libm only, no globals. Every function that can refuse its input
 * returns CAM_OK (0) on success and otherwise fills err (cam_error.h) with a message
 * naming the parameter and its allowed range (or the table row) and returns its status.
 */
#ifndef CAM_PROFILE_H
#define CAM_PROFILE_H

#include <stddef.h>

#include "cam_error.h"

#define CAM_SHAPE_CONST 0           /* A = c */
#define CAM_SHAPE_SIN 1             /* A = c sin(x) */
#define CAM_SHAPE_COS 2             /* A = c cos(x) */
/* rad: the shortest rise or return, 0.01 deg (kinematics.cam_program.MIN_STROKE_ANGLE: the stroke's
 * derivatives scale with 1/angle^3, which under- and overflows near 0) */
#define CAM_MIN_STROKE_ANGLE (0.01 * 3.141592653589793 / 180.0)

#define CAM_TABLE_MAX_ROWS 10000000     /* rows of a motion table, at most */
#define CAM_TABLE_MAX_LIFT_MM 10000.0   /* mm: a table's lifts lie in [0, 10 m], the lift parameter's range */
#define CAM_TABLE_MAX_NUMBER 100        /* characters of one number in a table, at most */
#define CAM_TABLE_MIN_SPACING_DEG 1e-6  /* deg: rows closer than this are refused (the third derivative would overflow) */

/* CAM_LAW_SEGMENTS (segments of one law), CAM_SEGMENT_FIELDS (end, start, F, c, kind, V0, S0 per non-empty
 * segment), CamProgramKind and the structures CamLaw, CamTable and CamProfile are generated from
 * engine/contract.py (cam_contract.h, through cam_error.h): Python's ctypes structures come from the same table.
 * A table's piece i runs from knot i to knot i + 1 (the last to knot 0 + 2 pi); with u = theta - angle[i] in
 * [0, width[i]] and v = u - width[i]:
 *   s = lift[i]   + u (slope[i]   + u (c2[i] + u c3[i]))     for u <= width[i] / 2,
 *   s = lift[i+1] + v (slope[i+1] + v (e2[i] + v c3[i]))     beyond (exact at both knots),
 * s clamped to the range of the piece's two lifts; its arrays are one allocation that starts at angle. A
 * program's breakpoints (rad, each in [0, 2 pi), ascending) are CamProgram.breakpoints() for laws (an allocation
 * of its own), the knots for a table (the array table.angle). */

/* The law with split points T[0..5] = T1..T6 (checked: finite, in [0, 1], ordered,
 * T3 > 0, T4 < 1); ``name`` names the parameters in messages ("rise": "rise law: ...
 * rise_T3=0.0 ..."); NULL or "" gives MotionLaw's own messages ("T3=0.0"). */
int cam_law_init(CamLaw *law, const double T[6], const char *name, CamError *err);

/* (S, V, A, J) of a dimensionless law at T into out[0..3]; dwells outside [0, 1]. */
void cam_law_eval(const CamLaw *law, double T, double out[4]);

/* A program of two laws and dwells (CamProgram's checks: lift finite > 0, angles finite >= 0,
 * rise and return > 0); the four angles must sum to 2 pi to 1e-9 rad (physics/parameters.py's
 * message). */
int cam_profile_init_laws(CamProfile *p, const double rise_T[6], const double return_T[6], double lift,
                          double rise_angle, double upper_dwell, double return_angle, double lower_dwell,
                          CamError *err);

/* A program from the CSV text of a motion table (see docs/cam_design.md for the format and the
 * refusals); ``text_len`` bytes, not necessarily NUL-terminated. O(text_len) time, O(rows) memory. */
int cam_profile_init_table(CamProfile *p, const char *text, size_t text_len, CamError *err);

/* sizeof(CamProfile), for bindings that mirror the structure (ctypes). */
size_t cam_profile_sizeof(void);

/* Free what an init allocated; safe on a zeroed or already freed profile. */
void cam_profile_free(CamProfile *p);

/* fmod(theta, 2 pi), to the bit, without fmod where it is not needed: theta itself on [0, 2 pi); on
 * [2 pi, 8 pi) one or two exact subtractions (Sterbenz: x - y is exact for y <= x <= 2 y, and the
 * subtracted multiples 2 pi and 4 pi are exact doubles); fmod elsewhere. The profile reduces its angle at
 * every evaluation: fmod was 7 % of a step's instructions. */
double cam_angle_mod(double theta);

/* s [m], ds/dtheta [m/rad], d2s/dtheta2, d3s/dtheta3 at theta [rad] into d[0..3].
 * Laws: exactly kinematics.cam_program.CamProgram.derivatives (a NaN or infinite theta gives the lower dwell there).
 * Tables: the piece ending at a knot (left limit; knot 0 ends the last piece); O(log n);
 * a NaN or infinite theta gives NaN. */
void cam_profile_eval(const CamProfile *p, double theta, double d[4]);

/* cam_profile_eval that also adds to *comparisons (if not NULL) the knot comparisons of a
 * table's binary search (at most ceil(log2(n + 1))): the complexity, observable in tests. */
void cam_profile_eval_counted(const CamProfile *p, double theta, double d[4], size_t *comparisons);

/* The first breakpoint angle [rad] strictly between start and end in the direction of travel
 * (periodic: the angle itself, not reduced), or NaN when none; O(log n_points). */
double cam_profile_first_breakpoint(const CamProfile *p, double start, double end);

/* The same over ascending points[0..n-1] in [0, 2 pi): kinematics.cam_program.first_angle_crossed's result
 * to the bit. Adds to *evaluations (if not NULL) the number of points whose crossing angle it
 * computed: a few per group of equal turn counts (at most 3 groups), O(log n) comparisons. */
double cam_first_crossed(const double *points, size_t n, double start, double end, size_t *evaluations);

#endif
