/* The formulations of the drive, by id (physics/formulations/__init__.py FORMULATIONS). */
#include <stddef.h>

#include "cam_model.h"

const CamFormulation *cam_formulation(CamFormulationId id)
{
    switch (id) {
    case CAM_FORM_CONSISTENT:
        return &cam_consistent;
    default:
        return NULL;   /* the paper's algorithm and the speed drive: not yet ported (their entries go here) */
    }
}
