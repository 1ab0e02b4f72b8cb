/*
 * Scriptable FMI 2.0 co-simulation host in plain C that builds for Linux (gcc, dlopen) and for
 * Windows (x86_64-w64-mingw32-gcc, LoadLibrary): the same program, the same script, on both
 * platforms' binaries of an FMU. tests/test_native_win64.py runs the Windows build under Wine on
 * binaries/win64/<model>.dll and the Linux build on binaries/linux64/<model>.so, and compares.
 *
 * Usage:  fmi2_portable_host <FMU binary> <guid> <resource URI> < script
 *
 * Script: one command per line (S is an instance slot, numbered from 0 in the order of
 * "instantiate"; values are parsed with strtod, so nan and inf are accepted):
 *   instantiate NAME          fmi2Instantiate (co-simulation, loggingOn)
 *   setup S T0                fmi2SetupExperiment(S, no tolerance, T0, no stop time)
 *   enter_init S | exit_init S | terminate S | reset S | free S
 *   set_real S VR VALUE       set_integer S VR VALUE       set_boolean S VR 0|1
 *   get_real S VR...          get_integer S VR...          get_boolean S VR...
 *   step S T H                fmi2DoStep(S, T, H, noSetFMUStatePriorToCurrentPoint = true)
 *
 * Output (stdout, flushed after every line):
 *   INFO <fmi2GetVersion> <fmi2GetTypesPlatform>
 *   LOG <instance> <status> <category>: <message>      every logger callback
 *   STATUS <command> <slot> <OK|Warning|Discard|Error|Fatal>   every fmi2 call
 *   REAL <slot> <vr> <%.17g>, INTEGER <slot> <vr> <%d>, BOOLEAN <slot> <vr> <0|1>
 *   INSTANCE <slot> <name>    or INSTANTIATE_FAILED (then exit code 3)
 *   DONE                      the script ran to its end
 *
 * Exit codes: 0 script done, 1 usage/script error, 2 cannot load the binary or a symbol,
 * 3 fmi2Instantiate returned NULL.
 *
 * Build:  gcc -O2 -o fmi2_portable_host fmi2_portable_host.c -ldl
 *         x86_64-w64-mingw32-gcc -O2 -D__USE_MINGW_ANSI_STDIO=1 -static -static-libgcc \
 *             -o fmi2_portable_host.exe fmi2_portable_host.c
 * (__USE_MINGW_ANSI_STDIO: C99 printf/strtod, so %.17g round-trips and "nan" parses.)
 */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef _WIN32
#include <windows.h>
typedef HMODULE lib_handle;
static lib_handle lib_open(const char *path) { return LoadLibraryA(path); }
static void *lib_sym(lib_handle lib, const char *name) { return (void *)(size_t)GetProcAddress(lib, name); }
static void lib_close(lib_handle lib) { FreeLibrary(lib); }
static void lib_error(const char *what)
{
    fprintf(stderr, "fmi2_portable_host: %s failed: Windows error %lu\n", what, (unsigned long)GetLastError());
}
#else
#include <dlfcn.h>
typedef void *lib_handle;
static lib_handle lib_open(const char *path) { return dlopen(path, RTLD_LAZY | RTLD_LOCAL); }
static void *lib_sym(lib_handle lib, const char *name) { return dlsym(lib, name); }
static void lib_close(lib_handle lib) { dlclose(lib); }
static void lib_error(const char *what) { fprintf(stderr, "fmi2_portable_host: %s failed: %s\n", what, dlerror()); }
#endif

typedef void *fmi2Component;
typedef void *fmi2ComponentEnvironment;
typedef unsigned int fmi2ValueReference;
typedef double fmi2Real;
typedef int fmi2Integer;
typedef int fmi2Boolean;
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
typedef const char *(*GetStringT)(void);

#define MAX_SLOTS 16
#define MAX_VRS 256
#define MAX_TOKENS (MAX_VRS + 4)

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
        fprintf(stderr, "fmi2_portable_host: missing symbol %s\n", name);
        exit(2);
    }
    return p;
}

static void report(const char *cmd, int slot, fmi2Status st)
{
    printf("STATUS %s %d %s\n", cmd, slot, status_name(st));
    fflush(stdout);
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

int main(int argc, char **argv)
{
    if (argc != 4) {
        fprintf(stderr, "usage: %s <FMU binary> <guid> <resource URI> < script\n", argv[0]);
        return 1;
    }
    lib = lib_open(argv[1]);
    if (!lib) {
        lib_error("loading the FMU binary");
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
    GetStringT get_version = (GetStringT)sym("fmi2GetVersion");
    GetStringT get_platform = (GetStringT)sym("fmi2GetTypesPlatform");
    printf("INFO %s %s\n", get_version(), get_platform());
    fflush(stdout);

    fmi2CallbackFunctions cb = {logger, calloc, free, NULL, NULL};
    fmi2Component inst[MAX_SLOTS] = {0};
    int nslots = 0;
    char line[8192];
    char *tok[MAX_TOKENS];
    while (fgets(line, sizeof line, stdin)) {
        int n = split(line, tok, MAX_TOKENS);
        if (n == 0 || tok[0][0] == '#') continue;
        const char *cmd = tok[0];
        if (!strcmp(cmd, "instantiate") && n == 2) {
            if (nslots == MAX_SLOTS) return 1;
            inst[nslots] = instantiate(tok[1], fmi2CoSimulation, argv[2], argv[3], &cb, 0, 1);
            if (!inst[nslots]) {
                printf("INSTANTIATE_FAILED\n");
                fflush(stdout);
                return 3;
            }
            printf("INSTANCE %d %s\n", nslots, tok[1]);
            nslots++;
            continue;
        }
        if (n < 2) {
            fprintf(stderr, "fmi2_portable_host: no slot in '%s'\n", cmd);
            return 1;
        }
        int s = atoi(tok[1]);
        if (s < 0 || s >= nslots || !inst[s]) {
            fprintf(stderr, "fmi2_portable_host: bad slot in '%s'\n", cmd);
            return 1;
        }
        fmi2Component c = inst[s];
        if (!strcmp(cmd, "setup")) {
            report(cmd, s, setup(c, 0, 0.0, n > 2 ? strtod(tok[2], NULL) : 0.0, 0, 0.0));
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
        } else if (!strcmp(cmd, "set_real") && n == 4) {
            fmi2ValueReference vr = (fmi2ValueReference)strtoul(tok[2], NULL, 10);
            fmi2Real v = strtod(tok[3], NULL);
            report(cmd, s, set_real(c, &vr, 1, &v));
        } else if ((!strcmp(cmd, "set_integer") || !strcmp(cmd, "set_boolean")) && n == 4) {
            fmi2ValueReference vr = (fmi2ValueReference)strtoul(tok[2], NULL, 10);
            fmi2Integer v = (fmi2Integer)strtol(tok[3], NULL, 10);
            report(cmd, s, (cmd[4] == 'i' ? set_integer : set_boolean)(c, &vr, 1, &v));
        } else if ((!strcmp(cmd, "get_real") || !strcmp(cmd, "get_integer") || !strcmp(cmd, "get_boolean")) && n > 2) {
            fmi2ValueReference vrs[MAX_VRS];
            size_t k, nv = 0;
            for (int i = 2; i < n && nv < MAX_VRS; i++) vrs[nv++] = (fmi2ValueReference)strtoul(tok[i], NULL, 10);
            if (!strcmp(cmd, "get_real")) {
                fmi2Real out[MAX_VRS];
                fmi2Status st = get_real(c, vrs, nv, out);
                report(cmd, s, st);
                for (k = 0; k < nv && st <= fmi2Warning; k++) printf("REAL %d %u %.17g\n", s, vrs[k], out[k]);
            } else {
                fmi2Integer out[MAX_VRS];
                int is_int = !strcmp(cmd, "get_integer");
                fmi2Status st = (is_int ? get_integer : get_boolean)(c, vrs, nv, out);
                report(cmd, s, st);
                for (k = 0; k < nv && st <= fmi2Warning; k++)
                    printf("%s %d %u %d\n", is_int ? "INTEGER" : "BOOLEAN", s, vrs[k], out[k]);
            }
            fflush(stdout);
        } else if (!strcmp(cmd, "step") && n == 4) {
            report(cmd, s, do_step(c, strtod(tok[2], NULL), strtod(tok[3], NULL), 1));
        } else {
            fprintf(stderr, "fmi2_portable_host: unknown or incomplete command '%s'\n", cmd);
            return 1;
        }
    }
    printf("DONE\n");
    fflush(stdout);
    lib_close(lib);
    return 0;
}
