"""``restitution fit``: calibrate the model's parameters from a drop test.

    restitution fit DATA --sphere KEY --d LEN --plate KEY --t LEN --fit NAME [--fit NAME ...]
                    [--sphere-material FILE | --sphere-E ... --plate-material FILE | --plate-E ...]
                    [--g ACC] [--h0 LEN] [--json FILE] [--plot FILE] [--times FILE] [--bayes] [--seed N] [--strict]

DATA: a CSV of rebound pairs (``v_in,v_out[,sigma]`` [m/s]) or of one drop's impact times (``t_impact``
[s]), or a WAV recording of the drop (16-bit PCM). Every parameter not fitted is the named materials' and
geometry's. Bad input is one line and exit 2; a missing optional package (emcee for ``--bayes``,
matplotlib for ``--plot``) one line naming the extra, before any work.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..inputs import check_plausible_lengths, input_reading, material_from_args, positive_quantity
from ..options import BARE_NUMBER_RULE, ArgumentParser, add_material_options
from ..units import OptionError
from ..output_files import (EXIT_IO_ERROR, EXIT_REFUSED, OutputPathError, check_output, check_outputs,
                            finish_stdout)

__all__ = ["main"]

PROG = "restitution fit"
#: The formats ``--plot`` writes, by the file's suffix: matplotlib's own backends, no external tool.
PLOT_FORMATS = ("png", "pdf", "svg", "svgz", "eps", "ps")
#: Exit status of ``--strict`` when the model does not describe the data (restitution.fit.goodness).
EXIT_LACK_OF_FIT = 3


def _needs(module: str, extra: str, option: str) -> None:
    from ..extras import MissingExtra, require

    try:
        require(option, {module: extra})
    except MissingExtra as exc:
        raise OptionError(str(exc)) from None


def _parser() -> argparse.ArgumentParser:
    parser = ArgumentParser(prog=PROG, description=__doc__.split("\n\n")[0],
                            formatter_class=argparse.RawDescriptionHelpFormatter,
                            epilog="Lengths take a unit (\"6.35 mm\"). " + BARE_NUMBER_RULE + "\n\n"
                                   "exit status: 0 done (also when lack of fit is detected, unless --strict); "
                                   "2 bad input;\n3 lack of fit detected with --strict; 74 an output "
                                   "could not be written.")
    parser.add_argument("data", help="rebound pairs or impact times (.csv), or a recording (.wav)")
    parser.add_argument("--d", required=True, metavar="LEN", help="sphere diameter, e.g. \"6.35 mm\" (a bare "
                                                                  "number is metres)")
    parser.add_argument("--t", required=True, metavar="LEN", help="plate thickness (a bare number is metres)")
    parser.add_argument("--allow-implausible", action="store_true",
                        help="accept a bare-number length that looks like a slip (a 10 m sphere)")
    parser.add_argument("--fit", required=True, action="append", metavar="NAME", dest="names",
                        help="a parameter to fit: plate.Sy, plate.E, sphere.Sy, sphere.E, plate.t, ... (repeatable)")
    parser.add_argument("--g", default="9.80665 m/s2", metavar="ACC", help="gravity of a drop (default 9.80665 m/s2)")
    parser.add_argument("--h0", metavar="LEN", help="drop height (default: the first impact speed is fitted)")
    parser.add_argument("--json", metavar="FILE", help="write the result as JSON")
    parser.add_argument("--plot", metavar="FILE", help="draw the data and the fit with its 95 %% band (PNG/PDF/SVG)")
    parser.add_argument("--times", metavar="FILE", help="save the impact times found in a recording as a t_impact CSV")
    parser.add_argument("--bayes", action="store_true", help="also sample the posterior (emcee; flat priors over "
                                                             "the physical domain)")
    parser.add_argument("--seed", type=int, default=None, help="seed of the posterior's draws")
    parser.add_argument("--strict", action="store_true", help="exit with status 3 when the lack-of-fit checks "
                                                              "find that the model does not describe the data")
    add_material_options(parser, "sphere")
    add_material_options(parser, "plate")
    return parser


def _prepare(args):
    """Every check before any work: options, outputs, optional packages, the data file."""
    from ..materials import Plate, Sphere
    from .datasets import check_drop, check_drop_speeds
    from .forward import check_names
    from .reading import read_data

    outputs = {"--json": args.json, "--plot": args.plot, "--times": args.times}
    check_outputs(outputs, {"DATA": args.data})  # no output over the data or over another output
    if args.plot and Path(args.plot).suffix.lower().lstrip(".") not in PLOT_FORMATS:
        suffix = f"suffix '{Path(args.plot).suffix}'" if Path(args.plot).suffix else "no suffix"
        raise OptionError(f"--plot {args.plot}: {suffix}: the plot's format is its suffix, one of "
                          f"{', '.join('.' + s for s in PLOT_FORMATS)}")
    for option, path in outputs.items():
        if path:
            check_output(path, option)
    if args.plot:
        _needs("matplotlib", "examples", "--plot")
    if args.bayes:
        _needs("emcee", "fit", "--bayes")
    try:
        names = check_names(args.names)
    except ValueError as exc:
        raise OptionError(f"--fit: {exc}") from None
    d, t = input_reading("d", "sphere.d", args.d), input_reading("t", "plate.t", args.t)
    check_plausible_lengths((f"--d {args.d}", *d), (f"--t {args.t}", *t), allow=args.allow_implausible)
    sphere = Sphere(material_from_args(args, "sphere")[0], d[0])
    plate = Plate(material_from_args(args, "plate")[0], t[0])
    g = positive_quantity("g", args.g, "m/s2", "acceleration")
    h0 = positive_quantity("h0", args.h0, "m", "length") if args.h0 else None
    check_drop(g, h0)
    data = read_data(args.data)
    if data.kind != "rebound_pairs":
        check_drop_speeds(data.times if data.kind == "recording" else data, g)
    if args.times and data.kind != "recording":
        raise OptionError(f"--times: {args.data} is not a recording; the impact times are saved from a .wav")
    return data, sphere, plate, names, g, h0


def _write(args, option: str, write, written: list[str]) -> int:
    """``write(path)`` for the output ``option`` (if asked for): 0, or :data:`EXIT_IO_ERROR` after one
    line naming it, the reason and the outputs already written (``written``, which it joins)."""
    path = getattr(args, option.lstrip("-"))
    if not path:
        return 0
    try:
        write(path)
    except (OSError, OutputPathError) as exc:
        done = f"; written: {', '.join(written)}" if written else ""
        print(f"{PROG}: error: {option}: {exc}{done}", file=sys.stderr)
        return EXIT_IO_ERROR
    written.append(f"{option} {path}")
    return 0


def main(argv=None) -> int:
    args = _parser().parse_args(argv)
    from .datasets import DataError

    written: list[str] = []
    try:
        data, sphere, plate, names, g, h0 = _prepare(args)
        if args.times:
            from .reading import write_times

            status = _write(args, "--times", lambda path: write_times(path, data.times), written)
            status = status or finish_stdout(PROG, f"saved the {data.times.n} impact times found in {args.data} "
                                                   f"to {args.times}")
            if status:
                return status
        from .calibration import fit

        calibration = fit(data, sphere, plate, names, g=g, h0=h0, bayes=args.bayes, seed=args.seed)
    except (OptionError, DataError, OutputPathError, ValueError) as exc:
        print(f"{PROG}: error: {exc}", file=sys.stderr)
        return EXIT_REFUSED
    from . import report

    status = (finish_stdout(PROG, str(calibration))
              or _write(args, "--json", lambda path: report.write_json(path, calibration), written)
              or _write(args, "--plot", lambda path: report.plot(path, calibration), written))
    if status:
        return status
    return EXIT_LACK_OF_FIT if args.strict and calibration.result.lack_of_fit.get("detected") else 0


if __name__ == "__main__":
    sys.exit(main())
