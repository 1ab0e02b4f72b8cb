"""What benchmarks/bench_native.py times, built into a scratch directory.

* the pythonfmu ``SpherePlateImpact.fmu`` (behind the project's C guard), the native one
  (``fmi2/SpherePlateImpact.fmu``, FMI 2.0) and the native FMI 3.0 one (``fmi3/SpherePlateImpact.fmu``: the
  same core behind the FMI 3.0 layer), by the project's own build functions;
* the *floor*: an FMU with the native FMU's modelDescription, compiled from the same C front
  (``fmu_src/restitution/fmu/cfront``), the same generated interface table and the same compiler and
  flags (``build_native.compile_binary``), with a glue file (``bench_c/floor_fmu.c``) whose backend
  does nothing: every hook returns at once and every output is a constant. What the native FMU costs
  above it is the physics and its glue; the floor itself is what the C front costs;
* the plain C timing host (``bench_c/timing_host.c``), with the *precomputed C floor* linked in
  (``bench_c/precomputed_floor.c``: the least C that computes e and v_rebound, by Eqs. 8, 12, 13 (the
  paper's fit) and 20 with the parameter-only terms computed once, no FMI: the least one impact can cost), and the C-physics loop (``bench_c/physics_loop.c``).

Each FMU is returned unzipped (``binaries/linux64/<model>.so`` or, FMI 3.0, ``binaries/x86_64-linux/<model>.so``,
``resources/``, modelDescription.xml).
"""
from __future__ import annotations

import shutil
import subprocess
import sys
import zipfile
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT / "fmu_src") not in sys.path:
    sys.path.insert(0, str(ROOT / "fmu_src"))

MODEL = "SpherePlateImpact"
#: The benchmark's C sources: the floor's glue, the timing host, the C-physics loop.
BENCH_C = Path(__file__).resolve().parent / "bench_c"

#: The floor's backend: the same hooks the native glue (models/sphere_plate_impact/rst_native_impact_fmu.c) registers,
#: each doing nothing; outputs are constants (Reals 0.5, Booleans true).
FLOOR_GLUE = BENCH_C / "floor_fmu.c"

#: A plain C FMI 2.0 and FMI 3.0 host that times round trips (no Python in it; the pythonfmu FMU's guard starts its
#: own interpreter). Every FMU named on the command line is opened (dlopen RTLD_LOCAL), instantiated and
#: initialised; then, REPS times, each FMU in turn (the first one rotating) runs round trips for
#: BATCH_SECONDS / 10 untimed, then for BATCH_SECONDS timed (1024 between clock readings). One round
#: trip: fmi2SetReal v_approach (a new value every time, so the model is evaluated), fmi2DoStep,
#: fmi2GetReal of the Real outputs, fmi2GetBoolean of the Boolean outputs (an FMI 3.0 FMU: fmi3SetFloat64,
#: fmi3DoStep, fmi3GetFloat64, fmi3GetBoolean, the same value references). Times are CPU time of the
#: calling thread (CLOCK_THREAD_CPUTIME_ID): every FMU here computes in the caller's thread.
#: ``each_call`` instead of ``round_trip`` times each of the four calls alone, batch after batch.
#:
#: An empty BOOL_VRS: no GetBoolean in the round trip. An FMU given as ``LABEL 0 - - -`` is the precomputed C
#: floor (:data:`PRECOMPUTED_FLOOR`), timed as the FMUs are, batches interleaved with theirs.
#:
#: usage: bench_host round_trip|each_call BATCH_SECONDS REPS VR_V REAL_VRS BOOL_VRS
#:        {LABEL 2|3 BINARY RESOURCE_URI|RESOURCE_PATH GUID|TOKEN | LABEL 0 - - -}...
#: (VRS comma-separated); prints "BATCH <label>[/<call>] <rep> <seconds per round trip or call>" per batch.
TIMING_HOST = BENCH_C / "timing_host.c"

#: The precomputed C floor, linked into the timing host: its parameter terms once for the native FMU's start
#: values, then per impact e and v_rebound at the round trip's speed (bench_c/precomputed_floor.h).
PRECOMPUTED_FLOOR = BENCH_C / "precomputed_floor.c"

#: The C physics alone: rst_impact in a loop, v changing every call so nothing is cached.
#: usage: physics_loop SECONDS METHOD_CODE; runs SECONDS / 10 untimed, then SECONDS timed (CPU time of
#: the thread, 1024 calls between clock readings); prints seconds per impact.
PHYSICS_LOOP = BENCH_C / "physics_loop.c"

@dataclass(frozen=True)
class Unzipped:
    """An FMU ready for a host: its unzipped directory, FMI version, binary, resources and GUID."""

    label: str
    directory: Path
    guid: str  #: FMI 3.0: the instantiation token (the same GUID)
    version: int = 2

    @property
    def binary(self) -> Path:
        return self.directory / "binaries" / ("linux64" if self.version == 2 else "x86_64-linux") / f"{MODEL}.so"

    @property
    def resource_uri(self) -> str:
        """What instantiation is given: FMI 2.0 a file: URI, FMI 3.0 a native path ending with a separator."""
        resources = (self.directory / "resources").resolve()
        return resources.as_uri() if self.version == 2 else f"{resources}/"


@dataclass(frozen=True)
class Built:
    python: Unzipped  # pythonfmu behind the C guard
    native: Unzipped  # the C front + native physics
    fmi3: Unzipped  # the same, behind the FMI 3.0 layer
    floor: Unzipped  # the C front + a backend that does nothing
    host: Path  # the C timing host
    physics_loop: Path  # the C physics loop
    model_description: str  # the pythonfmu FMU's (the native one's interface)


def _unzip(fmu: Path, directory: Path, label: str, guid: str | None = None, version: int = 2) -> Unzipped:
    from restitution.fmu.describe.c_header import model_info

    with zipfile.ZipFile(fmu) as z:
        z.extractall(directory)
        if guid is None:
            _, guid = model_info(z.read("modelDescription.xml").decode("utf-8"))
    (directory / "resources").mkdir(exist_ok=True)
    return Unzipped(label, directory, guid, version)


def build_floor(work: Path, model_description: str) -> Path:
    """The floor FMU, unzipped in ``work/floor``: the C front, the generated interface table and
    model info, ``bench_c/floor_fmu.c``, compiled by ``build_native.compile_binary`` (gcc, the native FMU's
    flags); its modelDescription is the native FMU's."""
    from restitution.fmu.builders import native as bn
    from restitution.fmu.describe import fmi2
    from restitution.fmu.describe.c_header import c_header, model_info, model_info_header

    stage = work / "floor"
    sources = stage / "sources"
    sources.mkdir(parents=True)
    for path in bn.front_files():
        shutil.copyfile(path, sources / path.name)
    (sources / bn.INTERFACE_HEADER.format(model=MODEL)).write_text(c_header(MODEL), encoding="utf-8")
    (sources / bn.MODEL_INFO_HEADER).write_text(model_info_header(*model_info(model_description)), encoding="ascii")
    shutil.copyfile(FLOOR_GLUE, sources / "rst_floor_fmu.c")
    c_files = sorted(p.name for p in sources.glob("*.c"))
    bn.compile_binary(MODEL, sources, c_files, "linux64", stage)
    (stage / "modelDescription.xml").write_text(fmi2.model_description(MODEL, native=True, c_files=c_files),
                                                encoding="utf-8")
    (stage / "resources").mkdir()
    return stage


def compile_host(out: Path, sources: list[Path], includes: list[Path], libs: list[str], defines=()) -> Path:
    """gcc with the native build's flags (C99, -Wall -Wextra -Werror -pedantic, -O2, no FMA contraction);
    ``defines``: ``NAME=VALUE`` texts for -D."""
    from restitution.fmu.builders.compile import CFLAGS

    cmd = ["gcc", *CFLAGS, *(f"-D{d}" for d in defines), *(f"-I{p}" for p in includes), "-o", str(out),
           *map(str, sources), *libs]
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"gcc failed for {out.name}:\n{done.stderr}")
    return out


def build_all(work: Path, log=None) -> Built:
    """Build everything the benchmark times into ``work`` (an empty scratch directory)."""
    from restitution.fmu.builders import build_one
    from restitution.fmu.builders.native import build_native_one, fmi_include_dir, write_backend
    from restitution.fmu.builders.compile import prepare_sources

    log = log or (lambda message: None)
    if shutil.which("gcc") is None:
        raise RuntimeError("gcc not found: the native FMU, the floor and the C hosts need it")
    fmus = work / "fmus"
    python_fmu = build_one(MODEL, fmus, log=log)
    native_fmu = build_native_one(MODEL, fmus, log=log)
    fmi3_fmu = build_native_one(MODEL, fmus, log=log, fmi_version="3.0")
    with zipfile.ZipFile(python_fmu) as z:
        xml = z.read("modelDescription.xml").decode("utf-8")
    python = _unzip(python_fmu, work / "python", "pythonfmu")
    native = _unzip(native_fmu, work / "native", "native")
    fmi3 = _unzip(fmi3_fmu, work / "fmi3", "fmi3", guid=native.guid, version=3)  # the token is the GUID
    _same_value_references(native_fmu, fmi3_fmu)
    floor = Unzipped("floor", build_floor(work, xml), native.guid)
    src = prepare_sources(work / "physics")
    write_backend(MODEL, src)  # the interface header: the precomputed floor reads its start values
    host = compile_host(work / "bench_host", [TIMING_HOST, PRECOMPUTED_FLOOR, src / "rst_physics.c"],
                        [BENCH_C, src, *sorted({fmi_include_dir("2.0"), fmi_include_dir("3.0")})], ["-ldl", "-lm"])
    loop = compile_host(work / "physics_loop", [PHYSICS_LOOP, src / "rst_physics.c"],
                    [src], ["-lm"])
    return Built(python, native, fmi3, floor, host, loop, xml)


def _same_value_references(fmi2_fmu: Path, fmi3_fmu: Path) -> None:
    """The timing host gives both versions the value references of the FMI 2.0 description: check they agree."""
    from xml.etree import ElementTree as ET

    refs = []
    for fmu in (fmi2_fmu, fmi3_fmu):
        with zipfile.ZipFile(fmu) as z:
            root = ET.fromstring(z.read("modelDescription.xml"))
        refs.append({v.get("name"): v.get("valueReference") for v in root.find("ModelVariables")
                     if v.get("name") != "time"})
    if refs[0] != refs[1]:
        raise RuntimeError("the FMI 2.0 and FMI 3.0 FMUs have different value references")

