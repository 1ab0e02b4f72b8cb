"""benchmarks/bench_native.py --quick: it builds what it times (the floor FMU and the C hosts among
them), runs, and writes docs/native_cost.md's page with every row. Timing is not asserted (machines
are noisy and shared): the page and the printed headline show the measured ratios against the goals."""
import math
import shutil
import sys

import pytest

pytestmark = [
    pytest.mark.skipif(not sys.platform.startswith("linux"), reason="Linux-only (linux64 binaries, C host)"),
    pytest.mark.skipif(shutil.which("gcc") is None, reason="gcc not available"),
]


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    import bench_native  # benchmarks/ is on sys.path (conftest.py)

    out = tmp_path_factory.mktemp("bench_native")
    return bench_native.run(quick=True, out_dir=out, verbose=False), out


@pytest.mark.slow
def test_quick_run_writes_the_page_with_every_row(quick):
    import bench_native_page as page
    import bench_native_timing as timing

    res, out = quick
    md = (out / "native_cost.md").read_text(encoding="utf-8")
    for heading in ("# What the native FMU costs", "## Headline", "## Through fmpy", "## In a plain C host",
                    "### Each call alone", "## Against the precomputed C floor", "## The C physics against the package",
                    "Machine:",
                    "**A shared machine**", "quick run"):
        assert heading in md, heading
    lines = md.splitlines()

    def row(first_cell):
        found = [line for line in lines if line.startswith(f"| {first_cell}")]
        assert len(found) >= 1, first_cell
        return found

    for text, goal, _ in page.TARGETS.values():  # every headline row, with its goal
        (line,) = row(text)
        assert f"| {goal} |" in line
    for label in page.FMU_ROWS:  # fmpy and C host tables, and native and floor against the precomputed C floor
        assert len(row(f"{label} (")) == 2 + (label in page.IMPACT_ROWS), label
    assert len(row("fmi3 (")) == 2  # the native FMI 3.0 FMU: the C host table and the per-impact table
    assert len(row("precomputed (")) == 1
    assert "the native physics and its glue above the floor FMU" in md  # native / precomputed split in two
    for call in page.CALLS:
        row(f"`{call}`")
    for method in timing.METHODS:
        row(f"{method} |")
    for key in page.TARGETS:  # every headline number measured, finite and positive
        value, (low, high) = res["headline"][key]
        assert all(math.isfinite(x) and x > 0.0 for x in (value, low, high)), key
        assert low <= value <= high, key
    assert not any(cell in md for cell in ("| nan", "| inf", " nan ", " inf "))


@pytest.mark.slow
def test_every_repeat_of_every_variant_was_measured(quick):
    res, _ = quick
    reps = res["config"]["reps"]
    for series in ("fmpy", "c_host", "impact", "calls", "physics"):
        batches = res[series].batches
        assert batches and all(len(v) == reps for v in batches.values()), series
