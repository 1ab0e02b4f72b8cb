"""pint Quantities as inputs: any compatible unit gives the SI call's result, a wrong dimension is a
ValueError naming the argument, and the package never imports pint itself.

The expected values are the same calls with plain SI floats; the unit factors are exact by
definition (1 in = 0.0254 m, 1 g/cm3 = 1000 kg/m3, 1 km/h = 1/3.6 m/s). A conversion rounds once
(relative 1.1e-16 per input); the functions are products and powers with exponents of at most 3 in
each input, so 1e-13 relative bounds the difference with a wide margin."""
import subprocess
import sys

import numpy as np
import pint
import pytest

import restitution as r
from restitution import fusion, jgm, zener

u = pint.UnitRegistry()
STEEL, AL = r.MATERIALS["s2_tool_steel"], r.MATERIALS["al_6061"]
SI = dict(v=2.3, sphere_E=STEEL.E, sphere_nu=STEEL.nu, sphere_Sy=STEEL.Sy, sphere_rho=STEEL.rho, sphere_d=6.35e-3,
          plate_E=AL.E, plate_nu=AL.nu, plate_Sy=AL.Sy, plate_rho=AL.rho, plate_t=3.175e-3)
WITH_UNITS = dict(v=2.3 * 3.6 * u.km / u.h, sphere_E=STEEL.E / 1e9 * u.GPa, sphere_nu=STEEL.nu * u.dimensionless,
                  sphere_Sy=STEEL.Sy / 1e6 * u.MPa, sphere_rho=STEEL.rho / 1000 * u.g / u.cm ** 3,
                  sphere_d=0.25 * u.inch, plate_E=AL.E * u.Pa, plate_nu=AL.nu, plate_Sy=AL.Sy / 1e3 * u.kPa,
                  plate_rho=AL.rho * u.kg / u.m ** 3, plate_t=0.125 * u.inch)
REL = 1e-13


def test_impact_with_units_equals_impact_in_si():
    a, b = r.impact(**SI), r.impact(**WITH_UNITS)
    for name, x in a.as_dict().items():
        assert getattr(b, name) == pytest.approx(x, rel=REL), name


def test_arrays_of_quantities_broadcast():
    v = np.array([0.5, 2.3, 9.0])
    a = r.impact(**dict(SI, v=v))
    b = r.impact(**dict(WITH_UNITS, v=v * 100 * u.cm / u.s))
    assert b.e == pytest.approx(a.e, rel=REL)


@pytest.mark.parametrize("name", [k for k in SI if not k.endswith("_nu")])
def test_a_wrong_dimension_names_the_argument(name):
    wrong = 3.0 * u.s if name != "v" else 3.0 * u.m
    with pytest.raises(ValueError, match=rf"^{name} = 3\.0 (s|m): a \w+ is expected \(SI unit"):
        r.impact(**dict(SI, **{name: wrong}))


def test_materials_spheres_and_plates_store_si():
    m = r.Material("Al", 69 * u.GPa, 0.33, 290 * u.MPa, 2.7 * u.g / u.cm ** 3)
    assert (m.E, m.Sy) == (69e9, 290e6) and m.rho == pytest.approx(2700.0, rel=REL)
    sphere, plate = r.Sphere(STEEL, 0.25 * u.inch), r.Plate(m, 3 * u.mm)
    assert sphere.d == pytest.approx(6.35e-3, rel=REL) and plate.t == pytest.approx(3e-3, rel=REL)
    assert plate.with_thickness(1 * u.cm).t == pytest.approx(0.01, rel=REL)
    assert r.impact_between(sphere, plate, 2.3 * u.m / u.s).e == pytest.approx(
        r.impact_between(r.Sphere(STEEL, 6.35e-3), r.Plate(m, 3e-3), 2.3).e, rel=REL)
    with pytest.raises(ValueError, match=r"^plate\.t = 3 kg: a length is expected"):
        r.Plate(m, 3 * u.kg)
    with pytest.raises(ValueError, match=r"^Al\.E = 69 m: a pressure is expected"):
        r.Material("Al", 69 * u.m, 0.33, 290e6, 2700)


# Every public equation that takes a physical quantity: (function, SI arguments, the same with units).
E, NU, SY, RHO, D = STEEL.E, STEEL.nu, STEEL.Sy, STEEL.rho, 6.35e-3
EQUATIONS = [
    (jgm.reduced_modulus, (E, NU), (E / 1e9 * u.GPa, NU)),
    (jgm.effective_modulus, (E, NU, AL.E, AL.nu), (E / 1e9 * u.GPa, NU, AL.E / 1e6 * u.MPa, AL.nu)),
    (jgm.critical_pressure, (NU, SY, AL.nu, AL.Sy), (NU, SY / 1e6 * u.MPa, AL.nu, AL.Sy * u.Pa)),
    (jgm.sphere_yields_first, (NU, SY, AL.nu, AL.Sy), (NU, SY / 1e6 * u.MPa, AL.nu, AL.Sy / 1e3 * u.kPa)),
    (jgm.yield_strain, (1e11, NU, SY, AL.nu, AL.Sy), (100 * u.GPa, NU, SY * u.Pa, AL.nu, AL.Sy * u.Pa)),
    (jgm.critical_interference, (1e9, 1e11, 3e-3), (1 * u.GPa, 100 * u.GPa, 3 * u.mm)),
    (jgm.critical_load, (1e9, 1e11, 3e-3), (1 * u.GPa, 100 * u.GPa, 0.3 * u.cm)),
    (jgm.sphere_mass, (RHO, D), (RHO / 1000 * u.g / u.cm ** 3, 0.25 * u.inch)),
    (jgm.critical_velocity, (1e-6, 10.0, 1e-3), (1 * u.um, 10 * u.N, 1 * u.g)),
    (zener.plate_wave_speed, (AL.E, AL.nu, AL.rho), (AL.E / 1e9 * u.GPa, AL.nu, AL.rho * u.kg / u.m ** 3)),
    (zener.inelasticity_parameter, (2.3, E, NU, RHO, D, AL.E, AL.nu, AL.rho, 3e-3),
     (230 * u.cm / u.s, E * u.Pa, NU, RHO * u.kg / u.m ** 3, 0.25 * u.inch, AL.E * u.Pa, AL.nu,
      AL.rho / 1000 * u.g / u.cm ** 3, 3 * u.mm)),
    (zener.hertz_stiffness, (1e11, D), (100 * u.GPa, 0.25 * u.inch)),
    (zener.time_scale, (1e-3, 1e9, 2.3), (1 * u.g, 1e9 * u.N / u.m ** 1.5, 2.3 * 3.6 * u.km / u.h)),
    (zener.contact_duration, (2e-5, 3.0), (20 * u.us, 3.0)),
    (fusion.equivalent_plate_mass, (1e-3, 0.8), (1 * u.g, 0.8)),
    (fusion.velocities_after_impact, (2.3, 0.6, 0.8), (230 * u.cm / u.s, 0.6, 0.8)),
]


@pytest.mark.parametrize("function, si, with_units", EQUATIONS, ids=[f[0].__name__ for f in EQUATIONS])
def test_every_public_equation_takes_quantities(function, si, with_units):
    expected, got = function(*si), function(*with_units)
    assert np.all(np.asarray(got) == pytest.approx(np.asarray(expected), rel=REL))
    # the same by keyword, and a wrong dimension named
    names = list(__import__("inspect").signature(function).parameters)
    assert np.all(np.asarray(function(**dict(zip(names, with_units)))) == pytest.approx(np.asarray(expected), rel=REL))
    dimensional = next(i for i, x in enumerate(with_units) if hasattr(x, "units") and not x.dimensionless)
    bad = list(with_units)
    bad[dimensional] = 1.0 * u.degK
    with pytest.raises(ValueError, match=rf"^{names[dimensional]} = "):
        function(*bad)


def test_the_package_never_imports_pint():
    """The FMUs bundle the package without pint: importing it and computing must not need pint."""
    code = ("import sys, restitution as r; m = r.MATERIALS['al_6061']; "
            "r.impact_between(r.Sphere(m, 0.01), r.Plate(m, 0.01), 1.0); r.Material('x', 1e9, 0.3, 1e6, 1e3); "
            "print('pint' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "False"
