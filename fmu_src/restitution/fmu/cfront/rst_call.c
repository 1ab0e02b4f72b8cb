/* The front's call layer, used by every other file of the core (see rst_lifecycle.c for the whole):
 * the accessors backends read an instance through, the mode's name in messages, entering and leaving an
 * FMI call (the contended half of the instance lock, handing the call's messages to the host after the
 * lock is given back), the refusal of a call in a mode that does not allow it, and a backend's status
 * applied to the mode. It calls only rst_log.c. */
#include "rst_instance.h"

#include <stdio.h>
#include <time.h>

/* ------------------------------------------------------------------------------------------------ */
/* Accessors for backends                                                                           */
/* ------------------------------------------------------------------------------------------------ */
const char *rst_instance_name(const rst_instance *inst) { return inst->name; }
rst_mode rst_mode_of(const rst_instance *inst) { return inst->mode; }
double rst_start_time(const rst_instance *inst) { return inst->has_start ? inst->start_time : 0.0; }
const char *rst_fmi_prefix(const rst_instance *inst) { return inst->api->prefix; }
int rst_is_model_exchange(const rst_instance *inst) { return inst->model_exchange; }
int rst_event_mode_used(const rst_instance *inst) { return inst->event_mode_used; }

/* The mode as messages name it; `buffer` holds the text of the modes that name a function. */
const char *front_mode_name(const rst_instance *inst, rst_mode mode, char *buffer, size_t size)
{
    switch (mode) {
    case RST_MODE_INSTANTIATED: return "instantiated";
    case RST_MODE_INITIALIZATION: return "initialization mode";
    case RST_MODE_STEP_COMPLETE: return "step mode";
    case RST_MODE_STEP_FAILED:
        snprintf(buffer, size, "step failed (after %sDoStep returned %sDiscard)", inst->api->prefix,
                 inst->api->prefix);
        return buffer;
    case RST_MODE_TERMINATED: return "terminated";
    case RST_MODE_EVENT: return "event mode";
    case RST_MODE_CONTINUOUS: return "continuous-time mode";
    case RST_MODE_ERROR: return "error";
    default: return "fatal error";
    }
}

/* ------------------------------------------------------------------------------------------------ */
/* Entering and leaving a call                                                                      */
/* ------------------------------------------------------------------------------------------------ */
#if defined(RST_LOCK_ATOMIC)
/* The longest a waiter sleeps before it looks at the word again [ns]: the bound on the one wake-up that
 * can be missed (see front_wake_waiter). */
#define WAIT_RECHECK_NS 1000000L

/* The lock word is taken: count this thread among the waiting (under `lock`), then take the word as
 * soon as it is free, sleeping on `waiters` in between. */
void front_lock_contended(rst_instance *inst)
{
    int free_word = 0;
    pthread_mutex_lock(&inst->lock);
    __atomic_add_fetch(&inst->waiting, 1, __ATOMIC_SEQ_CST);
    while (!__atomic_compare_exchange_n(&inst->lock_word, &free_word, 1, 0, __ATOMIC_ACQUIRE, __ATOMIC_RELAXED)) {
        struct timespec until;
        free_word = 0;
        clock_gettime(CLOCK_REALTIME, &until);
        until.tv_nsec += WAIT_RECHECK_NS;
        if (until.tv_nsec >= 1000000000L) {
            until.tv_sec += 1;
            until.tv_nsec -= 1000000000L;
        }
        pthread_cond_timedwait(&inst->waiters, &inst->lock, &until);
    }
    __atomic_sub_fetch(&inst->waiting, 1, __ATOMIC_SEQ_CST);
    pthread_mutex_unlock(&inst->lock);
}

/* After the word was freed and a waiter counted: wake one. Taking `lock` orders this after a waiter's
 * check of the word (it then sleeps, and is woken) or before it (it then finds the word free). Giving
 * the word back reads the count without a fence (the point of the plain store): a count raised just
 * then may be read as 0 and that waiter not woken; it looks again after WAIT_RECHECK_NS. */
void front_wake_waiter(rst_instance *inst)
{
    pthread_mutex_lock(&inst->lock);
    pthread_cond_signal(&inst->waiters);
    pthread_mutex_unlock(&inst->lock);
}
#else
void front_lock_contended(rst_instance *inst) { (void)inst; }
void front_wake_waiter(rst_instance *inst) { (void)inst; }
#endif

void front_unlock_and_deliver(rst_instance *inst)
{
    rst_message *messages = front_take_messages(inst);
    front_release(inst);
    front_deliver_messages(inst, messages);
}

int front_refuse_mode(rst_instance *inst, const char *function)
{
    char buffer[80];
    if (inst->mode == RST_MODE_FATAL) {
        rst_log(inst, RST_ERROR, "%s: this instance reported %sFatal earlier and cannot be used any more; "
                "free it (%sFreeInstance)", function, inst->api->prefix, inst->api->prefix);
        return 0;
    }
    rst_log(inst, RST_ERROR, "%s is not allowed in %s (%s %s state machine)", function,
            front_mode_name(inst, inst->mode, buffer, sizeof buffer), inst->api->standard,
            inst->model_exchange ? "model-exchange" : "co-simulation");
    return 0;
}
