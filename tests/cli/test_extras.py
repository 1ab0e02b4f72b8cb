"""A command whose optional extra is missing says so in one line naming the ``pip install`` that brings it,
exit 2, before any work (nothing written). Each runs in a child process in which the extra's module is made
unimportable (``sys.modules[name] = None``, what Python does for a package that is not installed)."""
from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
SCENE = ROOT / "examples" / "scenes" / "steel_ball_thin_aluminium.toml"


def _without(modules, command, args, cwd):
    code = textwrap.dedent(f"""
        import sys
        for name in {list(modules)!r}:
            sys.modules[name] = None
        from restitution.command import main
        sys.exit(main({[command, *map(str, args)]!r}))
    """)
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=cwd, timeout=300)


@pytest.mark.parametrize("hidden, command, args, extra", [
    (["distributed"], "sweep", ["--pair", "s2_tool_steel/al_6061", "--grid", "v_approach=1,2", "--out", "s.csv"], "sweep"),
    (["matplotlib"], "sweep", ["--pair", "s2_tool_steel/al_6061", "--grid", "v_approach=1,2", "--out", "s.csv"],
     "examples"),
    (["pyarrow"], "sweep", ["--pair", "s2_tool_steel/al_6061", "--grid", "v_approach=1,2", "--out", "s.parquet",
                            "--no-plot"], "parquet"),
    (["fmpy"], "sweep", ["--pair", "s2_tool_steel/al_6061", "--grid", "v_approach=1,2", "--out", "s.csv", "--no-plot",
                         "--backend", "fmu"], "fmu"),
    (["fmpy"], "scene", ["run", SCENE, "--out", "out", "--no-progress"], "scene"),
    (["matplotlib"], "scene", ["run", SCENE, "--out", "out", "--no-progress"], "scene"),
    (["emcee"], "fit", ["pairs.csv", "--sphere", "chrome_steel", "--d", "6.35 mm", "--plate", "al_6061", "--t",
                        "6.35 mm", "--fit", "plate.Sy", "--bayes"], "fit"),
])
def test_a_missing_extra_is_one_line_before_any_work(tmp_path, hidden, command, args, extra):
    (tmp_path / "pairs.csv").write_text("v_in,v_out\n1,0.6\n2,0.5\n3,0.45\n")
    before = sorted(p.name for p in tmp_path.iterdir())
    done = _without(hidden, command, args, tmp_path)
    lines = done.stderr.strip().splitlines()
    assert done.returncode == 2 and len(lines) == 1, done.stderr
    assert hidden[0] in lines[0] and f'pip install "restitution[{extra}]"' in lines[0], lines[0]
    assert sorted(p.name for p in tmp_path.iterdir()) == before  # nothing written


def test_sweep_results_become_dataframes():
    """pandas is in the sweep extra, so SweepResult.to_pandas works in the locked environment."""
    pytest.importorskip("distributed", reason="the sweep extra is not installed")
    from restitution.sweep import SweepSpec, run_sweep

    spec = SweepSpec(pairs=["s2_tool_steel/al_6061"], grid={"v_approach": [1.0, 2.0]})
    frame = run_sweep(spec, scheduler="serial").to_pandas()
    assert list(frame["v_approach"]) == [1.0, 2.0] and "e" in frame.columns
