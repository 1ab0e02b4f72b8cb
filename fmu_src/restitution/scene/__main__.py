"""Command line: ``restitution scene {check,run,report} ...`` (also run as ``python -m restitution.scene`` and
``restitution-scene``, which show the same name).

    check FILE...                      load and check scene files, print what they contain
    run FILE [--out DIR] [--all-on] [--zener-method M] [--fmu PATH] [--ball-fmu PATH] [--rebuild] [--no-plot]
                                       simulate a scene; write DIR/<stem>.csv, <stem>_summary.csv, <stem>.png;
                                       exit status 3 when a drop stops at its bounce limit still bouncing,
                                       74 on an I/O error writing them (ENOSPC, EIO, ...)
    report FILE... [--out docs/scenes.md] [--repeat N] [--methods exact,ode]
                                       auto vs every effect on: effect counts, wall times, differences
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..extras import MissingExtra, require
from ..fmu.builders.products import BuildError
from ..options import ArgumentParser
from ..output_files import (EXIT_IO_ERROR, EXIT_REFUSED, OutputPathError, check_output, check_output_dir,
                            check_outputs, describe_os_error)
from .loader import SceneError, load_scene


def _check(args) -> int:
    for path in args.files:
        scene = load_scene(path)
        plasticity, waves = scene.effect_modes()
        print(f"{path}: {scene.name!r}: {len(scene.plates)} plates, {len(scene.balls)} balls, "
              f"{len(scene.drops())} drops; outputs {', '.join(scene.outputs)} (tolerance {scene.tolerance:g}); "
              f"plasticity = {plasticity}, plate_waves = {waves}, zener_method = {scene.model.zener_method}")
    return 0


#: The command's name in its usage line and its errors, however it was started.
PROG = "restitution scene"
#: Exit status of an interrupted run (128 + SIGINT, as a shell reports Ctrl-C).
EXIT_INTERRUPTED = 130
#: `run` finished and wrote everything, but some drop stopped at its bounce limit still bouncing.
EXIT_NOT_AT_REST = 3


class UsageError(Exception):
    """A command-line value that cannot be used (one line, exit 2)."""


def _fmu(args) -> Path:
    """The FMU to run, checked (or built) before anything is written."""
    from .runner import chosen_fmu

    try:
        return chosen_fmu(args.fmu, rebuild=args.rebuild if hasattr(args, "rebuild") else False,
                          log=lambda text: print(text, file=sys.stderr))
    except SceneError:
        raise
    except ValueError as exc:  # --fmu PATH that is not a SpherePlateImpact FMU
        raise UsageError(str(exc)) from None


def _ball_fmu(args) -> Path:
    """The FMI 3.0 BouncingBall.fmu of ``simulation.master = "event_mode"``, checked (or built) before
    anything is written."""
    from .runner import chosen_ball_fmu

    try:
        return chosen_ball_fmu(args.ball_fmu, rebuild=args.rebuild,
                               log=lambda text: print(text, file=sys.stderr))
    except ValueError as exc:  # --ball-fmu PATH that is not one, or none could be built here
        raise UsageError(str(exc)) from None


def _run(args) -> int:
    require("restitution scene run", {"fmpy": "scene", **({} if args.no_plot else {"matplotlib": "scene"})})
    from .results import DropWriter
    from .runner import SceneInterrupted, run_scene

    scene = load_scene(args.file)
    out = check_output_dir(Path(args.out) if args.out else Path("scene-results") / scene.stem)
    suffix = "_all_on" if args.all_on else ""
    table = out / f"{scene.stem}{suffix}.csv"
    summary = out / f"{scene.stem}{suffix}_summary.csv"
    plot = None if args.no_plot else out / f"{scene.stem}{suffix}.png"
    for path in (table, summary, plot):  # before any work: a regular file or nothing
        if path is not None:
            check_output(path)
    check_outputs({"the drops' table": table, "the summary": summary, "the plot": plot},
                  {"FILE": args.file, "--fmu": args.fmu, "--ball-fmu": args.ball_fmu})
    fmu = _fmu(args)
    ball_fmu = _ball_fmu(args) if scene.simulation.master == "event_mode" else None
    # Each finished drop is on disk (fsynced) before the next starts; the CSV is kept with the drops
    # that finished, whatever stops the run, except on an I/O error (writing it or the summary): then
    # both files that were there before stay as they were.
    with DropWriter(table, scene) as writer:
        try:
            result = run_scene(scene, fmu=fmu, effects="all_on" if args.all_on else "scene",
                               zener_method=args.zener_method, progress=False if args.no_progress else None,
                               on_drop=writer.write, ball_fmu=ball_fmu)
        except SceneInterrupted as exc:
            exc.result.write_summary_csv(summary)
            print(f"interrupted: {len(exc.result.drops)} of {exc.n_drops} drops finished and written to {table} "
                  f"and {summary}; {exc.n_drops - len(exc.result.drops)} drops missing", file=sys.stderr)
            return EXIT_INTERRUPTED
        result.write_summary_csv(summary)
    written = [table, summary]
    if plot is not None:
        try:
            written.append(result.plot(plot))
        except OSError as exc:
            print(f"{PROG}: error: {describe_os_error(exc)}; wrote {table} and {summary}", file=sys.stderr)
            return EXIT_IO_ERROR
    print(result.summary())
    print("wrote " + ", ".join(str(p) for p in written))
    for warning in (result.warning(), *result.departure_warnings(), result.rest_warning()):
        if warning:
            print(warning, file=sys.stderr)
    return EXIT_NOT_AT_REST if result.not_at_rest() else 0


def _report(args) -> int:
    require("restitution scene report", {"fmpy": "scene"})
    from .report import write_report

    methods = [m.strip() for m in args.methods.split(",")] if args.methods else None
    from ..zener import ZENER_METHODS

    for method in methods or ():
        if method not in ZENER_METHODS:
            raise UsageError(f"--methods {args.methods}: {method!r} is not a Zener method ({', '.join(ZENER_METHODS)})")
    for path in args.files:  # every scene loads before any runs
        load_scene(path)
    if args.out is not None:
        check_output(args.out)
        check_outputs({"--out": args.out}, {**{f"FILE {i + 1}": path for i, path in enumerate(args.files)},
                                            "--fmu": args.fmu})
    fmu = _fmu(args)
    reports, table = write_report(args.files, out=args.out, fmu=fmu, repeat=args.repeat, methods=methods,
                                  progress=False if args.no_progress else None,
                                  log=lambda text: print(text, file=sys.stderr))
    print(table)
    if args.out:
        print(f"wrote {args.out}", file=sys.stderr)
    bad = [r.scene.stem for r in reports if not r.within_tolerance]
    if bad:
        print(f"outside the declared tolerance: {', '.join(bad)}", file=sys.stderr)
        return 1
    return 0


def _repeat(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not an integer") from None
    if not 1 <= value <= 1000:
        raise argparse.ArgumentTypeError(f"{value} is out of range: 1 <= value <= 1000")
    return value


def main(argv=None) -> int:
    parser = ArgumentParser(prog=PROG, description=(
        "Drop scenes: balls dropped on plates, described in TOML files and simulated through the FMU."))
    sub = parser.add_subparsers(dest="command", required=True)

    p = sub.add_parser("check", help="load and check scene files")
    p.add_argument("files", nargs="+", type=Path)
    p.set_defaults(func=_check)

    p = sub.add_parser("run", help="simulate one scene through the FMU")
    p.add_argument("file", type=Path)
    p.add_argument("--out", type=Path, default=None, help="output directory (default scene-results/<stem>)")
    p.add_argument("--fmu", type=Path, default=None, help="FMU to use (default: build or reuse dist/)")
    p.add_argument("--ball-fmu", type=Path, default=None,
                   help='FMI 3.0 BouncingBall.fmu for simulation.master = "event_mode" (default: dist/fmi3/)')
    p.add_argument("--rebuild", action="store_true", help="rebuild dist/SpherePlateImpact.fmu first")
    p.add_argument("--all-on", action="store_true", help="every effect on (the reference run)")
    p.add_argument("--zener-method", choices=("exact", "paper_fit", "linear", "ode"), default=None)
    p.add_argument("--no-plot", action="store_true")
    p.add_argument("--no-progress", action="store_true")
    p.set_defaults(func=_run)

    p = sub.add_parser("report", help="auto vs every effect on, as a Markdown table")
    p.add_argument("files", nargs="+", type=Path)
    p.add_argument("--out", type=Path, default=None, help="Markdown file to write or refresh")
    p.add_argument("--fmu", type=Path, default=None)
    p.add_argument("--repeat", type=_repeat, default=3, help="timing repeats (best of N, 1 ... 1000)")
    p.add_argument("--methods", default=None, help="Zener methods to compare (default: the scene's and ode)")
    p.add_argument("--no-progress", action="store_true")
    p.set_defaults(func=_report)

    args = parser.parse_args(argv)
    try:
        status = args.func(args)
    except (SceneError, BuildError, UsageError, OutputPathError, MissingExtra) as exc:
        print(f"{PROG}: error: {exc}", file=sys.stderr)
        return EXIT_REFUSED
    except OSError as exc:  # an I/O error (ENOSPC, EIO, EACCES, ...): nothing half written under an output's name
        print(f"{PROG}: error: {describe_os_error(exc)}", file=sys.stderr)
        return EXIT_IO_ERROR
    except KeyboardInterrupt:  # outside the drops (FMU build or load, report): nothing finished to keep
        print("\ninterrupted", file=sys.stderr)
        status = EXIT_INTERRUPTED
    if status == EXIT_INTERRUPTED:
        from ..cosim.interrupt import forget_unhandled_interrupt

        forget_unhandled_interrupt()
    return status


if __name__ == "__main__":
    sys.exit(main())
