"""benchmarks/bench_impact.py --quick runs in a process of its own and prints both sides of the
measurement and their ratio beside the goal; its numpy expression computes what impact() computes (the
benchmark stops otherwise). No timing is asserted (machines are noisy): the ratio is the benchmark's to print."""
import re

import numpy as np
from bench_script import run_benchmark

NUMBER = r"[0-9.]+(?:e[+-]?\d+)?"


def test_quick_run_prints_both_sides_and_the_ratio(tmp_path):
    proc = run_benchmark("bench_impact.py", "--quick", cwd=tmp_path, timeout=300)
    assert proc.returncode == 0, proc.stderr[-3000:]
    out = proc.stdout
    assert re.search(r"^bench_impact\.py on \d{4}-\d\d-\d\d .*\d+ cores", out, re.M), out
    match = re.search(rf"^impact / numpy expression, 1e\+04 cases: impact ({NUMBER}) s, numpy ({NUMBER}) s: "
                      rf"({NUMBER})x \(goal <= 2x: (met|NOT met)\)", out, re.M)
    assert match, out
    impact_s, numpy_s, ratio = (float(g) for g in match.groups()[:3])
    assert impact_s > 0 and numpy_s > 0 and ratio > 0


def test_the_numpy_expression_is_the_model_on_its_outputs():
    """The expression timed against impact() gives impact()'s e, e_ep, e_ze and v_rebound (within the
    rounding of two evaluations of the same equations and, for e, e_ep and v_rebound, the 1e-6 of the
    auto skip of small plastic losses, which the expression does not make), over the benchmark's own cases;
    a wrong expression is caught."""
    import bench_impact
    import restitution

    v, t = bench_impact.cases(5000)
    params = bench_impact.parameters()
    got = bench_impact.numpy_expression(v, t, bench_impact.scalar_terms(params), bench_impact.hermite_cells())
    ref = restitution.impact(v, **params, plate_t=t)
    for name, value in zip(("e", "e_ep", "e_ze", "v_rebound"), got):
        atol = 1e-6 * (v if name == "v_rebound" else 1.0) if name != "e_ze" else 0.0
        assert np.all(np.abs(value - getattr(ref, name)) <= 1e-12 * np.abs(getattr(ref, name)) + atol), name
    assert bench_impact.disagreement(got, ref, v) == {}
    assert set(bench_impact.disagreement((got[0] * 1.001,) + got[1:], ref, v)) == {"e"}
    assert np.any(ref.e_ep < 1.0) and np.any(ref.e_ep == 1.0)  # both branches of Eq. (8) are timed
