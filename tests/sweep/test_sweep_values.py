"""The sweep command line's values: units (a bare number is SI), and explicit values checked against the
inputs' declared ranges before any work (one line, exit 2), with a hint where a slipped SI prefix
explains the value. Small sweeps, package back end, serial scheduler."""
import os
import subprocess
import sys

import numpy as np
import pytest

from restitution.fmu.models.sphere_plate_impact.variables import TABLE
from restitution.units import split_quantity
from restitution.sweep import SweepSpec, read_table, run_sweep
from restitution.sweep.__main__ import main as sweep_cli
from restitution.inputs import QuantityError, outside, quantity

RUN = ["--scheduler", "serial", "--backend", "package", "--no-plot", "--no-progress"]


def _sweep(tmp_path, name, *args):
    """The table of a sweep run through the command line's main(), in this process."""
    out = tmp_path / f"{name}.csv"
    assert sweep_cli([*args, *RUN, "--out", str(out)]) == 0
    return read_table(out)


def _refused(tmp_path, capsys, *args):
    """The one line a refused command prints on stderr; nothing started, no file written."""
    out = tmp_path / "refused.csv"
    status = sweep_cli([*args, *RUN, "--out", str(out)])
    captured = capsys.readouterr()
    assert status == 2, (status, captured)
    lines = captured.err.splitlines()
    assert len(lines) == 1, captured.err  # no usage, no traceback, no second line
    assert captured.out == ""  # refused before the sweep said what it covers
    assert not out.exists() and not out.with_name(out.name + ".parts").exists()
    prefix = "restitution sweep: error: "
    assert lines[0].startswith(prefix), lines[0]
    return lines[0][len(prefix):]


def _same_table(a: dict, b: dict):
    """Same cases, computed the same way. The inputs are the same numbers: the unit conversion is one
    product with pint's factor for the unit (3 * 0.001, 0.25 * 0.0254), which here gives the double the
    SI literal gives, but may in general differ from it in the last bit; the model's outputs move with
    their inputs no more than a few ulps for such a change (their conditioning in plate.t and E is of
    order 1), so 1e-15 relative holds either way, and anything else (a wrong factor, another unit) fails
    it by many orders of magnitude."""
    assert list(a) == list(b)
    for name in a:
        if a[name].dtype.kind in "fc":
            np.testing.assert_allclose(a[name], b[name], rtol=1e-15, atol=0, err_msg=name)
        else:
            assert np.array_equal(a[name], b[name]), name


# --- units ---------------------------------------------------------------------------------
@pytest.mark.parametrize("name, with_unit, si", [
    ("plate.t", "3mm", "0.003"),
    ("plate.t", "3 mm", "0.003"),
    ("plate.t", "6.35e-3 m", "0.00635"),
    ("plate.t", "1/4 in", "0.00635"),
    ("plate.E", "114GPa", "114e9"),
    ("sphere.rho", "7.85 g/cm3", "7850"),
    ("v_approach", "250 cm/s", "2.5"),
])
def test_a_value_with_its_unit_is_the_case_of_its_si_number(tmp_path, name, with_unit, si):
    grid = ["--pair", "s2_tool_steel/al_6061"] if name.split(".")[-1] not in ("E", "rho") else []
    speeds = [] if name == "v_approach" else ["--grid", "v_approach=0.5,3"]
    a = _sweep(tmp_path, "unit", *grid, *speeds, "--set", f"{name}={with_unit}")
    b = _sweep(tmp_path, "si", *grid, *speeds, "--set", f"{name}={si}")
    assert np.all(a["ok"]) and len(a["case"]) == (1 if name == "v_approach" else 2)
    np.testing.assert_allclose(a[name], float(si), rtol=1e-15, atol=0)
    _same_table(a, b)


def test_a_grid_range_and_a_list_take_units(tmp_path):
    a = _sweep(tmp_path, "unit", "--pair", "s2_tool_steel/al_6061", "--grid", "plate.t=linspace:1mm:5mm:5",
               "--grid", "v_approach=geomspace:10 cm/s:10 m/s:3", "--grid", "sphere.d=1/8 in,1/4 in")
    b = _sweep(tmp_path, "si", "--pair", "s2_tool_steel/al_6061", "--grid", "plate.t=linspace:0.001:0.005:5",
               "--grid", "v_approach=geomspace:0.1:10:3", "--grid", "sphere.d=3.175e-3,6.35e-3")
    assert len(a["case"]) == 30 and np.all(a["ok"])
    np.testing.assert_allclose(np.unique(a["plate.t"]), [1e-3, 2e-3, 3e-3, 4e-3, 5e-3], rtol=1e-15)
    _same_table(a, b)


def test_a_spec_file_takes_units_too(tmp_path):
    spec = tmp_path / "s.toml"
    spec.write_text('[grid]\nv_approach = {linspace = ["1 m/s", "3 m/s", 3]}\n[fixed]\n"plate.t" = "3 mm"\n')
    a = _sweep(tmp_path, "file", str(spec))
    b = _sweep(tmp_path, "si", "--grid", "v_approach=linspace:1:3:3", "--set", "plate.t=0.003")
    _same_table(a, b)


def test_random_draws_take_units_and_keep_relative_spreads_plain(tmp_path):
    args = ["--pair", "brass_260/al_6061", "--random", "sphere.E=normal_rel:0.03", "--random",
            "plate.E=uniform_rel:0.15", "--samples", "40", "--seed", "5"]
    a = _sweep(tmp_path, "unit", *args, "--random", "plate.t=uniform:1mm:5mm", "--random", "v=normal:2 m/s:20 cm/s")
    b = _sweep(tmp_path, "si", *args, "--random", "plate.t=uniform:0.001:0.005", "--random", "v=normal:2:0.2")
    assert len(a["case"]) == 40 and np.all(a["ok"])
    assert 1e-3 <= a["plate.t"].min() and a["plate.t"].max() <= 5e-3
    _same_table(a, b)
    # the same draws as the spec built from Python with SI numbers
    spec = SweepSpec(pairs=["brass_260/al_6061"], samples=40, seed=5,
                     random={"sphere.E": {"normal_rel": 0.03}, "plate.E": {"uniform_rel": 0.15},
                             "plate.t": {"uniform": [1e-3, 5e-3]}, "v_approach": {"normal": [2.0, 0.2]}})
    _same_table({k: a[k] for k in ("plate.t", "v_approach", "e")},
                {k: run_sweep(spec, scheduler="serial")[k] for k in ("plate.t", "v_approach", "e")})


def test_random_draws_outside_the_range_stay_rows_not_ok(tmp_path, capsys):
    table = _sweep(tmp_path, "draws", "--random", "v_approach=normal:0:1", "--samples", "50", "--seed", "2")
    assert capsys.readouterr().err.count("error") == 0
    negative = table["v_approach"] < 0
    assert 0 < negative.sum() < 50
    assert np.array_equal(table["ok"], ~negative) and np.all(np.isnan(table["e"][negative]))


@pytest.mark.parametrize("args, words", [
    (["--set", "plate.t=3GPa"], ["--set plate.t = '3GPa'", "GPa is a unit of pressure", "plate.t is a length"]),
    (["--grid", "plate.E=100 GPa,3 mm"], ["--grid plate.E = '3 mm'", "mm is a unit of length",
                                          "plate.E is a pressure"]),
    (["--random", "v_approach=uniform:1 kg:2 kg"], ["--random v_approach = '1 kg'", "kg is a unit of",
                                                    "v_approach is a speed"]),
    (["--set", "plate.nu=0.3 mm"], ["--set plate.nu = '0.3 mm'", "dimensionless", "no unit"]),
    (["--random", "plate.E=normal_rel:3 %"], ["--random plate.E = '3 %'", "plain number"]),
    (["--set", "plate.t=3 furlongs/s"], ["--set plate.t = '3 furlongs/s'", "length"]),
    (["--set", "plate.t=3 parsnips"], ["--set plate.t = '3 parsnips'", "unknown unit 'parsnips'"]),
    (["--set", "plate.t=thick"], ["--set plate.t = 'thick'", "is not a number", "a bare number is in m"]),
    (["--grid", "plate.t=1,2,3mm"], ["--grid plate.t = '1,2,3mm'", "every value its unit or none", "1 m"]),
    (["--grid", "plate.t=linspace:1:5mm:3"], ["--grid plate.t = 'linspace:1:5mm:3'", "its unit or none"]),
    (["--grid", "plate.t=linspace:1mm:5mm:3 mm"], ["--grid plate.t = '3 mm'", "count of linspace is a plain"]),
])
def test_a_unit_that_does_not_fit_is_one_line(tmp_path, capsys, args, words):
    line = _refused(tmp_path, capsys, *args)
    for w in words:
        assert w in line, (w, line)


# --- the declared ranges -------------------------------------------------------------------------
def test_an_explicit_value_outside_the_range_is_refused_before_any_work(tmp_path, capsys):
    line = _refused(tmp_path, capsys, "--grid", "v_approach=-1,2")
    assert line == "--grid v_approach = -1 m/s is outside 0 <= value <= 10000 m/s"


def test_as_a_command_one_line_and_no_file(tmp_path):
    env = {k: v for k, v in os.environ.items() if k != "DASK_SCHEDULER_ADDRESS"}
    proc = subprocess.run([sys.executable, "-m", "restitution.sweep", "--grid", "v_approach=-1,2", *RUN,
                           "--out", str(tmp_path / "s.csv")], capture_output=True, text=True, env=env,
                          cwd=tmp_path, timeout=120)
    assert proc.returncode == 2 and proc.stdout == "", proc
    assert proc.stderr == ("restitution sweep: error: --grid v_approach = -1 m/s is outside "
                           "0 <= value <= 10000 m/s\n")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("args, expected", [
    # three prefixes bring 114 Pa in (kPa, MPa, GPa): the one nearest the default modulus, 68.9 GPa
    (["--set", "plate.E=114"], "--set plate.E = 114 Pa is outside 100000 <= value <= 1e+13 Pa: did you mean 114 GPa?"),
    (["--set", "sphere.Sy=250"], "--set sphere.Sy = 250 Pa is outside 1000 <= value <= 1e+13 Pa: "
                                 "did you mean 250 MPa?"),
    (["--set", "plate.t=3000"], "--set plate.t = 3000 m is outside 1e-07 <= value <= 100 m: did you mean 3000 mm?"),
    (["--grid", "v=1,20000"], "--grid v_approach = 20000 m/s is outside 0 <= value <= 10000 m/s: "
                              "did you mean 20000 mm/s?"),
    (["--set", "plate.rho=0.5"], "--set plate.rho = 0.5 kg/m3 is outside 1 <= value <= 100000 kg/m3: "
                                 "did you mean 0.5 g/cm3?"),
    # a unit given: the message is in SI; no prefix explains a negative value or a Poisson's ratio
    (["--set", "plate.t=2 km"], "--set plate.t = 2000 m is outside 1e-07 <= value <= 100 m: did you mean 2000 mm?"),
    (["--set", "plate.E=-70 GPa"], "--set plate.E = -70000000000 Pa is outside 100000 <= value <= 1e+13 Pa"),
    (["--set", "sphere.nu=0.6"], "--set sphere.nu = 0.6 is outside 0 <= value <= 0.5"),
    (["--set", "effect_tolerance=-1"], "--set effect_tolerance = -1 is outside finite and >= 0"),
])
def test_out_of_range_names_the_value_its_unit_the_range_and_a_likely_slip(tmp_path, capsys, args, expected):
    assert _refused(tmp_path, capsys, *args) == expected


@pytest.mark.parametrize("grid, words", [
    ("plate.t=linspace:1mm:200m:3", ["--grid plate.t = 200 m is outside"]),  # a range's last value
    ("plate.t=geomspace:1e-8:1e-3:4", ["--grid plate.t = 1e-08 m is outside"]),  # its first
    ("v=arange:0:20000:5000", ["--grid v_approach = 15000 m/s is outside"]),  # arange's last value, not its stop
    ("v=logspace:-2:5:8", ["--grid v_approach = 100000 m/s is outside"]),
    ("t_over_d=0.1,1e5", ["--grid t_over_d = 100000 with sphere.d = 0.00635 m gives plate.t = 635 m",
                          "1e-07 <= value <= 100 m"]),
])
def test_grid_ranges_are_checked_at_their_ends(tmp_path, capsys, grid, words):
    line = _refused(tmp_path, capsys, "--grid", grid)
    for w in words:
        assert w in line, (w, line)


def test_ends_inside_the_range_pass(tmp_path):
    table = _sweep(tmp_path, "ends", "--grid", "v=arange:0:10001:5000", "--grid", "plate.t=geomspace:1e-7:100:3")
    assert set(table["v_approach"]) == {0.0, 5000.0, 10000.0} and np.all(table["ok"])


def test_a_spec_file_value_is_named_by_its_table(tmp_path, capsys):
    spec = tmp_path / "s.toml"
    spec.write_text("[grid]\nv_approach = [-1, 2]\n")
    line = _refused(tmp_path, capsys, str(spec))
    assert line == f"spec file {spec}: [grid] v_approach = -1 m/s is outside 0 <= value <= 10000 m/s"
    # the command line's value replaces the file's, and is named by its option
    assert _refused(tmp_path, capsys, str(spec), "--set", "v=-2").startswith("--set v_approach = -2 m/s")


# --- the pieces ------------------------------------------------------------------------------------
def test_quantities_and_ranges_in_python():
    assert quantity("plate.t", "1/4 in") == quantity("plate.t", "0.25 in") == 0.00635
    assert quantity("plate.t", 0.003) == quantity("plate.t", "3mm") == 0.003
    assert quantity("sphere.nu", "0.3") == 0.3 and quantity("zener.ode_tolerance", "1e-8") == 1e-8
    assert split_quantity("1/4 in") == (1.0, "/4 in")  # the scene's syntax is unchanged: no fractions there
    assert split_quantity("1/4 in", fractions=True) == (0.25, "in") and split_quantity("1/0", fractions=True) is None
    for name in ("v_approach", "plate.E", "sphere.d", "plate.nu"):
        low, high = TABLE[name].interval[:2]
        assert outside(name, low) is None and outside(name, high) is None  # bounds included, as the FMUs
        assert outside(name, high * (1 + 1e-15)) and outside(name, float("nan"))
    with pytest.raises(QuantityError, match="plate.t") as info:
        SweepSpec(fixed={"plate.t": "3 GPa"})
    assert info.value.section == "fixed" and info.value.name == "plate.t"
    # SweepSpec itself still builds out-of-range cases (rows with ok = False); the check is asked for
    spec = SweepSpec(grid={"v": [-1, 2]})
    assert not run_sweep(spec, scheduler="serial")["ok"][0]
    with pytest.raises(QuantityError, match="v_approach = -1 m/s"):
        spec.check_domain()


def test_inputs_ok_checks_a_one_value_column_once_and_each_case_of_the_others():
    """inputs_ok against each variable's declared interval (the interface table, not the code under test):
    a one-value column (a stride-0 view, as SweepSpec.cases gives constants) out of its range marks every
    case, an array marks only its own bad cases, an Integer code must be whole."""
    from restitution.sweep.backends import inputs_ok
    from restitution.sweep.spec import SETTABLE, START

    n = 5
    cases = {name: np.broadcast_to(np.float64(value), (n,)) for name, value in START.items()}
    cases["v_approach"] = np.array([0.5, 1.0, -1.0, 2.0, 3.0])  # one case below the range
    assert inputs_ok(cases).tolist() == [True, True, False, True, True]
    var = next(v for v in SETTABLE if v.name == "plate.t")
    low = var.interval[0]
    bad_t = dict(cases, **{"plate.t": np.broadcast_to(np.float64(low - 1.0), (n,))})
    assert not inputs_ok(bad_t).any()
    code = next(v for v in SETTABLE if v.type == "Integer")
    half = dict(cases, **{code.name: np.array([1.0, 1.5, 1.0, 1.0, 1.0])})
    assert inputs_ok(half).tolist() == [True, False, False, True, True]
