"""What the data can determine (used by :mod:`restitution.fit.estimate`): structural and practical
identifiability, and the combinations that strongly correlated parameters determine together.

Three outcomes for each requested parameter (``identifiability``):

* ``"structural"``: the parameter does not enter e for these bodies at the data's speeds
  (:func:`structural_reason`: e unchanged, to within rounding, when it is scaled by 0.5 and 2). The chief case
  is Eq. (2): only the body with the smaller C(nu) Sy yields, so the other body's Sy enters neither V_c (Eq. 6)
  nor eps_y (Eq. 3). Nothing is fitted.
* ``"practical"``: the parameter enters e, but its 95 % profile-likelihood interval reaches the edge of its
  physical domain (Raue et al., Bioinformatics 25, 2009: such a parameter is practically non-identifiable).
  No estimate and no interval are reported. Open on both sides: no bound either. Open on one side only, the
  data still bound it on the other: ``bound`` {"lower": value} (or "upper"), the end of the same 95 % profile
  set {theta: 2 (log L_max - log L_profile(theta)) <= threshold} whose two ends are an identifiable
  parameter's 95 % interval (threshold chi2_1(0.95) = 3.841 with a known noise, its small-sample form with an
  estimated one: :func:`restitution.fit.estimate.profile_threshold`). One procedure whatever the set's shape,
  so its coverage is that of the 95 % set: the bound is not a one-sided 95 % bound at chi2_1(0.90) = 2.706.
  That choice would make the data decide between a two-sided interval and a one-sided bound and then use a
  laxer threshold for the latter ("flip-flopping", Feldman and Cousins, Phys. Rev. D 57, 1998). Measured on
  brass on S7 tool steel, 200 sets of 20 pairs at 1 % noise, true plate.Sy = 404 MPa, just below the Eq. (2)
  switch at ~407.7 MPa: 67 bounds, 58 of them below the truth at 2.706, 62 at the 95 % set's threshold.
  For a regular likelihood open on one side the bound holds the truth 97.5 % of the time; where the
  parameter truly does not enter e (the truth in the flat part of the profile) it always does. A typical
  case is Eq. (2) again: brass on S7 tool steel, where the sphere yields first for every plate.Sy above
  ~407.7 MPa, so the data say only plate.Sy > ~400 MPa.
* ``"identifiable"``: an estimate and its 95 % profile interval.
"""
from __future__ import annotations

import math

import numpy as np

from ..jgm import poisson_coefficient
from .forward import KEYS, UNITS, domain, restitution_at

__all__ = ["structural_reason", "practical_reason", "combinations", "correlation_of", "IDENTIFIABLE", "STRUCTURAL",
           "PRACTICAL"]

IDENTIFIABLE, STRUCTURAL, PRACTICAL = "identifiable", "structural", "practical"
#: Tolerance on e for "does not change" (rounding: e is computed to ~1e-15; a parameter that does not
#: enter leaves it bit-identical).
_E_ROUNDING = 1e-13
#: |correlation| above which two fitted parameters are reported as determined only in combination.
CORRELATED = 0.95


def _scaled_values(name: str, value: float) -> list[float]:
    low, high = domain(name)
    if KEYS[name].endswith("_nu"):
        candidates = [0.5 * value, min(2.0 * value, 0.49)] if value > 0.0 else [0.1, 0.25]
    else:
        candidates = [0.5 * value, 2.0 * value]
    return [min(max(c, low), high) for c in candidates if min(max(c, low), high) != value]


def _who_yields(params: dict) -> tuple[str, float, float]:
    """("sphere" or "plate", C(nu) Sy of the sphere, of the plate) [Pa] (Eq. 2; the sphere on a tie)."""
    cs = poisson_coefficient(params["sphere_nu"]) * params["sphere_Sy"]
    cp = poisson_coefficient(params["plate_nu"]) * params["plate_Sy"]
    return ("sphere" if cs <= cp else "plate"), cs, cp


def structural_reason(speeds, base: dict, name: str, options: dict | None = None) -> str | None:
    """Why the parameter ``name`` (FMU name) cannot be estimated from e at ``speeds`` [m/s] with the other
    parameters at ``base`` (impact keywords), or None when e depends on it there: e unchanged, to within
    rounding, with the parameter scaled by 0.5 and by 2 (clipped to its domain)."""
    key = KEYS[name]
    speeds = np.asarray(speeds, dtype=float)
    e0 = np.asarray(restitution_at(speeds, base, options).e)
    for value in _scaled_values(name, base[key]):
        e1 = np.asarray(restitution_at(speeds, {**base, key: value}, options).e)
        if not np.all(np.abs(e1 - e0) <= _E_ROUNDING):
            return None
    given = f"left at its given value {base[key]:.4g} {UNITS[name]}"
    if key.endswith("_Sy"):
        body = key.split("_")[0]
        yields, cs, cp = _who_yields(base)
        if yields != body:
            other = "plate" if body == "sphere" else "sphere"
            sign = "<" if yields == "sphere" else ">"
            return (f"{name} does not enter e: the {other} yields first, C(nu) Sy = {cs:.3g} Pa (sphere) {sign} "
                    f"{cp:.3g} Pa (plate) (Eq. 2), so only the {other}'s Sy sets V_c and eps_y; {given}")
        vstar = np.asarray(restitution_at(speeds, base, options).V_star)
        if np.all(vstar <= 1.0):
            return (f"{name} does not enter e: every impact stays elastic (V* = v/V_c <= {vstar.max():.3g} <= 1 at "
                    f"the data's speeds, Eqs. 6, 8: e_ep = 1); {given}")
    return (f"{name} does not enter e at the data's speeds (e unchanged when it is scaled by 0.5 and 2); {given}")




def correlation_of(cov: np.ndarray) -> np.ndarray:
    sd = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    with np.errstate(all="ignore"):
        corr = cov / np.outer(sd, sd)
    corr[~np.isfinite(corr)] = np.nan
    corr = 0.5 * (corr + corr.T)  # symmetric to the last bit (the inverse is not)
    np.fill_diagonal(corr, 1.0)
    return corr


def _term(coord, a: float) -> str:
    return f"{coord.name}^{a:.3g}" if coord.log else f"exp({a:.3g} {coord.name})"


def combinations(problem, x, cov, corr, fitted: list[int]) -> tuple:
    """For each group of fitted parameters of ``problem`` (a :class:`restitution.fit.likelihood.Problem`)
    linked by |correlation| > CORRELATED: the determined combination (stiff eigenvector of the group's
    Hessian, the other parameters profiled: inv of the covariance block) and the undetermined direction
    (the sloppy one)."""
    groups, seen = [], set()
    for i in range(len(fitted)):
        if i in seen:
            continue
        group, stack = [], [i]
        while stack:
            j = stack.pop()
            if j in seen:
                continue
            seen.add(j)
            group.append(j)
            stack.extend(k for k in range(len(fitted)) if k not in seen and abs(corr[j, k]) > CORRELATED)
        if len(group) > 1:
            groups.append(sorted(group))
    out = []
    for group in groups:
        idx = [fitted[g] for g in group]
        coords = [problem.coordinates[i] for i in idx]
        C = cov[np.ix_(idx, idx)]
        w, V = np.linalg.eigh(C)  # ascending variance: first = stiffest direction of the Hessian
        comb = {}
        for label, vec, var in (("determined", V[:, 0], w[0]), ("undetermined", V[:, -1], w[-1])):
            a = vec / vec[np.argmax(np.abs(vec))]
            sd = math.sqrt(max(float(a @ C @ a), 0.0))
            comb[label] = (a, sd)
        a, sd = comb["determined"]
        log_value = float(sum(ai * (math.log(c.to_value(x[i])) if c.log else c.to_value(x[i]))
                              for ai, c, i in zip(a, coords, idx)))
        value = math.exp(log_value)
        sub = corr[np.ix_(group, group)]
        rho = float(sub[np.unravel_index(np.argmax(np.abs(sub - np.eye(len(group)))), sub.shape)])
        a_sloppy, sd_sloppy = comb["undetermined"]
        out.append({
            "parameters": [c.name for c in coords],
            "exponents": {c.name: float(ai) for c, ai in zip(coords, a)},
            "expression": " * ".join(_term(c, ai) for c, ai in zip(coords, a)),
            "value": value, "relative_sd": sd, "ci95": [value * math.exp(-1.96 * sd), value * math.exp(1.96 * sd)],
            "correlation": rho,
            "undetermined_exponents": {c.name: float(ai) for c, ai in zip(coords, a_sloppy)},
            "undetermined_relative_sd": sd_sloppy,
            "description": "the data determine this product of powers (stiff eigenvector of the Hessian in log "
                           "space, the other parameters profiled); along the undetermined exponents the "
                           "parameters trade off against each other"})
    return tuple(out)


def practical_reason(name: str, coord, open_side: str | None, bound: float | None, params_at_open_end: dict) -> str:
    """Why ``name`` is practically non-identifiable, in words: its profile stays within the 95 % threshold up
    to the domain's ``open_side`` ("upper", "lower"; None: both) bound; ``bound`` [SI] the bound on the other
    side (the end of the 95 % profile set; None when open on both). With an Eq. (2) hint where, at the open
    end, the other body yields first."""
    if open_side is None:
        return (f"the data do not bound {name}: the profile likelihood stays within the 95 % threshold of its "
                f"maximum over the whole domain [{coord.low:.3g}, {coord.high:.3g}] {coord.unit}")
    relation, words = (">", "from below") if open_side == "upper" else ("<", "from above")
    text = (f"the data bound it only {words}, {name} {relation} {bound:.4g} {coord.unit} at 95 %; the "
            f"profile likelihood stays within the 95 % threshold of its maximum up to the domain's {open_side} "
            f"bound {coord.high if open_side == 'upper' else coord.low:.3g} {coord.unit}")
    key = KEYS.get(name, "")
    if key.endswith("_Sy"):
        body = key.split("_")[0]
        yields, _, _ = _who_yields(params_at_open_end)
        if yields != body:
            text += f" (there the {yields} yields first and {name} no longer enters e, Eq. 2)"
    return text
