"""The accuracy page's figure: error against cost per evaluation, log-log."""
from __future__ import annotations

from pathlib import Path

from .config import RANGES


def plot(res: dict, path: Path) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    acc, zs, fmu = res["accuracy"], res["zener_scalar"]["costs"], res["fmu"]
    lo_clip, hi_clip = 1e-14, 1e2
    colors = {"exact": "tab:red", "paper_fit": "tab:blue", "linear": "tab:green"}
    fig, axes = plt.subplots(2, 2, figsize=(10, 7.5), layout="constrained")
    for col, rng in enumerate(RANGES):
        for row, (costs, xlabel) in enumerate(((zs, "cost of a scalar package call [µs]"),
                                               (fmu["costs"], "cost of one FMU round trip [µs]"))):
            ax = axes[row, col]
            ode = [(label, rtol) for label, m, rtol in res["methods"] if m == "ode"]
            for q, marker, fill in (("e", "o", True), ("tau0", "s", False)):
                xs = [costs[(label, rng)] * 1e6 for label, _ in ode]
                ys = [min(max(acc[(label, rng)][q]["max_rel"], lo_clip), hi_clip) for label, _ in ode]
                ax.plot(xs, ys, color="0.3", lw=1, marker=marker, ms=5,
                        mfc="0.3" if fill else "none", label=f"ode, rtol 1e-3 ... 1e-12 ({q})")
                if q == "e":
                    for (label, rtol), x, y in zip(ode, xs, ys):
                        if rtol in (ode[0][1], ode[-1][1]) or len(ode) <= 4:
                            ax.annotate(f"{rtol:.0e}", (x, y), textcoords="offset points", xytext=(4, 4), fontsize=7)
                for label in ("exact", "paper_fit", "linear"):
                    y = acc[(label, rng)][q]["max_rel"]
                    ax.plot([costs[(label, rng)] * 1e6], [min(max(y, lo_clip), hi_clip)], marker=marker, ms=8,
                            color=colors[label], mfc=colors[label] if fill else "none", ls="none",
                            label=f"{label} ({q})")
            if row == 1:
                x_floor = fmu["costs"][("trivial FMU (floor)", rng)] * 1e6
                ax.axvline(x_floor, color="k", ls="--", lw=1)
                ax.text(x_floor * 0.93, lo_clip, "trivial FMU (floor)", rotation=90, fontsize=7, ha="right",
                        va="bottom")
            ax.axhline(1e-8, color="tab:red", ls=":", lw=0.8)
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_ylim(lo_clip / 3, hi_clip * 3)
            ax.set_xlabel(xlabel)
            ax.set_ylabel("largest relative error")
            ax.set_title(f"lambda in {rng}", fontsize=9)
            ax.grid(alpha=0.3, which="both")
            if row == 0 and col == 0:
                ax.legend(fontsize=6.5, ncol=2)
    fig.suptitle("Zener's e_ze (filled) and tau0 (open): error against cost. Off-scale errors are drawn at "
                 f"{hi_clip:g}; dotted: 1e-8", fontsize=9)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=90)
    plt.close(fig)
    try:  # a small palette PNG
        from PIL import Image

        with Image.open(path) as image:
            small = image.convert("RGB").quantize(colors=128, method=Image.Quantize.MEDIANCUT,
                                                  dither=Image.Dither.NONE)
        small.save(path, optimize=True)
    except ImportError:
        pass
    return path
