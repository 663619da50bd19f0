/* The motion table's parser and interpolant (motion_table.c), used by profile.c only (not the engine's
 * contract). motion_table.c makes and frees a CamTable; profile.c builds a CamProfile around it. */
#ifndef CAM_TABLE_H
#define CAM_TABLE_H

#include "cam_profile.h"

/* A table from the CSV text of a motion table (``text_len`` bytes, not necessarily NUL-terminated; the
 * format and the refusals: docs/cam_design.md). On refusal t is zeroed. cam_table_free releases it. */
int cam_table_init(CamTable *t, const char *text, size_t text_len, CamError *err);
/* Free the table's one allocation; safe on a zeroed table. */
void cam_table_free(CamTable *t);

/* s, s', s'', s''' of the table's interpolant at th [rad], reduced to [0, 2 pi) by the caller (profile.c's
 * cam_profile_eval_counted), into d[0..3] (see CamTable);
 * adds the binary search's knot comparisons to *comparisons when not NULL. */
void cam_table_eval(const CamTable *t, double th, double d[4], size_t *comparisons);

#endif
