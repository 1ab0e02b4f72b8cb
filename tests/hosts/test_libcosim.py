"""SpherePlateImpact.fmu under OSP libcosim (libcosimpy), the Open Simulation Platform's co-simulation
engine, checked against the package.

Two instances with different materials run in one fixed-step execution; instance a's
``v_rebound`` drives instance b's ``v_approach`` through a libcosim connection, an override
manipulator feeds a's ``v_approach``, and a last-value observer reads every output after each
step. libcosim counts time in integer nanoseconds (a float step such as 1e-3 silently becomes 0
and the execution then crashes, docs/fmi_tools.md): every duration here is an int. The execution runs
in a child process so that a crash inside libcosim fails this test instead of killing pytest.
"""
from __future__ import annotations

import json
import math
import subprocess
import sys
import textwrap

import pytest

import restitution as r
from restitution.cosim import impact_fmu_parameters

pytest.importorskip("libcosimpy", reason="libcosimpy (OSP libcosim) not installed")

STEP_NS = 1_000_000  # 1 ms, integer nanoseconds
SPEEDS_A = [0.0, 1e-3, 0.3, 1.0, 2.3, 4.0, 9.5, 30.0]
A = (r.Sphere(r.MATERIALS["s2_tool_steel"], 6.35e-3), r.Plate(r.MATERIALS["al_6061"], 3.175e-3))
B = (r.Sphere(r.MATERIALS["tungsten_carbide"], 4.76e-3), r.Plate(r.MATERIALS["borosilicate_glass"], 1.0e-3))
B_CODES = {"zener_method": 4, "restitution_model": 2}  # ode (scipy) and e44 in instance b
A_START_V = 2.3
OUTPUTS = ["e", "v_rebound", "jgm.e", "jgm.V_c", "jgm.V_star", "zener.e", "zener.lambda", "zener.tau0",
           "zener.t_contact", "plate.mass_ratio", "plate.v_after"]
FIELDS = dict(zip(OUTPUTS, ["e", "v_rebound", "e_ep", "V_c", "V_star", "e_ze", "lam", "tau0", "t_contact", "mass_ratio",
                            "v_plate"]))

SCRIPT = textwrap.dedent('''
    import json, sys
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimSlave import CosimLocalSlave
    from libcosimpy.CosimManipulator import CosimManipulator
    from libcosimpy.CosimObserver import CosimObserver
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy import CosimConstants

    log_output_level(CosimLogLevel.WARNING)
    cfg = json.loads(sys.argv[1])
    step_ns = cfg["step_ns"]
    assert isinstance(step_ns, int) and step_ns > 0  # nanoseconds, never a float
    execution = CosimExecution.from_step_size(step_size=step_ns)
    a = execution.add_local_slave(CosimLocalSlave(fmu_path=cfg["fmu"], instance_name="impact_a"))
    b = execution.add_local_slave(CosimLocalSlave(fmu_path=cfg["fmu"], instance_name="impact_b"))
    vr = {v.name.decode(): v.reference for v in execution.slave_variables(a)}
    for slave, values in ((a, cfg["a"]), (b, cfg["b"])):
        for name, value in values.items():
            if isinstance(value, int):
                assert execution.integer_initial_value(slave, vr[name], value)
            else:
                assert execution.real_initial_value(slave, vr[name], value)
    # returns libcosim's raw status (0 = success), unlike the bool of the calls above
    assert execution.connect_real_variables(a, vr["v_rebound"], b, vr["v_approach"]) == CosimConstants.success
    manipulator = CosimManipulator.create_override()
    observer = CosimObserver.create_last_value()
    assert execution.add_manipulator(manipulator) and execution.add_observer(observer)
    rows = []
    for k, v in enumerate(cfg["speeds"]):
        assert manipulator.slave_real_values(a, [vr["v_approach"]], [v])
        assert execution.step(), "libcosim step failed"
        status = execution.status()
        names = ["v_approach"] + cfg["outputs"]
        rows.append({
            "time_ns": status.current_time,
            "a": dict(zip(names, observer.last_real_values(a, [vr[n] for n in names]))),
            "b": dict(zip(names, observer.last_real_values(b, [vr[n] for n in names]))),
            "a_valid": observer.last_boolean_values(a, [vr["valid"]])[0],
        })
    print("RESULT " + json.dumps(rows))
''')


def _package(pair, v, **options):
    sphere, plate = pair
    return r.impact_between(sphere, plate, v, **{k: r.ZENER_METHODS[val - 1] if k == "zener_method"
                                                 else r.RESTITUTION_MODELS[val - 1] for k, val in options.items()})


def _same(got, want):
    if math.isinf(want):
        return got == want
    return got == want or got == pytest.approx(want, rel=1e-12, abs=0.0)


@pytest.fixture(scope="module")
def rows(impact_fmu):
    cfg = {
        "fmu": str(impact_fmu), "step_ns": STEP_NS, "speeds": SPEEDS_A, "outputs": OUTPUTS,
        "a": {**impact_fmu_parameters(*A), "v_approach": A_START_V},
        "b": {**impact_fmu_parameters(*B), **B_CODES},
    }
    cfg["a"] = {k: float(v) for k, v in cfg["a"].items()}
    cfg["b"] = {k: (v if k in B_CODES else float(v)) for k, v in cfg["b"].items()}
    proc = subprocess.run([sys.executable, "-c", SCRIPT, json.dumps(cfg)], capture_output=True, text=True,
                          timeout=300)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-4000:]
    line = next(line for line in proc.stdout.splitlines() if line.startswith("RESULT "))
    return json.loads(line[len("RESULT "):])


def test_time_advances_in_integer_nanoseconds(rows):
    assert [row["time_ns"] for row in rows] == [STEP_NS * (k + 1) for k in range(len(SPEEDS_A))]


def test_instance_a_matches_the_package(rows):
    for k, row in enumerate(rows):
        assert row["a"]["v_approach"] == SPEEDS_A[k]
        ref = _package(A, SPEEDS_A[k])
        for name in OUTPUTS:
            assert _same(row["a"][name], getattr(ref, FIELDS[name])), (k, name)
        assert row["a_valid"] == ref.valid


def test_connection_feeds_b_and_b_matches_the_package(rows):
    """b's v_approach is a's v_rebound of the previous communication point (libcosim transfers
    connections after each step); b's outputs are the package's for that speed, with the ode method."""
    previous = _package(A, A_START_V).v_rebound  # a's start value, transferred at initialisation
    for k, row in enumerate(rows):
        v_b = row["b"]["v_approach"]
        assert v_b == pytest.approx(previous, rel=1e-15), k
        ref = _package(B, v_b, **B_CODES)
        for name in OUTPUTS:
            assert _same(row["b"][name], getattr(ref, FIELDS[name])), (k, name)
        previous = row["a"]["v_rebound"]
    assert len({row["b"]["e"] for row in rows}) > 5  # b really followed a
