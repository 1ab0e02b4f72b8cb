"""A sweep's numpy columns as Arrow arrays, made from their buffers.

``pyarrow.array(ndarray)`` asks pandas whether the array is a categorical, and so imports pandas
wherever it is installed (it is, with the ``sweep`` extra): 0.26 s of CPU, on the first chunk of
every sweep that writes its parts, which is every command-line sweep (160 cases took 0.65 s in all).
Here the arrays are built from the columns' own memory (numbers without a copy; Booleans packed into
Arrow's bits) and the pair labels from their UTF-8 bytes, with no call that reaches pandas.
"""
from __future__ import annotations

import numpy as np

__all__ = ["numbers", "labels", "dictionary"]


def numbers(column: np.ndarray):
    """A 1-d numeric or Boolean numpy column as an Arrow array of its type (numbers share its memory)."""
    import pyarrow as pa

    column = np.ascontiguousarray(column)
    if column.dtype == np.bool_:
        bits = np.packbits(column, bitorder="little")  # Arrow's validity-style bitmap: bit i is row i
        return pa.Array.from_buffers(pa.bool_(), column.size, [None, pa.py_buffer(bits)])
    return pa.Array.from_buffers(pa.from_numpy_dtype(column.dtype), column.size, [None, pa.py_buffer(column)])


def labels(texts) -> object:
    """Strings as an Arrow string array."""
    import pyarrow as pa

    encoded = [str(t).encode("utf-8") for t in texts]
    offsets = np.zeros(len(encoded) + 1, dtype=np.int32)
    np.cumsum([len(b) for b in encoded], out=offsets[1:])
    return pa.Array.from_buffers(pa.string(), len(encoded),
                                 [None, pa.py_buffer(offsets), pa.py_buffer(b"".join(encoded))])


def dictionary(column: np.ndarray):
    """An object column of strings (a sweep's ``pair``) dictionary-encoded, its values in the order they
    first appear (as ``pyarrow``'s ``dictionary_encode`` orders them)."""
    import pyarrow as pa

    values, first, codes = np.unique(np.asarray(column, dtype=object).astype(str), return_index=True,
                                     return_inverse=True)
    order = np.argsort(first, kind="stable")  # first appearance
    rank = np.empty_like(order)
    rank[order] = np.arange(order.size)
    return pa.DictionaryArray.from_arrays(numbers(rank[codes.ravel()].astype(np.int32)), labels(values[order]))
