"""The posterior of the model parameters by Markov-chain Monte Carlo (emcee's affine-invariant ensemble
sampler), on the likelihood of :func:`restitution.fit.estimate.fit_parameters`: :func:`sample_posterior`.

Priors: flat in the fit coordinates over each parameter's physical domain (:data:`restitution.domain.DOMAIN`):
flat in ln theta for the positive parameters (and for a drop's v_1), flat in nu for Poisson's ratios.
The likelihood is the one the fit maximises, its noise level profiled out (the maximum over s or sigma_t);
for a level s with the scale-invariant prior 1/s, marginalising gives the same function of theta up to a
constant, so this is also the marginal posterior (for a drop's time origin t_1, also profiled, the exact
marginal would carry (n - 1)/2 instead of n/2 in the exponent: a 5 % wider posterior at n = 20).

Parameters that do not enter e (Eq. 2; :func:`restitution.fit.estimate.structural_reason`) are not sampled:
their posterior is their prior, and ``not_sampled`` says why.

emcee (``pip install emcee``, 3.x) is imported when a posterior is asked for.
"""
from __future__ import annotations

import time
import warnings
from dataclasses import dataclass, field

import numpy as np

from .estimate import _covariance, _optimum, _setup
from .forward import G_STANDARD

__all__ = ["sample_posterior", "PosteriorResult"]


@dataclass(frozen=True, eq=False)
class PosteriorResult:
    """Samples of the posterior: ``samples`` name -> values [SI] (the chains after ``burn`` steps, flattened;
    the parameters, then v1 for a drop whose first speed was fitted), ``interval95`` name -> the 2.5 and 97.5
    percentiles, ``median``; ``acceptance`` (mean acceptance fraction), ``autocorr`` name -> the integrated
    autocorrelation time [steps] (a rough estimate on short chains: emcee's own caution applies), the run's
    ``walkers``, ``steps`` (after burn-in), ``burn``, ``seed`` and ``elapsed`` [s]; ``not_sampled``: name -> why."""

    names: tuple
    samples: dict
    interval95: dict
    median: dict
    acceptance: float
    autocorr: dict
    walkers: int
    steps: int
    burn: int
    seed: int | None
    elapsed: float
    not_sampled: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        return {"parameters": {name: {"median": self.median[name], "interval95": list(self.interval95[name]),
                                      "autocorr": self.autocorr.get(name)} for name in self.names},
                "not_sampled": dict(self.not_sampled),
                "sampler": {"walkers": self.walkers, "steps": self.steps, "burn": self.burn,
                            "acceptance": self.acceptance, "seed": self.seed, "elapsed": self.elapsed}}


def sample_posterior(data, base: dict, names, *, g: float = G_STANDARD, v1: float | None = None,
                     h0: float | None = None, restitution_model: str = "e45", zener_method: str = "exact",
                     model_options: dict | None = None, start: dict | None = None, walkers: int | None = None,
                     steps: int = 400, burn: int = 50, seed: int | None = None,
                     rng: np.random.Generator | None = None, moves=None) -> PosteriorResult:
    """Sample the posterior of the parameters ``names`` given ``data``, the others at ``base`` (arguments as
    :func:`restitution.fit.estimate.fit_parameters`; ``start``: FMU name -> value where the search for the
    optimum begins, e.g. a fit's estimates). ``walkers`` (default max(32, 8 k) for k sampled coordinates) run
    ``burn`` + ``steps`` steps from the Gaussian approximation at the optimum (Hessian covariance C), so a
    short burn-in suffices. ``moves`` (emcee's): by default 70 % Metropolis steps proposing from
    N(0, 2.38^2 C / k) (the optimal scale for a Gaussian target; one model call for all walkers) and 30 %
    differential-evolution steps (affine invariant: they follow a curved or bounded posterior the Hessian
    misjudges); a 1-parameter posterior then has an autocorrelation time of ~4 steps. The walkers are
    evaluated together (one vectorised model call for rebound pairs, one per impact for a drop).
    ``seed`` (or ``rng``, a numpy Generator that draws one) makes the run reproducible. With the defaults a
    1-parameter posterior of 20 pairs takes ~0.2 s, of a 20-impact drop (v_1 fitted too) ~1-2 s."""
    import emcee

    t_start = time.perf_counter()
    if seed is None and rng is not None:
        seed = int(rng.integers(0, 2 ** 32 - 1))
    names, base, options, lik, reasons, free, problem = _setup(
        data, base, names, g=g, v1=v1, h0=h0, restitution_model=restitution_model, zener_method=zener_method,
        model_options=model_options, start=start)
    not_sampled = {name: reason for name, reason in reasons.items() if reason is not None}
    k = problem.k
    if k == 0:
        return PosteriorResult((), {}, {}, {}, float("nan"), {}, 0, 0, 0, seed, time.perf_counter() - t_start,
                               not_sampled)
    if steps < 1 or burn < 0:
        raise ValueError(f"steps = {steps}, burn = {burn}: steps >= 1, burn >= 0")
    walkers = int(walkers) if walkers is not None else max(32, 8 * k)
    walkers += walkers % 2
    if walkers < 2 * k:
        raise ValueError(f"walkers = {walkers}: emcee needs at least 2 per coordinate ({2 * k})")

    x_hat, _ = _optimum(problem, grid=25)
    cov = _covariance(problem, x_hat)
    generator = np.random.default_rng(seed)
    lower, upper = problem.lower, problem.upper
    try:
        chol = np.linalg.cholesky(cov + 1e-12 * np.eye(k))
        if not np.all(np.isfinite(chol)):
            raise np.linalg.LinAlgError
    except np.linalg.LinAlgError:
        chol = 0.1 * np.eye(k)
    span = upper - lower
    x_init = x_hat + generator.standard_normal((walkers, k)) @ chol.T
    x_init = np.clip(x_init, lower + 1e-9 * span, upper - 1e-9 * span)

    def log_probability(X):
        X = np.atleast_2d(X)
        out = np.full(X.shape[0], -np.inf)
        inside = np.all((X >= lower) & (X <= upper), axis=1)
        if inside.any():
            with np.errstate(all="ignore"):
                lp = -0.5 * problem.deviance(X[inside])
            out[inside] = np.where(np.isfinite(lp), lp, -np.inf)
        return out

    if moves is None:
        moves = [(emcee.moves.GaussianMove(cov * (2.38 ** 2 / k) + 1e-12 * np.eye(k)), 0.7),
                 (emcee.moves.DEMove(), 0.3)]
    sampler = emcee.EnsembleSampler(walkers, k, log_probability, vectorize=True, moves=moves)
    sampler.random_state = np.random.RandomState(seed if seed is not None else generator.integers(2 ** 32 - 1)) \
        .get_state()
    sampler.run_mcmc(x_init, burn + steps, progress=False)
    chain = sampler.get_chain(discard=burn, flat=True)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            tau = sampler.get_autocorr_time(discard=burn, tol=0, quiet=True)
        except Exception:  # noqa: BLE001 - a rough diagnostic only
            tau = np.full(k, np.nan)

    samples, interval, median, autocorr = {}, {}, {}, {}
    for j, c in enumerate(problem.coordinates):
        values = np.asarray(c.to_value(chain[:, j]), dtype=float)
        samples[c.name] = values
        lo, mid, hi = np.percentile(values, [2.5, 50.0, 97.5])
        interval[c.name] = (float(lo), float(hi))
        median[c.name] = float(mid)
        autocorr[c.name] = float(tau[j])
    return PosteriorResult(tuple(c.name for c in problem.coordinates), samples, interval, median,
                           float(np.mean(sampler.acceptance_fraction)), autocorr, walkers, steps, burn, seed,
                           time.perf_counter() - t_start, not_sampled)
