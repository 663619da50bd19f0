/* What the two files of the FMI 2.0 glue share (fmi2.c: common and co-simulation functions;
 * fmi2_me.c: Model Exchange): the instance over the shared glue (glue.h). Private to the glue. */
#ifndef FMI2_GLUE_H
#define FMI2_GLUE_H

#include "fmi2Functions.h"
#include "glue.h"

#define INSTANCE_MAGIC 0x666d6932u   /* 'fmi2': a pointer a host passes is checked to be an instance */

typedef struct {
    Glue glue;
    fmi2CallbackLogger logger;
    fmi2ComponentEnvironment environment;
} Instance;

/* The instance behind a component a host passes, or NULL (NULL, freed, or not an instance). */
Instance *instance(fmi2Component c);

#define GLUE(c) (&instance(c)->glue)

#endif
