"""Sobol' sensitivity indices of a random sweep (``restitution sweep --sobol``).

The ``--random`` inputs are sampled with Saltelli's scheme on a scrambled Sobol' sequence
(:func:`SALib.sample.sobol.sample`, first and total order only: ``N (D + 2)`` cases for ``N`` base
samples and ``D`` inputs), and that matrix becomes the sweep's cases in place of the random draws:
:class:`SobolSpec` is a :class:`~restitution.sweep.spec.SweepSpec` whose draws are the design's
rows, so the engine (serial or Dask, package or FMU back end, parts and resume) runs it unchanged.
A :class:`SobolCollector` keeps the analysed outputs of each chunk as it arrives (the table is never
read back), and :func:`sobol_indices` gives S1 and ST with their bootstrap intervals
(:func:`SALib.analyze.sobol.analyze`) for each output of :data:`SOBOL_OUTPUTS`.

How a distribution becomes a SALib input (``problem["dists"]``, ``problem["bounds"]``):

- ``uniform:lo:hi`` -> ``unif [lo, hi]``; ``loguniform:lo:hi`` -> ``logunif [lo, hi]`` (SALib 1.6
  maps the Sobol' point u to lo (hi/lo)^u, uniform in log space, by scipy's ``loguniform.ppf``);
  ``normal:mean:sd`` -> ``norm [mean, sd]``;
- the relative forms draw the factor that scales the input's base value, as a random sweep does:
  ``uniform_rel:h`` -> ``unif [1 - h, 1 + h]``, ``normal_rel:sd`` -> ``norm [1, sd]``;
- ``choice`` (a discrete set) and a spread of zero (a constant) are refused.

The indices are defined only over the whole design: a case that could not be evaluated (``ok =
False``: a draw outside the model's domain, a negative normal draw of a modulus) breaks the pairing
of the Saltelli matrices, so an output with any such case gets no indices and the reason instead.
"""
from __future__ import annotations

import functools
import math
import warnings
from dataclasses import dataclass

import numpy as np

from .spec import OUTPUTS, SweepSpec

__all__ = ["SobolError", "SobolSpec", "SobolCollector", "SOBOL_OUTPUTS", "salib_problem", "saltelli_design",
           "sobol_indices", "format_indices", "ranking_warning", "refusals"]

#: Outputs analysed: key in the summary (the field of restitution.impact's result) -> table column (FMU name).
SOBOL_OUTPUTS = {key: name for name, key, _type in OUTPUTS if key in ("e", "e_ep", "e_ze", "t_contact")}
#: Bootstrap resamples of the intervals (SALib's default). At N = 4096 and two inputs the whole
#: analysis takes well under a second; the model evaluations dominate.
RESAMPLES = 100
CONF_LEVEL = 0.95
#: The ranking warning (see :func:`ranking_warning`): an interval half-width above this is too wide
#: to state an index to one decimal ...
MAX_ST_CONF = 0.1
#: ... and two total indices this far apart are meant to be ranked, so their intervals must not overlap.
RANK_GAP = 0.05
#: A design of at most this many values (1 MiB) travels with the spec to the workers, so they need not
#: import SALib (pandas and scipy.stats: 1 to 2 s a worker, measured, against 0.4 s for the 16,384 cases
#: of N = 4096 over two inputs); a bigger one, which would go with every task, is built on each worker.
SHIPPED_VALUES = 2**17


class SobolError(ValueError):
    """A sweep that cannot be a Sobol' design (one line naming the option)."""


def _salib_input(name: str, kind: str, args: tuple) -> tuple[str, list]:
    """(SALib dist, bounds) of one ``--random`` distribution (see the module docstring)."""
    given = f"--random {name}={kind}"
    if kind == "choice":
        raise SobolError(f"{given}: a choice among values cannot be a Sobol' input (the indices need a "
                         f"continuous distribution): give it with --set, or run without --sobol")
    spread = {"uniform": args[-1] - args[0], "loguniform": args[-1] - args[0], "normal": args[-1],
              "normal_rel": args[0], "uniform_rel": args[0]}[kind]
    if not spread > 0:
        raise SobolError(f"{given}: a spread of zero is a constant, not a Sobol' input: give it with --set")
    if kind == "uniform":
        return "unif", [args[0], args[1]]
    if kind == "loguniform":
        return "logunif", [args[0], args[1]]
    if kind == "normal":
        return "norm", [args[0], args[1]]
    if kind == "normal_rel":
        return "norm", [1.0, args[0]]
    return "unif", [1.0 - args[0], 1.0 + args[0]]


def salib_problem(dists: dict) -> dict:
    """SALib's problem dict of the random inputs ``name -> (kind, args)`` (as parsed by
    :func:`restitution.sweep.values.parse_distribution`), in their order."""
    inputs = {name: _salib_input(name, kind, args) for name, (kind, args) in dists.items()}
    return {"num_vars": len(inputs), "names": list(inputs), "dists": [d for d, _ in inputs.values()],
            "bounds": [b for _, b in inputs.values()]}


@functools.lru_cache(maxsize=4)
def _design(names: tuple, dists: tuple, bounds: tuple, n: int, seed: int) -> np.ndarray:
    # Cached per process: every chunk a worker evaluates takes its rows from one design, built once
    # there from the spec (the matrix itself never travels with the tasks).
    from SALib.sample import sobol

    problem = {"num_vars": len(names), "names": list(names), "dists": list(dists),
               "bounds": [list(b) for b in bounds]}
    design = sobol.sample(problem, n, calc_second_order=False, scramble=True, seed=seed)
    design.flags.writeable = False
    return design


def saltelli_design(problem: dict, n: int, seed: int) -> np.ndarray:
    """The ``n (D + 2)`` x ``D`` Saltelli matrix of ``problem`` (rows A, AB_1 ... AB_D, B for each base
    sample), scrambled with ``seed``; the same for the same arguments in every process."""
    return _design(tuple(problem["names"]), tuple(problem["dists"]),
                   tuple(tuple(float(x) for x in b) for b in problem["bounds"]), int(n), int(seed))


@dataclass
class SobolSpec(SweepSpec):
    """A sweep whose cases are the Saltelli design of its random inputs: ``base_samples`` (N, a power
    of 2) base samples, ``samples`` = N (D + 2) cases. Build it with :meth:`from_dict`."""

    base_samples: int = 0

    def __post_init__(self):
        super().__post_init__()
        if not self.distributions:
            raise SobolError("--sobol needs the inputs to vary: give each with --random NAME=DIST")
        if self.grid or len(self.pairs) > 1:
            axes = [f"--grid {k}" for k in self.grid] + (["several --pair"] if len(self.pairs) > 1 else [])
            raise SobolError(f"--sobol samples the --random inputs at one point: {', '.join(axes)} makes a "
                             f"grid; give those values with --set (or one --pair) and sweep each point on its own")
        self.problem = salib_problem(self.distributions)
        n = self.base_samples
        if n < 2 or n & (n - 1):
            above = 2 ** max(1, math.ceil(math.log2(max(n, 1))))
            raise SobolError(f"--samples {n}: --sobol takes N base samples, a power of 2 >= 2 (the Sobol' "
                             f"sequence is balanced at powers of 2), e.g. --samples {above}")
        if self.samples != n * (self.problem["num_vars"] + 2):
            raise ValueError(f"samples = {self.samples}: a Sobol' design of {n} base samples over "
                             f"{self.problem['num_vars']} inputs has {n * (self.problem['num_vars'] + 2)} cases")
        small = self.n_cases * self.problem["num_vars"] <= SHIPPED_VALUES
        self._shipped = saltelli_design(self.problem, n, self.seed) if small else None

    @classmethod
    def from_dict(cls, data: dict) -> "SobolSpec":
        """The Sobol' design of a spec's random inputs, its ``samples`` the base samples N; SobolError
        (one line) when it cannot be one: no random input, a grid, a choice, N not a power of 2."""
        if not isinstance(data, dict) or not data.get("random"):
            raise SobolError("--sobol needs the inputs to vary: give each with --random NAME=DIST")
        n = data.get("samples", 1)
        if isinstance(n, bool) or not isinstance(n, (int, np.integer)):
            raise SobolError(f"samples = {n!r}: --sobol takes N base samples, an integer power of 2")
        spec = SweepSpec.from_dict({**data, "samples": 1})  # every other key checked as for any sweep
        return cls(**{**spec.as_dict(), "samples": int(n) * (len(spec.random) + 2)}, base_samples=int(n))

    def as_dict(self) -> dict:
        # Marks the design in a resumed run's manifest: a random sweep of as many samples is another sweep.
        return {**super().as_dict(), "design": "sobol-saltelli", "base_samples": self.base_samples}

    def _random_draws(self, start: int, stop: int) -> dict:
        design = self._shipped if self._shipped is not None else saltelli_design(
            self.problem, self.base_samples, self.seed)
        return {name: design[start:stop, j] for j, name in enumerate(self.problem["names"])}

    def describe(self) -> str:
        d = self.problem["num_vars"]
        return (f"{self.n_cases:,} cases: Sobol' design (Saltelli) of {', '.join(self.problem['names'])}, "
                f"{self.base_samples:,} base samples x ({d} + 2)")


class SobolCollector:
    """The analysed outputs and ``ok`` of each case of a :class:`SobolSpec`, copied from the chunks as
    they arrive (``run_sweep(..., on_chunk=collector)``); :meth:`analyze` gives the indices."""

    def __init__(self, spec: SobolSpec):
        self.spec = spec
        n = spec.n_cases
        self.outputs = {key: np.full(n, np.nan) for key in SOBOL_OUTPUTS}
        self.ok = np.zeros(n, dtype=bool)  # a case no chunk brought counts as not evaluated

    def __call__(self, start: int, stop: int, columns: dict) -> None:
        for key, column in SOBOL_OUTPUTS.items():
            self.outputs[key][start:stop] = columns[column]
        self.ok[start:stop] = columns["ok"]

    def analyze(self, resamples: int = RESAMPLES) -> dict:
        return sobol_indices(self.spec, self.outputs, self.ok, resamples)


def sobol_indices(spec: SobolSpec, outputs: dict, ok=None, resamples: int = RESAMPLES) -> dict:
    """``{"sobol": {output: {input: {"S1", "S1_conf", "ST", "ST_conf"}}}, "N", "evaluations", ...}`` of
    the outputs (``key -> values over the spec's cases``, in case order; any model's), ``ok`` marking
    the cases evaluated (default: those with a finite value). An output with a case not evaluated, or
    constant over the design, is left out of ``"sobol"`` and its reason given in ``"refused"``."""
    from SALib.analyze import sobol

    n = spec.n_cases
    ok = np.ones(n, dtype=bool) if ok is None else np.asarray(ok, dtype=bool)
    section = {"sobol": {}, "refused": {}, "N": spec.base_samples, "evaluations": n,
               "inputs": {name: {"dist": dist, "bounds": [float(x) for x in bounds]} for name, dist, bounds in
                          zip(spec.problem["names"], spec.problem["dists"], spec.problem["bounds"])},
               "resamples": resamples, "conf_level": CONF_LEVEL}
    for key, values in outputs.items():
        y = np.asarray(values, dtype=float)
        bad = ~ok | ~np.isfinite(y)
        if bad.any():
            section["refused"][key] = (
                f"{int(bad.sum()):,} of {n:,} cases of the Saltelli design could not be evaluated (ok = False: "
                f"inputs outside the model's domain): the indices need every case; narrow the --random "
                f"distributions (see the table's ok column)")
            continue
        if np.ptp(y) == 0:
            section["refused"][key] = f"{key} is the same in every case: no variance to apportion"
            continue
        with warnings.catch_warnings():  # SALib's "constant values" notice for a bootstrap resample
            warnings.simplefilter("ignore", UserWarning)
            # SALib reads a seed of 0 as "unseeded": shift it so every seed gives reproducible intervals
            result = sobol.analyze(dict(spec.problem), y, calc_second_order=False, num_resamples=resamples,
                                   conf_level=CONF_LEVEL, seed=spec.seed + 1)
        section["sobol"][key] = {name: {field: float(result[field][j]) for field in ("S1", "S1_conf", "ST", "ST_conf")}
                                 for j, name in enumerate(spec.problem["names"])}
    return section


def ranking_warning(section: dict) -> str | None:
    """One line when the intervals are too wide to rank the inputs, else None.

    The criterion, for each output: some ST_conf > :data:`MAX_ST_CONF`, or two inputs whose ST differ
    by at least :data:`RANK_GAP` (a difference meant to be ranked; closer ones are ties) while their
    intervals ST +- ST_conf overlap. The intervals shrink as 1/sqrt(N): four times the samples halves them."""
    unresolved = []
    for key, indices in section["sobol"].items():
        rows = sorted(indices.items(), key=lambda item: item[1]["ST"])
        wide = [name for name, s in rows if s["ST_conf"] > MAX_ST_CONF]
        overlap = [(a, b) for (a, sa), (b, sb) in zip(rows, rows[1:])
                   if sb["ST"] - sa["ST"] >= RANK_GAP and sb["ST"] - sa["ST"] <= sa["ST_conf"] + sb["ST_conf"]]
        if wide:
            unresolved.append(f"{key}: ST_conf > {MAX_ST_CONF} for {', '.join(wide)}")
        elif overlap:
            unresolved.append(f"{key}: the ST intervals of {' and '.join(overlap[0])} overlap")
    if not unresolved:
        return None
    return (f"warning: the Sobol' intervals are too wide to state the indices to one decimal or to rank the "
            f"inputs ({'; '.join(unresolved)}): more samples needed: --samples {4 * section['N']}")


def format_indices(section: dict) -> str:
    """The indices as a table, one block per output, with their intervals."""
    level = f"{section['conf_level']:.0%}"
    lines = [f"Sobol' indices ({section['N']:,} base samples, {section['evaluations']:,} evaluations; "
             f"+- the {level} bootstrap interval of {section['resamples']} resamples):"]
    names = list(section["inputs"])
    width = max(len(n) for n in names)
    shown = list(section["sobol"])  # the sweep's outputs in their usual order, then any other
    for key in [k for k in SOBOL_OUTPUTS if k in shown] + [k for k in shown if k not in SOBOL_OUTPUTS]:
        lines.append(f"  {key} (column {SOBOL_OUTPUTS[key]}):" if key in SOBOL_OUTPUTS else f"  {key}:")
        for name in names:
            s = section["sobol"][key][name]
            lines.append(f"    {name:{width}s}  S1 = {s['S1']:7.4f} +- {s['S1_conf']:.4f}   "
                         f"ST = {s['ST']:7.4f} +- {s['ST_conf']:.4f}")
    lines += [f"  {line}" for line in refusals(section)]
    return "\n".join(lines)


def refusals(section: dict) -> list[str]:
    """``"no Sobol' indices of e, e_ep: <reason>"``: the outputs left without indices, one line a reason."""
    by_reason = {}
    for key, reason in section["refused"].items():
        by_reason.setdefault(reason, []).append(key)
    return [f"no Sobol' indices of {', '.join(keys)}: {reason}" for reason, keys in by_reason.items()]
