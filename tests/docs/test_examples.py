"""The examples (examples/*.py), run with show_plot=False, and the statements they illustrate.

Each example is imported and its ``run`` called with the FMUs built from the working tree, once
with the pythonfmu FMUs, once with the native ones (DIR/fmi2/) and once with the native FMI 3.0
ones (DIR/fmi3/); the numbers it returns are
checked against the event-exact master, the package, and the paper's statements (Green,
Nonlinear Dyn 2022, Sec. 6-7).
"""
import importlib.util
import math
import re
import sys
from pathlib import Path
from xml.etree import ElementTree as ET

import numpy as np
import pytest

import restitution as r

from independent import apparent_cor, table_material

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"
G = 9.80665


def _load(name):
    spec = importlib.util.spec_from_file_location(f"example_{name}", EXAMPLES / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def fmu_dir(any_version_fmu_dir) -> Path:
    """The folder with both FMUs: the pythonfmu ones, their native FMI 2.0 twins or the FMI 3.0 ones."""
    return any_version_fmu_dir


# --- 1. bouncing ball on plates of several thicknesses ------------------------------------
@pytest.fixture(scope="module")
def bouncing(fmu_dir, tmp_path_factory):
    return _load("bouncing_ball").run(show_plot=False, fmu_path=fmu_dir / "SpherePlateImpact.fmu",
                                      out_dir=tmp_path_factory.mktemp("out"), verbose=False)


def test_bouncing_ball_thickness_effect(bouncing):
    cases = bouncing["cases"]
    assert list(cases) == ["t/d = 0.25", "t/d = 0.5", "t/d = 1", "t/d = 2", "half-space"]
    v1 = math.sqrt(2 * G * 0.3)
    first_e = [b.e[0] for b in cases.values()]
    for b in cases.values():
        assert b.v_approach[0] == pytest.approx(v1, rel=1e-12)
        assert b.time[0] == pytest.approx(math.sqrt(2 * 0.3 / G), rel=1e-12)
    # thicker plate, livelier bounce; the half-space gives the JGM value e = e_ep
    assert np.all(np.diff(first_e) > 0.03), first_e
    half = cases["half-space"]
    assert np.all(half.e_ze == 1.0) and np.allclose(half.e, half.e_ep, rtol=0, atol=1e-15)
    # t/d = 0.25: e < 0, the ball stays with the plate (Sec. 5: negative apparent COR)
    thin = cases["t/d = 0.25"]
    assert thin.n_impacts == 1 and thin.stop_reason == "e<=0" and -0.2 < thin.e[0] < -0.1
    # more bounces and a later rest on thicker plates
    assert [b.n_impacts for b in cases.values()] == sorted(b.n_impacts for b in cases.values())
    assert np.all(np.diff([b.rest_time for b in cases.values()]) > 0)
    # the first impact of each drop against Eqs. (8), (12), (20) and the ODE solved independently
    s2, al = table_material("s2_tool_steel"), table_material("al_6061")
    want = [apparent_cor(s2, al, 6.35e-3, x * 6.35e-3, v1) for x in (0.25, 0.5, 1.0, 2.0)]
    want.append(apparent_cor(s2, al, 6.35e-3, 2 * 6.35e-3, v1, half_space=True))
    np.testing.assert_allclose([b.e[0] for b in cases.values()], want, rtol=0, atol=1e-8)
    assert [round(x, 3) for x in want] == [-0.147, 0.224, 0.498, 0.595, 0.630]  # as the docs show


def test_bouncing_ball_table_matches_the_package(bouncing):
    rows = bouncing["rows"]
    assert {w["plate"] for w in rows} == set(bouncing["cases"])
    assert sum(w["plate"] == "t/d = 1" for w in rows) == 5
    sphere = r.Sphere(r.MATERIALS["s2_tool_steel"], 6.35e-3)
    for w in rows:
        if w["plate"] == "half-space":
            continue
        td = float(w["plate"].split("=")[1])
        ref = r.impact_between(sphere, r.Plate(r.MATERIALS["al_6061"], td * 6.35e-3), v=w["v_approach"])
        assert w["e"] == pytest.approx(ref.e, abs=1e-12)
        assert w["e_ze"] == pytest.approx(ref.e_ze, abs=1e-12)
        assert w["t_contact_us"] == pytest.approx(ref.t_contact * 1e6, rel=1e-9)
    assert bouncing["markdown"].count("\n") == len(rows) + 1
    assert bouncing["png"].stat().st_size > 10_000


CHROME_ON_BRASS = ["--sphere", "chrome_steel", "--d", "4.76 mm", "--plate", "brass_260"]


def test_bouncing_ball_defaults_are_todays_case(bouncing, fmu_dir, tmp_path, capsys):
    """Without --sphere/--d/--plate/--t the command line drops today's ball on today's plates."""
    result = _load("bouncing_ball").main(["--fmu", str(fmu_dir / "SpherePlateImpact.fmu"), "--out-dir", str(tmp_path)])
    out = capsys.readouterr().out
    assert out.startswith("S2 tool-steel ball, d = 6.35 mm, dropped from 0.3 m on Al 6061 (first 5 bounces)\n")
    assert result["markdown"] == bouncing["markdown"] and result["markdown"] in out


def test_bouncing_ball_takes_the_users_case(fmu_dir, tmp_path, capsys):
    """--sphere, --d, --plate and --t (with units, repeatable) choose the drop, and the printout shows it."""
    result = _load("bouncing_ball").main(["--fmu", str(fmu_dir / "SpherePlateImpact.fmu"), *CHROME_ON_BRASS,
                                          "--t", "3 mm", "--t", "0.006", "--out-dir", str(tmp_path)])
    out = capsys.readouterr().out
    assert out.startswith("Chrome steel (AISI 52100) ball, d = 4.76 mm, dropped from 0.3 m on Brass alloy 260 ")
    assert list(result["cases"]) == ["t/d = 0.63", "t/d = 1.26", "half-space"]
    sphere = r.Sphere(r.MATERIALS["chrome_steel"], 4.76e-3)
    for label, t in (("t/d = 0.63", 3e-3), ("t/d = 1.26", 6e-3)):
        first = result["cases"][label]
        ref = r.impact_between(sphere, r.Plate(r.MATERIALS["brass_260"], t), v=first.v_approach[0])
        assert first.e[0] == pytest.approx(ref.e, abs=1e-9)
        (row,) = [line for line in out.splitlines() if line.startswith(f"| {label} | 1 |")]
        assert f" {ref.e:.3f} | {ref.e_ep:.3f} | {ref.e_ze:.3f} |" in row
    assert (tmp_path / "bouncing_ball.png").stat().st_size > 10_000


def test_bouncing_ball_refuses_a_slip_in_one_line(fmu_dir, capsys):
    with pytest.raises(SystemExit) as exit_:
        _load("bouncing_ball").main(["--fmu", str(fmu_dir / "SpherePlateImpact.fmu"), "--t", "3 km"])
    assert exit_.value.code == 2
    assert capsys.readouterr().err == "bouncing_ball.py: error: --t: plate.t = 3000 m is outside 1e-07 <= value " \
                                      "<= 100 m: did you mean 3000 mm?\n"


def test_model_exchange_bounce_takes_the_users_case(fmu_dir, tmp_path, capsys):
    """examples/model_exchange_bounce.py with another ball and plate: the e of every contact is the package's
    for that case (and not the default case's), and the printed table shows it."""
    native = fmu_dir if fmu_dir.name in ("fmi2", "fmi3") else fmu_dir / "fmi2"  # the example's choice
    if not (native / "BouncingBall.fmu").is_file():
        pytest.skip("no native FMUs with model exchange built here (needs gcc)")
    result = _load("model_exchange_bounce").main(["--fmu-dir", str(fmu_dir), *CHROME_ON_BRASS, "--t", "2 mm",
                                                  "--out-dir", str(tmp_path)])
    out = capsys.readouterr().out
    me = result["me"]
    assert me.n_impacts > 3
    sphere, plate = r.Sphere(r.MATERIALS["chrome_steel"], 4.76e-3), r.Plate(r.MATERIALS["brass_260"], 2e-3)
    for k in range(3):
        ref = r.impact_between(sphere, plate, v=me.v_approach[k])
        assert me.e[k] == pytest.approx(ref.e, abs=1e-9)
        (row,) = [line for line in out.splitlines() if line.startswith(f"| {k + 1} |")]
        assert f" {ref.e:.6f} | {ref.e:.6f} |" in row  # model exchange and the co-simulation reference
    default = r.impact_between(r.Sphere(r.MATERIALS["s2_tool_steel"], 6.35e-3), r.Plate(r.MATERIALS["al_6061"], 6.35e-3),
                               v=me.v_approach[0])
    assert abs(default.e - me.e[0]) > 0.05


# --- 2. two FMUs under three masters ---------------------------------------------------------
STEPS = (1e-2, 1e-3)


@pytest.fixture(scope="module")
def cosim(fmu_dir, tmp_path_factory):
    return _load("two_fmu_cosim").run(show_plot=False, steps=STEPS, fmu_dir=fmu_dir,
                                      out_dir=tmp_path_factory.mktemp("cosim"), verbose=False)


def _row(cosim, master, step):
    (row,) = [w for w in cosim["rows"] if w["master"] == master and w["step"] == step]
    return row


def test_fixed_step_master_delays_the_rebound_by_less_than_a_step_per_bounce(cosim):
    for h in STEPS:
        w = _row(cosim, "fmpy fixed step", h)
        assert w["bounces"] == 5
        assert w["apex_rel_max"] < 1e-12 and w["de_max"] < 1e-12  # the COR is the exact one
        assert 0.5 * h < w["dt_max"] < 4 * h  # four waits, each shorter than one step
    assert _row(cosim, "fmpy fixed step", 1e-3)["dt_max"] < _row(cosim, "fmpy fixed step", 1e-2)["dt_max"] / 5


def test_immediate_rebound_has_the_right_time_base_but_a_stale_cor(cosim):
    coarse, fine = _row(cosim, "fmpy fixed step, immediate", 1e-2), _row(cosim, "fmpy fixed step, immediate", 1e-3)
    assert 1e-3 < coarse["apex_rel_max"] < 0.3 and fine["apex_rel_max"] < coarse["apex_rel_max"] / 5
    assert 0 < fine["de_max"] < coarse["de_max"] < 0.05


def test_libcosim_lags_one_communication_step(cosim, fmu_dir):
    if not any(w["master"] == "libcosim fixedStep" for w in cosim["rows"]):  # left out by the example: only there
        assert fmu_dir.name == "fmi3"
        pytest.skip("libcosim (libcosimpy 0.0.6) refuses FMI 3.0 FMUs: the example leaves that master out")
    exact = cosim["exact"]
    for h in STEPS:
        w = _row(cosim, "libcosim fixedStep", h)
        assert w["bounces"] == 5
        assert w["apex_rel_max"] > 1e-5 and w["dt_max"] < 5 * h
        # the first rebound uses the COR for the speed at the last communication point before the contact
        res = cosim["results"][("libcosim fixedStep", h)]
        e_applied = res["ball.e_applied"][np.flatnonzero(res["ball.t_rebound"] > 0)[0]]
        t_before = math.floor(exact.time[0] / h) * h
        sphere = r.Sphere(r.MATERIALS["s2_tool_steel"], 6.35e-3)
        ref = r.impact_between(sphere, r.Plate(r.MATERIALS["al_6061"], 6.35e-3), v=G * t_before)
        assert e_applied == pytest.approx(ref.e, abs=1e-9)
        structure = ET.parse(Path(res.extra["structure"])).getroot()
        ns = {"osp": "http://opensimulationplatform.com/MSMI/OSPSystemStructure"}
        assert float(structure.find("osp:BaseStepSize", ns).text) == h
        assert len(structure.findall("osp:Connections/osp:VariableConnection", ns)) == 2


def test_state_restore_master_matches_the_event_exact_master(cosim):
    for h in STEPS:
        w = _row(cosim, "fmpy state restore", h)
        assert w["bounces"] == 5
        assert w["dt_max"] < 1e-12 and w["apex_rel_max"] < 1e-12
        assert w["rollbacks"] == cosim["exact"].n_impacts  # one restore per impact, all inside a step
    assert cosim["png"].stat().st_size > 10_000


def test_state_restore_of_the_ball_alone_is_enough(cosim, fmu_dir):
    """The impact FMU is stateless: saving only the ball's state gives the same exact bounces."""
    from restitution.cosim import FixedStepMaster, FmuInstance, ball_bounces
    from restitution.cosim.fixed_step import BALL_RECORD

    with FmuInstance(fmu_dir / "SpherePlateImpact.fmu", "impact") as impact, \
            FmuInstance(fmu_dir / "BouncingBall.fmu", "ball", parameters={"h0": 0.3}) as ball:
        master = FixedStepMaster({"ball": ball, "impact": impact})
        res = master.run(1e-2, 1.0, record=BALL_RECORD, event=("ball.impacts", "ball.t_impact"), stateful=["ball"])
    b, exact = ball_bounces(res, G), cosim["exact"]
    assert res.rollbacks == exact.n_impacts
    assert np.allclose(b["t_impact"], exact.time, rtol=0, atol=1e-12)
    assert np.allclose(b["v_rebound"][:-1], exact.v_rebound[:-1], rtol=1e-12, atol=0)  # the last one: at rest


# --- 3. the paper's figures through the FMU ------------------------------------------------
@pytest.fixture(scope="module")
def figures(fmu_dir, tmp_path_factory):
    return _load("paper_figures").run(show_plot=False, fmu_path=fmu_dir / "SpherePlateImpact.fmu", n_points=81,
                                      out_dir=tmp_path_factory.mktemp("figs"), verbose=False)


def _at(x, grid, values):
    return float(np.interp(x, grid, values))


def test_fig4_curves_rise_with_t_over_d_toward_jgm(figures):
    for key, f in figures["fig4"].items():
        small, large = (f["curves"][d] for d in (4.76e-3, 6.35e-3))
        assert np.allclose(small["e"], large["e"], rtol=0, atol=1e-12)  # only t/d matters
        e, e_ep, td = large["e"], large["e_ep"], f["t_over_d"]
        assert np.all(np.diff(e) >= -1e-12), key
        assert np.all(e <= e_ep + 1e-15)
        assert 0 <= e_ep[-1] - e[-1] < 0.03, key  # at t/d = 3 within 0.03 of the JGM value
        for d, m in f["markers"].items():  # the experiments' plates lie on the same curve
            assert np.allclose(m["e"], np.interp(m["t_over_d"], td, e), atol=3e-3)
    sphere = r.Sphere(r.MATERIALS["tungsten_carbide"], 4.76e-3)
    m = figures["fig4"]["tungsten_carbide"]["markers"][4.76e-3]
    ref = r.impact_between(sphere, r.Plate(r.MATERIALS["al_6061"], np.array(m["t_over_d"]) * 4.76e-3), v=2.3)
    assert np.allclose(m["e"], ref.e, rtol=0, atol=1e-12)  # the FMU computes what the package does


def test_fig6_zener_statements_and_higher_speed_below(figures):
    f6 = figures["fig6"]
    for key, f in f6.items():
        td, slow, fast = f["t_over_d"], f[2.3], f[6.9]
        e_ze1, e_ze2 = _at(1.0, td, slow["e_ze"]), _at(2.0, td, slow["e_ze"])
        assert e_ze1 >= 0.75, key  # "about 0.8 or above" at t/d = 1
        assert e_ze2 >= 0.93, key  # "e_ze -> 1" at t/d = 2
        e_jgm, e_thin, e2 = slow["e_ep"][0], _at(0.25, td, slow["e"]), _at(2.0, td, slow["e"])
        assert (e2 - e_thin) / (e_jgm - e_thin) >= 0.9, key  # asymptotic approach nearly complete at t/d = 2
        assert np.all(fast["e"] < slow["e"]), key  # 6.9 m/s curves lie below the 2.3 m/s ones
        assert fast["e_ep"][0] < slow["e_ep"][0] and np.all(fast["e_ze"] <= slow["e_ze"])
        assert np.all(np.diff(fast["e"]) >= -1e-12)
    assert np.mean([_at(1.0, f["t_over_d"], f[2.3]["e_ze"]) for f in f6.values()]) >= 0.8
    assert list(f6) == ["tungsten_carbide", "s2_tool_steel", "borosilicate_glass"]


def test_fig5_cases_b_reach_the_asymptote_sooner(figures):
    f5 = figures["fig5"]
    for case, f in f5.items():
        assert np.all(np.diff(f["e"]) >= -1e-12), case
        assert np.all(f["e"] <= f["e_jgm"] + 1e-15)
    a = [f5[c]["asymptote_t_over_d"] for c in ("A1", "A2", "A3", "A4")]
    b = [f5[c]["asymptote_t_over_d"] for c in ("B1", "B2", "B3", "B4")]
    assert max(b) < 1.0 < 3.0 < min(a), (a, b)
    # hard plates (Sy >= 1000 MPa) do not yield at 5 m/s: e_ep = 1, e = e_ze
    for case in ("A3", "A4", "B3", "B4"):
        assert f5[case]["e_jgm"] == 1.0 and np.allclose(f5[case]["e"], f5[case]["e_ze"], atol=1e-15)
    assert f5["A1"]["e"][0] < -0.4  # the thin-plate outlier: strongly negative e


def test_fig7_velocity_dependence(figures):
    f = figures["fig7"]
    assert f["V_c"] == pytest.approx(0.0265, abs=5e-5) and f["V_star_ref"] == pytest.approx(86.9, abs=0.05)
    assert np.allclose(f["V_star_fmu"], f["V_star"], rtol=1e-9)
    assert f["V_star"][0] == pytest.approx(8.69, rel=1e-3) and f["V_star"][-1] == pytest.approx(869, rel=1e-3)
    for key in ("e_ze", "e_ep", "e"):
        assert np.all(np.diff(f[key]) < 0), key
    drop_ze, drop_ep = f["e_ze"][0] - f["e_ze"][-1], f["e_ep"][0] - f["e_ep"][-1]
    assert drop_ep > 2 * drop_ze > 0  # Eq. (13) moderate, Eq. (8) steeper
    assert np.all(f["e"] <= np.minimum(f["e_ze"], f["e_ep"]))
    s2 = figures["fig4"]["s2_tool_steel"]["markers"][6.35e-3]  # Fig. 4's point at t = d = 6.35 mm
    assert s2["t_over_d"][3] == 1.0 and float(f["ref"]["e"]) == pytest.approx(s2["e"][3], abs=1e-12)
    above, below = f["V_star"] > f["V_star_ref"] * (1 + 1e-9), f["V_star"] < f["V_star_ref"] * (1 - 1e-9)
    assert np.all(f["e"][above] < f["ref"]["e"]) and np.all(f["e"][below] > f["ref"]["e"])
    assert all(p.stat().st_size > 10_000 for p in figures["png"].values())



def _readme_blocks() -> list[tuple[str, str]]:
    """README's fenced blocks, in order: (language, text)."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    return [(m.group(1), m.group(2)) for m in re.finditer(r"(?ms)^```(\w*)\n(.*?)^```", text)]


@pytest.mark.parametrize("implementation", ["python", "fmi2"])
def test_readme_python_blocks_run_as_printed(built_fmus, implementation, capsys):
    """Every Python block of README runs against a built FMU (its dist/ path replaced), and where a
    text block follows it, prints exactly that. The fmpy example chooses the materials by name: the
    plate is brass, so the modulus used is brass's 103 GPa (Table 3) and e is the package's for
    chrome steel on brass (the native C physics agrees with the package to far better than 1e-9 on
    so well-conditioned a case)."""
    fmu = built_fmus / ("SpherePlateImpact.fmu" if implementation == "python" else "fmi2/SpherePlateImpact.fmu")
    if not fmu.is_file():
        pytest.skip(f"{fmu} not built here")
    blocks = _readme_blocks()
    ran = 0
    for k, (language, code) in enumerate(blocks):
        if language != "python":
            continue
        scope = {}
        capsys.readouterr()
        fmi3 = built_fmus / "fmi3" / "SpherePlateImpact.fmu"
        if '"dist/fmi3/SpherePlateImpact.fmu"' in code and not fmi3.is_file():
            continue  # the FMI 3.0 example needs the native FMI 3.0 FMU (gcc)
        code = code.replace('"dist/fmi3/SpherePlateImpact.fmu"', repr(str(fmi3)))
        exec(compile(code.replace('"dist/SpherePlateImpact.fmu"', repr(str(fmu))), f"README.md block {k}", "exec"),
             scope)
        printed = capsys.readouterr().out
        if k + 1 < len(blocks) and blocks[k + 1][0] == "text":
            assert printed == blocks[k + 1][1], f"README block {k} prints:\n{printed}"
        expected = r.impact_between(r.Sphere(r.MATERIALS["chrome_steel"], 4.76e-3),
                                    r.Plate(r.MATERIALS["brass_260"], 3.18e-3), 2.3)
        if "plate_E" in scope:  # the FMI 2.0 fmpy example
            assert scope["plate_E"] == 103e9
            assert scope["e"] == pytest.approx(expected.e, rel=1e-9)
            assert scope["v_rebound"] == pytest.approx(expected.v_rebound, rel=1e-9)
        if "e3" in scope:  # the FMI 3.0 fmpy example: the native C physics, the same case
            assert scope["e3"] == pytest.approx(expected.e, rel=1e-9)
            assert scope["v_rebound3"] == pytest.approx(expected.v_rebound, rel=1e-9)
        ran += 1
    assert ran >= 3


def test_readme_is_a_users_page():
    """README stays a user's page: at most 200 lines, the two Quickstart commands, an FMI 2.0 and an FMI 3.0
    fmpy example, and every docs/ page it links to exists."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    assert len(text.splitlines()) <= 200
    assert "bash build_scripts/quickstart.sh demo" in text and "bash build_scripts/quickstart.sh test" in text
    python = [code for language, code in _readme_blocks() if language == "python"]
    assert any("FMU2Slave" in code for code in python) and any("FMU3Slave" in code for code in python)
    for link in re.findall(r"\]\((docs/[^)#]+)", text):
        assert (ROOT / link).is_file(), link


def test_quickstart_takes_the_users_case(impact_fmu, capsys):
    """--sphere/--d/--plate/--t choose the case (units as restitution cor reads them): the header names the
    materials and sizes, and the first bounce's e is the package's for that ball and plate at its speed."""
    bounces = _load("quickstart_bounce").main(["--fmu", str(impact_fmu), "--sphere", "chrome_steel", "--d", "4.76 mm",
                                               "--plate", "brass_260", "--t", "3 mm", "--height", "0.2"])
    out = capsys.readouterr().out
    names = r.MATERIALS["chrome_steel"].name, r.MATERIALS["brass_260"].name
    assert out.startswith(f"{names[0]} ball (d = 4.76 mm) dropped from 0.2 m on {names[1]}, t = 3.00 mm"), out
    want = r.impact(bounces.v_approach[0], **r.MATERIALS["chrome_steel"].params("sphere"),
                    **r.MATERIALS["brass_260"].params("plate"), sphere_d=4.76e-3, plate_t=3e-3)
    first = out.splitlines()[2].split()
    assert first[0] == "1" and float(first[3]) == pytest.approx(float(want.e), abs=6e-5), (first, want.e)
    default = r.impact(bounces.v_approach[0], **r.MATERIALS["s2_tool_steel"].params("sphere"),
                       **r.MATERIALS["al_6061"].params("plate"), sphere_d=6.35e-3, plate_t=6.35e-3)
    assert abs(float(want.e) - float(default.e)) > 0.01  # another case than the default's


def test_quickstart_refuses_a_bad_case_in_one_line(capsys):
    with pytest.raises(SystemExit) as stop:
        _load("quickstart_bounce").main(["--fmu", "x.fmu", "--plate", "al_6016", "--t", "3 mm"])
    err = capsys.readouterr().err
    assert stop.value.code == 2 and err.startswith("quickstart_bounce.py: error: --plate 'al_6016': unknown material")


def test_the_demo_reuses_up_to_date_fmus_and_rebuilds_stale_ones(built_fmus, tmp_path, monkeypatch, capsys):
    """The Quickstart demo runs the example without --fmu: a full set of FMUs built from the current
    sources is used as it is (no build), a stale SpherePlateImpact.fmu (another recorded source hash) is
    rebuilt, and that one alone: the demo never builds the other FMUs nor another platform."""
    import shutil

    from restitution.fmu.builders import plan, products as fmu_build

    script = (ROOT / "build_scripts" / "quickstart.sh").read_text()
    demo = script[script.index("demo)"):script.index(";;", script.index("demo)"))]
    assert "restitution.fmu build" not in demo and "examples/quickstart_bounce.py" in demo
    dist = tmp_path / "dist"
    shutil.copytree(built_fmus, dist)
    builds = []
    monkeypatch.setattr(fmu_build, "default_fmu_dir", lambda: dist)
    monkeypatch.setattr(fmu_build, "run", lambda todo, out, **kw: builds.append((todo, out)) or [])
    bounces = _load("quickstart_bounce").run()
    assert builds == [] and bounces.n_impacts > 3
    assert f"FMU: {dist / 'SpherePlateImpact.fmu'}" in capsys.readouterr().out
    monkeypatch.setattr(plan, "source_hash", lambda model: "another")
    _load("quickstart_bounce").run()
    assert builds == [(plan.model_plan("SpherePlateImpact"), dist)]
