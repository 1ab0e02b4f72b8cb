"""The ``restitution`` command: every tool of the package under one name.

    restitution cor ...          one COR from the command line (restitution.cor)
    restitution fit ...          calibration from drop tests (restitution.fit)
    restitution sweep ...        design-space sweeps (restitution.sweep; the `sweep` extra)
    restitution scene ...        drop scenes through the FMUs (restitution.scene; the `scene` extra)
    restitution materials        the material presets
    restitution fmu build ...    build the FMUs (restitution.fmu; the `fmu` extra)
    restitution export HOST ...  the COR as a host simulator's parameters (restitution.export)

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
    "export": ("restitution.export.command", "the COR as another simulator's contact parameters (MuJoCo, Chrono, "
                                             "LIGGGHTS, Yade, ElastoGap, a table), verified by a drop"),
}


def _usage() -> str:
    width = max(map(len, SUBCOMMANDS))
    lines = ["usage: restitution COMMAND [ARGS...]", "", "The apparent coefficient of restitution of a sphere hitting "
             "a plate of finite thickness (Green 2022).", "", "commands:"]
    lines += [f"  {name:<{width}}  {text}" for name, (_module, text) in SUBCOMMANDS.items()]
    lines += ["", "restitution COMMAND --help shows a command's options."]
    return "\n".join(lines)


def _run(argv: list[str]) -> int:
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

        from .units import echo

        close = difflib.get_close_matches(name, list(SUBCOMMANDS), n=1) if len(name) <= 40 else []
        hint = f" (did you mean {close[0]}?)" if close else ""
        print(f"restitution: error: unknown command '{echo(name)}'{hint}; commands: {', '.join(SUBCOMMANDS)}",
              file=sys.stderr)
        return 2
    module = importlib.import_module(SUBCOMMANDS[name][0])
    return module.main(rest)


def main(argv=None) -> int:
    """Run ``restitution COMMAND ...``; its exit status. What a command printed is flushed here, inside the
    command's lifetime: standard output that cannot be written (a full disk, a closed pipe) is one line and
    exit 74, or a quiet 141 where the reader went away, never a traceback or an exit 0 with the output lost
    (argparse's --help, and print() in the tools, leave the flush to the interpreter's exit)."""
    from .output_files import EXIT_IO_ERROR, finish_stdout, os_reason, silence_stdout

    argv = list(sys.argv[1:] if argv is None else argv)
    prog = f"restitution {argv[0]}" if argv and argv[0] in SUBCOMMANDS else "restitution"
    try:
        status = _run(argv)
    except SystemExit as exc:  # argparse: --help (0), a refused option (2, its message already on stderr)
        status = exc.code
    except BrokenPipeError:  # the reader went away (`restitution cor ... | head -1`): no traceback
        silence_stdout()
        return 141
    except OSError as exc:  # writing the output failed where the tool did not catch it
        silence_stdout()
        print(f"{prog}: error: cannot write: {os_reason(exc)}", file=sys.stderr, flush=True)
        return EXIT_IO_ERROR
    return finish_stdout(prog) or status


if __name__ == "__main__":
    sys.exit(main())
