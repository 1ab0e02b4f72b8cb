/* The project's FMI 2.0 co-simulation front: one C implementation of everything an FMU owes its host
 * before any model code runs, shared by the guard in front of pythonfmu (pythonfmu_guard/) and by the
 * native FMUs (native/).
 *
 * rst_front.c exports every FMI 2.0 co-simulation function. It checks each call against the FMI 2.0
 * co-simulation state machine and its arguments against the interface table (generated from the
 * model's interface table): unknown value references, wrong types, variables that may not be set in the
 * current mode, values outside their declared range or non-finite, NULL pointers, a wrong GUID, a
 * doStep whose time does not continue the previous one. Anything wrong is answered with fmi2Error and
 * a log message naming the variable, its value and what is allowed, and changes nothing. It keeps
 * the value store (every variable as a double, indexed by value reference), the FMU states (versioned,
 * checksummed and validated on restore) and logging. A backend (the glue file compiled with the front
 * defines RST_MODEL) supplies the model: it is only ever called with checked arguments, in a legal
 * mode. There is no global mutable state here; each instance is independent.
 */
#ifndef RST_FRONT_H
#define RST_FRONT_H

#include <stddef.h>

#include "fmi2Functions.h"
#include "rst_variable.h"

#include "rst_prefix.h"
#if defined(FMI2_FUNCTION_PREFIX)
#define RST_MODEL RST_PREFIXED(RST_MODEL)
#define rst_store RST_PREFIXED(rst_store)
#define rst_backend RST_PREFIXED(rst_backend)
#define rst_instance_name RST_PREFIXED(rst_instance_name)
#define rst_mode_of RST_PREFIXED(rst_mode_of)
#define rst_start_time RST_PREFIXED(rst_start_time)
#define rst_log RST_PREFIXED(rst_log)
#define rst_log_text RST_PREFIXED(rst_log_text)
#define rst_format_double RST_PREFIXED(rst_format_double)
#endif

typedef struct rst_instance rst_instance;

/* The FMI 2.0 co-simulation modes, as bits (sets of modes describe where a call is allowed).
 * stepInProgress and stepCanceled never occur: every step here is synchronous. */
typedef enum {
    RST_INSTANTIATED = 1,
    RST_INITIALIZATION = 2,
    RST_STEP_COMPLETE = 4,
    RST_STEP_FAILED = 8,
    RST_TERMINATED = 16,
    RST_ERROR = 32,
    RST_FATAL = 64 /* latched: every later call returns fmi2Error without reaching the backend */
} rst_mode;

/* A model: its identity, its interface table and the backend's hooks. Every hook is optional (NULL:
 * nothing to do, fmi2OK). Hooks return an fmi2Status; fmi2Error puts the instance into the error
 * mode, fmi2Fatal latches it. They log with rst_log. */
typedef struct {
    const char *identifier;
    const char *guid;
    const rst_variable *variables; /* indexed by value reference */
    size_t n_variables;
    size_t backend_size;           /* bytes of zeroed backend data allocated with each instance */

    /* fmi2Instantiate, after the front's checks; `resource_dir` is the decoded fmuResourceLocation
     * (a directory path) or NULL when the host gave none. Not fmi2OK: no instance. */
    fmi2Status (*instantiate)(rst_instance *inst, const char *resource_dir, fmi2Boolean visible);
    /* fmi2FreeInstance; rst_mode_of(inst) == RST_FATAL tells that the backend reported fmi2Fatal */
    void (*free_instance)(rst_instance *inst);
    fmi2Status (*setup_experiment)(rst_instance *inst, fmi2Boolean tolerance_defined, double tolerance,
                                   double start_time, fmi2Boolean stop_time_defined, double stop_time);
    fmi2Status (*enter_initialization)(rst_instance *inst);
    fmi2Status (*exit_initialization)(rst_instance *inst);
    /* A check beyond the table, for a value the table allows (e.g. an option this backend does not
     * implement): not fmi2OK rejects it (log why). */
    fmi2Status (*accept)(rst_instance *inst, const rst_variable *var, double value);
    /* New values for inputs or parameters of one type: already checked and in the store. */
    fmi2Status (*set)(rst_instance *inst, rst_type type, const fmi2ValueReference vr[], size_t n,
                      const double values[]);
    /* Values of outputs and locals: the backend writes them to `values`. NULL: the front reads the store. */
    fmi2Status (*get_outputs)(rst_instance *inst, rst_type type, const fmi2ValueReference vr[], size_t n,
                              double values[]);
    /* fmi2DoStep from `t` [s] over `h` [s] (checked: h > 0, finite, t continues the previous step). */
    fmi2Status (*do_step)(rst_instance *inst, double t, double h);
    fmi2Status (*terminate)(rst_instance *inst);
    /* fmi2Reset: the store already holds the start values again */
    fmi2Status (*reset)(rst_instance *inst);
    /* fmi2GetFMUstate: bring the store's state variables that are not inputs or parameters up to
     * date (the backend keeps them elsewhere) */
    fmi2Status (*save_state)(rst_instance *inst);
    /* fmi2SetFMUstate: the store holds a validated snapshot; make the backend take every state
     * variable from it */
    fmi2Status (*restore_state)(rst_instance *inst);
} rst_model;

/* Defined by the glue file compiled together with the front (one model per binary). */
extern const rst_model RST_MODEL;

/* For backends. */
double *rst_store(rst_instance *inst);         /* every variable by value reference */
void *rst_backend(rst_instance *inst);         /* the backend's zeroed backend_size bytes */
const char *rst_instance_name(const rst_instance *inst);
rst_mode rst_mode_of(const rst_instance *inst);
double rst_start_time(const rst_instance *inst); /* from fmi2SetupExperiment (0 before) */
/* Log through the host's logger: fmi2Warning and worse always (they say why a call failed);
 * fmi2OK messages only when the host enabled debug logging for logAll. */
void rst_log(rst_instance *inst, fmi2Status status, const char *format, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
/* The same for a message that is not a format (text from elsewhere, e.g. Python). */
void rst_log_text(rst_instance *inst, fmi2Status status, const char *category, const char *text);
/* A double as Python's repr() writes it (1e-07, 0.5, 2.0, nan, -inf): messages read the same
 * whichever implementation of the FMU wrote them. `out` needs 32 bytes. */
void rst_format_double(double x, char *out, size_t size);

#endif
