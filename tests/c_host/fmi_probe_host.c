/* The smallest FMI co-simulation host: loads one FMU binary (dlopen, or LoadLibrary on Windows), makes
 * one instance, sets Float64/Real values in initialization mode, makes one step and prints the values it
 * is asked for. Built for each platform a test can run (tests/fmu/test_cross_binaries.py: x86_64 Linux
 * natively, aarch64 Linux under qemu-user, Windows under Wine), with -DFMI_VERSION=2 or 3 and the FMI
 * headers of that version on the include path (fmpy's copy).
 *
 *   fmi_probe_host LIBRARY TOKEN RESOURCES STEP [sVR=VALUE | gVR]...
 *
 * TOKEN: the GUID (FMI 2.0) or instantiation token (FMI 3.0); RESOURCES: the URI (FMI 2.0) or path (FMI
 * 3.0) of the unpacked FMU's resources/; STEP: the communication step [s] of the one doStep from 0;
 * sVR=VALUE: set that value reference to VALUE (strtod) before the step, gVR: print it after the step.
 * Prints "STATUS <call> <status>" per call, "LOG <status> <category> <message>" per log message and
 * "REAL <vr> <value as %a>" per value read; exits 0 when every call returned OK, 1 when one did not, 2 when
 * the library or a function could not be loaded or the arguments are wrong. */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#if FMI_VERSION == 2
#include "fmi2FunctionTypes.h"
typedef fmi2ValueReference value_reference;
#elif FMI_VERSION == 3
#include "fmi3FunctionTypes.h"
typedef fmi3ValueReference value_reference;
#else
#error "compile with -DFMI_VERSION=2 or -DFMI_VERSION=3"
#endif

#if defined(_WIN32)
#include <windows.h>
typedef FARPROC raw_symbol;
static HMODULE library;
static int open_library(const char *path) { library = LoadLibraryA(path); return library != NULL; }
static raw_symbol find_symbol(const char *name) { return GetProcAddress(library, name); }
#else
#include <dlfcn.h>
typedef void *raw_symbol;
static void *library;
static int open_library(const char *path) { library = dlopen(path, RTLD_NOW | RTLD_LOCAL); return library != NULL; }
static raw_symbol find_symbol(const char *name) { return dlsym(library, name); }
#endif

#define MAX_VALUES 64

/* A symbol into a function pointer: copied, as ISO C has no conversion between object and function
 * pointers (both are one machine address on every platform built here). */
#define LOAD(var, name)                                                                \
    do {                                                                               \
        raw_symbol found_ = find_symbol(name);                                         \
        if (found_ == NULL) {                                                          \
            printf("MISSING %s\n", name);                                              \
            return 2;                                                                  \
        }                                                                              \
        memcpy(&(var), &found_, sizeof(var));                                          \
    } while (0)

static int all_ok = 1;

static void report(const char *call, int status)
{
    static const char *names[] = {"OK", "Warning", "Discard", "Error", "Fatal", "Pending"};
    printf("STATUS %s %s\n", call, status >= 0 && status <= 5 ? names[status] : "?");
    if (status != 0) {
        all_ok = 0;
    }
}

#if FMI_VERSION == 2
static void log_message(fmi2ComponentEnvironment env, fmi2String instance, fmi2Status status, fmi2String category,
                        fmi2String message, ...)
{
    va_list args;
    (void)env;
    (void)instance;
    printf("LOG %d %s ", (int)status, category ? category : "-");
    va_start(args, message);
    vprintf(message ? message : "", args);
    va_end(args);
    printf("\n");
}
#else
static void log_message(fmi3InstanceEnvironment env, fmi3Status status, fmi3String category, fmi3String message)
{
    (void)env;
    printf("LOG %d %s %s\n", (int)status, category ? category : "-", message ? message : "");
}
#endif

int main(int argc, char **argv)
{
    value_reference set_vr[MAX_VALUES], get_vr[MAX_VALUES];
    double set_value[MAX_VALUES], got[MAX_VALUES];
    size_t n_set = 0, n_get = 0, i;
    double step;
    int k;

    if (argc < 5) {
        printf("usage: fmi_probe_host LIBRARY TOKEN RESOURCES STEP [sVR=VALUE | gVR]...\n");
        return 2;
    }
    step = strtod(argv[4], NULL);
    for (k = 5; k < argc; k++) {
        char *end = NULL;
        unsigned long vr = strtoul(argv[k] + 1, &end, 10);
        if (argv[k][0] == 's' && *end == '=' && n_set < MAX_VALUES) {
            set_vr[n_set] = (value_reference)vr;
            set_value[n_set++] = strtod(end + 1, NULL);
        } else if (argv[k][0] == 'g' && *end == '\0' && n_get < MAX_VALUES) {
            get_vr[n_get++] = (value_reference)vr;
        } else {
            printf("bad argument %s\n", argv[k]);
            return 2;
        }
    }
    if (!open_library(argv[1])) {
        printf("CANNOT LOAD %s\n", argv[1]);
        return 2;
    }
    {
#if FMI_VERSION == 2
        fmi2InstantiateTYPE *instantiate;
        fmi2SetupExperimentTYPE *setup;
        fmi2EnterInitializationModeTYPE *enter_init;
        fmi2ExitInitializationModeTYPE *exit_init;
        fmi2SetRealTYPE *set_real;
        fmi2GetRealTYPE *get_real;
        fmi2DoStepTYPE *do_step;
        fmi2TerminateTYPE *terminate;
        fmi2FreeInstanceTYPE *free_instance;
        fmi2CallbackFunctions callbacks = {log_message, calloc, free, NULL, NULL};
        fmi2Component c;

        LOAD(instantiate, "fmi2Instantiate");
        LOAD(setup, "fmi2SetupExperiment");
        LOAD(enter_init, "fmi2EnterInitializationMode");
        LOAD(exit_init, "fmi2ExitInitializationMode");
        LOAD(set_real, "fmi2SetReal");
        LOAD(get_real, "fmi2GetReal");
        LOAD(do_step, "fmi2DoStep");
        LOAD(terminate, "fmi2Terminate");
        LOAD(free_instance, "fmi2FreeInstance");
        c = instantiate("probe", fmi2CoSimulation, argv[2], argv[3], &callbacks, fmi2False, fmi2False);
        printf("STATUS instantiate %s\n", c != NULL ? "OK" : "NULL");
        if (c == NULL) {
            return 1;
        }
        report("setup", setup(c, fmi2False, 0.0, 0.0, fmi2False, 0.0));
        report("enter_init", enter_init(c));
        for (i = 0; i < n_set; i++) {
            report("set_real", set_real(c, &set_vr[i], 1, &set_value[i]));
        }
        report("exit_init", exit_init(c));
        report("step", do_step(c, 0.0, step, fmi2True));
        for (i = 0; i < n_get; i++) {
            int status = get_real(c, &get_vr[i], 1, &got[i]);
            report("get_real", status);
            if (status == 0) {
                printf("REAL %u %a\n", (unsigned)get_vr[i], got[i]);
            }
        }
        report("terminate", terminate(c));
        free_instance(c);
#else
        fmi3InstantiateCoSimulationTYPE *instantiate;
        fmi3EnterInitializationModeTYPE *enter_init;
        fmi3ExitInitializationModeTYPE *exit_init;
        fmi3SetFloat64TYPE *set_float64;
        fmi3GetFloat64TYPE *get_float64;
        fmi3DoStepTYPE *do_step;
        fmi3TerminateTYPE *terminate;
        fmi3FreeInstanceTYPE *free_instance;
        fmi3Instance c;
        fmi3Boolean event_needed = fmi3False, terminate_now = fmi3False, early = fmi3False;
        fmi3Float64 reached = 0.0;

        LOAD(instantiate, "fmi3InstantiateCoSimulation");
        LOAD(enter_init, "fmi3EnterInitializationMode");
        LOAD(exit_init, "fmi3ExitInitializationMode");
        LOAD(set_float64, "fmi3SetFloat64");
        LOAD(get_float64, "fmi3GetFloat64");
        LOAD(do_step, "fmi3DoStep");
        LOAD(terminate, "fmi3Terminate");
        LOAD(free_instance, "fmi3FreeInstance");
        c = instantiate("probe", argv[2], argv[3], fmi3False, fmi3False, fmi3False, fmi3False, NULL, 0, NULL,
                        log_message, NULL);
        printf("STATUS instantiate %s\n", c != NULL ? "OK" : "NULL");
        if (c == NULL) {
            return 1;
        }
        report("enter_init", enter_init(c, fmi3False, 0.0, 0.0, fmi3False, 0.0));
        for (i = 0; i < n_set; i++) {
            report("set_real", set_float64(c, &set_vr[i], 1, &set_value[i], 1));
        }
        report("exit_init", exit_init(c));
        report("step", do_step(c, 0.0, step, fmi3True, &event_needed, &terminate_now, &early, &reached));
        for (i = 0; i < n_get; i++) {
            int status = get_float64(c, &get_vr[i], 1, &got[i], 1);
            report("get_real", status);
            if (status == 0) {
                printf("REAL %u %a\n", (unsigned)get_vr[i], got[i]);
            }
        }
        report("terminate", terminate(c));
        free_instance(c);
#endif
    }
    printf("DONE\n");
    return all_ok ? 0 : 1;
}
