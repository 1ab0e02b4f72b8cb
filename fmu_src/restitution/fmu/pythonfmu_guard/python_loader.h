/* Python for pythonfmu's binary, in any host: see python_loader.c (and the pyloader_*.c it names). */
#ifndef PYTHON_LOADER_H
#define PYTHON_LOADER_H

#include "fmi2Functions.h" /* pythonfmu's binary is an FMI 2.0 FMU */
#include "rst_front.h"

/* pythonfmu's exported FMI functions the guard forwards to (its fmi2Component is pythonfmu's own). */
typedef struct {
    fmi2InstantiateTYPE *Instantiate;
    fmi2FreeInstanceTYPE *FreeInstance;
    fmi2SetupExperimentTYPE *SetupExperiment;
    fmi2EnterInitializationModeTYPE *EnterInitializationMode;
    fmi2ExitInitializationModeTYPE *ExitInitializationMode;
    fmi2TerminateTYPE *Terminate;
    fmi2ResetTYPE *Reset;
    fmi2GetRealTYPE *GetReal;
    fmi2GetIntegerTYPE *GetInteger;
    fmi2GetBooleanTYPE *GetBoolean;
    fmi2SetRealTYPE *SetReal;
    fmi2SetIntegerTYPE *SetInteger;
    fmi2SetBooleanTYPE *SetBoolean;
    fmi2DoStepTYPE *DoStep;
} pythonfmu_api;

/* Python running in this process (the host's, or started from resources/python_env.txt) and
 * pythonfmu's binary loaded: once per process. `resource_dir` is the FMU's resources directory.
 * Returns the binary's functions, or NULL after logging why through `inst`. */
const pythonfmu_api *pyloader_ensure_ready(rst_instance *inst, const char *resource_dir);

/* Call before every call into pythonfmu from a host thread (keeps one Python thread state per
 * thread when this module started the interpreter). */
void pyloader_attach_thread(void);

/* Around every call into pythonfmu in a Python host (fmpy, libcosimpy), once the held signals are only
 * noted (pythonfmu_backend.c): pyloader_enter_call takes the GIL and runs, on the
 * interpreter's main thread, the Python signal handlers and pending calls that were already due, so that
 * they cannot run inside the slave's code; what they raise is kept in `call`. pyloader_leave_call has it
 * raised again in the host's code (at the interpreter's next check, between two FMI calls) and releases
 * the GIL. pythonfmu's own PyGILState_Ensure inside the call then only counts. Both do nothing in a
 * plain C host. */
#define PYLOADER_MAX_RAISED 4
typedef struct {
    int gil;                            /* PyGILState_STATE taken by pyloader_enter_call, or -1 */
    int n_raised;                       /* exceptions kept in `raised` */
    void *raised[PYLOADER_MAX_RAISED][3]; /* (type, value, traceback), owned references */
} pyloader_call;
void pyloader_enter_call(pyloader_call *call);
void pyloader_leave_call(pyloader_call *call);

/* 1 when the interpreter is the host's own (a Python host: fmpy, libcosimpy), 0 when it was started
 * for the FMU (a plain C host). Valid after pyloader_ensure_ready succeeded. */
int pyloader_interpreter_is_hosts(void);

#endif
