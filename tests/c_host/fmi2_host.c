/*
 * Minimal, generic FMI 2.0 co-simulation host written in plain C.
 *
 * It behaves like the C/C++ simulation tools do: the FMU binary is opened
 * with dlopen(RTLD_LAZY | RTLD_LOCAL), and the process knows nothing about
 * Python.
 *
 * Usage:
 *   fmi2_host <unpacked_fmu_dir> <modelIdentifier> <guid>
 *             [--steps N] [--step-size H] [--start T]
 *             [vr=value ...] [vr ...]
 *
 *   vr=value   fmi2SetReal(vr, value) before every step
 *   vr         fmi2GetReal(vr) after the last step; printed as "vr value"
 *              with %.17g, one per line
 *
 * Log messages from the FMU are printed to stdout as
 *   LOG <instance> <status> <category>: <message>
 *
 * Exit codes: 0 ok, 1 usage, 2 dlopen/dlsym failure, 3 fmi2Instantiate
 * returned NULL, 4 another fmi2 call returned an error status.
 *
 * Build: gcc -O2 -o fmi2_host fmi2_host.c -ldl
 */
#include <dlfcn.h>
#include <limits.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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
typedef void *(*fmi2CallbackAllocateMemory)(size_t, size_t);
typedef void (*fmi2CallbackFreeMemory)(void *);
typedef void (*fmi2StepFinished)(fmi2ComponentEnvironment, fmi2Status);
typedef struct {
    fmi2CallbackLogger logger;
    fmi2CallbackAllocateMemory allocateMemory;
    fmi2CallbackFreeMemory freeMemory;
    fmi2StepFinished stepFinished;
    fmi2ComponentEnvironment componentEnvironment;
} fmi2CallbackFunctions;

typedef fmi2Component (*fmi2InstantiateTYPE)(fmi2String, fmi2Type, fmi2String, fmi2String,
                                             const fmi2CallbackFunctions *, fmi2Boolean, fmi2Boolean);
typedef void (*fmi2FreeInstanceTYPE)(fmi2Component);
typedef fmi2Status (*fmi2SetupExperimentTYPE)(fmi2Component, fmi2Boolean, fmi2Real, fmi2Real, fmi2Boolean, fmi2Real);
typedef fmi2Status (*fmi2ComponentOnlyTYPE)(fmi2Component);
typedef fmi2Status (*fmi2SetRealTYPE)(fmi2Component, const fmi2ValueReference[], size_t, const fmi2Real[]);
typedef fmi2Status (*fmi2GetRealTYPE)(fmi2Component, const fmi2ValueReference[], size_t, fmi2Real[]);
typedef fmi2Status (*fmi2DoStepTYPE)(fmi2Component, fmi2Real, fmi2Real, fmi2Boolean);

static const char *status_name(fmi2Status s)
{
    static const char *names[] = {"OK", "Warning", "Discard", "Error", "Fatal", "Pending"};
    return ((unsigned)s < 6u) ? names[s] : "?";
}

static void logger(fmi2ComponentEnvironment env, fmi2String instance, fmi2Status status,
                   fmi2String category, fmi2String message, ...)
{
    (void)env;
    va_list ap;
    printf("LOG %s %s %s: ", instance ? instance : "?", status_name(status), category ? category : "");
    va_start(ap, message);
    vprintf(message ? message : "", ap);
    va_end(ap);
    printf("\n");
    fflush(stdout);
}

static void *sym(void *lib, const char *name)
{
    void *p = dlsym(lib, name);
    if (!p) {
        fprintf(stderr, "fmi2_host: missing symbol %s: %s\n", name, dlerror());
        exit(2);
    }
    return p;
}

#define CHECK(call, what)                                                         \
    do {                                                                          \
        fmi2Status st_ = (call);                                                  \
        if (st_ > fmi2Warning) {                                                  \
            fprintf(stderr, "fmi2_host: %s returned %s\n", what, status_name(st_)); \
            rc = 4;                                                               \
            goto done;                                                            \
        }                                                                         \
    } while (0)

int main(int argc, char **argv)
{
    if (argc < 4) {
        fprintf(stderr, "usage: %s <unpacked_fmu_dir> <modelIdentifier> <guid> "
                        "[--steps N] [--step-size H] [--start T] [vr=value ...] [vr ...]\n", argv[0]);
        return 1;
    }
    char dir[PATH_MAX];
    if (!realpath(argv[1], dir)) {
        perror(argv[1]);
        return 1;
    }
    const char *model = argv[2];
    const char *guid = argv[3];

    int nsteps = 1;
    double h = 1e-3, t0 = 0.0;
    fmi2ValueReference set_vr[256], get_vr[256];
    fmi2Real set_val[256], get_val[256];
    size_t nset = 0, nget = 0;
    for (int i = 4; i < argc; i++) {
        if (!strcmp(argv[i], "--steps") && i + 1 < argc) {
            nsteps = atoi(argv[++i]);
        } else if (!strcmp(argv[i], "--step-size") && i + 1 < argc) {
            h = strtod(argv[++i], NULL);
        } else if (!strcmp(argv[i], "--start") && i + 1 < argc) {
            t0 = strtod(argv[++i], NULL);
        } else if (strchr(argv[i], '=')) {
            if (nset == 256) return 1;
            set_vr[nset] = (fmi2ValueReference)strtoul(argv[i], NULL, 10);
            set_val[nset] = strtod(strchr(argv[i], '=') + 1, NULL);
            nset++;
        } else {
            if (nget == 256) return 1;
            get_vr[nget++] = (fmi2ValueReference)strtoul(argv[i], NULL, 10);
        }
    }

    char lib_path[PATH_MAX + 256], resources[PATH_MAX + 64];
    snprintf(lib_path, sizeof lib_path, "%s/binaries/linux64/%s.so", dir, model);
    snprintf(resources, sizeof resources, "file://%s/resources", dir);

    void *lib = dlopen(lib_path, RTLD_LAZY | RTLD_LOCAL);
    if (!lib) {
        fprintf(stderr, "fmi2_host: dlopen failed: %s\n", dlerror());
        return 2;
    }
    fmi2InstantiateTYPE instantiate = (fmi2InstantiateTYPE)sym(lib, "fmi2Instantiate");
    fmi2FreeInstanceTYPE free_instance = (fmi2FreeInstanceTYPE)sym(lib, "fmi2FreeInstance");
    fmi2SetupExperimentTYPE setup = (fmi2SetupExperimentTYPE)sym(lib, "fmi2SetupExperiment");
    fmi2ComponentOnlyTYPE enter_init = (fmi2ComponentOnlyTYPE)sym(lib, "fmi2EnterInitializationMode");
    fmi2ComponentOnlyTYPE exit_init = (fmi2ComponentOnlyTYPE)sym(lib, "fmi2ExitInitializationMode");
    fmi2ComponentOnlyTYPE terminate = (fmi2ComponentOnlyTYPE)sym(lib, "fmi2Terminate");
    fmi2SetRealTYPE set_real = (fmi2SetRealTYPE)sym(lib, "fmi2SetReal");
    fmi2GetRealTYPE get_real = (fmi2GetRealTYPE)sym(lib, "fmi2GetReal");
    fmi2DoStepTYPE do_step = (fmi2DoStepTYPE)sym(lib, "fmi2DoStep");
    const char *(*get_version)(void) = (const char *(*)(void))sym(lib, "fmi2GetVersion");
    const char *(*get_platform)(void) = (const char *(*)(void))sym(lib, "fmi2GetTypesPlatform");
    printf("INFO fmi2GetVersion=%s fmi2GetTypesPlatform=%s\n", get_version(), get_platform());

    fmi2CallbackFunctions cb = {logger, calloc, free, NULL, NULL};
    fmi2Component c = instantiate("instance1", fmi2CoSimulation, guid, resources, &cb, 0, 1);
    if (!c) {
        printf("INSTANTIATE_FAILED\n");
        fflush(stdout);
        dlclose(lib);
        return 3;
    }

    int rc = 0;
    double t = t0;
    CHECK(setup(c, 0, 0.0, t0, 0, 0.0), "fmi2SetupExperiment");
    CHECK(enter_init(c), "fmi2EnterInitializationMode");
    if (nset) CHECK(set_real(c, set_vr, nset, set_val), "fmi2SetReal");
    CHECK(exit_init(c), "fmi2ExitInitializationMode");
    for (int k = 0; k < nsteps; k++) {
        if (nset) CHECK(set_real(c, set_vr, nset, set_val), "fmi2SetReal");
        CHECK(do_step(c, t, h, 1), "fmi2DoStep");
        t += h;
    }
    if (nget) CHECK(get_real(c, get_vr, nget, get_val), "fmi2GetReal");
    for (size_t i = 0; i < nget; i++) printf("%u %.17g\n", get_vr[i], get_val[i]);
    CHECK(terminate(c), "fmi2Terminate");
done:
    free_instance(c);
    fflush(stdout);
    dlclose(lib);
    return rc;
}
