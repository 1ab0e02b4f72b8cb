"""Two FMUs, BouncingBall.fmu + SpherePlateImpact.fmu, under three co-simulation masters.

    python examples/two_fmu_cosim.py [--fmu-dir dist] [--steps 1e-2 1e-3 1e-4 1e-5] [--show]

The ball FMU holds the free flight and finds each contact inside its own step; the impact
FMU turns the approach speed into a coefficient of restitution (COR):

    ball.v_approach -> impact.v_approach,    impact.e -> ball.e

An S2 tool-steel ball (d = 6.35 mm) falls from 0.3 m on an Al 6061 plate with t/d = 1.
Each master is compared with the event-exact master (restitution.cosim.bounce, which asks
the impact FMU at the exact impact instants) over the first five bounces:

* ``fmpy fixed step``: restitution.cosim.FixedStepMaster with a fixed communication step.
  With the ball's default ``contact_mode = wait`` the ball waits at the plate for the COR
  until the next communication point: the COR is right (the master resolves the impact
  FMU's direct feedthrough at the communication point), each rebound is late by up to
  one step, and the delays add up bounce after bounce.
* ``fmpy fixed step, immediate``: the same with ``contact_mode = immediate``: the ball
  rebounds at once with the COR held on its input, computed for the speed it had at the
  last communication point; the timing is right, the COR (and so the apex) is off.
* ``libcosim``: OSP libcosim's fixedStep algorithm, configured from an
  OspSystemStructure.xml written under examples/output/osp/ (FMI 2.0 FMUs only: libcosim
  through libcosimpy 0.0.6 refuses FMI 3.0 FMUs, so with ``--fmu-dir DIR/fmi3`` this master is
  left out). libcosim reads each FMU's
  outputs right after its step, so the loop ball -> impact -> ball lags one more step:
  the waiting ball gets the COR for the speed it had at the last communication point
  before the contact, not for its impact speed; both the timing and the COR are off.
* ``fmpy state restore``: FixedStepMaster with ``event=("ball.impacts", "ball.t_impact")``:
  every step starts by saving the FMU states; when the ball reports a contact inside the step,
  both FMUs are restored, stepped exactly to the reported contact time, the values are
  exchanged there, and the step is finished.

Writes examples/output/two_fmu_cosim.png (height traces, errors and wall time against the
communication step) and prints the table.
"""
from __future__ import annotations

import argparse
import shutil
import time
from pathlib import Path

import numpy as np

import restitution as r
from restitution.viz import finish
from restitution.cosim import FixedStepMaster, FmuInstance, ball_bounces, bounce, fmu_rebound, impact_fmu_parameters
from restitution.cosim.fixed_step import BALL_IMPACT_CONNECTIONS, BALL_RECORD
from restitution.fmu import default_fmu

HERE = Path(__file__).resolve().parent
OUTPUT = HERE / "output"
GRAVITY = 9.80665
EVENT = ("ball.impacts", "ball.t_impact")

FIXED, IMMEDIATE, LIBCOSIM, RESTORE = ("fmpy fixed step", "fmpy fixed step, immediate", "libcosim fixedStep",
                                       "fmpy state restore")
MASTERS = (FIXED, IMMEDIATE, LIBCOSIM, RESTORE)


def default_system(t_over_d: float = 1.0):
    sphere = r.Sphere(r.MATERIALS["s2_tool_steel"], 6.35e-3)
    plate = r.Plate(r.MATERIALS["al_6061"], t_over_d * 6.35e-3)
    return sphere, plate


def exact_reference(impact_fmu, params, drop_height, repeat: int = 5, unzip_dirs=None):
    """Event-exact bounces through the impact FMU, and the best wall time of ``repeat`` runs."""
    unzip = (unzip_dirs or {}).get(Path(impact_fmu))
    with FmuInstance(impact_fmu, "impact_exact", unzip_dir=unzip, parameters=params) as fmu:
        rebound = fmu_rebound(fmu)
        best = np.inf
        for _ in range(repeat):
            start = time.perf_counter()
            exact = bounce(rebound, drop_height=drop_height, gravity=GRAVITY)
            best = min(best, time.perf_counter() - start)
    return exact, best


def run_fmpy(ball_fmu, impact_fmu, params, drop_height, step, t_end, contact_mode=1, event=None, unzip_dirs=None):
    """One run of FixedStepMaster; ``unzip_dirs`` ({fmu path: extracted folder}) lets runs share one extraction."""
    unzip = unzip_dirs or {}
    with FmuInstance(impact_fmu, "impact", unzip_dir=unzip.get(Path(impact_fmu)), parameters=params) as impact, \
            FmuInstance(ball_fmu, "ball", unzip_dir=unzip.get(Path(ball_fmu)),
                        parameters={"h0": drop_height, "g": GRAVITY, "contact_mode": contact_mode}) as ball:
        master = FixedStepMaster({"ball": ball, "impact": impact}, BALL_IMPACT_CONNECTIONS)
        return master.run(step, t_end, record=BALL_RECORD, event=event)


def run_libcosim(ball_fmu, impact_fmu, params, drop_height, step, t_end, work_dir: Path):
    from restitution.cosim.libcosim_run import run_system_structure, write_system_structure

    structure = write_system_structure(
        work_dir / f"step_{step:.0e}" / "OspSystemStructure.xml",
        {"ball": (ball_fmu, {"h0": drop_height, "g": GRAVITY, "contact_mode": 1}),
         "impact": (impact_fmu, params)},
        step_size=step, connections=BALL_IMPACT_CONNECTIONS)
    return run_system_structure(structure, t_end, record=BALL_RECORD)


def compare(result, exact, n: int) -> dict:
    """Largest errors over the first ``n`` bounces against the event-exact master."""
    b = ball_bounces(result, GRAVITY)
    k = min(n, b["t_impact"].size, b["v_rebound"].size, exact.n_impacts)
    dt = np.abs(b["t_impact"][:k] - exact.time[:k])
    dapex = np.abs(b["apex"][:k] / exact.apex[:k] - 1.0)
    de = np.abs(b["e_applied"][:k] - exact.e[:k])
    return {"bounces": k, "dt_max": float(dt.max()) if k == n else np.inf,
            "apex_rel_max": float(dapex.max()) if k == n else np.inf,
            "de_max": float(de.max()) if k == n else np.inf, "bounce_data": b}


def markdown_table(rows, exact_wall: float) -> str:
    lines = ["| master | step [s] | max bounce-time error [s] | max apex error [rel.] | max COR error | "
             "wall time [s] | µs / step | rollbacks |",
             "|---|---:|---:|---:|---:|---:|---:|---:|"]
    for w in rows:
        lines.append(f"| {w['master']} | {w['step']:.0e} | {w['dt_max']:.2e} | {w['apex_rel_max']:.2e} | "
                     f"{w['de_max']:.1e} | {w['wall_time']:.3f} | {w['us_per_step']:.0f} | {w['rollbacks']} |")
    lines.append(f"| event-exact master (reference) | – | 0 | 0 | 0 | {exact_wall:.4f} | – | – |")
    return "\n".join(lines)


def plot(rows, traces, exact, path: Path, dpi: int = 90, show: bool = False, t_end: float = 1.0):
    import matplotlib
    if not show:
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    styles = {FIXED: dict(color="tab:blue", marker="o", ms=9), IMMEDIATE: dict(color="tab:orange", marker="s"),
              LIBCOSIM: dict(color="tab:green", marker="^"), RESTORE: dict(color="tab:red", marker="D")}
    floor = 1e-9  # errors below (exact to round-off: 0 or ~1e-16) are drawn here
    fig, axes = plt.subplots(2, 2, figsize=(10, 7), layout="constrained")
    ax = axes[0, 0]
    t = np.linspace(0.0, t_end, 3000)
    ax.plot(t, exact.height(t) * 1e3, color="k", lw=2.2, alpha=0.35, label="event-exact master")
    step = max(rows, key=lambda w: w["step"])["step"]
    for master, res in traces.items():
        ax.plot(res.time, res["ball.h"] * 1e3, lw=1.0, color=styles[master]["color"], label=master)
    ax.set_xlim(0.45, 0.85)
    ax.set_ylim(0.0, 30.0)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("height [mm]")
    ax.set_title(f"ball height, communication step {step:g} s", fontsize=9)
    ax.legend(fontsize=7)
    for ax, key, label in ((axes[0, 1], "dt_max", "max bounce-time error [s]"),
                           (axes[1, 0], "apex_rel_max", "max apex-height error [relative]")):
        for master in MASTERS:
            sel = [w for w in rows if w["master"] == master]
            if sel:
                ax.loglog([w["step"] for w in sel], [max(w[key], floor) for w in sel], label=master,
                          **styles[master])
        ax.set_xlabel("communication step [s]")
        ax.set_ylabel(label)
        ax.axhline(floor, color="0.6", lw=0.8, ls=":")
        ax.text(min(w["step"] for w in rows), floor * 2, "below 1e-9: exact to round-off", fontsize=7,
                color="0.4")
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=7)
    ax = axes[1, 1]
    for master in MASTERS:
        sel = [w for w in rows if w["master"] == master]
        if sel:
            ax.loglog([w["step"] for w in sel], [w["wall_time"] for w in sel], label=master, **styles[master])
    ax.axhline(rows[0]["exact_wall"], color="k", ls="--", lw=1, label="event-exact master")
    ax.set_xlabel("communication step [s]")
    ax.set_ylabel("wall time [s]")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7)
    fig.suptitle("BouncingBall.fmu + SpherePlateImpact.fmu: S2 ball (d = 6.35 mm) on Al 6061, t/d = 1, "
                 "first five bounces", fontsize=10)
    return finish(fig, path, dpi, show)


def masters_for(*fmus) -> tuple:
    """The masters that can load these FMUs: every one, less libcosim for FMI 3.0 FMUs (libcosimpy 0.0.6
    refuses them: "Unsupported FMI version")."""
    from fmpy import read_model_description

    fmi3 = any(read_model_description(str(fmu)).fmiVersion.startswith("3") for fmu in fmus)
    return tuple(m for m in MASTERS if not (fmi3 and m == LIBCOSIM))


def run(show_plot: bool = False, steps=(1e-2, 1e-3, 1e-4, 1e-5), fmu_dir=None, drop_height: float = 0.3,
        t_end: float = 1.0, n_bounces: int = 5, masters=None, out_dir=None, dpi: int = 90,
        osp_dir=None, repeat: int = 1, verbose: bool = True) -> dict:
    """Run every master (``masters``: default, every one that can load the FMUs, :func:`masters_for`) at
    every communication step; write the PNG; return rows and results.

    ``fmu_dir``: the folder with both FMUs (FMI 2.0: ``DIR`` or ``DIR/fmi2``; FMI 3.0: ``DIR/fmi3``).
    ``osp_dir``: where the OspSystemStructure.xml files go (default: ``out_dir/osp``).
    ``repeat``: runs per master and step; the wall time reported is the shortest.
    """
    if fmu_dir is not None:
        ball_fmu, impact_fmu = Path(fmu_dir) / "BouncingBall.fmu", Path(fmu_dir) / "SpherePlateImpact.fmu"
    else:
        ball_fmu, impact_fmu = default_fmu(model="BouncingBall"), default_fmu()
    possible = masters_for(ball_fmu, impact_fmu)
    if masters is None:
        masters = possible
        if verbose and len(masters) < len(MASTERS):
            print(f"{LIBCOSIM} left out: libcosim (libcosimpy 0.0.6) does not load FMI 3.0 FMUs")
    unsupported = [m for m in masters if m in MASTERS and m not in possible]
    if unsupported:
        raise ValueError(f"master(s) {unsupported} cannot load the FMI 3.0 FMUs in {Path(impact_fmu).parent}")
    out_dir = Path(out_dir or OUTPUT)
    osp_dir = Path(osp_dir) if osp_dir is not None else out_dir / "osp"
    sphere, plate = default_system()
    params = impact_fmu_parameters(sphere, plate)
    # One extraction per FMU for every fmpy instance of the run: each extraction is another copy of the
    # pythonfmu binary to load and unload (see the note on pythonfmu 0.7's exit-time bug in docs/examples.md).
    from fmpy import extract
    unzip_dirs = {Path(fmu): Path(extract(str(fmu))) for fmu in (ball_fmu, impact_fmu)}
    try:
        return _run(show_plot, steps, ball_fmu, impact_fmu, params, drop_height, t_end, n_bounces, masters, out_dir,
                    dpi, osp_dir, repeat, verbose, unzip_dirs)
    finally:
        for folder in unzip_dirs.values():
            shutil.rmtree(folder, ignore_errors=True)


def _run(show_plot, steps, ball_fmu, impact_fmu, params, drop_height, t_end, n_bounces, masters, out_dir, dpi,
         osp_dir, repeat, verbose, unzip_dirs):
    exact, exact_wall = exact_reference(impact_fmu, params, drop_height, unzip_dirs=unzip_dirs)
    if exact.n_impacts < n_bounces or exact.time[n_bounces - 1] > t_end:
        raise ValueError(f"t_end = {t_end} s does not cover {n_bounces} bounces")

    rows, results = [], {}
    for master in masters:
        if master not in MASTERS:
            raise ValueError(f"master = {master!r} is not one of {MASTERS}")

    def one_run(master, step):
        if master == FIXED:
            return run_fmpy(ball_fmu, impact_fmu, params, drop_height, step, t_end, unzip_dirs=unzip_dirs)
        if master == IMMEDIATE:
            return run_fmpy(ball_fmu, impact_fmu, params, drop_height, step, t_end, contact_mode=2,
                            unzip_dirs=unzip_dirs)
        if master == LIBCOSIM:
            return run_libcosim(ball_fmu, impact_fmu, params, drop_height, step, t_end, osp_dir)
        return run_fmpy(ball_fmu, impact_fmu, params, drop_height, step, t_end, event=EVENT, unzip_dirs=unzip_dirs)

    for step in sorted(steps, reverse=True):
        for _ in range(max(1, repeat)):  # interleaved, so that a load change hits every master alike
            for master in masters:
                new = one_run(master, step)
                if (master, step) not in results or new.wall_time < results[(master, step)].wall_time:
                    results[(master, step)] = new
        for master in masters:
            res = results[(master, step)]
            cmp = compare(res, exact, n_bounces)
            rows.append({"master": master, "step": step, "dt_max": cmp["dt_max"], "apex_rel_max": cmp["apex_rel_max"],
                         "de_max": cmp["de_max"], "bounces": cmp["bounces"], "wall_time": res.wall_time,
                         "us_per_step": res.wall_time / max(res.steps, 1) * 1e6, "steps": res.steps,
                         "rollbacks": res.rollbacks, "exact_wall": exact_wall})
            if verbose:
                w = rows[-1]
                print(f"{master:28s} step {step:7.0e}: dt_max {w['dt_max']:.2e} s, apex {w['apex_rel_max']:.2e}, "
                      f"wall {w['wall_time']:.3f} s ({w['us_per_step']:.0f} us/step, {w['rollbacks']} rollbacks)")
    largest = max(steps)
    traces = {m: results[(m, largest)] for m in masters}
    png = plot(rows, traces, exact, out_dir / "two_fmu_cosim.png", dpi, show_plot)
    md = markdown_table(rows, exact_wall)
    if verbose:
        print(md)
        print(f"wrote {png}")
    return {"exact": exact, "exact_wall": exact_wall, "rows": rows, "results": results, "markdown": md, "png": png,
            "osp_dir": osp_dir}


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--fmu-dir", type=Path, default=None,
                        help="folder with BouncingBall.fmu and SpherePlateImpact.fmu: dist/ (the default, "
                             "built if missing), dist/fmi2 or dist/fmi3")
    parser.add_argument("--steps", type=float, nargs="+", default=[1e-2, 1e-3, 1e-4, 1e-5])
    parser.add_argument("--show", action="store_true", help="show the plot window")
    args = parser.parse_args()
    run(show_plot=args.show, steps=args.steps, fmu_dir=args.fmu_dir)
