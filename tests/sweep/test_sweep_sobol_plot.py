"""The picture of a --sobol sweep: bars of S1 and ST per input with their intervals, one panel per output,
drawn from the indices given (checked on the drawn artists), and written by the command beside its table."""
from __future__ import annotations

import pytest

from restitution.sweep.__main__ import main as sweep_cli

pytest.importorskip("matplotlib", reason="matplotlib (the examples extra) draws the chart")

from restitution.sweep.sobol_plot import sobol_figure  # noqa: E402

INPUTS = ["v_approach", "plate.t", "plate.Sy"]


def section(outputs=("e", "t_contact"), refused=None):
    """Indices made up for the test: each (output, input) its own values, so a bar in the wrong place shows."""
    sobol = {}
    for k, key in enumerate(outputs):
        sobol[key] = {name: {"S1": 0.1 * (j + 1) + 0.01 * k, "S1_conf": 0.01 * (j + 1), "ST": 0.2 * (j + 1) + 0.01 * k,
                             "ST_conf": 0.005 * (j + 1)} for j, name in enumerate(INPUTS)}
    return {"sobol": sobol, "refused": refused or {}, "N": 512, "evaluations": 512 * 5,
            "inputs": {name: {"dist": "unif", "bounds": [0.0, 1.0]} for name in INPUTS}, "resamples": 100,
            "conf_level": 0.95}


def test_each_panel_draws_every_inputs_indices_and_intervals():
    import matplotlib.pyplot as plt

    given = section()
    fig = sobol_figure(given)
    try:
        panels = [ax for ax in fig.axes if ax.axison]
        assert [ax.get_title() for ax in panels] == ["e", "zener.t_contact (t_contact)"]
        for ax, key in zip(panels, ("e", "t_contact")):
            assert [t.get_text() for t in ax.get_xticklabels()] == INPUTS
            bars = [c for c in ax.containers if hasattr(c, "patches")]
            assert [c.get_label() for c in bars] == ["first order S1", "total ST"]
            for container, index in zip(bars, ("S1", "ST")):
                heights = [p.get_height() for p in container.patches]
                assert heights == pytest.approx([given["sobol"][key][n][index] for n in INPUTS], abs=1e-15)
                # the error bar of each: from value - conf to value + conf
                segments = container.errorbar.lines[2][0].get_segments()
                spans = [seg[1][1] - seg[0][1] for seg in segments]
                assert spans == pytest.approx([2 * given["sobol"][key][n][f"{index}_conf"] for n in INPUTS], abs=1e-12)
        assert "512 base samples (2,560 evaluations), 95% bootstrap intervals" in fig._suptitle.get_text()
    finally:
        plt.close(fig)


def test_refused_outputs_are_named_and_an_empty_analysis_is_refused():
    import matplotlib.pyplot as plt

    fig = sobol_figure(section(outputs=("e",), refused={"e_ze": "e_ze is the same in every case: no variance"}))
    try:
        assert "no Sobol' indices of e_ze" in " ".join(fig._suptitle.get_text().split())
        assert len([ax for ax in fig.axes if ax.axison]) == 1
    finally:
        plt.close(fig)
    with pytest.raises(ValueError, match="no output has Sobol' indices"):
        sobol_figure(section(outputs=()))


def _cli(tmp_path, *extra):
    return sweep_cli(["--pair", "s2_tool_steel/al_6061", "--random", "plate.t=uniform_rel:0.15",
                      "--random", "v_approach=uniform:0.5:3", "--samples", "64", "--sobol", "--scheduler", "serial",
                      "--out", str(tmp_path / "s.csv"), "--no-progress", *extra])


def test_the_command_writes_the_chart_beside_the_table_unless_told_not_to(tmp_path, capsys):
    assert _cli(tmp_path) == 0
    out = capsys.readouterr().out
    chart = tmp_path / "s_sobol.png"
    assert f"Sobol' chart: {chart}" in out
    assert chart.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    chart.unlink()
    assert _cli(tmp_path, "--no-plot") == 0
    assert not chart.exists() and "Sobol' chart" not in capsys.readouterr().out


def test_a_chart_path_that_is_not_a_regular_file_is_refused_before_any_work(tmp_path, capsys):
    (tmp_path / "s_sobol.png").mkdir()
    assert _cli(tmp_path) == 2
    err = capsys.readouterr().err
    assert "the Sobol' chart" in err and "s_sobol.png" in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "s.csv").exists()
