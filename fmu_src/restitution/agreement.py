"""How far two correct evaluations of the model may differ: tolerances from conditioning.

Two evaluations of the same inputs (the scalar and array paths, the package and an FMU, two
CPUs) differ only in the last bits of the elementary functions they call: numpy's SIMD
``exp``/``log``/``pow`` and the C library's differ by one ulp for some arguments. How much an
output moves then is its conditioning, not a fixed number: ``m_eff`` near a half-space or
``tau0`` of the paper fit at lambda ~ 100 amplify an ulp by orders of magnitude more than ``V_c``.

:func:`tolerances` bounds the difference case by case. Every last-bit difference inside the
model is equivalent to a relative perturbation of the order of an ulp of some input (each
intermediate is a product of powers of the inputs, or a function of one), so for an output y

    |y1 - y2| <= ULPS * eps * (1 + sum_i |d ln y / d ln x_i|) * |y|   (positive quantities)
    |y1 - y2| <= ULPS * eps * (1 + sum_i |d y / d ln x_i|)             (e, e_ep: may be 0 or change sign)

with the log-sensitivities measured by central differences over the 11 inputs. Near a branch
(a flag's threshold, the auto-skip decisions, a kink) the difference quotient is large and the
tolerance with it: exactly where two evaluations may legitimately land on different sides. A flag
may differ only where a perturbation of one input by the difference step ``STEP`` flips it.
The ``ode`` method adds its own tolerance (its adaptive steps may be chosen differently).
"""
from __future__ import annotations

import numpy as np

from .model import PARAMETERS, RECORD_FLAGS, RECORD_REALS, impact

__all__ = ["ULPS", "STEP", "ABSOLUTE", "REALS", "FLAGS", "tolerances", "disagreements"]

#: Ulps by which the elementary functions of two evaluations may differ in effect: 1 ulp per
#: call, a few calls on the longest path to any output (lambda and T: up to 8 powers), x4 margin.
ULPS = 32
#: Relative step of the central differences [1]: far above rounding, far below the model's scales.
STEP = 1e-6
EPS = float(np.finfo(float).eps)
#: Outputs compared in absolute terms (bounded, may be 0 or change sign); v_rebound = e v in m/s.
ABSOLUTE = ("e", "e_ep", "v_rebound")
#: The real outputs and the flags of :class:`restitution.ImpactResult` (its result record).
REALS, FLAGS = RECORD_REALS, RECORD_FLAGS
_INPUTS = ("v",) + tuple(name for name, _unit, _kind in PARAMETERS)


def _sensitivity(up, down, name):
    """|dy/d ln x| (absolute outputs) or |d ln y / d ln x| from values at x (1 +- STEP)."""
    with np.errstate(all="ignore"):
        if name in ABSOLUTE:
            s = np.abs(up - down) / (2.0 * STEP)
        else:
            s = np.abs(np.log(np.abs(up)) - np.log(np.abs(down))) / (2.0 * STEP)
    same = up == down  # equal (including equal infinities and exact zeros): no sensitivity
    return np.where(same, 0.0, np.where(np.isnan(s), np.inf, s))


def tolerances(v, params: dict, **options) -> tuple[dict, dict]:
    """(real_tolerances, flag_may_differ) for ``impact(v, **params, **options)``.

    ``real_tolerances[name]``: largest allowed |y1 - y2| per case (arrays broadcast over the
    inputs); ``flag_may_differ[name]``: True where a flag may legitimately differ.
    ``options`` are :func:`restitution.impact`'s keywords.
    """
    values = {"v": np.asarray(v, dtype=float), **{k: np.asarray(x, dtype=float) for k, x in params.items()}}
    method = options.get("zener_method", "exact")
    probe = dict(options, zener_method="exact") if method == "ode" else dict(options)  # same ODE, same conditioning
    base = impact(values["v"], **{k: values[k] for k in _INPUTS[1:]}, **probe)
    total = {name: np.zeros(np.shape(getattr(base, name))) for name in REALS}
    flips = {name: np.zeros(np.shape(getattr(base, name)), dtype=bool) for name in FLAGS}
    for name in _INPUTS:
        shifted = []
        for factor in (1.0 + STEP, 1.0 - STEP):
            moved = dict(values, **{name: values[name] * factor})
            if name.endswith("_nu"):  # keep nu <= 0.5: a relative step of nu near 0.5 stays inside
                moved[name] = np.minimum(moved[name], 0.5)
            # a probe a step beyond an input checked above (and maybe beyond the domain's edge): unchecked
            shifted.append(impact(moved["v"], **{k: moved[k] for k in _INPUTS[1:]}, **probe, validate=False))
        up, down = shifted
        for out in REALS:
            total[out] = total[out] + _sensitivity(getattr(up, out), getattr(down, out), out)
        for flag in FLAGS:
            b = getattr(base, flag)
            flips[flag] |= (getattr(up, flag) != b) | (getattr(down, flag) != b)

    def scale(out):  # what the bound multiplies: |y| for relative outputs, 1 (or v, in m/s) for absolute ones
        if out == "v_rebound":
            return values["v"]
        return 1.0 if out in ABSOLUTE else np.abs(getattr(base, out))

    with np.errstate(invalid="ignore"):
        tol = {out: ULPS * EPS * (1.0 + total[out]) * scale(out) for out in REALS}
    # an infinite sensitivity (a jump) times |y| = 0 is NaN: there the two may differ by the jump
    tol = {out: np.where(np.isnan(t), np.inf, t) for out, t in tol.items()}
    if method == "ode":  # plus the solver's own tolerance: its adaptive steps may be chosen differently
        rtol = options.get("ode_rtol", 1e-10)
        e_ze = np.asarray(base.e_ze)
        with np.errstate(divide="ignore", invalid="ignore"):
            via_deficit = np.where(e_ze < 1.0, e_ze / (1.0 - e_ze), 0.0)
        for out in REALS:
            factor = 1.0 + via_deficit if out in ("m_eff", "mass_ratio", "v_plate") else 1.0
            tol[out] = tol[out] + 100.0 * rtol * factor * scale(out)
    return tol, flips


def disagreements(a, b, tol: dict, flips: dict) -> list[str]:
    """Descriptions of every output where results ``a`` and ``b`` (ImpactResult-like, same shape)
    differ by more than ``tol`` or in a flag that may not differ; empty when they agree. Outputs
    that either result lacks (an FMU has no eps_y) are skipped."""
    problems = []
    for name in REALS:
        if not (hasattr(a, name) and hasattr(b, name)):
            continue
        x, y = np.asarray(getattr(a, name), dtype=float), np.asarray(getattr(b, name), dtype=float)
        with np.errstate(invalid="ignore"):
            ok = (x == y) | (np.abs(x - y) <= tol[name])
        if not np.all(ok):
            i = np.unravel_index(np.argmin(ok), ok.shape) if ok.ndim else ()
            problems.append(f"{name}: {x[i]!r} vs {y[i]!r} (allowed {np.broadcast_to(tol[name], ok.shape)[i]:.3g}) "
                            f"at index {tuple(int(j) for j in i)}")
    for name in FLAGS:
        if not (hasattr(a, name) and hasattr(b, name)):
            continue
        x, y = np.asarray(getattr(a, name)), np.asarray(getattr(b, name))
        bad = (x != y) & ~np.broadcast_to(flips[name], np.shape(x))
        if np.any(bad):
            i = np.unravel_index(np.argmax(bad), bad.shape) if bad.ndim else ()
            problems.append(f"{name}: {x[i]} vs {y[i]} at index {tuple(int(j) for j in i)}")
    return problems
