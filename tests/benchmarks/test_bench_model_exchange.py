"""The model-exchange benchmark runs and reports every operation for both FMI versions (a short run: the
numbers are the benchmark's job, checked here only to be positive and finite)."""
import math

import pytest

from bench_model_exchange import OPERATIONS, VERSIONS, measure, page


def test_model_exchange_costs_are_measured_for_both_versions(built_fmus, tmp_path):
    if not all((built_fmus / folder / "BouncingBall.fmu").is_file() for folder, _p, _n in VERSIONS.values()):
        pytest.skip("native FMUs not built here (needs gcc)")
    results = measure(built_fmus, tmp_path, seconds=0.002)
    for version in VERSIONS:
        assert all(math.isfinite(results[version][op]) and results[version][op] > 0 for op in OPERATIONS), results
    text = page(results, 0.002)
    assert "FMI 3.0 / FMI 2.0" in text and "one contact event" in text
