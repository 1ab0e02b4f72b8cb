"""Quickstart: drop an S2 tool-steel ball on an Al 6061 plate through SpherePlateImpact.fmu.

    python examples/quickstart_bounce.py [--fmu dist/SpherePlateImpact.fmu] [--height 0.3]
    python examples/quickstart_bounce.py --sphere chrome_steel --d "4.76 mm" --plate brass_260 --t "3 mm"

Uses the event-exact fmpy master (restitution.cosim.bouncing) and prints the first bounces. Without
--fmu it uses dist/SpherePlateImpact.fmu (outside a checkout, ~/.cache/restitution/fmus/), building and
validating it first when it is missing or was built from other sources: that FMU alone, the pythonfmu one,
in seconds (`restitution fmu build` builds every FMU, the native ones for every platform: minutes).
``--sphere``, ``--d``, ``--plate`` and ``--t`` choose another case, as ``restitution cor`` reads them: a
preset's name (``restitution materials``), a length with any unit (a bare number is SI); the defaults are
the case above (d = t = 6.35 mm).
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import restitution as r
from restitution.cosim import FmuInstance, bounce, fmu_rebound, impact_fmu_parameters
from restitution.fmu import default_fmu
from restitution.inputs import input_quantity, material
from restitution.units import OptionError

#: The default case: an S2 tool-steel ball, d = 6.35 mm, on Al 6061, t = 6.35 mm.
SPHERE, D, PLATE, T = "s2_tool_steel", 6.35e-3, "al_6061", 6.35e-3
#: How the text names a material (else the preset's own name).
SHORT_NAMES = {"s2_tool_steel": "S2 tool-steel", "al_6061": "Al 6061"}


def short_name(key: str) -> str:
    return SHORT_NAMES.get(key, r.MATERIALS[key].name)


def run(fmu_path=None, height: float = 0.3, thickness: float = T, show: int = 5, sphere: str = SPHERE,
        d: float = D, plate: str = PLATE):
    """Bounce the ball (preset ``sphere``, diameter ``d`` [m]) on the plate (preset ``plate``, thickness
    ``thickness`` [m]); return the :class:`~restitution.cosim.Bounces` record."""
    if fmu_path is None:
        fmu_path = default_fmu(log=lambda message: print(message, file=sys.stderr, flush=True), scope="model")
        print(f"FMU: {fmu_path} (built from the installed sources; `restitution fmu build` rebuilds every FMU)")
    fmu_path = Path(fmu_path)
    ball = r.Sphere(r.MATERIALS[sphere], d)
    sheet = r.Plate(r.MATERIALS[plate], thickness)
    with FmuInstance(fmu_path, parameters=impact_fmu_parameters(ball, sheet)) as fmu:
        bounces = bounce(fmu_rebound(fmu), drop_height=height)
    print(f"{short_name(sphere)} ball (d = {d * 1e3:g} mm) dropped from {height} m on {short_name(plate)}, "
          f"t = {thickness * 1e3:.2f} mm")
    print(f"{'#':>3} {'t [s]':>9} {'v [m/s]':>8} {'e':>7} {'e_ep':>7} {'e_ze':>7} {'t_c [us]':>9}")
    for i in range(min(show, bounces.n_impacts)):
        print(f"{i + 1:>3} {bounces.time[i]:9.5f} {bounces.v_approach[i]:8.4f} {bounces.e[i]:7.4f} "
              f"{bounces.e_ep[i]:7.4f} {bounces.e_ze[i]:7.4f} {bounces.t_contact[i] * 1e6:9.2f}")
    print(f"{bounces.n_impacts} impacts; at rest at t = {bounces.rest_time:.4f} s ({bounces.why_stopped})")
    return bounces


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     epilog="Lengths take a unit (\"6.35 mm\", \"1/4 in\"); a bare number is SI.")
    parser.add_argument("--fmu", type=Path, default=None, help="SpherePlateImpact.fmu (default: dist/, built if missing)")
    parser.add_argument("--height", type=float, default=0.3, help="drop height [m]")
    parser.add_argument("--sphere", default=SPHERE, metavar="KEY",
                        help=f"sphere material (restitution materials; default {SPHERE})")
    parser.add_argument("--d", default=f"{D * 1e3:g} mm", metavar="LEN", help=f"sphere diameter (default {D * 1e3:g} mm)")
    parser.add_argument("--plate", default=PLATE, metavar="KEY", help=f"plate material (default {PLATE})")
    parser.add_argument("--t", default=f"{T * 1e3:g} mm", metavar="LEN", help=f"plate thickness (default {T * 1e3:g} mm)")
    args = parser.parse_args(argv)
    try:
        material("sphere", args.sphere), material("plate", args.plate)
        d = input_quantity("d", "sphere.d", args.d)
        t = input_quantity("t", "plate.t", args.t)
    except OptionError as exc:
        parser.exit(2, f"quickstart_bounce.py: error: {exc}\n")
    return run(args.fmu, args.height, thickness=t, sphere=args.sphere, d=d, plate=args.plate)


if __name__ == "__main__":
    main()
