/* The formulations of the drive, by id (physics/formulations: FORMULATIONS): each is const data in its
 * own file (consistent.c, paper.c, speed.c). */
#include <stddef.h>

#include "cam_drive.h"

const CamFormulation *cam_formulation(CamFormulationId id)
{
    switch (id) {
    case CAM_FORM_CONSISTENT:
        return &cam_consistent;
    case CAM_FORM_PAPER:
        return &cam_paper;
    case CAM_FORM_SPEED:
        return &cam_speed;
    default:
        return NULL;
    }
}
