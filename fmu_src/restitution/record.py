"""The result of one impact (or one array of impacts): :class:`ImpactResult`, the order of its record
(:data:`RECORD_REALS`, :data:`RECORD_FLAGS`, :data:`RECORD`) and the record as the FMUs and the sweep tables
publish it (:func:`published`, every value finite). Plain data and two small functions: the C record's
header, the interface tables and the agreement checks read the fields without loading the physics;
:mod:`restitution.model` computes them (and names them too, as it always did)."""
from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

from ._num import is_scalar, minimum, where

__all__ = ["ImpactResult", "Real", "Flag", "RECORD_REALS", "RECORD_FLAGS", "RECORD", "EDGE_ECHO_PUBLISHED_MAX",
           "ENDLESS", "published"]

#: The largest ``edge_echo`` the FMUs and the sweep tables publish [1] (:func:`published`): an unbounded
#: plate (or no contact) has an infinite echo ratio, and every published output must be finite.
#: 1e9 contact times is far beyond any echo that matters (the monitor's threshold is 1).
EDGE_ECHO_PUBLISHED_MAX = 1e9


#: The annotations of :class:`ImpactResult`'s fields: a real (a float, or an array of floats) or a flag
#: (a bool, or an array of bools). The C record of one impact and the equivalence tests read them
#: (:data:`RECORD_REALS`, :data:`RECORD_FLAGS`): a field's annotation is its C type (double or int).
Real = object
Flag = object


@dataclass(frozen=True)
class ImpactResult:
    """Everything one impact (or one array of impacts) produces. Units in brackets."""

    e: Real  #: apparent COR, Eq. (20) [1]
    v_rebound: Real  #: sphere speed away from the plate after impact, e * v [m/s]
    e_ep: Real  #: elastoplastic COR, Eq. (7) or (8) [1]
    V_c: Real  #: critical (yield onset) velocity, Eq. (6) [m/s]
    V_star: Real  #: normalised impact speed v / V_c [1]
    eps_y: Real  #: yield strain, Eq. (3) [1]
    e_ze: Real  #: Zener's COR [1]
    lam: Real  #: Zener's parameter lambda, Eq. (12) [1]
    tau0: Real  #: dimensionless contact time [1]
    T: Real  #: Zener's time unit, Eq. (9) [s]
    t_contact: Real  #: contact duration T tau0 [s] (0 when v = 0: no impact)
    m_a: Real  #: sphere mass [kg]
    m_eff: Real  #: equivalent plate mass, Eq. (19) [kg] (+inf for e_ze = 1)
    mass_ratio: Real  #: m_a / m_eff = (1 - e_ze)/(1 + e_ze), Eq. (19) [1], in [0, 1] (0 for e_ze = 1)
    v_plate: Real  #: plate velocity after impact, Eq. (17) [m/s]
    wave_delay: Real  #: Zener's ejection time over its half-space value, tau0(lambda)/tau0(0) [1] (section 4)
    edge_echo: Real  #: first dilatational edge echo 2a/c_L over the contact time [1] (+inf: unbounded plate)
    plasticity_used: Flag  #: JGM contributed (e_ep < 1 was applied)
    plate_waves_used: Flag  #: Zener contributed (e_ze was computed)
    lambda_in_range: Flag  #: lambda <= 1.5, Zener's studied range
    vstar_in_range: Flag  #: V* <= 1000, JGM's fit range
    e_negative: Flag  #: e < 0: the sphere keeps moving with the plate
    contact_ends: Flag  #: tau0 is finite (False: the linear method at lambda >= 2 never releases)
    concurrent: Flag  #: wave_delay <= 1.8136 (its value at lambda = 1.5): plastic and wave processes overlap
    edge_clear: Flag  #: edge_echo >= 1: no edge echo returns during the contact

    @property
    def valid(self):
        """Inside both models' validated ranges."""
        return _both(self.lambda_in_range, self.vstar_in_range)

    def as_dict(self) -> dict:
        d = dict(self.__dict__)  # the fields, in order: a frozen dataclass has no other instance attributes
        d["valid"] = self.valid
        return d

    def __repr__(self) -> str:
        """The answer and what qualifies it: e and its two parts, the rebound speed, where the impact
        sits in each model's range, and every flag (for arrays: the range of e and how many impacts
        raise each flag). Every field is also an attribute; :meth:`as_dict` gives them all."""
        if is_scalar(self.lam):
            return (f"ImpactResult: e = {self.e:.4g} (e_ep = {self.e_ep:.4g} elastoplastic, "
                    f"e_ze = {self.e_ze:.4g} plate waves), v_rebound = {self.v_rebound:.4g} m/s\n"
                    f"  V* = {self.V_star:.4g} (V_c = {self.V_c:.4g} m/s), lambda = {self.lam:.4g}, "
                    f"t_contact = {self.t_contact:.4g} s\n"
                    f"  valid = {self.valid}: lambda <= 1.5 (lambda_in_range) {self.lambda_in_range}, "
                    f"V* <= 1000 (vstar_in_range) {self.vstar_in_range}\n"
                    + "  " + ", ".join(f"{name} = {getattr(self, name)}" for name in _REPR_FLAGS) + "\n"
                    + "  monitors: " + ", ".join(f"{value} = {getattr(self, value):.4g} ({flag} {getattr(self, flag)})"
                                                 for value, flag in _REPR_MONITORS))
        e = np.asarray(self.e)
        n = e.size
        counts = ", ".join(f"{name} {int(np.count_nonzero(getattr(self, name)))}"
                           for name in ("lambda_in_range", "vstar_in_range") + _REPR_FLAGS
                           + tuple(flag for _value, flag in _REPR_MONITORS))
        finite = e[np.isfinite(e)]
        span = f"e in [{finite.min():.4g}, {finite.max():.4g}]" if finite.size else "no finite e"
        return (f"ImpactResult of {n} impacts, shape {e.shape}: {span}; valid at "
                f"{int(np.count_nonzero(self.valid))} of {n}\n  impacts with each flag true: {counts}")


#: The result record of one impact, in order: :class:`ImpactResult`'s real fields, then its flags and
#: ``valid`` (a property: both models inside their validated ranges). The C physics' ``rst_impact_result``
#: (generated by restitution.fmu.physics_c.result_header), the agreement of the package and the C
#: (:mod:`restitution.agreement`) and the tests' ctypes view are written from these two lists, so a new
#: field is one edit here (docs/adding_an_output.md).
RECORD_REALS = tuple(f.name for f in fields(ImpactResult) if f.type == "Real")
RECORD_FLAGS = tuple(f.name for f in fields(ImpactResult) if f.type == "Flag") + ("valid",)
#: The names of :func:`impact_record_at`'s values, in order: :data:`RECORD_REALS`, then :data:`RECORD_FLAGS`,
#: which is :class:`ImpactResult`'s fields in order (its reals come first), then ``valid``.
RECORD = RECORD_REALS + RECORD_FLAGS
if RECORD != tuple(f.name for f in fields(ImpactResult)) + ("valid",):  # a field out of place: fail at import
    raise RuntimeError("ImpactResult's Real fields must all come before its Flag fields (the record's order)")
_RECORD_AT = {name: i for i, name in enumerate(RECORD)}  # name -> position in a record
_BY_NAME = {name: name for name in RECORD}  # name -> key in a dict of the fields
_LAMBDA_OK_AT, _VSTAR_OK_AT = _RECORD_AT["lambda_in_range"], _RECORD_AT["vstar_in_range"]


def _both(lambda_in_range, vstar_in_range):
    """``valid``: inside both models' validated ranges (a bool of two bools, else an array)."""
    if lambda_in_range.__class__ is bool and vstar_in_range.__class__ is bool:
        return lambda_in_range and vstar_in_range
    return np.logical_and(lambda_in_range, vstar_in_range)


#: The flags shown by ``repr`` beside ``valid`` and its two parts.
_REPR_FLAGS = ("plasticity_used", "plate_waves_used", "e_negative", "contact_ends")
#: The monitors of the assumptions, with their flags, shown by ``repr`` on a line of their own.
_REPR_MONITORS = (("wave_delay", "concurrent"), ("edge_echo", "edge_clear"))


#: Outputs that are +inf where the contact never ends (``contact_ends`` False: the linear method at
#: lambda >= 2, whose oscillator never returns to zero force).
ENDLESS = ("tau0", "t_contact", "wave_delay")


def published(values):
    """``values`` (:meth:`ImpactResult.as_dict`, or a record of :func:`impact_record_at`) as the FMUs and the
    sweep tables publish them: every value finite. Result writers (OMSimulator's, for one) drop a whole time
    point for one inf, so where the contact never ends tau0 and t_contact read 0 beside ``contact_ends`` =
    False, and the equivalent plate mass is published as ``mass_ratio`` (0 for a half-space) instead of
    m_eff = +inf; ``edge_echo`` is capped at :data:`EDGE_ECHO_PUBLISHED_MAX` (+inf for an unbounded plate)
    and ``wave_delay`` reads 0 with tau0 where the contact never ends.
    Nothing else changes; the package's own results keep the infinities. A dict gives a dict; a record
    gives a record (itself where nothing changes, else a list in the same order). A dict of some outputs
    (``impact(outputs=...)``) needs ``contact_ends`` and ``edge_echo`` among them."""
    at = _BY_NAME if values.__class__ is dict else _RECORD_AT  # where each value sits
    ends, echo = values[at["contact_ends"]], values[at["edge_echo"]]
    if ends is True and echo.__class__ is float:  # one impact whose contact ends
        if echo <= EDGE_ECHO_PUBLISHED_MAX:  # a bounded plate
            return values
        out = _copy(values)  # an unbounded plate (+inf), the FMUs' default
        out[at["edge_echo"]] = EDGE_ECHO_PUBLISHED_MAX
        return out
    out = _copy(values)
    out[at["edge_echo"]] = minimum(echo, EDGE_ECHO_PUBLISHED_MAX)
    if ends is True or (ends.__class__ is np.ndarray and ends.all()):  # every contact ends: one reduction,
        return out                                                      # not three whole-array selections
    for name in ENDLESS:
        if at is _RECORD_AT or name in values:  # a dict of some outputs (impact(outputs=...)): those it has
            out[at[name]] = where(ends, values[at[name]], 0.0)
    return out


def _copy(values):
    """A dict or a record, as one that :func:`published` may change."""
    return dict(values) if values.__class__ is dict else list(values)
