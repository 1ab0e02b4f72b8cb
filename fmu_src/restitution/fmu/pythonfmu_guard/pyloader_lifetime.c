/*
 * pyloader_lifetime.c - how long the guard and pythonfmu's binary stay loaded, for the loader
 * (python_loader.c): the guard pins itself once ready, and disarms a pythonfmu 0.7 bug that releases
 * freed memory at process exit.
 */
#ifndef _GNU_SOURCE
#define _GNU_SOURCE
#endif
#include "pyloader_internal.h"

#include <dlfcn.h>
#include <link.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* Stay loaded once ready, like the pythonfmu binary (which glibc never unloads): pythonfmu keeps
 * pointers into this library (the guard's logger and callback structs) for the process's lifetime. */
void pyloader_pin_self(void)
{
    Dl_info self;
    if (dladdr((void *)&pyloader_pin_self, &self) && self.dli_fname)
        dlopen(self.dli_fname, RTLD_LAZY | RTLD_NOLOAD | RTLD_NODELETE);
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

void pyloader_arm_pystate_exit_fix(void *real, const char *real_path)
{
    struct stat st;
    struct link_map *map = NULL;
    if (stat(real_path, &st) != 0 || st.st_size != (off_t)PYLOADER_REAL_SIZE) return;
    if (dlinfo(real, RTLD_DI_LINKMAP, &map) != 0 || !map) return;
    g_pystate_slot = (void *)(map->l_addr + (uintptr_t)PYLOADER_PYSTATE_OFFSET);
    Dl_info self;
    if (dladdr((void *)&disarm_pythonfmu_pystate, &self) && self.dli_fname)
        dlopen(self.dli_fname, RTLD_LAZY | RTLD_NOLOAD | RTLD_NODELETE); /* never unloaded from now on */
    atexit(disarm_pythonfmu_pystate);
}
#else
void pyloader_arm_pystate_exit_fix(void *real, const char *real_path)
{
    (void)real;
    (void)real_path;
}
#endif
