"""Command line: ``restitution fmu build [--out DIR] [--python-hosts-only]``; also run as ``python -m restitution.fmu``
and ``restitution-fmu``, which show the same name. It builds every FMU, the native ones for every platform,
with a line per product and platform on stderr as it goes (zig's first use fills its cache: a few
minutes), then a line per FMU built on stdout."""
from __future__ import annotations

import sys
from pathlib import Path

from ..options import ArgumentParser
from .builders import FMUS, BuildError, build_all, default_fmu_dir
from .builders.progress import stderr_line
from .ssp.check import check_ssp

#: The command's name in its usage line and its errors, however it was started.
PROG = "restitution fmu"


def main(argv=None) -> int:
    parser = ArgumentParser(prog=PROG,
                                     description="Build and validate the project's FMUs.")
    commands = parser.add_subparsers(dest="command", required=True)
    build = commands.add_parser("build", help=f"build {', '.join(f'{m}.fmu' for m in FMUS)} (pythonfmu) and their "
                                              "native FMI 2.0 and 3.0 twins, for every platform, and the SSPs of the native pair "
                                              "(ssp/BallOnPlate.ssp: SSP 1.0, FMI 2.0; ssp/BallOnPlate-SSP2.ssp: SSP 2.0, FMI 3.0)")
    build.add_argument("--out", type=Path, default=None,
                       help=f"output directory (default: {default_fmu_dir()})")
    build.add_argument("--python-hosts-only", action="store_true",
                       help="skip the pythonfmu guard (the C checks of every FMI call, and the loader for plain C hosts; the FMUs then need a Python host)")
    compat = commands.add_parser("compat", help="write the compatibility information of the native FMUs (FMI "
                                                 "Cross-Check format: FMU, _in.csv, _ref.csv, _ref.opt, ReadMe.txt "
                                                 "per model, FMI version and interface) into --out")
    compat.add_argument("--out", type=Path, required=True, help="output directory (DIR/fmus/...)")
    compat.add_argument("--fmus", type=Path, default=None,
                        help=f"where the built FMUs are, fmi2/ and fmi3/ (default: {default_fmu_dir()})")
    args = parser.parse_args(argv)
    if args.command == "compat":
        return _compat(args)
    out = args.out if args.out is not None else default_fmu_dir()
    try:
        for product in build_all(out, standalone=not args.python_hosts_only, log=stderr_line):
            checked = "fmpy validation: 0 problems" if product.suffix == ".fmu" else check_ssp(product)
            print(f"built {product} ({checked})")
    except (BuildError, ValueError) as exc:
        print(f"{PROG}: error: {exc}", file=sys.stderr)
        return 2
    return 0


def _compat(args) -> int:
    """``restitution fmu compat``: one line per model folder written; one line on stderr and exit 2 on error."""
    from ..output_files import OutputPathError
    from .compat import write_compat

    try:
        for folder in write_compat(args.out, args.fmus if args.fmus is not None else default_fmu_dir()):
            print(f"wrote {folder}")
    except (FileNotFoundError, OutputPathError, OSError) as exc:
        print(f"{PROG}: error: {exc}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
