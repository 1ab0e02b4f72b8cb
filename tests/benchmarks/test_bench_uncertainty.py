"""benchmarks/bench_uncertainty.py --quick runs in a process of its own and prints every line:
both sides of each measurement and their ratio beside the goal, and the two sides of the Monte Carlo
computed the same statistics of e. No timing is asserted (machines are noisy): the ratios are the
benchmark's to print."""
import re
from bench_script import NUMBER, run_benchmark



def test_quick_run_prints_both_sides_and_the_ratio_of_each_measurement(tmp_path):
    proc = run_benchmark("bench_uncertainty.py", "--quick", cwd=tmp_path, timeout=120)
    assert proc.returncode == 0, proc.stderr[-3000:]
    out = proc.stdout
    assert re.search(r"^bench_uncertainty\.py on \d{4}-\d\d-\d\d: .*\d+ cores", out, re.M), out
    expected = [
        rf"^1\(a\) Monte Carlo, .* sweep \+ statistics ({NUMBER}) s, impact \+ numpy statistics ({NUMBER}) s: "
        rf"({NUMBER})x \(goal <= 2x: (met|NOT met)",
        rf"^1\(b\) Monte Carlo, .* sweep command ({NUMBER}) s, plain impact process ({NUMBER}) s: ({NUMBER})x "
        rf"\(no goal: more work",
        rf"^1\(c\) the same with --columns e, .* sweep command ({NUMBER}) s, plain impact process ({NUMBER}) s: "
        rf"({NUMBER})x \(goal <= 2x: (met|NOT met)\)",
        rf"^     wall: sweep command ({NUMBER}) s, plain impact process ({NUMBER}) s: ({NUMBER})x",
        rf"^1\(d\) Monte Carlo of the speed, .*: sweep command ({NUMBER}) s, numpy floor process ({NUMBER}) s: "
        rf"({NUMBER})x \(goal <= 1.5x: (met|NOT met)\); wall ({NUMBER}) s / ({NUMBER}) s = ({NUMBER})x",
        rf"^2\. .*--scheduler serial .*: wall ({NUMBER}) s \(goal <= 5 s: (met|NOT met)\).* model evaluation "
        rf"({NUMBER}) s, analysis ({NUMBER}) s: analysis / evaluation ({NUMBER})x",
        rf"^2\. .*LocalCluster of 2 workers .*: wall ({NUMBER}) s \(goal <= 5 s: (met|NOT met)\).* model evaluation "
        rf"({NUMBER}) s, analysis ({NUMBER}) s: analysis / evaluation ({NUMBER})x",
        rf"^     in process .*: evaluation of the design ({NUMBER}) s, SobolCollector\.analyze\(\) ({NUMBER}) s: "
        rf"analysis / evaluation ({NUMBER})x",
    ]
    for pattern in expected:
        match = re.search(pattern, out, re.M)
        assert match, (pattern, out)
        numbers = [float(g) for g in match.groups() if g not in ("met", "NOT met")]
        assert all(x >= 0 for x in numbers), (pattern, match.group(0))
    # the two sides of the Monte Carlo are the same draws: e's statistics agree to rounding
    for agree in re.findall(rf"agree to ({NUMBER})", out):
        assert float(agree) < 1e-12, out
    assert len(re.findall("agree to", out)) == 2, out
    # against the numpy floor: the same draws, e by the paper's fit of Zener's COR (within 0.0136 of the exact)
    within = re.search(rf"e's mean and percentiles within ({NUMBER}) of the floor's", out)
    assert within and float(within.group(1)) <= 0.0136, out
