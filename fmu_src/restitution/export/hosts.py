"""What every host export takes and gives: the impact to export (:class:`ExportCase`, made from
:func:`restitution.model.impact` by :func:`export_case`) and the interface of a host module.

Each host module (``restitution.export.mujoco``, ``.chrono``, ``.liggghts``, ``.yade``, ``.elastogap``)
defines::

    NAME: str        # "mujoco", "chrono", ...
    FORCE_LAW: str   # one paragraph: the host's normal force law as read from its source or manual,
                     # whether it clamps the force at zero, and what this export maps
    def parameters(case: ExportCase) -> dict
        # the JSON dict of the host's contract (docs/exports.md): always "e" and "t_contact", then the
        # host's own parameters, SI
        # (a host whose parameters depend on the time step sets TUNES_TO_STEP = True and takes
        #  parameters(case, dt), dt the user's step [s] or None for its default)
    def snippet(params: dict) -> str
        # ready-to-paste text in the host's syntax, from the dict parameters() gave
    def simulate_drop(params: dict, case: ExportCase, dt: float | None) -> dict
        # a normal drop of the case's sphere at case.v on the host's contact with these parameters:
        # {"e": achieved COR, "t_contact": the host's contact time [s],
        #  "law": "host itself" | "published force law, integrated here"}
        # dt None: the host's contact resolved finely (the mapping's own error); else the user's step [s]

``table`` is no host module: it is the model itself over a speed range (:mod:`restitution.export.table`).
The export wing imports only the physics below it (:mod:`restitution.model`, :mod:`restitution.materials`,
:mod:`restitution.options`, :mod:`restitution.output_files`, :mod:`restitution.domain`): the exported COR
is :func:`~restitution.model.impact`'s, never recomputed here.
"""
from __future__ import annotations

import importlib
import math
from dataclasses import dataclass

__all__ = ["ExportCase", "export_case", "HOST_MODULES", "HOSTS", "host_module", "FLAGS", "NOT_IMPORTABLE"]

#: host -> the module that exports to it (the interface above). ``table`` is handled by the command.
HOST_MODULES = {
    "mujoco": "restitution.export.mujoco",
    "chrono": "restitution.export.chrono",
    "liggghts": "restitution.export.liggghts",
    "yade": "restitution.export.yade",
    "elastogap": "restitution.export.elastogap",
}
#: Every HOST of ``restitution export HOST``.
HOSTS = (*HOST_MODULES, "table")
#: The ImpactResult flags an ExportCase carries (``valid`` is both range flags).
FLAGS = ("valid", "lambda_in_range", "vstar_in_range", "e_negative", "contact_ends", "concurrent", "edge_clear",
         "plasticity_used", "plate_waves_used")
#: What a host module that cannot be imported yet raises (a host whose module is not in this build).
NOT_IMPORTABLE = ModuleNotFoundError


@dataclass(frozen=True)
class ExportCase:
    """One impact to export, SI floats: the model's answer and the pair it is for."""

    e: float  #: the model's apparent COR, Eq. (20) [1]
    t_contact: float  #: the model's contact duration T tau0 [s]
    v: float  #: approach speed [m/s]
    m_sphere: float  #: sphere mass [kg]
    R_sphere: float  #: sphere radius [m]
    E_eff: float  #: contact modulus E' = E1' E2' / (E1' + E2'), Ei' = Ei / (1 - nui^2), Eq. (1) [Pa]
    m_eff: float  #: the model's equivalent plate mass, Eq. (19) [kg] (+inf for a half-space)
    E1: float  #: sphere's elastic modulus [Pa]
    nu1: float  #: sphere's Poisson's ratio [1]
    E2: float  #: plate's elastic modulus [Pa]
    nu2: float  #: plate's Poisson's ratio [1]
    d: float  #: sphere diameter [m]
    t: float  #: plate thickness [m]
    valid: bool  #: inside both models' validated ranges
    lambda_in_range: bool
    vstar_in_range: bool
    e_negative: bool
    contact_ends: bool
    concurrent: bool
    edge_clear: bool
    plasticity_used: bool
    plate_waves_used: bool

    def flags(self) -> dict:
        """The ImpactResult flags, by name."""
        return {name: getattr(self, name) for name in FLAGS}

    def refusal(self) -> str | None:
        """Why this case should not be exported without ``--allow-invalid`` (one phrase), or None."""
        if self.e_negative or not self.e >= 0.0:
            return f"e = {self.e:.4g} < 0: the sphere keeps moving with the plate, no host can bounce it back"
        if not self.contact_ends:
            return "the contact never ends (contact_ends = no)"
        if not self.valid:
            outside = [name for name in ("lambda_in_range", "vstar_in_range") if not getattr(self, name)]
            return f"outside the model's validated range ({', '.join(f'{n} = no' for n in outside)})"
        return None


def export_case(v: float, sphere, plate, d: float, t: float, edge: float = 0.0, **impact_options) -> ExportCase:
    """The :class:`ExportCase` of ``sphere`` (a :class:`~restitution.Material`) of diameter ``d`` [m]
    hitting ``plate`` (a Material) of thickness ``t`` [m] at ``v`` [m/s]; ``edge`` [m] the distance to the
    plate's nearest edge (0: unbounded); ``impact_options`` go to :func:`~restitution.model.impact`."""
    from .. import jgm
    from ..model import impact

    result = impact(v, **sphere.params("sphere"), sphere_d=d, **plate.params("plate"), plate_t=t,
                    plate_edge_distance=edge, **impact_options)
    flags = {name: bool(getattr(result, name)) for name in FLAGS}
    return ExportCase(e=float(result.e), t_contact=float(result.t_contact), v=float(v), m_sphere=float(result.m_a),
                      R_sphere=0.5 * d, E_eff=float(jgm.effective_modulus(sphere.E, sphere.nu, plate.E, plate.nu)),
                      m_eff=float(result.m_eff), E1=sphere.E, nu1=sphere.nu, E2=plate.E, nu2=plate.nu, d=d, t=t,
                      **flags)


def host_module(name: str):
    """The module of host ``name`` (:data:`HOST_MODULES`); KeyError for an unknown host."""
    return importlib.import_module(HOST_MODULES[name])


def finite_or_none(value: float):
    """``value`` for JSON: None where it is not finite (JSON has no inf)."""
    return value if math.isfinite(value) else None
