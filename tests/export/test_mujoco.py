"""The MuJoCo export run in MuJoCo itself (from PyPI, the ``export`` extra): a sphere on a slide joint meets a
plane at the case's speed, stepped by mj_step. Without MuJoCo these tests skip and say so."""
from __future__ import annotations

import math

import pytest

from restitution.export import mujoco as export_mujoco
from restitution.export.hosts import ExportCase

mujoco = pytest.importorskip("mujoco", reason="MuJoCo is not installed (pip install \"restitution[export]\")")

#: Where in a step the contact begins: the first step in contact may find the sphere anywhere within one step.
PHASES = (0.0, 0.2, 0.4, 0.6, 0.8)


def _case(e: float, t_contact: float = 42e-6, v: float = 1.7) -> ExportCase:
    """A case with the given model e and contact time: a 9 mm sphere of 3 g (no material of the repository)."""
    return ExportCase(e=e, t_contact=t_contact, v=v, m_sphere=3.0e-3, R_sphere=4.5e-3, E_eff=80e9, m_eff=math.inf,
                      E1=200e9, nu1=0.29, E2=90e9, nu2=0.34, d=9e-3, t=5e-3, valid=True, lambda_in_range=True,
                      vstar_in_range=True, e_negative=False, contact_ends=True, concurrent=True, edge_clear=True,
                      plasticity_used=True, plate_waves_used=True)


@pytest.mark.parametrize("e", [0.2, 0.35, 0.5, 0.7, 0.85, 0.95])
def test_mujoco_gives_the_models_e_at_three_steps(e):
    """At the exported timestep (or t_contact/50 where that is coarser) and at half and a quarter of it, MuJoCo
    gives e within 1 % wherever in a step the contact begins; MuJoCo's step has first-order errors (its
    dashpot switches on at the contact), which the exported timestep bounds."""
    params = export_mujoco.parameters(_case(e))
    step = min(params["timestep"], params["t_contact"] / 50)
    for dt in (step, step / 2, step / 4):
        for phase in PHASES:
            achieved, _ = export_mujoco.mujoco_drop(params, dt, phase)
            assert achieved == pytest.approx(e, rel=0.01), (dt, phase, achieved)


@pytest.mark.parametrize("e", [0.2, 0.5, 0.95])
def test_finely_stepped_mujoco_gives_e_and_the_contact_time(e):
    """At t_contact/2000 MuJoCo's step error (first order: about 5 % x 50/n for e = 0.2 at its worst) is below
    0.2 %: the mapping itself (the clamped law's inverse, the impedance, the time constant) is what is tested.
    The contact lasts the model's t_contact to the same order (one step of 1/2000 and the same first order)."""
    params = export_mujoco.parameters(_case(e))
    achieved, contact = export_mujoco.mujoco_drop(params, params["t_contact"] / 2000, 0.5)
    assert achieved == pytest.approx(e, rel=0.002)
    assert contact == pytest.approx(params["t_contact"], rel=0.003)


@pytest.mark.parametrize("e, dt_steps", [(0.3, 60), (0.6, 25), (0.9, 12)])
def test_documented_step_is_mujocos_step(e, dt_steps):
    """The step written from MuJoCo's documentation (emulate_drop, which sets the exported timestep) is
    MuJoCo's: the same e to 1e-9 at coarse steps and every onset phase, so the timestep needs no MuJoCo."""
    params = export_mujoco.parameters(_case(e))
    dt = params["t_contact"] / dt_steps
    for phase in PHASES:
        assert export_mujoco.emulate_drop(params, params["v"], dt, phase)[0] == pytest.approx(
            export_mujoco.mujoco_drop(params, dt, phase)[0], rel=1e-9)


def test_the_unclamped_map_bounces_higher_in_mujoco():
    """MuJoCo discussion 3404: solref from the linear oscillator's formula for e = 0.75 bounced back higher.
    With that damping ratio (same time constant rule) the finely stepped MuJoCo drop gives about 0.76 here,
    the exact inverse 0.75."""
    params = export_mujoco.parameters(_case(0.75))
    naive = dict(params, solref=[params["solref"][0] * params["solref"][1] / params["dampratio_unclamped"],
                                 params["dampratio_unclamped"]])  # same omega = 1/(timeconst dampratio)
    dt = params["t_contact"] / 2000
    assert export_mujoco.mujoco_drop(naive, dt)[0] > 0.755 > 0.7515 > export_mujoco.mujoco_drop(params, dt)[0]
