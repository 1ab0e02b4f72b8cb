"""The sweep benchmark's goal measurements (benchmarks/sweep_goals.py) on a small sweep:
they run, and the gather they time rebuilds exactly the table the sweep returned. No timing is
asserted (shared machines are noisy); the ratios are printed by the benchmark."""
import math

import numpy as np

from restitution.sweep import SweepSpec, run_sweep
from restitution.sweep.table import assemble
from sweep_goals import _chunks, goal_lines, machine_scaling, sweep_over_model, write_over_gather

SPEC = SweepSpec(pairs=["s2_tool_steel/al_6061", "brass_260/borosilicate_glass"],
                 grid={"v_approach": {"geomspace": [0.05, 20.0, 30]}, "t_over_d": {"geomspace": [0.05, 10.0, 20]}})


def test_the_timed_gather_rebuilds_the_table():
    result = run_sweep(SPEC, "package", scheduler="serial")
    rebuilt = assemble(SPEC, _chunks(result, 7), None)
    assert list(rebuilt) == list(result.columns)
    for name, col in result.columns.items():
        assert np.array_equal(rebuilt[name], col, equal_nan=col.dtype.kind == "f"), name


def test_goal_measurements_run_and_report_every_goal():
    model = sweep_over_model(SPEC, repeats=1)
    write = write_over_gather(model.pop("result"), 3, repeats=1)
    assert model["cases"] == 1200 and all(math.isfinite(x) and x > 0 for x in (model["ratio"], write["parquet_s"]))
    ceiling = machine_scaling(SPEC, chunk=200, n_chunks=3, repeats=1)
    assert all(math.isfinite(x) and x > 0 for x in ceiling.values())
    text = "\n".join(goal_lines(model, write, {"package": 0.97}, task_cpu_us=1.0, dask_gather_us=0.5,
                                 ceiling=ceiling))
    assert "streamed runs were not part" in text
    for goal in ("sweep / model per case, serial", "per Dask worker", "Parquet write / gather", "1 worker / 2 workers",
                 "What the machine allows a second worker"):
        assert goal in text


def test_machine_scaling_children_ignore_a_pythonfmu_resources_dir_on_sys_path(tmp_path, monkeypatch):
    """pythonfmu puts an FMU's resources/ (with its own physics-only ``restitution``) first on sys.path;
    spawned children inherited it, could not unpickle the sweep spec and died, and the pool waited
    forever. Here a resources/ whose ``restitution`` cannot be imported at all stands in for it."""
    fake = tmp_path / "resources"
    (fake / "restitution").mkdir(parents=True)
    (fake / "slavemodule.txt").write_text("model\n")
    (fake / "restitution" / "__init__.py").write_text("raise ImportError('the FMU copy, not this one')\n")
    monkeypatch.syspath_prepend(str(fake))
    ceiling = machine_scaling(SPEC, chunk=200, n_chunks=2, repeats=1)
    assert all(math.isfinite(x) and x > 0 for x in ceiling.values())
