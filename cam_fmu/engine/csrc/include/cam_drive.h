/* One cam drive as its hosts see it: variables by value reference, initialisation, communication
 * steps, outputs, and the saved state. The FMI glue (csrc/fmi/) and the Python binding
 * (cam_fmu/engine/simulator.py) both call only these functions; the physics behind them is the
 * model contract (cam_model.h) advanced by the solvers (cam_solver.h).
 *
 * Value references are those of the generated variable table (cam_variables.h, generated from
 * cam_fmu/physics/parameters.py and variables.py): the inputs, then the outputs, then the
 * parameters, in table order, from 0.
 *
 * Every function that can refuse returns CAM_ERROR (or CAM_DISCARD for a step the solver cannot
 * complete at this size) and leaves its message, which names the variable or setting and its
 * allowed range, in cam_drive_message(). A refused call changes nothing. No globals.
 */
#ifndef CAM_DRIVE_H
#define CAM_DRIVE_H

#include <stddef.h>

typedef enum { CAM_OK = 0, CAM_DISCARD = 1, CAM_ERROR = 2 } CamStatus;

typedef struct CamDrive CamDrive;

/* A new drive: parameters at their defaults, inputs at their start values; NULL if out of memory. */
CamDrive *cam_drive_new(void);
void cam_drive_free(CamDrive *d);

/* Back to the state of cam_drive_new (parameters at their defaults, not initialised). */
void cam_drive_reset(CamDrive *d);

/* The message of the last refusal (empty if none); valid until the next call on d. */
const char *cam_drive_message(const CamDrive *d);

/* Variables. Setting a parameter is allowed only before cam_drive_initialize; an input any time;
 * an output never. A value outside its range is refused with the variable's name and range.
 * Getting an output before initialisation computes it from the parameters and inputs. */
CamStatus cam_drive_get_real(CamDrive *d, unsigned vr, double *value);
CamStatus cam_drive_set_real(CamDrive *d, unsigned vr, double value);
CamStatus cam_drive_check_real(const CamDrive *d, unsigned vr, double value, char *err, size_t err_len);
CamStatus cam_drive_get_boolean(CamDrive *d, unsigned vr, int *value);
CamStatus cam_drive_set_boolean(CamDrive *d, unsigned vr, int value);
/* Strings are copied in (len bytes, UTF-8, no NUL needed) and out (valid until the next call). */
CamStatus cam_drive_get_string(CamDrive *d, unsigned vr, const char **value);
CamStatus cam_drive_set_string(CamDrive *d, unsigned vr, const char *value, size_t len);

/* Validate the parameters together, build the cam program and the initial state at start_time [s]. */
CamStatus cam_drive_initialize(CamDrive *d, double start_time);
int cam_drive_initialized(const CamDrive *d);

/* Advance from t to t + h [s] with the inputs held; t must be where the drive is (to rounding).
 * CAM_DISCARD: the state is as before the step (restore or retry a shorter step). */
CamStatus cam_drive_step(CamDrive *d, double t, double h);
double cam_drive_time(const CamDrive *d);

/* The outputs in table order (cam_variables.h), current for the state and inputs. */
const double *cam_drive_outputs(CamDrive *d);

/* The whole state as bytes: size, save into a buffer of that size, restore (validated whole:
 * a blob of another build, a truncated or edited blob whose values are not a valid state is
 * refused with what is wrong, and nothing changes). */
size_t cam_drive_state_size(const CamDrive *d);
CamStatus cam_drive_save(const CamDrive *d, unsigned char *buffer, size_t size);
CamStatus cam_drive_restore(CamDrive *d, const unsigned char *buffer, size_t size);

#endif
