"""The case sets several test modules share: the hard-case matrix (material pairs at their extremes,
speeds, thickness ratios), random cases over the declared domain, hypothesis's strategy for it, and the
FMU's outputs with the ImpactResult field each publishes (written out here, independently of the
interface table, so a test catches a change of either)."""
from __future__ import annotations

import math

import numpy as np
from hypothesis import strategies as st

import restitution as r
from restitution.model import DOMAIN, PARAMETERS

D = 6.35e-3  # [m]
M = r.MATERIALS
STIFF_NU0 = r.Material("stiff, nu = 0", 200e9, 0.0, 1.0e9, 7800.0)
SOFT_NU499 = r.Material("soft, nu = 0.499", 70e9, 0.499, 0.3e9, 2700.0)
PAIRS = {
    "s2/al6061": (M["s2_tool_steel"], M["al_6061"]),  # Table 3, the paper's checkpoint
    "T4-A1": r.table4_case("A1"),  # heavy stiff sphere, light soft plate: lambda up to ~1e4
    "T4-B4": r.table4_case("B4"),
    "glass/glass": (M["borosilicate_glass"], M["borosilicate_glass"]),  # Sy = 1e12 on both sides
    "glass/al6061": (M["borosilicate_glass"], M["al_6061"]),  # brittle sphere
    "wc/glass": (M["tungsten_carbide"], M["borosilicate_glass"]),  # brittle plate
    "nu0/nu0.499": (STIFF_NU0, SOFT_NU499),
    "nu0.499/nu0": (SOFT_NU499, STIFF_NU0),
}
SPEEDS = [0.0, 1e-12, 1e-9, 1e-6, 1e-3, 0.1, 1.0, 10.0, 100.0, 1e3]
T_OVER_D = [0.01, 0.05, 0.2, 1.0, 10.0, 100.0, 1e3]
# FMU output -> ImpactResult field (the public interface table)
FMU_REALS = {"e": "e", "v_rebound": "v_rebound", "jgm.e": "e_ep", "jgm.V_c": "V_c", "jgm.V_star": "V_star",
             "zener.e": "e_ze", "zener.lambda": "lam", "zener.tau0": "tau0", "zener.t_contact": "t_contact",
             "plate.mass_ratio": "mass_ratio", "plate.v_after": "v_plate", "sphere.m": "m_a",
             "monitor.wave_delay": "wave_delay", "monitor.edge_echo": "edge_echo"}
FMU_FLAGS = {"valid": "valid", "zener.in_range": "lambda_in_range", "jgm.in_range": "vstar_in_range",
             "e_negative": "e_negative", "effects.plasticity": "plasticity_used",
             "effects.plate_waves": "plate_waves_used", "zener.contact_ends": "contact_ends",
             "monitor.concurrent": "concurrent", "monitor.edge_clear": "edge_clear"}


def params_for(pair, t_over_d=1.0, d=D):
    sphere_mat, plate_mat = PAIRS[pair]
    return {**r.Sphere(sphere_mat, d).params(), **r.Plate(plate_mat, t_over_d * d).params()}


NAMES = tuple(name for name, _unit, _kind in PARAMETERS)


def random_cases(rng, n):
    """n cases log-uniform over DOMAIN (nu uniform in [0, 0.5)), a few at v = 0 and at the bounds."""
    def logu(lo, hi):
        return np.exp(rng.uniform(math.log(lo), math.log(hi), n))

    lo_v = 1e-9
    v = logu(lo_v, DOMAIN["v"][1])
    v[:3] = (0.0, DOMAIN["v"][1], 1e-300)
    params = {}
    for name in NAMES:
        if name.endswith("_nu"):
            params[name] = rng.uniform(0.0, 0.5, n)
            params[name][0] = 0.0
            params[name][1] = np.nextafter(0.5, 0.0)
        else:
            lo, hi = DOMAIN[name]
            params[name] = logu(lo, hi)
            params[name][1] = hi
            params[name][2] = lo
    return v, params


def random_preset_bodies(rng):
    """(sphere material, plate material, d [m], t [m]) drawn from ``rng``: two presets, a sphere from 0.3 mm
    to 30 mm, a plate from 1/30 to 10 sphere diameters (thin plates reach lambda > 1.5 and lambda >= 2)."""
    mats = list(r.MATERIALS.values())
    a, b = mats[rng.integers(len(mats))], mats[rng.integers(len(mats))]
    d = 10 ** rng.uniform(-3.5, -1.5)
    t = d * 10 ** rng.uniform(-1.5, 1.0)
    return a, b, d, t

def log_uniform(low, high):
    """Floats spread evenly in log10 between low > 0 and high, with both ends as likely examples."""
    return st.one_of(st.sampled_from([low, high]),
                     st.floats(math.log10(low), math.log10(high)).map(lambda x: min(max(10.0 ** x, low), high)))


def parameter(name):
    low, high = DOMAIN[name]
    if name == "v":
        return st.one_of(st.just(0.0), log_uniform(1e-12, high))
    return log_uniform(low, high)


POISSON = st.one_of(st.sampled_from([0.0, 0.25, math.nextafter(0.5, 0.0)]), st.floats(0.0, 0.5, exclude_max=True))
CASES = st.fixed_dictionaries({
    **{name: parameter(name) for name in DOMAIN},
    "sphere_nu": POISSON, "plate_nu": POISSON,
    "restitution_model": st.sampled_from(r.RESTITUTION_MODELS),
    "zener_method": st.sampled_from(("exact", "paper_fit", "linear")),
    "plasticity": st.sampled_from(r.EFFECT_MODES), "plate_waves": st.sampled_from(r.EFFECT_MODES),
    # the edge monitor's distance: unbounded (0, as the FMUs say it; the package's +inf too, which the FMUs'
    # finite values cannot carry: tests/physics/test_monitors.py) or anything from 1 um to 1 km
    "plate_edge_distance": st.one_of(st.just(0.0), log_uniform(1e-6, 1e3)),
})


def runs_ode(fmu) -> bool:
    """Whether the FMU at path ``fmu`` (a fixture's) computes zener_method = 4 (ode): the pythonfmu FMU
    does, the native ones (FMI 2.0 in fmi2/, FMI 3.0 in fmi3/) refuse it (docs/implementations.md)."""
    return not ({"fmi2", "fmi3"} & set(fmu.parts))
