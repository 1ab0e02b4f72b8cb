"""Command line: ``restitution fmu build [--out DIR] [--python-hosts-only]``, ``restitution fmu path MODEL
[--fmi 2|3] [--implementation native|pythonfmu]``, ``restitution fmu copy --out DIR`` and ``restitution fmu
compat --out DIR [--fmus DIR]``; also run as
``python -m restitution.fmu`` and ``restitution-fmu``, which show the same name.

``build`` builds every FMU, the native ones for every platform, with a line per product and platform on
stderr as it goes (zig's first use fills its cache: a few minutes), then a line per FMU built on stdout.
``path`` prints the path of an FMU a wheel installed, ``copy`` copies all of them out (no compiler involved;
:mod:`restitution.fmu.installed`)."""
from __future__ import annotations

import sys
from pathlib import Path

from ..options import ArgumentParser
from ..output_files import OutputPathError, OutputWriteError
from .builders import FMUS, BuildError, build_all, default_fmu_dir
from .builders.progress import stderr_line
from .installed import FMI_VERSIONS, IMPLEMENTATIONS, NotInstalled, copy, path
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
    where = commands.add_parser("path", help="print the path of an installed FMU (a wheel carries them built)")
    where.add_argument("model", choices=sorted(FMUS), help="the model")
    where.add_argument("--fmi", choices=FMI_VERSIONS, default="2", help="FMI version (default 2)")
    where.add_argument("--implementation", choices=IMPLEMENTATIONS, default=None,
                       help="pythonfmu (FMI 2 only) or native (default: pythonfmu for FMI 2, native for FMI 3)")
    out_of = commands.add_parser("copy", help="copy every installed FMU (and SSP file) into a directory")
    out_of.add_argument("--out", type=Path, required=True, help="output directory (created where missing)")
    args = parser.parse_args(argv)
    if args.command == "compat":
        return _compat(args)
    if args.command == "path":
        return _installed(lambda: print(path(args.model, args.fmi, args.implementation)))
    if args.command == "copy":
        return _installed(lambda: [print(f"copied {target}") for target in copy(args.out)])
    out = args.out if args.out is not None else default_fmu_dir()
    try:
        for product in build_all(out, guard=not args.python_hosts_only, log=stderr_line):
            checked = "fmpy validation: 0 problems" if product.suffix == ".fmu" else check_ssp(product)
            print(f"built {product} ({checked})")
    except (BuildError, ValueError) as exc:
        print(f"{PROG}: error: {exc}", file=sys.stderr)
        return 2
    return 0


def _compat(args) -> int:
    """``restitution fmu compat``: one line per model folder written; one line on stderr and exit 2 on error."""
    from .compat import write_compat

    try:
        for folder in write_compat(args.out, args.fmus if args.fmus is not None else default_fmu_dir()):
            print(f"wrote {folder}")
    except (FileNotFoundError, OutputPathError, OSError) as exc:
        print(f"{PROG}: error: {exc}", file=sys.stderr)
        return 2
    return 0


def _installed(action) -> int:
    """``action()``; a reason it cannot be done as one line on stderr and exit 2."""
    try:
        action()
    except (NotInstalled, ValueError, OutputPathError, OutputWriteError) as exc:
        print(f"{PROG}: error: {exc.args[0] if isinstance(exc, NotInstalled) else exc}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
