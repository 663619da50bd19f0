/* The formulations of the drive, by the model's id (physics/formulations: FORMULATIONS) and its follower: each is
 * const data in its own file (consistent.c, paper.c, speed.c; cam_voltage_follower, the consistent formulation with a
 * follower of its own). */
#include <stddef.h>

#include "cam_drive.h"

const CamFormulation *cam_formulation(const CamModel *m)
{
    switch (m->formulation) {
    case CAM_FORM_CONSISTENT:
        return m->free_follower ? &cam_voltage_follower : &cam_consistent;
    case CAM_FORM_PAPER:
        return &cam_paper;
    case CAM_FORM_SPEED:
        return m->free_follower ? &cam_speed_follower : &cam_speed;
    default:
        return NULL;
    }
}
