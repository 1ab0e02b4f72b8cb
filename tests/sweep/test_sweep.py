"""Design-space sweeps (restitution.sweep): specs, both back ends, a 2-worker Dask cluster
against a serial run, the CLI on an existing scheduler, the table and the COR map."""
import math
import os
import sys
import time
import zipfile
from xml.etree import ElementTree as ET

import numpy as np
import pytest

import restitution as r

from independent import apparent_cor, table_material
from restitution.fmu.models.sphere_plate_impact.variables import MATERIAL_SELECTORS
from restitution.fmu.models.sphere_plate_impact.variables import TABLE as IMPACT_TABLE
from restitution.model import PARAMETERS, published
from restitution.sweep import (INPUTS, OUTPUTS, SweepSpec, code_fingerprint, compare_results, open_client,
                               read_table, release_fmus, run_sweep)
from restitution.sweep.__main__ import main as sweep_cli
from restitution.sweep.compare import agreement_report
from restitution.sweep.spec import RANDOM_BLOCK

TOL = 1e-12

#: Three pairs (one from Table 4), speeds from well below to far above yield, thin to thick
#: plates, two Zener methods, two restitution models, and a wide scatter of the sphere modulus
#: that drives some cases out of range (E <= 0): 2 * 3 * 7 * 4 * 2 * 2 = 1344 cases.
SPEC = dict(
    pairs=["s2_tool_steel/al_6061", "borosilicate_glass/stainless_440c", "table4:A2"],
    grid={"v_approach": {"geomspace": [0.02, 30.0, 7]}, "t_over_d": [0.05, 0.3, 1.0, 4.0],
          "zener_method": ["exact", "linear"], "restitution_model": ["e45", "e44"]},
    random={"sphere.E": {"normal_rel": 0.5}}, samples=2, seed=11,
)


@pytest.fixture(scope="module")
def cluster():
    """A 2-worker LocalCluster (processes), closed when the module's tests are done."""
    with open_client("local", n_workers=2) as client:
        yield client
    assert client.status == "closed"


@pytest.fixture(scope="module")
def serial(impact_fmu):
    spec = SweepSpec(**SPEC)
    return {"package": run_sweep(spec, "package", scheduler="serial"),
            "fmu": run_sweep(spec, "fmu", fmu=impact_fmu, scheduler="serial", chunk_size=500)}


# --- the spec ----------------------------------------------------------------------------
def test_cases_do_not_depend_on_chunking_and_are_reproducible():
    spec = SweepSpec(pairs=["brass_260/al_6061"], grid={"v_approach": [0.5, 1, 2]},
                     random={"plate.t": {"loguniform": [1e-3, 1e-2]}, "sphere.E": {"normal_rel": 0.05}},
                     samples=3000, seed=3)
    assert spec.n_cases == 9000 > RANDOM_BLOCK
    whole = spec.cases()
    for step in (1000, 4096, 777):
        parts = [spec.cases(a, a + step) for a in range(0, spec.n_cases, step)]
        for name, col in whole.items():
            assert np.array_equal(np.concatenate([p[name] for p in parts]), col), (step, name)
    assert np.array_equal(SweepSpec(**{**spec.as_dict()}).cases()["plate.t"], whole["plate.t"])
    other = SweepSpec(**{**spec.as_dict(), "seed": 4}).cases()
    assert not np.any(other["plate.t"] == whole["plate.t"])
    # case i: grid point i // samples (last axis fastest), draws within range, pair values set
    assert np.array_equal(whole["v_approach"], np.repeat([0.5, 1.0, 2.0], 3000))
    assert 1e-3 <= whole["plate.t"].min() and whole["plate.t"].max() <= 1e-2
    brass = r.MATERIALS["brass_260"]
    assert abs(np.mean(whole["sphere.E"]) / brass.E - 1) < 0.003
    assert abs(np.std(whole["sphere.E"]) / brass.E - 0.05) < 0.003
    assert np.all(whole["plate.E"] == r.MATERIALS["al_6061"].E)
    assert np.allclose(whole["t_over_d"], whole["plate.t"] / 6.35e-3)


def test_draws_are_each_blocks_own_generator_in_the_specs_order():
    """What the docs promise about the draws, computed here with numpy's distributions directly: case
    block b (RANDOM_BLOCK cases) draws from default_rng([seed, b]), each random input in the spec's
    order drawing a whole block, with rng.uniform, rng.standard_normal and rng.integers. Compared to
    a few ulps (the sweep applies the parameters to a whole range at once; the same operations)."""
    random = {"plate.Sy": "uniform_rel:0.15", "plate.t": "uniform:1mm:5mm", "v_approach": "normal:2:0.2",
              "sphere.E": "normal_rel:0.03", "sphere.d": "loguniform:1mm:1cm", "zener_method": "choice:1,3"}
    spec = SweepSpec(pairs=["brass_260/al_6061"], random=random, samples=2 * RANDOM_BLOCK + 100, seed=11)
    brass = r.MATERIALS["brass_260"]
    start, stop = RANDOM_BLOCK - 50, 2 * RANDOM_BLOCK + 60  # a range across two block boundaries
    got = spec.cases(start, stop)
    want = {k: [] for k in random}
    for b in range(3):
        rng = np.random.default_rng([11, b])
        want["plate.Sy"].append(rng.uniform(0.85, 1.15, RANDOM_BLOCK) * r.MATERIALS["al_6061"].Sy)
        want["plate.t"].append(rng.uniform(1e-3, 5e-3, RANDOM_BLOCK))
        want["v_approach"].append(2 + 0.2 * rng.standard_normal(RANDOM_BLOCK))
        want["sphere.E"].append((1 + 0.03 * rng.standard_normal(RANDOM_BLOCK)) * brass.E)
        want["sphere.d"].append(np.exp(rng.uniform(np.log(1e-3), np.log(1e-2), RANDOM_BLOCK)))
        want["zener_method"].append(np.array([1.0, 3.0])[rng.integers(0, 2, RANDOM_BLOCK)])
    for k, blocks in want.items():
        expected = np.concatenate(blocks)[start:stop]
        np.testing.assert_allclose(np.asarray(got[k], dtype=float), expected, rtol=4 * np.finfo(float).eps, err_msg=k)


def test_one_value_columns_are_read_only_views_and_pairs_split_inside_a_range():
    spec = SweepSpec(pairs=["brass_260/al_6061", "s2_tool_steel/borosilicate_glass"], grid={"v_approach": [0.5, 1, 2]},
                     fixed={"zener_method": "paper_fit"})
    one_pair, both = spec.cases(0, 3), spec.cases(0, 6)  # cases 0-2: the first pair; 3-5: the second
    for name in ("sphere.E", "plate.rho", "sphere.d", "zener_method"):  # one value in the range: no memory
        col = one_pair[name]
        assert col.strides == (0,) and not col.flags.writeable, name
    assert one_pair["zener_method"][0] == 2.0 and one_pair["sphere.d"][0] == 6.35e-3
    brass, steel = r.MATERIALS["brass_260"], r.MATERIALS["s2_tool_steel"]
    assert list(both["sphere.E"]) == [brass.E] * 3 + [steel.E] * 3  # two pairs in one range: each its own
    assert list(both["plate.E"]) == [r.MATERIALS["al_6061"].E] * 3 + [r.MATERIALS["borosilicate_glass"].E] * 3
    # the table holds whole columns (an input fixed over the whole sweep: a read-only view of its value);
    # a chunk spanning both pairs gives each case its own inputs (data, equal exactly) and outputs within
    # their conditioning (two evaluations: numpy's kernels may differ in the last bit between array lengths)
    cut = run_sweep(spec, "package", scheduler="serial", chunk_size=3)
    joint = run_sweep(spec, "package", scheduler="serial", chunk_size=4)
    fixed = {name for name, col in cut.columns.items() if col.strides == (0,)}
    assert {"zener_method", "sphere.d"} <= fixed and not fixed & {"sphere.E", "pair", "v_approach", "e"}
    assert all(col.flags.writeable != (name in fixed) for name, col in cut.columns.items())
    for name in ("case", "pair", *(n for n, _kw, _t, _s in INPUTS), "t_over_d"):
        assert np.array_equal(joint[name], cut[name]), name
    compared, problems = agreement_report(joint.columns, cut.columns)
    assert compared == 6 and not problems, problems


def test_grid_axes_names_and_derived_thickness():
    spec = SweepSpec(grid={"v": "0.5,1", "t/d": "geomspace:0.1:10:3", "sphere_d": [2e-3, 4e-3]},
                     fixed={"zener_method": "paper_fit", "plasticity": "off"})
    assert spec.shape == (2, 3, 2) and spec.n_cases == 12
    c = spec.cases()
    assert np.array_equal(c["v_approach"], np.repeat([0.5, 1.0], 6))
    assert np.allclose(c["plate.t"], np.tile(np.repeat([0.1, 1.0, 10.0], 2) * np.array([2e-3, 4e-3] * 3), 2))
    assert np.all(c["zener_method"] == 2) and np.all(c["plasticity"] == 0)
    assert np.all(c["sphere.E"] == 207e9) and np.all(c["pair"] == -1)  # FMU start values elsewhere


@pytest.mark.parametrize("bad, message", [
    (dict(pairs=["s2_tool_steel/al_6061"], grid={"sphere.E": [1e11, 2e11]}), "set by the material pairs"),
    (dict(grid={"plate.t": [1e-3], "t_over_d": [1.0]}), "plate.t and t_over_d"),
    (dict(grid={"sphere.G": [1.0]}), "unknown sweep parameter"),
    (dict(pairs=["steel/al_6061"]), "unknown material"),
    (dict(grid={"zener_method": ["exactly"]}), "zener_method"),
    (dict(random={"v_approach": {"uniform": [2, 1]}}), "low < high"),
    (dict(grid={"v_approach": [1.0]}, fixed={"v_approach": 2.0}), "set twice"),
])
def test_bad_specs_name_the_problem(bad, message):
    with pytest.raises(ValueError, match=message):
        SweepSpec(**bad)


def test_parameter_table_matches_the_fmu(impact_fmu):
    with zipfile.ZipFile(impact_fmu) as z:
        root = ET.fromstring(z.read("modelDescription.xml"))
    found = {sv.get("name"): (sv.get("causality"), sv[0].tag, sv[0].get("start"))
             for sv in root.find("ModelVariables")}
    expected = {name: ("input" if name == "v_approach" else "parameter", vtype, start)
                for name, _kw, vtype, start in INPUTS}
    expected.update({name: ("output", vtype, None) for name, _f, vtype in OUTPUTS})
    # what a sweep leaves alone: the material selectors (custom: a sweep sets the properties) and
    # the properties used that they show
    expected.update({name: ("parameter", "Enumeration", 0) for name in MATERIAL_SELECTORS})
    expected.update({v.name: ("calculatedParameter", "Real", None) for v in IMPACT_TABLE.calculated})
    assert set(found) == set(expected)
    for name, (causality, vtype, start) in expected.items():
        assert found[name][:2] == (causality, vtype), name
        if start is not None:
            assert float(found[name][2]) == start, name


# --- back ends, serial -------------------------------------------------------------------
def test_serial_backends_agree_and_match_impact(serial):
    package, fmu = serial["package"], serial["fmu"]
    diffs = compare_results(fmu, package)
    assert max(diffs.values()) <= TOL, diffs
    cols = package.columns
    # the scatter drove some sphere moduli below zero: those cases are flagged and NaN in both
    bad = ~cols["ok"]
    assert 0 < bad.sum() < 0.2 * len(package)
    assert np.all(cols["sphere.E"][bad] <= 0) and np.all(cols["sphere.E"][~bad] > 0)
    assert np.all(np.isnan(cols["e"][bad])) and np.all(np.isnan(fmu["e"][bad]))
    assert not np.any(cols["valid"][bad])
    # every valid case is what impact() gives for the same inputs, one at a time
    models, methods = r.RESTITUTION_MODELS, r.ZENER_METHODS
    for i in np.flatnonzero(~bad)[::37]:
        kw = {k: float(cols[k.replace("_", ".", 1)][i]) for k, _unit, _check in PARAMETERS}
        res = r.impact(float(cols["v_approach"][i]), **kw,
                       restitution_model=models[int(cols["restitution_model"][i]) - 1],
                       zener_method=methods[int(cols["zener_method"][i]) - 1])
        assert fmu["e"][i] == pytest.approx(res.e, rel=1e-13, abs=1e-15)
        # the table publishes t_contact = 0 where the contact never ends (a finite encoding)
        assert fmu["zener.t_contact"][i] == pytest.approx(published(res.as_dict())["t_contact"], rel=1e-12)
        assert bool(fmu["valid"][i]) == bool(res.valid)
    # the FMU ran the code it ships (built from these sources: the same as this process's package)
    assert os.path.basename(fmu.info["fmu_code_files"][0]) == "model.py"
    assert fmu.info["code"] == [package.info["code"][0]] == [code_fingerprint()]


def test_fmu_instantiation_leaves_the_hosts_modules_in_place(impact_fmu, monkeypatch):
    """While the back end creates an instance, every ``restitution`` module of this process stays in
    sys.modules: a Dask worker's other threads import them meanwhile (a task being unpickled), and
    found them missing when the back end set them aside ("No module named 'restitution.sweep'")."""
    from restitution.cosim import fmu as cosim_fmu  # the back end imports quiet_instantiate from there, when it runs

    before = {k: v for k, v in sys.modules.items() if k == "restitution" or k.startswith("restitution.")}
    during = []

    def watching(slave):
        during.append({k: sys.modules.get(k) for k in before})
        return real(slave)

    real = cosim_fmu.quiet_instantiate
    monkeypatch.setattr(cosim_fmu, "quiet_instantiate", watching)
    release_fmus()  # a new instance, not one this thread kept from an earlier test
    try:
        res = run_sweep(SweepSpec(pairs=["s2_tool_steel/al_6061"], grid={"v_approach": [1.0]}), "fmu",
                        fmu=impact_fmu, scheduler="serial")
    finally:
        release_fmus()
    assert len(during) == 1
    moved = [k for k, module in during[0].items() if module is not before[k]]
    assert not moved, f"set aside while the FMU was instantiated: {moved[:5]}"
    # the FMU's default case against Eqs. (8), (12), (20) solved independently (tests/independent.py)
    assert res["e"][0] == pytest.approx(apparent_cor(table_material("s2_tool_steel"), table_material("al_6061"),
                                                     6.35e-3, 6.35e-3, 1.0), rel=1e-8)


def test_an_fmu_built_from_other_sources_runs_its_own_copy(impact_fmu, tmp_path):
    """An FMU whose package differs from this process's (here: one comment line added to its model.py)
    runs the copy it ships, under a private name; the results report that copy and its fingerprint."""
    changed = tmp_path / "SpherePlateImpact.fmu"
    with zipfile.ZipFile(impact_fmu) as src, zipfile.ZipFile(changed, "w", zipfile.ZIP_DEFLATED) as dst:
        for item in src.infolist():
            data = src.read(item)
            if item.filename == "resources/restitution/model.py":
                data += b"\n# a build from other sources\n"
            dst.writestr(item, data)
    release_fmus()
    try:
        res = run_sweep(SweepSpec(pairs=["s2_tool_steel/al_6061"], grid={"v_approach": [0.5, 1.0]}), "fmu",
                        fmu=changed, scheduler="serial")
    finally:
        release_fmus()
    code_file = res.info["fmu_code_files"][0]
    assert code_file.endswith(os.path.join("resources", "restitution", "model.py"))
    assert os.path.dirname(r.__file__) not in code_file
    assert res.info["code"][0] != code_fingerprint()  # the changed model.py
    assert "restitution" in sys.modules and sys.modules["restitution"] is r  # the host's package untouched
    expected = [apparent_cor(table_material("s2_tool_steel"), table_material("al_6061"), 6.35e-3, 6.35e-3, v)
                for v in (0.5, 1.0)]
    assert res["e"] == pytest.approx(expected, rel=1e-8)


def test_known_value_and_physical_trends():
    spec = SweepSpec(pairs=["s2_tool_steel/al_6061"],
                     grid={"v_approach": [0.5, 1.0, 3.0], "t_over_d": [0.2, 1.0, 5.0]})
    res = run_sweep(spec, scheduler="serial")
    e = res["e"].reshape(3, 3)  # [speed, t/d]
    # the FMU's default case (S2 steel ball, d = t = 6.35 mm, on Al 6061 at 1 m/s)
    # exact method (relative error <= 4e-10 in e_ze) against Eqs. (8), (12), (20) and the ODE solved
    # independently in tests/independent.py
    assert e[1, 1] == pytest.approx(apparent_cor(table_material("s2_tool_steel"), table_material("al_6061"),
                                                 6.35e-3, 6.35e-3, 1.0), rel=1e-8)
    assert np.all(np.diff(e, axis=0) < 0)  # faster: more plasticity and plate waves, lower e
    assert np.all(np.diff(e, axis=1) > 0)  # thicker plate: fewer plate waves, higher e
    assert res.columns["pair"][0] == "s2_tool_steel/al_6061"


# --- on a 2-worker cluster ---------------------------------------------------------------
def test_cluster_matches_serial_for_both_backends(cluster, serial, impact_fmu):
    spec = SweepSpec(**SPEC)
    dask_package = run_sweep(spec, "package", scheduler=cluster)
    dask_fmu = run_sweep(spec, "fmu", fmu=impact_fmu, scheduler=cluster, chunk_size=100)
    assert dask_package.n_workers == dask_fmu.n_workers == 2
    assert dask_fmu.n_chunks == math.ceil(spec.n_cases / 100)
    assert dask_fmu.info["processes"] == 2  # one FMU instance in each worker process
    for ours, theirs in ((dask_package, serial["package"]), (dask_fmu, serial["fmu"]),
                         (dask_fmu, serial["package"])):
        for name in ("case", "pair", "sphere.E", "plate.t", "v_approach"):
            assert np.array_equal(ours[name], theirs[name]), name
        diffs = compare_results(ours, theirs)
        assert max(diffs.values()) <= TOL, diffs
    # worker-side FMU instances were freed at the end of the sweep
    assert set(cluster.run(release_fmus).values()) == {0}


def test_cli_on_an_existing_scheduler_writes_table_and_map(cluster, impact_fmu, tmp_path, capsys):
    spec_file = tmp_path / "map.toml"
    spec_file.write_text(
        'pairs = ["s2_tool_steel/al_6061", "chrome_steel/s7_tool_steel"]\n'
        '[grid]\n'
        'v_approach = {geomspace = [0.1, 10.0, 9]}\n'
        't_over_d = {geomspace = [0.1, 10.0, 7]}\n'
        '[run]\n'
        'backend = "both"\n')
    out = tmp_path / "map.csv"
    status = sweep_cli([str(spec_file), "--scheduler", cluster.scheduler.address, "--fmu", str(impact_fmu),
                        "--out", str(out), "--no-progress"])
    text = capsys.readouterr().out
    assert status == 0, text
    assert "126 cases" in text and "agree on all 126 cases" in text and "2 worker(s)" in text
    table = read_table(out)
    expected = run_sweep(SweepSpec(pairs=["s2_tool_steel/al_6061", "chrome_steel/s7_tool_steel"],
                                   grid={"v_approach": {"geomspace": [0.1, 10.0, 9]},
                                         "t_over_d": {"geomspace": [0.1, 10.0, 7]}}), scheduler="serial")
    for name, col in expected.columns.items():
        assert np.array_equal(table[name], col) if col.dtype != float else \
            np.array_equal(table[name], col, equal_nan=True), name
    png = out.with_name("map_cor_map.png")
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 20_000


def test_parquet_table_round_trip(tmp_path):
    pytest.importorskip("pyarrow")
    res = run_sweep(SweepSpec(grid={"v_approach": [0.3, 3.0]}, random={"plate.t": {"uniform": [1e-3, 5e-3]}},
                              samples=5), scheduler="serial")
    table = read_table(res.write(tmp_path / "t.parquet"))
    for name, col in res.columns.items():
        assert np.array_equal(table[name], col), name
    import pyarrow.parquet as pq

    schema = pq.read_schema(tmp_path / "t.parquet")  # no column of a sweep has missing values
    assert schema.names == list(res.columns) and not any(field.nullable for field in schema)
    # the pair dictionary-encoded: a categorical in pandas, a few labels in the file
    assert str(schema.field("pair").type) == "dictionary<values=string, indices=int32, ordered=0>"
    assert str(schema.field("e").type) == "double"


def test_dask_scheduler_address_setting_is_used(cluster):
    import dask

    spec = SweepSpec(pairs=["chrome_steel/s7_tool_steel"], grid={"v_approach": [0.5, 2.0, 8.0]})
    with dask.config.set({"scheduler-address": cluster.scheduler.address}):
        res = run_sweep(spec)  # no scheduler given: Dask's configured one, not a new LocalCluster
    assert res.scheduler == f"the Dask scheduler at {cluster.scheduler.address}" and res.n_workers == 2
    assert np.array_equal(res["e"], run_sweep(spec, scheduler="serial")["e"])


def test_fewer_columns_same_numbers(serial, impact_fmu):
    spec = SweepSpec(**SPEC)
    for backend in ("package", "fmu"):
        res = run_sweep(spec, backend, fmu=impact_fmu, scheduler="serial", columns=["v_approach", "e", "valid"])
        # case, pair, ok and the validity flags travel with every row
        assert list(res.columns) == ["case", "pair", "v_approach", "e", "valid", "zener.in_range", "jgm.in_range",
                                     "ok"]
        for name in res.columns:
            assert np.array_equal(res[name], serial[backend][name], equal_nan=name == "e"), (backend, name)
    with pytest.raises(ValueError, match="unknown column"):
        run_sweep(spec, scheduler="serial", columns=["E"])


@pytest.mark.parametrize("few, many", [("v_approach", "t_over_d"), ("t_over_d", "v_approach")])
def test_a_few_values_of_one_input_are_drawn_as_curves(tmp_path, monkeypatch, few, many):
    """COR against thickness at 1, 3 and 5 m/s: one labelled curve per speed through every case of
    that speed (not a colour map of three wide blocks); and the same the other way round."""
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    from restitution.sweep.plot import plot_cor_map

    grid = {few: [1.0, 3.0, 5.0] if few == "v_approach" else [0.2, 0.5, 1.0],
            many: {"linspace": [0.1, 2.0, 40]} if many == "t_over_d" else {"linspace": [0.5, 8.0, 40]}}
    res = run_sweep(SweepSpec(pairs=["s2_tool_steel/al_6061"], grid=grid), scheduler="serial")
    saved = []
    monkeypatch.setattr(Figure, "savefig", lambda fig, path, **kw: saved.append(fig))
    plot_cor_map(res, tmp_path / "map.png")
    ax = saved[0].axes[0]
    assert not ax.collections, "a colour map or scatter was drawn"
    curves = [line for line in ax.lines if line.get_label() and not line.get_label().startswith("_")
              and len(line.get_xdata()) > 1]
    unit = " m/s" if few == "v_approach" else ""
    assert sorted(line.get_label() for line in curves) == sorted(
        f"{'v' if few == 'v_approach' else 't/d'} = {value:g}{unit}" for value in grid[few])
    for line in curves:
        value = float(line.get_label().split("= ")[1].split()[0])
        sel = res.columns[few] == value
        assert np.array_equal(np.sort(line.get_xdata()), np.sort(res.columns[many][sel]))
        assert np.array_equal(np.sort(line.get_ydata()), np.sort(res.columns["e"][sel]))  # the data as computed


def test_several_pairs_over_one_input_share_one_panel_and_the_title_names_the_fixed_values(tmp_path, monkeypatch):
    """Two pairs over speeds only: one panel, a curve per pair (labelled by the pair, the data as computed),
    and the title names what the sweep held fixed."""
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    from restitution.sweep.plot import plot_cor_map
    from restitution.sweep.spec import pair_label

    pairs = ["s2_tool_steel/al_6061", "chrome_steel/brass_260"]
    spec = SweepSpec(pairs=pairs, grid={"v_approach": {"geomspace": [0.1, 10.0, 12]}}, fixed={"plate.t": "3mm"})
    res = run_sweep(spec, scheduler="serial")
    saved = []
    monkeypatch.setattr(Figure, "savefig", lambda fig, path, **kw: saved.append(fig))
    plot_cor_map(res, tmp_path / "map.png")
    (ax,) = [a for a in saved[0].axes if a.get_visible()]
    curves = {line.get_label(): line for line in ax.lines if not line.get_label().startswith("_")
              and len(line.get_xdata()) > 1}
    assert sorted(curves) == sorted(pair_label(p) for p in pairs)
    for k, pair in enumerate(pairs):
        sel = res.columns["pair"] == pair if res.columns["pair"].dtype == object else res.columns["pair"] == k
        line = curves[pair_label(pair)]
        assert np.array_equal(np.sort(line.get_ydata()), np.sort(res.columns["e"][sel]))
    assert "plate.t = 3mm" in saved[0]._suptitle.get_text()


def test_local_workers_keep_glibc_allocation_thresholds(cluster):
    """The sweep's LocalCluster starts its workers without Dask's MALLOC_TRIM_THRESHOLD_ (which makes
    glibc map and page-fault every large array afresh: twice the CPU time of a package chunk), and
    leaves this process's environment and Dask's configuration as they were."""
    import dask

    got = cluster.run(lambda: os.environ.get("MALLOC_TRIM_THRESHOLD_"))
    assert len(got) == 2 and set(got.values()) == {None}
    assert os.environ.get("MALLOC_TRIM_THRESHOLD_") is None
    assert "MALLOC_TRIM_THRESHOLD_" in dask.config.get("distributed.nanny.pre-spawn-environ")


def test_a_dask_sweep_keeps_few_chunks_in_flight(cluster, monkeypatch):
    """Chunks are submitted a few per worker at a time, the next when one is taken, so a sweep that
    this process takes more slowly than the workers compute never holds more than that many chunks in
    the cluster: memory does not grow with the sweep. Observed from the scheduler while this process
    is made slow at taking each chunk; the table is the serial one."""
    from restitution.sweep import run as sweep_run

    seen = []
    original = sweep_run._Run.finished

    def slow_finished(self, a, b, part):
        seen.append(cluster.run_on_scheduler(lambda dask_scheduler: sum(
            1 for key in dask_scheduler.tasks if "_run_chunk" in str(key))))
        time.sleep(0.02)
        original(self, a, b, part)

    monkeypatch.setattr(sweep_run._Run, "finished", slow_finished)
    spec = SweepSpec(grid={"v_approach": {"geomspace": [0.1, 10.0, 400]}})
    result = run_sweep(spec, "package", scheduler=cluster, chunk_size=10)
    assert len(seen) == 40 and max(seen) <= sweep_run.IN_FLIGHT_PER_WORKER * 2
    expected = run_sweep(spec, "package", scheduler="serial")
    assert np.array_equal(result.columns["e"], expected.columns["e"])


def test_serial_in_memory_chunks_are_the_back_ends_own_unless_it_names_bigger_ones(tmp_path):
    """A serial sweep kept in memory takes the back end's ``in_memory_chunk`` cases at a time (the package's:
    10^6, so a small sweep is one chunk); a back end without one keeps its ``default_chunk``, as does any
    sweep that writes its chunks to disk."""
    from restitution.sweep.backends import PackageBackend

    class SmallChunks(PackageBackend):
        default_chunk, in_memory_chunk = 7, None

    spec = SweepSpec(pairs=["s2_tool_steel/al_6061"], grid={"v_approach": [0.5, 1, 2, 3, 4], "t_over_d": [0.5, 1, 2, 4]})
    assert run_sweep(spec, "package", scheduler="serial").n_chunks == 1
    assert run_sweep(spec, SmallChunks(), scheduler="serial").n_chunks == 3  # 20 cases, 7 at a time
    assert run_sweep(spec, SmallChunks(), scheduler="serial", parts=tmp_path / "p").n_chunks == 3


def test_serial_in_memory_chunks_hold_a_few_seconds_of_work_for_the_progress_bar(monkeypatch):
    """A slow option (zener_method = ode, about 6 ms a case) makes the in-memory chunks smaller, so that
    each is about IN_MEMORY_SECONDS of work (made 30 ms here: 5 ode cases, 10^5 default ones)."""
    from restitution.sweep import run as sweep_run

    monkeypatch.setattr(sweep_run, "IN_MEMORY_SECONDS", 0.03)
    grid = {"v_approach": [0.5, 1, 2, 3, 4], "t_over_d": [0.5, 1, 2, 4]}
    ode = SweepSpec(pairs=["s2_tool_steel/al_6061"], grid=grid, fixed={"zener_method": "ode"})
    assert run_sweep(ode, "package", scheduler="serial").n_chunks == 4  # 20 cases, 5 at a time
    assert run_sweep(SweepSpec(pairs=["s2_tool_steel/al_6061"], grid=grid), "package", scheduler="serial").n_chunks == 1
