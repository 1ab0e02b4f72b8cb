"""``restitution fit``: calibrate the model's parameters from a drop test.

    restitution fit DATA --sphere KEY --d LEN --plate KEY --t LEN --fit NAME [--fit NAME ...]
                    [--g ACC] [--h0 LEN] [--json FILE] [--plot FILE] [--times FILE] [--bayes] [--seed N]

DATA: a CSV of rebound pairs (``v_in,v_out[,sigma]`` [m/s]) or of one drop's impact times (``t_impact``
[s]), or a WAV recording of the drop (16-bit PCM). Every parameter not fitted is the named materials' and
geometry's. Bad input is one line and exit 2; a missing optional package (emcee for ``--bayes``,
matplotlib for ``--plot``) one line naming the extra, before any work.
"""
from __future__ import annotations

import argparse
import sys

from ..options import OptionError, input_quantity, material, positive_quantity
from ..output_files import EXIT_IO_ERROR, EXIT_REFUSED, OutputPathError, check_output

__all__ = ["main"]

PROG = "restitution fit"


def _needs(module: str, extra: str, option: str) -> None:
    from ..extras import MissingExtra, require

    try:
        require(option, {module: extra})
    except MissingExtra as exc:
        raise OptionError(str(exc)) from None


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog=PROG, description=__doc__.split("\n\n")[0],
                                     epilog="Lengths take a unit (\"6.35 mm\"); a bare number is SI.")
    parser.add_argument("data", help="rebound pairs or impact times (.csv), or a recording (.wav)")
    parser.add_argument("--sphere", required=True, metavar="KEY", help="sphere material (restitution materials)")
    parser.add_argument("--d", required=True, metavar="LEN", help="sphere diameter, e.g. \"6.35 mm\"")
    parser.add_argument("--plate", required=True, metavar="KEY", help="plate material")
    parser.add_argument("--t", required=True, metavar="LEN", help="plate thickness")
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
    return parser


def _prepare(args):
    """Every check before any work: options, outputs, optional packages, the data file."""
    from ..materials import Plate, Sphere
    from .forward import check_names
    from .reading import read_data

    for option, path in (("--json", args.json), ("--plot", args.plot), ("--times", args.times)):
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
    sphere = Sphere(material("sphere", args.sphere), input_quantity("d", "sphere.d", args.d))
    plate = Plate(material("plate", args.plate), input_quantity("t", "plate.t", args.t))
    g = positive_quantity("g", args.g, "m/s2", "acceleration")
    h0 = positive_quantity("h0", args.h0, "m", "length") if args.h0 else None
    data = read_data(args.data)
    if args.times and data.kind != "recording":
        raise OptionError(f"--times: {args.data} is not a recording; the impact times are saved from a .wav")
    return data, sphere, plate, names, g, h0


def main(argv=None) -> int:
    args = _parser().parse_args(argv)
    from .datasets import DataError

    try:
        data, sphere, plate, names, g, h0 = _prepare(args)
        if args.times:
            from .reading import write_times

            write_times(args.times, data.times)
            print(f"saved the {data.times.n} impact times found in {args.data} to {args.times}")
        from .calibration import fit

        calibration = fit(data, sphere, plate, names, g=g, h0=h0, bayes=args.bayes, seed=args.seed)
    except (OptionError, DataError, OutputPathError, ValueError) as exc:
        print(f"{PROG}: error: {exc}", file=sys.stderr)
        return EXIT_REFUSED
    print(calibration)
    from . import report

    try:
        if args.json:
            report.write_json(args.json, calibration)
        if args.plot:
            report.plot(args.plot, calibration)
    except OSError as exc:
        print(f"{PROG}: error: {exc}", file=sys.stderr)
        return EXIT_IO_ERROR
    return 0


if __name__ == "__main__":
    sys.exit(main())
