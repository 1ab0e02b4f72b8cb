"""The package and the FMU back ends of a sweep agree within each output's conditioning over the
hard grid of the portability issue: S2 on Al 6061, t/d 0.05 ... 1e4, v 1e-6 ... 1e3 m/s, every
Zener method, plate waves on (lambda from ~1e-11, e_ze within ulps of 1, to ~1e3)."""
from __future__ import annotations

from restitution.sweep.__main__ import main as sweep_cli


def test_both_back_ends_agree_over_the_hard_grid(impact_fmu, tmp_path, capsys):
    status = sweep_cli(["--pair", "s2_tool_steel/al_6061", "--grid", "v_approach=geomspace:1e-6:1e3:10",
                        "--grid", "t_over_d=geomspace:0.05:1e4:8", "--grid", "zener_method=1,2,3,4",
                        "--set", "plate_waves=1", "--backend", "both", "--scheduler", "serial",
                        "--fmu", str(impact_fmu), "--out", str(tmp_path / "both.csv"), "--no-plot", "--no-progress"])
    out = capsys.readouterr()
    assert status == 0, out.err
    assert "agree on all 320 cases" in out.out
