/* What the front's files share (not for backends: they use rst_front.h). */
#ifndef RST_FRONT_INTERNAL_H
#define RST_FRONT_INTERNAL_H

/* Every instance has a lock (FMI does not ask one instance to be thread-safe; these are), whatever
 * the build command: POSIX threads, or a slim reader/writer lock on Windows. RST_FRONT_NO_LOCK leaves
 * it out for a platform with neither. With POSIX threads and a compiler with the GCC/Clang __atomic
 * builtins (gcc, clang, zig cc) the lock is a word taken with one compare-and-swap and given back with
 * a plain release store and a read of the waiters' count where no other thread wants it (the common
 * case: FMI asks nothing of a host that calls one instance from several threads; an exchange would cost
 * a locked instruction per call); a thread that finds it taken waits on a POSIX condition variable
 * (RST_LOCK_ATOMIC, below). Elsewhere it is a plain pthread mutex. */
#if !defined(RST_FRONT_NO_LOCK)
#if defined(_WIN32)
#define RST_LOCK_WIN32
#else
#define RST_LOCK_PTHREAD
#if (defined(__GNUC__) || defined(__clang__)) && defined(__ATOMIC_ACQUIRE) && !defined(RST_FRONT_PLAIN_MUTEX)
#define RST_LOCK_ATOMIC
#endif
#if !defined(_POSIX_C_SOURCE)
#define _POSIX_C_SOURCE 200809L
#endif
#endif
#endif

#include "rst_front.h"

#if defined(RST_PREFIXED)
#define front_lock_contended RST_PREFIXED(front_lock_contended)
#define front_wake_waiter RST_PREFIXED(front_wake_waiter)
#define front_unlock_and_deliver RST_PREFIXED(front_unlock_and_deliver)
#define front_refuse_mode RST_PREFIXED(front_refuse_mode)
#define front_mode_name RST_PREFIXED(front_mode_name)
#define front_describe_value RST_PREFIXED(front_describe_value)
#define front_type_name RST_PREFIXED(front_type_name)
#define front_reset_store RST_PREFIXED(front_reset_store)
#define front_take_messages RST_PREFIXED(front_take_messages)
#define front_deliver_messages RST_PREFIXED(front_deliver_messages)
#define front_free_states RST_PREFIXED(front_free_states)
#define front_new_instance RST_PREFIXED(front_new_instance)
#define front_instantiate RST_PREFIXED(front_instantiate)
#define front_discard_instance RST_PREFIXED(front_discard_instance)
#define front_free_instance RST_PREFIXED(front_free_instance)
#define front_set RST_PREFIXED(front_set)
#define front_get RST_PREFIXED(front_get)
#define front_refuse_type RST_PREFIXED(front_refuse_type)
#define front_setup_experiment RST_PREFIXED(front_setup_experiment)
#define front_enter_initialization RST_PREFIXED(front_enter_initialization)
#define front_exit_initialization RST_PREFIXED(front_exit_initialization)
#define front_terminate RST_PREFIXED(front_terminate)
#define front_reset RST_PREFIXED(front_reset)
#define front_do_step RST_PREFIXED(front_do_step)
#define front_refuse RST_PREFIXED(front_refuse)
#define front_enter_event_mode RST_PREFIXED(front_enter_event_mode)
#define front_enter_step_mode RST_PREFIXED(front_enter_step_mode)
#define front_enter_continuous_time_mode RST_PREFIXED(front_enter_continuous_time_mode)
#define front_update_discrete_states RST_PREFIXED(front_update_discrete_states)
#define front_completed_integrator_step RST_PREFIXED(front_completed_integrator_step)
#define front_set_time RST_PREFIXED(front_set_time)
#define front_set_continuous_states RST_PREFIXED(front_set_continuous_states)
#define front_get_continuous_states RST_PREFIXED(front_get_continuous_states)
#define front_get_derivatives RST_PREFIXED(front_get_derivatives)
#define front_get_event_indicators RST_PREFIXED(front_get_event_indicators)
#define front_get_nominals RST_PREFIXED(front_get_nominals)
#define front_get_sizes RST_PREFIXED(front_get_sizes)
#define front_read RST_PREFIXED(front_read)
#define front_set_debug_logging RST_PREFIXED(front_set_debug_logging)
#define front_decode_file_uri RST_PREFIXED(front_decode_file_uri)
#define front_get_state RST_PREFIXED(front_get_state)
#define front_set_state RST_PREFIXED(front_set_state)
#define front_free_state RST_PREFIXED(front_free_state)
#define front_serialized_size RST_PREFIXED(front_serialized_size)
#define front_serialize RST_PREFIXED(front_serialize)
#define front_deserialize RST_PREFIXED(front_deserialize)
#endif

#include <math.h>

#if defined(RST_LOCK_PTHREAD)
#include <pthread.h>
#elif defined(RST_LOCK_WIN32)
#include <windows.h>
#endif

#define RST_INSTANCE_MAGIC 0x52535446u /* "RSTF": a pointer that is not one of our instances */
#define RST_STATE_MAGIC 0x52535453u    /* "RSTS" */
#define RST_ALL_CATEGORIES 31u         /* the five log categories, all on */

#define ME_MODES (RST_MODE_EVENT | RST_MODE_CONTINUOUS)
#define ANY_LIVE_MODE (RST_MODE_INSTANTIATED | RST_MODE_INITIALIZATION | RST_MODE_STEP_COMPLETE | RST_MODE_STEP_FAILED | \
                       RST_MODE_TERMINATED | RST_MODE_ERROR | ME_MODES)
#define GET_MODES (RST_MODE_INITIALIZATION | RST_MODE_STEP_COMPLETE | RST_MODE_STEP_FAILED | RST_MODE_TERMINATED | \
                   RST_MODE_ERROR | ME_MODES)
#define SET_MODES (RST_MODE_INSTANTIATED | RST_MODE_INITIALIZATION | RST_MODE_STEP_COMPLETE | ME_MODES)

/* A message waiting to reach the host's logger: messages of a call are delivered after the call has
 * released the instance's lock, so a logger may call back into the same instance (FMI 2.0 does not
 * forbid it) without deadlocking, and finds the instance in a consistent state. */
typedef struct rst_message {
    struct rst_message *next;
    rst_status status;
    const char *category; /* points into text[], after the message */
    char text[1];         /* the message (its '%' doubled), NUL, the category, NUL */
} rst_message;

/* An FMU state. Its words are kept as they were read (a deserialized or host-overwritten state may
 * hold anything): rst_state.c checks them (one mode of the interface, flags 0 or 1, the interface of
 * the instance) before any reaches the instance. */
typedef struct rst_state {
    unsigned int magic;
    struct rst_state *next;
    unsigned int mode;           /* one rst_mode bit */
    unsigned int model_exchange; /* the interface it was taken from: 0 co-simulation, 1 model exchange */
    unsigned int has_start, has_time;
    double start_time, next_time, last_time;
    double values[1]; /* one per state variable of the table (allocated to size) */
} rst_state;

/* What an FMI version layer tells the core: its names, and how a message reaches the host. */
typedef struct {
    const char *prefix;     /* "fmi2" or "fmi3": the front of every FMI function name in messages */
    const char *standard;   /* "FMI 2.0" or "FMI 3.0" */
    const char *token_name; /* what the instantiation checks: "GUID" or "instantiation token" */
    /* the FMU-state functions, whose spelling differs between the versions */
    const char *get_state, *set_state, *deserialize_state, *serialized_state_size;
    /* the names of the access kinds (rst_access, by bit: Real, Integer, Boolean, Enumeration) */
    const char *type_names[4];
    /* 1: value reference n_variables is the independent variable `time` (FMI 3.0 declares one), Real
     * and read-only */
    int time_variable;
    /* hands one message to the host's logger, of the layer's type (cast back from host_logger) */
    void (*emit)(void (*host_logger)(void), void *environment, const char *instance_name, rst_status status,
                 const char *category, const char *message);
} rst_api;

typedef void *(*rst_allocate_fn)(size_t n, size_t size); /* zeroed, as calloc */
typedef void (*rst_release_fn)(void *pointer);

struct rst_instance {
    rst_instance_head head; /* first: the store and the backend data, which backends read inline (rst_front.h) */
    unsigned int magic;
    const rst_model *model;
    const rst_api *api;
    int model_exchange; /* instantiated for model exchange (else co-simulation) */
    /* FMI 3.0 co-simulation, as the host instantiated it: event mode used (initialization ends in event
     * mode, an event inside a step waits for the host there), early return allowed (a step ends at the
     * first event inside it). Both 0 for FMI 2.0 and model exchange. */
    int event_mode_used, early_return_allowed;
    char *name;
    void (*host_logger)(void); /* the host's logger, of the version layer's type (api->emit casts it back) */
    void *environment;         /* what the host passes back to its logger */
    rst_allocate_fn allocate;
    rst_release_fn release;
    int logging_on;
    unsigned int categories;
    rst_mode mode;
    int has_start;      /* the start time is known (fmi2SetupExperiment, fmi3EnterInitializationMode) */
    double start_time;
    int has_time;       /* next_time is known: the t the next step must have */
    double next_time;
    double last_time;   /* end of the last successful step (fmi2LastSuccessfulTime); model exchange: the time set */
    rst_status last_step_status;
    size_t n_state;     /* state variables of the table */
    rst_state *states;  /* FMU states made by this instance, to tell ours from any other pointer */
    int in_call;              /* set while a call holds the instance: its messages wait in `pending` */
    rst_message *pending;     /* in the order they were logged */
    rst_message **pending_end;
#if defined(RST_LOCK_ATOMIC)
    int lock_word;            /* 0 free, 1 held */
    int waiting;              /* threads waiting for the word (changed under `lock`, read by whoever frees it) */
    pthread_mutex_t lock;     /* guards the waiting: threads that found the word taken wait on `waiters` */
    pthread_cond_t waiters;
#elif defined(RST_LOCK_PTHREAD)
    pthread_mutex_t lock;
#elif defined(RST_LOCK_WIN32)
    SRWLOCK lock;
#endif
};

/* How the version layers name the variable types a get or set call is for (a variable's access kind:
 * its rst_type, and Enumeration for an Integer with named codes, which FMI 3.0 gets and sets with the
 * Int64 functions). A call passes the set of kinds it may touch. */
typedef enum { RST_AS_REAL = 1, RST_AS_INTEGER = 2, RST_AS_BOOLEAN = 4, RST_AS_ENUMERATION = 8 } rst_access;

/* The experiment an FMI 3.0 fmi3EnterInitializationMode (or FMI 2.0 fmi2SetupExperiment) gives. */
typedef struct {
    int tolerance_defined;
    double tolerance;
    double start_time;
    int stop_time_defined;
    double stop_time;
} rst_experiment;

/* Converters between the version's value arrays and the core's doubles: elements first ... first + n - 1
 * of `values`, a whole run per call (a get or set of many values pays one indirect call per run, not one
 * per value). RST_CONVERTERS defines a pair from the conversion of one element. */
/* A NULL converter: the values are doubles already (FMI 2.0 Real, FMI 3.0 Float64), read and written
 * without a call per run (the commonest get and set). */
typedef void (*rst_read_fn)(const void *values, size_t first, size_t n, double out[]);
typedef void (*rst_write_fn)(void *values, size_t first, size_t n, const double in[]);
#define RST_CONVERTERS(read_name, write_name, c_type, to_double, from_double)                   \
    static void read_name(const void *values, size_t first, size_t n, double out[])             \
    {                                                                                           \
        const c_type *in_ = (const c_type *)values + first;                                     \
        size_t i_;                                                                              \
        for (i_ = 0; i_ < n; i_++)                                                              \
            out[i_] = to_double(in_[i_]);                                                       \
    }                                                                                           \
    static void write_name(void *values, size_t first, size_t n, const double in[])             \
    {                                                                                           \
        c_type *out_ = (c_type *)values + first;                                                \
        size_t i_;                                                                              \
        for (i_ = 0; i_ < n; i_++)                                                              \
            out_[i_] = from_double(in[i_]);                                                     \
    }

/* Entering and leaving an FMI call: the common path inline (below), the rest in rst_call.c. */
void front_lock_contended(rst_instance *inst);     /* waits for the lock another thread holds */
void front_wake_waiter(rst_instance *inst);        /* after giving the lock back: wakes a waiting thread */
void front_unlock_and_deliver(rst_instance *inst); /* unlocks, then delivers the messages the call logged */
int front_refuse_mode(rst_instance *inst, const char *function); /* logs why the mode refuses; 0 */
/* The mode as messages name it; `buffer` holds the text of the modes that name a function. */
const char *front_mode_name(const rst_instance *inst, rst_mode mode, char *buffer, size_t size);

/* Values (rst_values.c). */
void front_reset_store(rst_instance *inst); /* every variable back to its start value */
/* Reads `n` variables of `kinds` as a get call does (the instance locked, the mode checked), handing each
 * value to `write`: inputs and parameters from the store, what the model computes from the backend. */
rst_status front_read(rst_instance *inst, const char *function, unsigned int kinds, const rst_vr vr[], size_t n,
                      void *values, rst_write_fn write);
void front_describe_value(rst_type type, double value, char *out, size_t size);
const char *front_type_name(rst_type type);

/* The version-neutral FMI functions (rst_lifecycle.c; get and set: rst_values.c): each checks its instance,
 * locks it, checks the mode and its arguments, logs under the name `function` and returns the status the
 * host sees. */
/* A new instance (not yet one the host may use): NULL when out of memory (logged). */
rst_instance *front_new_instance(const rst_api *api, void (*host_logger)(void), void *environment,
                                 rst_allocate_fn allocate, rst_release_fn release, const char *function,
                                 const char *name, int logging_on);
/* Checks the GUID (FMI 3.0: instantiation token) and runs the backend's instantiate: the instance, or
 * NULL (freed, with a message). */
rst_instance *front_instantiate(rst_instance *inst, const char *function, const char *token,
                                const char *resource_dir, int visible, int model_exchange);
void front_discard_instance(rst_instance *inst); /* frees an instance that never reached the host */
void front_free_instance(void *c);
/* `kinds`: the rst_access kinds this call may touch; `n_values` must equal `n` (one value each). */
rst_status front_set(void *c, const char *function, unsigned int kinds, const rst_vr vr[], size_t n,
                     const void *values, size_t n_values, rst_read_fn read);
rst_status front_get(void *c, const char *function, unsigned int kinds, const rst_vr vr[], size_t n,
                     void *values, size_t n_values, rst_write_fn write);
/* A get or set of a type this FMU has no variables of (String, Float32, Binary, ...). */
rst_status front_refuse_type(void *c, const char *function, const char *type_name, const rst_vr vr[], size_t n,
                             int set);
rst_status front_setup_experiment(void *c, const char *function, const rst_experiment *experiment);
/* `experiment`: NULL for FMI 2.0 (fmi2SetupExperiment gave it), the arguments for FMI 3.0 */
rst_status front_enter_initialization(void *c, const char *function, const rst_experiment *experiment);
rst_status front_exit_initialization(void *c, const char *function);
rst_status front_terminate(void *c, const char *function);
rst_status front_reset(void *c, const char *function);
/* `last_successful_time`: NULL, or where the end of the last successful step goes (FMI 3.0: the event
 * where the step returned early). `event_handling_needed`, `terminate_simulation`, `early_return`: NULL
 * (FMI 2.0), or all three FMI 3.0's out-arguments (fmi3Boolean is C99's bool), written wherever the step
 * ran (a status below RST_ERROR): here, not in rst_fmi3.c, so that fmi3DoStep passes them on without a
 * frame or a copy of its own. */
rst_status front_do_step(void *c, const char *function, double t, double h, double *last_successful_time,
                         _Bool *event_handling_needed, _Bool *terminate_simulation, _Bool *early_return);
/* A call this FMU does not provide, or whose arguments the version layer found wrong, in one of
 * `modes`: logs "<function>: <why>" and returns an error. */
rst_status front_refuse(void *c, const char *function, unsigned int modes, const char *why);
/* fmuResourceLocation (a file: URI) -> the path it names, in `path` (room for strlen(uri) + 1 bytes);
 * NULL, or why it cannot be decoded. */
const char *front_decode_file_uri(const char *uri, char *path);

/* Messages (rst_log.c): the ones logged since front_lock, taken out of the instance (under its lock),
 * then handed to the logger (after it is released). */
rst_message *front_take_messages(rst_instance *inst);
void front_deliver_messages(rst_instance *inst, rst_message *messages);
rst_status front_set_debug_logging(void *c, const char *function, int logging_on, size_t n,
                                   const char *const categories[]);

/* Model exchange (rst_exchange.c). */
rst_status front_enter_event_mode(void *c, const char *function);
/* FMI 3.0 co-simulation with event mode: event mode -> step mode */
rst_status front_enter_step_mode(void *c, const char *function);
rst_status front_enter_continuous_time_mode(void *c, const char *function);
rst_status front_update_discrete_states(void *c, const char *function, rst_event_update *result);
rst_status front_completed_integrator_step(void *c, const char *function, int *enter_event_mode, int *terminate);
rst_status front_set_time(void *c, const char *function, double time);
rst_status front_set_continuous_states(void *c, const char *function, const double x[], size_t n);
rst_status front_get_continuous_states(void *c, const char *function, double x[], size_t n);
rst_status front_get_derivatives(void *c, const char *function, double dx[], size_t n);
rst_status front_get_event_indicators(void *c, const char *function, double z[], size_t n);
rst_status front_get_nominals(void *c, const char *function, double nominals[], size_t n);
/* the sizes of the state vector and of the event indicators (FMI 3.0 asks for them) */
rst_status front_get_sizes(void *c, const char *function, size_t *n_states, size_t *n_event_indicators);

/* FMU states (rst_state.c). */
void front_free_states(rst_instance *inst);
rst_status front_get_state(void *c, const char *function, void **state);
rst_status front_set_state(void *c, const char *function, void *state);
rst_status front_free_state(void *c, const char *function, void **state);
rst_status front_serialized_size(void *c, const char *function, void *state, size_t *size);
rst_status front_serialize(void *c, const char *function, void *state, unsigned char bytes[], size_t size);
rst_status front_deserialize(void *c, const char *function, const unsigned char bytes[], size_t size,
                             void **state);

/* Is `value` inside the variable's declared range? (Reals: finite too.) Inline: a set checks every
 * value it changes. */
static inline int front_in_range(const rst_variable *var, double value)
{
    if (var->type == RST_BOOLEAN)
        return value == 0.0 || value == 1.0;
    if (!isfinite(value))
        return 0;
    if (var->low_open ? !(value > var->low) : !(value >= var->low))
        return 0;
    if (var->high_open ? !(value < var->high) : !(value <= var->high))
        return 0;
    return 1;
}

/* A backend's answer: RST_ERROR puts the instance into the error mode, RST_FATAL latches it. */
static inline rst_status front_backend_status(rst_instance *inst, rst_status status)
{
    if (status == RST_FATAL)
        inst->mode = RST_MODE_FATAL;
    else if (status == RST_ERROR)
        inst->mode = RST_MODE_ERROR;
    return status;
}

/* A test that the common path of a call expects to fail (a NULL out-argument): the compiler keeps it a
 * branch (a chain of pointer tests otherwise may become vector compares, slower on the path taken). */
#if defined(__GNUC__) || defined(__clang__)
#define RST_UNLIKELY(condition) __builtin_expect((condition) != 0, 0)
#else
#define RST_UNLIKELY(condition) (condition)
#endif

/* NULL unless c is one of our live instances. */
static inline rst_instance *front_instance(void *c)
{
    rst_instance *inst = (rst_instance *)c;
    return (inst != NULL && inst->magic == RST_INSTANCE_MAGIC) ? inst : NULL;
}

static inline void front_lock(rst_instance *inst)
{
#if defined(RST_LOCK_ATOMIC)
    int free_word = 0;
    if (!__atomic_compare_exchange_n(&inst->lock_word, &free_word, 1, 0, __ATOMIC_ACQUIRE, __ATOMIC_RELAXED))
        front_lock_contended(inst);
#elif defined(RST_LOCK_PTHREAD)
    pthread_mutex_lock(&inst->lock);
#elif defined(RST_LOCK_WIN32)
    AcquireSRWLockExclusive(&inst->lock);
#endif
    inst->in_call = 1;
}

/* Gives the lock back, without delivering messages (front_unlock does). */
static inline void front_release(rst_instance *inst)
{
    inst->in_call = 0;
#if defined(RST_LOCK_ATOMIC)
    __atomic_store_n(&inst->lock_word, 0, __ATOMIC_RELEASE);
    if (__atomic_load_n(&inst->waiting, __ATOMIC_RELAXED) != 0)
        front_wake_waiter(inst);
#elif defined(RST_LOCK_PTHREAD)
    pthread_mutex_unlock(&inst->lock);
#elif defined(RST_LOCK_WIN32)
    ReleaseSRWLockExclusive(&inst->lock);
#endif
}

/* The end of a call: the lock given back, then the messages the call logged (if any) handed to the
 * logger, which may call this instance again. */
static inline void front_unlock(rst_instance *inst)
{
    if (inst->pending == NULL)
        front_release(inst);
    else
        front_unlock_and_deliver(inst);
}

/* Is `function` allowed in the instance's mode (one of the `modes`; never after a fatal error)? Logs
 * why not. */
static inline int front_allowed(rst_instance *inst, const char *function, unsigned int modes)
{
    if (modes & (unsigned int)inst->mode & ~(unsigned int)RST_MODE_FATAL)
        return 1;
    return front_refuse_mode(inst, function);
}

/* The start of every FMI function of an instance: `inst` checked, locked, the call allowed in its
 * mode (else an error); LEAVE(status) unlocks and returns. (`status_` is an int: the version layers
 * return it as their own status type.) */
#define ENTER(function, modes)                     \
    rst_instance *inst = front_instance(c);        \
    int status_ = RST_OK;                          \
    if (inst == NULL)                              \
        return (int)RST_ERROR;                     \
    front_lock(inst);                              \
    if (!front_allowed(inst, function, modes)) {   \
        front_unlock(inst);                        \
        return (int)RST_ERROR;                     \
    }

#define LEAVE(status)          \
    do {                       \
        status_ = (int)(status); \
        front_unlock(inst);    \
        return status_;        \
    } while (0)

#endif
