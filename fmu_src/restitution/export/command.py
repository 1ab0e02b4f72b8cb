"""``restitution export HOST``: the COR of one sphere, plate and speed as a host's own contact parameters.

    restitution export mujoco --sphere chrome_steel --d "6.35 mm" --plate al_6061 --t "3 mm" --v "2 m/s" \\
        [--v-range LO HI --points N] [--json FILE] [--verify [--tolerance 0.01]] [--dt STEP] [--allow-invalid]
    restitution export table ... --v-range "0.1 m/s" "5 m/s" --points 50 [--format csv|json|solfec] [--out FILE]

HOST: mujoco, chrono, liggghts, yade, elastogap or table. Prints a snippet in the host's syntax (per speed
over a range); ``--json FILE`` writes the host's parameters (docs/exports.md gives each host's contract).
``--verify`` re-simulates a drop with the host's contact (MuJoCo itself where installed, else the host's
published force law integrated here, said so) and exits 1 when its e misses the model's by more than
``--tolerance``; ``--dt`` tells the e a run at that step gets and warns when the step is coarse for the contact.
An e < 0 or an impact outside the model's validated range is exported only with ``--allow-invalid``.
"""
from __future__ import annotations

import json
import math
import sys

from ..model import ZENER_METHODS
from ..inputs import impact_inputs, input_reading, material_from_args
from ..options import BARE_NUMBER_RULE, ArgumentParser, add_impact_options
from ..units import OptionError, echo, read_quantity
from ..output_files import (EXIT_IO_ERROR, EXIT_REFUSED, OutputPathError, atomic_write, check_output, check_outputs,
                            finish_stdout)
from .hosts import HOST_MODULES, HOSTS, export_case, finite_or_none, host_module
from . import table as table_module

__all__ = ["main", "EXIT_MISSED"]

PROG = "restitution export"
#: Exit status of --verify when the host's e misses the model's by more than --tolerance.
EXIT_MISSED = 1
#: Steps per contact below which --dt is called coarse where a host names no step of its own.
COARSE_STEPS = 50


def _parser() -> ArgumentParser:
    parser = ArgumentParser(prog=PROG, description=__doc__.split("\n\n")[0],
                            epilog="Lengths, speeds and steps take a unit (\"6.35 mm\", \"2 m/s\", \"1 us\"). "
                                   + BARE_NUMBER_RULE)
    parser.add_argument("host", metavar="HOST", help=f"one of {', '.join(HOSTS)}")
    add_impact_options(parser, speed_required=False)
    parser.add_argument("--zener-method", default="exact", choices=ZENER_METHODS,
                        help="Zener's COR and contact time (default: exact)")
    parser.add_argument("--v-range", nargs=2, metavar=("LO", "HI"), help="a speed range instead of --v, e.g. "
                        "\"0.1 m/s\" \"5 m/s\": parameters per speed")
    parser.add_argument("--points", type=int, default=11, help="speeds in --v-range, evenly spaced (default 11)")
    parser.add_argument("--format", default="csv", choices=table_module.FORMATS,
                        help="table only: csv, json or solfec ([vel0, res0, vel1, res1, ...]); default csv")
    parser.add_argument("--out", metavar="FILE", help="table only: write the table there instead of printing it")
    parser.add_argument("--json", metavar="FILE", help="write the host's parameters (SI) as JSON")
    parser.add_argument("--verify", action="store_true", help="re-simulate a drop with the host's contact and "
                        "compare its e with the model's (exit 1 beyond --tolerance)")
    parser.add_argument("--tolerance", type=float, default=0.01, help="relative error --verify accepts "
                        "(default 0.01: 1 %%)")
    parser.add_argument("--dt", metavar="STEP", help="your simulation's time step, e.g. \"1 us\": the e you get "
                        "at that step, and a warning where it is coarse for the contact; mujoco's solref and solimp "
                        "are tuned for it (default t_contact/50)")
    parser.add_argument("--allow-invalid", action="store_true", help="export an e < 0 or an impact outside the "
                        "model's validated range (said in the output)")
    return parser


def _speeds(args) -> list[float]:
    """The speeds [m/s] of --v or --v-range (OptionError: neither, both, or a range in the wrong order)."""
    if (args.v is None) == (args.v_range is None):
        raise OptionError("give one of --v SPEED and --v-range LO HI")
    if args.v is not None:
        return [input_reading("v", "v_approach", args.v)[0]]
    low, high = (input_reading("v-range", "v_approach", text)[0] for text in args.v_range)
    if not high > low:
        raise OptionError(f"--v-range {echo(args.v_range[0])} {echo(args.v_range[1])}: the second speed must be "
                          f"above the first")
    try:
        return [float(v) for v in table_module.speeds(low, high, args.points)]
    except ValueError as exc:
        raise OptionError(str(exc)) from None


def _read(args):
    """(speeds [m/s], impact keyword arguments (SI), the user's step [s] or None, inputs for the JSON)."""
    if args.host not in HOSTS:
        raise OptionError(f"unknown host '{echo(args.host)}'; hosts: {', '.join(HOSTS)}")
    if not (args.tolerance > 0.0 and math.isfinite(args.tolerance)):
        raise OptionError(f"--tolerance {args.tolerance:g}: a relative error > 0, e.g. 0.01")
    check_outputs({"--json": args.json, "--out": args.out},
                  {"--sphere-material": args.sphere_material, "--plate-material": args.plate_material})
    for option, path in (("--json", args.json), ("--out", args.out)):
        if path:
            check_output(path, option)
    (sphere, sphere_label), (plate, plate_label) = (material_from_args(args, role) for role in ("sphere", "plate"))
    _, params = impact_inputs(sphere, args.d, plate, args.t, None, args.edge, args.allow_implausible)
    dt = read_quantity("--dt", args.dt, "s", "time") if args.dt is not None else None
    if dt is not None and not dt > 0.0:
        raise OptionError(f"--dt {echo(args.dt)}: a step > 0 s")
    inputs = {"host": args.host, "sphere": sphere_label, "plate": plate_label, **params}
    return _speeds(args), (sphere, plate, params), dt, inputs


def _refuse_invalid(reasons: list[str], allow: bool) -> list[str]:
    """The notes to print for impacts outside validity; OptionError unless ``allow``."""
    if reasons and not allow:
        raise OptionError(f"{reasons[0]}; --allow-invalid exports it anyway")
    return [f"note: exported with --allow-invalid: {reason}" for reason in dict.fromkeys(reasons)]


def _check(result: dict, case, params: dict, dt: float | None, tolerance: float) -> tuple[list[str], bool]:
    """(the lines of one drop's report, whether its e is within ``tolerance`` of the model's)."""
    error = result["e"] / case.e - 1.0 if case.e else math.inf
    step = "finely resolved contact" if dt is None else f"dt = {dt:.4g} s ({case.t_contact / dt:.4g} steps a contact)"
    lines = [f"  drop ({result['law']}, {step}): e = {result['e']:.5g}, model e = {case.e:.5g}, error "
             f"{100 * error:+.3g} %; host contact time {result['t_contact']:.4g} s (model {case.t_contact:.4g} s)"]
    if "e_range" in result:
        low, high = result["e_range"]
        lines.append(f"    wherever the contact begins inside a step: e from {low:.5g} to {high:.5g} "
                     f"({100 * (low / case.e - 1):+.3g} % to {100 * (high / case.e - 1):+.3g} %)")
    limit = params.get("timestep", case.t_contact / COARSE_STEPS)
    if dt is not None and not dt <= limit:  # NaN: no step of the host's tuning holds
        holds = f"holds to 1 % at dt <= {limit:.4g} s" if limit == limit else "does not hold to 1 % at this step"
        lines.append(f"  warning: dt = {dt:.4g} s is coarse for this contact ({case.t_contact:.4g} s): the mapping "
                     f"{holds}")
    worst = max([abs(error)] + [abs(x / case.e - 1.0) for x in result.get("e_range", ())])
    return lines, worst <= tolerance


def _export_host(args, speeds, pair, dt, inputs) -> tuple[str, dict, bool]:
    """(the text to print, the JSON, whether every --verify passed) of a host module."""
    try:
        module = host_module(args.host)
    except ModuleNotFoundError as exc:
        if exc.name != HOST_MODULES[args.host]:
            raise
        raise OptionError(f"host '{args.host}': its export is not in this build of restitution") from None
    sphere, plate, params = pair
    entries, lines, reasons, passed = [], [], [], True
    for v in speeds:
        case = export_case(v, sphere, plate, params["sphere_d"], params["plate_t"], params["plate_edge_distance"],
                           zener_method=args.zener_method)
        reason = case.refusal()
        if reason:
            reasons.append(f"at {v:.6g} m/s: {reason}")
            if not args.allow_invalid:
                break
        try:
            host = module.parameters(case, dt) if getattr(module, "TUNES_TO_STEP", False) else module.parameters(case)
        except ValueError as exc:  # a COR the host's contact cannot give (e < 0), even with --allow-invalid
            if len(speeds) == 1:
                raise OptionError(f"at {v:.6g} m/s: {exc}") from None
            lines.append(f"# v = {v:.6g} m/s: left out, {exc}")
            continue
        entry = {**host, "flags": case.flags()}
        lines += ([f"# v = {v:.6g} m/s"] if len(speeds) > 1 else []) + [module.snippet(host)]
        for step in ([None] if args.verify else []) + ([dt] if dt is not None else []):
            result = module.simulate_drop(host, case, step)
            report, ok = _check(result, case, host, step, args.tolerance)
            if step is None and host.get("holds_at_finer_steps") is False:  # tuned for a coarse --dt alone
                report.append("    (the parameters are tuned for --dt alone: finer steps are not expected to hold)")
                ok = True
            lines += report
            passed = passed and (ok or not args.verify)
            entry.setdefault("verify", []).append({**result, "dt": step, "error": result["e"] / case.e - 1.0})
        entries.append(entry)
    notes = _refuse_invalid(reasons, args.allow_invalid)
    if not entries:
        raise OptionError("no speed of the range has a COR the host's contact can give (e < 0 at every one)")
    document = {"inputs": inputs, **entries[0]} if len(speeds) == 1 else {"inputs": inputs, "speeds": entries}
    if notes:
        document["allow_invalid"] = notes
    return "\n".join(notes + lines), document, passed


def _export_table(args, speeds, pair, inputs) -> tuple[str, dict]:
    _sphere, _plate, params = pair
    columns = table_module.table(speeds, params, zener_method=args.zener_method)
    reasons = [f"at {v:.6g} m/s: e = {e:.4g} < 0" if e < 0 else f"at {v:.6g} m/s: outside the model's validated "
               f"range" for v, e, ok in zip(columns["v"], columns["e"], columns["valid"]) if e < 0 or not ok]
    notes = _refuse_invalid(reasons, args.allow_invalid)
    for note in notes[:1]:
        print(note, file=sys.stderr)
    return table_module.render(columns, args.format), {"inputs": inputs, **columns}


def _write(path, text: str, option: str) -> None:
    atomic_write(path, lambda tmp: tmp.write_text(text + "\n", encoding="utf-8"), option)


def main(argv=None) -> int:
    args = _parser().parse_args(argv)
    passed = True
    try:
        speeds, pair, dt, inputs = _read(args)
        if args.host == "table":
            text, document = _export_table(args, speeds, pair, inputs)
        else:
            if args.host not in HOST_MODULES:
                raise OptionError(f"unknown host '{echo(args.host)}'")
            text, document, passed = _export_host(args, speeds, pair, dt, inputs)
    except (OptionError, OutputPathError) as exc:
        print(f"{PROG}: error: {exc}", file=sys.stderr)
        return EXIT_REFUSED
    try:
        if args.out:
            _write(args.out, text, "--out")
        if args.json:
            clean = json.loads(json.dumps(document, default=finite_or_none), parse_constant=lambda _c: None)
            _write(args.json, json.dumps(clean, indent=1, allow_nan=False), "--json")
    except (OSError, OutputPathError) as exc:
        print(f"{PROG}: error: {exc}", file=sys.stderr)
        return EXIT_IO_ERROR
    if not args.out:
        status = finish_stdout(PROG, text)
        if status:
            return status
    return 0 if passed else EXIT_MISSED
