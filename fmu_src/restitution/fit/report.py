"""What a calibration shows its user: :func:`table` (on screen, with units), :func:`write_json` (``--json``)
and :func:`plot` (``--plot``: the data, the fitted e(v) or bounce train with its 95 % band, the points
outside the model's validated range marked)."""
from __future__ import annotations

import math

import numpy as np

from ..assumptions import E_NEGATIVE_MEANING
from .datasets import ImpactTimes, Recording, ReboundPairs
from .forward import KEYS, bounce_train, restitution_at

__all__ = ["table", "write_json", "plot", "band_params", "bound_words"]

#: SI unit -> the kind of quantity restitution.units formats (MPa, GPa, mm, ...).
_KINDS = {"Pa": "pressure", "m": "length", "kg/m3": "density"}


def _value(value: float, unit: str) -> str:
    from ..units import format_quantity

    if unit in _KINDS and value > 0:
        return format_quantity(float(f"{value:.5g}"), _KINDS[unit])
    return f"{value:.5g}" + ("" if unit == "1" else f" {unit}")


def table(calibration) -> str:
    """The result on screen: what was fitted to what, each parameter's estimate and 95 % interval (and the
    posterior's, with ``--bayes``) with units, or why the data cannot determine it; the combinations the data
    determine together; the noise; the points outside the validated range."""
    result, data = calibration.result, calibration.data
    kind = {"rebound_pairs": "rebound pairs", "impact_times": "impact times", "recording": "impacts found in a recording"}
    lines = [f"fit of {result.n} {kind.get(data.kind, data.kind)}{' from ' + data.source if data.source else ''} "
             f"({result.evaluations} model evaluations, {result.elapsed:.2g} s)"]
    lof = result.lack_of_fit
    if lof.get("detected"):
        lines.append(f"  WARNING: the model does not describe these data: {lof['words']}. The numbers below assume "
                     "it does; do not trust them")
    width = max(len(name) for name in result.parameters)
    for p in result.parameters.values():
        if not p.identifiable:
            lines.append(f"  {p.name:<{width}}  {_not_identifiable(p)}")
            continue
        interval = ("no 95 % interval" if p.ci95 is None else
                    f"95 % [{_value(p.ci95[0], p.unit)}, {_value(p.ci95[1], p.unit)}] (profile likelihood)")
        text = f"  {p.name:<{width}}  {_value(p.estimate, p.unit):>12}   {interval}"
        post = calibration.posterior
        if post is not None and p.name in post.interval95:
            lo, hi = post.interval95[p.name]
            text += f"; posterior [{_value(lo, p.unit)}, {_value(hi, p.unit)}]"
        lines.append(text + (f"; {p.note}" if p.note else ""))
    for c in result.combinations:
        lines.append(f"  determined together: {c['expression']} = {c['value']:.5g} (+-{100 * c['relative_sd']:.2g} %), "
                     f"correlation {c['correlation']:+.3f}")
    noise = result.noise
    if noise.get("model") == "relative":
        lines.append(f"  noise: {100 * noise['s']:.3g} % of v_out (estimated from the residuals)")
    elif noise.get("model") == "timing_jitter":
        lines.append(f"  timing jitter: {noise['sigma_t'] * 1e6:.3g} us (estimated from the residuals)")
    elif noise.get("model") == "known":
        lines.append(f"  noise: sigma given; chi2 = {noise['chi2']:.3g} for {noise['dof']} degrees of freedom "
                     f"(upper-tail probability {noise['p_value']:.2g})")
    if result.out_of_range:
        lines.append(f"  {result.out_of_range} of {result.n} points outside the model's validated range "
                     "(lambda > 1.5, V* > 1000 or e < 0): kept, marked in the plot and the JSON")
    negative = int(np.count_nonzero(result.flags.get("e_negative", ()))) if result.flags else 0
    if negative:
        lines.append(f"  e < 0 (e_negative) at {negative} of {result.n} points: {E_NEGATIVE_MEANING}")
    return "\n".join(lines)


def bound_words(p) -> str:
    """"plate.Sy > 400 MPa" for a parameter with a one-sided ``bound`` ("" without one)."""
    if not p.bound:
        return ""
    side, value = next(iter(p.bound.items()))
    return f"{p.name} {'>' if side == 'lower' else '<'} {_value(value, p.unit)}"


def _not_identifiable(p) -> str:
    if p.identifiability != "practical":
        return f"not identifiable: {p.reason}"
    if not p.bound:
        return f"not identifiable from these data (practically): {p.reason}"
    words = "from below" if "lower" in p.bound else "from above"
    hint = p.reason[p.reason.index(" (there the"):] if " (there the" in p.reason else ""
    return (f"not identifiable from these data (practically): the data bound it only {words}, {bound_words(p)} at "
            f"95 %; its profile likelihood stays within the 95 % threshold up to the edge of its "
            f"domain{hint}")


def write_json(path, calibration) -> None:
    """``calibration.to_dict()`` into ``path``, atomically (non-finite numbers as null)."""
    from ..output_files import write_json as write_record

    write_record(path, calibration.to_dict(), "--json")


def band_params(calibration, draws: int = 400) -> list[dict]:
    """Parameter sets whose model curves span the 95 % band: posterior draws (at most 200) where a
    posterior was sampled; else, for one parameter, the ends of its profile interval; for several, ``draws``
    sets from the normal approximation at the optimum (the fitted coordinates, ln theta or nu, with their
    standard errors and correlation), so that correlated parameters move together (the corners of their
    separate intervals would draw a band far wider than the data allow). Seeded: the same picture each run."""
    fitted = calibration.fitted_params
    post = calibration.posterior
    if post is not None and post.names:
        n = len(next(iter(post.samples.values())))
        pick = np.linspace(0, n - 1, min(n, 200)).astype(int)
        return [{**fitted, **{KEYS[name]: float(post.samples[name][i]) for name in post.names if name in KEYS}}
                for i in pick]
    result = calibration.result
    known = [p for p in result.parameters.values() if p.ci95 is not None]
    if len(known) <= 1:
        return [{**fitted, KEYS[p.name]: end} for p in known for end in p.ci95] or [fitted]
    names = [name for name in result.correlation_names if name in {p.name for p in known}]
    index = [list(result.correlation_names).index(name) for name in names]
    se = np.array([result.parameters[name].se for name in names])
    corr = np.asarray(result.correlation_matrix)[np.ix_(index, index)]
    if not (np.all(np.isfinite(se)) and np.all(np.isfinite(corr))):
        return [{**fitted, KEYS[p.name]: end} for p in known for end in p.ci95]
    z = np.random.default_rng(0).multivariate_normal(np.zeros(len(names)), corr * np.outer(se, se), size=draws,
                                                     check_valid="ignore")
    sets = []
    for row in z:
        values = {}
        for name, dz in zip(names, row):
            estimate = result.parameters[name].estimate
            values[KEYS[name]] = estimate + dz if name.endswith(".nu") else estimate * math.exp(dz)
        sets.append({**fitted, **values})
    return sets


def _band(curves) -> tuple[np.ndarray, np.ndarray]:
    """The 2.5 and 97.5 percentiles of the curves at each point (the min and max of two profile ends)."""
    curves = np.asarray(curves)
    if len(curves) <= 2:
        return curves.min(axis=0), curves.max(axis=0)
    return np.percentile(curves, 2.5, axis=0), np.percentile(curves, 97.5, axis=0)


def _pairs_axes(ax, calibration):
    data, result = calibration.data, calibration.result
    v = np.geomspace(data.v_in.min() * 0.8, data.v_in.max() * 1.25, 200)
    curves = np.array([restitution_at(v, params, calibration.result.options or None).e
                       for params in band_params(calibration)])
    e_fit = restitution_at(v, calibration.fitted_params, calibration.result.options or None).e
    ax.fill_between(v, *_band(curves), color="tab:blue", alpha=0.25, label="95 % band")
    ax.plot(v, e_fit, color="tab:blue", label="fitted e(v)")
    out = np.asarray(result.flags["any"], dtype=bool)
    e_data = data.v_out / data.v_in
    ax.plot(data.v_in[~out], e_data[~out], "o", color="black", ms=4, label="measured v_out / v_in")
    if out.any():
        ax.plot(data.v_in[out], e_data[out], "x", color="tab:red", ms=6, label="outside the validated range")
    ax.set_xscale("log")
    ax.set_xlabel("approach speed v_in [m/s]")
    ax.set_ylabel("coefficient of restitution e [1]")


def _times_axes(ax, calibration):
    data, result = calibration.data, calibration.result
    times = data.times if isinstance(data, Recording) else data
    n = times.n
    v1 = float(result.nuisance["v1"]["estimate"])  # fitted, or the one h0 gives
    trains = [bounce_train(v1, n, params, g=calibration.g, options=result.options or None).intervals
              for params in band_params(calibration)]
    fit = bounce_train(v1, n, calibration.fitted_params, g=calibration.g, options=result.options or None).intervals
    k = np.arange(1, n)
    low, high = _band(trains)
    ax.fill_between(k, low * 1e3, high * 1e3, color="tab:blue", alpha=0.25, label="95 % band")
    ax.plot(k, fit * 1e3, color="tab:blue", label="fitted bounce train")
    measured = np.diff(times.t) * 1e3
    out = np.asarray(result.flags["any"], dtype=bool)[1:] if len(result.flags["any"]) == n else np.zeros(n - 1, bool)
    ax.plot(k[~out], measured[~out], "o", color="black", ms=4, label="measured intervals")
    if out.any():
        ax.plot(k[out], measured[out], "x", color="tab:red", ms=6, label="outside the validated range")
    ax.set_yscale("log")
    ax.set_xlabel("bounce k")
    ax.set_ylabel("time between impacts k and k+1 [ms]")


def plot(path, calibration) -> None:
    """The picture of a calibration into ``path`` (PNG, PDF or SVG by its suffix): rebound pairs as e(v)
    with the fitted curve and its 95 % band; impact times as the intervals between impacts against the
    fitted bounce train; a recording also as its waveform with the impacts found marked."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ..output_files import atomic_write

    data = calibration.data
    rows = 2 if isinstance(data, Recording) else 1
    fig, axes = plt.subplots(rows, 1, figsize=(7, 4.2 * rows), squeeze=False)
    if isinstance(data, ReboundPairs):
        _pairs_axes(axes[0, 0], calibration)
    elif isinstance(data, (ImpactTimes, Recording)):
        _times_axes(axes[0, 0], calibration)
    if isinstance(data, Recording):
        ax = axes[1, 0]
        t = np.arange(data.samples.size) / data.rate
        ax.plot(t, data.samples, lw=0.4, color="0.3")
        for onset in data.times.t:
            ax.axvline(onset, color="tab:red", lw=0.6)
        ax.set_xlabel("time [s]")
        ax.set_ylabel("recording [1]")
        ax.set_title(f"{data.times.n} impacts found (red)", fontsize=9)
    result = calibration.result
    estimates = ", ".join([f"{p.name} = {_value(p.estimate, p.unit)}" for p in result.parameters.values()
                           if p.estimate is not None]
                          + [f"{bound_words(p)} (95 %, not identifiable)" for p in result.parameters.values()
                             if p.bound])
    title = f"restitution fit: {estimates or 'nothing identifiable'}"
    if result.lack_of_fit.get("detected"):
        title += "\nlack of fit: the model does not describe these data"
    axes[0, 0].set_title(title, fontsize=10, color="tab:red" if result.lack_of_fit.get("detected") else "black")
    axes[0, 0].legend(fontsize=8)
    fig.tight_layout()
    atomic_write(path, lambda tmp: fig.savefig(tmp), "--plot")
    plt.close(fig)
