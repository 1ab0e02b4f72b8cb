/*
 * python_loader.c - makes Python available to pythonfmu's binary in any host, and loads that binary.
 *
 * Part of the guard in front of pythonfmu (pythonfmu_backend.c, on the C front of cfront/). pythonfmu's
 * binary (renamed to <modelIdentifier>_pythonfmu.so by build_guard.py) does not link libpython: it
 * expects a process that already contains a Python interpreter (fmpy, libcosimpy). In a C host,
 * dlopen fails with "undefined symbol: _Py_NoneStruct". On the first fmi2Instantiate:
 *
 *   1. If a Python interpreter is already initialized in the process (Python host such as fmpy or
 *      libcosimpy), nothing is changed: the real binary is loaded and uses that interpreter.
 *   2. Otherwise resources/python_env.txt (written at build time) names the interpreter: its
 *      libpython is loaded with RTLD_GLOBAL (so the pythonfmu binary and extension modules such as
 *      numpy resolve their Python symbols), the interpreter is started on the build environment's
 *      site-packages, the required modules are checked, the GIL is released (pythonfmu takes it with
 *      PyGILState_Ensure on every call and skips its own Py_Initialize when Python is running), and
 *      the real binary is loaded.
 *
 * Every failure is logged through the instance's logger; pyloader_ensure_ready then returns 0.
 * The state here is process-wide by nature (one interpreter, one pythonfmu binary per process),
 * guarded by a mutex.
 *
 * This file takes those steps, in order, and loads the binary. The loader's other files each do one
 * part (pyloader_internal.h declares what they share): pyloader_api.c, the Python C API resolved
 * with dlsym; pyloader_config.c, the guard's folder and python_env.txt; pyloader_start.c, starting
 * the interpreter; pyloader_preflight.c, site-packages and required modules; pyloader_threads.c, one
 * Python thread state per host thread; pyloader_lifetime.c, staying loaded and pythonfmu's exit-time
 * bug; pyloader_signals.c, the signal handlers due before a call in a Python host.
 */
#ifndef _GNU_SOURCE
#define _GNU_SOURCE
#endif
#include "pyloader_internal.h"

#include <dlfcn.h>
#include <limits.h>
#include <pthread.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>

#ifndef PYLOADER_REAL_BINARY
#error "define PYLOADER_REAL_BINARY, e.g. -DPYLOADER_REAL_BINARY='\"Model_pythonfmu.so\"'"
#endif
#ifndef PYLOADER_CONFIG_NAME
#define PYLOADER_CONFIG_NAME "python_env.txt"
#endif

static pythonfmu_api real;

/* ------------------------------------------------------------------------ */
/* State                                                                    */
/* ------------------------------------------------------------------------ */
static pthread_mutex_t g_lock = PTHREAD_MUTEX_INITIALIZER;
static int g_ready = 0;          /* real binary loaded and forwarding works   */
static int g_python_failed = 0;  /* our interpreter start failed: unrecoverable */
static int g_guard_managed = 0;   /* Python started by a guard (this or another) */
static void *g_libpython = NULL; /* handle from dlopen(libpython, RTLD_GLOBAL) */
static void *g_real = NULL;

/* ------------------------------------------------------------------------ */
/* Setup on first fmi2Instantiate (called with g_lock held)                 */
/* ------------------------------------------------------------------------ */
static int ensure_ready(rst_instance *inst, const char *resource_dir)
{
    char bindir[PATH_MAX] = "", cfg_a[PATH_MAX + 64] = "", cfg_b[PATH_MAX + 64] = "";
    char res_dir[PATH_MAX + 64] = "";
    guard_config cfg;
    int have_cfg = 0;

    if (g_ready) return 1; /* set up by an earlier fmi2Instantiate */
    if (!pyloader_guard_directory(bindir, sizeof bindir)) {
        LOG_ERROR("cannot determine the location of the FMU binary (dladdr failed)");
        return 0;
    }
    /* 1. resources next to the unpacked binary, 2. fmuResourceLocation */
    snprintf(cfg_a, sizeof cfg_a, "%s/../../resources/" PYLOADER_CONFIG_NAME, bindir);
    if (pyloader_read_config(cfg_a, &cfg)) {
        have_cfg = 1;
        snprintf(res_dir, sizeof res_dir, "%s/../../resources", bindir);
    } else if (resource_dir != NULL) {
        snprintf(cfg_b, sizeof cfg_b, "%s/" PYLOADER_CONFIG_NAME, resource_dir);
        if (pyloader_read_config(cfg_b, &cfg)) {
            have_cfg = 1;
            snprintf(res_dir, sizeof res_dir, "%s", resource_dir);
        }
    }
    char resolved[PATH_MAX];
    if (have_cfg && realpath(cfg.file, resolved)) snprintf(cfg.file, sizeof cfg.file, "%s", resolved);
    if (res_dir[0] && realpath(res_dir, resolved)) snprintf(res_dir, sizeof res_dir, "%s", resolved);

    if (g_python_failed) {
        LOG_ERROR("the embedded Python interpreter failed to start earlier in this process; see the first error");
        return 0;
    }

    /* Python already in the process? (Python host, or another FMU's guard) */
    void *is_init = dlsym(RTLD_DEFAULT, "Py_IsInitialized");
    if (is_init && ((int (*)(void))is_init)()) {
        const char *missing = pyloader_resolve_python_api(RTLD_DEFAULT);
        if (missing) {
            LOG_ERROR("Python is running in this process but symbol %s is not visible", missing);
            return 0;
        }
        g_guard_managed = pyloader_interpreter_is_guard_managed();
        rst_log(inst, RST_OK, "pythonfmu guard: using the Python %s already running "
                     "in this process%s", pyloader_py.Py_GetVersion(),
                     g_guard_managed ? " (started by another FMU)" : "");
    } else {
        if (!have_cfg) {
            LOG_ERROR("this FMU contains Python code and needs a Python interpreter; the host process has none, "
                      "and the configuration file naming the interpreter was not found (looked for %s%s%s). "
                      "Rebuild the FMU with build_guard.py or restore that file.",
                      cfg_a, cfg_b[0] ? " and " : "", cfg_b);
            return 0;
        }
        if (!cfg.libpython[0] || !(g_libpython = dlopen(cfg.libpython, RTLD_NOW | RTLD_GLOBAL))) {
            const char *err = cfg.libpython[0] ? dlerror() : "no libpython= line";
            LOG_ERROR("cannot load the Python shared library '%s' named in %s (%s). This FMU runs Python code "
                      "and needs the Python %s installation it was built with (interpreter %s, home %s) together "
                      "with the packages of its environment. Install that Python (built with --enable-shared, "
                      "i.e. providing libpython%.4s.so), or edit %s so that libpython= names an existing "
                      "libpython of that version and executable= the python (or venv python) whose "
                      "site-packages hold the required packages.",
                      cfg.libpython, cfg.file, err ? err : "?", cfg.version[0] ? cfg.version : "3",
                      cfg.executable, cfg.home, cfg.version, cfg.file);
            return 0;
        }
        const char *missing = pyloader_resolve_python_api(g_libpython);
        if (missing) {
            LOG_ERROR("%s is not a usable Python library (symbol %s missing)", cfg.libpython, missing);
            return 0;
        }
        const char *loaded = pyloader_py.Py_GetVersion();
        if (cfg.version[0] && !pyloader_same_major_minor(loaded, cfg.version))
            rst_log(inst, RST_WARNING,     "%s is Python %.10s but the FMU was built with Python %s", cfg.libpython, loaded, cfg.version);
        if (pyloader_py.Py_IsInitialized()) {
            g_guard_managed = pyloader_interpreter_is_guard_managed();
        } else {
            if (!pyloader_start_interpreter(g_libpython, loaded, &cfg, inst)) {
                g_python_failed = 1;
                return 0;
            }
            pyloader_py.PyEval_SaveThread(); /* release the GIL; pythonfmu uses PyGILState_Ensure */
            pyloader_mark_thread_attached(); /* this thread keeps the main thread state */
            g_guard_managed = 1;
            rst_log(inst, RST_OK, "pythonfmu guard: started embedded Python %s from %s (config %s)",
                         pyloader_py.Py_GetVersion(), cfg.libpython, cfg.file);
        }
    }

    if (g_guard_managed)
        pyloader_cache_thread_states(); /* one Python thread state per host thread from now on */

    /* Put the build environment's site-packages on sys.path and check imports. */
    if (g_guard_managed && have_cfg) {
        char msg[16384];
        int gil = pyloader_py.PyGILState_Ensure();
        pyloader_run_preflight(cfg.file, res_dir, msg, sizeof msg);
        pyloader_py.PyGILState_Release(gil);
        if (msg[0] == 'E') {
            LOG_ERROR("%s", msg + 2);
            return 0;
        }
        if (msg[0] == 'W') rst_log(inst, RST_WARNING, "%s", msg + 2);
    }

    if (!g_real) {
        char path[PATH_MAX + 64];
        snprintf(path, sizeof path, "%s/" PYLOADER_REAL_BINARY, bindir);
        g_real = dlopen(path, RTLD_NOW | RTLD_LOCAL);
        if (!g_real) {
            LOG_ERROR("cannot load the pythonfmu binary %s: %s", path, dlerror());
            return 0;
        }
        const char *missing = NULL;
#define PYLOADER_LOAD(field, name)                                                 \
    if (!(*(void **)(&real.field) = dlsym(g_real, #name)) && !missing) missing = #name;
        PYLOADER_LOAD(Instantiate, fmi2Instantiate)
        PYLOADER_LOAD(FreeInstance, fmi2FreeInstance)
        PYLOADER_LOAD(SetupExperiment, fmi2SetupExperiment)
        PYLOADER_LOAD(EnterInitializationMode, fmi2EnterInitializationMode)
        PYLOADER_LOAD(ExitInitializationMode, fmi2ExitInitializationMode)
        PYLOADER_LOAD(Terminate, fmi2Terminate)
        PYLOADER_LOAD(Reset, fmi2Reset)
        PYLOADER_LOAD(GetReal, fmi2GetReal)
        PYLOADER_LOAD(GetInteger, fmi2GetInteger)
        PYLOADER_LOAD(GetBoolean, fmi2GetBoolean)
        PYLOADER_LOAD(SetReal, fmi2SetReal)
        PYLOADER_LOAD(SetInteger, fmi2SetInteger)
        PYLOADER_LOAD(SetBoolean, fmi2SetBoolean)
        PYLOADER_LOAD(DoStep, fmi2DoStep)
#undef PYLOADER_LOAD
        if (missing) {
            LOG_ERROR("%s does not export %s", path, missing);
            dlclose(g_real);
            g_real = NULL;
            return 0;
        }
        pyloader_arm_pystate_exit_fix(g_real, path);
    }
    pyloader_pin_self();
    g_ready = 1;
    return 1;
}

/* ------------------------------------------------------------------------ */
/* Public                                                                   */
/* ------------------------------------------------------------------------ */
const pythonfmu_api *pyloader_ensure_ready(rst_instance *inst, const char *resource_dir)
{
    int ok;
    pthread_mutex_lock(&g_lock);
    ok = ensure_ready(inst, resource_dir);
    pthread_mutex_unlock(&g_lock);
    if (!ok)
        return NULL;
    pyloader_attach_thread();
    return &real;
}

int pyloader_interpreter_is_hosts(void) { return !g_guard_managed; }
