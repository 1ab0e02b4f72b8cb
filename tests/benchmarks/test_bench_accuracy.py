"""benchmarks/bench_accuracy.py --quick: it runs, writes its page and plot, and the accuracy
claims it prints hold. Timing is not asserted (machines are noisy): the benchmark's printed
ratios show the speed goals."""
import math

import numpy as np
import pytest

import bench_accuracy as bench  # benchmarks/ is on sys.path (conftest.py)
from accuracy_bench.reference import lambda_points, reference_solve
from restitution.zener import zener_restitution
from restitution.zener_exact import zener_exact


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    out = tmp_path_factory.mktemp("bench")
    return bench.run(quick=True, out_dir=out, verbose=False), out


@pytest.mark.slow
def test_quick_run_writes_the_page_and_the_plot(quick):
    res, out = quick
    md = (out / "accuracy.md").read_text()
    for heading in ("## Headline", "## Zener's COR e_ze", "## Cost per evaluation", "## e44 against e45",
                    "no ground truth", "## Bouncing ball", "Machine:"):
        assert heading in md, heading
    png = out / "img" / "accuracy_cost.png"
    assert png.stat().st_size > 10_000 and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    h = res["headline"]
    for key in bench.TARGETS:  # every headline number is measured and finite
        assert math.isfinite(h[key]) and h[key] > 0.0, key


@pytest.mark.slow
def test_exact_is_within_1e8_of_the_independent_reference(quick):
    res, _ = quick
    for rng in bench.RANGES:
        for q in ("e", "tau0"):
            assert res["accuracy"][("exact", rng)][q]["max_rel"] <= 1e-8, (rng, q)
    assert res["headline"]["exact_rel_error"] <= 1e-8


@pytest.mark.slow
def test_ode_error_falls_with_its_tolerance(quick):
    res, _ = quick
    rtols = bench.QUICK.ode_rtols
    for rng in bench.RANGES:
        for q in ("e", "tau0"):
            errs = [res["accuracy"][(f"ode rtol {rtol:.0e}", rng)][q]["max_rel"] for rtol in rtols]
            assert all(a > b for a, b in zip(errs, errs[1:])), (rng, q, errs)  # tighter rtol, smaller error
            for rtol, err in zip(rtols, errs):  # and the error follows the tolerance (LSODA: ~10-50 rtol)
                assert err <= 100.0 * rtol + 1e-12, (rng, q, rtol, err)


@pytest.mark.slow
def test_the_fits_are_as_inaccurate_as_documented(quick):
    res, _ = quick
    small = bench.RANGES[0]
    paper = res["accuracy"][("paper_fit", small)]
    assert 0.01 < paper["e"]["max_abs"] < 0.02 and 0.15 < paper["e"]["max_rel"] < 0.3  # docs/paper_departures.md: 0.0136, ~20 %
    assert res["accuracy"][("linear", bench.RANGES[1])]["tau0"]["max_rel"] == math.inf  # no return for lam >= 2


@pytest.mark.slow
def test_bouncing_ball_state_restore_is_exact_and_plain_fixed_step_is_late(quick):
    res, _ = quick
    rows = res["bouncing"]["rows"]
    if not rows:
        pytest.skip("no BouncingBall FMU in this tree")
    for w in rows:
        if "state restore" in w["master"]:
            assert w["dt_max"] < 1e-9 and w["de_max"] < 1e-12
        elif "waits" in w["master"]:
            assert 0.0 < w["dt_max"] and w["de_max"] < 1e-12  # late, with the right COR
    waits = sorted((w["step"], w["dt_max"]) for w in rows if "waits" in w["master"])
    assert waits[0][1] < waits[-1][1]  # a smaller step, a smaller timing error


def test_reference_solver_is_accurate_and_independent_of_the_methods():
    """The reference (Radau) agrees with the closed form at lambda = 0 and with `exact` elsewhere."""
    e0, tau0 = reference_solve(0.0)
    assert e0 == pytest.approx(1.0, rel=1e-12) and tau0 == pytest.approx(3.2180654597190425, rel=1e-12)
    for lam in (0.7, 4.0):
        e, tau = reference_solve(lam)
        ex = zener_exact(lam)
        assert e == pytest.approx(ex[0], rel=1e-8) and tau == pytest.approx(ex[1], rel=1e-8)
        ode = zener_restitution(lam, "ode", 1e-6)  # a loose ode solve is visibly off the reference
        assert abs(ode[0] / e - 1.0) > 1e-10


def test_lambda_points_avoid_the_table_nodes_and_cover_both_ranges():
    pts = lambda_points(bench.QUICK)
    small, large = pts[bench.RANGES[0]], pts[bench.RANGES[1]]
    assert small[0] == 0.0 and small[-1] == 1.5 and np.all((small >= 0.0) & (small <= 1.5))
    assert large[-1] == 100.0 and np.all((large > 1.5) & (large <= 100.0))
    interior = np.concatenate([small[1:-1], large[:-1]])
    assert np.all(np.abs(interior * 128.0 - np.round(interior * 128.0)) > 1e-3)  # off the 1/128 grid
