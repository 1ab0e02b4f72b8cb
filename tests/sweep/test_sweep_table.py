"""How a sweep's table is put together: chunks packed for the trip from a worker (one buffer, a column
of one value sent as that value) and joined into the table. Every value
must come back bit for bit: this is transport, no arithmetic, so equality of the bits is the right test."""
import numpy as np
import pytest

from restitution.sweep import SweepSpec
from restitution.sweep.backends import PackageBackend
from restitution.sweep.table import COLUMNS, PackedColumns, TableBuilder, assemble, keep_columns

SPEC = SweepSpec(pairs=["s2_tool_steel/al_6061", "brass_260/borosilicate_glass"],
                 grid={"v_approach": {"geomspace": [0.05, 20.0, 30]}, "t_over_d": {"geomspace": [0.05, 10.0, 20]}})


def _same_bits(a, b):
    a, b = np.asarray(a), np.asarray(b)
    return a.dtype == b.dtype and a.shape == b.shape and np.array_equal(
        a.view(f"u{a.dtype.itemsize}"), b.view(f"u{b.dtype.itemsize}"))


@pytest.mark.parametrize("rows", [0, 1, 2, 7, 1000])
def test_packed_columns_come_back_bit_for_bit(rows):
    rng = np.random.default_rng(rows)
    nan_payload = np.array([0x7FF8_0000_0000_0001], dtype=np.uint64).view(float)[0]
    columns = {
        "case": np.arange(rows, dtype=np.int64),
        "varying": rng.normal(size=rows),
        "constant": np.full(rows, 2.5e11),
        "signed_zeros": np.where(np.arange(rows) % 2 == 0, 0.0, -0.0),  # equal as numbers, not as bits
        "nan_payloads": np.where(np.arange(rows) % 3 == 0, np.nan, nan_payload),
        "flag": np.arange(rows) % 2 == 0,
        "all_true": np.ones(rows, dtype=bool),
        "odd_sized": np.arange(rows, dtype=np.int8),  # the next column still lands on an 8-byte boundary
        "after_odd": np.arange(rows, dtype=float),
        "strided": np.arange(2 * rows, dtype=float)[::2],
        "one_value_view": np.broadcast_to(np.float64(-0.0), (rows,)),  # as SweepSpec.cases gives constants
    }
    packed = PackedColumns(columns)
    back = packed.columns()
    assert list(back) == list(columns)
    for name, col in columns.items():
        assert _same_bits(back[name], col), name
    if rows > 1:  # the one-value columns ("constant", "all_true", "one_value_view") travel as one value each
        sent = sum(c.size * c.itemsize for c in columns.values()) - (rows - 1) * (8 + 1 + 8)
        assert sent <= packed.buffer.nbytes <= sent + 8 * len(columns)


def test_packed_chunk_survives_pickling_as_one_buffer():
    import pickle

    cases = SPEC.cases(0, 300)
    packed = PackedColumns(cases)
    buffers = []
    data = pickle.dumps(packed, protocol=5, buffer_callback=buffers.append)
    assert len(buffers) == 1 and len(data) < 4096  # Dask sends the buffer as one frame beside a small header
    back = pickle.loads(data, buffers=buffers).columns()
    for name, col in cases.items():
        assert _same_bits(back[name], col), name


def test_assemble_joins_packed_and_plain_chunks_into_the_table():
    """The table against the same chunks' own columns joined by hand: a copy of the values each chunk
    computed, so every bit must survive (the chunks are evaluated once; no two evaluations compared)."""
    n = SPEC.n_cases
    parts, expected = [], []
    for k, a in enumerate(range(0, n, 97)):  # uneven chunks, every other one as it comes from a worker
        cols = SPEC.cases(a, min(a + 97, n))
        cols.update(PackageBackend().evaluate(cols)[0])
        expected.append({name: np.array(col) for name, col in cols.items()})
        parts.append(PackedColumns(cols) if k % 2 else cols)
    table = assemble(SPEC, parts, None)
    assert parts == []  # consumed: each chunk is dropped once it is in
    assert list(table) == list(COLUMNS)
    assert list(table["pair"]) == [SPEC.pairs[j] for e in expected for j in e["pair"]]
    for name in COLUMNS:
        if name != "pair":
            col = np.concatenate([e[name] for e in expected]).astype(table[name].dtype)
            assert _same_bits(table[name], col), name


def test_assemble_keeps_the_asked_columns_with_their_types():
    keep = keep_columns(["v_approach", "e", "zener_method"])
    cols = SPEC.cases(0, 50)
    cols.update(PackageBackend().evaluate(cols)[0])
    table = assemble(SPEC, [PackedColumns({k: v for k, v in cols.items() if k in keep})], keep)
    assert set(table) == set(keep)
    assert table["case"].dtype == np.int64 and table["zener_method"].dtype == np.int64
    assert table["ok"].dtype == bool and table["valid"].dtype == bool and table["e"].dtype == float
    assert np.array_equal(table["zener_method"], cols["zener_method"].astype(np.int64))
    empty = assemble(SPEC, [], keep)
    assert set(empty) == set(keep) and all(len(c) == 0 for c in empty.values())


ONE_PAIR = SweepSpec(pairs=["s2_tool_steel/al_6061"], grid={"v_approach": {"geomspace": [0.05, 20.0, 30]},
                                                            "t_over_d": {"geomspace": [0.05, 10.0, 20]}})


def _evaluated(spec, a, b):
    cols = spec.cases(a, b)
    cols.update(PackageBackend().evaluate(cols)[0])
    return cols


@pytest.mark.parametrize("chunks", [1, 3])
@pytest.mark.parametrize("packed", [False, True])
def test_assemble_keeps_fixed_inputs_as_views_and_owns_every_other_column(chunks, packed):
    """Inputs that hold one value over the whole sweep (here one pair's materials and the fixed options,
    found from the values themselves) are read-only one-value views; outputs and varying inputs are
    writable arrays, none sharing memory with another column; the values are the chunks' own, bit for bit."""
    n, bounds = ONE_PAIR.n_cases, np.linspace(0, ONE_PAIR.n_cases, chunks + 1).astype(int)
    own = [_evaluated(ONE_PAIR, a, b) for a, b in zip(bounds[:-1], bounds[1:])]
    expected = {name: np.concatenate([np.array(c[name]) for c in own]) for name in own[0]}
    table = assemble(ONE_PAIR, [PackedColumns(c) if packed else c for c in own], None)
    outputs = set(COLUMNS[COLUMNS.index("t_over_d") + 1:])
    owned = []
    for name in COLUMNS:
        col = table[name]
        if name == "pair":
            assert list(col) == ["s2_tool_steel/al_6061"] * n
        else:
            assert _same_bits(col, expected[name].astype(col.dtype)), name
        constant = name not in outputs and np.all(col == col[0])
        assert (col.strides == (0,)) == constant, name  # a view exactly where the input is fixed
        assert col.flags.writeable != constant, name
        if not constant:
            owned.append(name)
    assert {"v_approach", "t_over_d", "e", "jgm.V_c"} <= set(owned) and "sphere.E" not in owned
    for i, a in enumerate(owned):
        for b in owned[i + 1:]:
            assert not np.shares_memory(table[a], table[b]), (a, b)


def test_the_table_builder_takes_chunks_in_any_order_and_an_input_that_varies_late():
    """Chunks added as they finish, out of order, give the table in case order, bit for bit. A sweep over
    two pairs whose first chunks all lie in the first pair holds the materials as one-value views up to
    the chunk where the second pair starts: the column then holds the earlier rows' value and the later
    rows' own. The chunks' arrays are not kept (each can be freed once added)."""
    import gc
    import weakref

    n = SPEC.n_cases  # pair 0's cases come first: its materials are one-value views in its chunks
    bounds = [0, 150, 300, 450, n]
    own = [_evaluated(SPEC, a, b) for a, b in zip(bounds[:-1], bounds[1:])]
    assert all(c["sphere.E"].strides == (0,) for c in own[:2])  # views in the first chunks
    expected = {name: np.concatenate([np.array(c[name]) for c in own]) for name in own[0]}
    builder = TableBuilder(SPEC, None, n)
    watched = weakref.ref(own[2]["e"])
    for k in (2, 0, 3, 1):  # the order a cluster may finish them in
        builder.add(bounds[k], PackedColumns(own[k]) if k % 2 else own[k])
    del own
    gc.collect()
    assert watched() is None  # copied, not kept
    table = builder.table()
    assert list(table["pair"]) == [SPEC.pairs[j] for j in expected["pair"]]
    for name in COLUMNS:
        if name != "pair":
            assert _same_bits(table[name], expected[name].astype(table[name].dtype)), name
    assert table["sphere.E"].strides != (0,) and len(set(table["sphere.E"].tolist())) == 2


@pytest.mark.parametrize("added", [[0, 2], [1], [2], []])
def test_an_interrupted_table_holds_the_rows_of_the_chunks_added_in_case_order(added):
    """After an interruption the table holds the finished chunks' rows only (gaps closed), still in case
    order; a fixed input stays a one-value view where more than one row remains."""
    n = ONE_PAIR.n_cases
    bounds = np.linspace(0, n, 4).astype(int)
    own = {k: _evaluated(ONE_PAIR, bounds[k], bounds[k + 1]) for k in added}
    builder = TableBuilder(ONE_PAIR, None, n)
    for k in reversed(added):
        builder.add(int(bounds[k]), own[k])
    table = builder.table()
    rows = sum(int(bounds[k + 1] - bounds[k]) for k in added)
    assert all(len(col) == rows for col in table.values())
    if added:
        want = np.concatenate([own[k]["case"] for k in added])
        assert np.array_equal(table["case"], want) and np.all(np.diff(table["case"]) > 0)
        assert _same_bits(table["e"], np.concatenate([own[k]["e"] for k in added]))
        assert table["sphere.E"].strides == (0,)
