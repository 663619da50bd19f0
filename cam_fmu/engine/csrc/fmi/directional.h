/* Model Exchange's directional derivatives by value reference (directional.c): the engine's tangent (jacobian.c, and
 * jacobian_follower.c for a follower of its own) at the host's state and inputs. FMI-free, like exchange.h. */
#ifndef CAM_DIRECTIONAL_H
#define CAM_DIRECTIONAL_H

#include <stddef.h>

#include "exchange.h"

/* dv_unknown[k] = sum_j d(unknown[k])/d(known[j]) dv_known[j]. Knowns: the continuous states (x_*) and the inputs;
 * unknowns: the state derivatives (der(x_*)) and the outputs. Anything else, or a mode whose tangent is not
 * implemented: an error naming it (cam_instance_error), dv_unknown untouched. */
int cam_exchange_directional(CamExchange *e, const unsigned unknown[], size_t n_unknown, const unsigned known[],
                             size_t n_known, const double dv_known[], double dv_unknown[]);

#endif
