"""restitution.sweep.arrow_arrays: the sweep's columns as Arrow arrays built from their buffers equal what
pyarrow.array makes of them (pyarrow is the reference), and a sweep that writes Parquet never imports
pandas (the reason the module exists), checked in a child process."""
import subprocess
import sys

import numpy as np
import pyarrow as pa
import pytest

from restitution.sweep import arrow_arrays


@pytest.mark.parametrize("column", [
    np.array([1.5, -0.0, np.nan, np.inf, 2e-308]),
    np.arange(7, dtype=np.int64) - 3,
    np.array([3, -1, 0], dtype=np.int32),
    np.array([True, False, True, True, False, False, True, True, True, False, True, False, True]),  # 13 bits
    np.zeros(0),
    np.zeros(0, dtype=bool),
    np.arange(10.0)[::2],  # not contiguous
])
def test_numbers_equal_pyarrows_own_arrays(column):
    got = arrow_arrays.numbers(column)
    want = pa.array(column)
    assert got.type == want.type and got.null_count == 0 and len(got) == column.size
    # NaN is a value in a sweep, which Arrow's equals() never finds equal: compared as numbers, bit for
    # bit (the same memory: nothing is computed)
    np.testing.assert_array_equal(got.to_numpy(zero_copy_only=False), want.to_numpy(zero_copy_only=False))
    np.testing.assert_array_equal(got.to_numpy(zero_copy_only=False), column)


def test_labels_and_dictionary_keep_text_and_first_appearance():
    texts = ["s2_tool_steel/al_6061", "", "glass/äöü", "x"]
    assert arrow_arrays.labels(texts).equals(pa.array(texts, type=pa.string()))
    column = np.array(["b/c", "a/z", "b/c", "", "a/z", "b/c"], dtype=object)
    got = arrow_arrays.dictionary(column)
    want = pa.array(column.tolist(), type=pa.string()).dictionary_encode()
    assert got.dictionary.equals(want.dictionary) and got.indices.equals(want.indices)


def test_a_sweep_written_to_parquet_imports_no_pandas(tmp_path):
    code = ("import sys\n"
            "from restitution.sweep import SweepSpec, run_sweep\n"
            "spec = SweepSpec(pairs=['s2_tool_steel/al_6061', 'chrome_steel/brass_260'], grid={'v_approach': [1.0, 2.0]})\n"
            f"res = run_sweep(spec, scheduler='serial', parts={str(tmp_path / 'parts')!r})\n"
            f"res.write({str(tmp_path / 't.parquet')!r})\n"
            "print('pandas' in sys.modules)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "False"
