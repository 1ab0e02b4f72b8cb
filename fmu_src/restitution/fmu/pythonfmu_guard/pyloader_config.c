/*
 * pyloader_config.c - where the guard is and what its configuration says, for the loader
 * (python_loader.c): the folder of the guard's library (binaries/linux64, where pythonfmu's binary lies
 * too) and resources/python_env.txt, written at build time by build_guard.py, which names the
 * interpreter to start in a host without Python (libpython, executable, home, version).
 */
#ifndef _GNU_SOURCE
#define _GNU_SOURCE
#endif
#include "pyloader_internal.h"

#include <dlfcn.h>
#include <limits.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

int pyloader_file_exists(const char *path)
{
    struct stat st;
    return path && *path && stat(path, &st) == 0;
}

/* directory containing this guard library (binaries/linux64) */
int pyloader_guard_directory(char *out, size_t size)
{
    Dl_info info;
    char resolved[PATH_MAX];
    if (!dladdr((void *)&pyloader_guard_directory, &info) || !info.dli_fname) return 0;
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

int pyloader_read_config(const char *file, guard_config *cfg)
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
