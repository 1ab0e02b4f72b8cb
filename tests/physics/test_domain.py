"""The model's domain in the Python front end: Material, Sphere, Plate and impact_between refuse a value
outside the ranges the FMUs declare, in one line naming the quantity and the unit it was likely meant
in; impact() (the equations, defined beyond) computes it with a DomainWarning saying the same. The
domain itself is read from the FMUs' own modelDescription here, not from the package."""
from __future__ import annotations

import math
import warnings
import xml.etree.ElementTree as ET
import zipfile

import numpy as np
import pint
import pytest

import restitution as r
from restitution.domain import DOMAIN, DomainWarning

U = pint.UnitRegistry()
TI = dict(nu=0.32, rho=4430.0)


@pytest.mark.parametrize("kwargs, message", [
    (dict(E=114, Sy=880e6), r"^ti\.E = 114 Pa is outside 100000 <= value <= 1e\+13 Pa: did you mean 114 GPa\?$"),
    (dict(E=114e9, Sy=880), r"^ti\.Sy = 880 Pa is outside .* Pa: did you mean 880 MPa\?$"),
    (dict(E=114e9, Sy=880e6, rho=0.5), r"^ti\.rho = 0\.5 kg/m3 is outside 1 <= value <= 100000 kg/m3: did you mean 0\.5 g/cm3\?$"),
    (dict(E=114e9, Sy=880e6, rho=2e5), r"^ti\.rho = 200000 kg/m3 is outside 1 <= value <= 100000 kg/m3$"),
])
def test_a_material_outside_the_domain_is_one_line_with_the_likely_unit(kwargs, message):
    with pytest.raises(ValueError, match=message):
        r.Material("ti", **{**TI, **kwargs})


def test_sizes_and_speeds_outside_the_domain_name_the_unit_meant():
    with pytest.raises(ValueError, match=r"^plate\.t = 3000 m is outside .*: did you mean 3000 mm\?$"):
        r.Plate("al_6061", t=3000)
    with pytest.raises(ValueError, match=r"^sphere\.d = 20 m is outside .*: did you mean 20 mm\?$"):
        r.Sphere("chrome_steel", d=20)
    ball, plate = r.Sphere("chrome_steel", d=6.35e-3), r.Plate("al_6061", t=3e-3)
    with pytest.raises(ValueError, match=r"^v_approach = 20000 m/s is outside 0 <= value <= 10000 m/s"):
        r.impact_between(ball, plate, v=2e4)
    with pytest.raises(ValueError, match=r"v_approach = 12000 m/s"):  # the first element outside, of an array
        r.impact_between(ball, plate, v=np.array([1.0, 1.2e4, 3e4]))
    with pytest.raises(ValueError, match="v_approach"):  # a unit that brings it outside
        r.impact_between(ball, plate, v=20 * U.km / U.s)


def test_the_ends_of_the_domain_are_accepted():
    for d in DOMAIN["sphere_d"]:
        r.Sphere("chrome_steel", d=d)
    for t in DOMAIN["plate_t"]:
        r.Plate("al_6061", t=t)
    low, high = DOMAIN["plate_E"]
    r.Material("a", E=low, nu=0.3, Sy=DOMAIN["plate_Sy"][1], rho=DOMAIN["plate_rho"][0])
    r.Material("b", E=high, nu=0.3, Sy=DOMAIN["plate_Sy"][0], rho=DOMAIN["plate_rho"][1])
    ball, plate = r.Sphere("chrome_steel", d=6.35e-3), r.Plate("al_6061", t=3e-3)
    assert r.impact_between(ball, plate, v=DOMAIN["v"][1]).e >= -1
    assert r.impact_between(ball, plate, v=6 * U.mm / U.s).e == pytest.approx(
        r.impact_between(ball, plate, v=6e-3).e, rel=1e-15)


def test_a_presets_name_is_its_material_and_anything_else_fails_at_once():
    assert r.Plate("al_6061", t=3e-3) == r.Plate(r.MATERIALS["al_6061"], t=3e-3)
    assert r.Sphere("chrome_steel", d=0.01).material is r.MATERIALS["chrome_steel"]
    with pytest.raises(KeyError, match="did you mean 'al_6061'"):
        r.Plate("al_606", t=3e-3)
    with pytest.raises(TypeError, match=r"^plate\.material = 3: a restitution\.Material or a preset's name"):
        r.Plate(3, t=3e-3)


def test_impact_computes_outside_the_domain_and_warns_with_the_same_line():
    args = dict(sphere_E=114, sphere_nu=0.3, sphere_Sy=1e9, sphere_rho=7800, sphere_d=0.01,
                plate_E=70e9, plate_nu=0.33, plate_Sy=3e8, plate_rho=2700, plate_t=3e-3)
    with pytest.warns(DomainWarning, match=r"^sphere\.E = 114 Pa is outside .*: did you mean 114 GPa\? \(outside "):
        res = r.impact(2.0, **args)
    assert 0 < res.e <= 1 and math.isfinite(res.e)
    with pytest.warns(DomainWarning, match=r"^v_approach = 20000 m/s"):
        r.impact(2e4, **{**args, "sphere_E": 2e11})
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # inside the domain: no warning at all
        r.impact(2.0, **{**args, "sphere_E": 2e11})
        r.impact(np.array([0.0, 1e4]), **{**args, "sphere_E": 2e11})


def test_the_domain_is_what_the_fmu_declares(impact_fmu):
    """min/max of each parameter in the built FMU's modelDescription.xml, against DOMAIN."""
    with zipfile.ZipFile(impact_fmu) as z:
        root = ET.fromstring(z.read("modelDescription.xml"))
    declared = {}
    for var in root.iter("ScalarVariable"):
        real = var.find("Real")
        if real is not None and "min" in real.attrib and "max" in real.attrib:
            declared[var.get("name")] = (float(real.get("min")), float(real.get("max")))
    for key, (low, high) in DOMAIN.items():
        name = "v_approach" if key == "v" else key.replace("_", ".", 1)
        assert declared[name] == (low, high), name
