"""A sweep keeping some columns asks the package for those outputs only (and what the published
values need), and each kept column holds the values of the sweep that keeps every column."""
import numpy as np
import pytest

import restitution.model
from restitution.sweep import SweepSpec, run_sweep
from restitution.sweep.spec import OUTPUT_NAMES

#: thin plates (t/d down to 0.05) at up to 5 m/s: lambda past 2, where the linear method's contact never
#: ends (published tau0 = 0), and a bounded plate (the edge echo): every published() change is exercised
SPEC = dict(pairs=["s2_tool_steel/al_6061"], random={"v_approach": "loguniform:0.01:5", "t_over_d": "loguniform:0.05:5",
                                                     "plate_edge_distance": "uniform:0:0.05"},
            fixed={"zener_method": "linear"}, samples=3000, seed=5)


@pytest.mark.parametrize("kept", [["e"], ["e", "v_rebound"], ["zener.tau0"], ["monitor.edge_echo", "jgm.e"],
                                  ["monitor.wave_delay", "zener.contact_ends"]])
def test_kept_columns_are_the_full_sweeps_and_only_their_work_runs(kept, monkeypatch):
    full = run_sweep(SweepSpec(**SPEC), "package", scheduler="serial").columns
    asked = []
    impact = restitution.model.impact

    def spy(*args, outputs=None, **kwargs):
        asked.append(outputs)
        return impact(*args, outputs=outputs, **kwargs)

    monkeypatch.setattr(restitution.model, "impact", spy)
    some = run_sweep(SweepSpec(**SPEC), "package", scheduler="serial", columns=kept).columns
    assert asked and all(a is not None for a in asked)
    skipped = {"t_contact", "wave_delay", "edge_echo", "mass_ratio", "v_plate"}
    if kept == ["e"]:  # a Monte Carlo of e: e and the validity flags, nothing of the contact's duration
        assert set(asked[0]) == {"e", "valid", "lambda_in_range", "vstar_in_range"}
        assert skipped.isdisjoint(restitution.model.output_dependencies("e"))
    for name in [*kept, "valid", "jgm.in_range", "zener.in_range"]:
        assert np.array_equal(some[name], full[name], equal_nan=True), name
    assert set(some) & set(OUTPUT_NAMES) == {*kept, "valid", "jgm.in_range", "zener.in_range"}
