#!/usr/bin/env python
"""What our native BouncingBall's FMI front costs, beside the Modelica Reference FMUs' BouncingBall.

    .venv/bin/python benchmarks/bench_ball.py [--reference-fmus DIR] [--quick] [--page]

Times, interleaved in one plain C host (``bench_c/ball_timing.c``, CPU time of its thread), one co-simulation
step (DoStep over 1 ms, the Reference ball's internal solver step, then Get of h and v) and one
model-exchange right-hand-side evaluation (SetTime, SetContinuousStates, GetDerivatives; and the same followed
by GetEventIndicators) of

* our native BouncingBall, FMI 2.0 and FMI 3.0, built by the package's own native build (its sources, its
  compiler and flags; the linux64 binary only) into a scratch directory;
* the Reference FMUs' BouncingBall (FMI 2.0), compiled with gcc -O2 as a shared library from a checkout of
  github.com/modelica/Reference-FMUs (BSD) given by ``--reference-fmus DIR`` or the environment variable
  RESTITUTION_REFERENCE_FMUS. Without it the run says so in one line and prints our own figures only.

Both balls fall from 1 m with a COR of 0.7 and g = 9.81 m/s2 (ours: contact_mode immediate, the rebound
inside the step, as the Reference ball does). Each ratio is the median over the repetitions of the ratio
of the two batches of that repetition (measured back to back), printed beside its goal; absolute times
depend on the machine and its load, so only the ratios are compared. ``--page`` writes docs/ball_cost.md.
"""
from __future__ import annotations

import argparse
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
from datetime import datetime, timezone
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
if str(ROOT / "fmu_src") not in sys.path:
    sys.path.insert(0, str(ROOT / "fmu_src"))
if str(HERE) not in sys.path:
    sys.path.insert(0, str(HERE))

from bench_native_build import compile_host  # noqa: E402
from harness import machine_line  # noqa: E402

MODEL = "BouncingBall"
HOST = HERE / "bench_c" / "ball_timing.c"
ENVIRONMENT_VARIABLE = "RESTITUTION_REFERENCE_FMUS"
PAGE = ROOT / "docs" / "ball_cost.md"
#: The Reference FMUs' BouncingBall: its source files in a checkout, and its value references of h and v.
REFERENCE_SOURCES = ("src/fmi2Functions.c", "BouncingBall/model.c", "src/cosimulation.c")
REFERENCE_HV = "1,3"
#: (operation, what is compared, goal): the ratios the benchmark reports.
GOALS = (("step", "native FMI 2.0 / Reference", 1.3), ("rhs", "native FMI 2.0 / Reference", 2.5),
         ("step", "native FMI 3.0 / native FMI 2.0", 1.1), ("rhs", "native FMI 3.0 / native FMI 2.0", 1.1))
OPERATIONS = {"step": "co-simulation step (DoStep 1 ms, get h and v)",
              "rhs": "model-exchange right-hand side (set time, set h and v, get the derivatives)",
              "rhs+z": "the same right-hand side, then get the event indicator"}


def our_settings() -> tuple[str, str]:
    """(what the host sets in our ball before initialization, the value references of h and v): the Reference
    ball's drop (h0 = 1 m, g = 9.81, e = 0.7), rebounding inside the step (contact_mode immediate); value
    references from the interface table."""
    from restitution.fmu.models.bouncing_ball.variables import CONTACT_MODES, TABLE

    vr = {row.name: row.vr for row in TABLE.rows}
    return (f"{vr['h0']}=1.0,{vr['g']}=9.81,{vr['e']}=0.7,"
            f"{vr['contact_mode']}:{CONTACT_MODES.index('immediate') + 1}"), f"{vr['h']},{vr['v']}"


def build_ours(work: Path) -> dict:
    """Our BouncingBall's linux64 binaries, FMI 2.0 and FMI 3.0, by the package's native build; label ->
    (FMI version, binary, resource, token)."""
    from restitution.about import VERSION
    from restitution.fmu.builders import native
    from restitution.fmu.describe.c_header import model_info_header
    from restitution.fmu.models import table

    token = table(MODEL).instantiation_token(VERSION)
    built = {}
    for fmi_version, folder, number in (("2.0", "linux64", 2), ("3.0", "x86_64-linux", 3)):
        stage = work / f"fmi{number}"
        sources = stage / "sources"
        c_files = native.write_sources(MODEL, sources, fmi_version)
        (sources / native.MODEL_INFO_HEADER).write_text(model_info_header(MODEL, token), encoding="ascii")
        binary, _ = native.compile_binary(MODEL, sources, c_files, folder, stage, fmi_version=fmi_version)
        resources = stage / "resources"
        resources.mkdir()
        resource = resources.resolve().as_uri() if number == 2 else f"{resources.resolve()}/"
        built[f"native FMI {fmi_version}"] = (number, binary, resource, token)
    return built


def reference_dir(given: Path | None) -> tuple[Path | None, str]:
    """The Reference FMUs checkout to use, or None and why not."""
    directory = given or (Path(os.environ[ENVIRONMENT_VARIABLE]) if os.environ.get(ENVIRONMENT_VARIABLE) else None)
    if directory is None:
        return None, (f"no Reference FMUs source (--reference-fmus DIR or {ENVIRONMENT_VARIABLE}): the Reference "
                      "ratios are skipped, our own figures only")
    missing = [name for name in REFERENCE_SOURCES if not (directory / name).is_file()]
    if missing:
        return None, f"{directory} is not a Reference-FMUs checkout ({', '.join(missing)} missing): the Reference " \
                     "ratios are skipped, our own figures only"
    return directory, ""


def build_reference(source: Path, work: Path) -> tuple:
    """The Reference FMUs' BouncingBall, FMI 2.0, compiled from ``source`` as its CMake build compiles it (one
    shared library, hidden visibility, unprefixed names) with -O2; (2, binary, resource URI, GUID)."""
    config = (source / "BouncingBall" / "config.h").read_text(encoding="utf-8")
    token = re.search(r'#define\s+INSTANTIATION_TOKEN\s+"([^"]+)"', config).group(1)
    binary = work / "reference" / "BouncingBall.so"
    resources = work / "reference" / "resources"
    resources.mkdir(parents=True)
    cmd = ["gcc", "-O2", "-fPIC", "-shared", "-fvisibility=hidden", "-DFMI_VERSION=2", "-DDISABLE_PREFIX",
           f"-I{source / 'include'}", f"-I{source / 'BouncingBall'}", "-o", str(binary),
           *(str(source / name) for name in REFERENCE_SOURCES), "-lm"]
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"the Reference BouncingBall did not compile:\n{done.stderr}")
    return 2, binary, resources.resolve().as_uri(), token


def reference_commit(source: Path) -> str:
    """The commit of a Reference-FMUs git checkout, or what to say where it is none."""
    done = subprocess.run(["git", "-C", str(source), "rev-parse", "HEAD"], capture_output=True, text=True)
    return done.stdout.strip() if done.returncode == 0 else "not a git checkout: commit unknown"


def run_host(host: Path, fmus: dict, settings: dict, hv: dict, seconds: float, reps: int) -> dict:
    """(label, operation) -> [seconds per operation, one per repetition]."""
    cmd = [str(host), repr(seconds), str(reps)]
    for label, (number, binary, resource, token) in fmus.items():
        cmd += [label, str(number), str(binary), resource, token, hv[label], settings[label]]
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"the timing host failed ({done.returncode}):\n{done.stderr}")
    times: dict = {}
    for line in done.stdout.splitlines():
        if line.startswith("BATCH "):
            *label, operation, rep, value = line.split()[1:]
            times.setdefault((" ".join(label), operation), {})[int(rep)] = float(value)
    return {key: [per_rep[r] for r in sorted(per_rep)] for key, per_rep in times.items()}


def paired_ratio(top: list, bottom: list) -> float:
    """The median of the per-repetition ratios (each pair measured back to back)."""
    return statistics.median(a / b for a, b in zip(top, bottom))


def report(times: dict) -> list[str]:
    """The lines the run prints: the median times, then each ratio beside its goal."""
    lines = []
    for operation, text in OPERATIONS.items():
        lines.append(f"{text}:")
        for label in ("Reference", "native FMI 2.0", "native FMI 3.0"):
            if (label, operation) in times:
                lines.append(f"  {label:15s} {statistics.median(times[label, operation]) * 1e9:8.1f} ns")
    lines.append("ratios (median of per-repetition ratios) vs goals:")
    for operation, compared, goal in GOALS:
        top, bottom = (label.strip() for label in compared.split("/"))
        if (bottom, operation) not in times:
            lines.append(f"  {operation:5s} {compared:33s} skipped (no Reference source)")
            continue
        ratio = paired_ratio(times[top, operation], times[bottom, operation])
        verdict = "met" if ratio <= goal else "NOT met"
        lines.append(f"  {operation:5s} {compared:33s} {ratio:5.2f}x   goal <= {goal:g}x   {verdict}")
    if ("Reference", "rhs+z") in times:
        ratio = paired_ratio(times["native FMI 2.0", "rhs+z"], times["Reference", "rhs+z"])
        lines.append(f"  rhs+z native FMI 2.0 / Reference         {ratio:5.2f}x   (no goal)")
    return lines


def page(lines: list[str], seconds: float, reps: int, command: str, reference: str) -> str:
    when = datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    return "\n".join([
        "# What the C front costs a BouncingBall",
        "",
        f"Written by `benchmarks/bench_ball.py` on {when} ({machine_line()}, shared with other work: "
        f"only the ratios, measured interleaved in one run, count; {reps} repetitions of {seconds:g} s batches "
        f"of thread CPU time), with `{command}`. The host (`benchmarks/bench_c/ball_timing.c`) "
        "loads each binary with dlopen and makes the same calls with the same arguments on each; see the "
        f"script's docstring. Reference FMUs: {reference}.",
        "",
        "The step is 1 ms, the Reference ball's fixed internal (explicit Euler) step, so that it makes one solver "
        "step per DoStep and what is compared is mostly the two FMI fronts; ours moves the ball in closed form. "
        "Every call of ours passes the checks of [host_contract.md](host_contract.md) and takes the instance's "
        "lock (one compare-and-swap and a plain store where no other thread holds it); the Reference FMUs' calls "
        "take no lock.",
        "",
        "```",
        *lines,
        "```",
        "",
    ])


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[1])
    parser.add_argument("--reference-fmus", type=Path,
                        help=f"a Reference-FMUs checkout (default: ${ENVIRONMENT_VARIABLE})")
    parser.add_argument("--seconds", type=float, default=0.2, help="CPU seconds per batch (default 0.2)")
    parser.add_argument("--reps", type=int, default=9, help="repetitions (default 9)")
    parser.add_argument("--quick", action="store_true", help="a short run (0.01 s batches, 2 repetitions): it works")
    parser.add_argument("--page", action="store_true", help=f"write {PAGE.relative_to(ROOT)}")
    args = parser.parse_args(argv)
    seconds, reps = (0.01, 2) if args.quick else (args.seconds, args.reps)
    if shutil.which("gcc") is None:
        print("gcc not found: the FMUs and the timing host need it", file=sys.stderr)
        return 2
    source, why_not = reference_dir(args.reference_fmus)
    if source is None:
        print(why_not)
    from restitution.fmu.builders.native import fmi_include_dir

    with tempfile.TemporaryDirectory(prefix="bench-ball-") as tmp:
        work = Path(tmp)
        fmus = build_ours(work)
        settings, hv = our_settings()
        all_settings = {label: settings for label in fmus}
        all_hv = {label: hv for label in fmus}
        if source is not None:
            fmus = {"Reference": build_reference(source, work), **fmus}
            all_settings["Reference"], all_hv["Reference"] = "-", REFERENCE_HV
        host = compile_host(work / "ball_timing", [HOST], sorted({fmi_include_dir("2.0"), fmi_include_dir("3.0")}),
                            ["-ldl"])
        times = run_host(host, fmus, all_settings, all_hv, seconds, reps)
    lines = report(times)
    print("\n".join(lines))
    if args.page:
        command = "bench_ball.py" + (" --reference-fmus DIR" if source is not None else "") + \
                  ("" if args.quick else f" --seconds {seconds:g} --reps {reps}")
        reference = (f"github.com/modelica/Reference-FMUs at {reference_commit(source)}, BouncingBall (FMI 2.0, "
                     "gcc -O2)") if source is not None else "not given (no Reference ratios)"
        PAGE.write_text(page(lines, seconds, reps, command, reference), encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
