/* The project's FMI front: one C implementation of everything an FMU owes its host before any model
 * code runs, shared by the guard in front of pythonfmu (pythonfmu_guard/) and by the native FMUs
 * (models/<model>/rst_native_*_fmu.c), whatever the FMI version.
 *
 * The core (rst_lifecycle.c: life cycle, steps; rst_call.c: entering and leaving a call; rst_values.c: values; rst_log.c: messages; rst_state.c:
 * FMU states) knows no FMI version. It checks each call against the co-simulation state machine and
 * its arguments against the interface table (generated from the model's interface table): unknown
 * value references, wrong types, variables that may not be set in the current mode, values outside
 * their declared range or non-finite, NULL pointers, a wrong GUID or instantiation token, a step whose
 * time does not continue the previous one. Anything wrong is answered with an error status and a log
 * message naming the variable, its value and what is allowed, and changes nothing. It keeps the value
 * store (every variable as a double, indexed by value reference), the FMU states (versioned,
 * checksummed and validated on restore) and logging. A thin layer per FMI version exports that
 * version's functions and translates its types (rst_fmi2.c, rst_fmi3.c); one FMU binary is built with
 * one of them. A backend (the glue file compiled with the front defines RST_MODEL) supplies the model:
 * it is only ever called with checked arguments, in a legal mode. There is no global mutable state
 * here; each instance is independent.
 */
#ifndef RST_FRONT_H
#define RST_FRONT_H

#include <stddef.h>

#include "rst_variable.h"

#include "rst_prefix.h"
#if defined(RST_PREFIXED)
#define RST_MODEL RST_PREFIXED(RST_MODEL)
#define rst_fmi_prefix RST_PREFIXED(rst_fmi_prefix)
#define rst_is_model_exchange RST_PREFIXED(rst_is_model_exchange)
#define rst_event_mode_used RST_PREFIXED(rst_event_mode_used)
#define rst_time RST_PREFIXED(rst_time)
#define rst_instance_name RST_PREFIXED(rst_instance_name)
#define rst_mode_of RST_PREFIXED(rst_mode_of)
#define rst_start_time RST_PREFIXED(rst_start_time)
#define rst_log RST_PREFIXED(rst_log)
#define rst_log_text RST_PREFIXED(rst_log_text)
#define rst_format_double RST_PREFIXED(rst_format_double)
#endif

typedef struct rst_instance rst_instance;

/* The status of a call, with the numbers FMI 2.0 and FMI 3.0 both give their statuses (the version
 * layers convert by value). */
typedef enum { RST_OK = 0, RST_WARNING = 1, RST_DISCARD = 2, RST_ERROR = 3, RST_FATAL = 4 } rst_status;
/* A value reference (fmi2ValueReference and fmi3ValueReference are both 32-bit unsigned). */
typedef unsigned int rst_vr;

/* What a model-exchange event update tells the host (fmi2NewDiscreteStates' fmi2EventInfo,
 * fmi3UpdateDiscreteStates' out-arguments). */
typedef struct {
    int discrete_states_need_update; /* iterate: call the update again */
    int terminate_simulation;
    int nominals_changed;            /* nominals of the continuous states */
    int states_changed;              /* values of the continuous states */
    int next_event_time_defined;
    double next_event_time;          /* [s] */
} rst_event_update;

/* How an FMI 3.0 co-simulation step that may end at an event ended (rst_model.do_step_to_event). */
typedef struct {
    double reached;      /* [s] the time the step reached: its end, or the event where it returned early */
    int event_pending;   /* an event at `reached` waits for the host's event mode (eventModeUsed) */
} rst_step_end;

/* The co-simulation and model-exchange modes, as bits (sets of modes describe where a call is allowed). FMI 2.0's
 * stepInProgress and stepCanceled never occur (every step here is synchronous), nor FMI 3.0's
 * intermediate-update mode (not offered). RST_MODE_STEP_FAILED: a step returned a discard. RST_MODE_EVENT
 * is model exchange's event mode and, for an FMI 3.0 co-simulation instance of a model with
 * co-simulation events whose host asked for them (eventModeUsed), co-simulation's event mode. */
typedef enum {
    RST_MODE_INSTANTIATED = 1,
    RST_MODE_INITIALIZATION = 2,
    RST_MODE_STEP_COMPLETE = 4,
    RST_MODE_STEP_FAILED = 8,
    RST_MODE_TERMINATED = 16,
    RST_MODE_ERROR = 32,
    RST_MODE_FATAL = 64, /* latched: every later call returns an error without reaching the backend */
    RST_MODE_EVENT = 128,      /* model exchange, and FMI 3.0 co-simulation with eventModeUsed: event mode */
    RST_MODE_CONTINUOUS = 256  /* model exchange: continuous-time mode */
} rst_mode;

/* A model: its identity, its interface table and the backend's hooks. Every hook is optional (NULL:
 * nothing to do, RST_OK). Hooks return an rst_status; RST_ERROR puts the instance into the error
 * mode, RST_FATAL latches it. They log with rst_log. Each hook is named by the FMI 2.0 call that runs
 * it; the FMI 3.0 layer runs it at the same point of the life cycle. */
typedef struct {
    const char *identifier;
    const char *guid;
    const rst_variable *variables; /* indexed by value reference */
    size_t n_variables;
    size_t backend_size;           /* bytes of zeroed backend data allocated with each instance */
    /* Model exchange (a model that offers it; the front refuses it for the others): the continuous
     * states and their derivatives (value references, in the state vector's order), the event
     * indicators. Derivatives and indicators are variables the backend computes in get_outputs;
     * states are variables of the store, which the host sets (the backend's set hook hears of it). */
    int model_exchange;
    size_t n_states;
    const unsigned int *state_vrs, *derivative_vrs;
    size_t n_event_indicators;
    const unsigned int *event_indicator_vrs;

    /* fmi2Instantiate, after the front's checks; `resource_dir` is the resource directory (FMI 2.0:
     * the decoded fmuResourceLocation; FMI 3.0: resourcePath) or NULL when the host gave none.
     * Not RST_OK: no instance. */
    rst_status (*instantiate)(rst_instance *inst, const char *resource_dir, int visible);
    /* fmi2FreeInstance; rst_mode_of(inst) == RST_MODE_FATAL tells that the backend reported RST_FATAL */
    void (*free_instance)(rst_instance *inst);
    rst_status (*setup_experiment)(rst_instance *inst, int tolerance_defined, double tolerance,
                                   double start_time, int stop_time_defined, double stop_time);
    rst_status (*enter_initialization)(rst_instance *inst);
    rst_status (*exit_initialization)(rst_instance *inst);
    /* A check beyond the table, for a value the table allows (e.g. an option this backend does not
     * implement): not RST_OK rejects it (log why). */
    rst_status (*accept)(rst_instance *inst, const rst_variable *var, double value);
    /* The value references `accept` may refuse a value of; the front asks it about no other variable (a
     * host setting an input at every step pays no call for it). NULL: every variable. */
    const unsigned int *accept_vrs;
    size_t n_accept_vrs;
    /* New values for inputs or parameters of one type: already checked and in the store. */
    rst_status (*set)(rst_instance *inst, rst_type type, const rst_vr vr[], size_t n,
                      const double values[]);
    /* Values of outputs and locals: the backend writes them to `values`. NULL: the front reads the store. */
    rst_status (*get_outputs)(rst_instance *inst, rst_type type, const rst_vr vr[], size_t n,
                              double values[]);
    /* fmi2DoStep from `t` [s] over `h` [s] (checked: h > 0, finite, t continues the previous step). */
    rst_status (*do_step)(rst_instance *inst, double t, double h);
    rst_status (*terminate)(rst_instance *inst);
    /* fmi2Reset: the store already holds the start values again */
    rst_status (*reset)(rst_instance *inst);
    /* fmi2GetFMUstate: bring the store's state variables that are not inputs or parameters up to
     * date (the backend keeps them elsewhere) */
    rst_status (*save_state)(rst_instance *inst);
    /* fmi2SetFMUstate: the store holds a validated snapshot; make the backend take every state
     * variable from it */
    rst_status (*restore_state)(rst_instance *inst);
    /* fmi2NewDiscreteStates / fmi3UpdateDiscreteStates (model exchange, event mode, at rst_time):
     * handle the event; `result` starts all zero */
    rst_status (*update_discrete_states)(rst_instance *inst, rst_event_update *result);
    /* fmi2GetNominalsOfContinuousStates / fmi3GetNominalsOfContinuousStates: the scale of each continuous
     * state (> 0, finite) from the store, in the state vector's order. NULL: 1 for every state. A model
     * whose nominals move reports nominals_changed from its event update. */
    void (*nominals)(rst_instance *inst, double nominals[]);
    /* FMI 3.0 co-simulation events (a model that offers them: hasEventMode and mightReturnEarlyFromDoStep;
     * the front refuses eventModeUsed for the others and never returns early for them). When the host
     * asked for event mode or allowed early return at instantiation, fmi3DoStep runs this hook instead
     * of do_step: the step from `t` over `h` (checked as for do_step) ends at the first event inside it
     * when `early_return`, and an event that `event_mode` leaves to the host is reported pending (the
     * host then enters event mode at end->reached; update_discrete_states handles it there, in a
     * co-simulation instance). With neither flag do_step runs, as for every other host. */
    rst_status (*do_step_to_event)(rst_instance *inst, double t, double h, int early_return, int event_mode,
                                   rst_step_end *end);
} rst_model;

/* The model-exchange vectors of a glue's RST_MODEL, from its generated interface header. */
#define RST_MODEL_EXCHANGE_VECTORS                                                                   \
    .n_states = RST_MODEL_N_STATES, .state_vrs = RST_MODEL_STATE_VRS, .derivative_vrs = RST_MODEL_DERIVATIVE_VRS, \
    .n_event_indicators = RST_MODEL_N_EVENT_INDICATORS, .event_indicator_vrs = RST_MODEL_EVENT_INDICATOR_VRS

/* Defined by the glue file compiled together with the front (one model per binary). */
extern const rst_model RST_MODEL;

/* For backends. */
/* What every instance begins with: what a backend reads at nearly every call, read inline (a call
 * into the front per read would cost more than the read). Nothing else of an instance is public. */
typedef struct {
    double *store; /* every variable by value reference */
    void *backend; /* the backend's zeroed backend_size bytes */
} rst_instance_head;
static inline double *rst_store(rst_instance *inst) { return ((rst_instance_head *)(void *)inst)->store; }
static inline void *rst_backend(rst_instance *inst) { return ((rst_instance_head *)(void *)inst)->backend; }
const char *rst_instance_name(const rst_instance *inst);
rst_mode rst_mode_of(const rst_instance *inst);
double rst_start_time(const rst_instance *inst); /* from fmi2SetupExperiment or fmi3EnterInitializationMode (0 before) */
const char *rst_fmi_prefix(const rst_instance *inst); /* "fmi2" or "fmi3": FMI function names in messages */
int rst_is_model_exchange(const rst_instance *inst);    /* instantiated for model exchange */
int rst_event_mode_used(const rst_instance *inst);      /* FMI 3.0 co-simulation: the host asked for event mode */
double rst_time(const rst_instance *inst); /* [s] the current time: start, end of the last step, or set (ME) */
/* Log through the host's logger: RST_WARNING and worse always (they say why a call failed);
 * RST_OK messages only when the host enabled debug logging for logAll. */
void rst_log(rst_instance *inst, rst_status status, const char *format, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
/* The same for a message that is not a format (text from elsewhere, e.g. Python). */
void rst_log_text(rst_instance *inst, rst_status status, const char *category, const char *text);
/* A double as Python's repr() writes it (1e-07, 0.5, 2.0, nan, -inf): messages read the same
 * whichever implementation of the FMU wrote them. `out` needs 32 bytes. */
void rst_format_double(double x, char *out, size_t size);

#endif
