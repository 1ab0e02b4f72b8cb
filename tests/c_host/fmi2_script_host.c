/*
 * Scriptable FMI 2.0 co-simulation host in plain C: drives several instances of one FMU
 * through a script read from stdin, the way C/C++ simulation tools call an FMU. The same
 * program builds for Linux (gcc; dlopen(RTLD_LAZY | RTLD_LOCAL) of binaries/linux64/<id>.so)
 * and for Windows (x86_64-w64-mingw32-gcc; LoadLibrary of binaries/win64/<id>.dll); the
 * process knows nothing about Python.
 *
 * Usage:  fmi2_script_host <unpacked_fmu_dir> <modelIdentifier> <guid> < script
 * (on Windows the directory is a Windows path, e.g. Z:\tmp\fmu under Wine). The host passes
 * fmi2Instantiate the file: URI of <dir>/resources, percent-encoded as RFC 3986 asks.
 *
 * Script: one command per line (S is an instance slot, numbered from 0 in the order of
 * "instantiate"; values are parsed with strtod, so nan and inf are accepted; # starts a comment):
 *   instantiate NAME          fmi2Instantiate (co-simulation, loggingOn)
 *   setup S T0                fmi2SetupExperiment(S, no tolerance, T0, no stop time)
 *   enter_init S | exit_init S | terminate S | reset S | free S
 *   set_real S VR VALUE       set_integer S VR VALUE       set_boolean S VR 0|1
 *   get_real S VR...          get_integer S VR...          get_boolean S VR...
 *   step S T H                fmi2DoStep(S, T, H, noSetFMUStatePriorToCurrentPoint = true)
 *   get_state S | set_state S | free_state S                (one stored state per slot)
 *   serialize S | deserialize S [FROM]   via the slot's byte buffer (size, serialize; deserialize
 *                             the bytes of slot FROM, default S, into slot S's state)
 *   deserialize_file S PATH   fmi2DeSerializeFMUstate of the bytes of a file (hostile states)
 *   set_foreign_state S       fmi2SetFMUstate with a pointer that is no state of the FMU's
 *   instantiate_bad KIND      fmi2Instantiate with one bad argument (null_name, empty_name, wrong_guid,
 *                             null_guid, null_callbacks, null_logger, null_alloc, model_exchange,
 *                             bad_uri); prints BAD_INSTANCE <KIND> <NULL|NONNULL> (a non-NULL one is freed)
 *   get_string S VR | set_string S VR      String calls (this FMU has no String variable)
 *
 * Output (stdout, flushed after every command and every log message):
 *   INFO <fmi2GetVersion> <fmi2GetTypesPlatform>         first, once the binary is loaded
 *   LOG <instance> <status> <category>: <message>      every logger callback
 *   STATUS <command> <slot> <OK|Warning|Discard|Error|Fatal>   every fmi2 call
 *   REAL <slot> <vr> <%.17g>, INTEGER <slot> <vr> <%d>, BOOLEAN <slot> <vr> <0|1>
 *   SERIALIZED <slot> <bytes>
 *   INSTANCE <slot> <name>    or INSTANTIATE_FAILED (then exit code 3)
 *   FREED <slot>
 *   LIBPYTHON <0|1>           at the end: whether a Python library (Linux: libpython*, Windows:
 *                             python*.dll) is loaded into the process
 *   DONE                      the last line: the script ran to its end
 *
 * Exit codes: 0 script done, 1 usage/script error, 2 cannot load the binary or a symbol,
 * 3 fmi2Instantiate returned NULL.
 *
 * Build:  gcc -O2 -Wall -Wextra -Werror -o fmi2_script_host fmi2_script_host.c -ldl
 *         x86_64-w64-mingw32-gcc -O2 -Wall -Wextra -Werror -D__USE_MINGW_ANSI_STDIO=1 -static -static-libgcc \
 *             -o fmi2_script_host.exe fmi2_script_host.c
 * (C99; __USE_MINGW_ANSI_STDIO: C99 printf/strtod, so %.17g round-trips, %zu works and "nan" parses.)
 */
#ifndef _WIN32
#define _XOPEN_SOURCE 700 /* realpath */
#endif
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* --- what differs between the platforms: loading the binary, absolute paths, loaded libraries --- */
#ifdef _WIN32
#include <windows.h>
#include <tlhelp32.h>
#define BINARY_FORMAT "%s\\binaries\\win64\\%s.dll"
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
#define BINARY_FORMAT "%s/binaries/linux64/%s.so"
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

typedef void *fmi2Component;
typedef void *fmi2ComponentEnvironment;
typedef void *fmi2FMUstate;
typedef unsigned int fmi2ValueReference;
typedef double fmi2Real;
typedef int fmi2Integer;
typedef int fmi2Boolean;
typedef char fmi2Byte;
typedef const char *fmi2String;
typedef enum { fmi2OK, fmi2Warning, fmi2Discard, fmi2Error, fmi2Fatal, fmi2Pending } fmi2Status;
typedef enum { fmi2ModelExchange, fmi2CoSimulation } fmi2Type;

typedef void (*fmi2CallbackLogger)(fmi2ComponentEnvironment, fmi2String, fmi2Status, fmi2String, fmi2String, ...);
typedef struct {
    fmi2CallbackLogger logger;
    void *(*allocateMemory)(size_t, size_t);
    void (*freeMemory)(void *);
    void (*stepFinished)(fmi2ComponentEnvironment, fmi2Status);
    fmi2ComponentEnvironment componentEnvironment;
} fmi2CallbackFunctions;

typedef fmi2Component (*InstantiateT)(fmi2String, fmi2Type, fmi2String, fmi2String, const fmi2CallbackFunctions *,
                                      fmi2Boolean, fmi2Boolean);
typedef void (*FreeInstanceT)(fmi2Component);
typedef fmi2Status (*SetupT)(fmi2Component, fmi2Boolean, fmi2Real, fmi2Real, fmi2Boolean, fmi2Real);
typedef fmi2Status (*ComponentOnlyT)(fmi2Component);
typedef fmi2Status (*SetRealT)(fmi2Component, const fmi2ValueReference[], size_t, const fmi2Real[]);
typedef fmi2Status (*GetRealT)(fmi2Component, const fmi2ValueReference[], size_t, fmi2Real[]);
typedef fmi2Status (*SetIntT)(fmi2Component, const fmi2ValueReference[], size_t, const fmi2Integer[]);
typedef fmi2Status (*GetIntT)(fmi2Component, const fmi2ValueReference[], size_t, fmi2Integer[]);
typedef fmi2Status (*DoStepT)(fmi2Component, fmi2Real, fmi2Real, fmi2Boolean);
typedef fmi2Status (*GetStateT)(fmi2Component, fmi2FMUstate *);
typedef fmi2Status (*SetStateT)(fmi2Component, fmi2FMUstate);
typedef fmi2Status (*StateSizeT)(fmi2Component, fmi2FMUstate, size_t *);
typedef fmi2Status (*SerializeT)(fmi2Component, fmi2FMUstate, fmi2Byte[], size_t);
typedef fmi2Status (*DeserializeT)(fmi2Component, const fmi2Byte[], size_t, fmi2FMUstate *);
typedef fmi2Status (*StringT)(fmi2Component, const fmi2ValueReference[], size_t, fmi2String[]);
typedef const char *(*InfoT)(void);

#define MAX_SLOTS 16
#define MAX_VRS 256
#define MAX_TOKENS (MAX_VRS + 4)
#define MAX_PATH_BYTES 4096

static const char *status_name(fmi2Status s)
{
    static const char *names[] = {"OK", "Warning", "Discard", "Error", "Fatal", "Pending"};
    return ((unsigned)s < 6u) ? names[s] : "?";
}

static void logger(fmi2ComponentEnvironment env, fmi2String instance, fmi2Status status, fmi2String category,
                   fmi2String message, ...)
{
    va_list ap;
    (void)env;
    printf("LOG %s %s %s: ", instance ? instance : "?", status_name(status), category ? category : "");
    va_start(ap, message);
    vprintf(message ? message : "", ap);
    va_end(ap);
    printf("\n");
    fflush(stdout);
}

static lib_handle lib;
static void *sym(const char *name)
{
    void *p = lib_sym(lib, name);
    if (!p) {
        fprintf(stderr, "fmi2_script_host: missing symbol %s: %s\n", name, lib_why());
        exit(2);
    }
    return p;
}

static void report(const char *cmd, int slot, fmi2Status st)
{
    printf("STATUS %s %d %s\n", cmd, slot, status_name(st));
}

/* Split a line at blanks into at most max tokens (no strtok_r: not in every C runtime). */
static int split(char *line, char **tokens, int max)
{
    int n = 0;
    char *p = line;
    while (*p && n < max) {
        while (*p == ' ' || *p == '\t' || *p == '\r' || *p == '\n') *p++ = '\0';
        if (!*p) break;
        tokens[n++] = p;
        while (*p && *p != ' ' && *p != '\t' && *p != '\r' && *p != '\n') p++;
    }
    if (*p) *p = '\0';
    return n;
}

/* The file: URI of <dir>/resources, percent-encoded as RFC 3986 asks (unreserved bytes and '/' as
 * is; the platform's path separator becomes '/'; a Windows drive path gets file:///Z:/...). */
static void resource_uri(const char *dir, char *uri, size_t size)
{
    char raw[MAX_PATH_BYTES + 16];
    size_t k = (size_t)snprintf(uri, size, "file://");
    snprintf(raw, sizeof raw, "%s%cresources", dir, PATH_SEPARATOR);
    if (raw[0] != '/' && raw[0] != PATH_SEPARATOR) uri[k++] = '/';
    for (const unsigned char *p = (const unsigned char *)raw; *p && k + 4 < size; p++) {
        if (*p == PATH_SEPARATOR)
            uri[k++] = '/';
        else if ((*p >= 'a' && *p <= 'z') || (*p >= 'A' && *p <= 'Z') || (*p >= '0' && *p <= '9') ||
                 strchr(URI_PLAIN, *p))
            uri[k++] = (char)*p;
        else
            k += (size_t)snprintf(uri + k, size - k, "%%%02X", *p);
    }
    uri[k] = '\0';
}

int main(int argc, char **argv)
{
    if (argc != 4) {
        fprintf(stderr, "usage: %s <unpacked_fmu_dir> <modelIdentifier> <guid> < script\n", argv[0]);
        return 1;
    }
    char dir[MAX_PATH_BYTES];
    if (!absolute_path(argv[1], dir, sizeof dir)) {
        perror(argv[1]);
        return 1;
    }
    char lib_path[MAX_PATH_BYTES + 256], resources[3 * MAX_PATH_BYTES + 64];
    snprintf(lib_path, sizeof lib_path, BINARY_FORMAT, dir, argv[2]);
    resource_uri(dir, resources, sizeof resources);
    lib = lib_open(lib_path);
    if (!lib) {
        fprintf(stderr, "fmi2_script_host: " LOADER " failed: %s\n", lib_why());
        return 2;
    }
    InstantiateT instantiate = (InstantiateT)sym("fmi2Instantiate");
    FreeInstanceT free_instance = (FreeInstanceT)sym("fmi2FreeInstance");
    SetupT setup = (SetupT)sym("fmi2SetupExperiment");
    ComponentOnlyT enter_init = (ComponentOnlyT)sym("fmi2EnterInitializationMode");
    ComponentOnlyT exit_init = (ComponentOnlyT)sym("fmi2ExitInitializationMode");
    ComponentOnlyT terminate = (ComponentOnlyT)sym("fmi2Terminate");
    ComponentOnlyT reset = (ComponentOnlyT)sym("fmi2Reset");
    SetRealT set_real = (SetRealT)sym("fmi2SetReal");
    GetRealT get_real = (GetRealT)sym("fmi2GetReal");
    SetIntT set_integer = (SetIntT)sym("fmi2SetInteger");
    GetIntT get_integer = (GetIntT)sym("fmi2GetInteger");
    SetIntT set_boolean = (SetIntT)sym("fmi2SetBoolean");
    GetIntT get_boolean = (GetIntT)sym("fmi2GetBoolean");
    DoStepT do_step = (DoStepT)sym("fmi2DoStep");
    GetStateT get_state = (GetStateT)sym("fmi2GetFMUstate");
    SetStateT set_state = (SetStateT)sym("fmi2SetFMUstate");
    GetStateT free_state = (GetStateT)sym("fmi2FreeFMUstate");
    StateSizeT state_size = (StateSizeT)sym("fmi2SerializedFMUstateSize");
    SerializeT serialize = (SerializeT)sym("fmi2SerializeFMUstate");
    DeserializeT deserialize = (DeserializeT)sym("fmi2DeSerializeFMUstate");
    StringT get_string = (StringT)sym("fmi2GetString");
    StringT set_string = (StringT)sym("fmi2SetString");
    InfoT get_version = (InfoT)sym("fmi2GetVersion");
    InfoT get_platform = (InfoT)sym("fmi2GetTypesPlatform");
    printf("INFO %s %s\n", get_version(), get_platform());
    fflush(stdout);

    fmi2CallbackFunctions cb = {logger, calloc, free, NULL, NULL};
    fmi2Component inst[MAX_SLOTS] = {0};
    fmi2FMUstate state[MAX_SLOTS] = {0};
    fmi2Byte *blob[MAX_SLOTS] = {0};
    size_t blob_size[MAX_SLOTS] = {0};
    int nslots = 0;

    char line[8192];
    char *tok[MAX_TOKENS];
    for (; fgets(line, sizeof line, stdin); fflush(stdout)) {
        int n = split(line, tok, MAX_TOKENS);
        if (n == 0 || tok[0][0] == '#') continue;
        const char *cmd = tok[0];
        if (!strcmp(cmd, "instantiate")) {
            if (n < 2 || nslots == MAX_SLOTS) return 1;
            inst[nslots] = instantiate(tok[1], fmi2CoSimulation, argv[3], resources, &cb, 0, 1);
            if (!inst[nslots]) {
                printf("INSTANTIATE_FAILED\n");
                return 3;
            }
            printf("INSTANCE %d %s\n", nslots, tok[1]);
            nslots++;
            continue;
        }
        if (!strcmp(cmd, "instantiate_bad")) {
            fmi2CallbackFunctions no_logger = {NULL, calloc, free, NULL, NULL};
            fmi2CallbackFunctions no_alloc = {logger, NULL, free, NULL, NULL};
            const char *kind = n > 1 ? tok[1] : "", *name = "bad", *guid = argv[3], *uri = resources;
            const fmi2CallbackFunctions *callbacks = &cb;
            fmi2Type type = fmi2CoSimulation;
            fmi2Component c;
            if (!strcmp(kind, "null_name")) name = NULL;
            else if (!strcmp(kind, "empty_name")) name = "";
            else if (!strcmp(kind, "wrong_guid")) guid = "{00000000-0000-0000-0000-000000000000}";
            else if (!strcmp(kind, "null_guid")) guid = NULL;
            else if (!strcmp(kind, "null_callbacks")) callbacks = NULL;
            else if (!strcmp(kind, "null_logger")) callbacks = &no_logger;
            else if (!strcmp(kind, "null_alloc")) callbacks = &no_alloc;
            else if (!strcmp(kind, "model_exchange")) type = fmi2ModelExchange;
            else if (!strcmp(kind, "bad_uri")) uri = "file:///nonexistent/%00/resources";
            else return 1;
            c = instantiate(name, type, guid, uri, callbacks, 0, 1);
            printf("BAD_INSTANCE %s %s\n", kind, c ? "NONNULL" : "NULL");
            if (c) free_instance(c);
            continue;
        }
        if (n < 2) return 1;
        int s = atoi(tok[1]);
        if (s < 0 || s >= nslots || !inst[s]) {
            fprintf(stderr, "fmi2_script_host: bad slot in '%s'\n", cmd);
            return 1;
        }
        fmi2Component c = inst[s];
        const char *a = n > 2 ? tok[2] : NULL, *b = n > 3 ? tok[3] : NULL;
        if (!strcmp(cmd, "setup")) {
            report(cmd, s, setup(c, 0, 0.0, a ? strtod(a, NULL) : 0.0, 0, 0.0));
        } else if (!strcmp(cmd, "enter_init")) {
            report(cmd, s, enter_init(c));
        } else if (!strcmp(cmd, "exit_init")) {
            report(cmd, s, exit_init(c));
        } else if (!strcmp(cmd, "terminate")) {
            report(cmd, s, terminate(c));
        } else if (!strcmp(cmd, "reset")) {
            report(cmd, s, reset(c));
        } else if (!strcmp(cmd, "free")) {
            free_instance(c);
            inst[s] = NULL;
            printf("FREED %d\n", s);
        } else if (!strcmp(cmd, "set_real") && b) {
            fmi2ValueReference vr = (fmi2ValueReference)strtoul(a, NULL, 10);
            fmi2Real v = strtod(b, NULL);
            report(cmd, s, set_real(c, &vr, 1, &v));
        } else if ((!strcmp(cmd, "set_integer") || !strcmp(cmd, "set_boolean")) && b) {
            fmi2ValueReference vr = (fmi2ValueReference)strtoul(a, NULL, 10);
            fmi2Integer v = (fmi2Integer)strtol(b, NULL, 10);
            report(cmd, s, (cmd[4] == 'i' ? set_integer : set_boolean)(c, &vr, 1, &v));
        } else if ((!strcmp(cmd, "get_real") || !strcmp(cmd, "get_integer") || !strcmp(cmd, "get_boolean")) && a) {
            fmi2ValueReference vrs[MAX_VRS];
            size_t nv = 0;
            for (int i = 2; i < n && nv < MAX_VRS; i++) vrs[nv++] = (fmi2ValueReference)strtoul(tok[i], NULL, 10);
            if (!strcmp(cmd, "get_real")) {
                fmi2Real out[MAX_VRS];
                fmi2Status st = get_real(c, vrs, nv, out);
                report(cmd, s, st);
                for (size_t i = 0; i < nv && st <= fmi2Warning; i++) printf("REAL %d %u %.17g\n", s, vrs[i], out[i]);
            } else {
                fmi2Integer out[MAX_VRS];
                int is_int = !strcmp(cmd, "get_integer");
                fmi2Status st = (is_int ? get_integer : get_boolean)(c, vrs, nv, out);
                report(cmd, s, st);
                for (size_t i = 0; i < nv && st <= fmi2Warning; i++)
                    printf("%s %d %u %d\n", is_int ? "INTEGER" : "BOOLEAN", s, vrs[i], out[i]);
            }
        } else if (!strcmp(cmd, "step") && b) {
            report(cmd, s, do_step(c, strtod(a, NULL), strtod(b, NULL), 1));
        } else if (!strcmp(cmd, "get_state")) {
            report(cmd, s, get_state(c, &state[s]));
        } else if (!strcmp(cmd, "set_state")) {
            report(cmd, s, set_state(c, state[s]));
        } else if (!strcmp(cmd, "free_state")) {
            report(cmd, s, free_state(c, &state[s]));
        } else if (!strcmp(cmd, "serialize")) {
            size_t size = 0;
            fmi2Status st = state_size(c, state[s], &size);
            if (st <= fmi2Warning) {
                free(blob[s]);
                blob[s] = malloc(size ? size : 1);
                blob_size[s] = size;
                st = serialize(c, state[s], blob[s], size);
            }
            report(cmd, s, st);
            printf("SERIALIZED %d %zu\n", s, blob_size[s]);
        } else if (!strcmp(cmd, "deserialize_file") && a) {
            FILE *f = fopen(a, "rb");
            static fmi2Byte bytes[1 << 16];
            size_t size = f ? fread(bytes, 1, sizeof bytes, f) : 0;
            if (f) fclose(f);
            report(cmd, s, deserialize(c, bytes, size, &state[s]));
        } else if (!strcmp(cmd, "set_foreign_state")) {
            double not_a_state[64] = {0};
            report(cmd, s, set_state(c, (fmi2FMUstate)not_a_state));
        } else if ((!strcmp(cmd, "get_string") || !strcmp(cmd, "set_string")) && a) {
            fmi2ValueReference vr = (fmi2ValueReference)strtoul(a, NULL, 10);
            fmi2String text[1] = {"text"};
            report(cmd, s, (cmd[0] == 'g' ? get_string : set_string)(c, &vr, 1, text));
        } else if (!strcmp(cmd, "deserialize")) {
            int from = a ? atoi(a) : s;
            if (from < 0 || from >= nslots || !blob[from]) return 1;
            report(cmd, s, deserialize(c, blob[from], blob_size[from], &state[s]));
        } else {
            fprintf(stderr, "fmi2_script_host: unknown or incomplete command '%s'\n", cmd);
            return 1;
        }
    }
    for (int s = 0; s < nslots; s++) free(blob[s]);
    printf("LIBPYTHON %d\n", python_loaded());
    printf("DONE\n");
    fflush(stdout);
    lib_close(lib);
    return 0;
}
