/* One cam drive as an FMI host sees it: variables by value reference, initialisation,
 * communication steps, outputs, and the saved state (parameters included). The FMI glues
 * (csrc/fmi/) call only these functions; the drive behind them is cam_drive.h's CamDrive.
 *
 * Value references are those of the generated table (cam_params.h, generated from
 * cam_fmu/physics/parameters.py and variables.py): the inputs, then the outputs, then the
 * parameters, in table order, from 0; then the continuous states x[CAM_ME_NX] and their derivatives
 * (Model Exchange's; read-only, of the consistent formulation).
 *
 * Every function that can refuse returns a CamStatus other than CAM_OK (CAM_ERR_REJECTED for a step
 * the solver cannot complete at this size: fmi2Discard) and leaves its message, which names the variable or
 * setting and its allowed range, in the instance's one CamError (cam_instance_error; the Model Exchange layer
 * of exchange.h fills the same one). A refused call changes nothing but that message. No globals.
 */
#ifndef CAM_INSTANCE_H
#define CAM_INSTANCE_H

#include <stddef.h>

#include "cam_drive.h"

typedef struct CamInstance CamInstance;

/* physics/variables.py's STATES name every slot of Model Exchange's x[CAM_ME_NX] (cam_model.h's x[CAM_NX], then a
 * free follower's gap and rate: cam_drive.h; a compile error if not) */
typedef char cam_states_name_every_slot[CAM_N_STATES == CAM_ME_NX ? 1 : -1];
#define CAM_VR_END (CAM_VR_DERIVATIVES + CAM_N_STATES)   /* one past the last value reference */

/* The kind and name of value reference vr; 0 if vr is no variable. */
int cam_instance_variable(unsigned vr, CamKind *kind, const char **name);
const char *cam_kind_name(CamKind kind);

/* A new drive: parameters at their defaults, inputs at their start values; NULL if out of memory. */
CamInstance *cam_instance_new(void);
void cam_instance_free(CamInstance *d);

/* Back to the state of cam_instance_new (parameters at their defaults, not initialised). */
void cam_instance_reset(CamInstance *d);

/* The last refusal (status and message; empty if none): the message valid until the next call on d. */
const char *cam_instance_message(const CamInstance *d);
CamError *cam_instance_error(CamInstance *d);

/* Variables. Setting a parameter is allowed only before cam_instance_initialize; an input any time;
 * an output never. A value outside its range is refused with the variable's name and range.
 * Getting an output before initialisation computes it from the parameters and inputs. */
int cam_instance_get_real(CamInstance *d, unsigned vr, double *value);
int cam_instance_set_real(CamInstance *d, unsigned vr, double value);
/* set_real's checks without the write: CAM_OK, or the refusal in cam_instance_message. */
int cam_instance_check_real(CamInstance *d, unsigned vr, double value);
int cam_instance_get_boolean(CamInstance *d, unsigned vr, int *value);
int cam_instance_set_boolean(CamInstance *d, unsigned vr, int value);
/* Strings are copied in (len bytes, UTF-8, no NUL needed) and out (valid until the next call). */
int cam_instance_get_string(CamInstance *d, unsigned vr, const char **value);
int cam_instance_set_string(CamInstance *d, unsigned vr, const char *value, size_t len);

/* Validate the parameters together, build the cam program and the initial state at start_time [s]. */
int cam_instance_initialize(CamInstance *d, double start_time);
int cam_instance_initialized(const CamInstance *d);

/* Advance from t to t + h [s] with the inputs held; t must be where the drive is (to rounding).
 * CAM_ERR_REJECTED: the state is as before the step (restore or retry a shorter step). */
int cam_instance_step(CamInstance *d, double t, double h);
double cam_instance_time(const CamInstance *d);

/* For the Model Exchange layer (exchange.h): the drive (NULL before initialisation) and the inputs
 * as the host set them last (CAM_N_INPUTS, CAM_I_* order). */
CamDrive *cam_instance_drive(CamInstance *d);
const double *cam_instance_inputs(const CamInstance *d);

/* The outputs in table order (cam_params.h, generated), current for the state and inputs. */
const double *cam_instance_outputs(CamInstance *d);

/* The whole state as bytes: size, save into a buffer of that size, restore (validated whole:
 * a blob of another build, a truncated or edited blob whose values are not a valid state is
 * refused with what is wrong, and nothing changes). */
size_t cam_instance_state_size(const CamInstance *d);
int cam_instance_save(const CamInstance *d, unsigned char *buffer, size_t size);
int cam_instance_restore(CamInstance *d, const unsigned char *buffer, size_t size);

#endif
