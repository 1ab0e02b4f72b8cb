"""``restitution cor``: one coefficient of restitution, from the command line.

    restitution cor --sphere chrome_steel --d "6.35 mm" --plate al_6061 --t "3 mm" --v "2 m/s" [--edge LEN] [--json FILE]

prints e and what lies behind it (e_ep, e_ze, v_rebound, V*, lambda, the contact time, the validity
flags and the monitors of the model's assumptions, docs/assumptions.md), each with its unit. ``--edge``:
the distance from the impact point to the plate's nearest edge (default: an unbounded plate). Lengths and the speed take any unit (a bare number is SI); a value outside
the model's domain (the ranges the FMUs declare) is refused in one line naming the quantity, with the
likely slip ("did you mean 3 mm?"); an unknown material names the close ones. ``--json FILE`` writes the
inputs and every field of the result in SI units.
"""
from __future__ import annotations

import json
import math
import sys

from .assumptions import E_NEGATIVE_MEANING, VALID_MEANING
from .fmu.models.sphere_plate_impact.variables import TABLE
from .model import ZENER_METHODS, impact, published
from .zener import WAVE_DELAY_LIMIT
from .inputs import IMPACT_QUANTITIES, impact_inputs, material_from_args
from .options import BARE_NUMBER_RULE, ArgumentParser, add_impact_options
from .units import OptionError
from .output_files import (EXIT_IO_ERROR, EXIT_REFUSED, OutputPathError, atomic_write, check_output,
                           finish_stdout)

__all__ = ["main", "evaluate"]

#: The options with a unit: option -> (FMU input name whose unit and range apply, impact keyword).
QUANTITIES = IMPACT_QUANTITIES
#: The result's numeric fields, in the order the JSON lists their units.
_FIELDS = ("e", "e_ep", "e_ze", "v_rebound", "V_c", "V_star", "eps_y", "lam", "tau0", "T", "t_contact", "m_a", "m_eff",
           "mass_ratio", "v_plate", "wave_delay", "edge_echo")
#: The units of the fields the FMUs do not publish; the interface table carries the others'.
_UNPUBLISHED_UNITS = {"eps_y": "1", "T": "s", "m_eff": "kg"}
_TABLE_UNITS = {row.key: row.unit for row in TABLE.rows if row.causality == "output" and row.unit}
#: Units of the result's fields, as printed and in the JSON (SI).
UNITS = {name: _TABLE_UNITS.get(name) or _UNPUBLISHED_UNITS[name] for name in _FIELDS}


def evaluate(sphere, d, plate, t, v, zener_method: str = "exact", edge=None,
             allow_implausible: bool = True) -> tuple[dict, dict]:
    """(inputs in SI, the published result as a dict) for the materials ``sphere`` and ``plate`` (a
    preset's name or a :class:`~restitution.Material`), the diameter ``d``, the thickness ``t``, the
    approach speed ``v`` and the edge distance ``edge`` (each a number in SI or a text with its unit;
    ``edge`` None or 0: an unbounded plate). Without ``allow_implausible`` a bare-number length that is
    a likely slip is refused (:func:`~restitution.inputs.check_plausible_lengths`).
    :class:`~restitution.units.OptionError` (one line) for an unknown material or a value outside the domain."""
    v, params = impact_inputs(sphere, d, plate, t, v, edge, allow_implausible)
    result = published(impact(v, **params, zener_method=zener_method).as_dict())
    inputs = {"sphere": sphere if isinstance(sphere, str) else sphere.name,
              "plate": plate if isinstance(plate, str) else plate.name,
              "v": v, **params, "zener_method": zener_method}
    return inputs, {key: (bool(value) if isinstance(value, bool) or key not in UNITS else float(value))
                    for key, value in result.items()}


def _line(name: str, value: float, what: str) -> str:
    unit = UNITS[name]
    return f"  {name} = {value:.6g}{'' if unit == '1' else ' ' + unit}  {what}"


def report(inputs: dict, r: dict) -> str:
    """What the command prints: e first, then its parts, the rebound and the validity, with what ``valid``
    means and, where e < 0, what that means (``e_negative``; the words of :mod:`restitution.assumptions`)."""
    yes = {True: "yes", False: "no"}
    return "\n".join([
        f"e = {r['e']:.4f}  apparent COR of {inputs['sphere']} (d = {inputs['sphere_d'] * 1e3:.6g} mm) on "
        f"{inputs['plate']} (t = {inputs['plate_t'] * 1e3:.6g} mm) at {inputs['v']:.6g} m/s (Eq. 20)",
        _line("e_ep", r["e_ep"], "elastoplastic COR, JGM (Eq. 7/8)"),
        _line("e_ze", r["e_ze"], "plate-wave COR, Zener (Eqs. 9-13a)"),
        _line("v_rebound", r["v_rebound"], "rebound speed, e v" + (" (below 0: e < 0, see e_negative)"
                                                                   if r["e_negative"] else "")),
        _line("V_star", r["V_star"], f"impact speed over the critical speed V_c = {r['V_c']:.4g} m/s (Eq. 6)"),
        _line("lam", r["lam"], "Zener's inelasticity parameter lambda (Eq. 12)"),
        _line("t_contact", r["t_contact"], "contact duration"),
        f"  valid = {yes[r['valid']]}  (lambda <= 1.5: {yes[r['lambda_in_range']]}, V* <= 1000: "
        f"{yes[r['vstar_in_range']]}, e < 0: {yes[r['e_negative']]})",
        f"    valid: {VALID_MEANING}",
        *([f"  e_negative = yes  e < 0: {E_NEGATIVE_MEANING}"] if r["e_negative"] else []),
        f"  wave_delay = {r['wave_delay']:.6g}  contact time over its half-space value, tau0(lambda)/tau0(0); "
        f"concurrent (<= {WAVE_DELAY_LIMIT}): {yes[r['concurrent']]}",
        (f"  edge_echo = {r['edge_echo']:.6g}  first edge echo (2 a/c_L, a = {inputs['plate_edge_distance'] * 1e3:.6g} "
         f"mm) over the contact time; edge_clear (>= 1): {yes[r['edge_clear']]}"
         if inputs["plate_edge_distance"] > 0.0 else "  edge_echo: an unbounded plate (give --edge LEN for the "
                                                     "edge monitor)"),
    ])


def main(argv=None) -> int:
    parser = ArgumentParser(prog="restitution cor", description=__doc__.split("\n\n")[0],
                            epilog="Lengths and speeds take a unit (\"6.35 mm\", \"1/4 in\", \"2 m/s\"). "
                                   + BARE_NUMBER_RULE)
    parser.add_argument("--zener-method", default="exact", choices=ZENER_METHODS,
                        help="Zener's COR and contact time (default: exact)")
    parser.add_argument("--json", metavar="FILE", help="write the inputs and every field of the result (SI)")
    add_impact_options(parser)
    args = parser.parse_args(argv)
    try:
        if args.json:
            check_output(args.json, "--json")
        (sphere, sphere_label), (plate, plate_label) = (material_from_args(args, role) for role in ("sphere", "plate"))
        inputs, result = evaluate(sphere, args.d, plate, args.t, args.v, args.zener_method, args.edge,
                                  allow_implausible=args.allow_implausible)
        inputs.update(sphere=sphere_label, plate=plate_label)
    except (OptionError, OutputPathError) as exc:
        print(f"restitution cor: error: {exc}", file=sys.stderr)
        return EXIT_REFUSED
    status = finish_stdout("restitution cor", report(inputs, result))
    if status:
        return status
    if args.json:
        finite = {key: (None if isinstance(value, float) and not math.isfinite(value) else value)
                  for key, value in result.items()}  # m_eff = +inf for a half-space: null, JSON has no inf
        text = json.dumps({"inputs": inputs, "result": finite, "units": UNITS}, indent=1, allow_nan=False)
        try:
            atomic_write(args.json, lambda tmp: tmp.write_text(text + "\n", encoding="utf-8"), "--json")
        except (OSError, OutputPathError) as exc:
            print(f"restitution cor: error: --json: {exc}", file=sys.stderr)
            return EXIT_IO_ERROR
    return 0


if __name__ == "__main__":
    sys.exit(main())
