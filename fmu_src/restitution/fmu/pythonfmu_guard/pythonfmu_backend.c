/*
 * pythonfmu_backend.c - the guard's backend: the C front (cfront/) in front of pythonfmu's binary.
 *
 * The front has checked every call and value before anything reaches here, so pythonfmu only ever
 * sees legal calls with values inside their declared ranges. What pythonfmu 0.7's binary does wrong
 * (docs/fmi_tools.md) is worked around here, never copied:
 *
 * - Resources: pythonfmu decodes only "%20" in the resource URI and crashes when it cannot open the
 *   slave script. It is handed "file://" + the decoded path, after checking that the slave script
 *   named by resources/slavemodule.txt exists. A path that contains "%20" itself (which pythonfmu
 *   would turn into a space) is handed as /proc/self/fd/N of an open descriptor of the directory.
 * - Leaks: every fmi2Instantiate of pythonfmu re-executes the slave module (a new class object that
 *   is never freed) and prepends resources/ to sys.path. Its instances are therefore kept in a
 *   process-wide pool and reused: fmi2FreeInstance resets one (pythonfmu's fmi2Reset makes a fresh
 *   slave object) and the next fmi2Instantiate with the same resources takes it. Instantiate/free
 *   cycles then cost nothing; the pool holds as many instances as were alive at once.
 * - Logging: pythonfmu keeps the host's callback struct pointer and passes messages as printf
 *   formats. It is given a callback struct of the pool slot instead, whose logger hands each message,
 *   as text, to whichever instance currently owns the slot (NULL loggers and '%' are then harmless).
 * - fmi2Fatal: pythonfmu answers any Python exception with fmi2Fatal after dropping its references
 *   to the slave, so the instance must never be called or freed again. The front latches such an
 *   instance; its pool slot is poisoned: never reset, reused or freed.
 * - Ctrl-C and SIGTERM in a Python host: the interpreter would raise KeyboardInterrupt (or whatever the
 *   host's Python handler raises) inside the slave's code, which pythonfmu turns into fmi2Fatal. Python's
 *   C handler only sets a flag; the Python handler runs at the eval loop's next check on the main thread.
 *   Two ways in, both closed: (1) a signal during the call: while a call is inside pythonfmu, SIGINT and
 *   SIGTERM are held back if the host handles them (a handler function; a default or ignored one is left
 *   alone: a default SIGTERM ends the process at once) and raised again as soon as the call returns;
 *   (2) a signal that came just before the call (while the host ran Python code after its last check,
 *   or in ctypes or the front before the call began) is still pending, and the slave's first
 *   line would run its handler (this gave fmi2Fatal for 5-10 % of SIGINTs in a set/get loop,
 *   tests/fmu/test_fmu_interrupt.py): with the GIL taken and the held signals noted, the pending handlers run
 *   first (pyloader_signals.c: pyloader_enter_call), and what they raise is raised again in the host's code
 *   once the call returns. Either way the host sees its exception between two FMI calls (fmpy:
 *   KeyboardInterrupt in fmpy's code right after the call) and the instance goes on. A single long call
 *   is not interrupted. Cost: two system calls per call (the two dispositions, see "Signals held back"
 *   below).
 * - FMU states: the front keeps them (the store's state variables, validated on restore), so
 *   pythonfmu's state functions, which leak and accept anything, are never called.
 */
#ifndef _GNU_SOURCE
#define _GNU_SOURCE
#endif
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "python_loader.h"
#include "rst_front.h"
#include "rst_interface.h"  /* generated: restitution.fmu.describe.c_header */
#include "rst_model_info.h" /* generated: identifier and GUID of modelDescription.xml */

/* One pythonfmu instance, kept for the process's lifetime. */
typedef struct slot {
    struct slot *next;
    fmi2Component real;
    fmi2CallbackFunctions callbacks; /* what pythonfmu keeps a pointer to */
    rst_instance *owner;             /* the guard instance using it, or NULL */
    int poisoned;                    /* pythonfmu reported fmi2Fatal: never touch it again */
    char resource_dir[1];            /* the pool key (allocated to size) */
} slot;

/* Process-wide because pythonfmu's instances must outlive ours (see the top of this file). */
static pthread_mutex_t pool_lock = PTHREAD_MUTEX_INITIALIZER;
static slot *pool = NULL;

typedef struct {
    const pythonfmu_api *api;
    slot *slot;
} guard;

#define API(inst) (((guard *)rst_backend(inst))->api)
#define REAL(inst) (((guard *)rst_backend(inst))->slot->real)

/* ------------------------------------------------------------------------------------------------ */
/* Signals held back during calls into Python (Python hosts only)                                   */
/* ------------------------------------------------------------------------------------------------ */
/* The signals a user sends to stop a run. Each is held back only while the host handles it (a handler
 * function: Python's, for SIGINT always); a default or ignored disposition is left alone, so a default
 * SIGTERM ends the process at once, even inside a call.
 *
 * How: the guard's own handler (`relay`) takes the place of the host's, once, and stays: between calls it
 * hands every signal straight on to the host's handler (kept in `host_action`, called as the kernel would:
 * the same signature, mask and flags), during a call it only notes it, and the last call to return raises
 * it again. Each call checks, with one system call per signal, that `relay` is still the disposition: when
 * the host has installed another handler since (Python's signal.signal, or C code), that one becomes the
 * host's and `relay` takes its place again; a default or ignored disposition is left alone. Swapping the
 * host's handler out and back in around every call instead cost three system calls per call. The guard is
 * never unloaded (pyloader_pin_self) while `relay` may be installed. */
static const int held[] = {SIGINT, SIGTERM};
#define N_HELD ((int)(sizeof held / sizeof held[0]))

static pthread_mutex_t signal_lock = PTHREAD_MUTEX_INITIALIZER;
static volatile sig_atomic_t calls_inside = 0; /* calls inside pythonfmu, all threads (changed under signal_lock) */
static struct sigaction host_action[N_HELD];   /* the host's handler that `relay` stands for */
static volatile sig_atomic_t relaying[N_HELD]; /* `relay` was installed in place of host_action[i] */
static volatile sig_atomic_t arrived[N_HELD];  /* noted during a call, raised again after it */

static int held_index(int signum)
{
    int i;
    for (i = 0; i < N_HELD; i++)
        if (held[i] == signum)
            return i;
    return -1;
}

static int is_handler(const struct sigaction *action)
{
    if (action->sa_flags & SA_SIGINFO)
        return action->sa_sigaction != NULL;
    return action->sa_handler != SIG_DFL && action->sa_handler != SIG_IGN;
}

/* The guard's handler, in place of the host's (see above). Async-signal-safe: flags, sigaction, and the
 * host's handler. */
static void relay(int signum, siginfo_t *info, void *context)
{
    int i = held_index(signum), saved_errno = errno;
    if (i < 0)
        return;
    if (calls_inside > 0 && relaying[i]) {
        arrived[i] = 1;
        return;
    }
    if (!is_handler(&host_action[i])) /* never: `relay` is installed only in place of a handler */
        return;
    if (host_action[i].sa_flags & SA_RESETHAND) { /* a one-shot handler: what the kernel would have done */
        struct sigaction dfl;
        memset(&dfl, 0, sizeof dfl);
        dfl.sa_handler = SIG_DFL;
        sigemptyset(&dfl.sa_mask);
        relaying[i] = 0;
        sigaction(signum, &dfl, NULL);
    }
    if (host_action[i].sa_flags & SA_SIGINFO)
        host_action[i].sa_sigaction(signum, info, context);
    else
        host_action[i].sa_handler(signum);
    errno = saved_errno;
}

/* `relay` for held[i], with the host's mask and flags (signal_lock held, calls_inside > 0). One system call
 * when `relay` is in place, two more when the host put a handler of its own there since the last call. */
static void keep_relay(int i)
{
    struct sigaction now, ours;
    if (sigaction(held[i], NULL, &now) != 0)
        return;
    if ((now.sa_flags & SA_SIGINFO) && now.sa_sigaction == relay)
        return;
    relaying[i] = 0;
    if (!is_handler(&now)) /* default or ignored: left alone */
        return;
    host_action[i] = now;
    memset(&ours, 0, sizeof ours);
    ours.sa_sigaction = relay;
    ours.sa_mask = now.sa_mask;
    ours.sa_flags = (now.sa_flags & ~SA_RESETHAND) | SA_SIGINFO;
    relaying[i] = 1;
    if (sigaction(held[i], &ours, NULL) != 0)
        relaying[i] = 0;
    /* one arriving before this went to the host's handler: pyloader_enter_call runs it */
}

/* Before a call into pythonfmu: in a Python host, the held signals are noted instead of handled until the
 * last call returns, so a signal during the call cannot raise in the slave's code, then the Python handlers
 * of signals that came earlier run (pyloader_enter_call), before the slave's code can. */
static void begin_call(pyloader_call *call)
{
    int i;
    call->gil = -1;
    call->n_raised = 0;
    pyloader_attach_thread();
    if (!pyloader_interpreter_is_hosts())
        return;
    pthread_mutex_lock(&signal_lock);
    calls_inside = calls_inside + 1;
    for (i = 0; i < N_HELD; i++)
        keep_relay(i);
    pthread_mutex_unlock(&signal_lock);
    pyloader_enter_call(call);
}

/* After it: a signal noted meanwhile raised again once no call is inside (`relay` hands it to the host's
 * handler; Python: its flag is set and the handler runs at the next check, in the host's code), and what
 * an earlier signal's handler raised in pyloader_enter_call raised again in the host's code. */
static void end_call(pyloader_call *call)
{
    int i;
    if (!pyloader_interpreter_is_hosts())
        return;
    pthread_mutex_lock(&signal_lock);
    calls_inside = calls_inside - 1;
    if (calls_inside == 0)
        for (i = 0; i < N_HELD; i++)
            if (arrived[i]) {
                arrived[i] = 0;
                raise(held[i]);
            }
    pthread_mutex_unlock(&signal_lock);
    pyloader_leave_call(call);
}

/* ------------------------------------------------------------------------------------------------ */
/* The pool                                                                                         */
/* ------------------------------------------------------------------------------------------------ */
static void slot_logger(fmi2ComponentEnvironment environment, fmi2String instance_name, fmi2Status status,
                        fmi2String category, fmi2String message, ...)
{
    slot *s = (slot *)environment;
    (void)instance_name;
    if (s != NULL && s->owner != NULL)
        rst_log_text(s->owner, (rst_status)status, category, message); /* pythonfmu passes no format arguments */
}

static void *slot_allocate(size_t n, size_t size) { return calloc(n, size); }

/* A free slot of the pool for `resource_dir`, now owned by `inst`; NULL if there is none. */
static slot *take_slot(rst_instance *inst, const char *resource_dir)
{
    slot *s;
    pthread_mutex_lock(&pool_lock);
    for (s = pool; s != NULL; s = s->next)
        if (s->owner == NULL && !s->poisoned && strcmp(s->resource_dir, resource_dir) == 0) {
            s->owner = inst;
            break;
        }
    pthread_mutex_unlock(&pool_lock);
    return s;
}

/* What pythonfmu can read as fmuResourceLocation for `dir` (it strips "file://" and turns "%20" into
 * a space, nothing else), written to `uri`. */
static int pythonfmu_uri(rst_instance *inst, const char *dir, char *uri, size_t size)
{
    if (strstr(dir, "%20") == NULL) {
        snprintf(uri, size, "file://%s", dir);
        return 1;
    }
    {
        int fd = open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC); /* kept open: the slot lives as long */
        if (fd < 0) {
            rst_log(inst, RST_ERROR, "fmi2Instantiate: cannot open the resources directory %s", dir);
            return 0;
        }
        snprintf(uri, size, "file:///proc/self/fd/%d", fd);
        return 1;
    }
}

static slot *new_slot(rst_instance *inst, const pythonfmu_api *api, const char *resource_dir, int visible)
{
    char uri[4200];
    pyloader_call call;
    slot *s = (slot *)calloc(1, sizeof(slot) + strlen(resource_dir));
    if (s == NULL) {
        rst_log(inst, RST_ERROR, "fmi2Instantiate: out of memory");
        return NULL;
    }
    {
        fmi2CallbackFunctions callbacks = {slot_logger, slot_allocate, free, NULL, s};
        memcpy((void *)&s->callbacks, &callbacks, sizeof callbacks); /* its members are const */
    }
    strcpy(s->resource_dir, resource_dir);
    s->owner = inst;
    if (!pythonfmu_uri(inst, resource_dir, uri, sizeof uri)) {
        free(s);
        return NULL;
    }
    begin_call(&call);
    s->real = api->Instantiate(rst_instance_name(inst), fmi2CoSimulation, RST_MODEL_GUID, uri, &s->callbacks,
                               visible, fmi2True);
    end_call(&call);
    if (s->real == NULL) {
        rst_log(inst, RST_ERROR, "fmi2Instantiate: pythonfmu could not instantiate the slave from %s (see the "
                "message above)", resource_dir);
        free(s); /* pythonfmu keeps nothing of a failed instance */
        return NULL;
    }
    pthread_mutex_lock(&pool_lock);
    s->next = pool;
    pool = s;
    pthread_mutex_unlock(&pool_lock);
    return s;
}

/* ------------------------------------------------------------------------------------------------ */
/* Hooks                                                                                            */
/* ------------------------------------------------------------------------------------------------ */
/* The slave script pythonfmu will load: resources/<first line of slavemodule.txt>.py. */
static int check_resources(rst_instance *inst, const char *dir)
{
    char path[4200], module[256] = "";
    struct stat st;
    FILE *f;
    size_t n;
    if (stat(dir, &st) != 0 || !S_ISDIR(st.st_mode)) {
        rst_log(inst, RST_ERROR, "fmi2Instantiate: the resource location %s is not a directory", dir);
        return 0;
    }
    snprintf(path, sizeof path, "%s/slavemodule.txt", dir);
    f = fopen(path, "r");
    if (f == NULL || fgets(module, sizeof module, f) == NULL) {
        rst_log(inst, RST_ERROR, "fmi2Instantiate: cannot read %s (it names the Python slave module)", path);
        if (f)
            fclose(f);
        return 0;
    }
    fclose(f);
    n = strcspn(module, "\r\n");
    module[n] = '\0';
    snprintf(path, sizeof path, "%s/%s.py", dir, module);
    if (n == 0 || stat(path, &st) != 0 || !S_ISREG(st.st_mode)) {
        rst_log(inst, RST_ERROR, "fmi2Instantiate: the Python slave script %s does not exist", path);
        return 0;
    }
    return 1;
}

static rst_status instantiate(rst_instance *inst, const char *resource_dir, int visible)
{
    guard *g = (guard *)rst_backend(inst);
    if (resource_dir == NULL) {
        rst_log(inst, RST_ERROR, "fmi2Instantiate: no fmuResourceLocation: this FMU runs the Python code in its "
                "resources directory");
        return RST_ERROR;
    }
    if (!check_resources(inst, resource_dir))
        return RST_ERROR;
    g->api = pyloader_ensure_ready(inst, resource_dir);
    if (g->api == NULL)
        return RST_ERROR;
    g->slot = take_slot(inst, resource_dir);
    if (g->slot == NULL)
        g->slot = new_slot(inst, g->api, resource_dir, visible);
    return g->slot != NULL ? RST_OK : RST_ERROR;
}

static void free_instance(rst_instance *inst)
{
    guard *g = (guard *)rst_backend(inst);
    slot *s = g->slot;
    fmi2Status status = fmi2Fatal;
    pyloader_call call;
    if (s == NULL)
        return;
    if (rst_mode_of(inst) != RST_MODE_FATAL && !s->poisoned) {
        begin_call(&call);
        status = g->api->Reset(s->real); /* a fresh slave object for the next owner */
        end_call(&call);
    }
    pthread_mutex_lock(&pool_lock);
    if (status > fmi2Warning)
        s->poisoned = 1;
    s->owner = NULL;
    pthread_mutex_unlock(&pool_lock);
}

static rst_status setup_experiment(rst_instance *inst, int tolerance_defined, double tolerance,
                                   double start_time, int stop_time_defined, double stop_time)
{
    fmi2Status status;
    pyloader_call call;
    begin_call(&call);
    status = API(inst)->SetupExperiment(REAL(inst), tolerance_defined, tolerance, start_time, stop_time_defined,
                                        stop_time);
    end_call(&call);
    return (rst_status)status;
}

#define FORWARD(name)                                         \
    static rst_status forward_##name(rst_instance *inst)      \
    {                                                         \
        fmi2Status status;                                    \
        pyloader_call call;                                     \
        begin_call(&call);                                    \
        status = API(inst)->name(REAL(inst));                 \
        end_call(&call);                                      \
        return (rst_status)status;                            \
    }
FORWARD(EnterInitializationMode)
FORWARD(ExitInitializationMode)
FORWARD(Terminate)
FORWARD(Reset)

static rst_status set_values(rst_instance *inst, rst_type type, const rst_vr vr[], size_t n,
                             const double values[])
{
    fmi2Integer integers[64];
    fmi2Boolean booleans[64];
    fmi2Status status = fmi2OK;
    size_t i0, i;
    pyloader_call call;
    begin_call(&call);
    for (i0 = 0; i0 < n && status <= fmi2Warning; i0 += 64) {
        size_t m = n - i0 < 64 ? n - i0 : 64;
        if (type == RST_REAL)
            status = API(inst)->SetReal(REAL(inst), vr + i0, m, values + i0);
        else if (type == RST_INTEGER) {
            for (i = 0; i < m; i++)
                integers[i] = (fmi2Integer)values[i0 + i]; /* checked integral and in range by the front */
            status = API(inst)->SetInteger(REAL(inst), vr + i0, m, integers);
        } else {
            for (i = 0; i < m; i++)
                booleans[i] = values[i0 + i] != 0.0;
            status = API(inst)->SetBoolean(REAL(inst), vr + i0, m, booleans);
        }
    }
    end_call(&call);
    return (rst_status)status;
}

static rst_status get_values(rst_instance *inst, rst_type type, const rst_vr vr[], size_t n,
                             double values[])
{
    fmi2Integer integers[64];
    fmi2Boolean booleans[64];
    fmi2Status status = fmi2OK;
    size_t i0, i;
    pyloader_call call;
    begin_call(&call);
    for (i0 = 0; i0 < n && status <= fmi2Warning; i0 += 64) {
        size_t m = n - i0 < 64 ? n - i0 : 64;
        if (type == RST_REAL)
            status = API(inst)->GetReal(REAL(inst), vr + i0, m, values + i0);
        else if (type == RST_INTEGER) {
            status = API(inst)->GetInteger(REAL(inst), vr + i0, m, integers);
            for (i = 0; i < m; i++)
                values[i0 + i] = integers[i];
        } else {
            status = API(inst)->GetBoolean(REAL(inst), vr + i0, m, booleans);
            for (i = 0; i < m; i++)
                values[i0 + i] = booleans[i] != fmi2False;
        }
    }
    end_call(&call);
    return (rst_status)status;
}

static rst_status do_step(rst_instance *inst, double t, double h)
{
    fmi2Status status;
    pyloader_call call;
    begin_call(&call);
    status = API(inst)->DoStep(REAL(inst), t, h, fmi2True);
    end_call(&call);
    return (rst_status)status;
}

/* The state variables that are not inputs or parameters, by type (those the slave evolves). */
static size_t evolving(rst_type type, fmi2ValueReference vr[], size_t size)
{
    size_t i, n = 0;
    for (i = 0; i < RST_MODEL_N_VARIABLES && n < size; i++) {
        const rst_variable *v = &RST_MODEL_VARIABLES[i];
        if (v->state && v->type == type && v->causality != RST_INPUT && v->causality != RST_PARAMETER)
            vr[n++] = v->vr;
    }
    return n;
}

static rst_status save_state(rst_instance *inst)
{
    fmi2ValueReference vr[RST_MODEL_N_VARIABLES];
    double values[RST_MODEL_N_VARIABLES];
    rst_status status = RST_OK;
    int t;
    for (t = RST_REAL; t <= RST_BOOLEAN && status <= RST_WARNING; t++) {
        size_t n = evolving((rst_type)t, vr, RST_MODEL_N_VARIABLES), i;
        if (n == 0)
            continue;
        status = get_values(inst, (rst_type)t, vr, n, values);
        for (i = 0; i < n && status <= RST_WARNING; i++)
            rst_store(inst)[vr[i]] = values[i];
    }
    return status;
}

static rst_status restore_state(rst_instance *inst)
{
    fmi2ValueReference vr[RST_MODEL_N_VARIABLES];
    double values[RST_MODEL_N_VARIABLES];
    rst_status status = RST_OK;
    int t;
    size_t i;
    for (t = RST_REAL; t <= RST_BOOLEAN && status <= RST_WARNING; t++) {
        size_t n = 0;
        for (i = 0; i < RST_MODEL_N_VARIABLES; i++)
            if (RST_MODEL_VARIABLES[i].state && RST_MODEL_VARIABLES[i].type == (rst_type)t) {
                vr[n] = (fmi2ValueReference)i;
                values[n++] = rst_store(inst)[i];
            }
        if (n > 0)
            status = set_values(inst, (rst_type)t, vr, n, values);
    }
    return status;
}

const rst_model RST_MODEL = {
    .identifier = RST_MODEL_IDENTIFIER, .guid = RST_MODEL_GUID,
    .variables = RST_MODEL_VARIABLES, .n_variables = RST_MODEL_N_VARIABLES, .backend_size = sizeof(guard),
    .instantiate = instantiate, .free_instance = free_instance, .setup_experiment = setup_experiment,
    .enter_initialization = forward_EnterInitializationMode, .exit_initialization = forward_ExitInitializationMode,
    .set = set_values, .get_outputs = get_values, .do_step = do_step, .terminate = forward_Terminate,
    .reset = forward_Reset, .save_state = save_state, .restore_state = restore_state};
