/*
 * pyloader_signals.c - the Python signal handlers that were due before a call into pythonfmu, in a
 * Python host (fmpy, libcosimpy): run before the call, not inside the slave, and what they raise raised
 * again in the host's code (pyloader_enter_call, pyloader_leave_call; see python_loader.h).
 */
#ifndef _GNU_SOURCE
#define _GNU_SOURCE
#endif
#include "pyloader_internal.h"

#include <stdlib.h>
#include <string.h>

/* A signal that arrives while the host runs Python code or C code before the guard has set the host's
 * handler aside (the ctypes call, the front's checks) only sets a flag of the interpreter: the Python
 * handler runs at the eval loop's next check, which without this is inside the slave's code
 * (KeyboardInterrupt there, which pythonfmu answers with fmi2Fatal). Py_MakePendingCalls runs the due
 * handlers and pending calls now, on the interpreter's main thread only (elsewhere it returns 0); an
 * exception stops it, so it is called again until nothing more fails. */
static int pending_ready(void)
{
    return pyloader_interpreter_is_hosts() && pyloader_py.Py_MakePendingCalls && pyloader_py.Py_AddPendingCall &&
           pyloader_py.PyErr_Fetch && pyloader_py.PyErr_Restore;
}

void pyloader_enter_call(pyloader_call *call)
{
    if (call == NULL)
        return;
    call->gil = -1;
    call->n_raised = 0;
    if (!pending_ready())
        return;
    /* held until pyloader_leave_call: pythonfmu's Ensure only counts */
    call->gil = pyloader_py.PyGILState_Ensure();
    while (call->n_raised < PYLOADER_MAX_RAISED && pyloader_py.Py_MakePendingCalls() != 0) {
        void **kept = call->raised[call->n_raised];
        pyloader_py.PyErr_Fetch((PyObj **)&kept[0], (PyObj **)&kept[1], (PyObj **)&kept[2]);
        if (kept[0] == NULL) /* failed without an exception: nothing to hand on, and nothing more to run */
            break;
        call->n_raised++;
    }
}

/* A pending call: the exception a signal handler raised before a call, raised again in the host's code. */
static int raise_again(void *arg)
{
    void **kept = (void **)arg;
    pyloader_py.PyErr_Restore(kept[0], kept[1], kept[2]); /* steals the references */
    free(kept);
    return -1;
}

void pyloader_leave_call(pyloader_call *call)
{
    int i;
    if (call == NULL || call->gil == -1)
        return;
    for (i = 0; i < call->n_raised; i++) {
        void **kept = (void **)malloc(3 * sizeof(void *));
        if (kept != NULL) {
            memcpy(kept, call->raised[i], 3 * sizeof(void *));
            if (pyloader_py.Py_AddPendingCall(raise_again, kept) == 0)
                continue;
            free(kept);
        }
        /* out of memory or the interpreter's queue of pending calls full: the exception is lost */
        if (call->raised[i][0]) pyloader_py.Py_DecRef(call->raised[i][0]);
        if (call->raised[i][1]) pyloader_py.Py_DecRef(call->raised[i][1]);
        if (call->raised[i][2]) pyloader_py.Py_DecRef(call->raised[i][2]);
    }
    call->n_raised = 0;
    pyloader_py.PyGILState_Release(call->gil);
    call->gil = -1;
}
