"""The material presets against the paper's Tables 1-4 as printed (tests/data/paper_tables.toml),
value by value, and every preset through the physics: Eq. (3)'s yield strain, Eqs. (2), (4)-(6)'s
critical velocity and Eq. (12)'s lambda evaluated here in 30-digit arithmetic from the TABLE values
(not from the presets), for every sphere on every plate."""
from __future__ import annotations

import itertools

import mpmath as mp
import pytest

import restitution as r

from independent import TABLES, printed_equations, table_material, table_rows

#: The paper's presets (Tables 1-3); those from handbooks, appended after them, are checked against their
#: references in tests/cli/test_handbook_presets.py.
M = {key: m for key, m in r.MATERIALS.items() if m.source.startswith("Green (2022)")}


@pytest.mark.parametrize("table,key,row", list(table_rows()), ids=lambda x: x if isinstance(x, str) else "")
def test_preset_equals_the_table(table, key, row):
    mat = M[key]
    for prop in ("E", "nu", "Sy", "rho"):
        if prop in row:
            assert getattr(mat, prop) == row[prop], (table, key, prop)
    if row.get("handbook"):
        assert "handbook" in mat.source, (key, mat.source)


def test_every_preset_comes_from_a_table():
    in_tables = {key for _table, key, _row in table_rows()}
    assert set(M) <= in_tables, set(M) - in_tables
    complete = {}  # every preset has E, nu, Sy and rho somewhere in the tables
    for _table, key, row in table_rows():
        complete.setdefault(key, set()).update(p for p in ("E", "nu", "Sy", "rho") if p in row)
    assert all(props == {"E", "nu", "Sy", "rho"} for props in complete.values()), complete


@pytest.mark.parametrize("case", ["A1", "A2", "A3", "A4", "B1", "B2", "B3", "B4"])
def test_table4_cases(case):
    t4 = TABLES["table4"]
    family = t4[case[0]]
    sphere, plate = r.table4_case(case)
    assert (sphere.rho, sphere.E, plate.rho, plate.E) == (family["sphere_rho"], family["sphere_E"],
                                                          family["plate_rho"], family["plate_E"])
    assert sphere.nu == plate.nu == t4["nu"]
    assert plate.Sy == t4["plate_Sy"][case[1]] and sphere.Sy == 1e12


@pytest.mark.parametrize("sphere,plate", list(itertools.product(sorted(M), ["al_6061", "s7_tool_steel",
                                                                               "stainless_440c", "nitinol_60",
                                                                               "borosilicate_glass"])))
def test_every_preset_through_the_printed_equations(sphere, plate):
    mp.mp.dps = 30
    d, t, v = 6.35e-3, 3.18e-3, 2.3
    eps_y, v_c, lam = printed_equations(table_material(sphere), table_material(plate), d, t, v)
    res = r.impact_between(r.Sphere(M[sphere], d), r.Plate(M[plate], t), v)
    assert res.eps_y == pytest.approx(float(eps_y), rel=1e-13)
    assert res.V_c == pytest.approx(float(v_c), rel=1e-13)
    assert res.lam == pytest.approx(float(lam), rel=1e-13)


def test_paper_checkpoint_from_the_table():
    """Sec. 7: S2 tool steel on Al 6061 (Table 3): V_c = 0.0265 m/s, V* = 86.9 at 2.3 m/s."""
    mp.mp.dps = 30
    _eps, v_c, _lam = printed_equations(table_material("s2_tool_steel"), table_material("al_6061"), 6.35e-3, 6.35e-3, 2.3)
    assert round(float(v_c), 4) == 0.0265 and round(2.3 / float(v_c), 1) == 86.9
