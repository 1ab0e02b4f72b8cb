"""The SSP archives of restitution.fmu.ssp (what `restitution fmu build` writes to dist/ssp/), built here
from this platform's native FMUs (gcc):

1. Packaging and schemas: SystemStructure.ssd at the root, every referenced entry present; the SSP 1.0
   SSD and each SSV valid against the official SSP 1.0 schemas (fmpy's copy, through lxml and through
   fmpy's own read_ssd/read_ssv); the checks do flag a broken archive. SSP 2.0: no schema is installable
   from PyPI, so its archive gets the packaging rules and its SSP 2.0 types are checked by name.
2. Parameter sets: materials set by enumeration item name, items of the FMU's own enumeration; the custom
   set gives every property with the unit the FMU declares; the archive's bytes repeat.
3. Importers:
   - restitution.cosim.ssp (fmpy, a master applying the bindings), SSP 1.0 and 2.0, on a Table 1 case by
     item name (not the FMUs' defaults, so the enumeration binding must be applied): the first contact at
     the closed-form free-fall time; each later contact late by at most the waits at the plate before it
     (contact_mode wait: at most one step each), and every COR applied equal to the package's at the
     contact's own impact speed (the ball holds its impact speed while it waits, so no lag). The default
     binding (Real only), custom.ssv and the preset pair by name give the same bounces.
   - libcosim (libcosimpy) and ecos (ecospy's engine; needs libtbb.so.12: the tbb wheel or libtbb12) run
     the shipped SSP as it is (its default binding needs no ssv:Enumeration, which neither reads): the
     contacts follow the closed-form flights, each COR is the package's at the ball's speed at the last
     communication point before the contact (a fixed-step master without events passes the outputs at
     communication points only), each contact within one step of the fmpy master's. A copy with changed
     values shows which bindings each applies (libcosim: both; ecos: the one set --parameterSet names).
   libcosim runs in a child process (an abort in it would end pytest); ecos is a program.
"""
from __future__ import annotations

import importlib.util
import json
import math
import shutil
import subprocess
import sys
import textwrap
import zipfile
from pathlib import Path
from xml.etree import ElementTree as ET

import numpy as np
import pytest

import restitution as r
from restitution.agreement import tolerances

G = 9.80665  # [m/s2] the ball set's g
H0 = 0.3  # [m] the ball set's drop height
CASE = "table1_case07"  # brass 260, d = 6.35 mm, on S7 tool steel, t = 10 d
CASE_SPHERE, CASE_PLATE = r.Sphere(r.MATERIALS["brass_260"], 6.35e-3), r.Plate(r.MATERIALS["s7_tool_steel"], 63.5e-3)
#: The FMUs' Table 3 default pair, which the shipped SSD binds as numbers (resources/<DEFAULT_SET>.ssv).
DEFAULT_SPHERE = r.Sphere(r.MATERIALS["s2_tool_steel"], 6.35e-3)
DEFAULT_PLATE = r.Plate(r.MATERIALS["al_6061"], 6.35e-3)
STEP = 1e-3  # [s] the SSD's default communication step
N = 4  # contacts compared (the Table 1 case bounces four times within the 1 s default experiment)
SSV = "http://ssp-standard.org/SSP1/SystemStructureParameterValues"
SSC = "http://ssp-standard.org/SSP1/SystemStructureCommon"


@pytest.fixture(scope="module")
def ssps(host_native_fmus):
    """{"1.0": BallOnPlate.ssp, "2.0": BallOnPlate-SSP2.ssp} from this platform's native FMUs."""
    from restitution.fmu.ssp import write_ssps

    written = write_ssps(host_native_fmus)
    out = host_native_fmus
    return {"1.0": out / "ssp" / "BallOnPlate.ssp", "2.0": out / "ssp" / "BallOnPlate-SSP2.ssp", "out": out,
            "written": written}


# --- 1. packaging and schemas ---------------------------------------------------------------------------
def test_both_ssps_are_written_with_the_ssd_at_the_root(ssps):
    from restitution.fmu.ssp.check import packaging_problems

    assert ssps["written"] == [ssps["1.0"], ssps["2.0"]]
    for version in ("1.0", "2.0"):
        with zipfile.ZipFile(ssps[version]) as z:
            names = z.namelist()
            root = ET.fromstring(z.read("SystemStructure.ssd"))
        assert names[0] == "SystemStructure.ssd" and root.get("version") == version
        assert {"resources/BouncingBall.fmu", "resources/SpherePlateImpact.fmu", "resources/custom.ssv",
                "resources/ball.ssv", f"resources/{CASE}.ssv"} <= set(names)
        assert len([n for n in names if n.startswith("resources/table1_case")]) == len(r.TABLE1_CASES)
        assert packaging_problems(ssps[version]) == []


def test_ssp1_validates_against_the_official_schemas(ssps):
    from fmpy.ssp.ssd import read_ssd, read_ssv

    from restitution.fmu.ssp.check import check_ssp, schema_problems

    assert schema_problems(ssps["1.0"]) == []
    assert check_ssp(ssps["1.0"]).startswith("SSP 1.0 schemas and packaging: 0 problems")
    ssd = read_ssd(str(ssps["1.0"]), validate=True)  # fmpy validates the SSD and every bound SSV
    with zipfile.ZipFile(ssps["1.0"]) as z:
        for name in z.namelist():
            if name.endswith(".ssv"):
                read_ssv(str(ssps["1.0"]), resource=name, validate=True)
    connections = {(c.startElement, c.startConnector, c.endElement, c.endConnector) for c in ssd.system.connections}
    assert connections == {("ball", "v_approach", "impact", "v_approach"), ("impact", "e", "ball", "e")}


def _rewrite(src: Path, dst: Path, change) -> Path:
    with zipfile.ZipFile(src) as zin, zipfile.ZipFile(dst, "w") as zout:
        for info in zin.infolist():
            data = change(info.filename, zin.read(info))
            if data is not None:
                zout.writestr(info.filename, data)
    return dst


def test_the_checks_flag_a_broken_archive(ssps, tmp_path):
    from restitution.fmu.ssp.check import check_ssp, packaging_problems, schema_problems

    no_ssd = _rewrite(ssps["1.0"], tmp_path / "no_ssd.ssp", lambda n, d: None if n == "SystemStructure.ssd" else d)
    assert packaging_problems(no_ssd) == ["no SystemStructure.ssd at the archive's root"]
    no_fmu = _rewrite(ssps["1.0"], tmp_path / "no_fmu.ssp", lambda n, d: None if n.endswith("Impact.fmu") else d)
    assert any("resources/SpherePlateImpact.fmu" in p for p in packaging_problems(no_fmu))
    bad_ssv = _rewrite(ssps["1.0"], tmp_path / "bad.ssp",
                       lambda n, d: d.replace(b"<ssv:Real ", b"<ssv:Float64 ") if n == "resources/custom.ssv" else d)
    assert any(p.startswith("resources/custom.ssv") for p in schema_problems(bad_ssv))
    with pytest.raises(ValueError, match="custom.ssv"):
        check_ssp(bad_ssv)


def test_ssp2_uses_the_ssp2_types(ssps):
    """SSP 2.0 (no schema installable here): version 2.0 everywhere, FMI 3.0 FMUs, Float64 values and connectors."""
    from fmpy import read_model_description

    with zipfile.ZipFile(ssps["2.0"]) as z:
        ssd = ET.fromstring(z.read("SystemStructure.ssd"))
        assert {e.tag.split("}")[1] for c in ssd.iter(f"{{{ssd.tag.split('}')[0][1:]}}}Connector") for e in c} == {"Float64"}
        for name in z.namelist():
            if name.endswith(".ssv"):
                pset = ET.fromstring(z.read(name))
                assert pset.get("version") == "2.0"
                kinds = {e.tag.split("}")[1] for p in pset.iter(f"{{{SSV}}}Parameter") for e in p}
                assert kinds <= {"Float64", "Enumeration"}, (name, kinds)
        z.extract("resources/BouncingBall.fmu", ssps["out"] / "x")
    assert read_model_description(str(ssps["out"] / "x" / "resources" / "BouncingBall.fmu")).fmiVersion == "3.0"


# --- 2. parameter sets ----------------------------------------------------------------------------------
def _enumeration_items(fmu_bytes: bytes, tmp: Path, name: str) -> dict:
    from fmpy import read_model_description

    path = tmp / name
    path.write_bytes(fmu_bytes)
    out = {}
    for v in read_model_description(str(path)).modelVariables:
        if v.type == "Enumeration":
            out[v.name] = {item.name: int(item.value) for item in v.declaredType.items}
    return out


@pytest.mark.parametrize("version", ["1.0", "2.0"])
def test_materials_are_set_by_item_name(ssps, version, tmp_path):
    with zipfile.ZipFile(ssps[version]) as z:
        items = _enumeration_items(z.read("resources/SpherePlateImpact.fmu"), tmp_path, "impact.fmu")
        for case, (sphere, _d, plate) in r.TABLE1_CASES.items():
            pset = ET.fromstring(z.read(f"resources/table1_case{case:02d}.ssv"))
            values = {}
            for p in pset.iter(f"{{{SSV}}}Parameter"):
                (typed,) = list(p)
                values[p.get("name")] = (typed.tag.split("}")[1], typed.get("value"))
            for body, key in (("sphere", sphere), ("plate", plate)):
                kind, item = values[f"{body}.material"]
                assert kind == "Enumeration" and item in items[f"{body}.material"]
                assert r.MATERIALS[item] == r.MATERIALS[key]  # the item names the case's material (aliases too)


def test_custom_gives_every_property_with_the_fmus_unit(ssps, tmp_path):
    from fmpy import read_model_description

    with zipfile.ZipFile(ssps["1.0"]) as z:
        (tmp_path / "i.fmu").write_bytes(z.read("resources/SpherePlateImpact.fmu"))
        pset = ET.fromstring(z.read("resources/custom.ssv"))
    units = {v.name: v.unit or (v.declaredType.unit if v.declaredType is not None else None)
             for v in read_model_description(str(tmp_path / "i.fmu")).modelVariables}
    declared = {u.get("name") for u in pset.iter(f"{{{SSC}}}Unit")}
    reals = {p.get("name"): list(p)[0] for p in pset.iter(f"{{{SSV}}}Parameter") if list(p)[0].tag.endswith("Real")}
    wanted = {f"{b}.{q}" for b in ("sphere", "plate") for q in ("E", "nu", "Sy", "rho")} | {"sphere.d", "plate.t"}
    assert set(reals) == wanted
    for name, element in reals.items():
        assert element.get("unit") == units[name] and element.get("unit") in declared, name
    assert float(reals["plate.Sy"].get("value")) == r.MATERIALS["al_6061"].Sy


def test_the_archive_repeats_byte_for_byte(ssps, tmp_path):
    from restitution.fmu.ssp import build_ssp

    again = build_ssp("1.0", ssps["out"] / "fmi2", tmp_path / "again.ssp")
    assert again.read_bytes() == ssps["1.0"].read_bytes()
    with zipfile.ZipFile(again) as z:
        assert {i.date_time for i in z.infolist()} == {(1980, 1, 1, 0, 0, 0)}
        assert {(i.external_attr >> 16) & 0o777 for i in z.infolist()} == {0o644}


# --- 3. importers ---------------------------------------------------------------------------------------
def _package_e(v):
    params = {**CASE_SPHERE.params(), **CASE_PLATE.params()}
    e = float(r.impact(v, **params).e)
    tol, _ = tolerances(np.array([v]), {k: np.array([x]) for k, x in params.items()})
    return e, float(tol["e"][0])


@pytest.fixture(scope="module")
def fmpy_runs(ssps):
    from restitution.cosim import ball_bounces
    from restitution.cosim.ssp import run_ssp

    return {v: ball_bounces(run_ssp(ssps[v], bindings={"impact": f"resources/{CASE}.ssv"}), G) for v in ("1.0", "2.0")}


@pytest.mark.parametrize("version", ["1.0", "2.0"])
def test_fmpy_master_against_the_closed_form(fmpy_runs, version):
    b = fmpy_runs[version]
    assert b["t_impact"].size >= N
    # free fall from rest: t = sqrt(2 h0 / g); the FMU finds it in closed form (1e-12: a few roundings)
    assert b["t_impact"][0] == pytest.approx(math.sqrt(2 * H0 / G), rel=1e-12)
    for k in range(N):
        e, tol = _package_e(b["v_impact"][k])
        assert abs(b["e_applied"][k] - e) <= tol, k  # the COR of this contact's own speed: no lag
        wait = b["t_rebound"][k] - b["t_impact"][k]
        assert 0.0 <= wait <= STEP * (1 + 1e-9), k  # wait mode: rebound at the next communication point
    # each flight after a rebound is the free flight of v_rebound = e v_impact: t_next = t_rebound + 2 v / g
    flights = b["t_rebound"][:N - 1] + 2 * b["v_rebound"][:N - 1] / G
    np.testing.assert_allclose(b["t_impact"][1:N], flights, rtol=1e-12)


def test_fmpy_master_ssp1_and_ssp2_agree(fmpy_runs):
    """The FMI 2.0 and FMI 3.0 FMUs compute the same contacts (4e-16 apart: tests/fmu/test_fmi3.py)."""
    np.testing.assert_allclose(fmpy_runs["1.0"]["t_impact"][:N], fmpy_runs["2.0"]["t_impact"][:N], rtol=1e-12)


def test_default_custom_and_preset_pair_sets_agree(ssps, fmpy_default):
    """The default set writes S2 tool steel on Al 6061 out as numbers (materials left 'custom'), custom.ssv
    names both materials 'custom' with the same numbers, the preset pair names the presets by item
    (ssv:Enumeration): the same bounces, and the default's are the package's at each contact's speed."""
    from restitution.cosim import ball_bounces
    from restitution.cosim.ssp import run_ssp
    from restitution.fmu.ssp import PRESET_PAIR_SET

    for alternative in ("custom", PRESET_PAIR_SET):
        run = ball_bounces(run_ssp(ssps["1.0"], bindings={"impact": f"resources/{alternative}.ssv"}), G)
        # same FMU, same values reaching the same code: a few roundings of the presets' numbers at most
        np.testing.assert_allclose(run["e_applied"][:N], fmpy_default["e_applied"][:N], rtol=1e-14)
    params = {**DEFAULT_SPHERE.params(), **DEFAULT_PLATE.params()}
    for k in range(N):
        v = fmpy_default["v_impact"][k]
        tol = float(tolerances(np.array([v]), {n: np.array([x]) for n, x in params.items()})[0]["e"][0])
        assert abs(fmpy_default["e_applied"][k] - float(r.impact(v, **params).e)) <= tol, k


@pytest.fixture(scope="module")
def fmpy_default(ssps):
    """The shipped BallOnPlate.ssp (SSP 1.0) as it is, its default binding, through restitution.cosim.ssp."""
    from restitution.cosim import ball_bounces
    from restitution.cosim.ssp import run_ssp

    return ball_bounces(run_ssp(ssps["1.0"]), G)


LIBCOSIM_CHILD = textwrap.dedent('''
    import json, sys, zipfile
    from pathlib import Path
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver

    log_output_level(CosimLogLevel.ERROR)
    cfg = json.loads(sys.argv[1])
    folder = Path(cfg["dir"])
    zipfile.ZipFile(cfg["ssp"]).extractall(folder)
    execution = CosimExecution.from_ssp_file(str(folder), int(round(cfg["step"] * 1e9)))
    observer = CosimObserver.create_last_value()
    execution.add_observer(observer)
    plan = []
    for instance, names in cfg["record"].items():
        index = execution.slave_index_from_instance_name(instance)
        refs = {v.name.decode(): v.reference for v in execution.slave_variables(index)}
        plan.append((index, [f"{instance}::{n}" for n in names], [refs[n] for n in names]))
    columns = {key: [] for _index, keys, _refs in plan for key in keys}
    for _ in range(int(round(cfg["stop"] / cfg["step"]))):
        execution.step()
        for index, keys, refs in plan:
            for key, value in zip(keys, observer.last_real_values(index, refs)):
                columns[key].append(value)
    print("RESULT " + json.dumps(columns))
''')
#: What the host runs record, as ecos's CSV names it.
RECORD = {"ball": ["t_impact", "v_impact", "t_rebound", "v_rebound", "e_applied"],
          "impact": ["plate.t", "sphere.used.E", "plate.used.E"]}


def _distinct(column) -> np.ndarray:
    column = np.asarray(column, dtype=float)
    keep = np.flatnonzero(np.diff(column) != 0) + 1
    return column[keep]


def _check_fixed_step_host(column: dict, reference: dict, resolution: float):
    """A run of the shipped SSP (default binding) by a fixed-step master without event handling (libcosim
    0.0.6, ecos 0.7.2) against the closed forms and the package. ``reference``: the fmpy master's bounces
    of the same SSP (tested against the closed form above); ``resolution``: how finely the host wrote its
    values (ecos's CSV: 6 decimals, so 5e-7; libcosim: 0)."""
    assert column["impact::plate.t"][-1] == pytest.approx(6.35e-3, abs=resolution)
    assert column["impact::sphere.used.E"][-1] == pytest.approx(r.MATERIALS["s2_tool_steel"].E, rel=1e-6)
    assert column["impact::plate.used.E"][-1] == pytest.approx(r.MATERIALS["al_6061"].E, rel=1e-6)
    params = {**DEFAULT_SPHERE.params(), **DEFAULT_PLATE.params()}
    t_impact, v_impact, t_rebound, v_rebound, e_applied = (
        _distinct(column[f"ball::{n}"])  # the first sample holds the start values
        for n in ("t_impact", "v_impact", "t_rebound", "v_rebound", "e_applied"))
    assert t_impact.size >= N
    # free fall from rest: closed form (1e-12: a few roundings), or the CSV's 6 decimals
    assert t_impact[0] == pytest.approx(math.sqrt(2 * H0 / G), rel=1e-12, abs=resolution)
    # each flight is the free flight of the rebound: t_next = t_rebound + 2 v_rebound / g
    np.testing.assert_allclose(t_impact[1:N], t_rebound[:N - 1] + 2 * v_rebound[:N - 1] / G, rtol=1e-12,
                               atol=4 * resolution)
    for k in range(N):
        assert 0.0 <= t_rebound[k] - t_impact[k] <= STEP + 2 * resolution, k  # wait mode: <= one step at the plate
        # Both masters step the FMUs side by side and pass the outputs at communication points only: the
        # impact FMU's e comes from the v_approach of the last communication point before the contact,
        # the ball's closed-form speed there, v_impact - g (t_impact - t_c), at most g h below v_impact.
        t_c = math.floor(t_impact[k] / STEP * (1 + 1e-12)) * STEP
        v_c = v_impact[k] - G * (t_impact[k] - t_c)
        e = float(r.impact(v_c, **params).e)
        tol = float(tolerances(np.array([v_c]), {n: np.array([x]) for n, x in params.items()})[0]["e"][0])
        assert abs(e_applied[k] - e) <= tol + 2 * resolution, (k, e_applied[k], e)
    # that lag moves each later contact by far less than a step from the event-exact master's
    # (|de| <= 1e-3 here, so 2 v |de| / g <= 5e-4 s per flight, summed over N flights)
    np.testing.assert_allclose(t_impact[:N], reference["t_impact"][:N], rtol=0, atol=STEP)


def test_libcosim_runs_the_shipped_ssp(ssps, fmpy_default, tmp_path):
    """libcosim applies both bindings of the SSD (ball.ssv and the Real-only default set): shown on a copy
    whose default set says plate.t = 10 d and whose ball set says h0 = 0.2 m."""
    if importlib.util.find_spec("libcosimpy") is None:
        pytest.skip("libcosimpy (OSP libcosim) not installed")

    def run(ssp, folder, record):
        cfg = {"ssp": str(ssp), "dir": str(tmp_path / folder), "step": STEP, "stop": 1.0, "record": record}
        proc = subprocess.run([sys.executable, "-c", LIBCOSIM_CHILD, json.dumps(cfg)], capture_output=True,
                              text=True, timeout=300)
        assert proc.returncode == 0, proc.stderr[-3000:]
        result = next(x for x in proc.stdout.splitlines() if x.startswith("RESULT "))[len("RESULT "):]
        return {k: np.array(v) for k, v in json.loads(result).items()}

    _check_fixed_step_host(run(ssps["1.0"], "as_shipped", RECORD), fmpy_default, resolution=0.0)
    changed = run(_changed_bindings(ssps["1.0"], tmp_path / "changed.ssp"), "changed",
                  {"ball": ["h0"], "impact": ["plate.t"]})
    assert (changed["ball::h0"][-1], changed["impact::plate.t"][-1]) == (0.2, 63.5e-3)


def _changed_bindings(src: Path, dst: Path) -> Path:
    """A copy of the SSP whose default set gives plate.t = 63.5 mm and whose ball set gives h0 = 0.2 m."""
    from restitution.fmu.ssp import DEFAULT_SET

    def change(name, data):
        if name == f"resources/{DEFAULT_SET}.ssv":
            changed = data.replace(b'"plate.t">\n      <ssv:Real value="0.00635"',
                                   b'"plate.t">\n      <ssv:Real value="0.0635"')
        elif name == "resources/ball.ssv":
            changed = data.replace(b'name="h0">\n      <ssv:Real value="0.3"',
                                   b'name="h0">\n      <ssv:Real value="0.2"')
        else:
            return data
        assert changed != data, name
        return changed

    return _rewrite(src, dst, change)


@pytest.fixture(scope="module")
def ecos(tmp_path_factory):
    from ecos_engine import ecos_engine

    return ecos_engine(tmp_path_factory.mktemp("ecos"))


def _ecos_simulate(ecos, ssp: Path, cwd: Path, parameter_set: str) -> dict:
    cwd.mkdir()
    proc = subprocess.run([str(ecos.exe), "simulate", "--path", str(ssp), "--stepSize", repr(STEP), "--stopTime",
                           "1.0", "--parameterSet", parameter_set, "--logLevel", "warn"], cwd=cwd,
                          capture_output=True, text=True, timeout=300, env=ecos.env)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    lines = (cwd / f"{ssp.stem}.csv").read_text().splitlines()
    header = [c.strip().rsplit("[", 1)[0] for c in lines[0].split(",")]
    data = np.array([[float(x) for x in line.split(",")] for line in lines[1:] if line.strip()])
    return {name: data[:, i] for i, name in enumerate(header)}


def test_ecos_runs_the_shipped_ssp(ssps, fmpy_default, ecos, tmp_path):
    """ecos applies only the parameter sets named by --parameterSet (the SSV's name): given the default set's
    name it applies that set and not ball.ssv, whose values are the BouncingBall FMU's own defaults, so the
    shipped SSP runs as bound. Shown on the copy with changed bindings."""
    from restitution.fmu.ssp import DEFAULT_SET

    _check_fixed_step_host(_ecos_simulate(ecos, ssps["1.0"], tmp_path / "as_shipped", DEFAULT_SET), fmpy_default,
                           resolution=5e-7)
    changed = _changed_bindings(ssps["1.0"], tmp_path / "changed.ssp")
    impact_set = _ecos_simulate(ecos, changed, tmp_path / "impact_set", DEFAULT_SET)
    assert (impact_set["ball::h0"][-1], impact_set["impact::plate.t"][-1]) == (0.3, 63.5e-3)
    ball_set = _ecos_simulate(ecos, changed, tmp_path / "ball_set", "ball")
    assert (ball_set["ball::h0"][-1], ball_set["impact::plate.t"][-1]) == (0.2, 6.35e-3)


def test_an_ssp_whose_fmus_are_missing_is_skipped_with_a_line(ssps, tmp_path):
    """A build without FMI 3.0 FMUs (no compiler for them) writes the SSP 1.0 archive only, and says why."""
    from restitution.fmu.ssp import write_ssps

    shutil.copytree(ssps["out"] / "fmi2", tmp_path / "fmi2")
    lines = []
    assert write_ssps(tmp_path, log=lines.append) == [tmp_path / "ssp" / "BallOnPlate.ssp"]
    assert lines == ["warning: BallOnPlate-SSP2.ssp (SSP 2.0) not written: no fmi3/ FMUs"]
