/* What the front's files share (not for backends: they use rst_front.h). */
#ifndef RST_FRONT_INTERNAL_H
#define RST_FRONT_INTERNAL_H

/* Every instance has a lock (FMI 2.0 does not ask one instance to be thread-safe; these are), whatever
 * the build command: POSIX threads, or a slim reader/writer lock on Windows. RST_FRONT_NO_LOCK leaves
 * it out for a platform with neither. */
#if !defined(RST_FRONT_NO_LOCK)
#if defined(_WIN32)
#define RST_LOCK_WIN32
#else
#define RST_LOCK_PTHREAD
#if !defined(_POSIX_C_SOURCE)
#define _POSIX_C_SOURCE 200809L
#endif
#endif
#endif

#include "rst_front.h"

#if defined(FMI2_FUNCTION_PREFIX)
#define front_instance RST_PREFIXED(front_instance)
#define front_lock RST_PREFIXED(front_lock)
#define front_unlock RST_PREFIXED(front_unlock)
#define front_allowed RST_PREFIXED(front_allowed)
#define front_backend_status RST_PREFIXED(front_backend_status)
#define front_in_range RST_PREFIXED(front_in_range)
#define front_describe_value RST_PREFIXED(front_describe_value)
#define front_type_name RST_PREFIXED(front_type_name)
#define front_take_messages RST_PREFIXED(front_take_messages)
#define front_deliver_messages RST_PREFIXED(front_deliver_messages)
#define front_free_states RST_PREFIXED(front_free_states)
#endif

#if defined(RST_LOCK_PTHREAD)
#include <pthread.h>
#elif defined(RST_LOCK_WIN32)
#include <windows.h>
#endif

#define RST_INSTANCE_MAGIC 0x52535446u /* "RSTF": a pointer that is not one of our instances */
#define RST_STATE_MAGIC 0x52535453u    /* "RSTS" */
#define RST_ALL_CATEGORIES 31u         /* the five log categories, all on */

#define ANY_LIVE_MODE (RST_INSTANTIATED | RST_INITIALIZATION | RST_STEP_COMPLETE | RST_STEP_FAILED | \
                       RST_TERMINATED | RST_ERROR)
#define GET_MODES (RST_INITIALIZATION | RST_STEP_COMPLETE | RST_STEP_FAILED | RST_TERMINATED | RST_ERROR)
#define SET_MODES (RST_INSTANTIATED | RST_INITIALIZATION | RST_STEP_COMPLETE)

/* A message waiting to reach the host's logger: messages of a call are delivered after the call has
 * released the instance's lock, so a logger may call back into the same instance (FMI 2.0 does not
 * forbid it) without deadlocking, and finds the instance in a consistent state. */
typedef struct rst_message {
    struct rst_message *next;
    fmi2Status status;
    const char *category; /* points into text[], after the message */
    char text[1];         /* the message (its '%' doubled), NUL, the category, NUL */
} rst_message;

typedef struct rst_state {
    unsigned int magic;
    struct rst_state *next;
    rst_mode mode;
    int has_start, has_time;
    double start_time, next_time, last_time;
    double values[1]; /* one per state variable of the table (allocated to size) */
} rst_state;

struct rst_instance {
    unsigned int magic;
    const rst_model *model;
    char *name;
    fmi2CallbackLogger logger;
    fmi2CallbackAllocateMemory allocate;
    fmi2CallbackFreeMemory release;
    fmi2ComponentEnvironment environment;
    int logging_on;
    unsigned int categories;
    rst_mode mode;
    int has_start;      /* fmi2SetupExperiment gave the start time */
    double start_time;
    int has_time;       /* next_time is known: the t the next doStep must have */
    double next_time;
    double last_time;   /* end of the last successful step (fmi2LastSuccessfulTime) */
    fmi2Status last_step_status;
    size_t n_state;     /* state variables of the table */
    rst_state *states;  /* FMU states made by this instance, to tell ours from any other pointer */
    double *store;
    void *backend;
    int in_call;              /* set while a call holds the instance: its messages wait in `pending` */
    rst_message *pending;     /* in the order they were logged */
    rst_message **pending_end;
#if defined(RST_LOCK_PTHREAD)
    pthread_mutex_t lock;
#elif defined(RST_LOCK_WIN32)
    SRWLOCK lock;
#endif
};

/* Entering and leaving an FMI call (rst_front.c). */
rst_instance *front_instance(fmi2Component c); /* NULL unless c is one of our live instances */
void front_lock(rst_instance *inst);
void front_unlock(rst_instance *inst); /* then delivers the messages the call logged */
int front_allowed(rst_instance *inst, const char *function, unsigned int modes); /* logs why not */
fmi2Status front_backend_status(rst_instance *inst, fmi2Status status);       /* Error, Fatal: change mode */

/* Values (rst_front.c). */
int front_in_range(const rst_variable *var, double value);
void front_describe_value(rst_type type, double value, char *out, size_t size);
const char *front_type_name(rst_type type);

/* Messages (rst_log.c): the ones logged since front_lock, taken out of the instance (under its lock),
 * then handed to the logger (after it is released). */
rst_message *front_take_messages(rst_instance *inst);
void front_deliver_messages(rst_instance *inst, rst_message *messages);

/* FMU states (rst_state.c). */
void front_free_states(rst_instance *inst);

/* The start of every FMI function of an instance: `inst` checked, locked, the call allowed in its
 * mode (else fmi2Error); LEAVE(status) unlocks and returns. */
#define ENTER(function, modes)                     \
    rst_instance *inst = front_instance(c);        \
    fmi2Status status_ = fmi2OK;                   \
    if (inst == NULL)                              \
        return fmi2Error;                          \
    front_lock(inst);                              \
    if (!front_allowed(inst, function, modes)) {   \
        front_unlock(inst);                        \
        return fmi2Error;                          \
    }

#define LEAVE(status)          \
    do {                       \
        status_ = status;      \
        front_unlock(inst);    \
        return status_;        \
    } while (0)

#endif
