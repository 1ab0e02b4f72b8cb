"""Sobol' indices of a sweep (restitution.sweep.sobol, ``--sobol``): closed-form models run through the
sweep engine with the design-to-cases mapping and the analysis the command line uses, the command line on
the model with both back ends, and the inputs it refuses."""
from __future__ import annotations

import json
import math
import os

import numpy as np
import pytest

from restitution.sweep import run_sweep
from restitution.sweep import sobol
from restitution.sweep.backends import Backend
from restitution.sweep.__main__ import main as sweep_cli
from restitution.sweep.sobol import (MAX_ST_CONF, RANK_GAP, SOBOL_OUTPUTS, SobolCollector, SobolSpec,
                                     ranking_warning)
from restitution.sweep.spec import OUTPUTS

FIELDS = ("S1", "S1_conf", "ST", "ST_conf")


class ClosedForm(Backend):
    """A back end that evaluates ``model(cases)`` (a closed form) into every analysed output, so the
    indices of a known function come out of the same engine, chunks and collector as the model's."""

    name = "closed_form"

    def __init__(self, model):
        self.model = model

    def evaluate(self, cases, payload=None, outputs=None):
        n = np.size(cases["case"])
        out = {name: np.full(n, np.nan) if kind == "Real" else np.zeros(n, dtype=bool) for name, _f, kind in OUTPUTS}
        y = self.model(cases)
        for column in SOBOL_OUTPUTS.values():
            out[column] = y
        out["ok"] = np.ones(n, dtype=bool)
        return out, {"code": "closed form", "pid": os.getpid()}


def indices_of(spec_dict, model, chunk_size=1000):
    """The Sobol' section of ``model`` over the design of ``spec_dict``, run in chunks that cut across the
    design's blocks of D + 2 rows."""
    spec = SobolSpec.from_dict(spec_dict)
    collector = SobolCollector(spec)
    run_sweep(spec, ClosedForm(model), scheduler="serial", chunk_size=chunk_size, on_chunk=collector)
    section = collector.analyze()
    assert section["refused"] == {}
    return section


def assert_close(estimated, exact, what):
    """An index within three of its 95 % bootstrap half-widths (plus 0.01 for a half-width near zero)."""
    for field in ("S1", "ST"):
        tol = 3 * estimated[f"{field}_conf"] + 0.01
        assert abs(estimated[field] - exact[field]) <= tol, (what, field, estimated, exact)


def test_additive_model_gives_each_input_its_share_of_the_variance():
    # Y = sum w_i (X_i / sd_i): S1_i = ST_i = w_i^2 / sum w_j^2, with sd_i from each distribution's closed
    # form, which checks how every kind of distribution maps to SALib's (and a relative one to its base value).
    t0, e0, lo, hi = 4e-3, 200e9, 50e9, 200e9
    log = math.log(hi / lo)
    loguniform_var = (hi**2 - lo**2) / (2 * log) - ((hi - lo) / log) ** 2
    variance = {"v_approach": (3.0 - 0.5) ** 2 / 12, "plate.E": loguniform_var, "sphere.d": 0.5e-3 ** 2,
                "plate.t": (2 * 0.2 * t0) ** 2 / 12, "sphere.E": (0.05 * e0) ** 2}
    weights = {"v_approach": 1.0, "plate.E": 2.0, "sphere.d": 3.0, "plate.t": 1.5, "sphere.E": 0.5}
    spec = dict(random={"v_approach": "uniform:0.5:3", "plate.E": "loguniform:50GPa:200GPa",
                        "sphere.d": "normal:6mm:0.5mm", "plate.t": "uniform_rel:0.2", "sphere.E": "normal_rel:0.05"},
                fixed={"plate.t": t0, "sphere.E": e0}, samples=2048, seed=3)

    def model(cases):
        return sum(w * cases[name] / math.sqrt(variance[name]) for name, w in weights.items())

    section = indices_of(spec, model)
    total = sum(w**2 for w in weights.values())
    assert section["N"] == 2048 and section["evaluations"] == 2048 * (5 + 2)
    for key in SOBOL_OUTPUTS:
        for name, w in weights.items():
            share = w**2 / total
            assert_close(section["sobol"][key][name], {"S1": share, "ST": share}, name)


#: The Ishigami function (a = 7, b = 0.1) on three inputs drawn uniform on [-pi, pi], the inputs' sweep names
ISHIGAMI_A, ISHIGAMI_B = 7.0, 0.1
ISHIGAMI_INPUTS = ("v_approach", "plate.Sy", "sphere.nu")


def ishigami_exact():
    """First-order and total indices of the Ishigami function from its variance decomposition (x3 acts only
    through its interaction with x1)."""
    a, b = ISHIGAMI_A, ISHIGAMI_B
    v1 = b * math.pi**4 / 5 + b**2 * math.pi**8 / 50 + 0.5
    v2 = a**2 / 8
    v13 = b**2 * math.pi**8 / 18 - b**2 * math.pi**8 / 50
    var = v1 + v2 + v13
    x1, x2, x3 = ISHIGAMI_INPUTS
    return {x1: {"S1": v1 / var, "ST": (v1 + v13) / var}, x2: {"S1": v2 / var, "ST": v2 / var},
            x3: {"S1": 0.0, "ST": v13 / var}}


def ishigami(cases):
    x1, x2, x3 = (cases[name] for name in ISHIGAMI_INPUTS)
    return np.sin(x1) + ISHIGAMI_A * np.sin(x2) ** 2 + ISHIGAMI_B * x3**4 * np.sin(x1)


def ishigami_spec(samples, seed):
    return dict(random={name: f"uniform:{-math.pi!r}:{math.pi!r}" for name in ISHIGAMI_INPUTS}, samples=samples,
                seed=seed)


def test_ishigami_function_matches_its_known_indices():
    exact = ishigami_exact()
    section = indices_of(ishigami_spec(4096, 5), ishigami, chunk_size=7777)
    for name in ISHIGAMI_INPUTS:
        assert_close(section["sobol"]["e"][name], exact[name], name)


def test_the_intervals_cover_the_true_indices_over_many_designs():
    """The 95 % bootstrap intervals (SALib's, 100 resamples) of the Ishigami indices over 100 designs, each
    scrambled with its own seed (N = 512): for every index that is not zero the interval holds the true value
    in at least 90 of them (measured: 96 to 100; on a scrambled Sobol' sequence the estimates scatter less than
    the bootstrap, which resamples them as if random, assumes). An index that is exactly zero (x3 alone) is
    covered less often (measured: 84): docs/uncertainty.md says so; here at least 75."""
    exact = ishigami_exact()
    covered = {(name, field): 0 for name in ISHIGAMI_INPUTS for field in ("S1", "ST")}
    n_designs = 100
    for seed in range(1, n_designs + 1):
        indices = indices_of(ishigami_spec(512, seed), ishigami, chunk_size=100_000)["sobol"]["e"]
        for (name, field) in covered:
            s = indices[name]
            covered[(name, field)] += abs(s[field] - exact[name][field]) <= s[f"{field}_conf"]
    for (name, field), hits in covered.items():
        floor = 75 if exact[name][field] == 0.0 else 90
        assert hits >= floor, (name, field, hits, n_designs)


def test_the_design_does_not_depend_on_chunks_and_resumed_chunks_are_collected(tmp_path, monkeypatch):
    spec = SobolSpec.from_dict(dict(random={"v_approach": "uniform:1:2", "plate.t": "uniform_rel:0.1"},
                                    samples=64, seed=9))
    whole = spec.cases()
    parts = [spec.cases(a, min(a + 37, spec.n_cases)) for a in range(0, spec.n_cases, 37)]
    for name in ("v_approach", "plate.t"):
        assert np.array_equal(whole[name], np.concatenate([p[name] for p in parts]))
    # each block of D + 2 rows: A, A with input j from B (j = 1 ... D), B (Saltelli's scheme)
    rows = np.column_stack([whole["v_approach"], whole["plate.t"]]).reshape(-1, 4, 2)
    a, ab1, ab2, b = rows[:, 0], rows[:, 1], rows[:, 2], rows[:, 3]
    assert np.array_equal(ab1[:, 0], b[:, 0]) and np.array_equal(ab1[:, 1], a[:, 1])
    assert np.array_equal(ab2[:, 0], a[:, 0]) and np.array_equal(ab2[:, 1], b[:, 1])

    # a design too big to travel with the tasks is built where the cases are: the same rows
    monkeypatch.setattr(sobol, "SHIPPED_VALUES", 0)
    built = SobolSpec.from_dict(dict(random={"v_approach": "uniform:1:2", "plate.t": "uniform_rel:0.1"},
                                     samples=64, seed=9))
    assert built._shipped is None and spec._shipped is not None
    assert all(np.array_equal(built.cases(5, 99)[name], whole[name][5:99]) for name in ("v_approach", "plate.t"))

    first = SobolCollector(spec)
    run_sweep(spec, scheduler="serial", chunk_size=50, on_chunk=first, parts=tmp_path / "p")
    for in_memory in (True, False):  # every chunk now comes from the parts, not from an evaluation
        again = SobolCollector(spec)
        run_sweep(spec, scheduler="serial", chunk_size=50, on_chunk=again, parts=tmp_path / "p", resume=True,
                  in_memory=in_memory)
        assert again.analyze() == first.analyze()


def run_cli(tmp_path, capsys, *extra, name="sobol"):
    summary = tmp_path / f"{name}.json"
    status = sweep_cli(["--pair", "s2_tool_steel/al_6061", "--random", "plate.t=uniform_rel:0.15",
                        "--random", "v_approach=uniform:0.5:3", "--random", "plate.Sy=uniform_rel:1e-6",
                        "--samples", "256", "--seed", "4", "--sobol", "--summary", str(summary),
                        "--scheduler", "serial", "--out", str(tmp_path / f"{name}.csv"), "--no-plot",
                        "--no-progress", *extra])
    out = capsys.readouterr()
    assert status == 0, out.err
    return json.loads(summary.read_text(encoding="utf-8")), out


@pytest.fixture(scope="module")
def fmu(tmp_path_factory):
    """The pythonfmu SpherePlateImpact.fmu alone, built from the working tree (seconds)."""
    from restitution.fmu.builders import build_one

    return build_one("SpherePlateImpact", tmp_path_factory.mktemp("fmu"))


def test_cli_writes_indices_with_the_properties_of_variance_shares(tmp_path, capsys):
    summary, out = run_cli(tmp_path, capsys)
    inputs = ["plate.t", "v_approach", "plate.Sy"]
    design = summary["sobol_design"]
    assert design["N"] == 256 and design["evaluations"] == 256 * 5 and design["refused"] == {}
    assert summary["n_cases"] == 256 * 5  # the statistics of the same cases beside the indices
    assert set(summary["sobol"]) == set(SOBOL_OUTPUTS) == {"e", "e_ep", "e_ze", "t_contact"}
    for key, indices in summary["sobol"].items():
        assert list(indices) == inputs
        for name, s in indices.items():
            assert set(s) == set(FIELDS) and all(math.isfinite(s[f]) for f in FIELDS)
            assert s["S1_conf"] >= 0 and s["ST_conf"] >= 0
            assert -s["S1_conf"] - 1e-9 <= s["S1"] <= s["ST"] + s["S1_conf"] + s["ST_conf"] + 1e-9, (key, name)
            assert s["ST"] <= 1 + s["ST_conf"] + 1e-9, (key, name)
        assert sum(s["S1"] for s in indices.values()) <= 1 + sum(s["S1_conf"] for s in indices.values()) + 1e-9
        # a yield strength scattered by one part in a million moves nothing
        assert abs(indices["plate.Sy"]["ST"]) < 1e-3, key
    # e_ep (JGM, a thick-plate model) does not depend on the plate's thickness at all
    assert summary["sobol"]["e_ep"]["plate.t"]["ST"] == pytest.approx(0, abs=1e-12)
    assert "Sobol' indices (256 base samples, 1,280 evaluations" in out.out
    assert "v_approach  S1 =" in out.out
    assert "more samples needed: --samples 1024" in out.err  # 256 base samples: intervals above 0.1


def test_package_and_fmu_back_ends_give_the_same_indices(tmp_path, capsys, fmu):
    package, _ = run_cli(tmp_path, capsys, name="package")
    fmu_run, out = run_cli(tmp_path, capsys, "--backend", "fmu", "--fmu", str(fmu), name="fmu")
    assert "1280 cases with the fmu (SpherePlateImpact.fmu" in out.out
    for key, indices in package["sobol"].items():
        for name, s in indices.items():
            f = fmu_run["sobol"][key][name]
            for field in ("S1", "ST"):
                assert abs(s[field] - f[field]) <= max(s[f"{field}_conf"], f[f"{field}_conf"]) + 1e-9, (key, name)


def test_cases_the_model_cannot_evaluate_leave_the_outputs_without_indices(tmp_path, capsys):
    # a normal draw of the speed reaches below zero: those cases are ok = False and break the design
    summary = tmp_path / "s.json"
    status = sweep_cli(["--random", "v=normal:1:1", "--random", "plate.E=normal_rel:0.1", "--samples", "16",
                        "--sobol", "--summary", str(summary), "--scheduler", "serial", "--no-plot", "--no-progress",
                        "--out", str(tmp_path / "t.csv")])
    out = capsys.readouterr()
    written = json.loads(summary.read_text(encoding="utf-8"))
    assert status == 1
    assert written["sobol"] == {} and set(written["sobol_design"]["refused"]) == set(SOBOL_OUTPUTS)
    lines = out.err.strip().splitlines()
    assert len(lines) == 1 and "no Sobol' indices of e, e_ep, e_ze, t_contact:" in lines[0]
    assert "could not be evaluated (ok = False" in lines[0]


@pytest.mark.parametrize("args, message", [
    (["--random", "plate.t=choice:1mm,2mm", "--samples", "8"], "a choice among values cannot be a Sobol' input"),
    (["--random", "plate.t=uniform_rel:0.1", "--samples", "1000"], "a power of 2 >= 2 (the Sobol' sequence"),
    (["--samples", "8"], "--sobol needs the inputs to vary: give each with --random"),
    (["--random", "plate.t=uniform_rel:0.1", "--grid", "v=1,2", "--samples", "8"], "--grid v_approach makes a grid"),
    (["--random", "v=normal:1:0", "--samples", "8"], "a spread of zero is a constant"),
])
def test_bad_sobol_inputs_are_refused_in_one_line(tmp_path, capsys, args, message):
    status = sweep_cli([*args, "--sobol", "--summary", str(tmp_path / "s.json"), "--out", str(tmp_path / "t.csv"),
                        "--scheduler", "serial"])
    err = capsys.readouterr().err
    assert status == 2
    assert err.count("\n") == 1 and message in err, err
    assert not list(tmp_path.iterdir())  # refused before any work: nothing written


def section_of(**st_and_conf):
    return {"N": 512, "sobol": {"e": {name: {"S1": st, "S1_conf": conf, "ST": st, "ST_conf": conf}
                                      for name, (st, conf) in st_and_conf.items()}}}


def test_ranking_warning_criterion():
    assert ranking_warning(section_of(a=(0.6, 0.05), b=(0.3, 0.05))) is None          # separated
    assert ranking_warning(section_of(a=(0.31, 0.05), b=(0.30, 0.05))) is None        # a tie: nothing to rank
    overlap = ranking_warning(section_of(a=(0.40, 0.04), b=(0.40 - 1.2 * RANK_GAP, 0.03)))  # apart, not resolved
    assert "the ST intervals of b and a overlap" in overlap and overlap.endswith("more samples needed: --samples 2048")
    wide = ranking_warning(section_of(a=(0.9, MAX_ST_CONF + 0.01), b=(0.1, 0.01)))
    assert "ST_conf > 0.1 for a" in wide and wide.count("\n") == 0


def test_a_dask_run_gives_the_serial_indices_with_the_design_shipped_or_built_on_the_workers(monkeypatch):
    from restitution.sweep import open_client

    spec_dict = dict(pairs=["s2_tool_steel/al_6061"], random={"v_approach": "uniform:0.5:3", "plate.t": "uniform_rel:0.2"},
                     samples=128, seed=2)
    serial = SobolCollector(SobolSpec.from_dict(spec_dict))
    run_sweep(serial.spec, scheduler="serial", on_chunk=serial)
    monkeypatch.setattr(sobol, "SHIPPED_VALUES", 0)  # in this process only: the second spec carries no design
    specs = [serial.spec, SobolSpec.from_dict(spec_dict)]
    assert specs[1]._shipped is None
    with open_client("local", n_workers=2) as client:
        for spec in specs:
            collector = SobolCollector(spec)
            run_sweep(spec, scheduler=client, chunk_size=100, on_chunk=collector)
            # the same cases (numpy may round a case's last bit differently where a chunk cuts the arrays)
            got, expected = collector.analyze()["sobol"], serial.analyze()["sobol"]
            assert got.keys() == expected.keys()
            for key in got:
                for name in got[key]:
                    assert got[key][name] == pytest.approx(expected[key][name], rel=1e-9, abs=1e-12)
