/* The motion table's internals shared by profile.c and motion_table.c (not the engine's contract). */
#ifndef CAM_TABLE_H
#define CAM_TABLE_H

#include "cam_profile.h"

/* s, s', s'', s''' of the table's interpolant at theta [rad] into d[0..3] (see CamTable);
 * adds the binary search's knot comparisons to *comparisons when not NULL. */
void cam_table_eval(const CamTable *t, double theta, double d[4], size_t *comparisons);

#endif
