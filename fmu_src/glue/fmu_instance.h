/* What the FMI 2.0 and FMI 3.0 glue (fmi2_cosim.c, fmi3_cosim.c) do the same
 * way: an instance of a model with its name, its place in the version's
 * call-sequence state machine, logging with categories, and the FMU state as
 * checked, platform-independent bytes. No FMI types: statuses are numerically
 * equal to both versions' (OK, Warning, Discard, Error). */
#ifndef FRACCONTACT_FMU_INSTANCE_H
#define FRACCONTACT_FMU_INSTANCE_H

#include <stddef.h>

#include "fmu_interface.h"

typedef enum { FI_OK = 0, FI_WARNING = 1, FI_DISCARD = 2, FI_ERROR = 3 } fi_status;

#define FI_CATEGORIES 4 /* logEvents, logCalls, logStatusWarning, logStatusError */

typedef struct fmu_instance fmu_instance;
typedef struct fv_values fv_values; /* fixed_values.c's */

/* How a version hands a message to the master's logger. */
typedef void (*fi_sink)(const fmu_instance *in, fi_status status, const char *category, const char *message);

/* A version's instance starts with this (its callbacks follow). */
struct fmu_instance {
    char *name;
    int state; /* one bit of the version's state machine */
    int model_exchange; /* instantiated for Model Exchange (else co-simulation) */
    int logging_on;
    unsigned char category_on[FI_CATEGORIES];
    double start_time;
    double stop_time; /* the experiment's, INFINITY when the master gives none */
    fmu_model *fm;
    fi_sink sink;
    fv_values *fixed; /* an exported FMU's fixed values (fixed_values.h), NULL in the full FMU */
};

/* A probe: an instance that can only log (before one exists). */
void fi_probe(fmu_instance *in, const char *name, fi_sink sink);

/* The name copied and a model made; 0 (and a logged error) when memory runs out. */
int fi_init(fmu_instance *in, const char *name, fi_sink sink, int logging_on, int state);
void fi_release(fmu_instance *in);

/* Errors and warnings always reach the user; the other categories only when
 * the master switched them on. */
void fi_log(const fmu_instance *in, fi_status status, const char *category, const char *message);

#if defined(__GNUC__)
__attribute__((format(printf, 2, 3)))
#endif
fi_status fi_fail(const fmu_instance *in, const char *fmt, ...);

/* The names of the version's states, fi_state_names[i] that of the state
 * 1 << i (NULL where no state has that bit): defined by its glue. */
#define FI_STATE_BITS 8
extern const char *const fi_state_names[FI_STATE_BITS];

/* Whether function `name` may be called in the current state (a bit mask
 * of the version's states); logs the call when asked to, and a refusal
 * naming the function, the state and the states it is allowed in. */
int fi_allowed(fmu_instance *in, int states, const char *name);

/* Whether an array of n > 0 values is missing (after logging an error). */
int fi_null_arrays(const fmu_instance *in, size_t n, const void *a, const void *b, const char *name);

/* Whether an array of n values (a Model Exchange call's states, derivatives
 * or indicators) is missing or not the `expected` count the FMU has, after
 * logging an error naming `what`. */
int fi_wrong_count(fmu_instance *in, const void *array, size_t n, size_t expected, const char *what,
                   const char *name);

fi_status fi_set_debug_logging(fmu_instance *in, int logging_on, size_t n, const char *const categories[],
                               const char *name);

/* FI_OK if a step from t of size H may be taken, else FI_ERROR after a log:
 * both finite, H > 0 (or 0 where zero_allowed: FMI 2.0 allows it, 3.0 does
 * not), and t the model's time up to the master's rounding. */
fi_status fi_check_step(const fmu_instance *in, double t, double H, int zero_allowed, const char *name);

/* The step the model takes for a communication step of size H from t: none
 * (0) where t + H rounds to t, since time does not advance (a model that
 * counts its internal steps would still count one); else H. */
double fi_advance(double t, double H);

/* ------------------------------------------------------------ FMU state */

/* An FMU state is its serialized bytes, so that getting, setting,
 * serializing and deserializing share one format and one set of checks.
 * `token` (the GUID or instantiation token) ties it to the FMU; `modes` is
 * the mask of the version's states a state may hold. */
typedef struct fi_state fi_state;

fi_status fi_get_state(fmu_instance *in, fi_state **state, const char *name);
fi_status fi_set_state(fmu_instance *in, const fi_state *state, int modes, const char *name);
void fi_free_state(fi_state **state);
fi_status fi_state_size(const fmu_instance *in, const fi_state *state, size_t *size, const char *name);
fi_status fi_serialize(const fmu_instance *in, const fi_state *state, unsigned char *bytes, size_t size,
                       const char *name);
fi_status fi_deserialize(const fmu_instance *in, const unsigned char *bytes, size_t size, fi_state **state,
                         const char *name);

#endif
