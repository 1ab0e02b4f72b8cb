"""sweep --summary and the statistics of a random sweep (restitution.sweep.statistics).

The expected numbers come from outside the statistics code: a Monte Carlo of restitution.impact on
draws made here (another generator, another seed), numpy's mean, std and percentiles of the written
table's rows, and counts of the drawn inputs in the table. Sampling tolerances are derived in the
comments; every bound is 5 standard errors (a false failure about once in 1.7 million runs)."""
import os
import json
import math

import numpy as np
import pytest

import restitution as r
from restitution.materials import MATERIALS
from restitution.sweep import OUTPUTS, SweepSpec, read_table, run_sweep
from restitution.sweep import run as sweep_run
from restitution.sweep.__main__ import EXIT_INTERRUPTED, main as sweep_cli
from restitution.sweep.statistics import SweepStatistics, write_summary

#: Standard errors a sampled number may stray from its expectation.
Z = 5.0

#: An S2 tool steel ball (d = 6.35 mm) on a 3 mm Al 6061 plate at 2 m/s, the plate's yield strength
#: scattered uniformly by +-15 % around the preset's: e depends on it through e_ep (Eq. 8).
D, T, V, SCATTER = 6.35e-3, 3e-3, 2.0, 0.15
POINT = ["--pair", "s2_tool_steel/al_6061", "--set", "sphere.d=6.35mm", "--set", "plate.t=3mm",
         "--set", "v_approach=2m/s", "--random", f"plate.Sy=uniform_rel:{SCATTER}"]
SAMPLES = 4000

#: The statistics each output of the summary has, as the issue asks for them.
KEYS = {"mean", "std", "p2.5", "p50", "p97.5", "n", "n_out_of_range", "mean_ci95", "unit"}
#: Real outputs of the sweep table (the FMU's), and the SI units of a few, known here.
REAL_OUTPUTS = [name for name, _key, vtype in OUTPUTS if vtype == "Real"]
SI = {"e": "1", "jgm.e": "1", "zener.e": "1", "v_rebound": "m/s", "zener.t_contact": "s", "sphere.m": "kg"}


def sweep(tmp_path, *options, name="s", samples=SAMPLES, check=True):
    """Run the command line with POINT and ``options``; (status, summary dict or None, table path)."""
    out, summary = tmp_path / f"{name}.csv", tmp_path / f"{name}.json"
    status = sweep_cli([*POINT, "--samples", str(samples), "--seed", "7", "--out", str(out),
                        "--summary", str(summary), "--no-plot", "--no-progress", *options])
    if check:
        assert status == 0
    return status, (json.loads(summary.read_text()) if summary.exists() else None), out


def independent_draws(n: int, seed: int = 20240611) -> np.ndarray:
    """e of ``n`` impacts with plate.Sy drawn here (U(0.85, 1.15) x the preset's), by restitution.impact."""
    sphere, plate = MATERIALS["s2_tool_steel"].params("sphere"), MATERIALS["al_6061"].params("plate")
    rng = np.random.default_rng(seed)
    plate["plate_Sy"] = plate["plate_Sy"] * rng.uniform(1 - SCATTER, 1 + SCATTER, n)
    return np.asarray(r.impact(V, **sphere, sphere_d=D, **plate, plate_t=T).e, dtype=float)


def test_statistics_agree_with_an_independent_monte_carlo(tmp_path, capsys):
    _status, summary, _out = sweep(tmp_path, "--scheduler", "serial")
    e = summary["outputs"]["e"]
    mc = independent_draws(40_000)
    n, m = e["n"], mc.size
    assert n == SAMPLES and e["n_out_of_range"] == 0
    # mean: two independent sample means of one distribution differ by N(0, s^2 (1/n + 1/m))
    assert abs(e["mean"] - mc.mean()) < Z * mc.std(ddof=1) * math.sqrt(1 / n + 1 / m)
    # std: Var(s^2) = (mu4 - s^4 (n - 3)/(n - 1)) / n, so s has SE ~ sqrt(mu4 / s^4 - 1) s / (2 sqrt(n))
    s = mc.std(ddof=1)
    kurtosis = np.mean((mc - mc.mean()) ** 4) / s ** 4
    assert abs(e["std"] - s) < Z * math.sqrt(kurtosis - 1) * s / 2 * math.sqrt(1 / n + 1 / m)
    # a percentile x_p of n draws: the fraction of the Monte Carlo below it is p, give or take the two
    # samples' binomial errors, sqrt(p (1 - p) (1/n + 1/m)) (distribution-free: no density needed)
    for p in (2.5, 50.0, 97.5):
        below = np.mean(mc < e[f"p{p:g}"])
        assert abs(below - p / 100) < Z * math.sqrt(p / 100 * (1 - p / 100) * (1 / n + 1 / m)), p
    # the mean's 95 % interval: mean -+ t(0.975, n - 1) s / sqrt(n), Student's t quantile from its
    # expansion about the normal's z = 1.959964: t = z + (z^3 + z) / (4 dof) + O(dof^-2), 1e-7 here
    z = 1.959964
    half = (z + (z ** 3 + z) / (4 * (n - 1))) * e["std"] / math.sqrt(n)
    assert np.diff(e["mean_ci95"])[0] / 2 == pytest.approx(half, rel=1e-6)
    assert np.mean(e["mean_ci95"]) == pytest.approx(e["mean"], rel=1e-12)
    # printed: the main outputs, with their units and the numbers of the summary
    text = capsys.readouterr().out
    table = text[text.index("statistics of 4,000 cases"):].splitlines()
    assert "mean" in table[1] and "p97.5" in table[1] and "unit" in table[1]
    rows = {line.split()[0]: line.split() for line in table[2:7]}
    assert set(rows) == {"e", "e_ep", "e_ze", "v_rebound", "t_contact"}
    assert rows["t_contact"][1] == "s" and rows["v_rebound"][1] == "m/s" and rows["e"][1] == "1"
    assert float(rows["e"][2]) == pytest.approx(e["mean"], rel=1e-5)
    assert float(rows["e_ep"][6]) == pytest.approx(summary["outputs"]["jgm.e"]["p97.5"], rel=1e-5)


def test_summary_keys_and_what_the_sweep_drew(tmp_path):
    _status, summary, _out = sweep(tmp_path, "--scheduler", "serial", samples=50)
    assert set(summary["outputs"]) == set(REAL_OUTPUTS)
    for name, entry in summary["outputs"].items():
        assert KEYS <= set(entry) <= KEYS | {"keyword", "n_not_finite"}, name
        assert len(entry["mean_ci95"]) == 2 and entry["mean_ci95"][0] <= entry["mean"] <= entry["mean_ci95"][1]
        assert entry["p2.5"] <= entry["p50"] <= entry["p97.5"]
    assert {name: summary["outputs"][name]["unit"] for name in SI} == SI
    assert summary["outputs"]["jgm.e"]["keyword"] == "e_ep"
    drawn = summary["sweep"]
    assert drawn["random"]["plate.Sy"]["distribution"] == "uniform_rel"
    assert drawn["random"]["plate.Sy"]["parameters"] == [SCATTER]
    assert drawn["samples"] == 50 and drawn["seed"] == 7 and drawn["backend"] == "package"
    assert summary["n_cases"] == 50 and summary["out_of_range"] == {**summary["out_of_range"], "n": 0, "cases": []}
    # another section (--sobol's) joins the statistics; one that would replace them is refused
    extra = tmp_path / "extra.json"
    write_summary(extra, summary, {"sobol": {"e": {"S1": {"plate.Sy": 1.0}}}})
    assert json.loads(extra.read_text())["sobol"] == {"e": {"S1": {"plate.Sy": 1.0}}}
    with pytest.raises(ValueError, match="outputs"):
        write_summary(extra, summary, {"outputs": {}})


def test_draws_outside_the_domain_are_counted_and_left_out(tmp_path):
    # sphere.E x (1 + 0.6 N(0, 1)) <= 0 where N < -1/0.6: P = Phi(-1.667) = 4.8 %, about 24 of 500
    _status, summary, out = sweep(tmp_path, "--scheduler", "serial", "--random", "sphere.E=normal_rel:0.6",
                                  samples=500)
    table = read_table(out)
    outside = table["sphere.E"] <= 0  # the drawn inputs, as the table records them
    assert 5 < outside.sum() < 60
    assert summary["out_of_range"]["n"] == outside.sum() == summary["n_cases"] - summary["n_evaluated"]
    assert summary["out_of_range"]["cases"] == table["case"][outside][:20].tolist()
    e = table["e"][~outside]
    entry = summary["outputs"]["e"]
    assert entry["n"] == e.size and entry["n_out_of_range"] == outside.sum()
    assert entry["mean"] == pytest.approx(e.mean(), rel=1e-12)
    assert entry["std"] == pytest.approx(e.std(ddof=1), rel=1e-10)
    assert [entry["p2.5"], entry["p50"], entry["p97.5"]] == pytest.approx(np.percentile(e, [2.5, 50, 97.5]), rel=1e-12)


def test_resumed_sweep_gives_the_statistics_of_a_whole_run(tmp_path, monkeypatch):
    _status, whole, _out = sweep(tmp_path, "--scheduler", "serial", "--chunk-size", "500", name="whole")
    calls = []
    real = sweep_run._run_chunk

    def interrupted_at_the_fourth_chunk(*args, **kwargs):
        calls.append(args[0])
        if len(calls) == 4:
            raise KeyboardInterrupt
        return real(*args, **kwargs)

    monkeypatch.setattr(sweep_run, "_run_chunk", interrupted_at_the_fourth_chunk)
    status, summary, out = sweep(tmp_path, "--scheduler", "serial", "--chunk-size", "500", check=False)
    assert status == EXIT_INTERRUPTED and summary is None  # no summary of a part of the sweep
    assert len(list(out.with_name("s.csv.parts").glob("*/chunk-*.parquet"))) == 3
    monkeypatch.setattr(sweep_run, "_run_chunk", real)
    out.unlink()  # the partial table: the statistics must not come from a table file
    _status, resumed, _out = sweep(tmp_path, "--scheduler", "serial", "--chunk-size", "500", "--resume")
    assert resumed["outputs"]["e"]["n"] == SAMPLES
    for name in REAL_OUTPUTS:
        for key in ("mean", "std", "p2.5", "p50", "p97.5", "n"):
            assert resumed["outputs"][name][key] == pytest.approx(whole["outputs"][name][key], rel=1e-12, abs=1e-300)


def test_resume_statistics_come_from_the_parts_loaded_for_the_check(tmp_path):
    """run_sweep's on_chunk hook sees the kept parts (read once, for their checksum) and the new chunks."""
    spec = SweepSpec(pairs=["s2_tool_steel/al_6061"], random={"plate.Sy": "uniform_rel:0.15"}, samples=300, seed=3)
    parts = tmp_path / "parts"
    run_sweep(spec, scheduler="serial", chunk_size=100, parts=parts)
    (parts / "chunk-000000000000100-000000000000200.parquet").unlink()
    statistics = SweepStatistics(spec)
    res = run_sweep(spec, scheduler="serial", chunk_size=100, parts=parts, resume=True, in_memory=False,
                    on_chunk=statistics)
    assert len(statistics) == 300
    table = read_table(res.write(tmp_path / "t.csv"))
    assert statistics.summary()["outputs"]["e"]["mean"] == pytest.approx(np.mean(table["e"]), rel=1e-12)


def test_a_directory_is_refused_as_summary_in_one_line(tmp_path, capsys):
    folder = tmp_path / "folder"
    folder.mkdir()
    status = sweep_cli([*POINT, "--samples", "10", "--scheduler", "serial", "--out", str(tmp_path / "s.csv"),
                        "--summary", str(folder), "--no-plot"])
    err = capsys.readouterr().err
    assert status == 2 and err.count("\n") == 1
    assert f"--summary {folder}: is a directory, not a regular file" in err
    assert not (tmp_path / "s.csv").exists() and list(folder.iterdir()) == []
    status = sweep_cli([*POINT, "--samples", "10", "--scheduler", "serial", "--out", str(tmp_path / "s.csv"),
                        "--summary", str(tmp_path / "s.csv"), "--no-plot"])
    assert status == 2 and "is the same file as --out" in capsys.readouterr().err


def test_grid_points_and_the_plot_of_a_random_sweep(tmp_path, monkeypatch):
    """Per grid point (by_point) the numbers are numpy's on the table rows of that point; the plot is
    a histogram (no grid axis) or the median and 95 % band along the grid axis, not points at one t/d."""
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    from restitution.sweep.plot import plot_cor_map

    saved = []
    monkeypatch.setattr(Figure, "savefig", lambda fig, path, **kw: saved.append(fig))
    spec = SweepSpec(pairs=["s2_tool_steel/al_6061"], grid={"v_approach": [0.5, 1.0, 2.0, 4.0]},
                     fixed={"t_over_d": 0.5}, random={"plate.Sy": "uniform_rel:0.15"}, samples=200, seed=5)
    res = run_sweep(spec, scheduler="serial")
    statistics = SweepStatistics(spec)
    statistics.add(res.columns)
    points = statistics.summary()["by_point"]
    assert [p["v_approach"] for p in points] == [0.5, 1.0, 2.0, 4.0]
    for p in points:
        e = res["e"][res["v_approach"] == p["v_approach"]]
        assert p["outputs"]["e"]["p50"] == pytest.approx(np.median(e), rel=1e-12)
        assert p["outputs"]["e"]["n"] == 200
    plot_cor_map(res, tmp_path / "band.png")
    ax = saved[-1].axes[0]
    (median,) = [line for line in ax.lines if len(line.get_xdata()) == 4]
    assert np.allclose(median.get_ydata(), [np.median(res["e"][res["v_approach"] == v]) for v in median.get_xdata()])
    assert ax.collections, "no 95 % band"
    assert "[m/s]" in ax.get_xlabel() and "[1]" in ax.get_ylabel()

    one_point = SweepSpec(pairs=["s2_tool_steel/al_6061"], fixed={"t_over_d": 0.5, "v_approach": 2.0},
                          random={"plate.Sy": "uniform_rel:0.15"}, samples=500, seed=5)
    res = run_sweep(one_point, scheduler="serial")
    plot_cor_map(res, tmp_path / "hist.png")
    ax = saved[-1].axes[0]
    assert len(ax.patches) >= 10  # the histogram's bars
    marked = sorted(line.get_xdata()[0] for line in ax.lines if len(line.get_xdata()) == 2)
    assert marked == pytest.approx(sorted([np.mean(res["e"]), *np.percentile(res["e"], [2.5, 97.5])]), rel=1e-12)
    assert ax.get_xlabel() == "apparent COR e [1]"
    title = " ".join(saved[-1]._suptitle.get_text().split())  # wrapped to the figure's width
    assert "plate.Sy ~ uniform_rel:0.15; t_over_d = 0.5, v_approach = 2.0 m/s" in title


def test_a_local_cluster_gives_the_statistics_of_a_serial_run(tmp_path):
    _status, serial, _out = sweep(tmp_path, "--scheduler", "serial", name="serial", samples=300)
    _status, dask, _out = sweep(tmp_path, "--scheduler", "local", "--workers", "2", "--chunk-size", "50",
                                name="dask", samples=300)
    # the chunks come back in any order and are joined in case order, as serially: the same numbers, to
    # the rounding of the sums (a different summation order would move the mean by ~n ulps, far under 1e-12)
    assert dask["out_of_range"] == serial["out_of_range"] and dask["outputs"].keys() == serial["outputs"].keys()
    for name, entry in serial["outputs"].items():
        for key, value in entry.items():
            got = dask["outputs"][name][key]
            if isinstance(value, (float, list)):
                assert got == pytest.approx(value, rel=1e-12, abs=1e-300), (name, key)
            else:  # counts, units, keywords
                assert got == value, (name, key)


def test_the_fmu_backend_gives_the_statistics_of_the_package(tmp_path, impact_fmu):
    _status, package, _out = sweep(tmp_path, "--scheduler", "serial", name="package", samples=300)
    _status, fmu, _out = sweep(tmp_path, "--scheduler", "serial", "--backend", "fmu", "--fmu", str(impact_fmu),
                               name="fmu", samples=300)
    assert fmu["sweep"]["backend"].startswith("fmu") and fmu["n_evaluated"] == package["n_evaluated"] == 300
    for name in ("e", "jgm.e", "zener.e", "v_rebound", "zener.t_contact"):
        for key in ("mean", "std", "p2.5", "p50", "p97.5"):
            # the same cases, which the FMU evaluates with the package bundled in it (the two agree
            # within 1e-12 case by case, tests/sweep/test_sweep.py)
            assert fmu["outputs"][name][key] == pytest.approx(package["outputs"][name][key], rel=1e-9), (name, key)


def test_the_interval_of_the_mean_covers_the_true_mean_over_many_datasets():
    """mean_ci95 (t(0.975, n - 1) s / sqrt(n)) over 400 synthetic datasets of 25 normal draws each, made here:
    it holds the true mean in 95 % of them, so the count lies within 3 binomial standard deviations
    (sqrt(400 0.95 0.05) = 4.4) of 380; both ways describe() computes it (one group, and 400 groups at once)."""
    from restitution.sweep.statistics import describe

    rng = np.random.default_rng(20261126)
    n_sets, n, mu, sigma = 400, 25, 0.5, 0.02
    draws = rng.normal(mu, sigma, size=(n_sets, n))
    grouped = describe(draws.ravel(), np.repeat(np.arange(n_sets), n), n_sets)
    one_by_one = [describe(row) for row in draws]
    for mean, half in ((grouped["mean"], grouped["ci_half"]),
                       (np.array([d["mean"][0] for d in one_by_one]), np.array([d["ci_half"][0] for d in one_by_one]))):
        hits = int(np.count_nonzero(np.abs(mean - mu) <= half))
        assert abs(hits - 0.95 * n_sets) <= 3 * math.sqrt(n_sets * 0.95 * 0.05), hits


def test_an_output_over_an_input_or_a_hard_link_of_another_output_is_refused(tmp_path, capsys):
    """No sweep output over its inputs (the spec file, the FMU) nor over another output by another name: a
    hard link of --out given as --summary wrote the summary over the table. Refused before any work, in
    one line, exit 2, the inputs left as they were."""
    spec = tmp_path / "spec.toml"
    spec.write_text('samples = 10\n[run]\nscheduler = "serial"\n')
    before = spec.read_bytes()
    table = tmp_path / "s.csv"
    status = sweep_cli([str(spec), *POINT, "--out", str(table), "--summary", str(spec), "--no-plot"])
    err = capsys.readouterr().err
    assert status == 2 and err.count("\n") == 1 and "is the input SPEC" in err, err
    assert spec.read_bytes() == before and not table.exists()
    table.write_text("kept\n")
    os.link(table, tmp_path / "same.json")
    status = sweep_cli([*POINT, "--samples", "10", "--scheduler", "serial", "--out", str(table),
                        "--summary", str(tmp_path / "same.json"), "--no-plot"])
    err = capsys.readouterr().err
    assert status == 2 and "is the same file as --out" in err, err
    assert table.read_text() == "kept\n"
