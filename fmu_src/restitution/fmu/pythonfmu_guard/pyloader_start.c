/*
 * pyloader_start.c - starts the embedded Python interpreter for the loader (python_loader.c), in a host
 * without Python, from the libpython it loaded and the paths of resources/python_env.txt.
 *
 * With PYLOADER_HAVE_PYTHON_H the interpreter is configured with PyConfig (clean error reporting, no
 * change to the host's locale or signal handlers) when the loaded libpython has the same major.minor
 * version as the headers; otherwise the legacy Py_SetProgramName/Py_InitializeEx(0) path is used.
 */
#ifdef PYLOADER_HAVE_PYTHON_H
#define PY_SSIZE_T_CLEAN
#include <Python.h> /* must come first; only types and macros are used */
#endif

#ifndef _GNU_SOURCE
#define _GNU_SOURCE
#endif
#include "pyloader_internal.h"

#include <dlfcn.h>
#include <limits.h>
#include <stddef.h>
#include <stdio.h>
#include <wchar.h>

int pyloader_same_major_minor(const char *a, const char *b)
{
    int a1 = 0, a2 = 0, b1 = 0, b2 = 0;
    return sscanf(a, "%d.%d", &a1, &a2) == 2 && sscanf(b, "%d.%d", &b1, &b2) == 2 && a1 == b1 && a2 == b2;
}

/* <home>/bin/python3.X (or python3) of the base installation, if it exists */
static int base_executable(const guard_config *cfg, char *out, size_t size)
{
    int major = 0, minor = 0;
    if (sscanf(cfg->version, "%d.%d", &major, &minor) == 2) {
        snprintf(out, size, "%s/bin/python%d.%d", cfg->home, major, minor);
        if (pyloader_file_exists(out)) return 1;
    }
    snprintf(out, size, "%s/bin/python3", cfg->home);
    return pyloader_file_exists(out);
}

#ifdef PYLOADER_HAVE_PYTHON_H
static int init_with_pyconfig(void *libpython, const guard_config *cfg, rst_instance *inst)
{
    typedef void (*PreInitFn)(PyPreConfig *);
    typedef PyStatus (*PreInitializeFn)(const PyPreConfig *);
    typedef void (*ConfigInitFn)(PyConfig *);
    typedef PyStatus (*SetBytesStringFn)(PyConfig *, wchar_t **, const char *);
    typedef PyStatus (*InitFromConfigFn)(const PyConfig *);
    typedef void (*ConfigClearFn)(PyConfig *);
    PreInitFn preInit = (PreInitFn)dlsym(libpython, "PyPreConfig_InitPythonConfig");
    PreInitializeFn preInitialize = (PreInitializeFn)dlsym(libpython, "Py_PreInitialize");
    ConfigInitFn configInit = (ConfigInitFn)dlsym(libpython, "PyConfig_InitPythonConfig");
    SetBytesStringFn setBytes = (SetBytesStringFn)dlsym(libpython, "PyConfig_SetBytesString");
    InitFromConfigFn initFromConfig = (InitFromConfigFn)dlsym(libpython, "Py_InitializeFromConfig");
    ConfigClearFn configClear = (ConfigClearFn)dlsym(libpython, "PyConfig_Clear");
    if (!preInit || !preInitialize || !configInit || !setBytes || !initFromConfig || !configClear) {
        LOG_ERROR("%s lacks the PyConfig API", cfg->libpython);
        return 0;
    }

    PyPreConfig pre;
    preInit(&pre);
    pre.utf8_mode = 1;         /* file names/IO as UTF-8 whatever the host's locale */
    pre.configure_locale = 0;  /* do not call setlocale() in the host process */
    pre.coerce_c_locale = 0;   /* do not set LC_CTYPE in the host's environment */
    pre.use_environment = cfg->use_environment;
    PyStatus st = preInitialize(&pre);
    if (st._type != 0) {
        LOG_ERROR("Python pre-initialization failed: %s%s%s", st.func ? st.func : "", st.func ? ": " : "",
                  st.err_msg ? st.err_msg : "unknown error");
        return 0;
    }

    PyConfig config;
    configInit(&config);
    config.install_signal_handlers = 0; /* leave SIGINT etc. to the host */
    config.parse_argv = 0;
    config.use_environment = cfg->use_environment;
    st._type = 0;
    if (pyloader_file_exists(cfg->executable)) {
        /* venv python: getpath/site find pyvenv.cfg next to it -> venv sys.prefix */
        st = setBytes(&config, &config.program_name, cfg->executable);
        if (st._type == 0) st = setBytes(&config, &config.executable, cfg->executable);
    } else if (cfg->home[0]) {
        char base_exe[PATH_MAX + 32];
        rst_log(inst, RST_WARNING, "Python executable %s (recorded in %s) does not exist; starting the interpreter with home=%s",
                 cfg->executable, cfg->file, cfg->home);
        st = setBytes(&config, &config.home, cfg->home);
        if (st._type == 0 && base_executable(cfg, base_exe, sizeof base_exe)) {
            st = setBytes(&config, &config.program_name, base_exe);
            if (st._type == 0) st = setBytes(&config, &config.executable, base_exe);
        }
    }
    if (st._type == 0) st = initFromConfig(&config);
    configClear(&config);
    if (st._type != 0) {
        LOG_ERROR("the embedded Python interpreter (%s) failed to start: %s%s%s. Check the paths in %s "
                  "(executable=%s, home=%s); the Python installation the FMU was built with must be present.",
                  cfg->libpython, st.func ? st.func : "", st.func ? ": " : "",
                  st.err_msg ? st.err_msg : "unknown error", cfg->file, cfg->executable, cfg->home);
        return 0;
    }
    return 1;
}
#endif

static int init_legacy(const guard_config *cfg, rst_instance *inst)
{
    if (!pyloader_py.Py_DecodeLocale || !pyloader_py.Py_SetProgramName || !pyloader_py.Py_InitializeEx) {
        LOG_ERROR("%s lacks Py_SetProgramName/Py_InitializeEx; rebuild the FMU with Python headers available",
                  cfg->libpython);
        return 0;
    }
    if (pyloader_file_exists(cfg->executable)) {
        static wchar_t *program; /* must stay valid for the interpreter's lifetime */
        program = pyloader_py.Py_DecodeLocale(cfg->executable, NULL);
        if (program) pyloader_py.Py_SetProgramName(program);
    } else if (cfg->home[0] && pyloader_file_exists(cfg->home) && pyloader_py.Py_SetPythonHome) {
        static wchar_t *home, *program;
        char base_exe[PATH_MAX + 32];
        rst_log(inst, RST_WARNING, "Python executable %s (recorded in %s) does not exist; starting the interpreter with home=%s",
                 cfg->executable, cfg->file, cfg->home);
        home = pyloader_py.Py_DecodeLocale(cfg->home, NULL);
        if (home) pyloader_py.Py_SetPythonHome(home);
        if (base_executable(cfg, base_exe, sizeof base_exe) &&
            (program = pyloader_py.Py_DecodeLocale(base_exe, NULL)))
            pyloader_py.Py_SetProgramName(program);
    } else {
        /* Py_InitializeEx aborts the process if it cannot find the standard library */
        LOG_ERROR("neither the Python executable %s nor the Python home %s recorded in %s exists; refusing to "
                  "start an interpreter that would abort the process.",
                  cfg->executable, cfg->home, cfg->file);
        return 0;
    }
    pyloader_py.Py_InitializeEx(0);
    return pyloader_py.Py_IsInitialized();
}

/* Starts the interpreter of `libpython` (its version `loaded`) as `cfg` says: 1, or 0 after logging why.
 * The GIL is held on return; the caller releases it. */
int pyloader_start_interpreter(void *libpython, const char *loaded, const guard_config *cfg,
                               rst_instance *inst)
{
    int ok = 0;
#ifdef PYLOADER_HAVE_PYTHON_H
    if (pyloader_same_major_minor(loaded, PY_VERSION))
        ok = init_with_pyconfig(libpython, cfg, inst);
    else
        ok = init_legacy(cfg, inst);
#else
    (void)libpython;
    (void)loaded;
    ok = init_legacy(cfg, inst);
#endif
    return ok;
}
