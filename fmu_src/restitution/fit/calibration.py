"""One calibration, from a user's terms to a result: :func:`fit` takes the data (a file or a dataset), the
named bodies and the parameters to fit, runs the estimate (:mod:`.estimate`) and, asked for, the posterior
(:mod:`.posterior`), and returns a :class:`Calibration` that the report (:mod:`.report`) prints, writes
as JSON and draws."""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from .datasets import ImpactTimes, Recording, ReboundPairs, check_drop, check_drop_speeds
from .estimate import FitResult, base_of, fit_parameters
from .forward import G_STANDARD, KEYS

__all__ = ["Calibration", "fit"]


@dataclass(frozen=True, eq=False)
class Calibration:
    """A calibration's inputs and results: ``data`` (the dataset fitted), ``base`` (impact keyword -> value
    [SI]: the named materials and geometry), ``result`` (:class:`~restitution.fit.estimate.FitResult`),
    ``posterior`` (:class:`~restitution.fit.posterior.PosteriorResult`, or None without ``bayes``), ``g``
    [m/s^2] and ``h0`` [m] of a drop."""

    data: object
    base: dict
    result: FitResult
    posterior: object = None
    g: float = G_STANDARD
    h0: float | None = None

    def __getitem__(self, name: str):
        return self.result[name]

    @property
    def fitted_params(self) -> dict:
        """impact keyword -> value [SI] of the fitted curve: ``base`` with the identifiable estimates and, for a
        practically non-identifiable parameter, the value where the likelihood is largest (the best fit, where
        the residuals are taken; the data do not determine it, so it is not reported as an estimate). A
        structurally non-identifiable parameter keeps its given value."""
        best = {KEYS[p.name]: p.estimate if p.estimate is not None else p.best
                for p in self.result.parameters.values()}
        return {**self.base, **{key: value for key, value in best.items() if value is not None}}

    def to_dict(self) -> dict:
        """The result as JSON-ready values (:meth:`FitResult.to_dict`), with each parameter's posterior
        interval (``bayes95``) where a posterior was sampled, and the inputs."""
        out = self.result.to_dict()
        if self.posterior is not None:
            post = self.posterior.to_dict()
            for name, values in post["parameters"].items():
                if name in out["parameters"]:
                    out["parameters"][name]["bayes95"] = values["interval95"]
                    out["parameters"][name]["bayes_median"] = values["median"]
            out["posterior"] = {"sampler": post["sampler"], "not_sampled": post["not_sampled"]}
        out["data"]["source"] = getattr(self.data, "source", "")
        out["inputs"] = {"base": dict(self.base), "g": self.g, "h0": self.h0}
        return out

    def __str__(self) -> str:
        from .report import table

        return table(self)


def _dataset(data):
    if isinstance(data, (ReboundPairs, ImpactTimes, Recording)):
        return data
    from .reading import read_data

    return read_data(Path(data))


def fit(data, sphere, plate, fit, *, g: float = G_STANDARD, h0: float | None = None, bayes: bool = False,
        seed: int | None = None, **options) -> Calibration:
    """Fit the parameters ``fit`` (FMU names, e.g. ``["plate.Sy"]``) of the impact of ``sphere``
    (:class:`restitution.Sphere`) on ``plate`` (:class:`restitution.Plate`) to ``data``: a path (a CSV of
    rebound pairs ``v_in,v_out[,sigma]`` [m/s] or of impact times ``t_impact`` [s], or a WAV recording of a
    drop) or a dataset (:mod:`restitution.fit.datasets`). Every other parameter is the bodies'.

    ``g`` [m/s^2] and ``h0`` [m] (the drop height; None: the first impact speed is fitted) apply to a drop;
    ``bayes``: also sample the posterior with emcee (``seed`` for repeatable draws); ``options``: more keywords
    of :func:`restitution.fit.estimate.fit_parameters` (``restitution_model``, ``zener_method``, ...).
    Returns a :class:`Calibration` (``str()`` a table with units, ``to_dict()`` the JSON). DataError or
    ValueError, one line, for bad data or names."""
    check_drop(g, h0)
    dataset = _dataset(data)
    if dataset.kind != "rebound_pairs":
        check_drop_speeds(dataset.times if isinstance(dataset, Recording) else dataset, g)
    names = [fit] if isinstance(fit, str) else list(fit)
    base = base_of(sphere, plate)
    times = dataset.times if isinstance(dataset, Recording) else dataset
    result = fit_parameters(times, base, names, g=g, h0=h0, **options)
    posterior = None
    if bayes:
        from .posterior import sample_posterior

        posterior = sample_posterior(times, base, names, g=g, h0=h0, seed=seed, **options)
    return Calibration(dataset, base, result, posterior, g, h0)
