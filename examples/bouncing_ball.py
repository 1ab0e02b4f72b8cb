"""A steel ball dropped on aluminium plates of several thicknesses, through SpherePlateImpact.fmu.

    python examples/bouncing_ball.py [--fmu dist/SpherePlateImpact.fmu] [--show]

An S2 tool-steel ball (d = 6.35 mm, Table 3 of Green 2022) falls from 0.3 m onto Al 6061
plates with t/d = 0.25, 0.5, 1 and 2, and onto a half-space (the FMU's ``plate_waves = 0``:
no plate waves, e = e_ep). Each drop runs the event-exact fmpy master
(:func:`restitution.cosim.bounce`), which asks the FMU for the rebound at every impact.
The picture (height against time) goes to examples/output/bouncing_ball.png; the table
lists the first five bounces of each plate.
"""
from __future__ import annotations

import argparse
import shutil
import tempfile
from pathlib import Path

import numpy as np

import restitution as r
from restitution.viz import finish
from restitution.cosim import FmuInstance, bounce, build_default_fmu, fmu_rebound, impact_fmu_parameters

HERE = Path(__file__).resolve().parent
OUTPUT = HERE / "output"
HALF_SPACE = "half-space"


def drop_on_plates(fmu_path, t_over_d=(0.25, 0.5, 1.0, 2.0), half_space=True, drop_height=0.3,
                   sphere_key="s2_tool_steel", d=6.35e-3, plate_key="al_6061"):
    """{label: Bounces} for one drop per plate, each through its own FMU instance."""
    from fmpy import extract

    sphere = r.Sphere(r.MATERIALS[sphere_key], d)
    plates = [(f"t/d = {x:g}", r.Plate(r.MATERIALS[plate_key], x * d), {}) for x in t_over_d]
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


def plot(cases: dict, path: Path, drop_height: float, t_end: float, dpi: int = 90, show: bool = False):
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
    ax.set_title("S2 tool-steel ball (d = 6.35 mm) dropped on Al 6061 plates: SpherePlateImpact.fmu + fmpy",
                 fontsize=9)
    ax.legend(fontsize=8, title="plate thickness", title_fontsize=8)
    ax.grid(alpha=0.3)
    return finish(fig, path, dpi, show)


def run(show_plot: bool = False, fmu_path=None, t_over_d=(0.25, 0.5, 1.0, 2.0), drop_height: float = 0.3,
        t_end: float = 1.5, n_bounces: int = 5, out_dir=None, dpi: int = 90, verbose: bool = True) -> dict:
    """Drop the ball on every plate; write the PNG; return {"cases", "rows", "markdown", "png"}."""
    fmu_path = Path(fmu_path) if fmu_path else build_default_fmu()
    cases = drop_on_plates(fmu_path, t_over_d, drop_height=drop_height)
    rows = bounce_table(cases, n_bounces)
    png = plot(cases, Path(out_dir or OUTPUT) / "bouncing_ball.png", drop_height, t_end, dpi, show_plot)
    md = markdown_table(rows)
    if verbose:
        print(f"S2 tool-steel ball, d = 6.35 mm, dropped from {drop_height} m on Al 6061 (first {n_bounces} bounces)")
        print(md)
        for label, b in cases.items():
            print(f"{label}: {b.n_impacts} impacts, at rest at t = {b.rest_time:.4f} s ({b.why_stopped})")
        print(f"wrote {png}")
    return {"cases": cases, "rows": rows, "markdown": md, "png": png}


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--fmu", type=Path, default=None, help="SpherePlateImpact.fmu (default: dist/, built if missing)")
    parser.add_argument("--show", action="store_true", help="show the plot window")
    args = parser.parse_args()
    run(show_plot=args.show, fmu_path=args.fmu)
