"""Large arrays of impacts evaluated a block of cases at a time, into memory the process reuses.

:func:`restitution.model.impact`'s array mode takes each step of the model as one numpy operation over all
the cases. Over 10^6 cases each such pass streams megabytes through memory, each temporary is memory
fresh from the system, and so are the 25 arrays of the result (200 MB), which the system must clear
page by page before the model writes them: the model cost 2.6 times a plain numpy expression of e alone,
the fresh arrays alone 1.6 times. Here the same steps run over :data:`CASES_PER_BLOCK` cases at a time,
whose temporaries stay in the processor's caches, and each output is written once into its row of a
block of every case. The operations on each case are the same, in the same order: only how many cases
one numpy call takes changes, so every value is the one the whole-array evaluation gives.

The blocks are kept for the next call once no array of the result that used them is alive (checked by
their reference counts, under a lock): a run of large evaluations (a benchmark, a sweep's chunks) writes
into memory already mapped. At most :data:`KEPT_BYTES` of blocks are kept after their results are gone,
the most recently made first.
"""
from __future__ import annotations

import sys
import threading

import numpy as np

__all__ = ["CASES_PER_BLOCK", "BLOCKS_FROM", "KEPT_BYTES", "blockable", "in_blocks", "is_whole_row", "has_own_bytes"]

#: Cases per block: each of a block's float temporaries is 256 kB; the thirty or so alive at once fit
#: the shared cache. Fewer cases per call cost more in numpy's per-call overhead than they save.
CASES_PER_BLOCK = 32768
#: Blocks from which the blocked evaluation pays: below, the whole arrays' temporaries are reused from the
#: allocator's heap, and a sweep's chunks of 10^5 cases (whose results it keeps, so that their blocks are
#: not reused) took 45 ms a chunk blocked against 35 ms whole.
BLOCKS_FROM = 4
#: Bytes of result blocks kept for reuse once their result is gone, at most (10^6 cases with every
#: output: 144 MB). A larger result's blocks are fresh memory, given back when it is gone.
KEPT_BYTES = 256 * 2**20


_KEPT: dict = {}  # (dtype, rows, cases) -> a block made for them (2-D), the most recent last
_KEPT_LOCK = threading.Lock()
_OWN_REFERENCES = 3  # of a kept block nobody uses: _KEPT's, the local name's, getrefcount's argument


def blockable(v: np.ndarray, terms) -> bool:
    """Are there enough cases for blocks to pay, and does every per-case term have them all (no
    broadcasting left to do: a speed array with parameter arrays of another shape is evaluated whole)?"""
    if v.size < BLOCKS_FROM * CASES_PER_BLOCK:
        return False
    if terms.floats:
        return True
    return all(x.shape == v.shape for x in _per_case(terms).values())


def _per_case(terms) -> dict:
    """The :class:`~restitution.model.ImpactTerms` fields that hold a value per case (arrays), by name."""
    return {f: x for f, x in terms._asdict().items() if isinstance(x, np.ndarray) and x.ndim}


def in_blocks(pipeline, v: np.ndarray, terms, want, dtype_of):
    """``pipeline(v, terms, want)`` (:func:`restitution.model._pipeline`'s array mode) evaluated a block of
    cases at a time, its values gathered into arrays of ``v``'s shape: the same record (a tuple) or dict of
    outputs. The arrays of one dtype (``dtype_of(key)``, key a position in the record or an output's name)
    are the rows of one 2-D block: each is contiguous, writable and shares no memory with another (a row
    kept alone keeps its block alive). Each block's values come raw (``raw=True``: a value every case
    shares as a scalar), written into their rows by one assignment each."""
    shape, n = v.shape, v.size
    flat_v = v.reshape(-1)
    per_case = {f: x.reshape(-1) for f, x in _per_case(terms).items()}
    gathered = None
    for start in range(0, n, CASES_PER_BLOCK):
        stop = min(start + CASES_PER_BLOCK, n)
        block_terms = terms._replace(shape=() if terms.floats else (stop - start,),
                                     **{f: x[start:stop] for f, x in per_case.items()})
        values = pipeline(flat_v[start:stop], block_terms, want, raw=True)
        keys = list(values) if isinstance(values, dict) else range(len(values))
        if gathered is None:
            gathered = _rows({key: np.dtype(dtype_of(key)) for key in keys}, n)
        for key in keys:
            gathered[key][start:stop] = values[key]
    if isinstance(values, dict):
        return {key: array.reshape(shape) for key, array in gathered.items()}
    return tuple(gathered[k].reshape(shape) for k in range(len(gathered)))


def is_whole_row(array: np.ndarray) -> bool:
    """Is ``array`` one whole row of a 2-D array that owns its memory, as :func:`in_blocks` returns the outputs?
    Its bytes are then its own (rows never overlap), as an array's that owns its memory: a table or the
    statistics of a sweep keep it without a copy."""
    base = array.base
    if not (isinstance(base, np.ndarray) and base.ndim == 2 and base.flags.owndata and base.flags.c_contiguous
            and array.ndim == 1 and array.size == base.shape[1] and array.dtype == base.dtype):
        return False
    offset = array.__array_interface__["data"][0] - base.__array_interface__["data"][0]
    return offset % base.strides[0] == 0


def has_own_bytes(array: np.ndarray) -> bool:
    """Does ``array`` own its memory, or is it a whole row of such a 2-D array (:func:`is_whole_row`)? Either
    way no other array's bytes are among its own."""
    return array.flags.owndata or is_whole_row(array)


def _rows(dtypes: dict, n: int) -> dict:
    """key -> a row of ``n`` elements of ``dtypes[key]``: the rows of one dtype are those of one block,
    the kept one where it has the shape and nobody uses it any more."""
    kinds = {}
    for key, dtype in dtypes.items():
        kinds.setdefault(dtype, []).append(key)
    rows = {}
    with _KEPT_LOCK:  # a block found unused is taken (its rows made) before another thread looks
        for dtype, keys in kinds.items():
            shape = (len(keys), n)
            block = _KEPT.get((dtype, *shape))
            if block is None or sys.getrefcount(block) > _OWN_REFERENCES:
                block = np.empty(shape, dtype=dtype)
                _keep((dtype, *shape), block)
            rows.update(zip(keys, block))
    return rows


def _keep(key, block: np.ndarray) -> None:
    """Keep ``block`` (the newest) under ``key``, and as many of the other kept blocks, newest first, as
    :data:`KEPT_BYTES` allows."""
    _KEPT.pop(key, None)
    if block.nbytes > KEPT_BYTES:
        return
    budget = KEPT_BYTES - block.nbytes
    for old in reversed(list(_KEPT)):
        if _KEPT[old].nbytes <= budget:
            budget -= _KEPT[old].nbytes
        else:
            del _KEPT[old]
    _KEPT[key] = block
