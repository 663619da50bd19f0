/* What the two files of the FMI 3.0 glue share (fmi3_cs.c: common and co-simulation functions;
 * fmi3_me.c: Model Exchange): the instance over the shared glue (glue.h). Private to the glue. */
#ifndef FMI3_GLUE_H
#define FMI3_GLUE_H

#include "fmi3Functions.h"
#include "glue.h"

#define INSTANCE_MAGIC 0x666d6933u   /* 'fmi3': a pointer a host passes is checked to be an instance */

typedef struct {
    Glue glue;
    fmi3LogMessageCallback logger;
    fmi3InstanceEnvironment environment;
} Instance;

/* The instance behind a pointer a host passes, or NULL (NULL, freed, or not an instance). */
Instance *instance(fmi3Instance c);

#define GLUE(c) (&instance(c)->glue)
#define STATUS(x) ((fmi3Status)(x))

/* A new instance (exchange: Model Exchange) after the checks every instantiation shares (a name, this binary's
 * token); NULL with the reason logged under call. */
Instance *fmi3_instantiate(fmi3String instanceName, fmi3String instantiationToken, fmi3Boolean loggingOn,
                           fmi3InstanceEnvironment environment, fmi3LogMessageCallback logMessage, int exchange,
                           const char *call);
/* A refused instantiation: the message through the host's logger (no instance). */
void fmi3_refuse_instantiation(const char *name, fmi3InstanceEnvironment environment,
                               fmi3LogMessageCallback logger, const char *call, const char *why);
/* A call the FMU (or this instance) does not offer: fmi3Error with why. */
fmi3Status fmi3_unsupported(fmi3Instance c, const char *call, const char *why);

/* The value references FMI 3.0 adds after the model's table: 'time' (vr_end), then the event indicators. */
int fmi3_own_variable(fmi3ValueReference vr);
/* Event indicator k (fmi3_me.c) into *value; GLUE_ERROR with the reason where there is none to read. */
int fmi3_me_indicator(Glue *g, size_t k, fmi3Float64 *value, const char *call);

#endif
