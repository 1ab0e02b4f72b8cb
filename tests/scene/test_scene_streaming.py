"""Scenes lose nothing and flag what they extrapolate: every finished drop on disk,
Ctrl-C (SIGINT to the child's process group, as a terminal sends it) writes what is done and exits
130, validity columns and counts, values the FMU would reject refused by the loader naming the key
(and a value an FMU refuses at run time reported the same way), one-line errors, progress output
that behaves in a terminal and when redirected."""
import csv
import os
import signal
import subprocess
import sys
import time
import tomllib
from dataclasses import replace

import pytest

from restitution.scene import SceneError, parse_scene, run_scene
from restitution.scene.__main__ import main
from restitution.scene.loader import MAX_BOUNCES
from terminal import takes_ctrl_c, with_terminal_stderr
from scene_texts import steel_on_aluminium

PYTHON = sys.executable
ENV = {**os.environ, "PYTHONUNBUFFERED": "1"}

SCENE = """
[scene]
name = "test"

[outputs]
requested = ["bounce_heights", "cor"]
tolerance = 1e-2
{model}
[simulation]
max_bounces = {max_bounces}
v_min = {v_min}
""" + steel_on_aluminium("{heights}", "{thickness}", "{diameter}")


def scene_text(thickness='"3.18 mm"', diameter='"6.35 mm"', heights='"0.1 m"', max_bounces=10000, model="",
               v_min='"0.1 m/s"'):
    return SCENE.format(thickness=thickness, diameter=diameter, heights=heights, max_bounces=max_bounces,
                        model=model, v_min=v_min)


def load(text):
    return parse_scene(tomllib.loads(text), source="t.toml")


# --- loader: values the FMU rejects, bounds, ASCII digits ---------------------------------
@pytest.mark.parametrize("kwargs, key, words", [
    # the wording every front end gives a value outside its range (restitution.domain.outside_text)
    (dict(diameter='"1e300 m"'), "balls[0].diameter", ["diameter = 1e+300 m is outside 1e-06 <= value <= 10 m"]),
    (dict(diameter='"0.1 um"'), "balls[0].diameter", ["is outside 1e-06 <= value"]),
    (dict(thickness='"1000 m"'), "plates[0].thickness", ["thickness = 1000 m is outside"]),
    (dict(heights='["0.1 m", "1e9 m"]'), "balls[0].drop_heights[1]", ["drop_heights[1] = 1000000000 m is outside"]),
    (dict(max_bounces=10 ** 12), "simulation.max_bounces", [f"<= {MAX_BOUNCES}"]),
    (dict(diameter='"٣.١٨ mm"'), "balls[0].diameter", ["ASCII digits"]),
    (dict(thickness='"3.18 mm"', diameter='"６ mm"'), "balls[0].diameter", ["ASCII digits"]),
])
def test_loader_refuses_what_the_fmu_would_reject(kwargs, key, words):
    with pytest.raises(SceneError) as info:
        load(scene_text(**kwargs))
    message = str(info.value)
    assert message.startswith(f"t.toml: {key}: "), message
    for w in words:
        assert w in message, (w, message)


def test_material_outside_the_domain_names_the_key():
    text = scene_text().replace('material = "al_6061"', 'material = {E = "1e20 Pa", nu = 0.3, Sy = "1 GPa", '
                                                         'rho = "2000 kg/m3"}')
    with pytest.raises(SceneError, match=r"plates\[0\]\.material\.E: E = 1e\+20 Pa is outside "
                                         r"100000 <= value <= 1e\+13 Pa$"):
        load(text)


def test_highest_bounds_still_load():
    scene = load(scene_text(diameter='"10 m"', thickness='"100 m"', heights='"5e6 m"', max_bounces=MAX_BOUNCES))
    assert scene.balls[0].diameter == 10.0 and scene.simulation.max_bounces == MAX_BOUNCES


# --- the command line: errors, validity, progress ------------------------------------------
def _run_cli(*args, cwd=None):
    return subprocess.run([PYTHON, "-m", "restitution.scene", *map(str, args)], capture_output=True, text=True,
                          env=ENV, cwd=cwd, timeout=300)


def test_cli_user_mistakes_are_one_line_errors(tmp_path, impact_fmu):
    scene = tmp_path / "s.toml"
    scene.write_text(scene_text(diameter='"1e300 m"'))
    a_file = tmp_path / "file"
    a_file.write_text("x")
    good = tmp_path / "good.toml"
    good.write_text(scene_text())
    latin1 = tmp_path / "latin1.toml"
    latin1.write_bytes(scene_text().replace('name = "test"', 'name = "caf\u00e9"').encode("latin-1"))
    out = tmp_path / "out"
    fmu = ("--fmu", impact_fmu)
    for args, words in (((tmp_path / "missing.toml", *fmu), ["missing.toml", "cannot read"]),
                        ((scene, *fmu), ["balls[0].diameter", "1e+300 m", "outside"]),
                        ((latin1, *fmu), ["latin1.toml", "not UTF-8"]),
                        ((good, *fmu, "--out", a_file), ["--out", "not a directory"]),
                        ((good, *fmu, "--out", a_file / "sub"), ["--out", "cannot write"]),
                        ((good, "--fmu", tmp_path / "missing.fmu", "--out", out), ["--fmu", "no such file"]),
                        ((good, "--fmu", a_file, "--out", out), ["--fmu", "not an FMU"])):
        proc = _run_cli("run", *args, "--no-plot")
        assert proc.returncode == 2, proc.stderr
        assert "Traceback" not in proc.stderr
        line, = proc.stderr.strip().splitlines()
        assert all(w in line for w in words), (words, line)
    assert not out.exists() or not any(out.iterdir())  # a bad --fmu is refused before anything is written
    for args, words in (((good, "--repeat", "0"), ["--repeat"]),  # argparse: its usage line, then the error
                        ((good, "--methods", "exact,bogus"), ["--methods", "'bogus'"]),
                        ((good, "--out", tmp_path, "--fmu", impact_fmu), ["--out", "is a directory"]),
                        ((good, "--out", a_file / "r.md", "--fmu", impact_fmu), ["--out", "not a directory"])):
        proc = _run_cli("report", *args)  # refused before any scene runs
        assert proc.returncode == 2, proc.stderr
        assert "Traceback" not in proc.stderr
        lines = proc.stderr.strip().splitlines()
        assert len(lines) == 1 or lines[0].startswith("usage:"), proc.stderr
        assert all(w in lines[-1] for w in words), (words, lines[-1])


def test_a_value_the_fmu_refuses_names_the_scene_key(tmp_path, impact_fmu):
    """The loader refuses what this FMU would; a scene built past the loader (or another FMU with a
    narrower domain) meets the FMU's refusal, reported as the loader would, naming the key, with the
    drops finished before it kept."""
    scene = load(scene_text(heights='["0.1 m", "0.2 m"]'))
    thin = replace(scene.plates[0], name="thin", thickness=-1.0)
    ball = replace(scene.balls[0], plates=("plate", "thin"))
    bad = replace(scene, plates=(scene.plates[0], thin), balls=(ball,))
    done = []
    with pytest.raises(SceneError) as info:
        run_scene(bad, fmu=impact_fmu, progress=False, on_drop=done.append)
    message = str(info.value)
    assert info.value.key == "plates[1].thickness", message
    assert "plate.t = -1.0" in message and "outside the allowed range" in message
    assert len(done) == 2  # both drops on the good plate finished first
    huge = replace(scene, balls=(replace(scene.balls[0], diameter=1e300),))
    with pytest.raises(SceneError, match=r"balls\[0\]\.diameter: the FMU rejects this value: sphere.d = 1e\+300"):
        run_scene(huge, fmu=impact_fmu, progress=False)


def test_drop_from_a_megametre_is_flagged(tmp_path, impact_fmu, capsys):
    # v = sqrt(2 g 1e6 m) = 4.4 km/s: V* ~ 1e5, far beyond JGM's fitted V* <= 1000
    scene = tmp_path / "high.toml"
    scene.write_text(scene_text(heights='["0.1 m", "1e6 m"]', max_bounces=50))  # both come to rest
    assert main(["run", str(scene), "--fmu", str(impact_fmu), "--out", str(tmp_path), "--no-plot",
                 "--no-progress"]) == 0
    captured = capsys.readouterr()
    with (tmp_path / "high.csv").open() as f:
        rows = list(csv.DictReader(f))
    assert {"valid", "jgm.in_range", "zener.in_range"} <= set(rows[0])
    high = [r for r in rows if float(r["drop_height_m"]) == 1e6]
    low = [r for r in rows if float(r["drop_height_m"]) == 0.1]
    assert high[0]["valid"] == "0" and high[0]["jgm.in_range"] == "0"
    assert {r["valid"] for r in low} == {"1"}
    n_out = sum(r["valid"] == "0" for r in rows)
    assert n_out >= 1
    with (tmp_path / "high_summary.csv").open() as f:
        summary = {r["drop_height_m"]: r for r in csv.DictReader(f)}
    assert summary["1000000"]["out_of_range_impacts"] == str(sum(r["valid"] == "0" for r in high))
    assert summary["0.1"]["out_of_range_impacts"] == "0"
    assert f"warning: {n_out} of {len(rows)} impacts lie outside the models' validated ranges" in captured.err
    assert "out of range" in captured.out  # the summary table's column


def test_progress_when_redirected_is_one_final_line(tmp_path, impact_fmu):
    scene = tmp_path / "s.toml"
    scene.write_text(scene_text(heights='["0.1 m", "0.2 m", "0.3 m"]'))
    proc = _run_cli("run", scene, "--fmu", impact_fmu, "--out", tmp_path, "--no-plot")
    assert proc.returncode == 0, proc.stderr
    assert "\r" not in proc.stderr
    line, = proc.stderr.strip().splitlines()  # no bar line per drop: only the final state
    assert line.startswith("s (exact): 3/3 drops done, ")
    assert proc.stdout.startswith("test: 3 drops, ")  # the summary starts on its own line


# --- interruption -----------------------------------------------------------------------
@pytest.mark.slow
def test_sigint_keeps_every_finished_drop(tmp_path, impact_fmu):
    heights = "[" + ", ".join(f'"{0.05 + 0.005 * k:.3f} m"' for k in range(200)) + "]"
    scene = tmp_path / "slow.toml"
    # zener_method = ode (ms an impact) and v_min = 1 mm/s (tens of impacts a drop): 200 drops take long
    scene.write_text(scene_text(heights=heights, model='[model]\nzener_method = "ode"\nplate_waves = "on"\n',
                                v_min='"0.001 m/s"'))
    out = tmp_path / "out"
    proc = subprocess.Popen([PYTHON, "-m", "restitution.scene", "run", str(scene), "--fmu", str(impact_fmu),
                             "--out", str(out), "--no-plot"], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, env=ENV, start_new_session=True, preexec_fn=takes_ctrl_c)
    table = out / "slow.csv"

    def finished_drops():
        if not table.exists():
            return set()
        with table.open() as f:
            return {r["drop_height_m"] for r in csv.DictReader(f)}

    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and proc.poll() is None and len(finished_drops()) < 3:
        time.sleep(0.05)
    assert proc.poll() is None, "the scene ended before it could be interrupted"
    os.killpg(proc.pid, signal.SIGINT)  # Ctrl-C: the whole process group
    _, err = proc.communicate(timeout=120)
    drops = finished_drops()
    assert 3 <= len(drops) < 200
    with table.open() as f:
        rows = list(csv.DictReader(f))
    # every drop in the table is whole: it ends where the ball rests (its last rebound below v_min)
    with (out / "slow_summary.csv").open() as f:
        summary = {r["drop_height_m"]: int(r["impacts"]) for r in csv.DictReader(f)}
    for h in drops:
        assert sum(r["drop_height_m"] == h for r in rows) == summary[h]
    assert proc.returncode == 130, err
    assert f"{len(drops)} of 200 drops finished" in err and "Traceback" not in err


def test_progress_in_a_terminal_ends_with_the_final_state_on_its_own_line(tmp_path, impact_fmu):
    scene = tmp_path / "s.toml"
    heights = "[" + ", ".join(f'"{0.05 + 0.005 * k:.3f} m"' for k in range(12)) + "]"
    # zener_method = ode: a couple of seconds, so a terminal may show the bar (not asserted: timing)
    scene.write_text(scene_text(heights=heights, model='[model]\nzener_method = "ode"\nplate_waves = "on"\n',
                                v_min='"0.001 m/s"'))
    status, out, err = with_terminal_stderr([PYTHON, "-m", "restitution.scene", "run", scene, "--fmu", impact_fmu,
                                             "--out", tmp_path, "--no-plot"], ENV)
    assert status == 0
    err = err.replace("\r\n", "\n")
    shown = [line.rsplit("\r", 1)[-1] for line in err.split("\n")]  # what the terminal shows on each line
    finals = [line for line in shown if "drops done" in line]
    assert len(finals) == 1 and finals[0].startswith("s (ode): 12/12 drops done, "), err
    assert not [line for line in shown if "%|" in line], err  # any bar was cleared, not left behind
    assert out.startswith("test: 12 drops, "), out  # the summary on its own line


def test_report_prints_one_final_line_per_variant_not_per_repeat(tmp_path, impact_fmu):
    scene = tmp_path / "s.toml"
    scene.write_text(scene_text())
    proc = _run_cli("report", scene, "--fmu", impact_fmu, "--repeat", "5", "--methods", "exact")
    assert proc.returncode == 0, proc.stderr
    finals = [line for line in proc.stderr.splitlines() if "drops done" in line]
    assert len(finals) == 2, proc.stderr  # as declared and every effect on; no bar when redirected
    assert "\r" not in proc.stderr
