"""``simulation.master = "event_mode"``: a scene whose drops co-simulate the FMI 3.0 BouncingBall.fmu with
SpherePlateImpact.fmu in event mode (restitution.cosim.event_mode). Its impacts must be the runner's own
closed-form ones (the same FMU for the COR, the same flight), the loader must read the two keys, and the
command must take --ball-fmu and refuse one that is not an event-mode ball in one line."""
from __future__ import annotations

import tomllib

import numpy as np
import pytest

from restitution.scene import SceneError, parse_scene, run_scene
from restitution.scene.__main__ import main
from scene_texts import steel_on_aluminium

SCENE = """
[scene]
name = "event mode"

[outputs]
requested = ["bounce_heights", "contact_durations"]

[simulation]
v_min = "0.05 m/s"
{extra}
""" + steel_on_aluminium('["0.1 m", "0.5 m"]')


def scene_from(extra: str):
    return parse_scene(tomllib.loads(SCENE.format(extra=extra)), source="t.toml")


def test_the_loader_reads_master_and_communication_step():
    """Defaults: the closed-form master, 1 ms; a time in any unit; wrong values name their key."""
    default = scene_from("").simulation
    assert (default.master, default.communication_step) == ("closed_form", 1e-3)
    chosen = scene_from('master = "event_mode"\ncommunication_step = "250 us"').simulation
    assert chosen.master == "event_mode" and chosen.communication_step == pytest.approx(2.5e-4, rel=1e-15)
    with pytest.raises(SceneError, match=r"simulation\.master: 'events' is not one of 'closed_form', 'event_mode'"):
        scene_from('master = "events"')
    with pytest.raises(SceneError, match=r"simulation\.communication_step: '1 kg': kg is a unit of"):
        scene_from('communication_step = "1 kg"')
    with pytest.raises(SceneError, match=r"simulation\.communication_step: '0 s' must be > 0"):
        scene_from('communication_step = "0 s"')


@pytest.mark.parametrize("step", ["0.1 s", "1 ms"])
def test_event_mode_drops_have_the_closed_form_impacts(host_fmi3, step):
    """Every drop's impacts through the event-mode master equal the closed-form master's: times and
    speeds to 1e-12 relative (two sums of the same flights, rounded differently), and every output read
    from SpherePlateImpact at each impact (heights from v_rebound, contact durations) to 1e-12 relative
    (the FMU evaluated at speeds equal within those roundings), whatever the communication step."""
    fmu = host_fmi3["SpherePlateImpact"]
    closed = run_scene(scene_from(""), fmu=fmu, progress=False)
    events = run_scene(scene_from(f'master = "event_mode"\ncommunication_step = "{step}"'), fmu=fmu,
                       ball_fmu=host_fmi3["BouncingBall"], progress=False)
    assert len(events.drops) == len(closed.drops) == 2
    for a, b in zip(events.drops, closed.drops):
        assert a.n_impacts == b.n_impacts > 3 and a.stop_reason == b.stop_reason
        np.testing.assert_allclose(a.time, b.time, rtol=1e-12, atol=0)
        np.testing.assert_allclose(a.v_approach, b.v_approach, rtol=1e-12, atol=0)
        for column in ("apex", "t_contact"):
            np.testing.assert_allclose(a.columns[column], b.columns[column], rtol=1e-12, atol=0)


def test_the_command_runs_event_mode_and_refuses_a_wrong_ball(host_fmi3, tmp_path, capsys):
    """`restitution scene run` with --ball-fmu runs the event-mode scene (exit 0, the table written); an FMU
    that is not an event-mode BouncingBall (SpherePlateImpact) is one line on stderr and exit 2."""
    path = tmp_path / "events.toml"
    path.write_text(SCENE.format(extra='master = "event_mode"'), encoding="utf-8")
    fmu, ball = str(host_fmi3["SpherePlateImpact"]), str(host_fmi3["BouncingBall"])
    assert main(["run", str(path), "--fmu", fmu, "--ball-fmu", ball, "--no-plot", "--no-progress",
                 "--out", str(tmp_path / "out")]) == 0
    assert (tmp_path / "out" / "events.csv").is_file()
    capsys.readouterr()
    assert main(["run", str(path), "--fmu", fmu, "--ball-fmu", fmu, "--no-plot", "--no-progress",
                 "--out", str(tmp_path / "out2")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--ball-fmu" in err[0] and "not an FMI 3.0 BouncingBall FMU with event mode" in err[0]
