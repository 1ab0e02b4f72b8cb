"""impact() on many cases evaluates a block of cases at a time (restitution._blocks), into blocks of memory
it reuses: every value must be the one the whole-array evaluation gives, and the one the package gave
before the change (commit BEFORE, taken from git), bit for bit, as the issue asks.

Bit identity is the right test here, not a tolerance: the blocks run the same numpy operations on the
same elements (numpy's loops compute each element from that element's operands alone), so a difference
in any bit would mean a case was computed differently, not rounded differently. The cases are random over
the model's declared domain (every pair of values, speeds of 0 and V* below 1 included), per-case parameter
arrays and scalar ones, a 2-D speed array, several option sets, the whole result and chosen outputs.
"""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import restitution as r
from restitution import _blocks
from git_sources import package_at
from blocked_cases import N, case_sets, differing, evaluate

ROOT = Path(__file__).resolve().parents[2]
BEFORE = "822cf88"  #: the last commit that evaluated large arrays whole, into fresh arrays


@pytest.fixture(scope="module")
def sets():
    return case_sets()


@pytest.fixture(scope="module")
def blocked(sets):
    return evaluate(r.impact, sets)


def test_the_cases_span_more_than_two_blocks():
    assert N > _blocks.BLOCKS_FROM * _blocks.CASES_PER_BLOCK and N % _blocks.CASES_PER_BLOCK != 0


def test_the_blocks_are_used_and_their_arrays_are_fresh_rows(sets):
    """Enough cases take the blocked way: every output an array of the speeds' shape, writable,
    sharing memory with no input and no other output, and still its own once the next result is made."""
    v, params = sets["scalar parameters"]
    assert _blocks.blockable(np.asarray(v), r.impact_terms(**params))
    first = r.impact(v, **params)
    arrays = [np.asarray(x) for x in first.as_dict().values()]
    assert all(a.shape == v.shape and a.flags.writeable for a in arrays)
    assert not any(np.shares_memory(a, b) for i, a in enumerate(arrays) for b in arrays[i + 1:] + [v])
    e = first.e.copy()
    second = r.impact(v * 0.5, **params)  # first is alive: its block is not reused
    assert np.array_equal(first.e, e) and not np.shares_memory(first.e, second.e)


def test_blocks_give_the_whole_arrays_values_bit_for_bit(sets, blocked, monkeypatch):
    monkeypatch.setattr(_blocks, "CASES_PER_BLOCK", 10**12)  # every array evaluated whole
    assert not _blocks.blockable(np.asarray(sets["scalar parameters"][0]), r.impact_terms(**sets["scalar parameters"][1]))
    whole = evaluate(r.impact, sets)
    assert differing(blocked, whole) == []


def test_a_reused_block_gives_the_same_values_bit_for_bit(sets, blocked):
    """Evaluated again, after the first results are gone (their blocks reused): the same bits."""
    again = evaluate(r.impact, sets)
    assert differing(blocked, again) == []


CHILD = r"""
import pickle, sys
sys.path[:0] = [sys.argv[1], sys.argv[2]]  # the package of BEFORE first, then the tests' helpers
import restitution
assert restitution.__file__.startswith(sys.argv[1]), restitution.__file__
import blocked_cases
with open(sys.argv[3], "wb") as f:
    pickle.dump(blocked_cases.evaluate(restitution.impact, blocked_cases.case_sets()), f)
"""


@pytest.fixture(scope="module")
def before_package(tmp_path_factory) -> Path:
    return package_at(BEFORE, tmp_path_factory.mktemp("before"))


def test_every_value_is_the_one_before_the_change_bit_for_bit(before_package, blocked, tmp_path):
    """The package of BEFORE (whole arrays, fresh memory) in a child process, on the same cases."""
    import pickle

    out = tmp_path / "before.pickle"
    done = subprocess.run([sys.executable, "-c", CHILD, str(before_package), str(ROOT / "tests"), str(out)],
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    with open(out, "rb") as f:
        before = pickle.load(f)
    assert before.keys() == blocked.keys()
    assert differing(blocked, before) == []


def test_a_whole_row_of_a_block_is_told_from_other_views():
    """is_whole_row, which lets a sweep's table and statistics keep impact's rows without a copy: true only
    for a whole row of a 2-D array that owns its memory (rows never overlap), whatever the row."""
    block = np.zeros((3, 10))
    assert all(_blocks.is_whole_row(row) for row in block)
    assert not _blocks.is_whole_row(block[1, 2:])  # part of a row
    assert not _blocks.is_whole_row(block[:, 0])  # a column: strided across the rows
    assert not _blocks.is_whole_row(np.zeros(10))  # owns its memory: no base at all
    assert _blocks.is_whole_row(block[::2][1])  # a row of a view of rows: still a whole row of the block
    assert not _blocks.is_whole_row(np.zeros(30).reshape(3, 10)[1])  # its memory's owner is 1-D
    assert not _blocks.is_whole_row(block.reshape(-1)[3:13])  # a block's span across two rows
    assert not _blocks.is_whole_row(block[0].view(np.int64))  # another dtype's view of a row
    assert _blocks.has_own_bytes(block[1]) and _blocks.has_own_bytes(np.zeros(3))
    assert not _blocks.has_own_bytes(block[1, 2:]) and not _blocks.has_own_bytes(np.zeros(6)[::2])
