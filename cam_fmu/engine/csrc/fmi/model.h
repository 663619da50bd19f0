/* The model contract of the FMI glue (glue.h): what a model gives the glue, as a table of functions, so
 * that one glue serves every model the project ships (cam.fmu's drive in model_cam.c, pi_speed.fmu's
 * controller in model_pi.c, and a third block the same way). FMI-free: no FMI header, no globals.
 *
 * A model is an opaque object (void *m) made by create; every function that can refuse (Model Exchange's
 * included) returns a ModelStatus and leaves its message in message(m), which names the variable or setting
 * and its allowed range: the one message the glue logs. A refused call changes nothing else.
 *
 * Value references run from 0 to vr_end - 1 without gaps; variable() names each one and its kind.
 * vr_cs_end (<= vr_end): where Model Exchange's states and derivatives begin (both versions describe them); the
 * FMI 3.0 independent variable 'time' takes vr_end, its event indicators the references after it (fmi3_me.c).
 *
 * Model Exchange (exchange != NULL): the model integrates nothing itself; the host's solver does, over
 * the functions of ModelExchangeOps, each on the object m. A co-simulation-only model leaves it NULL and
 * the glue refuses Model Exchange with a message.
 */
#ifndef MODEL_H
#define MODEL_H

#include <stddef.h>

typedef enum { MODEL_OK = 0, MODEL_DISCARD = 1, MODEL_ERROR = 2, MODEL_WARNING = 3 } ModelStatus;   /* WARNING: done, message() says what to heed */
typedef enum { MODEL_REAL = 0, MODEL_BOOLEAN = 1, MODEL_STRING = 2 } ModelKind;

/* Model Exchange's reads (fmi2_me.c). */
typedef enum { MODEL_READ_STATES, MODEL_READ_DERIVATIVES, MODEL_READ_INDICATORS, MODEL_READ_NOMINALS } ModelRead;

typedef struct {
    /* After initialisation or a restored initialised state: take the model for the host's solver, or refuse
     * with the reason (a setting that is no ODE). */
    int (*attach)(void *m);
    int (*attached)(const void *m);
    /* Back to not attached (a reset). */
    void (*detach)(void *m);
    /* Outputs at the host's state and inputs (before a get). */
    void (*sync)(void *m);
    int (*set_time)(void *m, double time);
    int (*set_states)(void *m, const double x[], size_t nx);
    int (*read)(void *m, ModelRead which, double values[], size_t n);
    void (*enter_event_mode)(void *m);
    /* One event update; *needed: call again; *values_changed: the states jumped; log: the transition
     * applied, for the host's log (empty if none). */
    int (*event_update)(void *m, int *values_changed, int *needed, char *log, size_t log_len);
    void (*enter_continuous)(void *m);
    /* The guards at a completed integrator step; *enter_event: the host must enter event mode. */
    int (*completed_step)(void *m, int *enter_event);
    /* The state as bytes (state_size long) with what Model Exchange books, the live books unchanged. */
    int (*save)(void *m, unsigned char *buffer, size_t size);
    size_t n_states;       /* the continuous states' count (FMI 3.0's fmi3GetNumberOfContinuousStates) */
    size_t n_indicators;   /* the event indicators' count (fmi3GetNumberOfEventIndicators) */
    /* Directional derivatives at the host's state and inputs: dv_unknown = d(unknowns)/d(knowns) dv_known, each
     * named by value reference (NULL: the model provides none). */
    int (*directional)(void *m, const unsigned unknown[], size_t n_unknown, const unsigned known[], size_t n_known,
                       const double dv_known[], double dv_unknown[]);
} ModelExchangeOps;

typedef struct {
    const char *name;            /* the model identifier: "cam", "pi_speed" */
    unsigned state_magic;        /* the first word of a serialised state of this model */
    unsigned vr_end;             /* one past the last value reference */
    unsigned vr_cs_end;          /* the first of Model Exchange's states and derivatives */
    void *(*create)(void);       /* NULL if out of memory */
    void (*destroy)(void *m);
    void (*reset)(void *m);      /* back to create's state: parameters at their defaults */
    const char *(*message)(const void *m);
    /* The kind and name of value reference vr; 0 if vr is no variable. */
    int (*variable)(unsigned vr, ModelKind *kind, const char **name);
    int (*get_real)(void *m, unsigned vr, double *value);
    int (*check_real)(void *m, unsigned vr, double value);   /* set_real's checks, nothing written */
    int (*set_real)(void *m, unsigned vr, double value);
    int (*get_boolean)(void *m, unsigned vr, int *value);
    int (*set_boolean)(void *m, unsigned vr, int value);
    int (*get_string)(void *m, unsigned vr, const char **value);   /* valid until the next call */
    int (*set_string)(void *m, unsigned vr, const char *value, size_t len);
    /* Validate the parameters together and start at start_time [s]. */
    int (*initialize)(void *m, double start_time);
    int (*initialized)(const void *m);
    /* Advance from t to t + h [s] with the inputs held; MODEL_DISCARD: the state is as before the step. */
    int (*step)(void *m, double t, double h);
    double (*time)(const void *m);   /* s: where the model is (the start time before initialisation) */
    /* The whole state as bytes: size, save, restore (validated whole; a refused blob changes nothing). */
    size_t (*state_size)(const void *m);
    int (*save)(const void *m, unsigned char *buffer, size_t size);
    int (*restore)(void *m, const unsigned char *buffer, size_t size);
    const ModelExchangeOps *exchange;   /* NULL: co-simulation only */
    /* The events of the last step as one line ("" when none; NULL: the model has none), logged under logEvents. */
    const char *(*step_events)(const void *m);
} Model;

/* The model this binary carries: each model file defines it (model_cam.c, model_pi.c), one per binary. */
const Model *model_table(void);

#endif
