"""Command line: ``restitution sweep [SPEC.toml|SPEC.json] [options]`` (see --help, docs/sweeps.md); also run as
``python -m restitution.sweep`` and ``restitution-sweep``, which show the same name."""
from __future__ import annotations

import argparse
import contextlib
import sys
import time
from dataclasses import dataclass
from pathlib import Path

from ..extras import MissingExtra
from ..materials_table import text as materials_text
from ..inputs import QuantityError
from ..options import BARE_NUMBER_RULE, ArgumentParser, add_material_options
from ..output_files import EXIT_IO_ERROR, EXIT_REFUSED, OutputPathError, OutputWriteError, describe_os_error
from ..units import OptionError
from .outputs import SweepOutputs, check_sweep_outputs, resolve_outputs
from .sobol import SOBOL_OUTPUTS, SobolCollector, SobolError, SobolSpec
from .spec import CODES, INPUT_NAMES, INPUTS, MAX_SAMPLES, MAX_SEED, T_OVER_D, SweepSpec, canonical_name, load_spec

#: The command's name in its usage line and its errors, however it was started.
PROG = "restitution sweep"
#: Exit status of an interrupted sweep (128 + SIGINT, as a shell reports Ctrl-C).
EXIT_INTERRUPTED = 130
#: Largest --chunk-size and --workers.
MAX_CHUNK = 10**9
MAX_WORKERS = 4096


def _int_in(low: int, high: int):
    """argparse type: an integer in [low, high] (checked at parse time; one-line error)."""
    def parse(text: str) -> int:
        try:
            value = int(text.strip())
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not an integer") from None
        if not low <= value <= high:
            raise argparse.ArgumentTypeError(f"{value} is out of range: {low} <= value <= {high}")
        return value
    return parse


def _bytes_arg(text: str) -> int:
    """argparse type: a size in bytes, with an optional K/M/G/T(iB) suffix."""
    units = {"": 1, "k": 2**10, "kib": 2**10, "m": 2**20, "mib": 2**20, "g": 2**30, "gib": 2**30,
             "t": 2**40, "tib": 2**40}
    body = text.strip()
    digits = body.rstrip("KMGTiBkmgtib")
    try:
        value = float(digits) * units[body[len(digits):].lower()]
    except (ValueError, KeyError):
        raise argparse.ArgumentTypeError(f"{text!r} is not a size (e.g. 2GiB, 500M, 1000000)") from None
    if not 1 <= value <= 2**60:
        raise argparse.ArgumentTypeError(f"{text!r} is out of range: 1 byte ... 1 EiB")
    return int(value)


def _error(text: str, status: int) -> int:
    """One line on stderr, no usage: the error is about a file, not about how the command is called."""
    print(f"{PROG}: error: {text}", file=sys.stderr, flush=True)
    return status


def _hooks(*hooks):
    """One ``on_chunk`` hook that calls each of ``hooks`` that is not None (None when none is)."""
    hooks = [h for h in hooks if h is not None]
    if len(hooks) < 2:
        return hooks[0] if hooks else None

    def every(start, stop, columns):
        for hook in hooks:
            hook(start, stop, columns)
    return every


def _kept(parts: Path) -> str:
    n = sum(1 for _ in parts.glob("*/chunk-*.parquet")) if parts.is_dir() else 0
    return f"the {n:,} finished chunk(s) are kept in {parts}" if n else f"no finished chunk is kept in {parts}"


EXAMPLES = """examples:
  # e over speed and t/d for two material pairs, on a local Dask cluster (one worker per core)
  restitution sweep --pair s2_tool_steel/al_6061 --pair chrome_steel/s7_tool_steel \\
      --grid v_approach=geomspace:0.1:10:60 --grid t_over_d=geomspace:0.1:10:50 --out map.csv

  # Monte Carlo: 10000 draws of scattered speed and moduli, checked through the FMU itself
  restitution sweep --pair brass_260/al_6061 --random v_approach=uniform:0.5:3 \\
      --random sphere.E=normal_rel:0.03 --random plate.E=normal_rel:0.03 --samples 10000 \\
      --backend fmu --out mc.csv

  # values with their units (a bare number is SI)
  restitution sweep --sphere chrome_steel --plate-material copper.toml --set sphere.d=6.35mm \\
      --set plate.t=3mm --grid v_approach=geomspace:0.1:10:40 --out cu.csv
  restitution sweep --set sphere.d="1/4 in" --set plate.E=114GPa --grid plate.t=linspace:1mm:5mm:9 \\
      --grid v_approach=geomspace:10cm/s:10m/s:40 --out t.csv

  # Sobol' indices of e, e_ep, e_ze and t_contact: 1024 base samples, 1024 x (2 + 2) cases
  restitution sweep --random plate.t=uniform_rel:0.15 --random v_approach=uniform:0.5:3 \\
      --samples 1024 --sobol --summary sobol.json --out sobol.csv

  # the same sweep on an existing cluster
  restitution sweep spec.toml --scheduler tcp://scheduler-host:8786
"""


def _pairs(items):
    out = {}
    for item in items or []:
        name, sep, value = item.partition("=")
        if not sep:
            raise ValueError(f"expected NAME=VALUE, got {item!r}")
        out[name.strip()] = value.strip()
    return out


def _list() -> str:
    lines = ["inputs and parameters (FMU name, impact() keyword, start value):"]
    for name, kw, vtype, start in INPUTS:
        codes = f"  codes: {', '.join(f'{k}={v}' for k, v in CODES[name].items())}" if name in CODES else ""
        lines.append(f"  {name:22s} {kw:18s} {start!r:>10}{codes}")
    lines.append(f"  {T_OVER_D:22s} (derived: plate.t = t_over_d * sphere.d)")
    lines.append("materials (pairs are sphere/plate keys, or table4:A1 ... table4:B4):")
    lines += [("  " + line).rstrip() for line in materials_text().splitlines()]
    return "\n".join(lines)


def build_spec(args) -> tuple[SweepSpec, dict]:
    """The spec of the spec file and the options, with its explicit values checked against the inputs'
    declared ranges (a Saltelli design, :class:`SobolSpec`, with --sobol), and its [run] table. A refused
    value is a :class:`QuantityError` naming the option (or the spec file's table) that gave it."""
    data = load_spec(args.spec) if args.spec else {}
    if not isinstance(data, dict):
        raise ValueError(f"spec file {args.spec}: expected a table (pairs, grid, random, fixed, samples, seed, "
                         f"[run]), got a {type(data).__name__}")
    run = data.pop("run", {}) or {}
    if not isinstance(run, dict):
        raise ValueError(f"spec file {args.spec}: run = {run!r}: expected a table [run]")
    run = dict(run)
    data = {k: (dict(v) if isinstance(v, dict) else v) for k, v in data.items()}
    if args.pair:
        data["pairs"] = list(args.pair)
    given = set()
    for section, items in (("grid", args.grid), ("random", args.random), ("fixed", args.set)):
        for name, value in _pairs(items).items():
            key = canonical_name(name)
            for other in ("grid", "random", "fixed"):  # a command-line value replaces the file's
                for k in list(data.get(other, {})):
                    if canonical_name(k) == key:
                        del data[other][k]
            data.setdefault(section, {})[key] = value
            given.add((section, key))
    for key, value in _material_values(args).items():  # --sphere/--plate and their properties: fixed values
        if any((section, key) in given for section in ("grid", "fixed")):
            raise OptionError(f"{key} is given by --set/--grid and by the {key.split('.')[0]} material options: "
                             f"give it once")
        for other in ("grid", "fixed"):  # they replace the spec file's values (a relative draw scatters them)
            for k in [k for k in data.get(other, {}) if canonical_name(k) == key]:
                del data[other][k]
        data.setdefault("fixed", {})[key] = value
        given.add(("fixed", key))
    if args.samples is not None:
        data["samples"] = args.samples
    if args.seed is not None:
        data["seed"] = args.seed
    try:
        spec = (SobolSpec if args.sobol else SweepSpec).from_dict(data)
        spec.check_domain()  # explicit values inside the inputs' declared ranges, before any work
    except QuantityError as exc:
        raise QuantityError(_value_error(exc, given, args.spec), exc.name) from None
    _check_set_lengths(args)
    return spec, run


def _material_values(args) -> dict:
    """The fixed values (SI, by FMU name) of --sphere/--plate, --ROLE-material and --ROLE-E ...: a
    material's four properties; refused with --pair, which names both materials."""
    from ..inputs import MATERIAL_PROPERTIES, material_from_args

    out = {}
    for role in ("sphere", "plate"):
        options = [getattr(args, role), getattr(args, f"{role}_material"),
                   *(getattr(args, f"{role}_{key}") for key in MATERIAL_PROPERTIES)]
        if all(option is None for option in options):
            continue
        if args.pair:
            raise OptionError(f"--{role} and its properties set the {role}'s material: not with --pair, "
                             f"which names both materials (give --sphere and --plate instead)")
        body = material_from_args(args, role)[0]
        out.update({f"{role}.{key}": float(getattr(body, key)) for key in MATERIAL_PROPERTIES})
    return out


def _check_set_lengths(args) -> None:
    """A bare-number sphere.d or plate.t of --set that is a likely slip refused
    (:func:`restitution.inputs.check_plausible_lengths`) unless --allow-implausible."""
    from ..inputs import check_plausible_lengths, input_reading

    readings = {}
    for item in args.set or []:
        name, _, text = item.partition("=")
        key = canonical_name(name)
        if key in ("sphere.d", "plate.t"):
            readings[key] = (f"--set {name.strip()}={text.strip()}",
                             *input_reading(f"set {key}", key, text.strip()))
    check_plausible_lengths(readings.get("sphere.d"), readings.get("plate.t"), allow=args.allow_implausible)


#: The option that gives the values of each section of a spec.
OPTIONS = {"grid": "--grid", "random": "--random", "fixed": "--set"}


def _value_error(exc: QuantityError, given: set, spec_file) -> str:
    """A refused value, named as it was given: ``--grid v_approach = -1 m/s is outside ...``."""
    if exc.section is None:
        return str(exc)
    if (exc.section, exc.name) in given or not spec_file:
        return f"{OPTIONS[exc.section]} {exc}"
    return f"spec file {spec_file}: [{exc.section}] {exc}"


def main(argv=None) -> int:
    parser = ArgumentParser(
        prog=PROG, formatter_class=argparse.RawDescriptionHelpFormatter,
        description="Sweep the apparent COR (Green 2022) over material pairs, FMU parameters and the "
                    "approach speed, on Dask; write a table (CSV headers with units) and a plot: a grid's "
                    "COR map, or the histogram of e of random draws.", epilog=EXAMPLES + "\n" + BARE_NUMBER_RULE)
    parser.add_argument("spec", nargs="?", help="TOML or JSON spec file (pairs, [grid], [random], [fixed], "
                                                "samples, seed, [run]); options below add to or override it")
    parser.add_argument("--pair", action="append", metavar="SPHERE/PLATE",
                        help="material pair, e.g. s2_tool_steel/al_6061 or table4:A1 (repeat for more)")
    parser.add_argument("--grid", action="append", metavar="NAME=VALUES",
                        help="grid axis: 'a,b,c', 'linspace:a:b:n' or 'geomspace:a:b:n'; values with units "
                             "(plate.t=linspace:1mm:5mm:9) or SI (repeat)")
    parser.add_argument("--random", action="append", metavar="NAME=DIST",
                        help="random parameter: uniform:lo:hi, loguniform:lo:hi, normal:mean:sd, "
                             "normal_rel:sd, uniform_rel:h, choice:a,b (repeat)")
    parser.add_argument("--set", action="append", metavar="NAME=VALUE",
                        help="fixed value, with a unit or SI: plate.t=3mm, plate.E=114GPa, sphere.d='1/4 in' (repeat)")
    parser.add_argument("--allow-implausible", action="store_true",
                        help="accept a bare-number --set sphere.d or plate.t that looks like a slip (a 10 m sphere)")
    add_material_options(parser, "sphere", "; they set the four properties as --set values (not with --pair)")
    add_material_options(parser, "plate", "; as for the sphere")
    parser.add_argument("--samples", type=_int_in(1, MAX_SAMPLES),
                        help="random cases per grid point (--sobol: N base samples, a power of 2)")
    parser.add_argument("--sobol", action="store_true",
                        help="Sobol' indices of the --random inputs: a Saltelli design of N (D + 2) cases, "
                             "S1 and ST of e, e_ep, e_ze, t_contact with 95%% bootstrap intervals (no grid)")
    parser.add_argument("--seed", type=_int_in(0, MAX_SEED), help="seed of the random draws (0 ... 2**63 - 1)")
    parser.add_argument("--backend", choices=("package", "fmu", "both"),
                        help="package: vectorized (default); fmu: the FMU itself; both: run both and "
                             "compare (exit 1 if any output differs by more than its conditioning allows, "
                             "restitution.agreement)")
    parser.add_argument("--fmu", help="FMU for the fmu back end (default: dist/SpherePlateImpact.fmu, "
                                      "built if missing)")
    parser.add_argument("--scheduler", help="address of a running dask.distributed scheduler "
                                            "(tcp://host:8786), 'local' (new LocalCluster) or 'serial' "
                                            "(no Dask); default: $DASK_SCHEDULER_ADDRESS, else serial for a "
                                            "sweep too small to win back a LocalCluster's start, else local")
    parser.add_argument("--workers", type=_int_in(1, MAX_WORKERS),
                        help="LocalCluster worker processes (default: one per core)")
    parser.add_argument("--chunk-size", type=_int_in(1, MAX_CHUNK), help="cases per Dask task")
    parser.add_argument("--memory-budget", type=_bytes_arg, metavar="BYTES",
                        help="largest table to gather, e.g. 2GiB (default: half the memory available); "
                             "a bigger sweep is refused before it starts")
    parser.add_argument("--resume", action="store_true",
                        help="complete an interrupted sweep: evaluate only the chunks missing from <out>.parts/")
    parser.add_argument("--columns", help="keep only these comma-separated columns (plus case and pair), "
                                          "e.g. v_approach,t_over_d,e,valid for a big sweep")
    parser.add_argument("--out", help="table: .csv or .parquet (default: sweep.parquet with pyarrow, else sweep.csv)")
    parser.add_argument("--plot", help="the plot's image: a grid's COR map (default: <out>_cor_map.png), the histogram "
                                       "of e of random draws around one point (default: <out>_hist.png); with "
                                       "--sobol the indices' chart is <out>_sobol.png")
    parser.add_argument("--no-plot", action="store_true", help="skip the plot (and the Sobol' chart)")
    parser.add_argument("--summary", metavar="FILE", help="JSON: mean, std, percentiles and the mean's 95 %% "
                                                          "interval of every output, the out-of-range cases, the draws "
                                                          "(printed for the main outputs whenever there are --random inputs), "
                                                          "and with --sobol the indices")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")
    parser.add_argument("--dry-run", action="store_true", help="print what the sweep covers and stop")
    parser.add_argument("--list", action="store_true", help="list parameter names and materials and stop")
    args = parser.parse_args(argv)

    if args.list:
        print(_list())
        return 0
    try:
        status = _main(parser, args)
    except KeyboardInterrupt:  # outside the sweep itself (which writes what is done): nothing to keep
        print("\ninterrupted before the sweep started or after its table was written", file=sys.stderr)
        status = EXIT_INTERRUPTED
    except OSError as exc:  # an I/O error outside the outputs (the FMU extracted to a full /tmp, ...)
        return _error(describe_os_error(exc), EXIT_IO_ERROR)
    if status == EXIT_INTERRUPTED:
        from ..cosim.interrupt import forget_unhandled_interrupt

        forget_unhandled_interrupt()
        _ignore_further_interrupts()
    return status


def _ignore_further_interrupts() -> None:
    """SIGINT ignored once the interpreter shuts down, after the sweep decided to exit interrupted.

    A SIGINT still pending then (blocked in the cluster's threads) would be delivered after Python
    has put back the default action and kill the process by the signal (status -2) after it said what
    it kept, instead of the 130 it reports. An exit hook, not an immediate change, so a caller who
    runs main() in process keeps its Ctrl-C."""
    import atexit
    import signal

    atexit.register(signal.signal, signal.SIGINT, signal.SIG_IGN)


@dataclass
class _Settings:
    """What the options and the spec file's [run] table ask of a sweep, besides its files."""
    spec: SweepSpec
    run: dict
    backend: str
    scheduler: str | None
    workers: int | None
    chunk: int | None
    fmu: str | None
    columns: list | None


def _settings(parser, args) -> _Settings | int:
    """The spec and the run's settings from the options and the spec file (the options win); an exit
    status for a refused value."""
    from .table import keep_columns

    try:
        spec, run = build_spec(args)
        run_ints = {key: _int_in(low, high)(str(run[key])) for key, low, high in (
            ("workers", 1, MAX_WORKERS), ("chunk_size", 1, MAX_CHUNK)) if run.get(key) is not None}
    except (QuantityError, SobolError, OptionError) as exc:  # a value, or a sweep --sobol cannot take: one line, no usage
        return _error(str(exc), EXIT_REFUSED)
    except (ValueError, argparse.ArgumentTypeError) as exc:
        parser.error(str(exc))
    backend = args.backend or run.get("backend", "package")
    if backend not in ("package", "fmu", "both"):
        parser.error(f"[run] backend = {backend!r}: use 'package', 'fmu' or 'both'")
    columns = args.columns or run.get("columns")
    if isinstance(columns, str):
        columns = [c.strip() for c in columns.split(",") if c.strip()]
    if args.sobol and columns is not None:  # the analysed outputs come from the chunks: they must travel
        columns = list(dict.fromkeys([*columns, *SOBOL_OUTPUTS.values()]))
    try:
        keep_columns(columns)
    except ValueError as exc:
        parser.error(f"--columns: {exc}")
    if backend == "both" and columns is not None:
        missing = [c for c in ("ok", *INPUT_NAMES) if c not in columns]
        if missing:  # checked before the run, not after it
            parser.error(f"--backend both compares every case from its inputs: --columns must keep {', '.join(missing)}")
    return _Settings(spec, run, backend, args.scheduler or run.get("scheduler"),
                     args.workers if args.workers is not None else run_ints.get("workers"),
                     args.chunk_size if args.chunk_size is not None else run_ints.get("chunk_size"),
                     args.fmu or run.get("fmu"), columns)


def _main(parser, args) -> int:
    from .size import plan_size, table_bytes
    from .spec import SizeError

    settings = _settings(parser, args)
    if isinstance(settings, int):
        return settings
    spec, run, backend = settings.spec, settings.run, settings.backend
    no_plot = args.no_plot or run.get("plot") is False
    try:  # before any work: one line naming the extra, not a traceback after the cluster started
        outputs = resolve_outputs(spec, args.out or run.get("out"), args.plot or run.get("plot"),
                                  args.summary or run.get("summary"), no_plot, args.sobol, backend)
    except MissingExtra as exc:
        hint = "; or --no-plot" if not no_plot and "matplotlib" in str(exc) else ""
        return _error(f"{exc}{hint}", EXIT_REFUSED)
    except OutputPathError as exc:
        return _error(str(exc), EXIT_REFUSED)
    print(f"sweep: {spec.describe()}")

    n_backends = 2 if backend == "both" else 1
    try:  # the size guard, from the axis sizes alone
        spec.check_axes()
        plan = plan_size(spec, settings.columns, args.memory_budget, backends=n_backends, out=outputs.out,
                         parts=outputs.parts)
    except SizeError as exc:
        if args.dry_run:
            print(f"sweep: refused: {exc}")
            return 0
        parser.error(str(exc))
    if args.dry_run:
        print(f"sweep: {plan.describe()} ({table_bytes(1, settings.columns) * n_backends} bytes a case)")
        return 0
    try:
        check_sweep_outputs(outputs, plan.stream, {"--fmu": settings.fmu, "SPEC": args.spec})
    except OutputPathError as exc:
        return _error(str(exc), EXIT_REFUSED)
    settings.fmu = _impact_fmu(parser, backend, settings.fmu)
    if plan.stream:
        print(f"sweep: {plan.describe()}", file=sys.stderr)
    return _run_and_write(parser, args, settings, outputs, plan)


def _impact_fmu(parser, backend: str, fmu):
    """The FMU the fmu back end runs: ``fmu`` checked, or the default one (built when missing); None for
    the package back end."""
    try:
        if backend in ("fmu", "both") and fmu is not None:
            from ..cosim.fmu import check_impact_fmu
            fmu = check_impact_fmu(fmu)
    except ValueError as exc:
        parser.error(str(exc))

    if backend in ("fmu", "both") and fmu is None:
        from ..fmu.builders.products import BuildError, default_fmu
        try:
            fmu = default_fmu(log=print)
        except BuildError as exc:
            parser.error(str(exc))
    return fmu


def _run_and_write(parser, args, settings: _Settings, outputs: SweepOutputs, plan) -> int:
    """Run the sweep on each back end, then write its table and report (statistics, Sobol' indices, the
    summary, the plot); the exit status."""
    from .cluster import open_client
    from .parts import PartError, ResumeError
    from .run import SweepInterrupted, run_sweep
    from .statistics import SweepStatistics
    from .table import keep_columns

    spec, backend, columns, parts, out = settings.spec, settings.backend, settings.columns, outputs.parts, outputs.out
    scheduler = settings.scheduler
    backends = ("package", "fmu") if backend == "both" else (backend,)
    if args.resume and not all((parts / name / "manifest.json").is_file() for name in backends):
        print(f"--resume: no finished chunks in {parts}: the whole sweep runs", file=sys.stderr)
    results = {}
    # gathered from the chunks as they come (and from the kept parts on --resume) of the written table's back end
    statistics = SweepStatistics(spec, keep_columns(columns)) if spec.random or outputs.summary else None
    sobol = SobolCollector(spec) if args.sobol else None
    chosen = None
    if scheduler is None:  # neither --scheduler nor $DASK_SCHEDULER_ADDRESS: a cluster only where it can pay
        from .cluster import serial_reason
        chosen = serial_reason(spec, backends, settings.workers)
        scheduler = "serial" if chosen else None
    try:
        with contextlib.ExitStack() as stack:
            target = "serial"
            if scheduler != "serial":
                try:
                    target = stack.enter_context(open_client(scheduler, settings.workers))
                except OSError as exc:  # an address nothing answers at (Dask waits its connect timeout)
                    parser.error(f"--scheduler {scheduler}: cannot connect: {exc}")
            # the columns stay in memory only for what reads them here: the plot, the comparison of
            # two back ends; the table itself is joined from the parts, and the statistics come chunk by chunk
            in_memory = not plan.stream and (outputs.plot is not None or backend == "both")
            for name in backends:
                res = run_sweep(spec, name, fmu=settings.fmu, scheduler=target, chunk_size=settings.chunk,
                                progress=not args.no_progress, columns=columns, parts=parts / name,
                                resume=args.resume, in_memory=in_memory,
                                on_chunk=_hooks(statistics, sobol) if name == backends[0] else None)
                if chosen:
                    res.scheduler = f"this process ({chosen})"
                print(res.summary())
                results[name] = res
    except SweepInterrupted as exc:
        try:
            written = exc.result.write(out)
        except KeyboardInterrupt:
            print(f"\ninterrupted again while writing {out}: nothing written there; the finished chunks are "
                  f"kept in {parts}: run the same command with --resume", file=sys.stderr)
            return EXIT_INTERRUPTED
        except (OutputWriteError, OutputPathError, PartError) as err:
            return _error(f"interrupted, then {err}; {_kept(parts)}: run the same command with --resume",
                          EXIT_REFUSED if isinstance(err, OutputPathError) else EXIT_IO_ERROR)
        print(f"\ninterrupted: wrote the {len(exc.result):,} finished cases to {written}; {exc.missing:,} of "
              f"{spec.n_cases:,} cases are missing (finished chunks kept in {parts}); run the same command "
              f"with --resume to complete them", file=sys.stderr)
        return EXIT_INTERRUPTED
    except ResumeError as exc:  # --resume on another sweep's parts, or a damaged part that cannot be removed
        return _error(str(exc), EXIT_REFUSED)
    except OutputPathError as exc:  # a part's name turned into a device or a directory during the run
        return _error(f"{exc}; {_kept(parts)}", EXIT_REFUSED)
    except OutputWriteError as exc:  # a part or the manifest: the chunks written before it stay
        return _error(f"{exc}; {_kept(parts)}: run the same command with --resume once it can be written",
                      EXIT_IO_ERROR)
    return _write_and_report(spec, results, backends, backend, outputs, plan, statistics, sobol)


def _write_and_report(spec, results: dict, backends: tuple, backend: str, outputs: SweepOutputs, plan, statistics,
                      sobol) -> int:
    """Compare two back ends' results, write the table, print the statistics and the Sobol' indices, write
    the summary and the plot; the exit status."""
    from .parts import PartError
    from .statistics import write_summary

    out, parts, plot, summary, sobol_chart = (outputs.out, outputs.parts, outputs.plot, outputs.summary,
                                              outputs.sobol_chart)
    status = 0
    if backend == "both":
        from .compare import agreement_report

        a_cols, b_cols = results["fmu"].columns, results["package"].columns
        compared, problems = agreement_report(a_cols, b_cols)
        if problems:
            for name, description in problems.items():
                print(f"FAIL: fmu vs package, {description}", file=sys.stderr)
            status = 1
        else:
            print(f"the FMU and the package agree on all {compared} cases within each output's conditioning "
                  "(restitution.agreement)")
    result = results[backends[0]]
    try:
        started = time.perf_counter()
        print(f"table: {result.write(out)}")
        if out.suffix.lower() != ".parquet":  # what CSV costs, beside the sweep: it is text, case by case
            print(f"CSV: {time.perf_counter() - started:.3g} s to write {len(result):,} rows (Parquet, "
                  f"--out {out.with_suffix('.parquet').name}, joins the finished chunks without formatting them)")
    except KeyboardInterrupt:
        print(f"\ninterrupted while writing {out}: nothing written there; every chunk is kept in {parts}: "
              f"run the same command with --resume to write the table", file=sys.stderr)
        return EXIT_INTERRUPTED
    except (OutputWriteError, OutputPathError, PartError) as exc:
        status = EXIT_REFUSED if isinstance(exc, OutputPathError) else EXIT_IO_ERROR
        return _error(f"{exc}; nothing written there, every chunk is kept in {parts}: run the same command "
                      f"with --resume to write the table", status)
    import shutil

    shutil.rmtree(parts, ignore_errors=True)  # the table is whole: the finished chunks are not needed
    for res in results.values():
        if res.warning():
            print(f"{res.backend}: {res.warning()}", file=sys.stderr)
    if spec.random:
        print(statistics.text())
    sobol_section, sobol_status = _sobol_report(sobol) if sobol is not None else ({}, 0)
    status = max(status, sobol_status)
    if sobol_chart is not None and sobol_section.get("sobol"):
        from .sobol_plot import plot_sobol

        try:
            drawn = plot_sobol({**sobol_section["sobol_design"], "sobol": sobol_section["sobol"]}, sobol_chart)
            print(f"Sobol' chart: {drawn}")
        except (OutputWriteError, OutputPathError) as exc:
            return _error(f"{exc}; the table was written to {out}",
                          EXIT_REFUSED if isinstance(exc, OutputPathError) else EXIT_IO_ERROR)
    if summary is not None:
        try:
            print(f"summary: {write_summary(summary, statistics.summary(backend=result.backend), sobol_section)}")
        except (OutputWriteError, OutputPathError) as exc:
            return _error(f"{exc}; the table was written to {out}",
                          EXIT_REFUSED if isinstance(exc, OutputPathError) else EXIT_IO_ERROR)
    if plot is None:
        return status
    return _draw(result, plot, outputs.plot_name, out, statistics, streamed=plan.stream) or status


def _draw(result, plot: Path, name: str, out: Path, statistics, streamed: bool) -> int:
    """Draw the sweep's plot (``name``: a COR map, a histogram of e) into ``plot`` and say where; one line
    saying why when there is none. The exit status of a file that cannot be written (0 otherwise)."""
    from .plot import NoPlot

    if streamed:
        print(f"no {name}: the table is too big for memory (streamed to {out}); plot a smaller sweep", file=sys.stderr)
        return 0
    try:
        print(f"{name}: {result.plot(plot, statistics=statistics)}")
    except ModuleNotFoundError as exc:
        print(f"no {name} ({exc}; pip install matplotlib)", file=sys.stderr)
    except (OutputWriteError, OutputPathError) as exc:
        return _error(f"{exc}; the table was written to {out}",
                      EXIT_REFUSED if isinstance(exc, OutputPathError) else EXIT_IO_ERROR)
    except NoPlot as exc:  # --columns left out what it draws: one line, why
        print(f"no {name}: {exc}", file=sys.stderr)
    return 0


def _sobol_report(collector) -> tuple[dict, int]:
    """Print the Sobol' indices (and why an output has none, and whether the intervals rank the inputs);
    (the summary's sections: ``sobol``, the indices, and ``sobol_design``, how they were made and what was
    refused; the exit status: 1 when an output has no indices)."""
    from .sobol import format_indices, ranking_warning, refusals

    section = collector.analyze()
    print(format_indices(section))
    for line in refusals(section):
        print(f"{PROG}: error: {line}", file=sys.stderr)
    warning = ranking_warning(section)
    if warning:
        print(warning, file=sys.stderr)
    design = {key: value for key, value in section.items() if key != "sobol"}
    return {"sobol": section["sobol"], "sobol_design": design}, 1 if section["refused"] else 0


if __name__ == "__main__":
    sys.exit(main())
