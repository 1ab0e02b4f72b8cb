"""Properties of the package over the whole declared domain (restitution.model.DOMAIN, the min/max the
FMUs declare), searched with hypothesis: every output finite except the documented infinities, the
CORs in their physical bounds, tau0 at least the method's value at lambda = 0, v_rebound = e v, and
the validity flags consistent with lambda and V*, and every value the FMUs publish finite. Runs derandomized (the same examples on every
machine), parameters drawn log-uniformly so that every decade, and both ends, are visited."""
import math

import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings

import restitution as r
from restitution.model import DOMAIN, published
from restitution.sweep.spec import OUTPUTS as PUBLISHED_OUTPUTS  # (FMU name, field, type) of every FMU output
from restitution.zener import TAU0_HERTZ, zener_linear, zener_paper_fit

from cases import CASES

pytestmark = pytest.mark.numerics

TAU0_AT_ZERO = {"exact": TAU0_HERTZ, "ode": TAU0_HERTZ, "paper_fit": zener_paper_fit(0.0)[1],
                "linear": zener_linear(0.0)[1]}
#: the documented infinities, as predicates on (result, case)
DOCUMENTED_INFINITE = {
    "m_eff": lambda res, case: res.e_ze == 1.0,
    "T": lambda res, case: case["v"] == 0.0,
    "tau0": lambda res, case: case["zener_method"] == "linear" and res.lam >= 2.0,
    "t_contact": lambda res, case: case["zener_method"] == "linear" and res.lam >= 2.0,
    "wave_delay": lambda res, case: case["zener_method"] == "linear" and res.lam >= 2.0,
    # an unbounded plate (0 or inf) or no contact: no echo ever returns
    "edge_echo": lambda res, case: case.get("plate_edge_distance", math.inf) in (0.0, math.inf) or case["v"] == 0.0,
}
FLAGS = ("plasticity_used", "plate_waves_used", "lambda_in_range", "vstar_in_range", "e_negative", "contact_ends",
         "concurrent", "edge_clear")





def check_properties(case):
    with np.errstate(all="raise"):  # no overflow, invalid operation or division by zero on the way
        res = r.impact(**case)
    method, v = case["zener_method"], case["v"]
    for name, value in res.as_dict().items():
        if name in FLAGS or name == "valid":
            assert value.__class__ is bool, name
            continue
        assert not math.isnan(value), (name, case)
        if math.isinf(value):
            assert value > 0 and name in DOCUMENTED_INFINITE and DOCUMENTED_INFINITE[name](res, case), (name, case)
    assert -1.0 <= res.e <= 1.0 and 0.0 <= res.e_ep <= 1.0 and 0.0 <= res.e_ze <= 1.0, case
    assert res.V_c > 0.0 and res.m_a > 0.0 and res.lam >= 0.0 and res.eps_y > 0.0, case
    assert res.v_rebound == res.e * v  # the definition, bit for bit: one multiplication
    if res.plate_waves_used:
        assert res.tau0 >= TAU0_AT_ZERO[method] * (1.0 - 4e-16), case
    else:
        assert res.e_ze == 1.0 and res.tau0 in (TAU0_AT_ZERO[method], TAU0_HERTZ), case
    if not res.plasticity_used:
        assert res.e_ep == 1.0
    assert res.lambda_in_range == (res.lam <= 1.5) and res.vstar_in_range == (res.V_star <= 1000.0)
    assert res.valid == (res.lambda_in_range and res.vstar_in_range)
    # what the FMUs and sweep tables publish: every value finite; m_a/m_b in [0, 1], 0 only where e_ze = 1
    assert res.contact_ends == math.isfinite(res.tau0), case
    assert 0.0 <= res.mass_ratio <= 1.0 and (res.mass_ratio > 0.0 or res.e_ze == 1.0), case
    shown = published(res.as_dict())
    for name, field, kind in PUBLISHED_OUTPUTS:
        assert kind == "Boolean" or math.isfinite(shown[field]), (name, shown[field], case)
    assert res.e_negative == (res.e < 0.0)
    if v == 0.0:
        assert res.e == 1.0 and res.t_contact == 0.0 and res.lam == 0.0
    return res


@settings(max_examples=1500, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(CASES)
@example({**{name: DOMAIN[name][0] for name in DOMAIN}, "v": DOMAIN["v"][1], "sphere_nu": 0.0, "plate_nu": 0.0,
          "restitution_model": "e45", "zener_method": "paper_fit", "plasticity": "on", "plate_waves": "on"})
@example({**{name: DOMAIN[name][1] for name in DOMAIN}, "v": 1e-12, "sphere_nu": 0.4999, "plate_nu": 0.4999,
          "restitution_model": "e44", "zener_method": "linear", "plasticity": "on", "plate_waves": "on"})
def test_every_case_of_the_declared_domain_is_finite_bounded_and_consistent(case):
    check_properties(case)


@settings(max_examples=40, deadline=None, derandomize=True)
@given(CASES.map(lambda c: {**c, "zener_method": "ode"}))
def test_the_ode_method_has_the_same_properties(case):
    check_properties(case)


@settings(max_examples=200, deadline=None, derandomize=True)
@given(CASES)
def test_arrays_give_what_floats_give(case):
    """The array path has the same properties; its values agree with the float path (restitution.agreement
    derives per-case tolerances; here a loose 1e-9 relative bound suffices for a property test)."""
    one = check_properties(case)
    many = r.impact(**{**case, "v": np.array([case["v"], case["v"]])})
    for name, value in one.as_dict().items():
        got = getattr(many, name) if name != "valid" else many.valid
        assert np.all(got == value) or np.allclose(got, value, rtol=1e-9, atol=0.0), (name, got, value)
