"""A steel ball dropped on aluminium plates of several thicknesses, through SpherePlateImpact.fmu.

    python examples/bouncing_ball.py [--fmu dist/SpherePlateImpact.fmu] [--show]
    python examples/bouncing_ball.py --sphere chrome_steel --d "4.76 mm" --plate brass_260 --t "3 mm" --t "6 mm"

An S2 tool-steel ball (d = 6.35 mm, Table 3 of Green 2022) falls from 0.3 m onto Al 6061
plates with t/d = 0.25, 0.5, 1 and 2, and onto a half-space (the FMU's ``plate_waves = 0``:
no plate waves, e = e_ep). ``--sphere``, ``--d``, ``--plate`` and ``--t`` (repeatable: one drop per
thickness) choose another case, as ``restitution cor`` reads them: a preset's name
(``restitution materials``), a length with any unit (a bare number is SI). Each drop runs the event-exact fmpy master
(:func:`restitution.cosim.bounce`), which asks the FMU for the rebound at every impact.
The picture (height against time) goes to examples/output/bouncing_ball.png; the table
lists the first five bounces of each plate.
"""
from __future__ import annotations

import argparse
import shutil
from pathlib import Path

import numpy as np

import restitution as r
from restitution.inputs import input_quantity, material
from restitution.units import OptionError
from restitution.viz import finish
from restitution.cosim import FmuInstance, bounce, fmu_rebound, impact_fmu_parameters
from restitution.fmu import default_fmu

HERE = Path(__file__).resolve().parent
OUTPUT = HERE / "output"
HALF_SPACE = "half-space"
#: The default case: today's drop (Table 3 of Green 2022), t = t/d x d for these t/d.
SPHERE, D, PLATE, T_OVER_D = "s2_tool_steel", 6.35e-3, "al_6061", (0.25, 0.5, 1.0, 2.0)
#: How the text and the picture name a material (else the preset's own name).
SHORT_NAMES = {"s2_tool_steel": "S2 tool-steel", "al_6061": "Al 6061"}


def short_name(key: str) -> str:
    return SHORT_NAMES.get(key, r.MATERIALS[key].name)


def plate_label(t: float, d: float) -> str:
    """A plate's label: its t/d to three digits ("t/d = 0.25", "t/d = 0.472")."""
    return f"t/d = {t / d:.3g}"


def drop_on_plates(fmu_path, t_over_d=T_OVER_D, half_space=True, drop_height=0.3,
                   sphere_key=SPHERE, d=D, plate_key=PLATE, thicknesses=None):
    """{label: Bounces} for one drop per plate, each through its own FMU instance: plates of thickness
    ``thicknesses`` [m] or, when None, ``t_over_d`` times ``d`` [m]."""
    from fmpy import extract

    sphere = r.Sphere(r.MATERIALS[sphere_key], d)
    thicknesses = [x * d for x in t_over_d] if thicknesses is None else list(thicknesses)
    plates = [(plate_label(t, d), r.Plate(r.MATERIALS[plate_key], t), {}) for t in thicknesses]
    if half_space:  # plate waves off: the plate behaves as a half-space, e = e_ep
        plates.append((HALF_SPACE, r.Plate(r.MATERIALS[plate_key], 2 * d), {"plate_waves": 0}))
    unzip = extract(str(fmu_path))
    try:
        cases = {}
        for label, plate, extra in plates:
            params = {**impact_fmu_parameters(sphere, plate), **extra}
            with FmuInstance(fmu_path, instance_name=label, unzip_dir=unzip, parameters=params) as fmu:
                cases[label] = bounce(fmu_rebound(fmu), drop_height=drop_height)
        return cases
    finally:
        shutil.rmtree(unzip, ignore_errors=True)


def bounce_table(cases: dict, n: int = 5) -> list[dict]:
    """The first ``n`` bounces of every case as rows (units: s, m/s, 1, microseconds, mm)."""
    rows = []
    for label, b in cases.items():
        for i in range(min(n, b.n_impacts)):
            lam = np.nan if label == HALF_SPACE else b.lam[i]  # plate waves off: lambda is not used
            rows.append({"plate": label, "bounce": i + 1, "t": b.time[i], "v_approach": b.v_approach[i],
                         "e": b.e[i], "e_ep": b.e_ep[i], "e_ze": b.e_ze[i], "lambda": lam,
                         "t_contact_us": b.t_contact[i] * 1e6, "apex_mm": b.apex[i] * 1e3})
    return rows


def markdown_table(rows) -> str:
    head = "| plate | # | t [s] | v_approach [m/s] | e | e_ep | e_ze | λ | contact [µs] | apex [mm] |"
    lines = [head, "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for w in rows:
        lam = "–" if np.isnan(w["lambda"]) else f"{w['lambda']:.3f}"
        lines.append(f"| {w['plate']} | {w['bounce']} | {w['t']:.4f} | {w['v_approach']:.3f} | {w['e']:.3f} | "
                     f"{w['e_ep']:.3f} | {w['e_ze']:.3f} | {lam} | {w['t_contact_us']:.1f} | "
                     f"{w['apex_mm']:.2f} |")
    return "\n".join(lines)


def plot(cases: dict, path: Path, drop_height: float, t_end: float, dpi: int = 90, show: bool = False,
         title: str = ""):
    import matplotlib
    if not show:
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = np.linspace(0.0, t_end, 4000)
    fig, ax = plt.subplots(figsize=(7.5, 4.0), layout="constrained")
    colors = plt.cm.viridis(np.linspace(0.0, 0.85, len(cases)))
    for (label, b), color in zip(cases.items(), colors):
        style = dict(color="k", ls="--") if label == HALF_SPACE else dict(color=color)
        note = " (no rebound)" if b.stop_reason == "e<=0" and b.n_impacts == 1 else ""
        ax.plot(t, b.height(t) * 1e3, lw=1.4, label=f"{label}: e₁ = {b.e[0]:.2f}{note}", **style)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("height [mm]")
    ax.set_xlim(0.0, t_end)
    ax.set_ylim(0.0, drop_height * 1e3 * 1.05)
    ax.set_title(f"{title}: SpherePlateImpact.fmu + fmpy", fontsize=9)
    ax.legend(fontsize=8, title="plate thickness", title_fontsize=8)
    ax.grid(alpha=0.3)
    return finish(fig, path, dpi, show)


def run(show_plot: bool = False, fmu_path=None, t_over_d=T_OVER_D, drop_height: float = 0.3,
        t_end: float = 1.5, n_bounces: int = 5, out_dir=None, dpi: int = 90, verbose: bool = True,
        sphere: str = SPHERE, d: float = D, plate: str = PLATE, thicknesses=None) -> dict:
    """Drop the ball (preset ``sphere``, diameter ``d`` [m]) on every plate (preset ``plate``, thickness
    ``thicknesses`` [m], default ``t_over_d`` times ``d``); write the PNG; return {"cases", "rows",
    "markdown", "png"}."""
    fmu_path = Path(fmu_path) if fmu_path else default_fmu()
    cases = drop_on_plates(fmu_path, t_over_d, drop_height=drop_height, sphere_key=sphere, d=d, plate_key=plate,
                           thicknesses=thicknesses)
    rows = bounce_table(cases, n_bounces)
    title = f"{short_name(sphere)} ball (d = {d * 1e3:g} mm) dropped on {short_name(plate)} plates"
    png = plot(cases, Path(out_dir or OUTPUT) / "bouncing_ball.png", drop_height, t_end, dpi, show_plot, title)
    md = markdown_table(rows)
    if verbose:
        print(f"{short_name(sphere)} ball, d = {d * 1e3:g} mm, dropped from {drop_height} m on {short_name(plate)} "
              f"(first {n_bounces} bounces)")
        print(md)
        for label, b in cases.items():
            print(f"{label}: {b.n_impacts} impacts, at rest at t = {b.rest_time:.4f} s ({b.why_stopped})")
        print(f"wrote {png}")
    return {"cases": cases, "rows": rows, "markdown": md, "png": png}


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     epilog="Lengths take a unit (\"6.35 mm\", \"1/4 in\"); a bare number is SI.")
    parser.add_argument("--fmu", type=Path, default=None, help="SpherePlateImpact.fmu (default: dist/, built if missing)")
    parser.add_argument("--sphere", default=SPHERE, metavar="KEY",
                        help=f"sphere material (restitution materials; default {SPHERE})")
    parser.add_argument("--d", default=f"{D * 1e3:g} mm", metavar="LEN", help=f"sphere diameter (default {D * 1e3:g} mm)")
    parser.add_argument("--plate", default=PLATE, metavar="KEY", help=f"plate material (default {PLATE})")
    parser.add_argument("--t", action="append", metavar="LEN",
                        help="plate thickness, repeat for several plates (default: t/d = "
                             f"{', '.join(f'{x:g}' for x in T_OVER_D)})")
    parser.add_argument("--out-dir", type=Path, default=None, help=f"folder of the PNG (default {OUTPUT})")
    parser.add_argument("--show", action="store_true", help="show the plot window")
    args = parser.parse_args(argv)
    try:
        material("sphere", args.sphere), material("plate", args.plate)
        d = input_quantity("d", "sphere.d", args.d)
        thicknesses = None if args.t is None else [input_quantity("t", "plate.t", text) for text in args.t]
    except OptionError as exc:
        parser.exit(2, f"bouncing_ball.py: error: {exc}\n")
    return run(show_plot=args.show, fmu_path=args.fmu, out_dir=args.out_dir, sphere=args.sphere, d=d,
               plate=args.plate, thicknesses=thicknesses)


if __name__ == "__main__":
    main()
