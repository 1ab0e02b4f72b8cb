"""The picture of a scene run: one panel per requested output (bounce heights against time, the
CORs and contact durations against approach speed)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..output_files import atomic_write


def plot_scene(result, path) -> Path:
    """One panel per requested output (bounce heights vs time, COR and contact durations vs speed)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    outs = result.scene.outputs
    fig, axes = plt.subplots(len(outs), 1, figsize=(8, 3.2 * len(outs)), squeeze=False)
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for ax, out in zip(axes[:, 0], outs):
        balls = [b.name for b in result.scene.balls]
        for k, d in enumerate(result.drops):
            color = colors[k % len(colors)]
            style = ("-", "--", ":", "-.")[balls.index(d.drop.ball.name) % 4]
            if out == "bounce_heights":
                t = np.linspace(0.0, d.rest_time * 1.02 if d.rest_time > 0 else 1.0, 2000)
                ax.plot(t, d.height(t) * 1e3, style, color=color, lw=1, label=d.drop.label)
            elif out == "cor":
                ax.plot(d.v_approach, d.columns["e"], "o-", color=color, ms=3, lw=1, label=d.drop.label)
                ax.plot(d.v_approach, d.columns["e_ep"], "v:", color=color, ms=3, lw=1)
                ax.plot(d.v_approach, d.columns["e_ze"], "^--", color=color, ms=3, lw=1)
            else:
                ax.plot(d.v_approach, d.columns["t_contact"] * 1e6, "o-", color=color, ms=3, lw=1,
                        label=d.drop.label)
        if out == "bounce_heights":
            ax.set(xlabel="time [s]", ylabel="height [mm]", title="bounce heights")
            _readable_heights(ax, [d.apex for d in result.drops] + [[d.drop_height for d in result.drops]])
        elif out == "cor":
            ax.set(xlabel="approach speed [m/s]", ylabel="COR [1]",
                   title="COR: e (o, solid), e_ep (v, dotted), e_ze (^, dashed)")
            ax.axhline(0.0, color="0.6", lw=0.5)
        else:
            ax.set(xlabel="approach speed [m/s]", ylabel="contact duration [µs]", title="contact durations")
            ax.set_yscale("log")
        ax.grid(alpha=0.3)
    axes[0, 0].legend(fontsize=7, loc="best")
    fig.suptitle(f"{result.scene.name} (plasticity = {result.plasticity_mode}, plate_waves = {result.plate_waves_mode}, "
                 f"zener_method = {result.zener_method})", fontsize=9)
    fig.tight_layout()
    path = Path(path)
    try:  # under a temporary name, renamed when whole (restitution.output_files)
        atomic_write(path, lambda tmp: fig.savefig(tmp, dpi=120), "plot")
    finally:
        plt.close(fig)
    return path


def _readable_heights(ax, heights) -> None:
    """A logarithmic height axis [mm] when the bounces span more than a decade and a half, so that
    a 0.1 mm bounce after a 1 m drop stays visible; its floor is half the lowest bounce."""
    positive = np.concatenate([np.asarray(h, dtype=float).ravel() for h in heights]) * 1e3
    positive = positive[positive > 0.0]
    if positive.size and positive.max() > 30.0 * positive.min():
        ax.set_yscale("log")
        ax.set_ylim(positive.min() / 2.0, positive.max() * 1.5)
        ax.set_ylabel("height [mm], logarithmic")
