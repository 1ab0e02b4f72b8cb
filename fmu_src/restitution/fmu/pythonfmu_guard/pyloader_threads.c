/*
 * pyloader_threads.c - one Python thread state per host thread, kept by the loader (python_loader.c)
 * when a guard started the interpreter. The cache is process-wide, like the interpreter.
 */
#ifndef _GNU_SOURCE
#define _GNU_SOURCE
#endif
#include "pyloader_internal.h"

#include <pthread.h>
#include <stddef.h>

/* Per-thread Python thread states (only when a guard started the interpreter).
 * pythonfmu wraps every call in PyGILState_Ensure/Release; on a thread that has
 * no Python thread state this creates and destroys one per call (about 10x the
 * cost of the call itself). The guard keeps one thread state per host thread
 * (gilstate counter held at 1, GIL released) and deletes it when the thread
 * exits (pthread key destructor). */
static int g_cache_tstates = 0;
static int g_tstate_key_ok = 0;
static pthread_key_t g_tstate_key;
static __thread int t_attached = 0;

/* Thread exit: delete the thread state kept by attach_thread. glibc may already
 * have cleared CPython's own thread-local key, so PyGILState_* cannot be used. */
__attribute__((unused)) static void release_thread_state(void *tstate)
{
    if (!g_cache_tstates || !tstate) return;
    pyloader_py.PyEval_RestoreThread(tstate); /* take the GIL with this thread state */
    pyloader_py.PyThreadState_Clear(tstate);
    pyloader_py.PyThreadState_DeleteCurrent(); /* deletes it and releases the GIL */
}

static inline void attach_thread(void)
{
    if (!g_cache_tstates || t_attached) return;
    t_attached = 1;
    /* Thread state owned by someone else (the interpreter's main thread, another
     * FMU's guard, the host)? Then leave it alone: its owner deletes it. */
    if (pyloader_py.PyGILState_GetThisThreadState()) return;
    pyloader_py.PyGILState_Ensure();                /* creates this thread's state (counter 1), takes the GIL */
    void *tstate = pyloader_py.PyEval_SaveThread(); /* releases the GIL, keeps the thread state */
    pthread_setspecific(g_tstate_key, tstate);
}

__attribute__((destructor)) static void guard_unload(void)
{
    /* the key destructor lives in this library: never call it once unloaded */
    g_cache_tstates = 0;
    if (g_tstate_key_ok) pthread_key_delete(g_tstate_key);
    g_tstate_key_ok = 0;
    /* libpython and the pythonfmu binary stay loaded: the interpreter cannot be
     * restarted in a process, and pythonfmu's binary is NODELETE anyway (it has
     * STB_GNU_UNIQUE symbols, so glibc never unloads it). */
}

/* A guard started the interpreter on this thread, which keeps the main thread state. */
void pyloader_mark_thread_attached(void) { t_attached = 1; }

/* The interpreter is a guard's: keep one thread state per host thread from now on (once per process). */
void pyloader_cache_thread_states(void)
{
#ifndef PYLOADER_NO_TSTATE_CACHE
    if (!g_tstate_key_ok && pyloader_py.PyEval_RestoreThread && pyloader_py.PyThreadState_Clear &&
        pyloader_py.PyThreadState_DeleteCurrent && pyloader_py.PyGILState_GetThisThreadState) {
        if (pthread_key_create(&g_tstate_key, release_thread_state) == 0) {
            g_tstate_key_ok = 1;
            g_cache_tstates = 1;
        }
    }
#endif
}

void pyloader_attach_thread(void) { attach_thread(); }
