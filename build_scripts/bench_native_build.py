"""What build_scripts/bench_native.py times, built into a scratch directory.

* the pythonfmu ``SpherePlateImpact.fmu`` (behind the project's C guard) and the native one
  (``native/SpherePlateImpact.fmu``), by the project's own build functions;
* the *floor*: an FMU with the native FMU's modelDescription, compiled from the same C front
  (``fmu_src/restitution/fmu/cfront``), the same generated interface table and the same compiler and
  flags (``build_native.compile_binary``), with a glue file (:data:`FLOOR_GLUE`, below) whose backend
  does nothing: every hook returns at once and every output is a constant. What the native FMU costs
  above it is the physics and its glue; the floor itself is what the C front costs;
* the plain C timing host (:data:`TIMING_HOST`) and the C-physics loop (:data:`PHYSICS_LOOP`).

Each FMU is returned unzipped (``binaries/linux64/<model>.so``, ``resources/``, modelDescription.xml).
"""
from __future__ import annotations

import shutil
import subprocess
import sys
import zipfile
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT / "fmu_src") not in sys.path:
    sys.path.insert(0, str(ROOT / "fmu_src"))

MODEL = "SpherePlateImpact"

#: The floor's backend: the same hooks the native glue (native/rst_native_impact_fmu.c) registers,
#: each doing nothing; outputs are constants (Reals 0.5, Booleans true).
FLOOR_GLUE = r"""/* The C wrapper floor (build_scripts/bench_native_build.py): the project's C front with a backend
 * that does nothing. Same hooks as the native glue; outputs are constants. */
#include "rst_front.h"

#include "rst_SpherePlateImpact_interface.h" /* generated: restitution.fmu.interface.c_header */
#include "rst_model_info.h"                  /* generated: identifier and GUID of modelDescription.xml */

static fmi2Status instantiate(rst_instance *inst, const char *resource_dir, fmi2Boolean visible)
{
    (void)inst, (void)resource_dir, (void)visible;
    return fmi2OK;
}

static fmi2Status accept(rst_instance *inst, const rst_variable *var, double value)
{
    (void)inst, (void)var, (void)value;
    return fmi2OK;
}

static fmi2Status set(rst_instance *inst, rst_type type, const fmi2ValueReference vr[], size_t n,
                      const double values[])
{
    (void)inst, (void)type, (void)vr, (void)n, (void)values;
    return fmi2OK;
}

static fmi2Status nothing(rst_instance *inst)
{
    (void)inst;
    return fmi2OK;
}

static fmi2Status get_outputs(rst_instance *inst, rst_type type, const fmi2ValueReference vr[], size_t n,
                              double values[])
{
    size_t i;
    (void)inst, (void)vr;
    for (i = 0; i < n; i++)
        values[i] = type == RST_BOOLEAN ? 1.0 : 0.5;
    return fmi2OK;
}

static fmi2Status do_step(rst_instance *inst, double t, double h)
{
    (void)inst, (void)t, (void)h;
    return fmi2OK;
}

const rst_model RST_MODEL = {
    .identifier = RST_MODEL_IDENTIFIER, .guid = RST_MODEL_GUID,
    .variables = RST_MODEL_VARIABLES, .n_variables = RST_MODEL_N_VARIABLES, .backend_size = 1,
    .instantiate = instantiate, .exit_initialization = nothing, .accept = accept, .set = set,
    .get_outputs = get_outputs, .do_step = do_step, .reset = nothing, .restore_state = nothing};
"""

#: A plain C FMI 2.0 host that times round trips (no Python in it; the pythonfmu FMU's guard starts its
#: own interpreter). Every FMU named on the command line is opened (dlopen RTLD_LOCAL), instantiated and
#: initialised; then, REPS times, each FMU in turn (the first one rotating) runs round trips for
#: BATCH_SECONDS / 10 untimed, then for BATCH_SECONDS timed (64 between clock readings). One round
#: trip: fmi2SetReal v_approach (a new value every time, so the model is evaluated), fmi2DoStep,
#: fmi2GetReal of the Real outputs, fmi2GetBoolean of the Boolean outputs. Times are CPU time of the
#: calling thread (CLOCK_THREAD_CPUTIME_ID): every FMU here computes in the caller's thread.
#: ``each_call`` instead of ``round_trip`` times each of the four calls alone, batch after batch.
#:
#: usage: bench_host round_trip|each_call BATCH_SECONDS REPS VR_V REAL_VRS BOOL_VRS
#:        {LABEL BINARY RESOURCE_URI GUID}...
#: (VRS comma-separated); prints "BATCH <label>[/<call>] <rep> <seconds per round trip or call>" per batch.
TIMING_HOST = r"""#define _POSIX_C_SOURCE 199309L
#include <dlfcn.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "fmi2FunctionTypes.h"

#define MAX_FMUS 8
#define MAX_VRS 64

typedef struct {
    const char *label;
    void *dl;
    fmi2Component c;
    fmi2SetRealTYPE *set_real;
    fmi2DoStepTYPE *do_step;
    fmi2GetRealTYPE *get_real;
    fmi2GetBooleanTYPE *get_boolean;
    fmi2FreeInstanceTYPE *free_instance;
    fmi2TerminateTYPE *terminate;
    double t;
    long k;
} fmu;

static void logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status, fmi2String category,
                   fmi2String message, ...)
{
    (void)env;
    if (status != fmi2OK)
        fprintf(stderr, "LOG %s %d %s: %s\n", name ? name : "?", (int)status, category ? category : "",
                message ? message : "");
}

static double cpu_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static size_t parse_vrs(const char *text, fmi2ValueReference *vr)
{
    size_t n = 0;
    char *end;
    while (*text && n < MAX_VRS) {
        vr[n++] = (fmi2ValueReference)strtoul(text, &end, 10);
        text = *end == ',' ? end + 1 : end;
    }
    return n;
}

static void *symbol(fmu *f, const char *name)
{
    void *p = dlsym(f->dl, name);
    if (p == NULL) {
        fprintf(stderr, "%s: %s not found\n", f->label, name);
        exit(2);
    }
    return p;
}

/* a function pointer from dlsym without the object-to-function pointer cast ISO C forbids */
#define LOAD(target, name)                  \
    do {                                    \
        void *p_ = symbol(f, name);         \
        memcpy(&(target), &p_, sizeof p_);  \
    } while (0)

static fmi2ValueReference vr_v, vr_reals[MAX_VRS], vr_bools[MAX_VRS];
static size_t n_reals, n_bools;
static double sink;

#define SET 1
#define STEP 2
#define GET_REAL 4
#define GET_BOOLEAN 8
#define ROUND_TRIP (SET | STEP | GET_REAL | GET_BOOLEAN)
static const char *const CALL_NAMES[] = {"fmi2SetReal", "fmi2DoStep", "fmi2GetReal", "fmi2GetBoolean"};

/* n round trips made of the `calls` (ROUND_TRIP: all four); the status of every call OR-ed together
 * (0: every call returned fmi2OK) */
static int round_trips(fmu *f, int calls, long n)
{
    fmi2Real reals[MAX_VRS];
    fmi2Boolean bools[MAX_VRS];
    const fmi2Real h = 1e-3;
    int bad = 0;
    long i;
    reals[0] = 0.0, bools[0] = fmi2False;
    for (i = 0; i < n; i++) {
        fmi2Real v = 0.1 + 1e-6 * (double)(f->k++ % 1000000);
        if (calls & SET)
            bad |= (int)f->set_real(f->c, &vr_v, 1, &v);
        if (calls & STEP) {
            bad |= (int)f->do_step(f->c, f->t, h, fmi2True);
            f->t += h;
        }
        if (calls & GET_REAL)
            bad |= (int)f->get_real(f->c, vr_reals, n_reals, reals);
        if (calls & GET_BOOLEAN)
            bad |= (int)f->get_boolean(f->c, vr_bools, n_bools, bools);
        sink += reals[0] + (double)bools[0];
    }
    return bad;
}

/* Round trips in chunks of CHUNK until `seconds` of CPU time have passed; seconds per round trip. */
#define CHUNK 64
static double timed_batch(fmu *f, int calls, double seconds)
{
    double t0 = cpu_seconds(), elapsed;
    long count = 0;
    do {
        if (round_trips(f, calls, CHUNK)) {
            fprintf(stderr, "%s: a call did not return fmi2OK\n", f->label);
            exit(4);
        }
        count += CHUNK;
        elapsed = cpu_seconds() - t0;
    } while (elapsed < seconds);
    return elapsed / (double)count;
}

int main(int argc, char **argv)
{
    fmu fmus[MAX_FMUS];
    fmi2CallbackFunctions callbacks = {logger, calloc, free, NULL, NULL};
    double batch;
    long reps, r;
    int m = 0, i, each;
    if (argc < 11 || (argc - 7) % 4 != 0 || (argc - 7) / 4 > MAX_FMUS
            || (strcmp(argv[1], "round_trip") != 0 && strcmp(argv[1], "each_call") != 0)) {
        fprintf(stderr, "usage: %s round_trip|each_call BATCH_SECONDS REPS VR_V REAL_VRS BOOL_VRS "
                "{LABEL BINARY RESOURCE_URI GUID}...\n", argv[0]);
        return 1;
    }
    each = strcmp(argv[1], "each_call") == 0;
    batch = atof(argv[2]);
    reps = atol(argv[3]);
    vr_v = (fmi2ValueReference)strtoul(argv[4], NULL, 10);
    n_reals = parse_vrs(argv[5], vr_reals);
    n_bools = parse_vrs(argv[6], vr_bools);
    for (i = 7; i + 3 < argc; i += 4, m++) {
        fmu *f = &fmus[m];
        fmi2InstantiateTYPE *instantiate;
        fmi2SetupExperimentTYPE *setup;
        fmi2EnterInitializationModeTYPE *enter_init;
        fmi2ExitInitializationModeTYPE *exit_init;
        memset(f, 0, sizeof *f);
        f->label = argv[i];
        f->dl = dlopen(argv[i + 1], RTLD_NOW | RTLD_LOCAL);
        if (f->dl == NULL) {
            fprintf(stderr, "%s: dlopen failed: %s\n", f->label, dlerror());
            return 2;
        }
        LOAD(instantiate, "fmi2Instantiate");
        LOAD(setup, "fmi2SetupExperiment");
        LOAD(enter_init, "fmi2EnterInitializationMode");
        LOAD(exit_init, "fmi2ExitInitializationMode");
        LOAD(f->set_real, "fmi2SetReal");
        LOAD(f->do_step, "fmi2DoStep");
        LOAD(f->get_real, "fmi2GetReal");
        LOAD(f->get_boolean, "fmi2GetBoolean");
        LOAD(f->terminate, "fmi2Terminate");
        LOAD(f->free_instance, "fmi2FreeInstance");
        f->c = instantiate(f->label, fmi2CoSimulation, argv[i + 3], argv[i + 2], &callbacks, fmi2False, fmi2False);
        if (f->c == NULL) {
            fprintf(stderr, "%s: fmi2Instantiate returned NULL\n", f->label);
            return 3;
        }
        if (setup(f->c, fmi2False, 0.0, 0.0, fmi2False, 0.0) != fmi2OK || enter_init(f->c) != fmi2OK
                || exit_init(f->c) != fmi2OK) {
            fprintf(stderr, "%s: initialisation failed\n", f->label);
            return 3;
        }
    }
    for (r = 0; r < reps; r++)
        for (i = 0; i < m; i++) {
            fmu *f = &fmus[(i + r) % m];
            int call;
            timed_batch(f, ROUND_TRIP, 0.1 * batch); /* warm-up: caches, branch predictors */
            if (!each) {
                printf("BATCH %s %ld %.6e\n", f->label, r, timed_batch(f, ROUND_TRIP, batch));
                fflush(stdout);
                continue;
            }
            for (call = 0; call < 4; call++) {
                printf("BATCH %s/%s %ld %.6e\n", f->label, CALL_NAMES[call], r, timed_batch(f, 1 << call, batch));
                fflush(stdout);
            }
        }
    for (i = 0; i < m; i++) {
        fmus[i].terminate(fmus[i].c);
        fmus[i].free_instance(fmus[i].c);
    }
    fprintf(stderr, "checksum %g\n", sink);
    return 0;
}
"""

#: The C physics alone: rst_impact in a loop, v changing every call so nothing is cached.
#: usage: physics_loop SECONDS METHOD_CODE; runs SECONDS / 10 untimed, then SECONDS timed (CPU time of
#: the thread, 1024 calls between clock readings); prints seconds per impact.
PHYSICS_LOOP = r"""#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "rst_physics.h"

static double cpu_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static rst_impact_inputs in;
static double sink;
static long k;

static double timed(double seconds)
{
    rst_impact_result out;
    double t0 = cpu_seconds(), elapsed;
    long count = 0, i;
    do {
        for (i = 0; i < 1024; i++) {
            in.v = 0.1 + 1e-6 * (double)(k++ % 1000000);
            if (rst_impact(&in, &out) != 0)
                exit(3);
            sink += out.e + out.t_contact;
        }
        count += 1024;
        elapsed = cpu_seconds() - t0;
    } while (elapsed < seconds);
    return elapsed / (double)count;
}

int main(int argc, char **argv)
{
    double seconds;
    if (argc != 3)
        return 2;
    seconds = atof(argv[1]);
    in.v = 1.0;
    in.sphere_E = 207e9, in.sphere_nu = 0.30, in.sphere_Sy = 2.0e9, in.sphere_rho = 7861.0, in.sphere_d = 6.35e-3;
    in.plate_E = 69e9, in.plate_nu = 0.33, in.plate_Sy = 0.290e9, in.plate_rho = 2700.0, in.plate_t = 6.35e-3;
    in.restitution_model = 1, in.plasticity = 2, in.plate_waves = 2;
    in.effect_tolerance = 1e-6, in.ode_rtol = 1e-10;
    in.zener_method = atoi(argv[2]);
    timed(0.1 * seconds);
    printf("%.6e %g\n", timed(seconds), sink);
    return 0;
}
"""

@dataclass(frozen=True)
class Unzipped:
    """An FMU ready for a host: its unzipped directory, binary, resources URI and GUID."""

    label: str
    directory: Path
    guid: str

    @property
    def binary(self) -> Path:
        return self.directory / "binaries" / "linux64" / f"{MODEL}.so"

    @property
    def resource_uri(self) -> str:
        return (self.directory / "resources").resolve().as_uri()


@dataclass(frozen=True)
class Built:
    python: Unzipped  # pythonfmu behind the C guard
    native: Unzipped  # the C front + native physics
    floor: Unzipped  # the C front + a backend that does nothing
    host: Path  # the C timing host
    physics_loop: Path  # the C physics loop
    model_description: str  # the pythonfmu FMU's (the native one's interface)


def _unzip(fmu: Path, directory: Path, label: str) -> Unzipped:
    from restitution.fmu.interface import model_info

    with zipfile.ZipFile(fmu) as z:
        z.extractall(directory)
        _, guid = model_info(z.read("modelDescription.xml").decode("utf-8"))
    (directory / "resources").mkdir(exist_ok=True)
    return Unzipped(label, directory, guid)


def build_floor(work: Path, model_description: str) -> Path:
    """The floor FMU, unzipped in ``work/floor``: the C front, the generated interface table and
    model info, :data:`FLOOR_GLUE`, compiled by ``build_native.compile_binary`` (gcc, the native FMU's
    flags); its modelDescription is the native FMU's."""
    from restitution.fmu.interface import c_header, model_info_header
    from restitution.fmu import build_native as bn

    stage = work / "floor"
    sources = stage / "sources"
    sources.mkdir(parents=True)
    for path in bn.front_files():
        shutil.copyfile(path, sources / path.name)
    (sources / bn.INTERFACE_HEADER.format(model=MODEL)).write_text(c_header(MODEL), encoding="utf-8")
    (sources / bn.MODEL_INFO_HEADER).write_text(model_info_header(model_description), encoding="ascii")
    (sources / "rst_floor_fmu.c").write_text(FLOOR_GLUE, encoding="ascii")
    c_files = sorted(p.name for p in sources.glob("*.c"))
    bn.compile_binary(MODEL, sources, c_files, "linux64", stage)
    (stage / "modelDescription.xml").write_text(bn.native_model_description(model_description, c_files),
                                                encoding="utf-8")
    (stage / "resources").mkdir()
    return stage


def _compile(out: Path, sources: list[Path], includes: list[Path], libs: list[str]) -> Path:
    """gcc with the native build's flags (C99, -Wall -Wextra -Werror -pedantic, -O2, no FMA contraction)."""
    from restitution.fmu.compile import CFLAGS

    cmd = ["gcc", *CFLAGS, *(f"-I{p}" for p in includes), "-o", str(out), *map(str, sources), *libs]
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"gcc failed for {out.name}:\n{done.stderr}")
    return out


def build_all(work: Path, log=None) -> Built:
    """Build everything the benchmark times into ``work`` (an empty scratch directory)."""
    from restitution.fmu.build import build_one
    from restitution.fmu.build_native import build_native_one, fmi2_include_dir
    from restitution.fmu.compile import prepare_sources

    log = log or (lambda message: None)
    if shutil.which("gcc") is None:
        raise RuntimeError("gcc not found: the native FMU, the floor and the C hosts need it")
    fmus = work / "fmus"
    python_fmu = build_one(MODEL, fmus, log=log)
    native_fmu = build_native_one(MODEL, fmus, python_fmu, log=log)
    with zipfile.ZipFile(python_fmu) as z:
        xml = z.read("modelDescription.xml").decode("utf-8")
    python = _unzip(python_fmu, work / "python", "pythonfmu")
    native = _unzip(native_fmu, work / "native", "native")
    floor = Unzipped("floor", build_floor(work, xml), native.guid)
    host = _compile(work / "bench_host", [_write(work / "bench_host.c", TIMING_HOST)], [fmi2_include_dir()], ["-ldl"])
    src = prepare_sources(work / "physics")
    loop = _compile(work / "physics_loop", [_write(src / "physics_loop.c", PHYSICS_LOOP), src / "rst_physics.c"],
                    [src], ["-lm"])
    return Built(python, native, floor, host, loop, xml)


def _write(path: Path, text: str) -> Path:
    path.write_text(text, encoding="ascii")
    return path
