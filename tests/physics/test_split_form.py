"""The split form of the model: impact_terms (what depends on the parameters only, once) and impact_at /
impact_record_at (per speed), as a co-simulation uses it. It must give what impact() gives, within each
output's conditioning (restitution.agreement: tolerances from central differences, never bit identity,
since the split evaluates products such as lambda's factors in another order), for many parameter sets
and speeds, v = 0 and impacts outside the validated ranges included; check its inputs as impact() does;
and its record must be the result's fields, then ``valid``."""
import math

import numpy as np
import pytest

import restitution as r
from restitution.model import (RECORD, RECORD_FLAGS, RECORD_REALS, ImpactResult, ImpactTerms, impact, impact_at,
                               impact_record_at, impact_terms, published)

from agree import assert_agree, stack
from cases import random_preset_bodies

NAMES = ("sphere_E", "sphere_nu", "sphere_Sy", "sphere_rho", "sphere_d",
         "plate_E", "plate_nu", "plate_Sy", "plate_rho", "plate_t")
OPTION_SETS = (
    {},  # the defaults: e45, exact, auto, auto
    dict(restitution_model="e44", zener_method="paper_fit", plasticity="on", plate_waves="on"),
    dict(zener_method="linear", plasticity="off", plate_waves="on"),  # lambda >= 2: the contact never ends
    dict(zener_method="linear", plate_waves="auto", effect_tolerance=1e-3),
    dict(plasticity="auto", plate_waves="off", effect_tolerance=0.0),
)


def _parameter_sets(n, seed):
    """Random material pairs (the presets), spheres from 0.3 mm to 30 mm, plates from 1/30 to 10 sphere
    diameters (thin plates reach lambda > 1.5, and lambda >= 2), edges: unbounded (0 or inf) or bounded."""
    rng = np.random.default_rng(seed)
    for k in range(n):
        a, b, d, t = random_preset_bodies(rng)
        params = dict(zip(NAMES, map(float, (a.E, a.nu, a.Sy, a.rho, d, b.E, b.nu, b.Sy, b.rho, t))))
        edge = (0.0, math.inf, float(d * 10 ** rng.uniform(-1, 3)))[k % 3]
        yield params, edge


# speeds: none, tiny (every effect skipped by "auto"), ordinary, V* far above JGM's fit range
SPEEDS = np.array([0.0, 1e-9, 1e-4, 0.05, 1.0, 3.7, 40.0, 600.0, 5e3])


@pytest.mark.parametrize("options", OPTION_SETS, ids=lambda o: ",".join(f"{k}={v}" for k, v in o.items()) or "defaults")
def test_the_split_form_gives_what_impact_gives(options):
    """One ImpactTerms per parameter set, every speed through it, in floats and as one array: each output
    within its conditioning of impact()'s at the same inputs, the flags equal except where a perturbation of
    an input by the tolerances' difference step flips them."""
    seen = {"lambda > 1.5": False, "V* > 1000": False, "v = 0": False, "never ends": False}
    for params, edge in _parameter_sets(12, seed=len(options)):
        terms = impact_terms(**params, plate_edge_distance=edge, **options)
        assert isinstance(terms, ImpactTerms) and terms.floats
        want = [impact(float(v), **params, plate_edge_distance=edge, **options) for v in SPEEDS]
        split = [impact_at(float(v), terms) for v in SPEEDS]
        grid = {k: np.full(SPEEDS.shape, x) for k, x in params.items()}
        opts = dict(options, plate_edge_distance=edge)
        assert_agree(stack(want), stack(split), SPEEDS, grid, f"floats {params}", **opts)
        assert_agree(stack(want), impact_at(SPEEDS, terms), SPEEDS, grid, f"array {params}", **opts)
        for res in split:  # the scalar mode's plain Python types
            assert all(type(x) is (bool if name in RECORD_FLAGS else float) for name, x in res.as_dict().items())
        seen["lambda > 1.5"] |= any(not res.lambda_in_range for res in want)
        seen["V* > 1000"] |= any(not res.vstar_in_range for res in want)
        seen["v = 0"] |= want[0].t_contact == 0.0
        seen["never ends"] |= any(not res.contact_ends for res in want)
    assert seen["lambda > 1.5"] and seen["V* > 1000"] and seen["v = 0"], seen
    if options.get("zener_method") == "linear" and options.get("plate_waves") == "on":
        assert seen["never ends"]


def test_the_record_is_the_fields_then_valid():
    """impact_record_at gives, in the order of RECORD (the reals, then the flags and valid, as the C record),
    the values of impact_at's result and its ``valid``."""
    assert RECORD == RECORD_REALS + RECORD_FLAGS
    assert RECORD[:-1] == tuple(f for f in ImpactResult.__dataclass_fields__) and RECORD[-1] == "valid"
    for params, edge in _parameter_sets(6, seed=11):
        terms = impact_terms(**params, plate_edge_distance=edge, zener_method="linear")
        for v in SPEEDS:
            record = impact_record_at(float(v), terms)
            res = impact_at(float(v), terms)
            assert len(record) == len(RECORD) and record[-1] is res.valid
            assert list(vars(res)) == list(RECORD[:-1])  # the result's own order, as_dict's
            for name, value in zip(RECORD, record):
                want = res.as_dict()[name]
                assert value == want or (math.isnan(value) and math.isnan(want)), name


def test_published_reads_a_record_as_it_reads_the_fields():
    """published() of a record changes what it changes in the result's dict, position by position: an
    unbounded plate's edge echo capped, tau0, t_contact and wave_delay 0 where the contact never ends; a
    record where nothing changes is returned as it is."""
    params = dict(zip(NAMES, (207e9, 0.3, 2e9, 7861.0, 6.35e-3, 69e9, 0.33, 0.29e9, 2700.0, 6.35e-3)))
    thin = dict(params, plate_t=2e-5)  # lambda >= 2: the linear method never releases
    for p, edge, method in ((params, 0.0, "exact"), (params, 0.5, "exact"), (thin, math.inf, "linear"),
                            (thin, 0.5, "linear")):
        terms = impact_terms(**p, plate_edge_distance=edge, zener_method=method, plate_waves="on")
        record = impact_record_at(2.0, terms)
        from_dict = published(impact_at(2.0, terms).as_dict())
        from_record = published(record)
        assert [from_dict[name] for name in RECORD] == list(from_record)
        assert all(math.isfinite(x) for x in from_record[:len(RECORD_REALS)])
        if edge == 0.5 and method == "exact":
            assert from_record is record
    assert from_dict["tau0"] == 0.0 and not from_dict["contact_ends"]


def test_the_split_form_checks_its_inputs_as_impact_does():
    """impact_terms refuses what impact() refuses, with the same message; impact_at refuses a bad speed
    (named v_approach, as impact() names it) and anything but an ImpactTerms; validate=False skips both."""
    params = dict(zip(NAMES, (207e9, 0.3, 2e9, 7861.0, 6.35e-3, 69e9, 0.33, 0.29e9, 2700.0, 6.35e-3)))
    for bad, options in ((dict(params, plate_t=-1.0), {}), (dict(params, sphere_nu=0.7), {}),
                         (params, dict(zener_method="spline")), (params, dict(plasticity=7)),
                         (params, dict(effect_tolerance=-1.0)), (params, dict(plate_edge_distance=-2.0))):
        with pytest.raises(ValueError) as want:
            impact(1.0, **bad, **options)
        with pytest.raises(ValueError) as got:
            impact_terms(**bad, **options)
        assert str(got.value) == str(want.value)
    terms = impact_terms(**params)
    for v in (-1.0, math.nan, math.inf):
        with pytest.raises(ValueError, match="v_approach") as want:
            impact(v, **params)
        with pytest.raises(ValueError) as got:
            impact_at(v, terms)
        assert str(got.value) == str(want.value)
        with pytest.raises(ValueError, match="v_approach"):
            impact_record_at(v, terms)
    with pytest.raises(TypeError, match="ImpactTerms"):
        impact_at(1.0, tuple(terms)[2:])
    assert isinstance(impact_at(1.0, terms, validate=False), ImpactResult)


def test_the_package_exports_the_split_for_bodies_and_quantities_with_units():
    """restitution.impact_terms / impact_at as docs/api shows them: the bodies' parameters, speeds in any
    unit (pint), one terms object for many speeds, each result within conditioning of impact_between."""
    pint = pytest.importorskip("pint")
    Q_ = pint.get_application_registry().Quantity

    sphere = r.Sphere(r.MATERIALS["s2_tool_steel"], d=6.35e-3)
    plate = r.Plate(r.MATERIALS["al_6061"], t=3e-3)
    terms = r.impact_terms(**sphere.params(), **plate.params())
    assert isinstance(terms, r.ImpactTerms)
    params = {**sphere.params(), **plate.params()}
    for v in (0.0, 0.3, 2.0, 7.5):
        assert_agree(r.impact_between(sphere, plate, v), r.impact_at(v, terms), v, params, f"v = {v}")
        in_kmh = r.impact_at(Q_(v * 3.6, "km/h"), terms)
        assert_agree(r.impact_between(sphere, plate, v), in_kmh, v, params, f"v = {v * 3.6} km/h")
