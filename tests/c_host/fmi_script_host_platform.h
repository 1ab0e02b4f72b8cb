/* The scripted FMI host: what differs between Linux and Windows (loading the binary,
 * absolute paths, whether a Python library is loaded).
 * Part of fmi_script_host.c (its usage is there), included once by it: kept apart so that each file
 * stays readable; it relies on the types and helpers defined before the #include. */
#ifndef FMI_SCRIPT_HOST_PLATFORM_H
#define FMI_SCRIPT_HOST_PLATFORM_H

#ifdef _WIN32
#include <windows.h>
#include <tlhelp32.h>
#define BINARY_FORMAT "%s\\binaries\\" PLATFORM_DIR "\\%s.dll"
#if FMI_VERSION == 3
#define PLATFORM_DIR "x86_64-windows"
#else
#define PLATFORM_DIR "win64"
#endif
#define PATH_SEPARATOR '\\'
#define URI_PLAIN "-._~/:" /* bytes a file: URI keeps as they are (':' of the drive, Z:/...) */
typedef HMODULE lib_handle;
static lib_handle lib_open(const char *path) { return LoadLibraryExA(path, NULL, LOAD_WITH_ALTERED_SEARCH_PATH); }
static void *lib_sym(lib_handle lib, const char *name) { return (void *)(size_t)GetProcAddress(lib, name); }
static void lib_close(lib_handle lib) { FreeLibrary(lib); }
#define LOADER "LoadLibrary"
static const char *lib_why(void)
{
    static char why[64];
    snprintf(why, sizeof why, "Windows error %lu", (unsigned long)GetLastError());
    return why;
}
static int absolute_path(const char *path, char *out, size_t size) { return _fullpath(out, path, size) != NULL; }
static int python_loaded(void)
{
    HANDLE snap = CreateToolhelp32Snapshot(TH32CS_SNAPMODULE, GetCurrentProcessId());
    MODULEENTRY32 module;
    int python = 0;
    if (snap == INVALID_HANDLE_VALUE) return 0;
    module.dwSize = sizeof module;
    for (BOOL more = Module32First(snap, &module); more; more = Module32Next(snap, &module))
        python |= _strnicmp(module.szModule, "python", 6) == 0;
    CloseHandle(snap);
    return python;
}
#else
#include <dlfcn.h>
#define BINARY_FORMAT "%s/binaries/" PLATFORM_DIR "/%s.so"
#if FMI_VERSION == 3
#define PLATFORM_DIR "x86_64-linux"
#else
#define PLATFORM_DIR "linux64"
#endif
#define PATH_SEPARATOR '/'
#define URI_PLAIN "-._~/"
typedef void *lib_handle;
static lib_handle lib_open(const char *path) { return dlopen(path, RTLD_LAZY | RTLD_LOCAL); }
static void *lib_sym(lib_handle lib, const char *name) { return dlsym(lib, name); }
static void lib_close(lib_handle lib) { dlclose(lib); }
#define LOADER "dlopen"
static const char *lib_why(void)
{
    const char *why = dlerror();
    return why ? why : "unknown error";
}
static int absolute_path(const char *path, char *out, size_t size)
{
    char *full = realpath(path, NULL);
    int ok = full != NULL && strlen(full) < size;
    if (ok) strcpy(out, full);
    free(full);
    return ok;
}
static int python_loaded(void)
{
    char line[8192];
    int python = 0;
    FILE *maps = fopen("/proc/self/maps", "r");
    while (maps && fgets(line, sizeof line, maps))
        python |= strstr(line, "libpython") != NULL;
    if (maps) fclose(maps);
    return python;
}
#endif

#endif /* FMI_SCRIPT_HOST_PLATFORM_H */
