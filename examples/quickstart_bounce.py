"""Quickstart: drop an S2 tool-steel ball on an Al 6061 plate through SpherePlateImpact.fmu.

    python examples/quickstart_bounce.py [--fmu dist/SpherePlateImpact.fmu] [--height 0.3]

Uses the event-exact fmpy master (restitution.cosim.bouncing) and prints the first bounces. Without
--fmu it uses dist/SpherePlateImpact.fmu (outside a checkout, ~/.cache/restitution/fmus/), building and
validating it first when it is missing or was built from other sources: that FMU alone, the pythonfmu one,
in seconds (`restitution fmu build` builds every FMU, the native ones for every platform: minutes).
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import restitution as r
from restitution.cosim import FmuInstance, bounce, build_default_fmu, fmu_rebound, impact_fmu_parameters


def run(fmu_path=None, height: float = 0.3, thickness: float = 6.35e-3, show: int = 5):
    """Bounce the default ball; return the :class:`~restitution.cosim.Bounces` record."""
    if fmu_path is None:
        fmu_path = build_default_fmu(log=lambda message: print(message, file=sys.stderr, flush=True), scope="model")
        print(f"FMU: {fmu_path} (built from the installed sources; `restitution fmu build` rebuilds every FMU)")
    fmu_path = Path(fmu_path)
    sphere = r.Sphere(r.MATERIALS["s2_tool_steel"], 6.35e-3)
    plate = r.Plate(r.MATERIALS["al_6061"], thickness)
    with FmuInstance(fmu_path, parameters=impact_fmu_parameters(sphere, plate)) as fmu:
        bounces = bounce(fmu_rebound(fmu), drop_height=height)
    print(f"S2 tool-steel ball (d = 6.35 mm) dropped from {height} m on Al 6061, t = {thickness * 1e3:.2f} mm")
    print(f"{'#':>3} {'t [s]':>9} {'v [m/s]':>8} {'e':>7} {'e_ep':>7} {'e_ze':>7} {'t_c [us]':>9}")
    for i in range(min(show, bounces.n_impacts)):
        print(f"{i + 1:>3} {bounces.time[i]:9.5f} {bounces.v_approach[i]:8.4f} {bounces.e[i]:7.4f} "
              f"{bounces.e_ep[i]:7.4f} {bounces.e_ze[i]:7.4f} {bounces.t_contact[i] * 1e6:9.2f}")
    print(f"{bounces.n_impacts} impacts; at rest at t = {bounces.rest_time:.4f} s ({bounces.why_stopped})")
    return bounces


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--fmu", type=Path, default=None)
    parser.add_argument("--height", type=float, default=0.3, help="drop height [m]")
    args = parser.parse_args()
    run(args.fmu, args.height)
