"""Scene files (restitution.scene): loader errors, the example scenes through the FMU, what
``auto`` leaves out and what that costs against every effect on."""
import csv
import gc
import math
import re
import subprocess
import tomllib
import types
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

import restitution as r
from restitution.scene import SceneError, load_scene, parse_scene, run_scene
from restitution.scene.__main__ import main
from restitution.scene.report import MARK_END, MARK_START, compare, report_scene
from restitution.scene.runner import open_instance
from scene_texts import steel_on_aluminium

ROOT = Path(__file__).resolve().parents[2]
SCENES = ROOT / "examples" / "scenes"
EXAMPLES = sorted(SCENES.glob("*.toml"))
G = 9.80665

MINIMAL = """
[scene]
name = "test"

[outputs]
requested = ["bounce_heights"]
tolerance = 1e-6
""" + steel_on_aluminium()


def scene_from(text):
    return parse_scene(tomllib.loads(text), source="t.toml")


@pytest.fixture(scope="module")
def instance(impact_fmu):
    inst = open_instance(impact_fmu)
    yield inst
    inst.close()


@pytest.fixture(scope="module")
def runs(instance):
    """Every example scene, as declared (auto) and with every effect on (exact Zener)."""
    out = {}
    for path in EXAMPLES:
        scene = load_scene(path)
        out[path.stem] = (scene, run_scene(scene, instance=instance, progress=False),
                          run_scene(scene, instance=instance, effects="all_on", progress=False))
    return out


# --- loader ------------------------------------------------------------------------------------

def test_minimal_scene_loads_in_si_units():
    scene = scene_from(MINIMAL)
    assert scene.plates[0].thickness == pytest.approx(3.18e-3, rel=1e-15)
    assert scene.balls[0].diameter == pytest.approx(6.35e-3, rel=1e-15)
    assert scene.balls[0].drop_heights == (pytest.approx(0.1),)
    assert scene.balls[0].material is r.MATERIALS["s2_tool_steel"]
    assert scene.simulation.gravity == 9.80665 and scene.simulation.v_min == 0.1
    assert scene.model.effect_tolerance == 1e-6 and scene.model.zener_method == "exact"
    assert scene.effect_modes() == ("auto", "auto")
    assert [d.drop_height for d in scene.drops()] == [pytest.approx(0.1)]


def test_units_and_materials_convert():
    text = MINIMAL.replace('thickness = "3.18 mm"', 'thickness = "0.125 in"').replace(
        'material = "al_6061"', 'material = { E = "70 GPa", nu = 0.3, Sy = "250 MPa", rho = "2.7 g/cm3" }')
    text = text.replace('material = "s2_tool_steel"', 'material = { base = "s2_tool_steel", Sy = "brittle" }')
    text += '\n[simulation]\ngravity = "9.81 m/s2"\nv_min = "5 cm/s"\n'
    scene = scene_from(text)
    plate, ball = scene.plates[0], scene.balls[0]
    assert plate.thickness == pytest.approx(3.175e-3, rel=1e-14)
    assert (plate.material.E, plate.material.nu, plate.material.Sy, plate.material.rho) == pytest.approx(
        (70e9, 0.3, 250e6, 2700.0), rel=1e-14)
    assert ball.material.Sy == r.BRITTLE_SY and ball.material.E == 207e9 and ball.material.rho == 7861.0
    assert scene.simulation.v_min == pytest.approx(0.05) and scene.simulation.gravity == 9.81
    sphere, plate4 = r.table4_case("A1")
    s4 = scene_from(MINIMAL.replace('"al_6061"', '"table4.A1.plate"').replace('"s2_tool_steel"', '"table4.A1.sphere"'))
    assert s4.plates[0].material == plate4 and s4.balls[0].material == sphere


@pytest.mark.parametrize("key, written, si", [
    ("thickness", "1 ft", 0.3048), ("thickness", "3.18 millimeter", 3.18e-3), ("thickness", "0.5 µm", 5e-7),
    ("v_min", "0.36 km/h", 0.1), ("gravity", "32.174 ft/s^2", 9.8066),
    ("rho", "0.0975 lb/in3", 2698.7), ("E", "10 Mpsi", 68.95e9),
])
def test_any_unit_of_the_right_kind_is_read(key, written, si):
    """Units are pint's: besides the usual ones, imperial and spelled-out units convert (factors
    exact by definition: 1 ft = 0.3048 m, 1 lb = 0.45359237 kg, 1 psi = 1 lbf/in2)."""
    text = MINIMAL + '\n[simulation]\nv_min = "0.1 m/s"\n'
    if key in ("v_min", "gravity"):
        text = text.replace('v_min = "0.1 m/s"', f'{key} = "{written}"')
    elif key == "thickness":
        text = text.replace('thickness = "3.18 mm"', f'thickness = "{written}"')
    else:
        props = {"E": '"70 GPa"', "nu": "0.3", "Sy": '"250 MPa"', "rho": '"2700 kg/m3"', key: f'"{written}"'}
        text = text.replace('material = "al_6061"', "material = { " + ", ".join(f"{k} = {v}" for k, v in props.items()) + " }")
    scene = scene_from(text)
    value = {"thickness": scene.plates[0].thickness, "v_min": scene.simulation.v_min,
             "gravity": scene.simulation.gravity, "rho": scene.plates[0].material.rho,
             "E": scene.plates[0].material.E}[key]
    assert value == pytest.approx(si, rel=1e-4)


def test_a_unit_of_no_scene_kind_is_named_by_its_dimension():
    with pytest.raises(SceneError, match=r"'3\.18 J': J is a unit of \[mass\] \* \[length\] \*\* 2 / \[time\] \*\* 2, "
                                         r"but thickness is a length"):
        scene_from(MINIMAL.replace('thickness = "3.18 mm"', 'thickness = "3.18 J"'))


def test_contact_durations_force_plate_waves_on():
    scene = scene_from(MINIMAL.replace('["bounce_heights"]', '["bounce_heights", "contact_durations"]'))
    assert scene.effect_modes() == ("auto", "on")
    off = scene_from(MINIMAL.replace('["bounce_heights"]', '["contact_durations"]') + '\n[model]\nplate_waves = "off"\n')
    assert off.effect_modes() == ("auto", "off")  # an explicit choice is kept


def test_a_bare_number_is_si_as_everywhere_in_the_package():
    with_units = scene_from(MINIMAL)
    bare = scene_from(MINIMAL.replace('thickness = "3.18 mm"', "thickness = 0.00318")
                      .replace('diameter = "6.35 mm"', 'diameter = "0.00635"')
                      .replace('drop_heights = "0.1 m"', "drop_heights = [0.1]"))
    assert bare.plates[0].thickness == with_units.plates[0].thickness == pytest.approx(3.18e-3, rel=1e-15)
    assert bare.balls[0].diameter == with_units.balls[0].diameter
    assert bare.balls[0].drop_heights == with_units.balls[0].drop_heights


@pytest.mark.parametrize("old, new, key, words", [
    ('diameter = "6.35 mm"', 'diamter = "6.35 mm"', "balls[0].diamter", ["unknown key", "did you mean 'diameter'"]),
    ('[outputs]', '[outputs]\ncolour = "red"', "outputs.colour", ["unknown key"]),
    ('[scene]', '[scenery]\n[scene]', "scenery", ["unknown key", "did you mean 'scene'"]),
    ('thickness = "3.18 mm"', 'thickness = "3.18 GPa"', "plates[0].thickness", ["GPa is a unit of pressure", "length"]),
    ('thickness = "3.18 mm"', 'thickness = 3180', "plates[0].thickness",
     ["thickness = 3180 m is outside 1e-07 <= value <= 100 m", "did you mean 3180 mm?"]),
    ('material = "al_6061"', 'material = { E = 114, nu = 0.3, Sy = "1 GPa", rho = "2700 kg/m3" }',
     "plates[0].material.E", ["E = 114 Pa is outside 100000 <= value <= 1e+13 Pa", "did you mean 114 GPa?"]),
    ('thickness = "3.18 mm"', 'thickness = "3.18 blargs"', "plates[0].thickness", ["unknown unit 'blargs'"]),
    ('thickness = "3.18 mm"', 'thickness = "-1 mm"', "plates[0].thickness", ["must be > 0"]),
    ('drop_heights = "0.1 m"', 'drop_heights = ["0.1 m", "20 m/s"]', "balls[0].drop_heights[1]",
     ["m/s is a unit of speed"]),
    ('diameter = "6.35 mm"\n', '', "balls[0].diameter", ["missing required key"]),
    ('drop_heights = "0.1 m"\n', '', "balls[0].drop_heights", ["missing required key"]),
    ('tolerance = 1e-6', 'tolerance = "1e-6 m"', "outputs.tolerance", ["plain number", "dimensionless"]),
    ('["bounce_heights"]', '["bounce_height"]', "outputs.requested", ["unknown output", "did you mean 'bounce_heights'"]),
    ('material = "al_6061"', 'material = "al_6016"', "plates[0].material", ["unknown material", "al_6061"]),
    ('material = "al_6061"', 'material = { E = "70 GPa", nu = 0.3, rho = "2700 kg/m3" }',
     "plates[0].material.Sy", ["missing required key"]),
    ('material = "al_6061"', 'material = { E = "70 GPa", nu = 0.51, Sy = "1 GPa", rho = "2700 kg/m3" }',
     "plates[0].material.nu", ["must be <= 0.5"]),
    ('drop_heights = "0.1 m"', 'drop_heights = "0.1 m"\nplates = ["table"]', "balls[0].plates", ["no plate named 'table'"]),
])
def test_loader_errors_name_the_key(old, new, key, words):
    assert old in MINIMAL
    with pytest.raises(SceneError) as info:
        scene_from(MINIMAL.replace(old, new, 1))
    assert info.value.key == key
    message = str(info.value)
    assert message.startswith(f"t.toml: {key}: ")
    for word in words:
        assert word in message, message


def test_a_scene_without_outputs_gets_bounce_heights_and_cor():
    scene = scene_from(MINIMAL.replace('[outputs]\nrequested = ["bounce_heights"]\ntolerance = 1e-6\n', ""))
    assert scene.outputs == ("bounce_heights", "cor") and scene.tolerance == 1e-3
    scene = scene_from(MINIMAL.replace("tolerance = 1e-6\n", ""))  # either key alone
    assert scene.outputs == ("bounce_heights",) and scene.tolerance == 1e-3


def test_model_choices_and_file_errors(tmp_path):
    with pytest.raises(SceneError, match=r"model.zener_method: 'rk4' is not one of 'exact'"):
        scene_from(MINIMAL + '\n[model]\nzener_method = "rk4"\n')
    bad = tmp_path / "bad.toml"
    bad.write_text("[scene\nname = 1\n")
    with pytest.raises(SceneError, match=r"bad.toml: not valid TOML"):
        load_scene(bad)
    with pytest.raises(SceneError, match=r"missing.toml: cannot read"):
        load_scene(tmp_path / "missing.toml")
    assert main(["check", str(bad)]) == 2


def test_every_example_scene_loads():
    assert {p.stem for p in EXAMPLES} >= {"steel_ball_thick_steel_table", "glass_marble_glass_plate",
                                          "steel_ball_thin_aluminium", "tungsten_carbide_soft_plate"}
    for path in EXAMPLES:
        scene = load_scene(path)
        assert scene.drops() and scene.tolerance > 0


# --- running through the FMU ---------------------------------------------------------------------

def test_each_example_scene_runs_and_matches_the_package(runs):
    for stem, (scene, auto, _on) in runs.items():
        plasticity, waves = scene.effect_modes()
        for d in auto.drops:
            assert d.n_impacts >= 1, (stem, d.drop.label)
            # flight is symmetric: the ball comes back down as fast as it went up
            assert d.v_approach[0] == pytest.approx(math.sqrt(2 * G * d.drop.drop_height), rel=1e-15)
            np.testing.assert_allclose(d.v_approach[1:], d.v_rebound[:-1], rtol=1e-12)
            # the FMU's answer at each impact is the package's for the same modes
            ref = r.impact(d.v_approach, **r.Sphere(d.drop.ball.material, d.drop.ball.diameter).params(),
                           **r.Plate(d.drop.plate.material, d.drop.plate.thickness).params(),
                           plasticity=plasticity, plate_waves=waves, zener_method=scene.model.zener_method,
                           effect_tolerance=scene.model.effect_tolerance)
            np.testing.assert_allclose(d.v_rebound, ref.v_rebound, rtol=1e-12, atol=1e-15)
            np.testing.assert_array_equal(d.plasticity, ref.plasticity_used)
            np.testing.assert_array_equal(d.plate_waves, ref.plate_waves_used)
            for col, field in (("e", "e"), ("e_ep", "e_ep"), ("e_ze", "e_ze"), ("t_contact", "t_contact")):
                if col in d.columns:
                    np.testing.assert_allclose(d.columns[col], getattr(ref, field), rtol=1e-12, atol=1e-15)
            if "apex" in d.columns:
                np.testing.assert_allclose(d.columns["apex"], np.maximum(ref.v_rebound, 0) ** 2 / (2 * G), rtol=1e-12)
            # stop rule
            last = d.v_rebound[-1]
            assert d.stop_reason == ("e<=0" if last <= 0 else "v_min")
            assert (d.v_rebound[:-1] >= scene.simulation.v_min).all()
            # only the requested outputs were read
            from restitution.scene.results import READ_OUTPUTS
            assert set(d.columns) == {c for o in scene.outputs for c in READ_OUTPUTS[o][1]}


def test_effect_counts(runs):
    counts = {stem: auto.effect_counts() for stem, (_s, auto, _on) in runs.items()}
    # thick steel table, no durations requested: plate waves skipped everywhere, plasticity needed everywhere
    assert counts["steel_ball_thick_steel_table"] == {"impacts": 52, "plasticity": 52, "plate_waves": 0}
    # glass on glass: both brittle, plasticity never; durations requested: plate waves always
    assert counts["glass_marble_glass_plate"] == {"impacts": 22, "plasticity": 0, "plate_waves": 22}
    assert counts["steel_ball_thin_aluminium"] == {"impacts": 27, "plasticity": 27, "plate_waves": 27}
    assert counts["tungsten_carbide_soft_plate"] == {"impacts": 8, "plasticity": 6, "plate_waves": 8}
    # every effect on: the JGM flag is set wherever e_ep < 1, Zener always computed
    for stem, (_s, _auto, on) in runs.items():
        c = on.effect_counts()
        assert c["plate_waves"] == c["impacts"], stem
    assert runs["glass_marble_glass_plate"][2].effect_counts()["plasticity"] == 0


def test_thin_sheets_and_table4_case_a_end_with_negative_e(runs):
    _scene, auto, _on = runs["steel_ball_thin_aluminium"]
    first_e = {(d.drop.plate.name, d.drop.drop_height): d.columns["e"][0] for d in auto.drops}
    stops = {(d.drop.plate.name, d.drop.drop_height): d.stop_reason for d in auto.drops}
    assert stops[("1 mm sheet", 0.3)] == "e<=0" and first_e[("1 mm sheet", 0.3)] == pytest.approx(-0.18452, abs=1e-4)
    assert stops[("1/4 in plate", 0.3)] == "v_min"
    # thicker sheets rebound better at the same speed
    assert first_e[("1 mm sheet", 0.3)] < first_e[("2 mm sheet", 0.3)] < first_e[("1/8 in sheet", 0.3)] \
        < first_e[("1/4 in plate", 0.3)]
    _scene, auto, _on = runs["tungsten_carbide_soft_plate"]
    thin = [d for d in auto.drops if d.drop.plate.name.startswith("A1 thin")]
    for d in thin:
        assert d.stop_reason == "e<=0" and d.n_impacts == 1
        assert d.columns["e_ze"][0] < 1e-3 and d.columns["e"][0] < 0
        assert d.columns["t_contact"][0] > 5e-4  # long contact: lambda ~ 6 (Hertz alone: ~30 us)


def test_auto_versus_all_on_within_declared_tolerance(runs):
    for stem, (scene, auto, on) in runs.items():
        diffs = compare(auto, on)
        assert diffs["impact_count"] == 0, stem
        worst = max(v for k, v in diffs.items() if k != "impact_count")
        assert worst <= scene.tolerance, (stem, diffs)
    # where nothing is skipped that changes e, auto and all-on agree exactly
    for stem in ("glass_marble_glass_plate", "steel_ball_thin_aluminium", "tungsten_carbide_soft_plate"):
        _s, auto, on = runs[stem]
        assert max(v for v in compare(auto, on).values()) == 0.0, stem
    # the table: skipping Zener changes e by less than effect_tolerance at every impact, but does change it
    scene, auto, on = runs["steel_ball_thick_steel_table"]
    diffs = compare(auto, on)
    assert 1e-4 < diffs["e_ze"] < scene.model.effect_tolerance
    assert 1e-4 < diffs["e"] < scene.model.effect_tolerance
    assert diffs["e_ep"] < scene.model.effect_tolerance  # only through the slightly different speeds
    assert 1e-3 < diffs["apex"] < scene.tolerance


def test_table_with_contact_durations_keeps_plate_waves(instance):
    scene = load_scene(SCENES / "steel_ball_thick_steel_table.toml")
    timed = replace(scene, outputs=scene.outputs + ("contact_durations",))
    auto = run_scene(timed, instance=instance, progress=False)
    on = run_scene(timed, instance=instance, effects="all_on", progress=False)
    assert auto.plate_waves_mode == "on"
    assert auto.effect_counts() == {"impacts": 52, "plasticity": 52, "plate_waves": 52}
    assert compare(auto, on)["t_contact"] == 0.0
    # what the skipped Zener evaluation would have reported: the Hertz duration, off by more than the tolerance
    skipped = run_scene(timed.with_model(plate_waves="off"), instance=instance, progress=False)
    rel = np.abs(skipped.drops[0].columns["t_contact"] / auto.drops[0].columns["t_contact"] - 1)
    assert rel.max() > 1e-4


def test_impact_model_evaluated_only_at_impact_events(instance):
    # the FMU's slave module(s) in this process (other tests may have loaded more than one copy)
    modules = [m for m in gc.get_objects()
               if isinstance(m, types.ModuleType) and m.__name__ == "sphere_plate_impact_slave"]
    assert modules
    calls = []
    originals = [m._impact_si for m in modules]

    def counting(original):
        def impact(v, *args, **kwargs):
            calls.append(v)
            return original(v, *args, **kwargs)
        return impact

    for m, original in zip(modules, originals):
        m._impact_si = counting(original)
    try:
        scene = load_scene(SCENES / "steel_ball_thick_steel_table.toml")
        result = run_scene(scene, instance=instance, progress=False)
    finally:
        for m, original in zip(modules, originals):
            m._impact_si = original
    speeds = np.concatenate([d.v_approach for d in result.drops])
    assert len(calls) == result.n_impacts == 52
    np.testing.assert_array_equal(np.array(calls), speeds)


def test_report_with_ode_on_the_table(instance):
    """zener_method = ode, where skipping saves the most: same counts, no ODE solve at all in auto."""
    scene = load_scene(SCENES / "steel_ball_thick_steel_table.toml")
    scene = replace(scene, balls=scene.balls[:1])  # one ball: 26 impacts
    rep = report_scene(scene, instance, methods=["ode"], repeat=1, progress=False)
    auto, on = rep.runs[("scene", "ode")], rep.runs[("all_on", "ode")]
    assert auto.effect_counts() == {"impacts": 26, "plasticity": 26, "plate_waves": 0}
    assert rep.within_tolerance and rep.diffs["ode"]["impact_count"] == 0
    assert rep.times[("all_on", "ode")] > 3 * rep.times[("scene", "ode")]


def test_command_line_run_and_report(any_version_impact_fmu, tmp_path, capsys):
    """Through every FMU: --fmu DIR/SpherePlateImpact.fmu, DIR/fmi2/SpherePlateImpact.fmu (FMI 2.0) and
    DIR/fmi3/SpherePlateImpact.fmu (FMI 3.0)."""
    impact_fmu = any_version_impact_fmu
    path = SCENES / "glass_marble_glass_plate.toml"
    assert main(["run", str(path), "--fmu", str(impact_fmu), "--out", str(tmp_path), "--no-progress"]) == 0
    printed = capsys.readouterr().out
    assert "plasticity: skipped at 22 of 22 impacts: 22 where neither body can yield" in printed
    with (tmp_path / "glass_marble_glass_plate.csv").open() as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == 22
    assert list(rows[0]) == ["ball", "plate", "drop_height_m", "impact", "time_s", "v_approach_m_s", "apex_m",
                             "t_contact_s", "plasticity", "plate_waves", "valid", "jgm.in_range", "zener.in_range"]
    assert float(rows[0]["v_approach_m_s"]) == pytest.approx(math.sqrt(2 * G * 0.05), rel=1e-11)
    assert {r_["plasticity"] for r_ in rows} == {"0"} and {r_["plate_waves"] for r_ in rows} == {"1"}
    assert (tmp_path / "glass_marble_glass_plate.png").stat().st_size > 10_000

    doc = tmp_path / "scenes.md"
    doc.write_text(f"# intro\n\n{MARK_START}\nold table\n{MARK_END}\n\ntail text\n")
    assert main(["report", str(path), "--fmu", str(impact_fmu), "--out", str(doc), "--repeat", "1",
                 "--methods", "exact", "--no-progress"]) == 0
    text = doc.read_text()
    assert text.startswith("# intro\n") and text.rstrip().endswith("tail text") and "old table" not in text
    assert "| `glass_marble_glass_plate` | heights, durations | 22 | 0/22 | 22/22 |" in text


BOUNCE_TABLE = "bounce height after each impact [mm] (e [1])"
CELL = re.compile(r"(\S+) \((\S+)\)")


def test_run_prints_the_bounce_heights_and_cor_of_each_drop(any_version_impact_fmu, tmp_path, capsys):
    """The answer on screen: per drop, the height after each of the first impacts and its COR. The
    first is checked against the package alone: e at v0 = sqrt(2 g h0), and the rebound apex e^2 h0
    (energy), to the 4 and 3 digits printed."""
    path = SCENES / "steel_ball_thin_aluminium.toml"
    assert main(["run", str(path), "--fmu", str(any_version_impact_fmu), "--out", str(tmp_path), "--no-plot",
                 "--no-progress"]) == 0
    table = capsys.readouterr().out.split(BOUNCE_TABLE, 1)[1].splitlines()
    for drop in load_scene(path).drops():
        line = next(row for row in table if row.strip().startswith(drop.label))
        cells = CELL.findall(line[len(drop.label) + 2:])
        assert cells, line
        h0 = drop.drop_height
        e = r.impact_between(r.Sphere(drop.ball.material, drop.ball.diameter),
                             r.Plate(drop.plate.material, drop.plate.thickness), math.sqrt(2 * G * h0)).e
        apex_mm, cor = map(float, cells[0])
        assert cor == pytest.approx(e, rel=5e-3), drop.label
        assert apex_mm == pytest.approx(max(e, 0.0) ** 2 * h0 * 1e3, rel=5e-4, abs=0.0), drop.label


ENDLESS_SCENE = """
[scene]
name = "glass marble on a 3 m glass block"

[simulation]
max_bounces = 50

[[plates]]
name = "block"
material = "borosilicate_glass"
thickness = "3 m"

[[balls]]
name = "marble"
material = "borosilicate_glass"
diameter = "16 mm"
drop_heights = "1 m"
"""


def test_a_drop_still_bouncing_at_its_limit_warns_and_exits_3(any_version_impact_fmu, tmp_path, capsys):
    """Glass on a 3 m glass block loses almost nothing per impact (neither body yields, the plate is
    a half-space for Zener: e within 1e-4 of 1), so the ball never comes to rest: everything is
    written, a warning says why and what to change, and the exit status is not 0."""
    scene = tmp_path / "endless.toml"
    scene.write_text(ENDLESS_SCENE)
    status = main(["run", str(scene), "--fmu", str(any_version_impact_fmu), "--out", str(tmp_path / "out"), "--no-plot",
                   "--no-progress"])
    captured = capsys.readouterr()
    assert status == 3
    assert "1 of 1 drops did not come to rest within simulation.max_bounces = 50 impacts" in captured.err
    assert "Raise simulation.max_bounces" in captured.err
    with (tmp_path / "out" / "endless.csv").open() as f:
        assert len(list(csv.DictReader(f))) == 50
    assert "max_bounces" in captured.out  # the summary's stop column


def test_the_height_axis_turns_logarithmic_when_bounces_span_decades():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from restitution.scene.plot import _readable_heights

    fig, (wide, narrow) = plt.subplots(2)
    _readable_heights(wide, [np.array([0.3, 1.35e-3, 1.1e-4, 0.0]), [1.0]])  # 1 m drop, 0.11 mm bounce
    _readable_heights(narrow, [np.array([0.045, 0.04]), [0.05]])
    assert wide.get_yscale() == "log" and wide.get_ylim()[0] <= 0.11 < 1000.0 <= wide.get_ylim()[1]
    assert narrow.get_yscale() == "linear"
    plt.close(fig)


def test_default_scene_results_are_ignored_by_git():
    """`run` writes scene-results/<stem>/ by default; in a checkout that leaves `git status` clean."""
    if not (ROOT / ".git").exists():
        pytest.skip("not a git checkout")
    probe = subprocess.run(["git", "check-ignore", "-q", "scene-results/any/any.csv"], cwd=ROOT)
    assert probe.returncode == 0


def test_a_scene_outside_the_validated_domain_says_so_once_per_condition(impact_fmu):
    """A 0.3 mm plate under a 1/4 in steel ball dropped from 0.5 m: lambda far above 1.5 and e < 0 at the first
    impact. The FMU logs each condition once (a fresh instance: the count is per instance), and the result
    gives those lines, naming the drop, in restitution.assumptions' words."""
    from restitution.assumptions import CONDITIONS

    scene = scene_from(MINIMAL.replace('thickness = "3.18 mm"', 'thickness = "0.3 mm"').replace(
        'drop_heights = "0.1 m"', 'drop_heights = ["0.5 m", "0.4 m"]'))
    fresh = open_instance(impact_fmu)
    try:
        result = run_scene(scene, instance=fresh, progress=False)
    finally:
        fresh.close()
    lines = result.departure_warnings()
    assert lines and all(line.startswith("warning: ") for line in lines)
    said = [line.split(": ", 2)[2] for line in lines]
    assert any(text.startswith("zener.lambda = ") and "is above 1.5" in text for text in said)
    names = [name for name, _flag, _message in CONDITIONS]
    first_words = [text.split(" = ")[0] for text in said]
    assert len(first_words) == len(set(first_words)) <= len(names)  # once per condition, over both drops


def test_a_report_over_a_scene_file_is_refused_before_any_work(tmp_path, capsys):
    """`restitution scene report a.toml --out a.toml` wrote the Markdown report over the scene it reads;
    refused in one line, exit 2, the scene file left as it was (a hard link counts as the same file)."""
    scene = tmp_path / "scene.toml"
    scene.write_bytes(EXAMPLES[0].read_bytes())
    link = tmp_path / "report.md"
    link.hardlink_to(scene)
    for out in (scene, link):
        status = main(["report", str(scene), "--out", str(out), "--no-progress"])
        err = capsys.readouterr().err
        assert status == 2 and err.count("\n") == 1 and "is the input FILE 1" in err, err
    assert scene.read_bytes() == EXAMPLES[0].read_bytes()
