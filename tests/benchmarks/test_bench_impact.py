"""benchmarks/bench_impact.py --quick runs in a process of its own and prints the three sides of the
measurement and their ratios to the numpy floor beside the goals; the floor (numpy_floor.py) computes what impact()
computes under the same equations (the benchmark stops otherwise). No timing is asserted (machines are noisy)."""
import re

import numpy as np
from bench_script import NUMBER, run_benchmark



def test_quick_run_prints_the_sides_and_the_ratios(tmp_path):
    proc = run_benchmark("bench_impact.py", "--quick", cwd=tmp_path, timeout=300)
    assert proc.returncode == 0, proc.stderr[-3000:]
    out = proc.stdout
    assert re.search(r"^bench_impact\.py on \d{4}-\d\d-\d\d .*\d+ cores", out, re.M), out
    assert re.search(rf"^1e\+04 cases: impact {NUMBER} s, impact e, v_rebound {NUMBER} s, numpy floor {NUMBER} s "
                     rf"\(load average {NUMBER}\)$", out, re.M), out
    for side, goal in (("impact", "2"), ("impact e, v_rebound", "1.2")):
        match = re.search(rf"^{side} / numpy floor, 1e\+04 cases: ({NUMBER})x \(goal <= {goal}x: (met|NOT met)\)$",
                          out, re.M)
        assert match and float(match.group(1)) > 0, out
    assert re.search(rf"^result arrays alone / numpy floor, 1e\+04 cases: {NUMBER}x \(no goal: ", out, re.M), out


def test_the_result_arrays_alone_are_as_many_and_of_the_kinds_impact_returns():
    """The side without physics makes one fresh array per field of the default ImpactResult, of its kind
    (float for the reals, bool for the flags), counted from the result impact() returns."""
    import bench_impact
    import restitution

    v, params = bench_impact.cases(100), bench_impact.parameters()
    fields = vars(restitution.impact(v, **params))
    arrays = bench_impact.result_arrays_alone(v)
    assert len(arrays) == len(fields)
    assert sorted(a.dtype.kind for a in arrays) == sorted(np.asarray(x).dtype.kind for x in fields.values())
    assert all(a.shape == v.shape and a.flags.owndata for a in arrays)


def test_the_numpy_floor_is_the_model_on_e_and_v_rebound():
    """The floor gives impact()'s e and v_rebound under the same equations (Zener's paper fit, both effects
    on) within rounding, over the benchmark's own cases; its critical velocity is the paper's (section 7,
    S2 tool steel on Al 6061: V_c = 0.0265 m/s, printed to 3 digits); a wrong floor is caught."""
    import bench_impact
    import numpy_floor
    import restitution

    v, params = bench_impact.cases(5000), bench_impact.parameters()
    assert bench_impact.disagreement(v, params) == 0.0
    assert abs(numpy_floor.floor_terms(params)[0] - 0.0265) <= 0.00005
    wrong = dict(params, plate_t=2 * params["plate_t"])  # lambda of another plate
    got, _ = numpy_floor.e_and_rebound(v, numpy_floor.floor_terms(wrong))
    ref = restitution.impact(v, **params, zener_method="paper_fit", plasticity="on", plate_waves="on")
    assert np.max(np.abs(got - ref.e)) > 1e-3
