"""The page benchmarks/bench_native.py writes (docs/native_cost.md) and the table it prints."""
from __future__ import annotations

import math
import statistics

from bench_native_timing import METHODS

#: The native FMUs' cost goals: key -> (what is measured, goal text, test on the measured value). Ratios are
#: medians over the repeats of the ratio within a repeat; the absolute figure a median of batches.
TARGETS = {
    "native_over_floor_fmpy": (
        "native / floor (the C front with a do-nothing backend, same variables), one impact through fmpy",
        "<= 1.5x", lambda x: x <= 1.5),
    "python_over_native_c_host": (
        "pythonfmu / native, one impact in a plain C host", ">= 30x", lambda x: x >= 30.0),
    "native_c_host": (
        "native, one impact in a plain C host (absolute)", "< 1 us", lambda x: x < 1e-6),
    "fmi3_over_native_c_host": (
        "native FMI 3.0 / native FMI 2.0, one impact in a plain C host", "<= 1.1x", lambda x: x <= 1.1),
    "native_over_precomputed_c_host": (
        "native FMI 2.0 / precomputed C floor (the least C computing e and v_rebound, parameter terms once, no "
        "FMI), one impact getting e and v_rebound in a plain C host", "<= 2.5x", lambda x: x <= 2.5),
    "fmi3_over_precomputed_c_host": (
        "native FMI 3.0 / precomputed C floor, the same", "<= 2.5x", lambda x: x <= 2.5),
    "package_over_c_physics": (
        "package scalar `impact` / C physics `rst_impact`, one impact (`exact`)", "none (was ~50x)", None),
}
#: Rows of each section (the test checks every one is on the page).
FMU_ROWS = ("native", "floor", "pythonfmu")
#: The C host's rows: the same and the native FMI 3.0 FMU.
C_HOST_ROWS = ("native", "fmi3", "floor", "pythonfmu")
CALLS = ("fmi2SetReal", "fmi2DoStep", "fmi2GetReal", "fmi2GetBoolean")
#: The rows of the section against the precomputed C floor (one impact getting e and v_rebound).
IMPACT_ROWS = ("native", "fmi3", "floor", "precomputed")


def fmt_time(seconds: float) -> str:
    if not math.isfinite(seconds):
        return str(seconds)
    if seconds < 1e-6:
        return f"{seconds * 1e9:.0f} ns"
    if seconds < 1e-3:
        return f"{seconds * 1e6:.2f} us"
    return f"{seconds * 1e3:.2f} ms"


def fmt_ratio(x: float) -> str:
    return f"{x:.2f}x" if x < 10 else f"{x:.1f}x" if x < 100 else f"{x:.0f}x"


def _spread(lo_hi) -> str:
    return f"{fmt_ratio(lo_hi[0])} – {fmt_ratio(lo_hi[1])}"


def headline_rows(res: dict) -> list[tuple[str, str, str, str, str]]:
    """(target, measured, range over repeats, goal, met) per target."""
    rows = []
    for key, (text, goal, test) in TARGETS.items():
        value, spread = res["headline"][key]
        measured = fmt_time(value) if key == "native_c_host" else fmt_ratio(value)
        span = "" if spread is None else (f"{fmt_time(spread[0])} – {fmt_time(spread[1])}" if key == "native_c_host"
                                          else _spread(spread))
        met = "—" if test is None else ("yes" if test(value) else "**no**")
        rows.append((text, measured, span, goal, met))
    return rows


def split_over_precomputed(series) -> tuple[float, float]:
    """native / precomputed split into its two parts, medians over the repeats of the per-repeat values:
    (floor FMU / precomputed: the C front, the host's FMI calls and the floor itself; (native - floor FMU) /
    precomputed: what the native physics and its glue add)."""
    native, floor, pre = (series.batches[k] for k in ("native", "floor", "precomputed"))
    return (statistics.median(f / p for f, p in zip(floor, pre)),
            statistics.median((n - f) / p for n, f, p in zip(native, floor, pre)))


def _split_text(res: dict) -> str:
    front, rest = split_over_precomputed(res["impact"])
    return (f"native / precomputed = {fmt_ratio(res['headline']['native_over_precomputed_c_host'][0])} = "
            f"{fmt_ratio(front)} the floor FMU (the C front and FMI calls with a do-nothing backend) "
            f"+ {fmt_ratio(rest)} the native physics and its glue above the floor FMU")


def console(res: dict) -> str:
    """The headline as printed: the measured values next to the goals."""
    rows = headline_rows(res)
    width = max(len(r[0]) for r in rows)
    lines = [f"{'target':<{width}}  {'measured':>9}  {'range over repeats':>19}  {'goal':>15}  met"]
    lines += [f"{t:<{width}}  {m:>9}  {s:>19}  {g:>15}  {ok.strip('*')}" for t, m, s, g, ok in rows]
    lines += ["", _split_text(res)]
    return "\n".join(lines)


def _table(header: list[str], rows: list[list[str]], align: str) -> list[str]:
    out = ["| " + " | ".join(header) + " |", "|" + "|".join("---:" if a == "r" else "---" for a in align) + "|"]
    out += ["| " + " | ".join(row) + " |" for row in rows]
    return out


def _fmu_table(series, reference: str, note: dict, labels=FMU_ROWS) -> list[str]:
    rows = []
    for label in labels:
        if label not in series.batches:
            continue
        ratio = "1" if label == reference else fmt_ratio(series.ratio(label, reference))
        span = "" if label == reference else _spread(series.spread(label, reference))
        rows.append([f"{label} ({note[label]})", fmt_time(series.median(label)), ratio, span])
    return _table(["FMU", "per impact (median)", f"/ {reference}", "range over repeats"], rows, "lrrr")


FMU_NOTE = {"native": "C front + C physics", "fmi3": "native FMI 3.0: the same core behind the fmi3 layer",
            "floor": "C front, backend does nothing",
            "precomputed": "no FMI: e and v_rebound by Eqs. 8, 12, 13 (fit), 20, the parameter terms once",
            "pythonfmu": "C guard + pythonfmu + the package"}


def render(res: dict) -> str:
    m, cfg = res["machine"], res["config"]
    lines = [
        "# What the native FMU costs",
        "",
        f"Measured by `benchmarks/bench_native.py` on {res['date']} ({res['duration']:.0f} s, "
        f"{cfg['name']} run). Generated: rerun it to measure your machine:",
        "",
        "```sh",
        ".venv/bin/python benchmarks/bench_native.py   # writes docs/native_cost.md; --quick for a short run",
        "```",
        "",
        f"Machine: {m['cpu']}, {m['cores']} cores; {m['versions']}; {m['platform']}.",
        "",
        f"**A shared machine**: other jobs ran alongside (load average {m['load_start']:.1f} at the start, "
        f"{m['load_end']:.1f} at the end, on {m['cores']} cores); they share the caches and cores, so absolute "
        "times move from batch to batch (the ranges below show by how much). Each comparison runs its variants "
        f"in turn, batch by batch ({cfg['reps']} repeats, the first variant rotating, {cfg['seconds']:g} s of CPU "
        "time per batch after an untimed tenth of that); a time is the median of its batches, a ratio the median "
        "over the repeats of the ratio within one repeat. Times are CPU time of the timing thread "
        "(`time.thread_time`, `CLOCK_THREAD_CPUTIME_ID`), not wall time: every FMU here computes in the "
        "caller's thread. **Ratios are the headline.**",
        "",
        "One impact = one round trip: `fmi2SetReal` of `v_approach` (a new value every time, so the model is "
        f"evaluated), `fmi2DoStep` ({res['step']:g} s), `fmi2GetReal` of all {res['n_reals']} Real outputs and "
        f"`fmi2GetBoolean` of all {res['n_bools']} Boolean outputs, `exact` method, S2 tool steel on Al 6061 "
        "(the start values).",
        "",
        "## Headline",
        "",
        *_table(["target", "measured", "range over repeats", "goal", "met"],
                [list(r) for r in headline_rows(res)], "lrrrl"),
        "",
        "## Through fmpy",
        "",
        "fmpy's `FMU2Slave` in this Python process, its raw FMI functions called with preallocated ctypes "
        "arrays (as `tests/fmu/test_fmu_robustness.py`'s million-step test calls them). The *floor* is an FMU "
        "with the same modelDescription built from the same C front (`fmu_src/restitution/fmu/cfront/`), the "
        "same generated interface table and the same compiler flags as the native FMU, with a backend that "
        "does nothing (every hook returns at once, outputs are constants: `benchmarks/bench_c/floor_fmu.c`): "
        "native / floor is what the physics and its glue add to what the front and fmpy cost.",
        "",
        *_fmu_table(res["fmpy"], "floor", FMU_NOTE),
        "",
        "## In a plain C host",
        "",
        "A C timing host (`benchmarks/bench_c/timing_host.c`: dlopen of the FMU binary, the four calls in a loop, "
        "`clock_gettime`) run under `env -i PATH=/usr/bin:/bin` as `tests/hosts/test_c_host_impact.py` runs its "
        "host, all four FMUs instantiated in the one process; the pythonfmu FMU's guard starts the "
        "interpreter recorded in `resources/python_env.txt`. `fmi3` is the native FMI 3.0 FMU "
        "(`fmi3/SpherePlateImpact.fmu`) through its own calls: `fmi3SetFloat64`, `fmi3DoStep` (with its "
        "out-arguments), `fmi3GetFloat64`, `fmi3GetBoolean`, the same value references; its ratio to the FMI 2.0 "
        "native FMU is what the FMI 3.0 layer costs against the FMI 2.0 one.",
        "",
        *_fmu_table(res["c_host"], "native", FMU_NOTE, C_HOST_ROWS),
        "",
        f"native / floor in the C host: {fmt_ratio(res['c_host'].ratio('native', 'floor'))} "
        f"(range {_spread(res['c_host'].spread('native', 'floor'))}): the floor's time is "
        f"{100 / res['c_host'].ratio('native', 'floor'):.0f} % of the native FMU's, so that share of one impact "
        "is the C front (and the host's loop), the rest the physics and its glue.",
        "",
        "### Each call alone (the floor: the C front's own cost)",
        "",
        "The floor FMU in the same host, each of the four calls made alone in its own batches (the values "
        "set and the times stepped as in the round trip).",
        "",
        *_table(["call", "per call (median)", "share of their sum"],
                _call_rows(res["calls"]), "lrr"),
        "",
        "## Against the precomputed C floor",
        "",
        "One impact as a simulation uses it: `fmi2SetReal` of `v_approach`, `fmi2DoStep`, `fmi2GetReal` of `e` and "
        "`v_rebound` (no `fmi2GetBoolean`), in the same C host, against the *precomputed C floor* "
        "(`benchmarks/bench_c/precomputed_floor.c`, linked into the host and timed as one of its "
        "variants, batches interleaved with the FMUs'): the least C that computes e and v_rebound, with no FMI "
        "at all: Eq. (8), lambda by Eq. (12), Zener's COR by the paper's fit, Eq. (13), and Eq. (20), every term "
        "that depends on the parameters alone computed once (at the FMU's start values), so that an impact "
        "costs one logarithm of v, one of V* - 1 and three exponentials. The native FMU computes e and "
        "v_rebound at a step by the default `exact` method (the other outputs on their first read) and "
        "goes through the FMI front and its glue.",
        "",
        *_fmu_table(res["impact"], "precomputed", FMU_NOTE, IMPACT_ROWS),
        "",
        _split_text(res) + ": the first part is outside the physics (the C front, `fmu_src/restitution/fmu/cfront/`), "
        "the second is the backend (`models/sphere_plate_impact/`) and the physics per step.",
        "",
        "## The C physics against the package",
        "",
        "`rst_impact` in a compiled C loop (`benchmarks/bench_c/physics_loop.c`, v changing every call) against "
        "the package's scalar `restitution.impact` with Python floats (`validate=False`; what the pythonfmu "
        "FMU evaluates per step), per Zener method the C implements.",
        "",
        *_table(["Zener method", "C physics per impact", "package scalar call", "package / C", "range over repeats"],
                [[meth, fmt_time(res["physics"].median(f"C {meth}")),
                  fmt_time(res["physics"].median(f"package {meth}")),
                  fmt_ratio(res["physics"].ratio(f"package {meth}", f"C {meth}")),
                  _spread(res["physics"].spread(f"package {meth}", f"C {meth}"))] for meth in METHODS], "lrrrr"),
        "",
    ]
    return "\n".join(lines)


def _call_rows(series) -> list[list[str]]:
    medians = {call: series.median(f"floor/{call}") for call in CALLS}
    total = sum(medians.values())
    return [[f"`{call}`", fmt_time(medians[call]), f"{100 * medians[call] / total:.0f} %"] for call in CALLS]
