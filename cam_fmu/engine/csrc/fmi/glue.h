/* What the FMI 2.0 and FMI 3.0 glues share, FMI-version neutral and model neutral: the instance's state
 * machine, logging with its message rules, the checks of value references, the variable access, the
 * communication step and the saved states, over the model table of
 * model.h (cam.fmu: model_cam.c; pi_speed.fmu: model_pi.c). fmi2.c and fmi3_cs.c are thin over it; fmi2_me.c
 * and fmi3_me.c are Model Exchange, whole.
 *
 * Statuses are the FMI numbering both versions share: OK 0, Warning 1, Discard 2, Error 3, Fatal 4.
 * Every call name in a message is the version's own ("fmi2GetReal", "fmi3GetFloat64"): the glue passes it.
 * Rules: docs/fmu.md "Errors" (a refused request writes nothing; get arrays are filled with safe values
 * first; a model error puts the instance into the error state; Discard leaves the state as before).
 */
#ifndef CAM_GLUE_H
#define CAM_GLUE_H

#include <stddef.h>

#include "model.h"

enum { GLUE_OK = 0, GLUE_WARNING = 1, GLUE_DISCARD = 2, GLUE_ERROR = 3 };

typedef enum {
    GLUE_INSTANTIATED = 1 << 0,
    GLUE_INITIALIZATION = 1 << 1,
    GLUE_STEP_COMPLETE = 1 << 2,
    GLUE_STEP_FAILED = 1 << 3,   /* after Discard */
    GLUE_ERROR_STATE = 1 << 4,   /* after Error */
    GLUE_TERMINATED = 1 << 5,
    GLUE_EVENT_MODE = 1 << 6,    /* Model Exchange */
    GLUE_CONTINUOUS_TIME_MODE = 1 << 7
} GlueState;

#define GLUE_ME_STATES (GLUE_EVENT_MODE | GLUE_CONTINUOUS_TIME_MODE)
#define GLUE_GET_STATES (GLUE_INITIALIZATION | GLUE_STEP_COMPLETE | GLUE_STEP_FAILED | GLUE_ERROR_STATE \
                         | GLUE_TERMINATED | GLUE_ME_STATES)
#define GLUE_SET_STATES (GLUE_INSTANTIATED | GLUE_INITIALIZATION | GLUE_STEP_COMPLETE | GLUE_ME_STATES)

/* The host's logger as the glue calls it: status, category, and the message (already cut and with every
 * '%' doubled, so printf-style hosts and hosts that cannot see varargs both show it). */
typedef void (*GlueEmit)(void *host, int status, const char *category, const char *message);

typedef struct {
    unsigned magic;               /* the version's magic while alive, 0 once freed */
    const Model *model;           /* the model's table (model_table()) */
    void *m;                      /* the model's object */
    GlueEmit emit;                /* NULL: no logger */
    void *host;                   /* what emit gets back (the version's instance) */
    char *name;
    int logging_on;
    GlueState state;
    double start_time;            /* s */
    double last_successful_time;  /* s */
    const char *version;          /* "fmi2" or "fmi3": names calls and statuses in state names */
    unsigned vr_end;              /* one past the last value reference the version describes */
    int exchange;                 /* a Model Exchange instance: the host's solver runs the model */
} Glue;

/* A saved state: the instance layer's bytes, and the Model Exchange mode it was saved in (0: co-simulation). */
typedef struct {
    size_t size;
    unsigned mode;
    unsigned char bytes[];
} GlueSaved;

/* Set up g (name copied, a new model object; exchange: a Model Exchange instance); 0 when out of memory
 * (then nothing is left allocated). Every variable of the table is addressable (vr_end: the model's). */
int glue_init(Glue *g, const char *name, int logging_on, const char *version, int exchange);
void glue_free(Glue *g);

void glue_log(const Glue *g, int status, const char *category, const char *format, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;
/* A refused request: Error with "call: text"; nothing of the request was done. */
int glue_fail(const Glue *g, const char *call, const char *text);
/* 1 when the instance's state is one of states, else logs the refusal and returns 0. */
int glue_allowed(const Glue *g, int states, const char *call);
/* The model's verdict on initialisation or a step: OK, Discard (state STEP_FAILED) or Error (ERROR_STATE). */
int glue_model_status(Glue *g, int status, const char *call);

/* The life cycle. */
int glue_setup(Glue *g, double start_time, int stop_defined, double stop_time, const char *call);
int glue_enter_initialization(Glue *g, const char *call);
int glue_exit_initialization(Glue *g, const char *call);
int glue_terminate(Glue *g, const char *call);
void glue_reset(Glue *g);

/* Variables: nvr references of one kind; the get calls fill value with safe values before any check. */
int glue_get_reals(Glue *g, const unsigned vr[], size_t nvr, double value[], const char *call);
int glue_get_booleans(Glue *g, const unsigned vr[], size_t nvr, int value[], const char *call);
int glue_get_strings(Glue *g, const unsigned vr[], size_t nvr, const char *value[], const char *call);
int glue_set_reals(Glue *g, const unsigned vr[], size_t nvr, const double value[], const char *call);
int glue_set_booleans(Glue *g, const unsigned vr[], size_t nvr, const int value[], const char *call);
int glue_set_strings(Glue *g, const unsigned vr[], size_t nvr, const char *const value[], const char *call);

/* A communication step from t (where the FMU is, to rounding) over h [s]. */
int glue_do_step(Glue *g, double t, double h, const char *call);

/* FMU states: save (NULL when out of memory), restore, serialise (header + bytes) and back. */
GlueSaved *glue_save(Glue *g);
int glue_restore(Glue *g, const GlueSaved *saved, const char *call);
size_t glue_serialized_size(const GlueSaved *saved);
int glue_serialize(Glue *g, const GlueSaved *saved, unsigned char *out, size_t size, const char *call);
/* A new saved state from serialised bytes into *saved (a former one freed); Error with a message if they are
 * not a serialised state of this model. */
int glue_deserialize(Glue *g, const unsigned char *in, size_t size, GlueSaved **saved, const char *call);

/* Model Exchange's calls and their state machine are fmi2_me.c's and fmi3_me.c's, one per version. */

#endif
