"""The user's own materials and the slips a person makes, on the command lines (``restitution cor``,
``fit``, ``sweep``) and in Python: --ROLE-E/-nu/-Sy/-rho and --ROLE-material FILE.toml give the same e as
:func:`restitution.impact` with those values; bad keys, values out of the domain and implausible bare
lengths are refused in one line with exit 2; Sphere, Plate, Material and impact_between take strings
with units."""
from __future__ import annotations

import csv
import json

import numpy as np
import pytest

import restitution as r
from restitution.cor import main as cor_main
from restitution.fit.command import main as fit_main
from restitution.units import OptionError
from restitution.sweep.__main__ import main as sweep_main

#: The custom copper plate of the tests, as the options give it and in SI.
COPPER_OPTIONS = ["--plate-E", "115 GPa", "--plate-nu", "0.31", "--plate-Sy", "69 MPa", "--plate-rho", "8960 kg/m3"]
COPPER = dict(plate_E=115e9, plate_nu=0.31, plate_Sy=69e6, plate_rho=8960.0)
COPPER_TOML = 'name = "OFHC copper"\nsource = "a handbook"\nE = "115 GPa"\nnu = 0.31\nSy = "69 MPa"\nrho = 8960\n'
SPHERE = r.MATERIALS["chrome_steel"].params("sphere")
D, T, V = 6.35e-3, 3e-3, 0.2


def _expected(v=V, **plate):
    return float(r.impact(v, **SPHERE, sphere_d=D, **{**COPPER, **plate}, plate_t=T).e)


def _one_line_refusal(capsys, main, argv) -> str:
    status = main(argv) if main is not sweep_main else _sweep_status(argv)
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(err) == 1, err
    return err[0]


def _sweep_status(argv):
    try:
        return sweep_main(argv)
    except SystemExit as exc:
        return exc.code


def _cor_e(tmp_path, capsys, *args) -> tuple[float, dict]:
    out = tmp_path / "cor.json"
    status = cor_main(["--d", "6.35 mm", "--t", "3 mm", "--v", f"{V} m/s", *args, "--json", str(out)])
    printed = capsys.readouterr()
    assert status == 0, printed.err
    data = json.loads(out.read_text())
    return data["result"]["e"], data["inputs"]


def test_cor_takes_a_custom_plate_from_the_options(tmp_path, capsys):
    """All four --plate-* (no --plate): the plate is "custom" and e is impact()'s with those values."""
    e, inputs = _cor_e(tmp_path, capsys, "--sphere", "chrome_steel", *COPPER_OPTIONS)
    assert e == pytest.approx(_expected(), rel=1e-12)
    assert inputs["plate"] == "custom" and inputs["plate_E"] == 115e9 and inputs["plate_rho"] == 8960.0


def test_an_option_overrides_the_presets_value(tmp_path, capsys):
    """--plate al_6061 --plate-Sy 69 MPa: Al 6061's E, nu, rho and the given Sy."""
    e, inputs = _cor_e(tmp_path, capsys, "--sphere", "chrome_steel", "--plate", "al_6061", "--plate-Sy", "69 MPa")
    al = r.MATERIALS["al_6061"]
    assert e == pytest.approx(_expected(plate_E=al.E, plate_nu=al.nu, plate_rho=al.rho), rel=1e-12)
    assert inputs["plate"] == "al_6061 (custom Sy)" and inputs["plate_Sy"] == 69e6


def test_cor_takes_a_material_file(tmp_path, capsys):
    """--plate-material FILE.toml: numbers in SI and strings with units; the file's name names the plate;
    an option overrides the file's value."""
    path = tmp_path / "copper.toml"
    path.write_text(COPPER_TOML)
    e, inputs = _cor_e(tmp_path, capsys, "--sphere", "chrome_steel", "--plate-material", str(path))
    assert e == pytest.approx(_expected(), rel=1e-12) and inputs["plate"] == "OFHC copper"
    e, _ = _cor_e(tmp_path, capsys, "--sphere", "chrome_steel", "--plate-material", str(path), "--plate-Sy", "250 MPa")
    assert e == pytest.approx(_expected(plate_Sy=250e6), rel=1e-12)


@pytest.mark.parametrize("text, words", [
    ('E = "115 GPa"\nnu = 0.31\nSy = "69 MPa"\nrho = 8960\ndensity = 1\nyoung = 2\n',
     ["unknown key(s)", "'density'", "'young'", "E, nu, Sy, rho"]),
    ('E = "115 GPa"\nnu = 0.31\nSy = "69 MPa"\n', ["missing: rho"]),
    ('E = "115 kg"\nnu = 0.31\nSy = "69 MPa"\nrho = 8960\n', ["plate.E", "pressure"]),
    ('E = 115\nnu = 0.31\nSy = "69 MPa"\nrho = 8960\n', ["plate.E = 115 Pa is outside", "did you mean 115 GPa?"]),
    ('E = "115 GPa"\nnu = 0.7\nSy = "69 MPa"\nrho = 8960\n', ["plate.nu = 0.7 is outside"]),
    ('E = [1]\nnu = 0.31\nSy = "69 MPa"\nrho = 8960\n', ["E = [1]", "expected a number"]),
    ('E = "115 GPa\n', ["not a TOML file"]),
])
def test_a_bad_material_file_is_one_line(tmp_path, capsys, text, words):
    path = tmp_path / "bad.toml"
    path.write_text(text)
    line = _one_line_refusal(capsys, cor_main, ["--sphere", "chrome_steel", "--plate-material", str(path),
                                                "--d", "6.35 mm", "--t", "3 mm", "--v", "2"])
    assert "--plate-material" in line or "--plate:" in line, line
    assert all(w in line for w in words), line


@pytest.mark.parametrize("change, words", [
    (["--plate-E", "115"], ["--plate-E: plate.E = 115 Pa is outside", "did you mean 115 GPa?"]),
    (["--plate-rho", "8.96 kg"], ["--plate-rho", "density"]),
    (["--plate-nu", "0.31 GPa"], ["--plate-nu", "dimensionless"]),
    (["--plate-Sy", "1 Pa"], ["--plate-Sy: plate.Sy = 1 Pa is outside"]),
])
def test_a_property_out_of_the_domain_is_one_line(capsys, change, words):
    options = list(COPPER_OPTIONS)
    options[options.index(change[0]) + 1] = change[1]
    line = _one_line_refusal(capsys, cor_main, ["--sphere", "chrome_steel", *options, "--d", "6.35 mm",
                                                "--t", "3 mm", "--v", "2"])
    assert all(w in line for w in words), line


def test_a_material_needs_all_four_properties(capsys):
    line = _one_line_refusal(capsys, cor_main, ["--sphere", "chrome_steel", "--plate-E", "115 GPa",
                                                "--d", "6.35 mm", "--t", "3 mm", "--v", "2"])
    assert "--plate-material" in line and "missing: nu, Sy, rho" in line, line


def test_fit_takes_a_custom_plate(tmp_path, capsys):
    """Pairs made with the copper plate (0.2 % noise): fitting plate.Sy with the plate's other properties
    from the options finds 69 MPa, which it would not with another E, nu or rho."""
    v_in = np.geomspace(0.05, 0.5, 16)
    params = dict(**SPHERE, sphere_d=D, **COPPER, plate_t=6.35e-3)
    e = r.impact(v_in, **params).e
    v_out = e * v_in * (1 + 0.002 * np.random.default_rng(7).standard_normal(v_in.size))
    data = tmp_path / "pairs.csv"
    data.write_text("v_in,v_out\n" + "".join(f"{a!r},{b!r}\n" for a, b in zip(v_in.tolist(), v_out.tolist())))
    out = tmp_path / "fit.json"
    status = fit_main([str(data), "--sphere", "chrome_steel", "--d", "6.35 mm", *COPPER_OPTIONS, "--t", "6.35 mm",
                       "--fit", "plate.Sy", "--json", str(out)])
    assert status == 0, capsys.readouterr().err
    estimate = json.loads(out.read_text())["parameters"]["plate.Sy"]["estimate"]
    assert estimate == pytest.approx(69e6, rel=0.02)


def test_sweep_takes_a_custom_plate_and_a_material_file(tmp_path, capsys):
    """--sphere KEY and --plate-* (or --plate-material) are the fixed values of the sweep: the table's e
    is impact()'s."""
    path = tmp_path / "copper.toml"
    path.write_text(COPPER_TOML)
    for n, plate in enumerate((COPPER_OPTIONS, ["--plate-material", str(path)])):
        out = tmp_path / f"sweep{n}.csv"
        status = sweep_main(["--sphere", "chrome_steel", *plate, "--set", "sphere.d=6.35mm", "--set", "plate.t=3mm",
                             "--set", f"v_approach={V}", "--out", str(out), "--no-plot", "--no-progress",
                             "--scheduler", "serial"])
        assert status == 0, capsys.readouterr().err
        with out.open() as handle:
            (row,) = list(csv.DictReader(handle))
        assert float(row["e [1]"]) == pytest.approx(_expected(), rel=1e-9)
        assert float(row["plate.E [Pa]"]) == 115e9 and float(row["plate.rho [kg/m3]"]) == 8960.0


@pytest.mark.parametrize("argv, words", [
    (["--pair", "chrome_steel/al_6061", "--plate-E", "115 GPa"], ["not with --pair"]),
    (["--plate", "al_6061", "--set", "plate.E=1GPa"], ["plate.E is given by --set"]),
    (["--plate", "al_6061", "--plate-E", "115"], ["did you mean 115 GPa?"]),
])
def test_sweep_refuses_a_material_given_twice_or_out_of_the_domain(capsys, argv, words):
    line = _one_line_refusal(capsys, sweep_main, [*argv, "--dry-run"])
    assert all(w in line for w in words), line


# --- the slips a person makes ----------------------------------------------------------------
BODIES = ["--sphere", "chrome_steel", "--plate", "al_6061", "--v", "2"]


@pytest.mark.parametrize("d, t, words", [
    ("10", "3 mm", ["--d 10: a bare number is metres: a 10 m sphere is implausible; did you mean 10 mm? "
                    "(--allow-implausible accepts it)"]),
    ("6.35 mm", "2", ["--t 2: a bare number is metres: a 2 m plate is implausible; did you mean 2 mm?"]),
    ("0.3", "2 mm", ["--d 0.3:", "t/d = 0.00667", "did you mean 0.3 mm?"]),
    ("0.002", "0.3", ["--t 0.3:", "t/d = 150", "did you mean 0.3 mm?"]),
    ("20", "3 mm", ["--d: sphere.d = 20 m is outside", "did you mean 20 mm?"]),  # the domain's own hint first
])
def test_an_implausible_bare_length_is_refused_with_its_likely_unit(capsys, d, t, words):
    line = _one_line_refusal(capsys, cor_main, [*BODIES, "--d", d, "--t", t])
    assert all(w in line for w in words), line


@pytest.mark.parametrize("d, t, extra", [("10", "3 mm", ["--allow-implausible"]), ("10 m", "3 mm", []),
                                          ("0.3 m", "2 mm", []), ("6.35 mm", "2 m", []), ("0.00635", "0.003", [])])
def test_a_length_with_its_unit_or_allowed_is_accepted(capsys, d, t, extra):
    assert cor_main([*BODIES, "--d", d, "--t", t, *extra]) == 0, capsys.readouterr().err


def test_fit_and_sweep_refuse_an_implausible_bare_length(tmp_path, capsys):
    data = tmp_path / "pairs.csv"
    data.write_text("v_in,v_out\n1,0.5\n2,0.9\n")
    line = _one_line_refusal(capsys, fit_main, [str(data), "--sphere", "chrome_steel", "--d", "10", "--plate",
                                                "al_6061", "--t", "3 mm", "--fit", "plate.Sy"])
    assert line.endswith("--d 10: a bare number is metres: a 10 m sphere is implausible; did you mean 10 mm? "
                         "(--allow-implausible accepts it)"), line
    line = _one_line_refusal(capsys, sweep_main, ["--set", "plate.t=2", "--dry-run"])
    assert "--set plate.t=2: a bare number is metres: a 2 m plate is implausible; did you mean 2 mm?" in line
    assert _sweep_status(["--set", "plate.t=2", "--allow-implausible", "--dry-run"]) == 0


@pytest.mark.parametrize("main", [cor_main, fit_main, sweep_main])
def test_help_says_a_bare_number_is_si(capsys, main):
    with pytest.raises(SystemExit):
        main(["--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "A bare number is SI" in text and "--allow-implausible" in text and "--plate-material" in text


# --- Python takes strings with units ---------------------------------------------------------
def test_the_objects_take_strings_with_units():
    al = r.MATERIALS["al_6061"]
    assert r.Plate(al, t="2 mm").t == 0.002 and r.Plate(al, t="0.002").t == 0.002
    assert r.Sphere("chrome_steel", d="1/4 in").d == pytest.approx(6.35e-3, rel=1e-15)
    cu = r.Material("Cu", "115 GPa", "0.31", "69 MPa", "8.96 g/cm3")
    assert (cu.E, cu.nu, cu.Sy, cu.rho) == (115e9, 0.31, 69e6, pytest.approx(8960.0, rel=1e-15))
    sphere, plate = r.Sphere("chrome_steel", d="6.35 mm"), r.Plate(cu, t="3 mm")
    assert r.impact_between(sphere, plate, "20 cm/s").e == pytest.approx(_expected(), rel=1e-12)
    assert r.impact_between(sphere, plate, "0.2").e == r.impact_between(sphere, plate, 0.2).e


def test_the_objects_still_take_pint_quantities():
    pint = pytest.importorskip("pint")
    u = pint.UnitRegistry()
    assert r.Plate(r.MATERIALS["al_6061"], t=2 * u.mm).t == pytest.approx(0.002, rel=1e-15)
    assert r.Material("Cu", 115 * u.GPa, 0.31, 69 * u.MPa, 8960 * u.kg / u.m ** 3).E == pytest.approx(115e9)


@pytest.mark.parametrize("make, words", [
    (lambda: r.Plate(r.MATERIALS["al_6061"], t="2 xx"), ["plate.t = '2 xx'", "unknown unit"]),
    (lambda: r.Plate(r.MATERIALS["al_6061"], t="two mm"), ["plate.t = 'two mm' is not a number"]),
    (lambda: r.Sphere("chrome_steel", d="3 GPa"), ["sphere.d", "length"]),
    (lambda: r.Material("Cu", "115 kg", 0.31, "69 MPa", 8960), ["Cu.E", "pressure"]),
    (lambda: r.Material("Cu", "115 GPa", "0.31 mm", "69 MPa", 8960), ["Cu.nu", "dimensionless"]),
    (lambda: r.impact_between(r.Sphere("chrome_steel", d="6 mm"), r.Plate("al_6061", t="3 mm"), "2 mm"),
     ["v_approach", "speed"]),
    (lambda: r.Plate(r.MATERIALS["al_6061"], t="2 km"), ["plate.t = 2000 m is outside"]),
])
def test_a_bad_string_is_one_line_naming_the_value(make, words):
    with pytest.raises(ValueError) as info:
        make()
    message = str(info.value)
    assert "\n" not in message and all(w in message for w in words), message
    assert isinstance(info.value, (OptionError, ValueError))
