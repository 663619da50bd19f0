/* What the two files of cam.fmu's FMI 2.0 glue share (fmi2.c: common and co-simulation functions;
 * fmi2_me.c: Model Exchange): the instance over the shared glue (glue.h). Private to the glue. */
#ifndef CAM_FMI2_GLUE_H
#define CAM_FMI2_GLUE_H

#include "fmi2Functions.h"
#include "glue.h"

#define INSTANCE_MAGIC 0x63616d32u   /* 'cam2': a pointer a host passes is checked to be an instance */

typedef struct {
    Glue glue;
    fmi2CallbackLogger logger;
    fmi2ComponentEnvironment environment;
} Instance;

/* The instance behind a component a host passes, or NULL (NULL, freed, or not an instance). */
Instance *instance(fmi2Component c);

#define GLUE(c) (&instance(c)->glue)

#endif
