"""BouncingBall.fmu on its own (fmpy), every implementation (pythonfmu behind the C guard, native FMI 2.0
and native FMI 3.0; the modelDescription test: the two FMI 2.0 ones, tests/fmu/test_fmi3_model_description.py
has FMI 3.0's): interface, exact free flight, contact inside the step, state save/restore and bad input."""
import math
import zipfile
from xml.etree import ElementTree as ET

import pytest
from fmpy.validation import validate_fmu

from restitution.cosim import FmiStatusError, FmuInstance

G = 9.80665


@pytest.fixture(scope="module")
def ball_fmu(any_version_ball_fmu):
    return any_version_ball_fmu


def test_interface(any_ball_fmu):
    assert validate_fmu(str(any_ball_fmu)) == []
    with zipfile.ZipFile(any_ball_fmu) as z:
        root = ET.fromstring(z.read("modelDescription.xml"))
    assert root.find("CoSimulation").get("canGetAndSetFMUstate") == "true"
    found = {sv.get("name"): (sv.get("causality"), sv[0].get("unit")) for sv in root.find("ModelVariables")}
    assert found["g"] == ("parameter", "m/s2") and found["h0"] == ("parameter", "m")
    assert found["e"] == ("input", "1") and found["v_approach"] == ("output", "m/s")
    assert found["t_impact"] == ("output", "s") and found["impacts"][0] == "output"
    # no direct feedthrough: the COR input acts only inside fmi2DoStep
    assert all(u.get("dependencies") == "" for u in root.find("ModelStructure/Outputs"))


@pytest.mark.parametrize("step", [0.1, 0.013, 1e-3])
def test_elastic_bounces_are_exact_for_any_step(ball_fmu, step):
    h0 = 0.5
    t1 = math.sqrt(2 * h0 / G)
    with FmuInstance(ball_fmu, "ball", parameters={"h0": h0, "contact_mode": 2}) as ball:
        ball.set(e=1.0)
        impacts = []
        t, n = 0.0, int(round(2.0 / step))
        for k in range(n):
            ball.do_step(k * step, step)
            count, t_imp = ball.get("impacts", "t_impact")
            if count > len(impacts):
                impacts.append(t_imp)
        expected = [t1 * (2 * i + 1) for i in range(len(impacts))]
        assert len(impacts) == int((n * step - t1) // (2 * t1)) + 1
        assert impacts == pytest.approx(expected, rel=0, abs=1e-12)
        h, v = ball.get("h", "v")
        tn = n * step
        phase = (tn - t1) % (2 * t1) - t1  # time since the last apex-to-apex midpoint
        assert h == pytest.approx(h0 - 0.5 * G * phase * phase, abs=1e-9)


def test_wait_mode_step_to_the_reported_contact_time(ball_fmu):
    t1 = math.sqrt(2 * 0.3 / G)
    with FmuInstance(ball_fmu, "ball", parameters={"h0": 0.3}) as ball:
        state = ball.get_state()
        ball.do_step(0.0, 0.3)
        count, t_imp, in_contact, v_app = ball.get("impacts", "t_impact", "in_contact", "v_approach")
        assert count == 1 and in_contact and t_imp == pytest.approx(t1, abs=1e-15)
        assert v_app == pytest.approx(G * t1, rel=1e-12)  # waits at the plate with its impact speed
        ball.set_state(state)
        ball.free_state(state)
        assert ball.get("impacts", "h") == [0, pytest.approx(0.3)]
        ball.do_step(0.0, t_imp)  # exactly to the contact: it is seen within this step
        assert ball.get("impacts", "in_contact", "h") == [1, True, 0.0]
        ball.set(e=0.5)
        ball.do_step(t_imp, 0.01)  # rebounds at the start of the step with the COR then on the input
        t_reb, v_reb, e_applied = ball.get("t_rebound", "v_rebound", "e_applied")
        assert t_reb == t_imp and v_reb == pytest.approx(0.5 * G * t1, rel=1e-12) and e_applied == 0.5


def test_rest_and_bad_input(ball_fmu):
    with FmuInstance(ball_fmu, "ball", parameters={"h0": 0.01, "v_min": 0.5}) as ball:
        ball.set(e=0.5)  # 0.5 * 0.443 m/s < v_min
        ball.do_step(0.0, 0.1)
        ball.do_step(0.1, 0.1)
        assert ball.get("at_rest", "h", "v_approach", "v_rebound") == [True, 0.0, 0.0, 0.0]
        with pytest.raises(FmiStatusError, match="e = nan is outside the allowed range: -1 <= e <= 1"):
            ball.set(e=math.nan)
        assert ball.get("e") == [0.5]  # refused: the previous value stays
        with pytest.raises(FmiStatusError, match="h0 is a fixed parameter and cannot be set in step mode"):
            ball.set(h0=1.0)
        ball.do_step(0.2, 0.1)
        ball.set(e=0.9)
        ball.do_step(0.3, 0.1)
        ball.reset()  # back to the start values (h0 = 0.3 m), released again from rest
        assert ball.get("h", "impacts", "at_rest", "t_impact") == [0.3, 0, False, -1.0]
