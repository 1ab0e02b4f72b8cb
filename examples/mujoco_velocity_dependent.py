"""A ball bouncing on a plate in MuJoCo, each contact's solref set from the model's e at that contact's speed.

    python examples/mujoco_velocity_dependent.py [--sphere s2_tool_steel --d "6.35 mm" --plate al_6061 --t "6.35 mm"]
        [--height "0.3 m"] [--show]

MuJoCo's geoms have one solref each; this model's e falls with the impact speed (plasticity and the plate's
waves). The ball is dropped on a plane in MuJoCo (``pip install "restitution[export]"``); before each
contact the geom's solref and solimp are set from ``restitution export mujoco``'s mapping for the approach
speed predicted from the ball's height and speed (:func:`restitution.export.mujoco_bounce.bounce_in_mujoco`),
and MuJoCo steps the contact with the step they are tuned for (t_contact/50). A second run keeps the first
contact's solref for every bounce (a constant e; solimp's ramp still spans one step's approach). The
picture (examples/output/mujoco_velocity_dependent.png) shows the achieved e of each bounce against its
approach speed, beside the model's e(v) and the constant-e run.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

import restitution as r
from restitution.export import export_case
from restitution.export.mujoco import ramp_solimp
from restitution.export.mujoco_bounce import G, bounce_in_mujoco, solref_from_model
from restitution.inputs import input_quantity, material, positive_quantity
from restitution.units import OptionError
from restitution.viz import finish

HERE = Path(__file__).resolve().parent
OUTPUT = HERE / "output"
#: The default case: an S2 tool-steel ball (d = 6.35 mm) on Al 6061, t = 6.35 mm, dropped from 0.3 m.
SPHERE, D, PLATE, T, HEIGHT = "s2_tool_steel", 6.35e-3, "al_6061", 6.35e-3, 0.3


def model_e(sphere, plate, d: float, t: float, v) -> np.ndarray:
    """The model's e at the speeds ``v`` [m/s] (one array call of impact())."""
    return np.asarray(r.impact(np.asarray(v, float), **sphere.params("sphere"), sphere_d=d,
                               **plate.params("plate"), plate_t=t).e)


def plot(variable, constant, sphere_key, plate_key, d, t, path: Path, dpi: int = 90, show: bool = False) -> Path:
    import matplotlib
    if not show:
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    sphere, plate = r.MATERIALS[sphere_key], r.MATERIALS[plate_key]
    v = np.geomspace(min(variable.v_in) * 0.8, max(variable.v_in) * 1.1, 200)
    fig, ax = plt.subplots(figsize=(7.5, 4.2), layout="constrained")
    ax.plot(v, model_e(sphere, plate, d, t, v), color="0.5", lw=2.5, label="model e(v) (restitution)")
    ax.plot(variable.v_in, variable.e, "o", color="C0", label="MuJoCo, solref per contact from e(v)")
    ax.plot(constant.v_in, constant.e, "s", color="C1", mfc="none", label="MuJoCo, the first contact's solref kept")
    ax.set_xscale("log")
    ax.set_xlabel("approach speed of the bounce [m/s]")
    ax.set_ylabel("coefficient of restitution e")
    ax.set_title(f"{sphere.name} ball (d = {d * 1e3:.3g} mm) on {plate.name} (t = {t * 1e3:.3g} mm) in MuJoCo "
                 f"{_mujoco_version()}", fontsize=9)
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3, which="both")
    return finish(fig, path, dpi, show)


def _mujoco_version() -> str:
    import mujoco

    return mujoco.__version__


def run(show_plot: bool = False, out_dir=None, dpi: int = 90, verbose: bool = True, sphere: str = SPHERE,
        d: float = D, plate: str = PLATE, t: float = T, height: float = HEIGHT, v_min: float = 0.05) -> dict:
    """Both runs and the PNG: {"variable", "constant" (:class:`~restitution.export.mujoco_bounce.Bounces`),
    "model_e" (the model's e at each variable bounce's approach speed), "errors" (achieved over model, minus 1),
    "png"}."""
    sphere_m, plate_m = r.MATERIALS[sphere], r.MATERIALS[plate]
    first = export_case(float(np.sqrt(2 * G * height)), sphere_m, plate_m, d, t)
    solref_at = solref_from_model(sphere_m, plate_m, d, t)
    variable = bounce_in_mujoco(solref_at, 0.5 * d, first.m_sphere, height, v_min=v_min)
    kept, _solimp, step = solref_at(first.v)  # the solimp ramp spans one step's approach: it follows the speed
    constant = bounce_in_mujoco(lambda v: (kept, ramp_solimp(v, step), step), 0.5 * d, first.m_sphere, height,
                                v_min=v_min)
    want = model_e(sphere_m, plate_m, d, t, variable.v_in)
    errors = np.asarray(variable.e) / want - 1.0
    png = plot(variable, constant, sphere, plate, d, t, Path(out_dir or OUTPUT) / "mujoco_velocity_dependent.png",
               dpi, show_plot)
    if verbose:
        print(f"{len(variable.e)} bounces in MuJoCo {_mujoco_version()}, e from the model at each contact's speed")
        print("   v_in [m/s]   e MuJoCo   e model   error")
        for v, e, m, err in zip(variable.v_in, variable.e, want, errors):
            print(f"   {v:10.4f}   {e:8.4f}   {m:7.4f}   {100 * err:+.2f} %")
        print(f"constant solref (e = {first.e:.4f} at {first.v:.3g} m/s): e per bounce "
              + ", ".join(f"{e:.4f}" for e in constant.e))
        print(f"picture: {png}")
    return {"variable": variable, "constant": constant, "model_e": want, "errors": errors, "png": png,
            "first": first}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--sphere", default=SPHERE)
    parser.add_argument("--d", default=f"{D} m")
    parser.add_argument("--plate", default=PLATE)
    parser.add_argument("--t", default=f"{T} m")
    parser.add_argument("--height", default=f"{HEIGHT} m", help="drop height, e.g. \"30 cm\"")
    parser.add_argument("--out-dir", type=Path, default=None, help=f"folder of the PNG (default {OUTPUT})")
    parser.add_argument("--show", action="store_true")
    args = parser.parse_args(argv)
    try:
        material("sphere", args.sphere), material("plate", args.plate)
        d, t = input_quantity("d", "sphere.d", args.d), input_quantity("t", "plate.t", args.t)
        height = positive_quantity("height", args.height, "m", "length")
    except OptionError as exc:
        print(f"mujoco_velocity_dependent: error: {exc}", file=sys.stderr)
        return 2
    run(args.show, args.out_dir, sphere=args.sphere, d=d, plate=args.plate, t=t, height=height)
    return 0


if __name__ == "__main__":
    sys.exit(main())
