"""A model-exchange drop: BouncingBall.fmu integrated by the master, e(v) from SpherePlateImpact at each contact.

    python examples/model_exchange_bounce.py [--fmu-dir dist/fmi2] [--impact me|cs|package] [--show]
    python examples/model_exchange_bounce.py --sphere chrome_steel --d "4.76 mm" --plate brass_260 --t "3 mm"

The native BouncingBall FMU runs in model exchange (FMI 2.0 from ``DIR``/``DIR/fmi2``, FMI 3.0 from
``DIR/fmi3``): the master (:func:`restitution.cosim.bounce_model_exchange`) integrates its states h and v
with scipy's RK45, locates each contact as a zero crossing of the ball's event indicator and, in the event,
sets the ball's ``e`` from SpherePlateImpact evaluated at the impact speed: the FMU in model exchange
(``--impact me``, the default), in co-simulation (``cs``), or the package (``package``). An S2 tool-steel
ball (d = 6.35 mm) falls from 0.3 m onto an Al 6061 plate with t/d = 1 and bounces until its rebound is
slower than ``v_min`` (1 cm/s). The same drop through the event-exact co-simulation master
(:func:`restitution.cosim.bounce`, closed-form flights, e from the package) is the reference: the table
lists both, and the picture (height against time, the master's accepted points marked) goes to
examples/output/model_exchange_bounce.png. ``--sphere``, ``--d``, ``--plate`` and ``--t`` choose another case,
as ``restitution cor`` reads them: a preset's name (``restitution materials``), a length with any unit (a bare
number is SI).
"""
from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

import restitution as r
from restitution.cosim import (FmuInstance, ModelExchangeInstance, bounce, bounce_model_exchange, fmu_rebound,
                               impact_fmu_parameters, model_exchange_rebound, package_rebound)
from restitution.fmu import default_fmu
from restitution.inputs import input_quantity, material
from restitution.units import OptionError
from restitution.viz import finish

HERE = Path(__file__).resolve().parent
OUTPUT = HERE / "output"
#: --impact's choices and what they mean
IMPACTS = {"me": "SpherePlateImpact.fmu (model exchange)", "cs": "SpherePlateImpact.fmu (co-simulation)",
           "package": "the package (restitution.impact)"}
#: The default case: an S2 tool-steel ball, d = 6.35 mm, on an Al 6061 plate with t = d.
SPHERE, D, PLATE = "s2_tool_steel", 6.35e-3, "al_6061"


def native_dir(fmu_dir=None) -> Path:
    """The folder with the native BouncingBall.fmu and SpherePlateImpact.fmu: ``fmu_dir`` itself when it holds
    them with a model-exchange interface, else its ``fmi2/``; by default dist/fmi2 (built when missing)."""
    from fmpy import read_model_description

    base = Path(fmu_dir) if fmu_dir is not None else default_fmu(model="BouncingBall").parent
    for folder in (base, base / "fmi2"):
        ball = folder / "BouncingBall.fmu"
        if ball.is_file() and (folder / "SpherePlateImpact.fmu").is_file() and \
                read_model_description(str(ball)).modelExchange is not None:
            return folder
    raise ValueError(f"--fmu-dir {base}: no native BouncingBall.fmu and SpherePlateImpact.fmu with model exchange "
                     "there or in its fmi2/ (the pythonfmu FMUs are co-simulation only)")


def drop(fmu_dir=None, impact: str = "me", drop_height: float = 0.3, t_over_d: float = 1.0, v_min: float = 1e-2,
         event_tol: float = 1e-12, sphere_key: str = SPHERE, d: float = D, plate_key: str = PLATE, t=None):
    """(model-exchange Bounces, co-simulation reference Bounces, the folder of the FMUs used): the preset
    ``sphere_key``, diameter ``d`` [m], on the preset ``plate_key``, thickness ``t`` [m] (None: ``t_over_d`` d)."""
    if impact not in IMPACTS:
        raise ValueError(f"impact = {impact!r} is not one of {', '.join(IMPACTS)}")
    folder = native_dir(fmu_dir)
    sphere = r.Sphere(r.MATERIALS[sphere_key], d)
    plate = r.Plate(r.MATERIALS[plate_key], t_over_d * d if t is None else t)
    package = package_rebound(**sphere.params(), **plate.params())
    ball, impact_fmu = folder / "BouncingBall.fmu", folder / "SpherePlateImpact.fmu"
    params = impact_fmu_parameters(sphere, plate)
    if impact == "package":
        me = bounce_model_exchange(ball, package, drop_height, v_min=v_min, event_tol=event_tol)
    else:
        kind, make = (ModelExchangeInstance, model_exchange_rebound) if impact == "me" else (FmuInstance, fmu_rebound)
        with kind(impact_fmu, instance_name="impact", parameters=params) as inst:
            me = bounce_model_exchange(ball, make(inst), drop_height, v_min=v_min, event_tol=event_tol)
    return me, bounce(package, drop_height, v_min=v_min), folder


def table(me, ref, n: int = 8) -> str:
    head = ["| # | t [s] (ME) | t [s] (co-sim) | v_approach [m/s] (ME) | e (ME) | e (co-sim) | apex [mm] (ME) |",
            "|---:|---:|---:|---:|---:|---:|---:|"]
    for i in range(min(n, me.n_impacts, ref.n_impacts)):
        head.append(f"| {i + 1} | {me.time[i]:.9f} | {ref.time[i]:.9f} | {me.v_approach[i]:.6f} | {me.e[i]:.6f} | "
                    f"{ref.e[i]:.6f} | {me.apex[i] * 1e3:.4f} |")
    return "\n".join(head)


def plot(me, ref, path: Path, dpi: int = 90, show: bool = False):
    import matplotlib
    if not show:
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = np.linspace(0.0, ref.rest_time * 1.05, 4000)
    pts = me.extra["points"]
    fig, ax = plt.subplots(figsize=(7.5, 4.0), layout="constrained")
    ax.plot(t, ref.height(t) * 1e3, color="0.6", lw=3.0, label="co-simulation master (closed-form flights)")
    ax.plot(t, me.height(t) * 1e3, color="C0", lw=1.2, label=f"model exchange, FMI {me.extra['fmi_version']}")
    ax.plot(pts["t"], np.maximum(pts["h"], 0.0) * 1e3, ".", color="C1", ms=3, label="accepted integrator points")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("height [mm]")
    ax.set_title(f"BouncingBall.fmu in model exchange, e(v) from SpherePlateImpact at each of {me.n_impacts} contacts",
                 fontsize=9)
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    return finish(fig, path, dpi, show)


def run(show_plot: bool = False, fmu_dir=None, impact: str = "me", drop_height: float = 0.3, v_min: float = 1e-2,
        event_tol: float = 1e-12, out_dir=None, dpi: int = 90, verbose: bool = True, sphere: str = SPHERE,
        d: float = D, plate: str = PLATE, t=None) -> dict:
    """One drop in model exchange and its co-simulation reference (the preset ``sphere``, diameter ``d`` [m],
    on the preset ``plate``, thickness ``t`` [m], default ``d``); the PNG; {"me", "ref", "markdown", "png",
    "max_dt", "max_dv"} (the largest differences of the contact instants [s] and impact speeds [m/s])."""
    me, ref, folder = drop(fmu_dir, impact, drop_height, v_min=v_min, event_tol=event_tol, sphere_key=sphere, d=d,
                           plate_key=plate, t=t)
    n = min(me.n_impacts, ref.n_impacts)
    max_dt = float(np.max(np.abs(me.time[:n] - ref.time[:n])))
    max_dv = float(np.max(np.abs(me.v_approach[:n] - ref.v_approach[:n])))
    png = plot(me, ref, Path(out_dir or OUTPUT) / "model_exchange_bounce.png", dpi, show_plot)
    md = table(me, ref)
    if verbose:
        x = me.extra
        print(f"{folder / 'BouncingBall.fmu'} (FMI {x['fmi_version']}) in model exchange, e from {IMPACTS[impact]}")
        print(md)
        print(f"model exchange: {me.n_impacts} contacts, at rest at t = {me.rest_time:.9f} s ({me.why_stopped}); "
              f"{x['steps']} {x['method']} steps, {x['rhs_calls']} derivative and {x['indicator_calls']} indicator "
              f"evaluations, {x['wall_time'] * 1e3:.1f} ms")
        print(f"co-simulation: {ref.n_impacts} contacts, at rest at t = {ref.rest_time:.9f} s ({ref.why_stopped})")
        print(f"largest differences: {max_dt:.2e} s in the contact instants, {max_dv:.2e} m/s in the impact speeds "
              f"(event_tol = {event_tol:g} s)")
        print(f"wrote {png}")
    return {"me": me, "ref": ref, "markdown": md, "png": png, "max_dt": max_dt, "max_dv": max_dv}


def main(argv=None) -> dict | None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     epilog="Lengths take a unit (\"6.35 mm\", \"1/4 in\"); a bare number is SI.")
    parser.add_argument("--fmu-dir", type=Path, default=None,
                        help="folder with the native BouncingBall.fmu and SpherePlateImpact.fmu: dist/fmi2 (the "
                             "default, built if missing) or dist/fmi3")
    parser.add_argument("--impact", choices=list(IMPACTS), default="me",
                        help="SpherePlateImpact in model exchange (me), co-simulation (cs), or the package")
    parser.add_argument("--drop-height", type=float, default=0.3, help="[m]")
    parser.add_argument("--v-min", type=float, default=1e-2, help="rest below this rebound speed [m/s]")
    parser.add_argument("--event-tol", type=float, default=1e-12, help="contact location tolerance [s]")
    parser.add_argument("--sphere", default=SPHERE, metavar="KEY",
                        help=f"sphere material (restitution materials; default {SPHERE})")
    parser.add_argument("--d", default=f"{D * 1e3:g} mm", metavar="LEN", help=f"sphere diameter (default {D * 1e3:g} mm)")
    parser.add_argument("--plate", default=PLATE, metavar="KEY", help=f"plate material (default {PLATE})")
    parser.add_argument("--t", default=None, metavar="LEN", help="plate thickness (default: the sphere's diameter)")
    parser.add_argument("--out-dir", type=Path, default=None, help=f"folder of the PNG (default {OUTPUT})")
    parser.add_argument("--show", action="store_true", help="show the plot window")
    args = parser.parse_args(argv)
    try:
        material("sphere", args.sphere), material("plate", args.plate)
        d = input_quantity("d", "sphere.d", args.d)
        t = None if args.t is None else input_quantity("t", "plate.t", args.t)
        return run(show_plot=args.show, fmu_dir=args.fmu_dir, impact=args.impact, drop_height=args.drop_height,
                   v_min=args.v_min, event_tol=args.event_tol, out_dir=args.out_dir, sphere=args.sphere, d=d,
                   plate=args.plate, t=t)
    except (OptionError, ValueError) as exc:  # a refused option, no native FMU with model exchange
        parser.exit(2, f"model_exchange_bounce.py: error: {exc}\n")


if __name__ == "__main__":
    main()
