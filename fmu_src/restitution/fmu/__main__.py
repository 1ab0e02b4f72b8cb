"""Command line: ``restitution fmu build [--out DIR] [--python-hosts-only]``; also run as ``python -m restitution.fmu``
and ``restitution-fmu``, which show the same name. It builds every FMU, the native ones for every platform,
with a line per product and platform on stderr as it goes (zig's first use fills its cache: a few
minutes), then a line per FMU built on stdout."""
from __future__ import annotations

import sys
from pathlib import Path

from ..options import ArgumentParser
from .build import FMUS, BuildError, build_all, default_fmu_dir
from .build.progress import stderr_line
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
    args = parser.parse_args(argv)
    out = args.out if args.out is not None else default_fmu_dir()
    try:
        for product in build_all(out, standalone=not args.python_hosts_only, log=stderr_line):
            checked = "fmpy validation: 0 problems" if product.suffix == ".fmu" else check_ssp(product)
            print(f"built {product} ({checked})")
    except (BuildError, ValueError) as exc:
        print(f"{PROG}: error: {exc}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
