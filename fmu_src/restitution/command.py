"""The ``restitution`` command: every tool of the package under one name.

    restitution cor ...          one COR from the command line (restitution.cor)
    restitution fit ...          calibration from drop tests (restitution.fit)
    restitution sweep ...        design-space sweeps (restitution.sweep; the `sweep` extra)
    restitution scene ...        drop scenes through the FMUs (restitution.scene; the `scene` extra)
    restitution materials        the material presets
    restitution fmu build ...    build the FMUs (restitution.fmu; the `fmu` extra)

Each subcommand is the tool's own command line, and names itself ``restitution X`` in its usage line and
its errors however it is started: ``restitution-sweep``, ``python -m restitution.sweep`` (and the same for
scene, fmu) still run it, as aliases.
"""
from __future__ import annotations

import importlib
import sys

__all__ = ["main", "SUBCOMMANDS"]

#: subcommand -> (module with ``main(argv)``, one line of help)
SUBCOMMANDS = {
    "cor": ("restitution.cor", "one coefficient of restitution, e and what lies behind it"),
    "fit": ("restitution.fit.command", "calibrate parameters from a drop test (rebound pairs, impact times, a recording)"),
    "sweep": ("restitution.sweep.__main__", "design-space sweeps on Dask (grids, random samples)"),
    "scene": ("restitution.scene.__main__", "drop scenes: balls bouncing on plates through the FMUs"),
    "materials": ("restitution.materials_table", "the material presets and their sources"),
    "fmu": ("restitution.fmu.__main__", "build the FMUs (restitution fmu build --out DIR)"),
}


def _usage() -> str:
    width = max(map(len, SUBCOMMANDS))
    lines = ["usage: restitution COMMAND [ARGS...]", "", "The apparent coefficient of restitution of a sphere hitting "
             "a plate of finite thickness (Green 2022).", "", "commands:"]
    lines += [f"  {name:<{width}}  {text}" for name, (_module, text) in SUBCOMMANDS.items()]
    lines += ["", "restitution COMMAND --help shows a command's options."]
    return "\n".join(lines)


def main(argv=None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    if not argv or argv[0] in ("-h", "--help"):
        print(_usage())
        return 0 if argv else 2
    if argv[0] in ("-V", "--version"):
        from .about import VERSION

        print(f"restitution {VERSION}")
        return 0
    name, rest = argv[0], argv[1:]
    if name not in SUBCOMMANDS:
        import difflib

        close = difflib.get_close_matches(name, list(SUBCOMMANDS), n=1)
        hint = f" (did you mean {close[0]}?)" if close else ""
        print(f"restitution: error: unknown command {name!r}{hint}; commands: {', '.join(SUBCOMMANDS)}",
              file=sys.stderr)
        return 2
    module = importlib.import_module(SUBCOMMANDS[name][0])
    try:
        return module.main(rest)
    except BrokenPipeError:  # the reader went away (`restitution cor ... | head -1`): no traceback
        import os

        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141


if __name__ == "__main__":
    sys.exit(main())
