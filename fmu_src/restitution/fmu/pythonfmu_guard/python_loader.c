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
#include "python_loader.h"

#include <dlfcn.h>
#include <errno.h>
#include <limits.h>
#include <link.h>
#include <pthread.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <wchar.h>

#ifndef PYLOADER_REAL_BINARY
#error "define PYLOADER_REAL_BINARY, e.g. -DPYLOADER_REAL_BINARY='\"Model_pythonfmu.so\"'"
#endif
#ifndef PYLOADER_CONFIG_NAME
#define PYLOADER_CONFIG_NAME "python_env.txt"
#endif

static pythonfmu_api real;

/* ------------------------------------------------------------------------ */
/* Python C API, resolved with dlsym (the guard never links libpython)       */
/* ------------------------------------------------------------------------ */
typedef void PyObj;
static struct {
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
} py;

static const char *resolve_python_api(void *handle)
{
#define RESOLVE(name)                                           \
    do {                                                        \
        *(void **)(&py.name) = dlsym(handle, #name);            \
        if (!py.name) return #name;                             \
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
    *(void **)(&py.Py_MakePendingCalls) = dlsym(handle, "Py_MakePendingCalls");
    *(void **)(&py.Py_AddPendingCall) = dlsym(handle, "Py_AddPendingCall");
    *(void **)(&py.PyErr_Fetch) = dlsym(handle, "PyErr_Fetch");
    *(void **)(&py.PyErr_Restore) = dlsym(handle, "PyErr_Restore");
    *(void **)(&py.PyEval_RestoreThread) = dlsym(handle, "PyEval_RestoreThread");
    *(void **)(&py.PyThreadState_Clear) = dlsym(handle, "PyThreadState_Clear");
    *(void **)(&py.PyThreadState_DeleteCurrent) = dlsym(handle, "PyThreadState_DeleteCurrent");
    *(void **)(&py.PyGILState_GetThisThreadState) = dlsym(handle, "PyGILState_GetThisThreadState");
    /* optional: only needed by the legacy initialization path */
    *(void **)(&py.Py_DecodeLocale) = dlsym(handle, "Py_DecodeLocale");
    *(void **)(&py.Py_SetProgramName) = dlsym(handle, "Py_SetProgramName");
    *(void **)(&py.Py_SetPythonHome) = dlsym(handle, "Py_SetPythonHome");
    *(void **)(&py.Py_InitializeEx) = dlsym(handle, "Py_InitializeEx");
    return NULL;
}

/* ------------------------------------------------------------------------ */
/* State                                                                    */
/* ------------------------------------------------------------------------ */
static pthread_mutex_t g_lock = PTHREAD_MUTEX_INITIALIZER;
static int g_ready = 0;          /* real binary loaded and forwarding works   */
static int g_python_failed = 0;  /* our interpreter start failed: unrecoverable */
static int g_guard_managed = 0;   /* Python started by a guard (this or another) */
static void *g_libpython = NULL; /* handle from dlopen(libpython, RTLD_GLOBAL) */
static void *g_real = NULL;

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

typedef struct {
    char file[PATH_MAX];       /* the configuration file that was read */
    char libpython[PATH_MAX];  /* libpython3.X.so.1.0 of the build interpreter */
    char executable[PATH_MAX]; /* sys.executable at build time (venv python) */
    char home[PATH_MAX];       /* sys.base_prefix at build time */
    char version[64];          /* e.g. 3.11.7 */
    int use_environment;       /* honour PYTHONPATH/PYTHONHOME etc. (default 0) */
} guard_config;

/* ------------------------------------------------------------------------ */
/* Helpers                                                                  */
/* ------------------------------------------------------------------------ */
#define LOG_ERROR(...) rst_log(inst, RST_ERROR, __VA_ARGS__)

static int file_exists(const char *path)
{
    struct stat st;
    return path && *path && stat(path, &st) == 0;
}

/* directory containing this guard library (binaries/linux64) */
static int guard_directory(char *out, size_t size)
{
    Dl_info info;
    char resolved[PATH_MAX];
    if (!dladdr((void *)&guard_directory, &info) || !info.dli_fname) return 0;
    if (!realpath(info.dli_fname, resolved)) return 0;
    char *slash = strrchr(resolved, '/');
    if (!slash) return 0;
    *slash = '\0';
    snprintf(out, size, "%s", resolved);
    return 1;
}

static void trim(char *s)
{
    size_t n = strlen(s);
    while (n && (s[n - 1] == '\n' || s[n - 1] == '\r' || s[n - 1] == ' ' || s[n - 1] == '\t')) s[--n] = '\0';
    size_t i = 0;
    while (s[i] == ' ' || s[i] == '\t') i++;
    if (i) memmove(s, s + i, n - i + 1);
}

static int read_config(const char *file, guard_config *cfg)
{
    FILE *f = fopen(file, "r");
    if (!f) return 0;
    memset(cfg, 0, sizeof *cfg);
    snprintf(cfg->file, sizeof cfg->file, "%s", file);
    char line[PATH_MAX + 64];
    while (fgets(line, sizeof line, f)) {
        trim(line);
        if (!line[0] || line[0] == '#') continue;
        char *eq = strchr(line, '=');
        if (!eq) continue;
        *eq = '\0';
        char *key = line, *value = eq + 1;
        trim(key);
        trim(value);
        if (!strcmp(key, "libpython"))
            snprintf(cfg->libpython, sizeof cfg->libpython, "%s", value);
        else if (!strcmp(key, "executable"))
            snprintf(cfg->executable, sizeof cfg->executable, "%s", value);
        else if (!strcmp(key, "home"))
            snprintf(cfg->home, sizeof cfg->home, "%s", value);
        else if (!strcmp(key, "python_version"))
            snprintf(cfg->version, sizeof cfg->version, "%s", value);
        else if (!strcmp(key, "use_environment"))
            cfg->use_environment = atoi(value) != 0;
        /* site= and require= lines are read by the Python preflight code */
    }
    fclose(f);
    return 1;
}

/* Python bytes literal for an arbitrary path: b'\x2f...' then os.fsdecode() */
static void py_bytes_literal(const char *s, char *out, size_t size)
{
    size_t n = 0;
    if (size < 4) return;
    out[n++] = 'b';
    out[n++] = '\'';
    for (const unsigned char *p = (const unsigned char *)s; *p && n + 6 < size; p++) {
        if ((*p >= 'a' && *p <= 'z') || (*p >= 'A' && *p <= 'Z') || (*p >= '0' && *p <= '9') || *p == '/' ||
            *p == '.' || *p == '_' || *p == '-')
            out[n++] = (char)*p;
        else
            n += (size_t)snprintf(out + n, size - n, "\\x%02x", *p);
    }
    out[n++] = '\'';
    out[n] = '\0';
}

/* ------------------------------------------------------------------------ */
/* Preflight: put the recorded site-packages on sys.path, check that the    */
/* required modules import. Runs with the GIL held. Returns a message       */
/* starting with "E:" (fatal), "W:" (warning) or "" in msg.                 */
/* ------------------------------------------------------------------------ */
static const char PREFLIGHT_CODE[] =
    "def _pythonfmu_native_host_preflight(cfg_path, res_dir):\n"
    "    import os, sys, site\n"
    "    sites, requires = [], []\n"
    "    with open(cfg_path, 'r', encoding='utf-8', errors='surrogateescape') as f:\n"
    "        for raw in f:\n"
    "            line = raw.strip()\n"
    "            if not line or line.startswith('#') or '=' not in line:\n"
    "                continue\n"
    "            key, value = (s.strip() for s in line.split('=', 1))\n"
    "            if key == 'site' and value:\n"
    "                sites.append(value)\n"
    "            elif key == 'require':\n"
    "                requires.extend(m.strip() for m in value.split(',') if m.strip())\n"
    "    missing_dirs = [d for d in sites if not os.path.isdir(d)]\n"
    "    for d in sites:\n"
    "        if d not in missing_dirs and d not in sys.path:\n"
    "            site.addsitedir(d)\n"
    "    failed = []\n"
    "    for mod in requires:\n"
    "        try:\n"
    "            __import__(mod)\n"
    "        except BaseException as exc:\n"
    "            failed.append('%s (%s: %s)' % (mod, type(exc).__name__, exc))\n"
    "    sys._pythonfmu_native_host = True\n"
    "    req_txt = os.path.join(res_dir, 'requirements.txt')\n"
    "    if failed:\n"
    "        lines = ['this FMU needs Python modules that the embedded interpreter cannot import: '\n"
    "                 + '; '.join(failed) + '.',\n"
    "                 'Interpreter: %s (Python %s), sys.prefix=%s.' % (sys.executable,\n"
    "                 sys.version.split()[0], sys.prefix)]\n"
    "        if missing_dirs:\n"
    "            lines.append('site-packages directories recorded at build time that no longer exist: '\n"
    "                         + ', '.join(missing_dirs) + '.')\n"
    "        lines.append('sys.path=%r.' % (sys.path,))\n"
    "        inst = 'requirements.txt (' + req_txt + ')' if os.path.isfile(req_txt) else 'the packages providing: ' + ', '.join(m.split(' ')[0] for m in failed)\n"
    "        lines.append('Fix: install ' + inst + ' into that Python environment (' + sys.executable\n"
    "                     + ' -m pip install ...), or edit ' + cfg_path + ' (executable=, libpython=, site= lines)'\n"
    "                     + ' to point to a Python environment that has them.')\n"
    "        return 'E:' + ' '.join(lines)\n"
    "    if missing_dirs:\n"
    "        return 'W:site-packages directories recorded in %s do not exist: %s' % (cfg_path, ', '.join(missing_dirs))\n"
    "    return ''\n"
    "import sys as _pfmu_sys\n"
    "try:\n"
    "    _pfmu_sys._pythonfmu_native_host_msg = _pythonfmu_native_host_preflight(\n"
    "        __import__('os').fsdecode(@CFG@), __import__('os').fsdecode(@RES@))\n"
    "except BaseException as _pfmu_exc:\n"
    "    _pfmu_sys._pythonfmu_native_host_msg = 'E:preflight check failed: %r' % (_pfmu_exc,)\n"
    "del _pythonfmu_native_host_preflight, _pfmu_sys\n";

/* copy src to dst replacing the first occurrence of token by value */
static void replace_token(char *dst, size_t size, const char *src, const char *token, const char *value)
{
    const char *at = strstr(src, token);
    if (!at) {
        snprintf(dst, size, "%s", src);
        return;
    }
    snprintf(dst, size, "%.*s%s%s", (int)(at - src), src, value, at + strlen(token));
}

static void run_preflight(const char *cfg_file, const char *res_dir, char *msg, size_t size)
{
    char lit_cfg[4 * PATH_MAX + 8], lit_res[4 * PATH_MAX + 8];
    py_bytes_literal(cfg_file, lit_cfg, sizeof lit_cfg);
    py_bytes_literal(res_dir, lit_res, sizeof lit_res);
    size_t n = sizeof PREFLIGHT_CODE + strlen(lit_cfg) + strlen(lit_res) + 16;
    char *tmp = malloc(n), *code = malloc(n);
    msg[0] = '\0';
    if (!tmp || !code) {
        free(tmp);
        free(code);
        snprintf(msg, size, "E:out of memory");
        return;
    }
    replace_token(tmp, n, PREFLIGHT_CODE, "@CFG@", lit_cfg);
    replace_token(code, n, tmp, "@RES@", lit_res);
    free(tmp);
    int rc = py.PyRun_SimpleStringFlags(code, NULL);
    free(code);
    if (rc != 0) {
        snprintf(msg, size, "E:the preflight Python code failed (traceback on stderr)");
        return;
    }
    PyObj *sys = py.PyImport_ImportModule("sys");
    if (!sys) {
        py.PyErr_Clear();
        if (!msg[0]) snprintf(msg, size, "E:cannot import sys");
        return;
    }
    PyObj *m = py.PyObject_GetAttrString(sys, "_pythonfmu_native_host_msg");
    if (m) {
        const char *s = py.PyUnicode_AsUTF8(m);
        if (s) snprintf(msg, size, "%s", s);
        py.Py_DecRef(m);
    }
    py.PyErr_Clear();
    py.Py_DecRef(sys);
}

/* Is the running interpreter one started by a guard (marker set in preflight)? */
static int interpreter_is_guard_managed(void)
{
    int managed = 0;
    int gil = py.PyGILState_Ensure();
    PyObj *sys = py.PyImport_ImportModule("sys");
    if (sys) {
        PyObj *marker = py.PyObject_GetAttrString(sys, "_pythonfmu_native_host");
        if (marker) {
            managed = 1;
            py.Py_DecRef(marker);
        }
        py.Py_DecRef(sys);
    }
    py.PyErr_Clear();
    py.PyGILState_Release(gil);
    return managed;
}

/* Thread exit: delete the thread state kept by attach_thread. glibc may already
 * have cleared CPython's own thread-local key, so PyGILState_* cannot be used. */
__attribute__((unused)) static void release_thread_state(void *tstate)
{
    if (!g_cache_tstates || !tstate) return;
    py.PyEval_RestoreThread(tstate); /* take the GIL with this thread state */
    py.PyThreadState_Clear(tstate);
    py.PyThreadState_DeleteCurrent(); /* deletes it and releases the GIL */
}

static inline void attach_thread(void)
{
    if (!g_cache_tstates || t_attached) return;
    t_attached = 1;
    /* Thread state owned by someone else (the interpreter's main thread, another
     * FMU's guard, the host)? Then leave it alone: its owner deletes it. */
    if (py.PyGILState_GetThisThreadState()) return;
    py.PyGILState_Ensure();                  /* creates this thread's state (counter 1), takes the GIL */
    void *tstate = py.PyEval_SaveThread();   /* releases the GIL, keeps the thread state */
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


/* pythonfmu 0.7 bug at process exit: its static std::shared_ptr<PyState> pyState is
 * destroyed by the exit handlers (__cxa_atexit), then its __attribute__((destructor))
 * onLibraryUnload assigns nullptr to the destroyed object and so releases the already
 * freed control block again (valgrind: invalid read in finalizePythonInterpreter). That
 * write into freed heap memory made plain C hosts abort at exit ("free(): corrupted
 * unsorted chunks", in libgfortran's fini) once scipy had loaded libgfortran. The handler
 * below is registered right after the pythonfmu binary is loaded, so it runs before that
 * binary's static destructors (exit handlers run last-in, first-out): it empties the
 * shared_ptr (pointer and control block, two words), after which both the destructor and
 * onLibraryUnload do nothing; the PyState is left to the process exit (the interpreter is
 * never finalized anyway). build_guard.py finds the symbol's offset in the binary's
 * symbol table at build time; the binary's size guards against a different binary.
 * atexit() from a shared library is tied to that library: glibc runs the handler when the
 * library is dlclosed (fmpy's freeInstance does), not at exit. It then emptied pyState at
 * every unload, leaking the PyState and its finished but never joined std::thread (an 8 MB
 * stack mapping per load/free cycle), and the next instance made a new one. So the guard
 * pins itself (RTLD_NODELETE) before registering the handler: it stays loaded like the
 * pythonfmu binary, the handler runs once at process exit, and a reload reuses the state. */
#if defined(PYLOADER_PYSTATE_OFFSET) && defined(PYLOADER_REAL_SIZE)
static void *g_pystate_slot = NULL;

static void disarm_pythonfmu_pystate(void)
{
    if (g_pystate_slot) memset(g_pystate_slot, 0, 2 * sizeof(void *));
    g_pystate_slot = NULL;
}

static void arm_pystate_exit_fix(const char *real_path)
{
    struct stat st;
    struct link_map *map = NULL;
    if (stat(real_path, &st) != 0 || st.st_size != (off_t)PYLOADER_REAL_SIZE) return;
    if (dlinfo(g_real, RTLD_DI_LINKMAP, &map) != 0 || !map) return;
    g_pystate_slot = (void *)(map->l_addr + (uintptr_t)PYLOADER_PYSTATE_OFFSET);
    Dl_info self;
    if (dladdr((void *)&disarm_pythonfmu_pystate, &self) && self.dli_fname)
        dlopen(self.dli_fname, RTLD_LAZY | RTLD_NOLOAD | RTLD_NODELETE); /* never unloaded from now on */
    atexit(disarm_pythonfmu_pystate);
}
#else
static void arm_pystate_exit_fix(const char *real_path) { (void)real_path; }
#endif

/* ------------------------------------------------------------------------ */
/* Interpreter start-up (GIL held on return, caller releases it)            */
/* ------------------------------------------------------------------------ */
static int same_major_minor(const char *a, const char *b)
{
    int a1 = 0, a2 = 0, b1 = 0, b2 = 0;
    return sscanf(a, "%d.%d", &a1, &a2) == 2 && sscanf(b, "%d.%d", &b1, &b2) == 2 && a1 == b1 && a2 == b2;
}

/* Stay loaded once ready, like the pythonfmu binary (which glibc never unloads): pythonfmu keeps
 * pointers into this library (the guard's logger and callback structs) for the process's lifetime. */
static void pin_self(void)
{
    Dl_info self;
    if (dladdr((void *)&pin_self, &self) && self.dli_fname)
        dlopen(self.dli_fname, RTLD_LAZY | RTLD_NOLOAD | RTLD_NODELETE);
}

/* <home>/bin/python3.X (or python3) of the base installation, if it exists */
static int base_executable(const guard_config *cfg, char *out, size_t size)
{
    int major = 0, minor = 0;
    if (sscanf(cfg->version, "%d.%d", &major, &minor) == 2) {
        snprintf(out, size, "%s/bin/python%d.%d", cfg->home, major, minor);
        if (file_exists(out)) return 1;
    }
    snprintf(out, size, "%s/bin/python3", cfg->home);
    return file_exists(out);
}

#ifdef PYLOADER_HAVE_PYTHON_H
static int init_with_pyconfig(const guard_config *cfg, rst_instance *inst)
{
    typedef void (*PreInitFn)(PyPreConfig *);
    typedef PyStatus (*PreInitializeFn)(const PyPreConfig *);
    typedef void (*ConfigInitFn)(PyConfig *);
    typedef PyStatus (*SetBytesStringFn)(PyConfig *, wchar_t **, const char *);
    typedef PyStatus (*InitFromConfigFn)(const PyConfig *);
    typedef void (*ConfigClearFn)(PyConfig *);
    PreInitFn preInit = (PreInitFn)dlsym(g_libpython, "PyPreConfig_InitPythonConfig");
    PreInitializeFn preInitialize = (PreInitializeFn)dlsym(g_libpython, "Py_PreInitialize");
    ConfigInitFn configInit = (ConfigInitFn)dlsym(g_libpython, "PyConfig_InitPythonConfig");
    SetBytesStringFn setBytes = (SetBytesStringFn)dlsym(g_libpython, "PyConfig_SetBytesString");
    InitFromConfigFn initFromConfig = (InitFromConfigFn)dlsym(g_libpython, "Py_InitializeFromConfig");
    ConfigClearFn configClear = (ConfigClearFn)dlsym(g_libpython, "PyConfig_Clear");
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
    if (file_exists(cfg->executable)) {
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
    if (!py.Py_DecodeLocale || !py.Py_SetProgramName || !py.Py_InitializeEx) {
        LOG_ERROR("%s lacks Py_SetProgramName/Py_InitializeEx; rebuild the FMU with Python headers available",
                  cfg->libpython);
        return 0;
    }
    if (file_exists(cfg->executable)) {
        static wchar_t *program; /* must stay valid for the interpreter's lifetime */
        program = py.Py_DecodeLocale(cfg->executable, NULL);
        if (program) py.Py_SetProgramName(program);
    } else if (cfg->home[0] && file_exists(cfg->home) && py.Py_SetPythonHome) {
        static wchar_t *home, *program;
        char base_exe[PATH_MAX + 32];
        rst_log(inst, RST_WARNING, "Python executable %s (recorded in %s) does not exist; starting the interpreter with home=%s",
                 cfg->executable, cfg->file, cfg->home);
        home = py.Py_DecodeLocale(cfg->home, NULL);
        if (home) py.Py_SetPythonHome(home);
        if (base_executable(cfg, base_exe, sizeof base_exe) && (program = py.Py_DecodeLocale(base_exe, NULL)))
            py.Py_SetProgramName(program);
    } else {
        /* Py_InitializeEx aborts the process if it cannot find the standard library */
        LOG_ERROR("neither the Python executable %s nor the Python home %s recorded in %s exists; refusing to "
                  "start an interpreter that would abort the process.",
                  cfg->executable, cfg->home, cfg->file);
        return 0;
    }
    py.Py_InitializeEx(0);
    return py.Py_IsInitialized();
}

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
    if (!guard_directory(bindir, sizeof bindir)) {
        LOG_ERROR("cannot determine the location of the FMU binary (dladdr failed)");
        return 0;
    }
    /* 1. resources next to the unpacked binary, 2. fmuResourceLocation */
    snprintf(cfg_a, sizeof cfg_a, "%s/../../resources/" PYLOADER_CONFIG_NAME, bindir);
    if (read_config(cfg_a, &cfg)) {
        have_cfg = 1;
        snprintf(res_dir, sizeof res_dir, "%s/../../resources", bindir);
    } else if (resource_dir != NULL) {
        snprintf(cfg_b, sizeof cfg_b, "%s/" PYLOADER_CONFIG_NAME, resource_dir);
        if (read_config(cfg_b, &cfg)) {
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
        const char *missing = resolve_python_api(RTLD_DEFAULT);
        if (missing) {
            LOG_ERROR("Python is running in this process but symbol %s is not visible", missing);
            return 0;
        }
        g_guard_managed = interpreter_is_guard_managed();
        rst_log(inst, RST_OK, "pythonfmu guard: using the Python %s already running "
                     "in this process%s", py.Py_GetVersion(), g_guard_managed ? " (started by another FMU)" : "");
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
        const char *missing = resolve_python_api(g_libpython);
        if (missing) {
            LOG_ERROR("%s is not a usable Python library (symbol %s missing)", cfg.libpython, missing);
            return 0;
        }
        const char *loaded = py.Py_GetVersion();
        if (cfg.version[0] && !same_major_minor(loaded, cfg.version))
            rst_log(inst, RST_WARNING,     "%s is Python %.10s but the FMU was built with Python %s", cfg.libpython, loaded, cfg.version);
        if (py.Py_IsInitialized()) {
            g_guard_managed = interpreter_is_guard_managed();
        } else {
            int ok = 0;
#ifdef PYLOADER_HAVE_PYTHON_H
            if (same_major_minor(loaded, PY_VERSION))
                ok = init_with_pyconfig(&cfg, inst);
            else
                ok = init_legacy(&cfg, inst);
#else
            ok = init_legacy(&cfg, inst);
#endif
            if (!ok) {
                g_python_failed = 1;
                return 0;
            }
            py.PyEval_SaveThread(); /* release the GIL; pythonfmu uses PyGILState_Ensure */
            t_attached = 1;         /* this thread keeps the main thread state */
            g_guard_managed = 1;
            rst_log(inst, RST_OK, "pythonfmu guard: started embedded Python %s from %s (config %s)",
                         py.Py_GetVersion(), cfg.libpython, cfg.file);
        }
    }

#ifndef PYLOADER_NO_TSTATE_CACHE
    if (g_guard_managed && !g_tstate_key_ok && py.PyEval_RestoreThread && py.PyThreadState_Clear &&
        py.PyThreadState_DeleteCurrent && py.PyGILState_GetThisThreadState) {
        if (pthread_key_create(&g_tstate_key, release_thread_state) == 0) {
            g_tstate_key_ok = 1;
            g_cache_tstates = 1;
        }
    }
#endif

    /* Put the build environment's site-packages on sys.path and check imports. */
    if (g_guard_managed && have_cfg) {
        char msg[16384];
        int gil = py.PyGILState_Ensure();
        run_preflight(cfg.file, res_dir, msg, sizeof msg);
        py.PyGILState_Release(gil);
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
        arm_pystate_exit_fix(path);
    }
    pin_self();
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
    attach_thread();
    return &real;
}

void pyloader_attach_thread(void) { attach_thread(); }

/* ------------------------------------------------------------------------ */
/* Signal handlers that were due before a call (Python hosts only)          */
/* ------------------------------------------------------------------------ */
/* A signal that arrives while the host runs Python code or C code before the guard has set the host's
 * handler aside (the ctypes call, the front's checks) only sets a flag of the interpreter: the Python
 * handler runs at the eval loop's next check, which without this is inside the slave's code
 * (KeyboardInterrupt there, which pythonfmu answers with fmi2Fatal). Py_MakePendingCalls runs the due
 * handlers and pending calls now, on the interpreter's main thread only (elsewhere it returns 0); an
 * exception stops it, so it is called again until nothing more fails. */
static int pending_ready(void)
{
    return !g_guard_managed && py.Py_MakePendingCalls && py.Py_AddPendingCall && py.PyErr_Fetch &&
           py.PyErr_Restore;
}

void pyloader_enter_call(pyloader_call *call)
{
    if (call == NULL)
        return;
    call->gil = -1;
    call->n_raised = 0;
    if (!pending_ready())
        return;
    call->gil = py.PyGILState_Ensure(); /* held until pyloader_leave_call: pythonfmu's Ensure only counts */
    while (call->n_raised < PYLOADER_MAX_RAISED && py.Py_MakePendingCalls() != 0) {
        void **kept = call->raised[call->n_raised];
        py.PyErr_Fetch((PyObj **)&kept[0], (PyObj **)&kept[1], (PyObj **)&kept[2]);
        if (kept[0] == NULL) /* failed without an exception: nothing to hand on, and nothing more to run */
            break;
        call->n_raised++;
    }
}

/* A pending call: the exception a signal handler raised before a call, raised again in the host's code. */
static int raise_again(void *arg)
{
    void **kept = (void **)arg;
    py.PyErr_Restore(kept[0], kept[1], kept[2]); /* steals the references */
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
            if (py.Py_AddPendingCall(raise_again, kept) == 0)
                continue;
            free(kept);
        }
        /* out of memory or the interpreter's queue of pending calls full: the exception is lost */
        if (call->raised[i][0]) py.Py_DecRef(call->raised[i][0]);
        if (call->raised[i][1]) py.Py_DecRef(call->raised[i][1]);
        if (call->raised[i][2]) py.Py_DecRef(call->raised[i][2]);
    }
    call->n_raised = 0;
    py.PyGILState_Release(call->gil);
    call->gil = -1;
}

int pyloader_interpreter_is_hosts(void) { return !g_guard_managed; }
