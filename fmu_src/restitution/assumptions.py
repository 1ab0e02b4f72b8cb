"""Where one impact leaves the model's validated domain, in words: the conditions the FMUs log (once per
instance and condition), and that :func:`restitution.cosim.bounce` and the scene runner warn about.

Each condition reads the fields of one impact (:meth:`restitution.ImpactResult.as_dict`, or the
published values, :func:`restitution.model.published`) and names the quantity, its value and its limit.
The thresholds are the model's own (docs/assumptions.md): Zener's studied range lambda <= 1.5
(:data:`restitution.zener.LAMBDA_STUDIED_MAX`), the JGM fits' V* <= 1000
(:data:`restitution.jgm.VSTAR_FIT_MAX`), e >= 0, and the edge echo after the contact
(:func:`restitution.zener.edge_clear`). The native FMUs' C backend writes the same messages
(``rst_native_impact_fmu.c``); the tests compare the two.
"""
from __future__ import annotations

import warnings

__all__ = ["CONDITIONS", "departures", "AssumptionWarning", "warn_departures", "E_NEGATIVE_MEANING",
           "VALID_MEANING", "meaning_lines"]

#: What e < 0 means (the flag ``e_negative``), in the words every report showing e < 0 gives beside it
#: (``restitution cor``, the fit report, a sweep's statistics, a scene's summary; docs/assumptions.md).
E_NEGATIVE_MEANING = ("the sphere keeps moving with the plate after the impact instead of bouncing back: Eq. (20) "
                      "gives e < 0 where e_ep or e_ze is near 0 (a thin plate, a hard impact); a result of the "
                      "model, not an error, and it does not make valid false")
#: What ``valid`` means, where it is shown beside one impact (docs/assumptions.md, "Validated ranges").
VALID_MEANING = ("inside the models' validated ranges, lambda <= 1.5 and V* <= 1000 (outside them e is an "
                 "extrapolation); it does not cover e < 0 (e_negative)")


def meaning_lines(n_negative: int | None, n_invalid: int, of: int, what: str = "impacts",
                  zero_negative: bool = True) -> list[str]:
    """Lines saying how many of ``of`` cases have e < 0 (``e_negative``; None: not known, no line; 0: a
    line only with ``zero_negative``) and how many lie outside the validated ranges (``valid`` false),
    each with what it means where there are any."""
    lines = []
    if n_negative is not None and (n_negative or zero_negative):
        lines.append(f"e < 0 (e_negative): {n_negative:,} of {of:,} {what}"
                     + (f": {E_NEGATIVE_MEANING}" if n_negative else ""))
    lines.append(f"valid = false (outside the models' validated ranges, lambda <= 1.5 and V* <= 1000): "
                 f"{n_invalid:,} of {of:,} {what}" + ("; their e is an extrapolation" if n_invalid else ""))
    return lines


class AssumptionWarning(UserWarning):
    """An impact outside the model's validated domain (the result is computed and reported, not clipped)."""


def _lambda(v):
    return (f"zener.lambda = {v['lam']:.4g} is above 1.5, the range Zener's plate-wave model was studied on: "
            f"e = {v['e']:.4g} is an extrapolation (valid = false)")


def _vstar(v):
    return (f"jgm.V_star = {v['V_star']:.4g} is above 1000, the range of the JGM fits: "
            f"e = {v['e']:.4g} is an extrapolation (valid = false)")


def _negative(v):
    return f"e = {v['e']:.4g} is below 0: the sphere keeps moving with the plate after the impact (e_negative)"


def _edge(v):
    return (f"monitor.edge_echo = {v['edge_echo']:.4g} is below 1: a wave reflected from the plate's edge "
            "returns during the contact, which Zener's unbounded plate excludes (edge_clear = false)")


#: (name, the flag field that is True where the impact is inside, its message from the impact's values),
#: in the order the messages come.
CONDITIONS = (
    ("lambda", "lambda_in_range", _lambda),
    ("V_star", "vstar_in_range", _vstar),
    ("e_negative", None, _negative),
    ("edge_echo", "edge_clear", _edge),
)


def departures(values: dict) -> list[tuple[str, str]]:
    """(condition name, message) for each condition that one impact's ``values`` (a field -> value
    mapping, with the flags) violates; empty inside the validated domain."""
    out = []
    for name, inside, message in CONDITIONS:
        violated = values["e_negative"] if inside is None else not values[inside]
        if violated:
            out.append((name, message(values)))
    return out


def warn_departures(impacts, warned: set | None = None, stacklevel: int = 3) -> set:
    """Warn (:class:`AssumptionWarning`) once per condition over ``impacts`` (an iterable of value
    mappings, as :func:`departures` takes), skipping the conditions already in ``warned``; returns the
    conditions warned about, ``warned`` included."""
    warned = set() if warned is None else warned
    for values in impacts:
        for name, message in departures(values):
            if name not in warned:
                warned.add(name)
                warnings.warn(message, AssumptionWarning, stacklevel=stacklevel)
    return warned
