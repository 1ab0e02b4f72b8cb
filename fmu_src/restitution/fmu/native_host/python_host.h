/* Python for pythonfmu's binary, in any host: see python_host.c. */
#ifndef PYTHON_HOST_H
#define PYTHON_HOST_H

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
const pythonfmu_api *pyhost_ensure_ready(rst_instance *inst, const char *resource_dir);

/* Call before every call into pythonfmu from a host thread (keeps one Python thread state per
 * thread when this module started the interpreter). */
void pyhost_attach_thread(void);

/* 1 when the interpreter is the host's own (a Python host: fmpy, libcosimpy), 0 when it was started
 * for the FMU (a plain C host). Valid after pyhost_ensure_ready succeeded. */
int pyhost_interpreter_is_hosts(void);

#endif
