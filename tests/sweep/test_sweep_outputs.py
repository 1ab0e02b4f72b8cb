"""What a sweep writes, read back from outside: the plot's file named for what it holds (a grid's COR map, a
histogram of e), the CSV header's units and its numbers (the decimals given, Python's shortest round-trip
text), the Parquet field units, older headers read back, a plot for whatever --columns keeps (or one line
why none), and the cases with e < 0 counted and said. Small sweeps, package back end, in this process."""
import csv
import json

import numpy as np
import pytest

from restitution.fmu.models.sphere_plate_impact.variables import TABLE
from restitution.sweep import read_table
from restitution.sweep.__main__ import main as sweep_cli

RUN = ["--scheduler", "serial", "--backend", "package", "--no-progress"]
PAIR = ["--pair", "s2_tool_steel/al_6061"]
#: A 6.35 mm steel ball on a 1 mm aluminium sheet at 2-3 m/s: e < 0 at every draw (the paper's thin plates).
THIN_SHEET = [*PAIR, "--set", "sphere.d=6.35mm", "--set", "plate.t=1mm", "--random", "v_approach=uniform:2:3"]


def _sweep(capsys, tmp_path, *args, out="s.csv"):
    """(exit status, stdout, stderr) of the sweep command run in this process, writing ``tmp_path/out``."""
    status = sweep_cli([*args, *RUN, "--out", str(tmp_path / out)])
    captured = capsys.readouterr()
    return status, captured.out, captured.err


def _csv(path):
    with open(path, newline="", encoding="utf-8") as f:
        rows = list(csv.reader(f))
    return rows[0], rows[1:]


def _column(path, header_cell):
    header, rows = _csv(path)
    j = header.index(header_cell)
    return [row[j] for row in rows]


# --- the plot's file is named for what it holds ---------------------------------------------------
def test_a_histogram_is_written_and_announced_as_one(tmp_path, capsys):
    status, out, _err = _sweep(capsys, tmp_path, *PAIR, "--random", "v_approach=uniform:1:3", "--samples", "200")
    assert status == 0
    assert (tmp_path / "s_hist.png").is_file() and not (tmp_path / "s_cor_map.png").exists()
    assert f"histogram of e: {tmp_path / 's_hist.png'}" in out.splitlines()
    assert "COR map" not in out


def test_a_grid_writes_its_cor_map(tmp_path, capsys):
    status, out, _err = _sweep(capsys, tmp_path, *PAIR, "--grid", "v_approach=1,2,3", "--grid", "t_over_d=0.5,1,2")
    assert status == 0
    assert (tmp_path / "s_cor_map.png").is_file() and not (tmp_path / "s_hist.png").exists()
    assert f"COR map: {tmp_path / 's_cor_map.png'}" in out.splitlines()


# --- the table: units in the header, the numbers as given --------------------------------------
def test_csv_header_carries_each_quantitys_unit_and_none_for_the_rest(tmp_path, capsys):
    assert _sweep(capsys, tmp_path, *PAIR, "--grid", "v_approach=1,2", "--no-plot")[0] == 0
    header, rows = _csv(tmp_path / "s.csv")
    units = {v.name: v.unit or "1" for v in (*TABLE.settable, *TABLE.outputs) if v.type == "Real"}
    units["t_over_d"] = "1"
    expected = {"v_approach": "v_approach [m/s]", "e": "e [1]", "sphere.rho": "sphere.rho [kg/m3]",
                "zener.t_contact": "zener.t_contact [s]", "plate.E": "plate.E [Pa]", "t_over_d": "t_over_d [1]",
                "case": "case", "pair": "pair", "valid": "valid", "e_negative": "e_negative",
                "zener_method": "zener_method", "ok": "ok"}
    for name, cell in expected.items():
        assert cell in header, (name, header)
    for cell in header:
        name, _, unit = cell.partition(" [")
        if name in units:
            assert unit == units[name] + "]", cell
        else:
            assert cell == name, cell  # no quantity: no brackets
    # every float as the shortest text that reads back as the same double
    floats = [j for j, cell in enumerate(header) if "[" in cell]
    for row in rows:
        for j in floats:
            assert repr(float(row[j])) == row[j], (header[j], row[j])


@pytest.mark.parametrize("grid, column, cells", [
    ("v_approach=linspace:0.1:0.5:5", "v_approach [m/s]", ["0.1", "0.2", "0.3", "0.4", "0.5"]),
    ("v_approach=arange:0.1:0.5:0.1", "v_approach [m/s]", ["0.1", "0.2", "0.3", "0.4"]),
    ("plate.t=linspace:1mm:5mm:9", "plate.t [m]",
     ["0.001", "0.0015", "0.002", "0.0025", "0.003", "0.0035", "0.004", "0.0045", "0.005"]),
    ("t_over_d=geomspace:2:32:5", "t_over_d [1]", ["2.0", "4.0", "8.0", "16.0", "32.0"]),
    ("t_over_d=linspace:0.7:1:4", "t_over_d [1]", ["0.7", "0.8", "0.9", "1.0"]),
])
def test_grid_values_are_the_decimals_given(tmp_path, capsys, grid, column, cells):
    assert _sweep(capsys, tmp_path, *PAIR, "--grid", grid, "--no-plot")[0] == 0
    assert _column(tmp_path / "s.csv", column) == cells


def test_a_value_with_a_unit_is_the_decimal_given(tmp_path, capsys):
    assert _sweep(capsys, tmp_path, *PAIR, "--set", "plate.t=4.5mm", "--set", "sphere.d=0.35in",
                  "--grid", "v_approach=1,2", "--no-plot")[0] == 0
    assert set(_column(tmp_path / "s.csv", "plate.t [m]")) == {"0.0045"}
    assert set(_column(tmp_path / "s.csv", "sphere.d [m]")) == {"0.00889"}


def test_read_table_reads_headers_with_and_without_units(tmp_path, capsys):
    assert _sweep(capsys, tmp_path, *PAIR, "--grid", "v_approach=linspace:0.5:2:4", "--no-plot")[0] == 0
    new = tmp_path / "s.csv"
    header, _rows = _csv(new)
    old = tmp_path / "old.csv"  # as written before the units: bare names
    text = new.read_text(encoding="utf-8").split("\n", 1)[1]
    old.write_text(",".join(cell.split(" [")[0] for cell in header) + "\n" + text, encoding="utf-8")
    a, b = read_table(new), read_table(old)
    assert list(a) == list(b) == [cell.split(" [")[0] for cell in header]
    for name in a:
        assert np.array_equal(a[name], b[name]), name
    assert a["v_approach"].tolist() == [0.5, 1.0, 1.5, 2.0]


def test_parquet_keeps_bare_names_and_units_in_field_metadata(tmp_path, capsys):
    pq = pytest.importorskip("pyarrow.parquet")
    assert _sweep(capsys, tmp_path, *PAIR, "--grid", "v_approach=1,2", "--no-plot", out="s.parquet")[0] == 0
    schema = pq.read_schema(tmp_path / "s.parquet")
    assert "v_approach" in schema.names and not any("[" in name for name in schema.names)
    unit = {name: (schema.field(name).metadata or {}).get(b"unit") for name in schema.names}
    assert unit["v_approach"] == b"m/s" and unit["e"] == b"1" and unit["zener.t_contact"] == b"s"
    assert unit["valid"] is None and unit["case"] is None and unit["pair"] is None
    assert read_table(tmp_path / "s.parquet")["v_approach"].tolist() == [1.0, 2.0]


# --- a plot for whatever --columns keeps ------------------------------------------------------
@pytest.fixture
def figures(monkeypatch):
    """The figures the sweep saves (still written)."""
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    saved, savefig = [], Figure.savefig

    def keep(fig, path, **kwargs):
        saved.append(fig)
        return savefig(fig, path, **kwargs)
    monkeypatch.setattr(Figure, "savefig", keep)
    return saved


def test_one_kept_input_gives_e_against_it(tmp_path, capsys, figures):
    status, out, err = _sweep(capsys, tmp_path, *PAIR, "--grid", "v_approach=linspace:0.5:3:6",
                              "--grid", "t_over_d=0.5", "--columns", "v_approach,e")
    assert status == 0 and "no COR map" not in err
    assert (tmp_path / "s_cor_map.png").is_file() and "COR map: " in out
    (ax,) = [a for a in figures[-1].axes if a.get_visible()]
    assert ax.get_xlabel() == "approach speed v [m/s]"
    table = read_table(tmp_path / "s.csv")
    (line,) = [line for line in ax.lines if len(line.get_xdata()) > 1]
    assert np.array_equal(line.get_xdata(), table["v_approach"])
    assert np.array_equal(line.get_ydata(), table["e"])


def test_two_kept_inputs_give_a_map_and_a_dropped_axis_is_named(tmp_path, capsys, figures):
    status, out, _err = _sweep(capsys, tmp_path, *PAIR, "--grid", "v_approach=linspace:0.5:4:8",
                               "--grid", "plate.t=linspace:2mm:6mm:9", "--columns", "v_approach,plate.t,e")
    assert status == 0 and "COR map: " in out
    ax = [a for a in figures[-1].axes if a.get_visible() and a.get_xlabel()][0]
    assert ax.get_xlabel() == "approach speed v [m/s]" and ax.get_ylabel() == "plate.t [m]"
    assert ax.collections, "no colour map"

    status, out, _err = _sweep(capsys, tmp_path, *PAIR, "--grid", "v_approach=1,3",
                               "--grid", "plate.t=linspace:2mm:6mm:5", "--columns", "plate.t,e", out="t.csv")
    assert status == 0 and "COR map: " in out
    (ax,) = [a for a in figures[-1].axes if a.get_visible()]
    assert ax.get_xlabel() == "plate.t [m]"
    title = " ".join(figures[-1]._suptitle.get_text().split())
    assert "v_approach not kept by --columns" in title


@pytest.mark.parametrize("columns, why", [
    ("e", "no COR map: --columns keeps none of the inputs the sweep varies (v_approach, t_over_d); keep one to "
          "draw e against it"),
    ("v_approach,t_over_d", "no COR map: --columns leaves out e, which the COR map draws"),
])
def test_no_plot_possible_is_one_line_saying_why(tmp_path, capsys, columns, why):
    status, out, err = _sweep(capsys, tmp_path, *PAIR, "--grid", "v_approach=1,2", "--grid", "t_over_d=0.5,1",
                              "--columns", columns)
    assert status == 0
    assert err.strip().splitlines() == [why]
    assert not (tmp_path / "s_cor_map.png").exists() and (tmp_path / "s.csv").is_file()


# --- e < 0 counted and said -------------------------------------------------------------------
def test_a_monte_carlo_with_negative_e_says_so(tmp_path, capsys):
    status, out, _err = _sweep(capsys, tmp_path, *THIN_SHEET, "--samples", "300", "--no-plot",
                               "--summary", str(tmp_path / "s.json"))
    assert status == 0
    e = np.array([float(x) for x in _column(tmp_path / "s.csv", "e [1]")])
    flags = _column(tmp_path / "s.csv", "e_negative")
    n = int(np.count_nonzero(e < 0))
    assert n == 300 == flags.count("True")  # the case this test is about: every draw
    (line,) = [line for line in out.splitlines() if line.startswith("e < 0 (e_negative):")]
    assert line.startswith(f"e < 0 (e_negative): {n:,} of 300 evaluated cases: the sphere keeps moving with the "
                           f"plate after the impact instead of bouncing back")
    assert "Eq. (20)" in line and "does not make valid false" in line
    valid = _column(tmp_path / "s.csv", "valid")
    (line,) = [line for line in out.splitlines() if line.startswith("valid = false")]
    assert f": {valid.count('False'):,} of 300 evaluated cases" in line and "lambda <= 1.5 and V* <= 1000" in line
    summary = json.loads((tmp_path / "s.json").read_text())
    assert summary["e_negative"]["n"] == n and "keeps moving with the plate" in summary["e_negative"]["meaning"]


def test_the_count_comes_from_e_when_only_e_is_kept_and_is_zero_when_none(tmp_path, capsys):
    status, out, _err = _sweep(capsys, tmp_path, *THIN_SHEET, "--samples", "50", "--no-plot", "--columns", "e")
    assert status == 0 and "e < 0 (e_negative): 50 of 50 evaluated cases: " in out
    status, out, _err = _sweep(capsys, tmp_path, *PAIR, "--random", "v_approach=uniform:1:2", "--samples", "50",
                               "--no-plot", out="t.csv")
    e = [float(x) for x in _column(tmp_path / "t.csv", "e [1]")]
    assert status == 0 and min(e) > 0
    assert "e < 0 (e_negative): 0 of 50 evaluated cases" in out.splitlines()
