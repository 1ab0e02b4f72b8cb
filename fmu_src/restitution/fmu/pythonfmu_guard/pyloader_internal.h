/* What the loader's files share (python_loader.c and pyloader_*.c); pythonfmu_backend.c uses
 * python_loader.h. */
#ifndef PYLOADER_INTERNAL_H
#define PYLOADER_INTERNAL_H

#include "python_loader.h"

#include <limits.h>
#include <stddef.h>
#include <wchar.h>

#if defined(RST_PREFIXED)
#define pyloader_py RST_PREFIXED(pyloader_py)
#define pyloader_resolve_python_api RST_PREFIXED(pyloader_resolve_python_api)
#define pyloader_file_exists RST_PREFIXED(pyloader_file_exists)
#define pyloader_guard_directory RST_PREFIXED(pyloader_guard_directory)
#define pyloader_read_config RST_PREFIXED(pyloader_read_config)
#define pyloader_run_preflight RST_PREFIXED(pyloader_run_preflight)
#define pyloader_interpreter_is_guard_managed RST_PREFIXED(pyloader_interpreter_is_guard_managed)
#define pyloader_same_major_minor RST_PREFIXED(pyloader_same_major_minor)
#define pyloader_start_interpreter RST_PREFIXED(pyloader_start_interpreter)
#define pyloader_mark_thread_attached RST_PREFIXED(pyloader_mark_thread_attached)
#define pyloader_cache_thread_states RST_PREFIXED(pyloader_cache_thread_states)
#define pyloader_pin_self RST_PREFIXED(pyloader_pin_self)
#define pyloader_arm_pystate_exit_fix RST_PREFIXED(pyloader_arm_pystate_exit_fix)
#endif

#define LOG_ERROR(...) rst_log(inst, RST_ERROR, __VA_ARGS__)

/* The Python C API, resolved with dlsym (pyloader_api.c; the guard never links libpython). */
typedef void PyObj;
typedef struct {
    int (*Py_IsInitialized)(void);
    const char *(*Py_GetVersion)(void);
    int (*PyGILState_Ensure)(void);
    void (*PyGILState_Release)(int);
    void *(*PyEval_SaveThread)(void);
    /* optional: only needed for the per-thread state cache */
    void (*PyEval_RestoreThread)(void *);
    void (*PyThreadState_Clear)(void *);
    void (*PyThreadState_DeleteCurrent)(void);
    void *(*PyGILState_GetThisThreadState)(void);
    int (*PyRun_SimpleStringFlags)(const char *, void *);
    PyObj *(*PyImport_ImportModule)(const char *);
    PyObj *(*PyObject_GetAttrString)(PyObj *, const char *);
    const char *(*PyUnicode_AsUTF8)(PyObj *);
    void (*Py_DecRef)(PyObj *);
    void (*PyErr_Clear)(void);
    /* optional: only needed to keep the host's pending signal handlers out of the slave */
    int (*Py_MakePendingCalls)(void);
    int (*Py_AddPendingCall)(int (*)(void *), void *);
    void (*PyErr_Fetch)(PyObj **, PyObj **, PyObj **);
    void (*PyErr_Restore)(PyObj *, PyObj *, PyObj *);
    /* legacy initialization */
    wchar_t *(*Py_DecodeLocale)(const char *, size_t *);
    void (*Py_SetProgramName)(const wchar_t *);
    void (*Py_SetPythonHome)(const wchar_t *);
    void (*Py_InitializeEx)(int);
} pyloader_python_api;
extern pyloader_python_api pyloader_py;
/* Fills pyloader_py from `handle` (a libpython, or RTLD_DEFAULT): NULL, or the first required symbol
 * that is missing. */
const char *pyloader_resolve_python_api(void *handle);

/* Where the guard is and what resources/python_env.txt says (pyloader_config.c). */
typedef struct {
    char file[PATH_MAX];       /* the configuration file that was read */
    char libpython[PATH_MAX];  /* libpython3.X.so.1.0 of the build interpreter */
    char executable[PATH_MAX]; /* sys.executable at build time (venv python) */
    char home[PATH_MAX];       /* sys.base_prefix at build time */
    char version[64];          /* e.g. 3.11.7 */
    int use_environment;       /* honour PYTHONPATH/PYTHONHOME etc. (default 0) */
} guard_config;
int pyloader_file_exists(const char *path);
int pyloader_guard_directory(char *out, size_t size); /* directory containing this guard library */
int pyloader_read_config(const char *file, guard_config *cfg); /* 0: the file cannot be read */

/* The preflight check (pyloader_preflight.c), with the GIL held: the recorded site-packages on sys.path,
 * the required modules imported; `msg` starts with "E:" (fatal), "W:" (warning) or is "". */
void pyloader_run_preflight(const char *cfg_file, const char *res_dir, char *msg, size_t size);
int pyloader_interpreter_is_guard_managed(void); /* the running interpreter was started by a guard */

/* Interpreter start-up (pyloader_start.c). */
int pyloader_same_major_minor(const char *a, const char *b); /* "3.11.7" and "3.11" agree */
/* Starts the interpreter of `libpython` (its version `loaded`): 1, or 0 after logging why; the GIL is held
 * on return. */
int pyloader_start_interpreter(void *libpython, const char *loaded, const guard_config *cfg,
                               rst_instance *inst);

/* Thread states (pyloader_threads.c), when a guard started the interpreter. */
void pyloader_mark_thread_attached(void);
void pyloader_cache_thread_states(void);

/* How long the guard and pythonfmu's binary stay loaded (pyloader_lifetime.c). */
void pyloader_pin_self(void);
void pyloader_arm_pystate_exit_fix(void *real, const char *real_path);

#endif
