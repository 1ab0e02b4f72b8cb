/*
 * pyloader_api.c - the Python C API of the loader (python_loader.c), resolved with dlsym: the guard never
 * links libpython, so every Python function it calls is looked up in the libpython it loaded or, in a
 * Python host, in the process (RTLD_DEFAULT). The table is process-wide, like the interpreter; it is
 * filled under the loader's mutex before the first call into pythonfmu.
 */
#ifndef _GNU_SOURCE
#define _GNU_SOURCE
#endif
#include "pyloader_internal.h"

#include <dlfcn.h>
#include <stddef.h>

pyloader_python_api pyloader_py;

const char *pyloader_resolve_python_api(void *handle)
{
#define RESOLVE(name)                                           \
    do {                                                        \
        *(void **)(&pyloader_py.name) = dlsym(handle, #name);   \
        if (!pyloader_py.name) return #name;                    \
    } while (0)
    RESOLVE(Py_IsInitialized);
    RESOLVE(Py_GetVersion);
    RESOLVE(PyGILState_Ensure);
    RESOLVE(PyGILState_Release);
    RESOLVE(PyEval_SaveThread);
    RESOLVE(PyRun_SimpleStringFlags);
    RESOLVE(PyImport_ImportModule);
    RESOLVE(PyObject_GetAttrString);
    RESOLVE(PyUnicode_AsUTF8);
    RESOLVE(Py_DecRef);
    RESOLVE(PyErr_Clear);
#undef RESOLVE
    *(void **)(&pyloader_py.Py_MakePendingCalls) = dlsym(handle, "Py_MakePendingCalls");
    *(void **)(&pyloader_py.Py_AddPendingCall) = dlsym(handle, "Py_AddPendingCall");
    *(void **)(&pyloader_py.PyErr_Fetch) = dlsym(handle, "PyErr_Fetch");
    *(void **)(&pyloader_py.PyErr_Restore) = dlsym(handle, "PyErr_Restore");
    *(void **)(&pyloader_py.PyEval_RestoreThread) = dlsym(handle, "PyEval_RestoreThread");
    *(void **)(&pyloader_py.PyThreadState_Clear) = dlsym(handle, "PyThreadState_Clear");
    *(void **)(&pyloader_py.PyThreadState_DeleteCurrent) = dlsym(handle, "PyThreadState_DeleteCurrent");
    *(void **)(&pyloader_py.PyGILState_GetThisThreadState) = dlsym(handle, "PyGILState_GetThisThreadState");
    /* optional: only needed by the legacy initialization path */
    *(void **)(&pyloader_py.Py_DecodeLocale) = dlsym(handle, "Py_DecodeLocale");
    *(void **)(&pyloader_py.Py_SetProgramName) = dlsym(handle, "Py_SetProgramName");
    *(void **)(&pyloader_py.Py_SetPythonHome) = dlsym(handle, "Py_SetPythonHome");
    *(void **)(&pyloader_py.Py_InitializeEx) = dlsym(handle, "Py_InitializeEx");
    return NULL;
}
